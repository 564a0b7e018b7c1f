//! The course model's photon pass: a budget of stored caustic photons, shared between the lights
//! so that every stored photon carries about the same power (Jensen's rule), each light emitting
//! until its share is stored or the emission cap stops it.
//!
//! A pilot first emits a few thousand photons from each light and measures the caustic power
//! it delivers per photon emitted, falloff, aiming and every mirror and glass on the way
//! included; the budget is shared in proportion to it. (Shared by emitted power instead, a
//! directional light aimed through small targets and point lights with the course's falloff can
//! differ 2,000-fold in the power of their stored photons, and the strong ones show as dots.)
//! The pilot also finds the scenes where no caustic can form, and the pass then stops at once
//! and says why ([`NoCaustics`]).
//!
//! Each light's photons are the shortest prefix of its photon paths (by index) that stores its
//! share exactly, so the map does not depend on the thread count.

use super::trace::{trace_batch, trace_path, CourseModel, BATCH};
use super::Photon;
use crate::light::aim::{caustic_targets, Aim};
use crate::light::emission::Emitters;
use crate::light::Light;
use crate::math::luminance;
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::Scene;
use crate::spectrum::Wavelengths;
use rayon::prelude::*;
use std::time::Instant;

/// How photons are shot and stored.
#[derive(Clone, Debug, PartialEq)]
pub struct PhotonSettings {
    /// Photons to store, shared between lights by the power they deliver unless `per_light` is
    /// set.
    pub target_stored: usize,
    /// Stop emitting after this many photons in all, stored or not.
    pub max_emitted: u64,
    /// Aim photons at the bounding spheres of reflective and transmissive objects.
    pub aim: bool,
    /// Seed of the photon streams.
    pub seed: u64,
    /// Longest specular chain followed.
    pub max_bounces: u32,
    /// Store every photon at its first surface instead (a map of direct light, for checks).
    pub first_hit: bool,
    /// Photons to store for each light, overriding the shared budget.
    pub per_light: Option<Vec<usize>>,
    /// Photons inside glass reflect by its `reflective` colour too, not only by total internal
    /// reflection (keep equal to the Whitted renderer's setting).
    pub internal_reflection: bool,
}

impl Default for PhotonSettings {
    fn default() -> Self {
        PhotonSettings {
            target_stored: 200_000,
            max_emitted: 0,
            aim: true,
            seed: 0,
            max_bounces: 32,
            first_hit: false,
            per_light: None,
            internal_reflection: false,
        }
    }
}

impl PhotonSettings {
    /// The emission cap in force: the set one, or 200 photons per photon to store.
    pub fn emission_cap(&self) -> u64 {
        if self.max_emitted > 0 {
            self.max_emitted
        } else {
            (self.target_stored as u64).saturating_mul(200).max(1_000_000)
        }
    }
}

/// Why a photon pass stored nothing, when it could tell before or soon after starting.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NoCaustics {
    /// No point, spot, directional or sun light sends photons.
    NoLight,
    /// Nothing reflects or refracts (no `reflective` or `transmissive` colour).
    NoSpecular,
    /// Nothing has a `diffuse` or `specular` colour for a caustic to land on.
    NoReceiver,
    /// None of the pilot's photons landed on a diffuse or glossy surface after a mirror or glass
    /// (a lone convex mirror, glass over nothing, …): caustic photons are too rare here.
    NoneLanded {
        /// Photons the pilot emitted.
        emitted: u64,
    },
}

impl NoCaustics {
    /// A short name, for JSON.
    pub fn name(self) -> &'static str {
        match self {
            NoCaustics::NoLight => "no_light",
            NoCaustics::NoSpecular => "no_specular",
            NoCaustics::NoReceiver => "no_receiver",
            NoCaustics::NoneLanded { .. } => "none_landed",
        }
    }
}

impl std::fmt::Display for NoCaustics {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            NoCaustics::NoLight => write!(f, "no point, spot, directional or sun light sends photons"),
            NoCaustics::NoSpecular => write!(f, "no object is a mirror or glass (reflective or transmissive)"),
            NoCaustics::NoReceiver => write!(
                f,
                "no object is diffuse or glossy (diffuse or specular), so a caustic has nowhere to land"
            ),
            NoCaustics::NoneLanded { emitted } => write!(
                f,
                "none of the first {emitted} photons aimed at mirrors and glass landed on a diffuse or glossy surface after them"
            ),
        }
    }
}

/// What the photon pass did, per light and in all.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PhotonStats {
    /// Photons emitted.
    pub emitted: u64,
    /// Photons stored.
    pub stored: u64,
    /// Emitted photons that stored at least one photon (a path can store several: on each
    /// diffuse surface that is also a mirror or glass it meets).
    pub landed: u64,
    /// Whether some light stopped at the emission cap before storing its share.
    pub cap_reached: bool,
    /// Why nothing was traced or stored, when the pass stopped early.
    pub none: Option<NoCaustics>,
    /// Per light: (emitted, stored).
    pub per_light: Vec<(u64, u64)>,
    /// Wall-clock seconds of the pass.
    pub seconds: f64,
}

impl PhotonStats {
    /// The fraction of emitted photons that stored something (at most 1).
    pub fn useful_fraction(&self) -> f64 {
        if self.emitted == 0 {
            0.0
        } else {
            self.landed as f64 / self.emitted as f64
        }
    }

    /// Photons stored per photon that stored any (at least 1).
    pub fn stores_per_landing(&self) -> f64 {
        if self.landed == 0 {
            0.0
        } else {
            self.stored as f64 / self.landed as f64
        }
    }
}

/// The pilot stops once a light has stored this many photons: enough to measure the power it
/// delivers to within some 10%.
const PILOT_STORED: usize = 256;
/// … or once it has emitted this many (at most a quarter of its emission cap).
const PILOT_EMITTED: u64 = 1 << 16;

/// Traces caustic photons from every course light until the budget is stored or the cap is
/// reached, sharing the budget by delivered power (or as `settings.per_light` says).
pub fn trace_photons(scene: &Scene, settings: &PhotonSettings, control: Control) -> (Vec<Photon>, PhotonStats) {
    let start = Instant::now();
    let (numbers, lights): (Vec<usize>, Vec<&Light>) = scene
        .lights()
        .iter()
        .enumerate()
        .filter(|(_, light)| light.is_course_light())
        .unzip();
    let mut stats = PhotonStats {
        per_light: vec![(0, 0); lights.len()],
        ..PhotonStats::default()
    };
    let (emitters, none) = emitters(scene, settings);
    // Each course light's number among the scene's lights, where it emits.
    let emitting: Vec<Option<usize>> = numbers.iter().map(|&n| emitters.emits(n).then_some(n)).collect();
    let none = none.or_else(|| emitting.iter().all(Option::is_none).then_some(NoCaustics::NoLight));
    if let Some(reason) = none {
        stats.none = Some(reason);
        stats.seconds = start.elapsed().as_secs_f64();
        return (Vec::new(), stats);
    }
    let budget = settings.target_stored;
    if budget == 0 {
        return (Vec::new(), stats);
    }
    let cap = settings.emission_cap();
    control.progress.start("photons", budget as u64);
    let tracer = |index: usize| {
        emitting[index].map(|number| Tracer {
            scene,
            emitters: &emitters,
            number,
            model: CourseModel {
                light: lights[index],
                first_hit: settings.first_hit,
                internal_reflection: settings.internal_reflection,
            },
            light_index: index,
            settings,
            control,
        })
    };

    // The pilot: a few photons from each light, kept as the start of its run.
    let active = emitting.iter().flatten().count() as u64;
    let pilot_cap = PILOT_EMITTED.min(cap / (4 * active).max(1)).max(1);
    let mut runs: Vec<LightRun> = (0..lights.len())
        .map(|index| {
            let mut run = LightRun::default();
            if let Some(tracer) = tracer(index) {
                run.extend(&tracer, PILOT_STORED.min(budget), pilot_cap, Cut::AfterPath);
            }
            run
        })
        .collect();
    let delivered: Vec<f64> = runs.iter().map(LightRun::delivered_per_emitted).collect();
    let pilot_emitted: u64 = runs.iter().map(|r| r.emitted).sum();
    if delivered.iter().all(|&d| d <= 0.0) && !control.cancelled() {
        stats.none = Some(NoCaustics::NoneLanded { emitted: pilot_emitted });
        stats.emitted = pilot_emitted;
        stats.cap_reached = pilot_emitted >= cap;
        for (slot, run) in stats.per_light.iter_mut().zip(&runs) {
            slot.0 = run.emitted;
        }
        control.progress.finish();
        stats.seconds = start.elapsed().as_secs_f64();
        return (Vec::new(), stats);
    }
    let shares: Vec<usize> = match &settings.per_light {
        Some(counts) => (0..lights.len())
            .map(|i| {
                if emitting[i].is_some() {
                    counts.get(i).copied().unwrap_or(0)
                } else {
                    0
                }
            })
            .collect(),
        None => share_out(budget, &delivered),
    };

    // The emission cap, shared by the emission each light is expected to need.
    let needed: Vec<f64> = runs
        .iter()
        .zip(&shares)
        .map(|(run, &share)| share as f64 * run.emitted.max(1) as f64 / run.photons.len().max(1) as f64)
        .collect();
    let total_needed: f64 = needed.iter().sum::<f64>().max(1.0);
    for (index, run) in runs.iter_mut().enumerate() {
        let share = shares[index];
        let light_cap = ((cap as f64 * needed[index] / total_needed).ceil() as u64).max(run.emitted);
        if share <= run.photons.len() {
            run.cut_to(share);
        } else if let Some(tracer) = tracer(index) {
            run.landings.clear();
            run.extend(&tracer, share, light_cap, Cut::Exactly);
        }
        stats.cap_reached |= run.photons.len() < share && run.emitted >= light_cap;
    }
    control.progress.finish();

    let mut photons = Vec::with_capacity(runs.iter().map(|r| r.photons.len()).sum());
    for (index, run) in runs.into_iter().enumerate() {
        stats.emitted += run.emitted;
        stats.stored += run.photons.len() as u64;
        stats.landed += run.landed;
        stats.per_light[index] = (run.emitted, run.photons.len() as u64);
        let scale = if run.emitted > 0 { 1.0 / run.emitted as f32 } else { 0.0 };
        let mut light_photons = run.photons;
        light_photons.par_iter_mut().for_each(|p| {
            let power = p.power() * scale;
            p.set_power(power);
        });
        photons.extend(light_photons);
    }
    stats.seconds = start.elapsed().as_secs_f64();
    (photons, stats)
}

/// The lights' emitters, every one aimed at the caustics' sources only (unless the settings
/// say otherwise), or why no photon can make a caustic (known before emitting any).
fn emitters(scene: &Scene, settings: &PhotonSettings) -> (Emitters, Option<NoCaustics>) {
    let targets = caustic_targets(scene);
    let none = if settings.first_hit {
        None
    } else if targets.is_empty() {
        Some(NoCaustics::NoSpecular)
    } else if !scene.objects().any(|(object, _)| scene.object_receives(object)) {
        Some(NoCaustics::NoReceiver)
    } else {
        None
    };
    if none.is_some() {
        return (Emitters::default(), none);
    }
    let aim = if settings.aim && !settings.first_hit {
        Aim::every(&targets, 1.0)
    } else {
        None
    };
    let lights = scene.lights();
    let emitters = Emitters::new(lights.as_slice(), lights.scene_sphere(), aim.clone(), aim);
    (emitters, None)
}

/// `budget` shared in proportion to `weights` by largest remainder: the shares sum to the
/// budget exactly (when any weight is positive), and a zero weight gets nothing.
fn share_out(budget: usize, weights: &[f64]) -> Vec<usize> {
    let total: f64 = weights.iter().filter(|w| w.is_finite() && **w > 0.0).sum();
    if total <= 0.0 {
        return vec![0; weights.len()];
    }
    let exact: Vec<f64> = weights
        .iter()
        .map(|&w| {
            if w.is_finite() && w > 0.0 {
                budget as f64 * w / total
            } else {
                0.0
            }
        })
        .collect();
    let mut shares: Vec<usize> = exact.iter().map(|e| e.floor() as usize).collect();
    let mut order: Vec<usize> = (0..weights.len()).filter(|&i| exact[i] > 0.0).collect();
    order.sort_by(|&a, &b| {
        (exact[b] - exact[b].floor())
            .total_cmp(&(exact[a] - exact[a].floor()))
            .then(a.cmp(&b))
    });
    let left = budget.saturating_sub(shares.iter().sum());
    for &i in order.iter().cycle().take(left) {
        shares[i] += 1;
    }
    shares
}

/// Emits one light's photons.
struct Tracer<'a> {
    scene: &'a Scene,
    emitters: &'a Emitters,
    /// The light's number among the scene's lights.
    number: usize,
    model: CourseModel<'a>,
    light_index: usize,
    settings: &'a PhotonSettings,
    control: Control<'a>,
}

/// Where a run stops once it has stored what it wanted.
#[derive(Clone, Copy, PartialEq, Eq)]
enum Cut {
    /// After the path that reaches the count, keeping all its photons.
    AfterPath,
    /// At exactly the count, dropping the rest of that path's photons.
    Exactly,
}

/// One light's photons so far (powers not yet divided by the photons emitted).
#[derive(Default)]
struct LightRun {
    photons: Vec<Photon>,
    /// Photons emitted: paths `0..emitted` of the light's stream.
    emitted: u64,
    /// Emitted photons that stored at least one.
    landed: u64,
    /// During the pilot: each storing path and the photon count after it, for an exact cut.
    landings: Vec<(u64, usize)>,
}

impl LightRun {
    /// Stored luminance per photon emitted: the caustic power the light delivers.
    fn delivered_per_emitted(&self) -> f64 {
        if self.emitted == 0 {
            return 0.0;
        }
        let sum: f64 = self.photons.iter().map(|p| luminance(p.power()) as f64).sum();
        sum / self.emitted as f64
    }

    /// Keeps exactly the first `count` photons (fewer than it holds) and the paths they need.
    fn cut_to(&mut self, count: usize) {
        if count == 0 {
            *self = LightRun::default();
            return;
        }
        let last = self.landings.partition_point(|&(_, after)| after < count);
        let (path, _) = self.landings[last];
        self.photons.truncate(count);
        self.emitted = path + 1;
        self.landed = last as u64 + 1;
        self.landings.truncate(last + 1);
    }

    /// Emits further photons until `want` are stored or `cap` are emitted.
    fn extend(&mut self, tracer: &Tracer, want: usize, cap: u64, cut: Cut) {
        let Tracer {
            scene,
            emitters,
            number,
            model,
            light_index,
            settings,
            control,
        } = tracer;
        let stream = (*light_index as u64) << 40;
        let keep_landings = cut == Cut::AfterPath;
        let mut reported = self.photons.len().min(want) as u64;
        while self.photons.len() < want && self.emitted < cap && !control.cancelled() {
            // Size the round from the yield so far: enough to finish, never absurdly many batches.
            let needed = if self.photons.is_empty() {
                BATCH * 8
            } else {
                ((want - self.photons.len()) as f64 * self.emitted as f64 / self.photons.len() as f64 * 1.1) as u64
            };
            let batches = needed
                .div_ceil(BATCH)
                .clamp(1, 256)
                .min((cap - self.emitted).div_ceil(BATCH));
            let first_path = self.emitted;
            let results: Vec<(Vec<Photon>, Vec<u32>)> = (0..batches)
                .into_par_iter()
                .map(|b| {
                    let first = first_path + b * BATCH;
                    let count = BATCH.min(cap - first.min(cap));
                    trace_batch(first..first + count, |i, out| {
                        let mut rng = Rng::new(settings.seed, stream | i);
                        if let Some(photon) = emitters.emit_from(scene, *number, &Wavelengths::Rgb, &mut rng) {
                            trace_path(
                                scene,
                                model,
                                photon.ray,
                                photon.throughput,
                                settings.max_bounces,
                                &mut rng,
                                out,
                            );
                        }
                    })
                })
                .collect();
            for (batch, ends) in results {
                let needed = want - self.photons.len();
                // The paths of this batch that are kept: all, or up to the one reaching `want`.
                let last = ends
                    .iter()
                    .position(|&e| e as usize >= needed)
                    .unwrap_or(ends.len() - 1);
                let mut before = 0;
                for (i, &end) in ends[..=last].iter().enumerate() {
                    if end > before {
                        self.landed += 1;
                        if keep_landings {
                            self.landings
                                .push((self.emitted + i as u64, self.photons.len() + end as usize));
                        }
                    }
                    before = end;
                }
                let kept = match cut {
                    Cut::Exactly => (ends[last] as usize).min(needed),
                    Cut::AfterPath => ends[last] as usize,
                };
                self.photons.extend_from_slice(&batch[..kept]);
                self.emitted += last as u64 + 1;
                if self.photons.len() >= want {
                    break;
                }
            }
            let done = self.photons.len().min(want) as u64;
            control.progress.advance(done.saturating_sub(reported));
            reported = done;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_sum_to_the_budget_in_proportion() {
        assert_eq!(share_out(10, &[1.0, 1.0, 1.0]), [4, 3, 3]);
        assert_eq!(share_out(10_000, &[11.7, 455.9, 54.1]).iter().sum::<usize>(), 10_000);
        assert_eq!(share_out(10_000, &[11.7, 455.9, 54.1]), [224, 8739, 1037]);
        assert_eq!(share_out(7, &[0.0, 2.0, f64::NAN]), [0, 7, 0]);
        assert_eq!(share_out(7, &[0.0, 0.0]), [0, 0]);
        assert_eq!(share_out(1, &[1.0, 1.0]), [1, 0]);
    }
}
