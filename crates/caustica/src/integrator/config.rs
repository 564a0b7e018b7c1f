//! Every render option by its command-line name, with the command line's defaults: what a
//! front end (the `caustica` binary, the Python module) fills in and turns into an
//! [`Integrator`] and a [`PassPlan`]. Both front ends go through here, so the same options give
//! the same image.

use super::gi::GiSettings;
use super::lt::LtSettings;
use super::path::PathSettings;
use super::ppm::PpmSettings;
use super::radius::InitialRadius;
use super::session::{PassPlan, RenderOptions};
use super::vcm::VcmSettings;
use super::whitted::WhittedSettings;
use super::{Integrator, WhittedOptions};
use crate::description::{IntegratorHint, RenderHints};
use crate::error::{Error, Result};
use crate::photon::{EstimateSettings, Estimator, PhotonSettings};
use std::path::PathBuf;
use std::str::FromStr;

/// The shading model.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    /// The `.ray` look: the course's Whitted shading and caustics.
    Course,
    /// Radiometric units, inverse-square lights, Fresnel glass, emissive objects as lights.
    Physical,
}

impl FromStr for Model {
    type Err = Error;

    fn from_str(s: &str) -> Result<Model> {
        match s {
            "course" => Ok(Model::Course),
            "physical" => Ok(Model::Physical),
            other => Err(Error::InvalidSettings(format!(
                "unknown model `{other}`: expected course or physical"
            ))),
        }
    }
}

/// An integrator by name.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorKind {
    /// The course model's Whitted ray tracer with caustics.
    Whitted,
    /// Path tracing.
    Path,
    /// Progressive photon mapping.
    Ppm,
    /// Jensen's photon mapping with final gathering.
    Gi,
    /// Light tracing.
    Lt,
    /// Vertex connection and merging.
    Vcm,
}

impl IntegratorKind {
    /// The name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            IntegratorKind::Whitted => "whitted",
            IntegratorKind::Path => "path",
            IntegratorKind::Ppm => "ppm",
            IntegratorKind::Gi => "gi",
            IntegratorKind::Lt => "lt",
            IntegratorKind::Vcm => "vcm",
        }
    }
}

impl FromStr for IntegratorKind {
    type Err = Error;

    fn from_str(s: &str) -> Result<IntegratorKind> {
        match s {
            "whitted" => Ok(IntegratorKind::Whitted),
            "path" => Ok(IntegratorKind::Path),
            "ppm" => Ok(IntegratorKind::Ppm),
            "gi" => Ok(IntegratorKind::Gi),
            "lt" => Ok(IntegratorKind::Lt),
            "vcm" => Ok(IntegratorKind::Vcm),
            other => Err(Error::InvalidSettings(format!(
                "unknown integrator `{other}`: expected whitted, path, ppm, gi, lt or vcm"
            ))),
        }
    }
}

/// Every option of `caustica render` that shapes the image, and the two it checks with them.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderConfig {
    /// `--model`.
    pub model: Option<Model>,
    /// `--integrator`.
    pub integrator: Option<IntegratorKind>,
    /// `--width`.
    pub width: usize,
    /// `--height`.
    pub height: Option<usize>,
    /// `--aa`.
    pub aa: u32,
    /// `--depth`: bounces after the first surface the eye sees, so light reaches the eye after
    /// scattering at no more than depth + 1 surfaces ([`scattering_surfaces`]); 5 for whitted, 64 for
    /// the physical integrators.
    pub depth: Option<u32>,
    /// `--seed`.
    pub seed: u64,
    /// `--photons`: caustic photons to store (course), photons emitted per pass (physical).
    pub photons: usize,
    /// `--photons` as given (not the scene's or the default): vcm's light subpaths per pass
    /// (16 per pixel when unset, half in the first two passes).
    pub light_paths: Option<u64>,
    /// `--max-emitted`.
    pub max_emitted: Option<u64>,
    /// `--photons-per-light`.
    pub photons_per_light: Option<Vec<usize>>,
    /// `--no-aim`.
    pub no_aim: bool,
    /// `--k`.
    pub k: usize,
    /// `--radius`.
    pub radius: Option<f32>,
    /// `--cone-filter` (0: off).
    pub cone_filter: f32,
    /// `--estimate`: the course model's caustic estimate.
    pub estimator: Estimator,
    /// `--no-estimate-reuse`.
    pub no_estimate_reuse: bool,
    /// `--passes`: N or A..B.
    pub passes: Option<String>,
    /// `--time`.
    pub time: Option<f64>,
    /// `--footprint` (`None`: each integrator's own first radius, 2 pixels for `ppm` and `gi`,
    /// [`MERGING_FOOTPRINT`](super::vcm::MERGING_FOOTPRINT) for `vcm`).
    pub footprint: Option<f32>,
    /// `--alpha`.
    pub alpha: f32,
    /// `--no-camera-specular`.
    pub no_camera_specular: bool,
    /// `--vertex-connections` (vcm).
    pub vertex_connections: bool,
    /// `--no-beams` (vcm).
    pub no_beams: bool,
    /// `--spectral` / `--no-spectral` (physical model): light at sampled wavelengths or in RGB;
    /// by default spectral exactly when the scene has a dispersive glass.
    pub spectral: Option<bool>,
    /// `--max-memory`: the largest photon map in MB.
    pub max_memory: u64,
    /// `--partial`: where the sums of the passes go (only the physical integrators keep sums).
    pub partial: Option<PathBuf>,
}

impl Default for RenderConfig {
    fn default() -> Self {
        RenderConfig {
            model: None,
            integrator: None,
            width: 512,
            height: None,
            aa: 1,
            depth: None,
            seed: 0,
            photons: 200_000,
            light_paths: None,
            max_emitted: None,
            photons_per_light: None,
            no_aim: false,
            k: 100,
            radius: None,
            cone_filter: 1.1,
            estimator: Estimator::Kernels,
            no_estimate_reuse: false,
            passes: None,
            time: None,
            footprint: None,
            alpha: 2.0 / 3.0,
            no_camera_specular: false,
            vertex_connections: false,
            no_beams: false,
            spectral: None,
            max_memory: 4096,
            partial: None,
        }
    }
}

/// Which of a front end's options its user set, among those a scene file sets too
/// ([`RenderConfig::over_scene`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GivenOptions {
    /// `model` or `integrator`: either replaces the scene's choice of both.
    pub model_or_integrator: bool,
    /// `width` (`--width`).
    pub width: bool,
    /// `height`.
    pub height: bool,
    /// `depth`.
    pub depth: bool,
    /// `photons`.
    pub photons: bool,
    /// `radius`.
    pub radius: bool,
    /// `passes`.
    pub passes: bool,
    /// `time`: a time limit, under which the scene's passes do not apply.
    pub time: bool,
}

impl RenderConfig {
    /// These options (a front end's, `given` saying which its user set) over a scene file's own
    /// settings ([`RenderConfig::for_scene`]): the one precedence the command line and Python
    /// share, so a file renders the same pixels from both.
    ///
    /// - A model or integrator given replaces the scene's choice of both.
    /// - The scene's depth and passes are for a physical integrator (the course model has none);
    ///   its passes yield to a time limit given.
    /// - With only a width given, the height follows the camera rather than the scene's film.
    pub fn over_scene(self, given: &GivenOptions, hints: &RenderHints) -> RenderConfig {
        let scene = RenderConfig::for_scene(hints);
        let mut c = self;
        if !given.model_or_integrator {
            c.model = scene.model;
            c.integrator = scene.integrator;
        }
        let course = c.model == Some(Model::Course) || c.integrator == Some(IntegratorKind::Whitted);
        if !given.depth {
            c.depth = if course { None } else { scene.depth };
        }
        if !given.height {
            c.height = if given.width { None } else { scene.height };
        }
        if !given.width {
            c.width = scene.width;
        }
        if !given.photons {
            c.photons = scene.photons;
        }
        if !given.radius {
            c.radius = scene.radius;
        }
        if !given.passes {
            c.passes = if given.time || course { None } else { scene.passes };
        }
        c
    }

    /// The defaults with a scene file's own settings applied (pbrt-v4's `Film`, `Sampler` and
    /// `Integrator`): a front end starts here and then sets the options its user gave.
    ///
    /// A file in physical units (pbrt, glTF) that names no integrator renders with `vcm`: it
    /// shows the caustics of point, spot and sun lights through glass and mirrors, which a path
    /// tracer cannot, and everything a path tracer shows ([`integrator_note`] says so).
    ///
    /// pbrt's `maxdepth` N counts scattering events (its paths have up to N + 1 segments), so
    /// every physical integrator gets `--depth` N − 1 ([`scattering_surfaces`] of it is N);
    /// pbrt's `maxdepth` 0, light seen only where it is emitted, has no `--depth` and becomes 0.
    pub fn for_scene(hints: &RenderHints) -> RenderConfig {
        let mut config = RenderConfig::default();
        if let Some(w) = hints.width {
            config.width = w;
        }
        config.height = hints.height;
        // The course model knows no media: a scene with one is rendered physically.
        if hints.physical || hints.scattering_media {
            config.model = Some(Model::Physical);
            config.integrator = Some(match hints.integrator {
                Some(IntegratorHint::Ppm) => IntegratorKind::Ppm,
                Some(IntegratorHint::LightTracer) => IntegratorKind::Lt,
                Some(IntegratorHint::Bidirectional) | None => IntegratorKind::Vcm,
                Some(IntegratorHint::Path) => IntegratorKind::Path,
            });
        }
        if let Some(n) = hints.max_depth {
            config.depth = Some(n.saturating_sub(1));
        }
        if let Some(n) = hints.samples.filter(|&n| n > 0) {
            config.passes = Some(n.to_string());
        }
        if let Some(n) = hints.photons_per_pass {
            config.photons = n;
        }
        config.radius = hints.radius;
        config
    }

    /// The integrator `--model` and `--integrator` ask for: whitted for the course model (the
    /// default), ppm for the physical model unless named.
    pub fn integrator_kind(&self) -> Result<IntegratorKind> {
        match (self.model, self.integrator) {
            (Some(Model::Course), Some(kind)) if kind != IntegratorKind::Whitted => {
                Err(Error::InvalidSettings(format!(
                    "--integrator {} renders the physical model; drop --model course (or use --integrator whitted)",
                    kind.name()
                )))
            }
            (Some(Model::Physical), Some(IntegratorKind::Whitted)) => Err(Error::InvalidSettings(
                "the whitted integrator renders the course model; with --model physical use path, ppm, gi, lt or vcm"
                    .into(),
            )),
            (Some(Model::Physical), None) => Ok(IntegratorKind::Ppm),
            (_, Some(kind)) => Ok(kind),
            (_, None) => Ok(IntegratorKind::Whitted),
        }
    }

    /// Photons to store, summed over lights when given per light.
    pub fn photon_total(&self) -> usize {
        match &self.photons_per_light {
            Some(counts) => counts.iter().fold(0usize, |a, b| a.saturating_add(*b)),
            None => self.photons,
        }
    }

    /// The course model's photon settings.
    pub fn photon_settings(&self) -> PhotonSettings {
        PhotonSettings {
            target_stored: self.photon_total(),
            max_emitted: self.max_emitted.unwrap_or(0),
            aim: !self.no_aim,
            seed: self.seed,
            per_light: self.photons_per_light.clone(),
            ..PhotonSettings::default()
        }
    }

    /// The integrator with its settings (checked).
    pub fn integrator(&self) -> Result<Integrator> {
        let kind = self.integrator_kind()?;
        // path, lt and vcm store no photon map.
        if !matches!(kind, IntegratorKind::Path | IntegratorKind::Lt | IntegratorKind::Vcm) {
            check_photon_memory(self.photon_total(), self.max_memory)?;
        }
        let progressive = kind != IntegratorKind::Whitted;
        if !progressive && (self.passes.is_some() || self.time.is_some() || self.partial.is_some()) {
            return Err(Error::InvalidSettings(
                "--passes, --time and --partial belong to the physical model's integrators (--model physical)".into(),
            ));
        }
        let depth = self.depth.unwrap_or(if progressive { 64 } else { 5 });
        // `--radius`, else `--footprint`, else the integrator's own default.
        let initial_radius = |default: InitialRadius| match (self.radius, self.footprint) {
            (Some(r), _) => InitialRadius::World(r),
            (None, Some(px)) => InitialRadius::Pixels(px),
            (None, None) => default,
        };
        let specular_camera_paths = !self.no_camera_specular;
        let photons_per_pass = self.photon_total() as u64;
        let integrator = match kind {
            IntegratorKind::Whitted => Integrator::Whitted(WhittedOptions {
                whitted: WhittedSettings {
                    max_depth: depth,
                    reuse_caustic_estimates: !self.no_estimate_reuse,
                    ..WhittedSettings::default()
                },
                photons: self.photon_settings(),
                estimate: EstimateSettings {
                    k: self.k,
                    max_radius: self.radius,
                    cone_filter: (self.cone_filter != 0.0).then_some(self.cone_filter),
                    estimator: self.estimator,
                    ..EstimateSettings::default()
                },
                aa: self.aa,
            }),
            IntegratorKind::Path => Integrator::Path(PathSettings {
                // The path tracer counts the surfaces a camera path scatters at, not the bounces
                // after the first one: `--depth` N allows it N + 1, as photons of N bounces meet.
                max_depth: scattering_surfaces(depth),
                specular_camera_paths,
                spectral: self.spectral,
                ..PathSettings::default()
            }),
            IntegratorKind::Ppm => Integrator::Ppm(PpmSettings {
                photons_per_pass,
                alpha: self.alpha,
                initial_radius: initial_radius(PpmSettings::default().initial_radius),
                max_depth: depth,
                specular_camera_paths,
                spectral: self.spectral,
                ..PpmSettings::default()
            }),
            IntegratorKind::Gi => Integrator::Gi(GiSettings {
                photons_per_pass,
                k_global: self.k,
                caustic_radius: initial_radius(GiSettings::default().caustic_radius),
                alpha: self.alpha,
                max_depth: depth,
                specular_camera_paths,
                spectral: self.spectral,
            }),
            IntegratorKind::Lt => Integrator::Lt(LtSettings {
                photons_per_pass,
                max_depth: depth,
                spectral: self.spectral,
            }),
            IntegratorKind::Vcm => Integrator::Vcm(VcmSettings {
                light_paths_per_pass: self.light_paths,
                alpha: self.alpha,
                initial_radius: initial_radius(VcmSettings::default().initial_radius),
                max_depth: depth,
                connections: self.vertex_connections,
                beams: !self.no_beams,
                aim: !self.no_aim,
                spectral: self.spectral,
                balanced_footprint: match (self.radius, self.footprint) {
                    (None, None) => VcmSettings::default().balanced_footprint,
                    _ => None,
                },
                ..VcmSettings::default()
            }),
        };
        if progressive {
            // Options the physical integrators read whatever their kind.
            if self.radius.is_some_and(|r| !(r > 0.0 && r.is_finite())) {
                return Err(Error::InvalidSettings("--radius must be a positive number".into()));
            }
            if self.k == 0 || self.k > 10_000 {
                return Err(Error::InvalidSettings("--k must be between 1 and 10000".into()));
            }
            if self.footprint.is_some_and(|px| !(px > 0.0 && px <= 10_000.0)) {
                return Err(Error::InvalidSettings(
                    "--footprint must be a positive number of pixels (at most 10000)".into(),
                ));
            }
            if !(self.alpha > 0.0 && self.alpha < 1.0) {
                return Err(Error::InvalidSettings(
                    "--alpha must lie strictly between 0 and 1".into(),
                ));
            }
        } else if !(self.cone_filter == 0.0 || self.cone_filter >= 1.0) {
            return Err(Error::InvalidSettings(
                "--cone-filter must be 0 (off) or at least 1".into(),
            ));
        }
        integrator.validate()?;
        Ok(integrator)
    }

    /// Which passes to render (the physical integrators).
    pub fn plan(&self) -> Result<PassPlan> {
        PassPlan::new(self.passes.as_deref(), self.time)
    }

    /// The session options for a scene identified by `scene_id`.
    pub fn render_options(&self, scene_id: impl Into<String>) -> Result<RenderOptions> {
        Ok(RenderOptions {
            integrator: self.integrator()?,
            width: self.width,
            height: self.height,
            seed: self.seed,
            scene_id: scene_id.into(),
        })
    }

    /// Options given that only the course model's Whitted renderer reads, when the physical
    /// model renders.
    pub fn ignored_by_physical(&self) -> Vec<&'static str> {
        let mut ignored = Vec::new();
        if self.aa != 1 {
            ignored.push("--aa (each pass takes one jittered sample per pixel)");
        }
        if self.photons_per_light.is_some() {
            ignored.push("--photons-per-light");
        }
        if self.no_aim && self.integrator != Some(IntegratorKind::Vcm) {
            ignored.push("--no-aim");
        }
        if self.max_emitted.is_some() {
            ignored.push("--max-emitted");
        }
        if self.no_estimate_reuse {
            ignored.push("--no-estimate-reuse");
        }
        if self.estimator != Estimator::Kernels {
            ignored.push("--estimate");
        }
        ignored
    }

    /// Options given that light tracing does not read: it gathers nothing, so has no radius.
    pub fn ignored_by_lt(&self) -> Vec<&'static str> {
        let mut ignored = Vec::new();
        if self.integrator != Some(IntegratorKind::Lt) {
            return ignored;
        }
        let default = RenderConfig::default();
        if self.radius.is_some() {
            ignored.push("--radius");
        }
        if self.footprint.is_some() {
            ignored.push("--footprint");
        }
        if self.alpha != default.alpha {
            ignored.push("--alpha");
        }
        if self.k != default.k {
            ignored.push("--k");
        }
        ignored
    }
}

/// The surfaces light may scatter at on its way to the eye under `--depth` `depth`: the
/// first surface the eye sees and `depth` bounces after it. This is what `--depth` means for
/// every integrator: whitted follows `depth` reflection and refraction rays, photons (`ppm`,
/// `gi`, `lt`) make at most `depth` bounces before the surface they are seen on, and the path
/// tracer, whose own limit counts scattering surfaces, gets this many. So `path --depth 8` and
/// `ppm --depth 8` carry light from at most 9 surfaces, as pbrt's `maxdepth` 9 or Mitsuba's
/// `max_depth` 10 (which counts path segments) do.
pub const fn scattering_surfaces(depth: u32) -> u32 {
    depth.saturating_add(1)
}

/// Refuses photon counts whose map would exceed `max_memory` MB (`--max-memory`), before any
/// work.
pub fn check_photon_memory(total: usize, max_memory: u64) -> Result<()> {
    // 24 bytes a photon plus the tree's node per 8–16 photons; stored counts overshoot by a few.
    let needed_mb = (total as u64).saturating_mul(25) / 1_000_000;
    if needed_mb > max_memory {
        return Err(Error::InvalidSettings(format!(
            "{total} photons need about {needed_mb} MB, more than --max-memory {max_memory} MB: store fewer photons or raise the cap"
        )));
    }
    Ok(())
}

/// The worker threads `--threads` asks for (all cores by default).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    if threads == Some(0) || threads.is_some_and(|t| t > 1024) {
        return Err(Error::InvalidSettings("--threads must be between 1 and 1024".into()));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::InvalidSettings(format!("cannot start worker threads: {e}")))
}

/// Which integrator renders a file in physical units and why, when its user chose none: the one
/// the file names, or `vcm` where it names none; and, where the file names `path` but its mirrors
/// or glass are lit by point, spot or sun lights, that a path tracer cannot show their caustics.
/// `None` where the user chose, or the file is not in physical units.
pub fn integrator_note(given: &GivenOptions, hints: &RenderHints, scene: &crate::scene::Scene) -> Option<String> {
    if given.model_or_integrator || !(hints.physical || hints.scattering_media) {
        return None;
    }
    let Some(named) = hints.integrator else {
        return Some(
            "integrator vcm: the file names none, and vcm renders the caustics of point, spot and sun lights \
             through glass and mirrors as well as all a path tracer renders (--integrator chooses another)"
                .into(),
        );
    };
    let kind = RenderConfig::for_scene(hints).integrator?;
    let mut note = format!("integrator {}: the file names it", kind.name());
    let delta_lights = scene.lights().iter().any(|l| {
        matches!(
            l,
            crate::light::Light::Point { .. }
                | crate::light::Light::Spot { .. }
                | crate::light::Light::Directional { .. }
                | crate::light::Light::Sun { .. }
        )
    });
    if named == IntegratorHint::Path && delta_lights && !crate::light::aim::caustic_targets(scene).is_empty() {
        note.push_str(
            "; a path tracer cannot show the caustics its mirrors and glass cast from point, spot or sun \
             lights: --integrator vcm shows them",
        );
    }
    Some(note)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn depths(config: &RenderConfig) -> u32 {
        match config.integrator().unwrap() {
            Integrator::Whitted(o) => o.whitted.max_depth,
            Integrator::Path(s) => s.max_depth,
            Integrator::Ppm(s) => s.max_depth,
            Integrator::Gi(s) => s.max_depth,
            Integrator::Lt(s) => s.max_depth,
            Integrator::Vcm(s) => s.max_depth,
        }
    }

    /// `--depth` 8 lets light scatter at 9 surfaces in every physical integrator: photons make
    /// 8 bounces, the path tracer's own limit (surfaces) is 9. pbrt's `maxdepth` 9 (scattering
    /// events) is `--depth` 8 whatever the integrator; whitted keeps its 5 by default.
    #[test]
    fn depth_is_bounces_after_the_first_surface_everywhere() {
        let with = |kind, depth| RenderConfig {
            integrator: Some(kind),
            depth,
            ..RenderConfig::default()
        };
        assert_eq!(depths(&with(IntegratorKind::Path, Some(8))), 9);
        assert_eq!(depths(&with(IntegratorKind::Path, Some(0))), 1);
        assert_eq!(depths(&with(IntegratorKind::Path, None)), 65);
        for kind in [
            IntegratorKind::Ppm,
            IntegratorKind::Gi,
            IntegratorKind::Lt,
            IntegratorKind::Vcm,
        ] {
            assert_eq!(depths(&with(kind, Some(8))), 8);
            assert_eq!(depths(&with(kind, None)), 64);
        }
        assert_eq!(depths(&with(IntegratorKind::Whitted, None)), 5);
        assert!(with(IntegratorKind::Ppm, Some(1025)).integrator().is_err());
        assert!(with(IntegratorKind::Path, Some(1025)).integrator().is_err());
        assert!(with(IntegratorKind::Path, Some(1024)).integrator().is_ok());
        for (hint, kind) in [
            (IntegratorHint::Path, IntegratorKind::Path),
            (IntegratorHint::Ppm, IntegratorKind::Ppm),
            (IntegratorHint::LightTracer, IntegratorKind::Lt),
            (IntegratorHint::Bidirectional, IntegratorKind::Vcm),
        ] {
            let hints = |n| RenderHints {
                physical: true,
                integrator: Some(hint),
                max_depth: Some(n),
                ..RenderHints::default()
            };
            let config = RenderConfig::for_scene(&hints(9));
            assert_eq!((config.integrator, config.depth), (Some(kind), Some(8)));
            assert_eq!(RenderConfig::for_scene(&hints(1)).depth, Some(0), "direct light only");
            assert_eq!(RenderConfig::for_scene(&hints(0)).depth, Some(0));
        }
    }

    fn first_radius(config: &RenderConfig) -> InitialRadius {
        match config.integrator().unwrap() {
            Integrator::Ppm(s) => s.initial_radius,
            Integrator::Gi(s) => s.caustic_radius,
            Integrator::Vcm(s) => s.initial_radius,
            other => panic!("{other:?} has no radius"),
        }
    }

    /// Without `--footprint` each integrator starts from its own radius (`vcm` merges from 3
    /// pixels, 2 where its pilot balanced the count; `ppm` and `gi` gather from 2);
    /// `--footprint` sets it for all, `--radius` wins.
    #[test]
    fn the_first_radius_is_each_integrators_own_unless_given() {
        let with = |kind, footprint, radius| RenderConfig {
            integrator: Some(kind),
            footprint,
            radius,
            ..RenderConfig::default()
        };
        use InitialRadius::{Pixels, World};
        for (kind, own) in [
            (IntegratorKind::Ppm, 2.0),
            (IntegratorKind::Gi, 2.0),
            (IntegratorKind::Vcm, 3.0),
        ] {
            assert_eq!(first_radius(&with(kind, None, None)), Pixels(own));
            assert_eq!(first_radius(&with(kind, Some(1.5), None)), Pixels(1.5));
            assert_eq!(first_radius(&with(kind, Some(1.5), Some(0.1))), World(0.1));
            assert!(with(kind, Some(0.0), None).integrator().is_err());
        }
        // vcm's balanced scenes merge from 2 pixels unless a radius is given.
        let balanced = |footprint, radius| match with(IntegratorKind::Vcm, footprint, radius).integrator().unwrap() {
            Integrator::Vcm(s) => s.balanced_footprint,
            other => panic!("{other:?}"),
        };
        assert_eq!(balanced(None, None), Some(2.0));
        assert_eq!(balanced(Some(3.0), None), None);
        assert_eq!(balanced(None, Some(0.1)), None);
        assert_eq!(
            with(IntegratorKind::Lt, Some(3.0), None).ignored_by_lt(),
            ["--footprint"]
        );
        assert!(with(IntegratorKind::Lt, None, None).ignored_by_lt().is_empty());
    }

    /// The precedence both front ends share: what the user gave wins; the scene fills the rest,
    /// its depth and passes only for a physical integrator, its passes not under a time limit,
    /// its height not when only a width was given.
    #[test]
    fn options_given_win_over_the_scenes_and_the_scene_fills_the_rest() {
        let hints = RenderHints {
            width: Some(40),
            height: Some(30),
            physical: true,
            max_depth: Some(5),
            samples: Some(3),
            photons_per_pass: Some(4000),
            radius: Some(0.5),
            ..RenderHints::default()
        };
        let asked = RenderConfig {
            width: 24,
            height: Some(10),
            depth: Some(2),
            photons: 99,
            radius: Some(0.1),
            passes: Some("7".into()),
            time: Some(1.5),
            model: Some(Model::Course),
            ..RenderConfig::default()
        };
        let none = asked.clone().over_scene(&GivenOptions::default(), &hints);
        assert_eq!((none.width, none.height, none.depth), (40, Some(30), Some(4)));
        assert_eq!(
            (none.model, none.integrator),
            (Some(Model::Physical), Some(IntegratorKind::Vcm)),
            "a file in physical units that names no integrator renders with vcm"
        );
        assert_eq!(
            (none.photons, none.radius, none.passes.as_deref()),
            (4000, Some(0.5), Some("3"))
        );
        let all = GivenOptions {
            model_or_integrator: true,
            width: true,
            height: true,
            depth: true,
            photons: true,
            radius: true,
            passes: true,
            time: true,
        };
        assert_eq!(asked.clone().over_scene(&all, &hints), asked);
        let width = asked.clone().over_scene(
            &GivenOptions {
                width: true,
                ..GivenOptions::default()
            },
            &hints,
        );
        assert_eq!((width.width, width.height), (24, None), "the height follows the camera");
        let course = asked.clone().over_scene(
            &GivenOptions {
                model_or_integrator: true,
                ..GivenOptions::default()
            },
            &hints,
        );
        assert_eq!(
            (course.model, course.depth, course.passes),
            (Some(Model::Course), None, None)
        );
        assert_eq!(course.photons, 4000, "photons are the scene's for the course model too");
        let timed = asked.over_scene(
            &GivenOptions {
                time: true,
                ..GivenOptions::default()
            },
            &hints,
        );
        assert_eq!((timed.passes, timed.time), (None, Some(1.5)));
    }
}
