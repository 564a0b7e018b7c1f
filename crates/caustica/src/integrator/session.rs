//! A render session: one integrator over one scene at one image size, run pass by pass into an
//! [`Accumulator`] that hands out the current image and the partial sums, and merges the sums
//! of other runs of the same settings.
//!
//! The course model's Whitted renderer makes its whole image in one pass (pass 0), its caustic
//! photons traced first; the physical integrators render independent passes that converge.

use super::gi::Gi;
use super::lt::LightTracer;
use super::partial::Accumulator;
use super::path::PathTracer;
use super::ppm::Ppm;
use super::vcm::Vcm;
use super::whitted;
use super::{image_size, ImageSettings, Integrator, Progressive};
use crate::error::{Error, Result};
use crate::film::Film;
use crate::photon::{PhotonMap, PhotonSettings};
use crate::progress::Control;
use crate::scene::Scene;
use std::time::Instant;

/// Largest image side accepted: beyond it the film alone would not fit in memory.
pub const MAX_SIDE: usize = 32_768;
/// Largest pixel count (1 GiB of float RGB film).
pub const MAX_PIXELS: usize = 1 << 26;
/// Passes run when neither a count nor a time is given.
pub const DEFAULT_PASSES: u64 = 64;

/// What to render.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderOptions {
    /// The integrator and its settings.
    pub integrator: Integrator,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels (default: the width over the camera's aspect ratio).
    pub height: Option<usize>,
    /// Seed of all random streams.
    pub seed: u64,
    /// What identifies the scene (its content and how it was read) in the run's fingerprint, so
    /// that only parts of one run are merged.
    pub scene_id: String,
}

/// Which passes to run: `first..end`, or from `first` until `time_limit` seconds have passed
/// (at least one pass).
#[derive(Clone, Debug, PartialEq)]
pub struct PassPlan {
    /// The first pass.
    pub first: u64,
    /// One past the last pass; `None` runs until the time limit.
    pub end: Option<u64>,
    /// Seconds after which no new pass starts.
    pub time_limit: Option<f64>,
}

impl Default for PassPlan {
    fn default() -> Self {
        PassPlan {
            first: 0,
            end: Some(DEFAULT_PASSES),
            time_limit: None,
        }
    }
}

impl PassPlan {
    /// The plan of `passes` — `N` (passes 0..N) or `A..B` — and `time` in seconds; with
    /// neither, 64 passes.
    pub fn new(passes: Option<&str>, time: Option<f64>) -> Result<PassPlan> {
        if time.is_some_and(|t| !(t > 0.0 && t.is_finite())) {
            return Err(Error::InvalidSettings(
                "--time must be a positive number of seconds".into(),
            ));
        }
        let bad = |s: &str| {
            Error::InvalidSettings(format!(
                "--passes {s}: expected a count N (passes 0..N) or a range A..B with A < B"
            ))
        };
        let Some(spec) = passes else {
            return Ok(PassPlan {
                first: 0,
                end: if time.is_some() { None } else { Some(DEFAULT_PASSES) },
                time_limit: time,
            });
        };
        let (first, end) = match spec.split_once("..") {
            Some((a, b)) => (
                a.trim().parse::<u64>().map_err(|_| bad(spec))?,
                b.trim().parse::<u64>().map_err(|_| bad(spec))?,
            ),
            None => (0, spec.trim().parse::<u64>().map_err(|_| bad(spec))?),
        };
        // Pass indices feed 32 bits of the random streams' index.
        if first >= end || end > u32::MAX as u64 {
            return Err(bad(spec));
        }
        Ok(PassPlan {
            first,
            end: Some(end),
            time_limit: time,
        })
    }
}

/// The smallest share of a full pass worth a pass of its own at the end of a time limit.
const MIN_SHARE: f64 = 1.0 / 64.0;

impl PassPlan {
    /// Whether pass `pass` is past the plan's end.
    pub fn past_end(&self, pass: u64) -> bool {
        self.end.is_some_and(|end| pass >= end)
    }

    /// Whether pass `pass`, of relative cost `next` (1 for a full pass, see
    /// [`Progressive::pass_cost`]), is to start, passes of total cost `done` having been
    /// rendered in `elapsed` seconds: not past the end, and (once a pass is done) expected to
    /// finish less than half the pass past the time limit, so a run ends within half a pass of
    /// it either way.
    pub fn admits(&self, pass: u64, done: f64, elapsed: f64, next: f64) -> bool {
        let past_end = self.past_end(pass);
        let out_of_time = self
            .time_limit
            .is_some_and(|limit| done > 0.0 && elapsed + 0.5 * next * elapsed / done >= limit);
        !past_end && !out_of_time
    }
}

/// The size of a run's next pass ([`RenderSession::next_pass`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Resize {
    /// Its own.
    Own,
    /// This share of a full pass, the run's last.
    To(f64),
    /// None: the time is up.
    Stop,
}

impl Resize {
    /// The size of a pass of relative cost `own`, followed by one of cost `next` (0: none), when
    /// `share` of a full pass fits in the time left (`None`: passes keep their size).
    fn choose(share: Option<f64>, own: f64, next: f64, first: bool) -> Resize {
        match share {
            None => Resize::Own,
            Some(share) if share >= own + next => Resize::Own,
            Some(share) if share >= MIN_SHARE => Resize::To(share),
            // A run renders at least one pass.
            Some(_) if first => Resize::To(MIN_SHARE),
            Some(_) => Resize::Stop,
        }
    }
}

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct RunSummary {
    /// Whether it ran to its end (false when cancelled).
    pub complete: bool,
    /// Seconds spent tracing the course model's caustic photons.
    pub photon_seconds: f64,
    /// Seconds spent rendering passes.
    pub render_seconds: f64,
}

/// Refuses image sizes that cannot be rendered, before any memory is committed.
pub fn check_image_size(width: usize, height: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::InvalidSettings(
            "the image needs a width and height of at least 1 pixel".into(),
        ));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_PIXELS {
        return Err(Error::InvalidSettings(format!(
            "{width}×{height} is too large: at most {MAX_SIDE} pixels a side and {MAX_PIXELS} pixels in all"
        )));
    }
    Ok(())
}

/// One integrator rendering one scene.
pub struct RenderSession<'a> {
    scene: &'a Scene,
    integrator: Integrator,
    seed: u64,
    /// The physical integrators' sums; for the course model only its size and fingerprint.
    accumulator: Accumulator,
    /// The course model's image (kept as it is: one pass needs no sums).
    whitted_image: Option<Film>,
    passes: Option<Box<dyn Progressive + 'a>>,
    /// Whether the integrator's work before its first pass is done ([`Progressive::prepare`]).
    prepared: bool,
    caustic_map: Option<PhotonMap>,
    photon_seconds: f64,
}

impl<'a> RenderSession<'a> {
    /// A session for `scene`; the options are checked here.
    pub fn new(scene: &'a Scene, options: RenderOptions) -> Result<RenderSession<'a>> {
        options.integrator.validate()?;
        if scene.scatters() && matches!(options.integrator, Integrator::Whitted(_)) {
            return Err(crate::error::Error::InvalidSettings(
                "the scene has a medium that scatters light, which --integrator vcm, path, lt, ppm and gi render (not the course model)".into(),
            ));
        }
        let (width, height) = image_size(scene.camera(), options.width, options.height);
        check_image_size(width, height)?;
        let seed = options.seed;
        let passes: Option<Box<dyn Progressive + 'a>> = match &options.integrator {
            Integrator::Whitted(_) => None,
            Integrator::Path(s) => Some(Box::new(PathTracer::new(scene, s.clone(), width, height, seed))),
            Integrator::Ppm(s) => Some(Box::new(Ppm::new(scene, s.clone(), width, height, seed))),
            Integrator::Gi(s) => Some(Box::new(Gi::new(scene, s.clone(), width, height, seed))),
            Integrator::Lt(s) => Some(Box::new(LightTracer::new(scene, s.clone(), width, height, seed))),
            Integrator::Vcm(s) => Some(Box::new(Vcm::new(scene, s.clone(), width, height, seed))),
        };
        let fingerprint = format!(
            "scene {} size {width}x{height} seed {seed} {:?}",
            options.scene_id, options.integrator
        );
        Ok(RenderSession {
            scene,
            integrator: options.integrator,
            seed,
            accumulator: if passes.is_some() {
                Accumulator::new(width, height, fingerprint)
            } else {
                Accumulator::without_sums(width, height, fingerprint)
            },
            whitted_image: None,
            passes,
            prepared: false,
            caustic_map: None,
            photon_seconds: 0.0,
        })
    }

    /// The image size.
    pub fn size(&self) -> (usize, usize) {
        (self.accumulator.width, self.accumulator.height)
    }

    /// Seconds spent tracing the course model's caustic photons so far.
    pub fn photon_seconds(&self) -> f64 {
        self.photon_seconds
    }

    /// The scene.
    pub fn scene(&self) -> &Scene {
        self.scene
    }

    /// The integrator.
    pub fn integrator(&self) -> &Integrator {
        &self.integrator
    }

    /// Everything that must agree for two runs' sums to be merged.
    pub fn fingerprint(&self) -> &str {
        &self.accumulator.fingerprint
    }

    /// The course model's caustic photon map, once traced (`None` when no photons are stored).
    pub fn caustic_map(&self) -> Option<&PhotonMap> {
        self.caustic_map.as_ref()
    }

    /// Traces the course model's caustic photons, once (a "photons" phase); nothing for the
    /// other integrators or when no photons are asked for.
    pub fn trace_photons(&mut self, control: Control) {
        let Integrator::Whitted(options) = &self.integrator else {
            return;
        };
        if self.caustic_map.is_some() || options.photons.target_stored == 0 {
            return;
        }
        let start = Instant::now();
        // Photons follow the camera rays' rule inside glass.
        let photons = PhotonSettings {
            internal_reflection: options.whitted.internal_reflection,
            ..options.photons.clone()
        };
        self.caustic_map = Some(PhotonMap::trace(self.scene, &photons, &options.estimate, control));
        self.photon_seconds += start.elapsed().as_secs_f64();
    }

    /// Renders pass `pass` and adds it to the sums; returns whether it was completed. An
    /// interrupted pass of a progressive integrator is dropped; the course model's single pass
    /// keeps the tiles it finished.
    pub fn render_pass(&mut self, pass: u64, control: Control) -> bool {
        self.render_sized_pass(pass, None, control)
    }

    /// Runs the integrator's work before its first pass (vcm's pilots), once; `false` when
    /// cancelled (it runs again on the next call). Passes run it themselves when it has not
    /// been run; a caller that times its run calls it within the time.
    pub fn prepare(&mut self, control: Control) -> bool {
        if !self.prepared {
            if let Some(passes) = &mut self.passes {
                self.prepared = passes.prepare(control);
            } else {
                self.prepared = true;
            }
        }
        self.prepared
    }

    /// [`RenderSession::render_pass`], at `share` of a full pass when given.
    pub fn render_sized_pass(&mut self, pass: u64, share: Option<f64>, control: Control) -> bool {
        if self.passes.is_some() && !self.prepare(control) {
            return false;
        }
        if let Some(passes) = &self.passes {
            let (pixels, weight) = match share {
                Some(share) => (passes.render_share(pass, share, control), share),
                None => (passes.render_pass(pass, control), passes.pass_weight(pass)),
            };
            return match pixels {
                Some(pixels) => {
                    self.accumulator.add(pass, &pixels, weight);
                    true
                }
                None => false,
            };
        }
        let Integrator::Whitted(options) = &self.integrator else {
            return false;
        };
        let options = options.clone();
        self.trace_photons(control);
        let (width, height) = self.size();
        let image = ImageSettings {
            width,
            height,
            aa: options.aa,
            seed: self.seed,
        };
        let caustics = self
            .caustic_map
            .as_ref()
            .filter(|m| !m.is_empty())
            .map(|m| (m, &options.estimate));
        let (film, complete) = whitted::render(self.scene, caustics, &options.whitted, &image, control);
        self.whitted_image = Some(film);
        complete
    }

    /// Runs the passes of `plan` (the course model: its one pass), calling `after_pass` after
    /// each; stops early when cancelled. Progress: "passes" counts passes, or tenths of a
    /// second under a time limit.
    pub fn run(
        &mut self,
        plan: &PassPlan,
        control: Control,
        mut after_pass: impl FnMut(&RenderSession) -> Result<()>,
    ) -> Result<RunSummary> {
        if self.passes.is_none() {
            self.trace_photons(control);
            let start = Instant::now();
            let complete = self.render_pass(0, control) && !control.cancelled();
            let render_seconds = start.elapsed().as_secs_f64();
            after_pass(self)?;
            return Ok(RunSummary {
                complete: complete && !control.cancelled(),
                photon_seconds: self.photon_seconds,
                render_seconds,
            });
        }
        let start = Instant::now();
        let (bar_total, by_time) = match (plan.end, plan.time_limit) {
            (Some(end), None) => (end - plan.first, false),
            (_, Some(t)) => ((t * 10.0).ceil() as u64, true),
            (None, None) => (DEFAULT_PASSES, false),
        };
        // The pilots count in the time limit (the passes' sizes leave room for them).
        self.prepare(control);
        control.progress.start("passes", bar_total);
        let mut reported = 0u64;
        let mut pass = plan.first;
        // The cost of this run's passes, in full passes.
        let mut cost_done = 0.0;
        loop {
            let next = self.pass_cost(pass);
            if control.cancelled() {
                break;
            }
            let share = match self.next_pass(plan, pass, cost_done, start.elapsed().as_secs_f64()) {
                Resize::Stop => break,
                Resize::To(share) => Some(share),
                Resize::Own => None,
            };
            if !self.render_sized_pass(pass, share, control) {
                break;
            }
            cost_done += share.unwrap_or(next);
            pass += 1;
            let done = if by_time {
                ((start.elapsed().as_secs_f64() * 10.0) as u64).min(bar_total)
            } else {
                self.accumulator.pass_count()
            };
            control.progress.advance(done.saturating_sub(reported));
            reported = reported.max(done);
            after_pass(self)?;
            if share.is_some() {
                break;
            }
        }
        control.progress.finish();
        Ok(RunSummary {
            complete: !control.cancelled(),
            photon_seconds: 0.0,
            render_seconds: start.elapsed().as_secs_f64(),
        })
    }

    /// The size of pass `pass` of `plan`, `elapsed` seconds into a run whose passes so far cost
    /// `cost_done` full passes: [`Resize::Stop`] past the plan's end or its time (a pass of its
    /// own size starts only if it is expected to end less than half a pass past the limit).
    pub fn next_pass(&self, plan: &PassPlan, pass: u64, cost_done: f64, elapsed: f64) -> Resize {
        if plan.past_end(pass) {
            return Resize::Stop;
        }
        match self.resize(plan, pass, elapsed, cost_done == 0.0) {
            Resize::Own if !plan.admits(pass, cost_done, elapsed, self.pass_cost(pass)) => Resize::Stop,
            size => size,
        }
    }

    /// Whether pass `pass` of `plan`, `elapsed` seconds into the run (`first`: its first pass),
    /// keeps its own size. Under a time limit, an integrator that can resize its passes makes
    /// the last one fill the time left: it is cut when it would not end in time, and stretched
    /// when the next pass would not (so no time is left idle and none overrun by more than the
    /// estimate's error).
    fn resize(&self, plan: &PassPlan, pass: u64, elapsed: f64, first: bool) -> Resize {
        let (Some(limit), Some(passes)) = (plan.time_limit, &self.passes) else {
            return Resize::Own;
        };
        let next = if plan.past_end(pass + 1) {
            0.0
        } else {
            passes.pass_cost(pass + 1)
        };
        Resize::choose(
            passes.share_within(pass, limit - elapsed),
            passes.pass_cost(pass),
            next,
            first,
        )
    }

    /// The mean of the passes so far (the course model: its image, black before it is made).
    pub fn image(&self) -> Film {
        match &self.whitted_image {
            Some(film) => film.clone(),
            None if self.passes.is_none() => Film::new(self.accumulator.width, self.accumulator.height),
            None => self.accumulator.film(),
        }
    }

    /// Light paths a full pass traces, when the integrator chose the number
    /// ([`Progressive::chosen_paths_per_pass`]).
    pub fn chosen_paths_per_pass(&self) -> Option<u64> {
        self.passes.as_ref().and_then(|p| p.chosen_paths_per_pass())
    }

    /// The time pass `pass` takes relative to a full pass ([`Progressive::pass_cost`]).
    pub fn pass_cost(&self, pass: u64) -> f64 {
        self.passes.as_ref().map_or(1.0, |p| p.pass_cost(pass))
    }

    /// Passes rendered so far.
    pub fn pass_count(&self) -> u64 {
        match self.passes {
            Some(_) => self.accumulator.pass_count(),
            None => u64::from(self.whitted_image.is_some()),
        }
    }

    /// The sums of the passes so far (empty for the course model, which keeps no sums).
    pub fn accumulator(&self) -> &Accumulator {
        &self.accumulator
    }

    /// Adds the sums of another run of the same settings (refused otherwise, or when they share
    /// a pass).
    pub fn merge(&mut self, part: &Accumulator) -> Result<()> {
        self.accumulator.merge(part)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plan_admits_passes_up_to_its_end_and_within_half_a_pass_of_its_time() {
        let counted = PassPlan::new(Some("2..4"), None).unwrap();
        assert!(counted.admits(2, 0.0, 1e9, 1.0) && counted.admits(3, 1.0, 0.0, 1.0));
        assert!(!counted.admits(4, 2.0, 0.0, 1.0));
        let timed = PassPlan::new(None, Some(1.0)).unwrap();
        // The first pass always runs; later ones only within the time.
        assert!(timed.admits(0, 0.0, 5.0, 1.0) && timed.admits(7, 7.0, 0.5, 1.0));
        assert!(!timed.admits(1, 1.0, 1.0, 1.0));
        // 0.3 s a pass: a third at 0.6 s would end at 0.9 s; after 0.7 s in one pass, a second
        // would end 0.4 s past the limit, more than half a pass.
        assert!(timed.admits(2, 2.0, 0.6, 1.0) && !timed.admits(1, 1.0, 0.7, 1.0));
        // A half pass in 0.4 s: a full one would take 0.8 s and end 0.2 s past the limit, less
        // than half of it, so it runs; after a half pass in 0.55 s it would end 0.65 s past.
        assert!(timed.admits(1, 0.5, 0.4, 1.0) && !timed.admits(1, 0.5, 0.55, 1.0));
        let both = PassPlan::new(Some("3"), Some(10.0)).unwrap();
        assert!(!both.admits(3, 3.0, 0.0, 1.0) && !both.admits(1, 1.0, 10.0, 1.0));
        assert!(both.past_end(3) && !both.past_end(2));
    }

    #[test]
    fn the_last_pass_of_a_time_limit_fills_the_time_left() {
        // Room for this half pass and the next full one: its own size.
        assert_eq!(Resize::choose(Some(1.6), 0.5, 1.0, true), Resize::Own);
        // Room for more than this half pass but not the next: it takes all the time left.
        assert_eq!(Resize::choose(Some(0.73), 0.5, 1.0, true), Resize::To(0.73));
        // No room for this pass: it is cut.
        assert_eq!(Resize::choose(Some(0.3), 1.0, 1.0, false), Resize::To(0.3));
        // The plan's last pass (no next) keeps its size when it fits, and is not stretched.
        assert_eq!(Resize::choose(Some(5.0), 1.0, 0.0, false), Resize::Own);
        assert_eq!(Resize::choose(Some(0.6), 1.0, 0.0, false), Resize::To(0.6));
        // Too little time for a useful pass: the run ends, unless it has rendered none.
        assert_eq!(Resize::choose(Some(0.001), 1.0, 1.0, false), Resize::Stop);
        assert_eq!(Resize::choose(Some(0.0), 0.5, 1.0, true), Resize::To(MIN_SHARE));
        // Integrators that do not resize passes.
        assert_eq!(Resize::choose(None, 1.0, 1.0, false), Resize::Own);
    }
}
