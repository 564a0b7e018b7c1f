//! What a run did, for every front end alike: the command line's `--json` prints it (with its
//! own fields: the files written, the preview), Python's `Progressive.report()` returns it.

use super::{Integrator, RenderSession, RunSummary};
use serde::Serialize;

/// A run's report.
#[derive(Clone, Debug, Serialize)]
pub struct RunReport {
    /// The integrator's name (`whitted` for the course model).
    pub integrator: &'static str,
    /// `physical` or `course`.
    pub model: &'static str,
    /// Image width in pixels.
    pub width: usize,
    /// Image height in pixels.
    pub height: usize,
    /// How an image of another aspect than the camera's is cropped or extended.
    pub camera_fit: Option<String>,
    /// Whether the run reached its end (false when interrupted).
    pub complete: bool,
    /// Where the time went.
    pub seconds: RunSeconds,
    /// The passes (physical model) or the photons and samples (course model).
    #[serde(flatten)]
    pub detail: RunDetail,
}

/// Seconds spent, by phase.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RunSeconds {
    /// Reading the files.
    pub parse: f64,
    /// Building the scene (BVHs, lights, textures).
    pub build: f64,
    /// Tracing the course model's caustic photons.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub photons: Option<f64>,
    /// Rendering (the physical model's pilots and passes).
    pub render: f64,
    /// The whole run, as its caller measured it (reading and writing included).
    pub total: f64,
}

/// The part of a report that differs between the models.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum RunDetail {
    /// A physical integrator's passes.
    Passes {
        /// Passes held (the merged parts' included).
        passes: u64,
        /// Their index ranges, `A..B` comma separated.
        pass_ranges: String,
        /// Photons or light subpaths a full pass traces (0 for `path`).
        photons_per_pass: u64,
        /// Passes resized to a time limit count by their share of a full pass.
        full_passes: f64,
        /// Photons or light subpaths traced in all.
        photons: u64,
    },
    /// The course model's one pass.
    Course {
        /// N² for N×N supersampling.
        samples_per_pixel: u32,
        /// Caustic photons stored.
        photons_stored: u64,
        /// Photons emitted.
        photons_emitted: u64,
        /// Emitted photons that stored any.
        photons_landed: u64,
        /// The share of the emitted photons that stored any.
        photons_useful_fraction: f64,
        /// Whether emission stopped at its cap before the budget was stored.
        photons_cap_reached: bool,
        /// Why no photon could make a caustic, when none could.
        photons_none_reason: Option<&'static str>,
    },
}

impl RenderSession<'_> {
    /// The report of a run that ended with `summary`, its scene read in `parse` and built in
    /// `build` seconds, `total` seconds in all as the caller measured.
    pub fn report(&self, summary: &RunSummary, (parse, build): (f64, f64), total: f64) -> RunReport {
        let (width, height) = self.size();
        let integrator = self.integrator();
        let detail = match integrator {
            Integrator::Whitted(options) => {
                let stats = self.caustic_map().map(|m| &m.stats);
                RunDetail::Course {
                    samples_per_pixel: options.aa * options.aa,
                    photons_stored: stats.map_or(0, |s| s.stored),
                    photons_emitted: stats.map_or(0, |s| s.emitted),
                    photons_landed: stats.map_or(0, |s| s.landed),
                    photons_useful_fraction: stats.map_or(0.0, |s| s.useful_fraction()),
                    photons_cap_reached: stats.is_some_and(|s| s.cap_reached),
                    photons_none_reason: stats.and_then(|s| s.none).map(|r| r.name()),
                }
            }
            _ => {
                let accumulator = self.accumulator();
                let photons_per_pass = self.photons_per_pass();
                let ranges: Vec<String> = accumulator.passes.iter().map(|(a, b)| format!("{a}..{b}")).collect();
                RunDetail::Passes {
                    passes: self.pass_count(),
                    pass_ranges: ranges.join(","),
                    photons_per_pass,
                    full_passes: accumulator.weight,
                    photons: (accumulator.weight * photons_per_pass as f64).round() as u64,
                }
            }
        };
        let course = matches!(integrator, Integrator::Whitted(_));
        RunReport {
            integrator: integrator.name(),
            model: if course { "course" } else { "physical" },
            width,
            height,
            camera_fit: self.scene().camera().fit_note(width, height),
            complete: summary.complete,
            seconds: RunSeconds {
                parse,
                build,
                photons: course.then_some(summary.photon_seconds),
                render: summary.render_seconds,
                total,
            },
            detail,
        }
    }

    /// Photons or light subpaths a full pass traces: the settings', or what the integrator
    /// chose (vcm's balance); 0 for the integrators that trace none.
    pub fn photons_per_pass(&self) -> u64 {
        let (width, height) = self.size();
        match self.integrator() {
            Integrator::Ppm(s) => s.photons_per_pass,
            Integrator::Gi(s) => s.photons_per_pass,
            Integrator::Lt(s) => s.photons_per_pass,
            Integrator::Vcm(s) => s
                .light_paths_per_pass
                .or_else(|| self.chosen_paths_per_pass())
                .unwrap_or_else(|| super::vcm::default_light_paths(width, height)),
            _ => 0,
        }
    }
}
