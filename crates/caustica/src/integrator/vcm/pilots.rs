//! The pilots vcm runs before its first pass ([`Progressive::prepare`]): where caustics seen
//! directly are focused (a pilot run of light subpaths, [`CausticFocus`]), the pixels that see
//! them, and how many light subpaths a pass traces against its camera paths (the balance
//! pilot, [`balance`]). They read the renderer and return what they found; the caller keeps it,
//! so nothing is filled in from whichever pass asks first, and a cancel leaves nothing behind.

use super::*;

/// The pilot run's least light subpaths: a small image still finds its caustics' focus.
const MIN_PILOT_PATHS: u64 = 16_384;

/// The pilot run's pass index: a random stream no real pass reaches.
const PILOT_PASS: u64 = (1 << 24) - 1;
/// The balance pilot's two halves' pass indices, streams no real pass reaches either.
const BALANCE_PASSES: [u64; 2] = [PILOT_PASS - 1, PILOT_PASS - 2];
/// Seed offset of the balance pilot's camera samples.
const BALANCE_SEED: u64 = 0x0062_616c_616e_6365;
/// The balance pilot samples this share of the pixels, and at least [`MIN_BALANCE_PIXELS`].
const BALANCE_PIXEL_SHARE: usize = 16;
const MIN_BALANCE_PIXELS: usize = 2048;
/// The run whose mean merging variance the balance weighs ([`balance::merging_growth`]): the
/// default plan's passes. Not the run's own plan, which the parts of a split run do not share;
/// the growth goes as the cube root of the passes, so a run of a tenth or ten times as many is
/// off by about 2× in the variance and 1.5× in the count.
const BALANCE_RUN_PASSES: u64 = crate::integrator::session::DEFAULT_PASSES;
/// The balanced count's bounds: one light subpath for this many pixels, and at least
/// [`MIN_LIGHT_PATHS`]; [`MOST_LIGHT_PATHS_PER_PIXEL`] a pixel, at most
/// [`MAX_DEFAULT_LIGHT_PATHS`].
const LEAST_SHARE_OF_PIXELS: u64 = 16;
const MIN_LIGHT_PATHS: u64 = 256;
const MOST_LIGHT_PATHS_PER_PIXEL: u64 = 4 * LIGHT_PATHS_PER_PIXEL;

/// A first pass's time per light subpath, all its work counted, over the pilot run's (which
/// neither joins subpaths to the eye nor merges them, nor pays for a pass's first memory).
/// Measured on six scenes' first passes, on one and two threads: 1.6–2.2; on the race's boxes
/// at 0.5 s, 2.0 overran the limit and 2.2 stopped short of it (measured:
/// docs/benchmarks/2026-12-02.md, "vcm fills the time limit").
pub(super) const PILOT_TO_PASS_COST: f64 = 2.1;

/// The balance pilot's two halves of a pass's light subpaths.
struct BalanceHalves {
    data: [PassData; 2],
    /// Each half's light tracing on the film (the mean of R, G, B).
    splats: [Vec<f64>; 2],
    /// A half's light estimates times this stand for a pass of the default count's.
    scale: f64,
    /// Light subpaths in each half.
    half: u64,
}

impl<'a> Vcm<'a> {
    /// The pilots, before the first pass: where caustics seen directly are focused, the
    /// pixels that see them, and how many light subpaths a pass traces. `false` when cancelled
    /// (nothing kept: the next call starts again).
    pub(super) fn run_pilots(&mut self, cancel: &AtomicBool) -> bool {
        if self.balanced.is_some() {
            return true;
        }
        if self.spectral {
            crate::spectrum::prepare();
        }
        let Some((focus, pilot_seconds)) = self.focus_pilot(cancel) else {
            return false;
        };
        self.focus = focus;
        self.pilot_seconds = Some(pilot_seconds);
        self.focus_pixels = self.find_focus_pixels();
        let balanced = match self.settings.light_paths_per_pass {
            Some(count) => Some(Balance {
                light_paths: count.max(1),
                radius: self.pilot_radius,
                seconds_per_light_path: None,
            }),
            None => self.balance_pilot(cancel),
        };
        match balanced {
            Some(balanced) => {
                self.balanced = Some(balanced);
                true
            }
            None => false,
        }
    }

    /// Where caustics seen directly are focused: a pilot run of one light subpath per pixel
    /// (at least [`MIN_PILOT_PATHS`], at most the default pass's cap), in cells one merging
    /// diameter wide; and the seconds each pilot subpath took. `None` when cancelled.
    fn focus_pilot(&self, cancel: &AtomicBool) -> Option<(CausticFocus, f64)> {
        if self.scene.lights().is_empty() || self.emitters.is_empty() {
            return Some((CausticFocus::default(), 0.0));
        }
        let start = std::time::Instant::now();
        let count = (self.pixels() as u64).clamp(MIN_PILOT_PATHS, MAX_DEFAULT_LIGHT_PATHS);
        let f = Factors::new(self.pilot_radius, count as f32);
        let wl = pass_wavelengths(self.spectral, self.seed, PILOT_PASS);
        let paths = self.pilot_paths(PILOT_PASS, count, &f, &wl, false, cancel)?;
        let seconds = start.elapsed().as_secs_f64() / count as f64;
        let caustic = paths
            .merge_points
            .iter()
            .zip(&paths.merge_vertices)
            .filter(|(_, v)| v.direct_caustic)
            .map(|(p, v)| (*p, wl.to_rgb(v.throughput).max_element()));
        Some((CausticFocus::new(caustic, 2.0 * self.pilot_radius), seconds))
    }

    /// The first `count` light subpaths of pass `pass`, for a pilot; `None` when cancelled.
    fn pilot_paths(
        &self,
        pass: u64,
        count: u64,
        f: &Factors,
        wl: &Wavelengths,
        to_eye: bool,
        cancel: &AtomicBool,
    ) -> Option<LightPaths> {
        let mut scratch = Scratch::default();
        self.light_paths((pass, count), f, wl, to_eye, cancel, &mut scratch)?;
        Some(scratch.paths)
    }

    /// The balance pilot ([`balance`]): two independent halves of a pilot pass's light subpaths,
    /// and two camera samples at each of a sample of the pixels, each joined to both halves.
    /// The halves' difference is the light side's noise, the samples' the camera side's; rays
    /// counted are the costs. Its own random streams, so every run of a seed finds the same
    /// count (split runs merge into one).
    fn balance_pilot(&self, cancel: &AtomicBool) -> Option<Balance> {
        let (w, h) = (self.width, self.height);
        let pixels = self.pixels();
        let default = Balance {
            light_paths: default_light_paths(w, h),
            radius: self.pilot_radius,
            seconds_per_light_path: None,
        };
        if self.scene.lights().is_empty() || self.emitters.is_empty() {
            return Some(default);
        }
        // Where the eye sees a caustic's focus, its error falls with every light subpath
        // traced, and the default count was measured best for it (the race's focus).
        if self.focus_pixels.iter().any(|&f| f) {
            return Some(default);
        }
        let start = std::time::Instant::now();
        let half = (pixels as u64)
            .clamp(MIN_PILOT_PATHS, MAX_DEFAULT_LIGHT_PATHS)
            .div_ceil(2);
        // Every weight as in a pass of the default count; each half's light estimates scaled
        // up to stand for such a pass.
        let radius = match self.settings.balanced_footprint {
            Some(px) => self.pilot_radius * px / MERGING_FOOTPRINT,
            None => self.pilot_radius,
        };
        let f = Factors::new(radius, default.light_paths as f32);
        let wl = pass_wavelengths(self.spectral, self.seed, BALANCE_PASSES[0]);
        let [first, second] = BALANCE_PASSES.map(|pass| self.pilot_paths(pass, half, &f, &wl, true, cancel));
        let halves =
            [first?, second?].map(|paths| PassData::arrange(paths, HashGrid::default(), Vec::new(), f, radius));
        let light_seconds = start.elapsed().as_secs_f64() / (2 * half) as f64;
        let splats = halves.each_ref().map(|data| {
            let mut film = vec![0.0f64; pixels];
            for &(pixel, value) in &data.paths.splats {
                film[pixel as usize] += channel_mean(value);
            }
            film
        });
        let sampled = pixels.min(MIN_BALANCE_PIXELS.max(pixels / BALANCE_PIXEL_SHARE)).max(1);
        let stride = pixels / sampled;
        let camera_start = std::time::Instant::now();
        // A pixel from each run of `stride`.
        let chosen: Vec<usize> = (0..sampled)
            .map(|j| {
                let mut rng = Rng::new(self.seed ^ BALANCE_SEED, j as u64);
                j * stride + ((rng.uniform() * stride as f32) as usize).min(stride - 1)
            })
            .collect();
        let pilot = BalanceHalves {
            data: halves,
            splats,
            scale: default.light_paths as f64 / half as f64,
            half,
        };
        let measured: Vec<(PixelSpread, CameraWork)> = chosen
            .par_iter()
            .map(|&pixel| self.balance_pixel(pixel, &pilot, &wl))
            .collect();
        if cancel.load(Ordering::Relaxed) {
            return None;
        }
        let camera_seconds = camera_start.elapsed().as_secs_f64() / (4 * chosen.len()) as f64;
        let spreads: Vec<PixelSpread> = measured.iter().map(|(s, _)| *s).collect();
        let (rays, candidates) = measured
            .iter()
            .fold((0u64, 0u64), |(r, c), (_, work)| (r + work.rays, c + work.candidates));
        let camera_samples = (2 * chosen.len()) as f64;
        // No pixel sees a focus: one camera sample each.
        let samples_a_pass = pixels as f64;
        let costs = PassCosts {
            camera: rays as f64 / camera_samples * samples_a_pass,
            per_light_path: (pilot.data[0].paths.rays + pilot.data[1].paths.rays) as f64 / (2 * half) as f64
                + CANDIDATE_COST * candidates as f64 / camera_samples * samples_a_pass / half as f64,
        };
        let bounds = (
            (pixels as u64 / LEAST_SHARE_OF_PIXELS).max(MIN_LIGHT_PATHS),
            (pixels as u64 * MOST_LIGHT_PATHS_PER_PIXEL).clamp(MIN_LIGHT_PATHS, MAX_DEFAULT_LIGHT_PATHS),
        );
        let growth = merging_growth(BALANCE_RUN_PASSES, self.settings.alpha);
        let count = balanced_light_paths(&spreads, growth, costs, bounds).unwrap_or(default.light_paths);
        let pass_seconds = light_seconds * count as f64 + camera_seconds * samples_a_pass;
        // Kept by the caller with the count (the pilot only reads `self`).
        Some(Balance {
            light_paths: count,
            radius,
            seconds_per_light_path: Some(pass_seconds / count as f64),
        })
    }

    /// The balance pilot at one pixel: two camera samples, each joined to both halves with the
    /// same random numbers, so the camera strategies' part is the same and the light's differs.
    fn balance_pixel(&self, pixel: usize, pilot: &BalanceHalves, wl: &Wavelengths) -> (PixelSpread, CameraWork) {
        let (w, h) = (self.width, self.height);
        let camera = &self.camera;
        let scale = pilot.scale;
        let mut rng = Rng::new(self.seed ^ BALANCE_SEED ^ 1, pixel as u64);
        let (x, y) = (pixel % w, pixel / w);
        let own = pixel % pilot.half as usize;
        let mut work = CameraWork::default();
        let (mut values, mut cameras) = ([0.0f64; 2], [0.0f64; 2]);
        let (mut traced, mut merged, mut covariance) = (0.0, 0.0, 0.0);
        for i in 0..2 {
            let (jx, jy) = (rng.uniform(), rng.uniform());
            let ray = camera.generate_ray((x as f32 + jx) / w as f32, 1.0 - (y as f32 + jy) / h as f32);
            let mut twin = rng.clone();
            let merged_before = work.merged;
            let all = channel_mean(wl.to_rgb(self.camera_path(ray, &pilot.data[0], own, wl, &mut rng, &mut work)));
            let merged_a = channel_mean(wl.to_rgb(work.merged - merged_before));
            let mut other = CameraWork::default();
            self.camera_path(ray, &pilot.data[1], own, wl, &mut twin, &mut other);
            let merged_b = channel_mean(wl.to_rgb(other.merged));
            cameras[i] = all - merged_a;
            let (splat_a, splat_b) = (scale * pilot.splats[0][pixel], scale * pilot.splats[1][pixel]);
            let (merged_a, merged_b) = (scale * merged_a, scale * merged_b);
            values[i] = cameras[i] + 0.5 * (splat_a + splat_b + merged_a + merged_b);
            // A half's variance is half its squared difference from the other's.
            let (dt, dm) = (splat_a - splat_b, merged_a - merged_b);
            traced += 0.5 * dt * dt;
            merged += 0.5 * dm * dm;
            covariance += 0.5 * dt * dm;
        }
        // Per light subpath: times their number, over the two samples.
        let per_path = pilot.half as f64 / 2.0;
        let spread = PixelSpread {
            camera: 0.5 * (cameras[0] - cameras[1]).powi(2),
            traced: per_path * traced,
            merged: per_path * merged,
            covariance: per_path * covariance,
            mean: 0.5 * (values[0] + values[1]),
        };
        (spread, work)
    }

    /// Whether each pixel sees a focused cell directly: the ray through its centre ends in
    /// one, or a neighbour's does (a pixel's samples spread over it).
    fn find_focus_pixels(&self) -> Vec<bool> {
        {
            let (w, h) = (self.width, self.height);
            let focus = &self.focus;
            if focus.is_empty() {
                return vec![false; w * h];
            }
            let camera = &self.camera;
            let centre: Vec<bool> = (0..w * h)
                .into_par_iter()
                .map(|pixel| {
                    let (x, y) = (pixel % w, pixel / w);
                    let ray = camera.generate_ray((x as f32 + 0.5) / w as f32, 1.0 - (y as f32 + 0.5) / h as f32);
                    self.scene
                        .intersect(&ray, f32::INFINITY)
                        .is_some_and(|isect| focus.contains(ray.at(isect.t)))
                })
                .collect();
            (0..w * h)
                .map(|pixel| {
                    let (x, y) = ((pixel % w) as isize, (pixel / w) as isize);
                    (-1..=1).any(|dy| {
                        (-1..=1).any(|dx| {
                            let (nx, ny) = (x + dx, y + dy);
                            nx >= 0
                                && ny >= 0
                                && (nx as usize) < w
                                && (ny as usize) < h
                                && centre[ny as usize * w + nx as usize]
                        })
                    })
                })
                .collect()
        }
    }
}

/// The mean of a colour's channels, in the image's units.
fn channel_mean(rgb: Vec3) -> f64 {
    if rgb.is_finite() {
        (rgb.x as f64 + rgb.y as f64 + rgb.z as f64) / 3.0
    } else {
        0.0
    }
}
