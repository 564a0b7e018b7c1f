//! Integrators turn camera rays into pixel values: [`Integrator`] names one with its settings,
//! [`RenderSession`] runs it over a scene, pass by pass, and [`RenderConfig`] is every render
//! option as a front end (the command line, Python) gives it.
//!
//! - [`whitted`]: the course model: the course's Whitted ray tracer plus caustics from a photon
//!   map, rendered in one go.
//! - [`path`], [`ppm`], [`gi`], [`lt`], [`vcm`]: the physical model, rendered in independent
//!   passes that converge: a path tracer, progressive photon mapping, Jensen's photon mapping
//!   with final gathering, light tracing, vertex connection and merging.

pub mod beam_estimate;
pub mod camera_walk;
pub mod config;
pub mod darkness;
pub mod direct;
pub mod gi;
pub mod lt;
pub mod partial;
pub mod path;
pub mod ppm;
pub mod radius;
pub mod report;
pub mod session;
pub mod specular_chain;
pub mod tiles;
pub mod vcm;
pub mod whitted;

pub use config::{GivenOptions, RenderConfig};
pub use report::{RunDetail, RunReport, RunSeconds};
pub use session::{PassPlan, RenderOptions, RenderSession, Resize, RunSummary};
pub use tiles::{image_size, ImageSettings};

use crate::error::{Error, Result};
use crate::math::Vec3;
use crate::photon::{EstimateSettings, PhotonSettings};
use crate::progress::Control;
use gi::GiSettings;
use lt::LtSettings;
use path::PathSettings;
use ppm::PpmSettings;
use radius::InitialRadius;
use vcm::VcmSettings;
use whitted::WhittedSettings;

/// An integrator and its settings.
#[derive(Clone, Debug, PartialEq)]
pub enum Integrator {
    /// The course's Whitted ray tracer with caustics from a photon map.
    Whitted(WhittedOptions),
    /// Unidirectional path tracing (the physical model's reference).
    Path(PathSettings),
    /// Progressive photon mapping.
    Ppm(PpmSettings),
    /// Jensen's photon mapping with final gathering.
    Gi(GiSettings),
    /// Light tracing: photons splatted onto the film through the pinhole.
    Lt(LtSettings),
    /// Vertex connection and merging: every strategy above, weighted against each other.
    Vcm(VcmSettings),
}

/// Everything the course model's render uses.
#[derive(Clone, Debug, PartialEq)]
pub struct WhittedOptions {
    /// The ray tracer.
    pub whitted: WhittedSettings,
    /// The caustic photons (none stored when `target_stored` is 0).
    pub photons: PhotonSettings,
    /// How caustic radiance is estimated from them.
    pub estimate: EstimateSettings,
    /// N for N×N stratified, jittered samples per pixel.
    pub aa: u32,
}

impl Default for WhittedOptions {
    fn default() -> Self {
        WhittedOptions {
            whitted: WhittedSettings::default(),
            photons: PhotonSettings::default(),
            estimate: EstimateSettings::default(),
            aa: 1,
        }
    }
}

/// Largest photon count accepted (24 bytes each: 2.4 GB).
pub const MAX_PHOTONS: usize = 100_000_000;

impl Integrator {
    /// The integrator's name on the command line.
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Whitted(_) => "whitted",
            Integrator::Path(_) => "path",
            Integrator::Ppm(_) => "ppm",
            Integrator::Gi(_) => "gi",
            Integrator::Lt(_) => "lt",
            Integrator::Vcm(_) => "vcm",
        }
    }

    /// Whether it renders the physical model in independent passes (every integrator but
    /// Whitted's).
    pub fn is_progressive(&self) -> bool {
        !matches!(self, Integrator::Whitted(_))
    }

    /// Refuses settings out of their ranges, with the option that is wrong.
    pub fn validate(&self) -> Result<()> {
        let invalid = |m: &str| Err(Error::InvalidSettings(m.into()));
        match self {
            Integrator::Whitted(o) => {
                if o.aa == 0 || o.aa > 64 {
                    return invalid("--aa must be between 1 and 64");
                }
                if o.whitted.max_depth > 64 {
                    return invalid("--depth must be at most 64");
                }
                if o.estimate.max_radius.is_some_and(|r| !(r > 0.0 && r.is_finite())) {
                    return invalid("--radius must be a positive number");
                }
                if o.estimate.cone_filter.is_some_and(|c| !(c >= 1.0 && c.is_finite())) {
                    return invalid("--cone-filter must be 0 (off) or at least 1");
                }
                check_k(o.estimate.k)?;
                check_photons(o.photons.target_stored)
            }
            // The path tracer's limit counts scattering surfaces: `--depth` + 1.
            Integrator::Path(s) => check_depth(s.max_depth.saturating_sub(1)),
            Integrator::Ppm(s) => {
                check_depth(s.max_depth)?;
                check_alpha(s.alpha)?;
                check_radius(s.initial_radius)?;
                check_photons_per_pass(self.name(), s.photons_per_pass)
            }
            Integrator::Gi(s) => {
                check_depth(s.max_depth)?;
                check_alpha(s.alpha)?;
                check_radius(s.caustic_radius)?;
                check_k(s.k_global)?;
                check_photons_per_pass(self.name(), s.photons_per_pass)
            }
            Integrator::Lt(s) => {
                check_depth(s.max_depth)?;
                check_photons_per_pass(self.name(), s.photons_per_pass)
            }
            Integrator::Vcm(s) => {
                check_depth(s.max_depth)?;
                check_alpha(s.alpha)?;
                check_radius(s.initial_radius)?;
                match s.light_paths_per_pass {
                    Some(n) => check_photons_per_pass(self.name(), n),
                    None => Ok(()),
                }
            }
        }
    }
}

fn check_k(k: usize) -> Result<()> {
    if k == 0 || k > 10_000 {
        return Err(Error::InvalidSettings("--k must be between 1 and 10000".into()));
    }
    Ok(())
}

fn check_photons(count: usize) -> Result<()> {
    if count > MAX_PHOTONS {
        return Err(Error::InvalidSettings(format!(
            "{count} photons would need {} MB; at most {MAX_PHOTONS} photons are accepted",
            count.saturating_mul(24) / 1_000_000
        )));
    }
    Ok(())
}

fn check_photons_per_pass(name: &str, count: u64) -> Result<()> {
    if count == 0 {
        return Err(Error::InvalidSettings(format!(
            "--integrator {name} needs photons: --photons must be at least 1 (photons per pass)"
        )));
    }
    check_photons(usize::try_from(count).unwrap_or(usize::MAX))
}

/// `--depth` of a physical integrator: 0 (direct light only) to 1024.
fn check_depth(depth: u32) -> Result<()> {
    if depth > 1024 {
        return Err(Error::InvalidSettings(
            "--depth must be between 0 and 1024 for the physical integrators".into(),
        ));
    }
    Ok(())
}

fn check_alpha(alpha: f32) -> Result<()> {
    if !(alpha > 0.0 && alpha < 1.0) {
        return Err(Error::InvalidSettings(
            "--alpha must lie strictly between 0 and 1".into(),
        ));
    }
    Ok(())
}

fn check_radius(radius: InitialRadius) -> Result<()> {
    match radius {
        InitialRadius::Pixels(px) if !(px > 0.0 && px <= 10_000.0) => Err(Error::InvalidSettings(
            "--footprint must be a positive number of pixels (at most 10000)".into(),
        )),
        InitialRadius::World(r) if !(r > 0.0 && r.is_finite()) => {
            Err(Error::InvalidSettings("--radius must be a positive number".into()))
        }
        _ => Ok(()),
    }
}

/// An integrator that renders the image as a series of independent passes.
pub trait Progressive: Send + Sync {
    /// Work done once before the first pass (pilot runs that choose the passes' settings);
    /// `false` when cancelled. [`RenderSession`] runs it; a caller driving passes itself calls
    /// it first.
    fn prepare(&mut self, _control: Control) -> bool {
        true
    }

    /// Renders pass `pass` (global index); `None` when cancelled (or not prepared).
    fn render_pass(&self, pass: u64, control: Control) -> Option<Vec<Vec3>>;

    /// The time pass `pass` takes relative to a full pass, for a time limit's plan.
    fn pass_cost(&self, _pass: u64) -> f64 {
        1.0
    }

    /// Pass `pass`'s weight in the image's mean: its share of a full pass's light paths.
    fn pass_weight(&self, _pass: u64) -> f64 {
        1.0
    }

    /// Light paths (photons) a full pass traces, when the integrator chose the number itself.
    fn chosen_paths_per_pass(&self) -> Option<u64> {
        None
    }

    /// For the end of a time limit: the share of a full pass that pass `pass` can take and
    /// still end within `seconds`, from the passes timed so far. `None`: this integrator's
    /// passes keep their size.
    fn share_within(&self, _pass: u64, _seconds: f64) -> Option<f64> {
        None
    }

    /// Renders pass `pass` at `share` of a full pass (its weight is `share`); an integrator
    /// whose [`Progressive::share_within`] is `None` renders it at its own size.
    fn render_share(&self, pass: u64, _share: f64, control: Control) -> Option<Vec<Vec3>> {
        self.render_pass(pass, control)
    }
}
