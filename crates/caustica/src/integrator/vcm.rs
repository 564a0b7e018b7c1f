//! Vertex connection and merging (Georgiev et al., "Light transport simulation with vertex
//! connection and merging", 2012; Hachisuka et al.'s unified path sampling, 2012): every pass
//! traces light subpaths and one camera subpath per pixel, and joins them in every way a path
//! can be made — the camera path hitting an emitter, next-event estimation, light tracing
//! (a light vertex joined to the eye), connections between the two subpaths' vertices, and
//! merging (a camera vertex gathering the light vertices within a radius that shrinks pass by
//! pass, as in progressive photon mapping) — each weighted against all the others by multiple
//! importance sampling ([`mis`]).
//!
//! Departures from the textbook, each leaving a strategy out for a class of paths where it is
//! the worst estimator (the weights of those paths still sum to one, see [`mis`]):
//! - merging happens only at the first vertex where the camera path scatters off a smooth
//!   lobe (as in progressive photon mapping; a coated glass's delta lobes pass it on, as
//!   mirrors and glass do): deeper, a merge stands on one sampled bounce of the camera path
//!   and is as noisy as path tracing, yet the balance heuristic would weigh it like the first;
//! - where the eye sees a caustic's focus directly (light came from the light through mirrors
//!   and glass only, and a pilot run found such light concentrated there: [`focus`]), merging
//!   is left out there too, so light tracing keeps the focus sharp instead of sharing it with a
//!   blurring kernel, while the dim spread-out part is merged smooth; light that met a diffuse
//!   surface before the glass (a wall's light focused by a lens) is smooth and merged even
//!   there, since light tracing it would be the focus's main noise;
//! - direct light (light tracing and merging at the surface light reaches first) is left to
//!   next-event estimation (noiseless for a point light) and to emitters that camera paths hit;
//!   measured, light tracing it doubled the area light's image error.
//!
//! Merging still smooths indirect light and the caustics seen by a mirror or through glass.
//! A share of the light subpaths is aimed at the mirrors and glass ([`Aim`]): caustic
//! paths, a few percent of uniform emission on the race's scenes, become many times more
//! frequent, and every weight uses the mixture's density. So is a share of their bounces off
//! Lambertian surfaces ([`BOUNCE_AIM_SHARE`]), for the light a lit wall sends through a glass.
//! How many light subpaths a pass traces against its camera paths is measured on the scene by
//! a pilot ([`balance`]).
//! Determinism: light subpaths are traced in fixed batches and added in index order.

pub mod balance;
pub mod focus;
pub mod grid;
pub mod mis;

use super::lt::Sensor;
use super::ppm::{pass_wavelengths, settings_spectral, PHOTON_SEED};
use super::radius::{radius_factor, InitialRadius};
use super::tiles::shade_tiles;
use super::Progressive;
use crate::bsdf::{adjoint_correction, Bsdf, BsdfSample, Transport};
use crate::light::aim::{caustic_targets, Aim};
use crate::light::emission::Emitters;
use crate::math::{Ray, Vec3};
use crate::progress::Control;
use crate::sampling::{power_heuristic, Rng};
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths, SAMPLES};
use balance::{balanced_light_paths, merging_growth, PassCosts, PixelSpread, CANDIDATE_COST};
use focus::CausticFocus;
use grid::HashGrid;
use mis::{ConnectionPdfs, DirectPdfs, Factors, Partial};
use rayon::prelude::*;
use std::sync::atomic::{AtomicBool, Ordering};

/// Settings of vertex connection and merging.
#[derive(Clone, Debug, PartialEq)]
pub struct VcmSettings {
    /// Light subpaths per pass (`None`: as many as a pilot finds best against the camera paths
    /// ([`balance`]), and half as many in the first two passes).
    pub light_paths_per_pass: Option<u64>,
    /// Knaus & Zwicker's α in (0, 1): how fast the merging radius shrinks.
    pub alpha: f32,
    /// The first pass's merging radius: a number of pixels as wide as they are at the distance
    /// from the eye to the scene's centre, or a world radius.
    pub initial_radius: InitialRadius,
    /// Bounces: light reaches the eye from at most this many surfaces plus one.
    pub max_depth: u32,
    /// Connect every smooth camera vertex to every vertex of one light subpath (bidirectional
    /// path tracing's inner connections). Off, the strategies are the camera path's own (hitting
    /// emitters, next-event estimation), light tracing and merging, and camera paths cost far
    /// less; on the Cornell box race that wins (docs/benchmarks/2026-12-02.md, "The caustics
    /// race: vcm against Mitsuba 3").
    pub connections: bool,
    /// Aim [`AIM_SHARE`] of the light subpaths, and [`BOUNCE_AIM_SHARE`] of their bounces off
    /// Lambertian surfaces, at the mirrors and glass (`--no-aim`: none).
    pub aim: bool,
    /// Carry light at sampled wavelengths instead of RGB (`None`: when the scene has a
    /// dispersive glass).
    pub spectral: Option<bool>,
    /// Camera samples a pass in the pixels that see a caustic's focus (1: one, as elsewhere).
    pub focus_samples: usize,
    /// The first merging radius in pixels where the balance pilot chose the count (the eye sees
    /// no caustic's focus directly); `None` keeps `initial_radius` there too. `--radius` and
    /// `--footprint` set `None`.
    pub balanced_footprint: Option<f32>,
}

impl Default for VcmSettings {
    fn default() -> Self {
        VcmSettings {
            light_paths_per_pass: None,
            alpha: 2.0 / 3.0,
            initial_radius: InitialRadius::Pixels(MERGING_FOOTPRINT),
            max_depth: 64,
            connections: false,
            aim: true,
            spectral: None,
            focus_samples: FOCUS_CAMERA_SAMPLES,
            balanced_footprint: Some(BALANCED_FOOTPRINT),
        }
    }
}

/// The first pass's merging radius in pixels. Measured on the Cornell box race at equal
/// passes (eight seeds, docs/benchmarks/2026-12-02.md, "The caustics race: vcm with more camera
/// samples at the focus, and cheaper passes"): 3 pixels against 2 cut the caustic region's error by
/// 44% at one pass and 14–39% at 3 and 9, level at 20, the focus level, for 2–15% more time
/// a pass (more light vertices to merge); 1 pixel doubled it. (`ppm`'s gathers keep 2:
/// `--footprint` gives both.)
pub const MERGING_FOOTPRINT: f32 = 3.0;

/// The first merging radius in pixels of a scene the balance pilot balanced. Against a
/// reference of `scenes/pool.ray` (a caustic net seen through water), 3 pixels' blur was most of
/// vcm's error at 20 s; 2 pixels cut it 1.5× (docs/benchmarks/2026-12-03.md, "The pool against a
/// reference").
pub const BALANCED_FOOTPRINT: f32 = 2.0;

/// The share of light subpaths aimed at the bounding spheres of mirrors and glass: caustic
/// paths become several times more frequent while the rest keep most of their subpaths.
/// Measured on the race (0.5–4 s, four seeds): 0.15 cut the focus error by 20–60% for
/// 1.1–1.6× the caustic region's error; 0.3 and 0.5 took too many subpaths from the indirect
/// light merged around the caustic (region error 1.4–2.2×) (docs/benchmarks/2026-12-02.md,
/// "The caustics race, aimed vcm").
pub const AIM_SHARE: f32 = 0.15;

/// The share of a directional light's or sun's subpaths (and the sky's) aimed at the mirrors
/// and glass: their beam covers the whole scene, where a glass may take a hundredth of it.
pub const FAR_AIM_SHARE: f32 = 0.5;

/// The share of the light subpaths' bounces off Lambertian surfaces aimed at the mirrors and
/// glass. Light that a lamp-lit ceiling or wall sends through a glass is a second caustic over
/// the first; unaimed, few subpaths carry it, and it was most of the area light's focus noise.
/// A bounce towards a mirror or glass carries little power then (its density is the aimed
/// mixture's) and skips the roulette, so such subpaths become many times more frequent.
/// 0.05 of every bounce cut the race's focus error by 29–36% for 7–8% more time; more, or only
/// the first bounce, was no better (measured: docs/benchmarks/2026-12-03.md, "Aimed
/// bounces").
pub const BOUNCE_AIM_SHARE: f32 = 0.05;

/// Light subpaths per pixel and pass where the eye sees a caustic's focus (elsewhere the
/// balance pilot chooses, [`balance`]), and the weights of the pilot's estimates. Measured on
/// the Cornell box race (docs/benchmarks/2026-12-02.md, "The caustics race: vcm with 16 light
/// subpaths per pixel"), at equal time: 16 cut the focus's error by a fifth and
/// the caustic region's by a sixth against 8; 24 was no better. The first passes trace half
/// (see [`Vcm::pass_light_paths`]).
pub const LIGHT_PATHS_PER_PIXEL: u64 = 16;
/// The default's cap, so that a large image's pass stays within memory (about 100 bytes per
/// stored light vertex, one or two per path).
pub const MAX_DEFAULT_LIGHT_PATHS: u64 = 4_000_000;

/// Light subpaths per batch: the unit of parallel work and of the fixed order of addition.
const BATCH: u64 = 1024;
/// Seed offset of the light subpaths (apart from the photon mappers' streams).
const LIGHT_SEED: u64 = PHOTON_SEED ^ 0x0076_636d;
/// Next-event samples of each emissive object at the camera path's first vertex. One: four
/// halved the area light's image error at one pass but slowed every pass more than the
/// caustic gained (measured on the race's scenes).
const FIRST_VERTEX_LIGHT_SAMPLES: u32 = 1;
/// Camera samples a pass in a pixel that sees a focused cell by default. Their first vertices
/// merge the light around the focus from the same light subpaths, and which of the few bright
/// subpaths a single sample's disc catches is a large part of the focus's noise. At one pass, 8
/// cut the focus's error by 13–28% and the caustic region's by 20–23% against 1; 16 was no
/// better (measured: docs/benchmarks/2026-12-02.md, "The caustics race: vcm with more camera
/// samples at the focus, and cheaper passes"). The focus's pixels are a few hundred of the
/// image's, so the pass takes no measurably longer.
pub const FOCUS_CAMERA_SAMPLES: usize = 8;
/// Camera bounces before Russian roulette may end a camera path.
const ROULETTE_DEPTH: u32 = 3;

/// A vertex of a light subpath on a smooth surface.
#[derive(Clone, Copy, Debug)]
struct LightVertex {
    hit: SurfaceHit,
    /// Unit direction back towards the previous vertex.
    wo: Vec3,
    /// Light arriving here over the density of the subpath so far (flux of one light path).
    throughput: Spectrum,
    partial: Partial,
    /// Segments from the light.
    length: u32,
    /// The subpath kept only its hero wavelength.
    dispersed: bool,
    /// Every surface before it has only delta lobes (mirrors, glass): light seen here is a
    /// direct caustic, which light tracing keeps sharp where it is focused.
    direct_caustic: bool,
}

/// What merging reads of a light vertex: a fraction of a [`LightVertex`], so that a pass's
/// hundreds of thousands of them stay small.
#[derive(Clone, Copy, Debug)]
struct MergeVertex {
    wo: Vec3,
    normal: Vec3,
    throughput: Spectrum,
    partial: Partial,
    length: u32,
    dispersed: bool,
    direct_caustic: bool,
}

/// The light subpaths of one pass (or of one batch of it).
#[derive(Default)]
struct LightPaths {
    /// The vertices of the subpaths camera paths connect to (the first one per pixel): path
    /// `i`'s are `vertices[ends[i]..ends[i + 1]]`.
    vertices: Vec<LightVertex>,
    ends: Vec<u32>,
    /// Every vertex that may be merged (light reached it after a bounce), and where it is.
    merge_points: Vec<Vec3>,
    merge_vertices: Vec<MergeVertex>,
    /// What light tracing adds to each pixel, in batch order.
    splats: Vec<(u32, Vec3)>,
    /// Rays the subpaths cast (for the balance pilot's costs).
    rays: u64,
}

impl LightPaths {
    /// Empties it, keeping its memory.
    fn clear(&mut self) {
        self.vertices.clear();
        self.ends.clear();
        self.merge_points.clear();
        self.merge_vertices.clear();
        self.splats.clear();
        self.rays = 0;
    }

    /// Appends `batch`'s subpaths after its own.
    fn append(&mut self, batch: &LightPaths) {
        let base = self.vertices.len() as u32;
        self.ends.extend(batch.ends.iter().map(|e| base + e));
        self.vertices.extend_from_slice(&batch.vertices);
        self.merge_points.extend_from_slice(&batch.merge_points);
        self.merge_vertices.extend_from_slice(&batch.merge_vertices);
        self.splats.extend_from_slice(&batch.splats);
        self.rays += batch.rays;
    }
}

/// The memory of the last pass's light subpaths, kept for the next: a pass's tens of megabytes
/// come back without the page faults and regrowth of new vectors.
#[derive(Default)]
struct Scratch {
    batches: Vec<LightPaths>,
    paths: LightPaths,
    grid: HashGrid,
    merge_vertices: Vec<MergeVertex>,
}

/// One pass's light subpaths, arranged for the camera paths.
struct PassData {
    paths: LightPaths,
    grid: HashGrid,
    /// The mergeable light vertices in the grid's order.
    merge_vertices: Vec<MergeVertex>,
    factors: Factors,
    radius: f32,
}

/// The work of camera paths, for the balance pilot's costs.
#[derive(Clone, Copy, Debug, Default)]
struct CameraWork {
    rays: u64,
    /// Light vertices looked at by merging.
    candidates: u64,
    /// What merging added.
    merged: Spectrum,
}

impl PassData {
    /// `paths` arranged for merging within `radius` (`grid` and `merge_vertices` lend their
    /// memory).
    fn arrange(
        paths: LightPaths,
        mut grid: HashGrid,
        mut merge_vertices: Vec<MergeVertex>,
        factors: Factors,
        radius: f32,
    ) -> PassData {
        grid.rebuild(&paths.merge_points, radius);
        merge_vertices.clear();
        merge_vertices.extend(grid.order().iter().map(|&i| paths.merge_vertices[i as usize]));
        PassData {
            paths,
            grid,
            merge_vertices,
            factors,
            radius,
        }
    }
}

/// What a camera vertex needs to join light to.
struct CameraVertex<'h> {
    hit: &'h SurfaceHit,
    bsdf: &'h Bsdf,
    wo: Vec3,
    throughput: Spectrum,
    partial: Partial,
    length: u32,
    dispersed: bool,
}

/// The renderer over a whole image.
pub struct Vcm<'a> {
    scene: &'a Scene,
    /// The scene's camera fitted to the image ([`Camera::fitted`]).
    camera: crate::camera::Camera,
    settings: VcmSettings,
    width: usize,
    height: usize,
    seed: u64,
    sensor: Sensor,
    emitters: Emitters,
    /// Where a share of the light subpaths' diffuse bounces is aimed.
    bounce_aim: Option<Aim>,
    spectral: bool,
    /// Longest path in segments (eye to light).
    max_length: u32,
    /// The settings' first merging radius in scene units: the pilots' (the focus cells are
    /// twice it); the passes start from [`Balance::radius`].
    pilot_radius: f32,
    /// Light subpaths in a full pass and the first pass's merging radius: the settings', or the
    /// balance pilot's on first use.
    balanced: std::sync::OnceLock<Balance>,
    /// The balance pilot's estimate of a full pass's seconds per light subpath.
    balance_seconds: std::sync::OnceLock<f64>,
    /// The first [`RAMP_PASSES`] passes trace half the light subpaths (the default count only).
    ramp: bool,
    /// Where caustics are focused, from a pilot run on first use.
    focus: std::sync::OnceLock<CausticFocus>,
    /// The pixels that see a focused cell, from rays through their centres on first use.
    focus_pixels: std::sync::OnceLock<Vec<bool>>,
    scratch: std::sync::Mutex<Scratch>,
    /// Seconds a pilot light subpath took, for sizing a first pass to a time limit.
    pilot_seconds: std::sync::OnceLock<f64>,
    /// How long the last pass took, for sizing the next to a time limit.
    timing: std::sync::Mutex<Option<PassTiming>>,
}

/// What the balance pilot chose.
#[derive(Clone, Copy, Debug)]
struct Balance {
    light_paths: u64,
    /// The first pass's merging radius in scene units.
    radius: f32,
}

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

/// A pass's seconds per light subpath, all its work counted (the camera paths' share too, which
/// does not grow with the subpaths: a pass sized from a smaller one ends a little early, from a
/// larger one a little late).
#[derive(Clone, Copy, Debug)]
struct PassTiming {
    seconds_per_light_path: f64,
}

/// Passes at half the default light subpaths: with full passes from the start, a one-second
/// time limit stopped after the first (its successor would have ended half a pass late).
const RAMP_PASSES: u64 = 2;

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
const BALANCE_RUN_PASSES: u64 = super::session::DEFAULT_PASSES;
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
const PILOT_TO_PASS_COST: f64 = 2.1;

impl<'a> Vcm<'a> {
    /// A renderer for `scene` at `width`×`height`.
    pub fn new(scene: &'a Scene, settings: VcmSettings, width: usize, height: usize, seed: u64) -> Vcm<'a> {
        let camera = scene.camera().fitted(width, height);
        let radius = match settings.initial_radius {
            InitialRadius::World(r) => r,
            InitialRadius::Pixels(px) => {
                let distance = (scene.lights().scene_sphere().0 - camera.eye).length().max(1e-6);
                px * super::radius::pixel_angle(&camera, height) * distance
            }
        };
        Vcm {
            scene,
            sensor: Sensor::new(&camera, width, height),
            camera,
            emitters: {
                let targets = if settings.aim {
                    caustic_targets(scene)
                } else {
                    Vec::new()
                };
                let lights = scene.lights();
                Emitters::new(
                    lights.as_slice(),
                    lights.scene_sphere(),
                    Aim::new(&targets, AIM_SHARE),
                    Aim::new(&targets, FAR_AIM_SHARE),
                )
            },
            bounce_aim: if settings.aim {
                Aim::new(&caustic_targets(scene), BOUNCE_AIM_SHARE)
            } else {
                None
            },
            spectral: settings_spectral(&settings.spectral, scene),
            // Segments: one more than the surfaces light may scatter at.
            max_length: super::config::scattering_surfaces(settings.max_depth).saturating_add(1),
            pilot_radius: radius,
            balanced: match settings.light_paths_per_pass {
                Some(count) => std::sync::OnceLock::from(Balance {
                    light_paths: count.max(1),
                    radius,
                }),
                None => std::sync::OnceLock::new(),
            },
            balance_seconds: std::sync::OnceLock::new(),
            ramp: settings.light_paths_per_pass.is_none(),
            settings,
            width,
            height,
            seed,
            focus: std::sync::OnceLock::new(),
            focus_pixels: std::sync::OnceLock::new(),
            scratch: std::sync::Mutex::default(),
            pilot_seconds: std::sync::OnceLock::new(),
            timing: std::sync::Mutex::new(None),
        }
    }

    /// Light subpaths of pass `pass`. With the default count the first [`RAMP_PASSES`] trace
    /// half: the first pictures (and a run with a time limit of a second or two) come as soon as
    /// with half the count, and the passes after them spend most of their time on light tracing.
    fn pass_light_paths(&self, pass: u64) -> u64 {
        if pass < RAMP_PASSES && self.ramp {
            self.full_pass_paths().div_ceil(2)
        } else {
            self.full_pass_paths()
        }
    }

    /// Where caustics seen directly are focused: a pilot run of one light subpath per pixel
    /// (at least [`MIN_PILOT_PATHS`], at most the default pass's cap), in cells one merging
    /// diameter wide.
    fn focus(&self) -> &CausticFocus {
        self.focus.get_or_init(|| {
            if self.spectral {
                crate::spectrum::prepare();
            }
            let start = std::time::Instant::now();
            let count = (self.pixels() as u64).clamp(MIN_PILOT_PATHS, MAX_DEFAULT_LIGHT_PATHS);
            let f = Factors::new(self.pilot_radius, count as f32);
            let wl = pass_wavelengths(self.spectral, self.seed, PILOT_PASS);
            let paths = self.pilot_paths(PILOT_PASS, count, &f, &wl, false);
            let _ = self.pilot_seconds.set(start.elapsed().as_secs_f64() / count as f64);
            let caustic = paths
                .merge_points
                .iter()
                .zip(&paths.merge_vertices)
                .filter(|(_, v)| v.direct_caustic)
                .map(|(p, v)| (*p, wl.to_rgb(v.throughput).max_element()));
            CausticFocus::new(caustic, 2.0 * self.pilot_radius)
        })
    }

    /// The first `count` light subpaths of pass `pass`, for a pilot (nothing cancels it).
    fn pilot_paths(&self, pass: u64, count: u64, f: &Factors, wl: &Wavelengths, to_eye: bool) -> LightPaths {
        let mut scratch = Scratch::default();
        let never = AtomicBool::new(false);
        let _ = self.light_paths((pass, count), f, wl, to_eye, &never, &mut scratch);
        scratch.paths
    }

    /// Light subpaths in a full pass: the setting's, or else the balance pilot's count.
    fn full_pass_paths(&self) -> u64 {
        self.balanced().light_paths
    }

    /// The first pass's merging radius.
    fn first_radius(&self) -> f32 {
        self.balanced().radius
    }

    fn balanced(&self) -> &Balance {
        self.balanced.get_or_init(|| self.balance_pilot())
    }

    /// The balance pilot ([`balance`]): two independent halves of a pilot pass's light subpaths,
    /// and two camera samples at each of a sample of the pixels, each joined to both halves.
    /// The halves' difference is the light side's noise, the samples' the camera side's; rays
    /// counted are the costs. Its own random streams, so every run of a seed finds the same
    /// count (split runs merge into one).
    fn balance_pilot(&self) -> Balance {
        let (w, h) = (self.width, self.height);
        let pixels = self.pixels();
        let default = Balance {
            light_paths: default_light_paths(w, h),
            radius: self.pilot_radius,
        };
        if self.scene.lights().is_empty() || self.emitters.is_empty() {
            return default;
        }
        let focus_pixels = self.focus_pixels();
        // Where the eye sees a caustic's focus, its error falls with every light subpath
        // traced, and the default count was measured best for it (the race's focus).
        if focus_pixels.iter().any(|&f| f) {
            return default;
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
        let halves = BALANCE_PASSES.map(|pass| {
            let paths = self.pilot_paths(pass, half, &f, &wl, true);
            PassData::arrange(paths, HashGrid::default(), Vec::new(), f, radius)
        });
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
        let _ = self.balance_seconds.set(pass_seconds / count as f64);
        Balance {
            light_paths: count,
            radius,
        }
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
    fn focus_pixels(&self) -> &[bool] {
        self.focus_pixels.get_or_init(|| {
            let (w, h) = (self.width, self.height);
            let focus = self.focus();
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
        })
    }

    /// Traces light subpath `index` of pass `pass`: stores its smooth vertices and joins each
    /// to the eye.
    /// (The pilot run, `to_eye` false, only stores.)
    fn trace_light(&self, pass: u64, index: u64, f: &Factors, wl: &Wavelengths, to_eye: bool, out: &mut LightPaths) {
        let connected = self.settings.connections && index < self.pixels() as u64;
        let scene = self.scene;
        let mut rng = Rng::new(self.seed ^ LIGHT_SEED, (pass << 40) ^ index);
        let Some(emission) = self.emitters.emit(scene, wl, &mut rng) else {
            return;
        };
        let mut throughput = emission.throughput;
        let start = throughput.max_element();
        let mut partial = Partial::default();
        let mut ray = emission.ray;
        let mut previous = emission.ray.origin;
        let mut dispersed = false;
        // Only mirrors and glass so far.
        let mut all_specular = true;
        for length in 1..self.max_length {
            out.rays += 1;
            let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
                return;
            };
            let hit = scene.surface(&ray, &isect);
            let wo = -ray.dir;
            let bsdf = Bsdf::at(scene, &hit, wo, wl);
            if length == 1 {
                // Next-event estimation's density of the light point depends on where it is
                // seen from (a sphere is sampled by its cone).
                let direct = self.emitters.direct_pdf(scene, &emission, hit.point);
                partial = Partial::light(f, emission.emission_pdf, direct, emission.cos, emission.delta);
            }
            // A far light's densities are across its beam: no distance to its first vertex.
            let d2 = if length == 1 && emission.far {
                1.0
            } else {
                (hit.point - previous).length_squared()
            };
            partial.arrive(d2, bsdf.normal().dot(wo).abs());
            if !self.settings.connections && length > 1 {
                // The sum's first term stands for a connection that makes this vertex.
                partial.vcm = 0.0;
            }
            let direct_caustic = length > 1 && all_specular;
            if bsdf.is_smooth() {
                let vertex = LightVertex {
                    hit,
                    wo,
                    throughput,
                    partial,
                    length,
                    dispersed,
                    direct_caustic,
                };
                if to_eye {
                    // Direct light is not traced to the eye (see trace_to_eye).
                    out.rays += u64::from(length > 1);
                    self.trace_to_eye(&vertex, &bsdf, f, wl, &mut out.splats);
                }
                // Light reaching a vertex first is never merged (see the module's notes).
                if length > 1 {
                    out.merge_points.push(hit.point);
                    out.merge_vertices.push(MergeVertex {
                        wo,
                        normal: hit.geometric_normal,
                        throughput,
                        partial,
                        length,
                        dispersed,
                        direct_caustic,
                    });
                }
                if connected {
                    out.vertices.push(vertex);
                }
            }
            all_specular &= !bsdf.is_smooth();
            // A further vertex must still reach the eye within the longest path.
            if length + 2 > self.max_length {
                return;
            }
            let aim = self.bounce_aim.as_ref().filter(|_| bsdf.is_lambertian());
            let Some((sample, towards_target)) = light_bounce(&bsdf, hit.point, wo, aim, &mut rng) else {
                return;
            };
            let cos_out = bsdf.normal().dot(sample.wi).abs();
            if sample.specular {
                partial.scatter_specular(cos_out);
            } else {
                // A light vertex with a smooth vertex after it is never the camera path's first
                // smooth one: no merging here.
                partial.scatter(f, sample.pdf, bsdf.pdf_reverse(wo, sample.wi), cos_out, false);
            }
            // Flux, as the photon tracer carries it: Veach's correction for interpolated
            // normals (1 on flat geometry). Without it a caustic through smooth-shaded glass
            // came out 1.7% brighter than the photon tracer's.
            let Some(correction) = adjoint_correction(hit.shading_normal, hit.geometric_normal, wo, sample.wi) else {
                return;
            };
            let weight = sample.weight * correction;
            // The photon tracer's roulette keeps the subpath's power near its start, except
            // that a bounce towards a mirror or glass where bounces are aimed goes on with the
            // little it carries (the point of aiming it); a diffuse bounce after it brings the
            // power back or ends the subpath.
            let q = if towards_target {
                1.0
            } else if sample.specular {
                weight.max_element().min(1.0)
            } else {
                (weight.max_element() * (throughput.max_element() / start).min(1.0)).min(1.0)
            };
            if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
                return;
            }
            throughput *= weight / q;
            if sample.dispersive {
                wl.terminate_secondary(&mut throughput, &mut dispersed);
            }
            previous = hit.point;
            ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
        }
    }

    /// Light tracing: the light vertex seen by the eye, splatted onto its pixel.
    fn trace_to_eye(&self, v: &LightVertex, bsdf: &Bsdf, f: &Factors, wl: &Wavelengths, splats: &mut Vec<(u32, Vec3)>) {
        // Direct light is the camera strategies' (see the module's notes).
        if v.length == 1 || v.length + 1 > self.max_length {
            return;
        }
        let Some(s) = self.sensor.sample(v.hit.point) else {
            return;
        };
        let value = bsdf.eval(v.wo, s.to_eye);
        if value == Spectrum::ZERO {
            return;
        }
        let (ns, ng) = (v.hit.shading_normal, v.hit.geometric_normal);
        let wo_ng = v.wo.dot(ng).abs();
        if wo_ng <= 0.0 || !self.scene.unoccluded(&v.hit, s.to_eye, s.distance) {
            return;
        }
        let inv_d2 = 1.0 / (s.distance * s.distance);
        // The adjoint BSDF's shading-normal correction, as in light tracing.
        let cos = s.to_eye.dot(ng).abs() * v.wo.dot(ns).abs() / wo_ng;
        let camera_pdf = s.importance * bsdf.normal().dot(s.to_eye).abs() * inv_d2;
        let weight = mis::light_tracing(
            f,
            &v.partial,
            camera_pdf,
            bsdf.pdf_reverse(v.wo, s.to_eye),
            v.length > 1 && !(v.direct_caustic && self.focus().contains(v.hit.point)),
        );
        let splat = v.throughput * value * (cos * inv_d2 * s.importance * weight / f.light_paths);
        let rgb = wl.to_rgb(splat);
        if rgb.is_finite() {
            splats.push((s.pixel as u32, rgb));
        }
    }

    /// The first `count` light subpaths of pass `pass`, traced in batches in parallel and kept
    /// in index order in `scratch.paths` (emptied first; `scratch.batches` lends the batches'
    /// memory). `None` when `cancel` is set. `to_eye`: joined to the eye (a pilot that only
    /// looks for the focus does not).
    fn light_paths(
        &self,
        (pass, count): (u64, u64),
        f: &Factors,
        wl: &Wavelengths,
        to_eye: bool,
        cancel: &AtomicBool,
        scratch: &mut Scratch,
    ) -> Option<()> {
        let batch_count = count.div_ceil(BATCH) as usize;
        let batches = &mut scratch.batches;
        batches.resize_with(batches.len().max(batch_count), LightPaths::default);
        let complete = batches[..batch_count].par_iter_mut().enumerate().all(|(b, out)| {
            if cancel.load(Ordering::Relaxed) {
                return false;
            }
            out.clear();
            let b = b as u64;
            for i in b * BATCH..((b + 1) * BATCH).min(count) {
                self.trace_light(pass, i, f, wl, to_eye, out);
                out.ends.push(out.vertices.len() as u32);
            }
            true
        });
        if !complete {
            return None;
        }
        let all = &mut scratch.paths;
        all.clear();
        all.ends.push(0);
        for batch in &batches[..batch_count] {
            all.append(batch);
        }
        Some(())
    }

    fn pixels(&self) -> usize {
        self.width * self.height
    }

    /// Radiance along the camera ray `ray`, joined to the pass's light subpaths (`own`: the
    /// one this pixel connects to).
    fn camera_path(
        &self,
        ray: Ray,
        pass: &PassData,
        own: usize,
        wl: &Wavelengths,
        rng: &mut Rng,
        work: &mut CameraWork,
    ) -> Spectrum {
        let f = &pass.factors;
        let scene = self.scene;
        let camera_pdf = self.sensor.importance(ray.dir);
        if camera_pdf <= 0.0 {
            return Spectrum::ZERO;
        }
        let mut partial = Partial::camera(f, camera_pdf);
        let mut ray = ray;
        let mut throughput = wl.grey(1.0);
        let mut l = Spectrum::ZERO;
        let mut previous = ray.origin;
        let mut dispersed = false;
        // The last bounce's density, for the sky and suns (None: seen directly or by a mirror).
        let mut last_pdf: Option<f32> = None;
        // The sums as they would be without merging at the first vertex, taken if the second
        // turns out to be a mirror or glass (the eye then sees a caustic there), and the sums
        // with it, kept along the mirrors and glass that follow: light that reached them from
        // a diffuse surface (not a direct caustic) is merged at the first vertex again.
        let mut without_first_merge = Partial::default();
        let mut with_first_merge: Option<Partial> = None;
        // The sums without merging at the last vertex, for an emitter hit next (light reaches
        // that vertex first).
        let mut without_last_merge = Partial::default();
        // Whether the path scattered off a smooth lobe before: merging is a strategy at the
        // first vertex where it does (the delta lobes of coated glass, as mirrors and glass,
        // pass the merge on to the next vertex).
        let mut smooth_before = false;
        // Whether the first vertex lies where caustics are focused.
        let mut first_focused = false;
        for length in 1..=self.max_length {
            work.rays += 1;
            let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
                l += throughput * self.escaped(ray.dir, previous, last_pdf, &without_last_merge, length, wl);
                break;
            };
            let hit = scene.surface(&ray, &isect);
            let wo = -ray.dir;
            let d2 = (hit.point - previous).length_squared();
            let bsdf = Bsdf::at(scene, &hit, wo, wl);
            let cos_in = bsdf.normal().dot(wo).abs();
            partial.arrive(d2, cos_in);
            let le = scene.emission_towards(&hit, wo, wl);
            if le != Spectrum::ZERO {
                without_last_merge.arrive(d2, cos_in);
                l += throughput * le * self.emitter_weight(&hit, &without_last_merge, previous, wo, d2, length);
            }
            if length == 2 && !bsdf.is_smooth() && first_focused {
                without_first_merge.arrive(d2, cos_in);
                with_first_merge = Some(partial);
                partial = without_first_merge;
            } else if let Some(mut with) = with_first_merge {
                with.arrive(d2, cos_in);
                with_first_merge = Some(with);
                if bsdf.is_smooth() {
                    partial = with;
                    with_first_merge = None;
                }
            }
            if !self.settings.connections && length > 1 {
                // The sum's first term stands for a connection that makes this vertex (for an
                // emitter, next-event estimation, counted above).
                partial.vcm = 0.0;
            }
            if length >= self.max_length || bsdf.is_black() {
                break;
            }
            let merges_here = bsdf.is_smooth() && !smooth_before;
            if length == 1 {
                first_focused = self.focus().contains(hit.point);
            }
            if bsdf.is_smooth() {
                let v = CameraVertex {
                    hit: &hit,
                    bsdf: &bsdf,
                    wo,
                    throughput,
                    partial,
                    length,
                    dispersed,
                };
                l += self.direct(&v, f, wl, rng, work);
                let paths = &pass.paths;
                if self.settings.connections && own + 1 < paths.ends.len() {
                    let (start, end) = (paths.ends[own] as usize, paths.ends[own + 1] as usize);
                    for z in &paths.vertices[start..end] {
                        l += self.connect(&v, z, f, wl, merges_here);
                    }
                }
                if merges_here && f.merge > 0.0 {
                    let merged = self.merge(&v, pass, work);
                    work.merged += merged;
                    l += merged;
                }
            }
            let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) else {
                break;
            };
            let cos_out = bsdf.normal().dot(sample.wi).abs();
            smooth_before |= !sample.specular;
            if sample.specular {
                partial.scatter_specular(cos_out);
                if let Some(with) = with_first_merge.as_mut() {
                    with.scatter_specular(cos_out);
                }
                without_last_merge = partial;
                if length == 1 {
                    without_first_merge = partial;
                }
                last_pdf = None;
            } else {
                let reverse = self.light_pdf(&bsdf, hit.point, wo, bsdf.pdf_reverse(wo, sample.wi));
                without_last_merge = partial;
                without_last_merge.scatter(f, sample.pdf, reverse, cos_out, false);
                if length == 1 {
                    without_first_merge = without_last_merge;
                    // An emitter hit next is direct light at the first vertex: no light tracing
                    // there either (its term is the sum's first at the eye's first vertex).
                    without_last_merge = Partial { vcm: 0.0, ..partial };
                    without_last_merge.scatter(f, sample.pdf, reverse, cos_out, false);
                }
                partial.scatter(f, sample.pdf, reverse, cos_out, merges_here);
                last_pdf = Some(sample.pdf);
            }
            throughput *= sample.weight;
            if sample.dispersive {
                wl.terminate_secondary(&mut throughput, &mut dispersed);
            }
            if length >= ROULETTE_DEPTH {
                let q = throughput.max_element().min(0.95);
                if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
                    break;
                }
                throughput /= q;
            }
            previous = hit.point;
            ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
        }
        if l.is_finite() {
            l
        } else {
            Spectrum::ZERO
        }
    }

    /// What a camera path leaving `from` in `dir` after `length` segments sees of the sky and
    /// suns: those that start light subpaths weighed against every strategy (`camera`: the
    /// sums without merging at the last vertex, where light arrives first), any other against
    /// next-event estimation alone, as in the path tracer (`last_pdf`: the last bounce's).
    fn escaped(
        &self,
        dir: Vec3,
        from: Vec3,
        last_pdf: Option<f32>,
        camera: &Partial,
        length: u32,
        wl: &Wavelengths,
    ) -> Spectrum {
        let lights = self.scene.lights();
        let mut l = lights.escaped_weighted_except(dir, last_pdf, wl, |number| self.emitters.emits(number));
        for number in 0..lights.len() {
            if let Some((radiance, direct, emission)) = self.emitters.far_seen(self.scene, number, from, dir) {
                let weight = if length == 1 {
                    1.0
                } else {
                    mis::emitter_hit(
                        camera,
                        direct * self.direct_samples(number, length - 1) as f32,
                        emission,
                    )
                };
                l += wl.unbounded(radiance) * weight;
            }
        }
        l
    }

    /// The weight of an emitter the camera path hit after `length` segments.
    fn emitter_weight(&self, hit: &SurfaceHit, camera: &Partial, from: Vec3, wo: Vec3, d2: f32, length: u32) -> f32 {
        if length == 1 {
            return 1.0;
        }
        let lights = self.scene.lights();
        let Some((number, light)) = lights.area_light_of(hit) else {
            return 1.0;
        };
        if !self.emitters.emits(number) {
            return 1.0;
        }
        let normal = hit.geometric_normal;
        // Next-event estimation at the vertex before took this many samples.
        let samples = self.direct_samples(number, length - 1) as f32;
        let direct = samples
            * lights.direct_probability(number)
            * light.pdf_towards(from, hit.point, normal)
            * normal.dot(wo).abs()
            / d2;
        let emission = self.emitters.emission_pdf(number, light, hit.point, normal, wo);
        mis::emitter_hit(camera, direct, emission)
    }

    /// The density with which a light subpath leaves a vertex at `point`, with `bsdf`, in `dir`
    /// where the BSDF alone draws it with density `plain`: on a Lambertian surface, the mixture
    /// with the cones aimed at mirrors and glass ([`BOUNCE_AIM_SHARE`]).
    fn light_pdf(&self, bsdf: &Bsdf, point: Vec3, dir: Vec3, plain: f32) -> f32 {
        match &self.bounce_aim {
            Some(aim) if bsdf.is_lambertian() => (1.0 - aim.share()) * plain + aim.share() * aim.pdf(point, dir),
            _ => plain,
        }
    }

    /// Next-event samples of emitter `number` at the camera vertex `length` segments from the
    /// eye: [`FIRST_VERTEX_LIGHT_SAMPLES`] for a light with a size at the first, whose penumbrae
    /// the eye sees directly.
    fn direct_samples(&self, number: usize, length: u32) -> u32 {
        match self.scene.lights().get(number) {
            Some(crate::light::Light::Area(_)) if length == 1 => FIRST_VERTEX_LIGHT_SAMPLES,
            _ => 1,
        }
    }

    /// Next-event estimation at a camera vertex: every light when there are few, else one by
    /// power (as the path tracer).
    fn direct(
        &self,
        v: &CameraVertex,
        f: &Factors,
        wl: &Wavelengths,
        rng: &mut Rng,
        work: &mut CameraWork,
    ) -> Spectrum {
        if v.length + 1 > self.max_length {
            return Spectrum::ZERO;
        }
        let lights = self.scene.lights();
        let mut l = Spectrum::ZERO;
        let mut one = |number: usize, pick: f32, rng: &mut Rng| {
            work.rays += 1;
            if self.emitters.emits(number) {
                let samples = self.direct_samples(number, v.length);
                for _ in 0..samples {
                    let choice = lights.direct_probability(number);
                    let Some(s) = lights.sample_light(number, choice, self.scene, v.hit, wl, rng) else {
                        continue;
                    };
                    let value = v.bsdf.eval(v.wo, s.wi);
                    if value == Spectrum::ZERO {
                        continue;
                    }
                    let cos_here = v.bsdf.normal().dot(s.wi).abs();
                    let pdfs = DirectPdfs {
                        bsdf: v.bsdf.pdf(v.wo, s.wi),
                        bsdf_reverse: self.light_pdf(v.bsdf, v.hit.point, v.wo, v.bsdf.pdf_reverse(v.wo, s.wi)),
                        // Several samples are one strategy of that many times the density.
                        direct: s.direct_pdf * samples as f32,
                        emission: self.emitters.emission_pdf_of(self.scene, number, &s, v.hit.point),
                        cos_here,
                        cos_light: s.cos_light,
                        delta: s.delta,
                    };
                    // Light reaches this vertex first: merging is no strategy here, and light
                    // tracing none either if it is the eye's first (the sum's first term there).
                    let camera = if v.length == 1 {
                        Partial { vcm: 0.0, ..v.partial }
                    } else {
                        v.partial
                    };
                    let weight = mis::direct(f, &camera, &pdfs, false);
                    l += v.throughput * value * s.contribution * (cos_here * weight / samples as f32);
                }
            } else if let Some(s) = lights.sample_light(number, pick, self.scene, v.hit, wl, rng) {
                // Far lights and lights with a size: the camera's strategies only.
                let value = v.bsdf.eval(v.wo, s.wi);
                let weight = if s.pdf > 0.0 {
                    power_heuristic(s.pdf, v.bsdf.pdf(v.wo, s.wi))
                } else {
                    1.0
                };
                l += v.throughput * value * s.contribution * (v.bsdf.normal().dot(s.wi).abs() * weight);
            }
        };
        if lights.samples_every_light() {
            for number in 0..lights.len() {
                if lights.direct_probability(number) > 0.0 {
                    one(number, 1.0, rng);
                }
            }
        } else if let Some((number, pick)) = lights.pick_for_direct(rng.uniform()) {
            one(number, pick, rng);
        }
        l
    }

    /// A connection between a camera vertex and a light vertex (`camera_merges`: merging is a
    /// strategy at the camera vertex).
    fn connect(
        &self,
        v: &CameraVertex,
        z: &LightVertex,
        f: &Factors,
        wl: &Wavelengths,
        camera_merges: bool,
    ) -> Spectrum {
        if v.length + z.length + 1 > self.max_length {
            return Spectrum::ZERO;
        }
        let to = z.hit.point - v.hit.point;
        let d2 = to.length_squared();
        if !(d2 > 0.0 && d2.is_finite()) {
            return Spectrum::ZERO;
        }
        let dir = to / d2.sqrt();
        let camera_f = v.bsdf.eval(v.wo, dir);
        if camera_f == Spectrum::ZERO {
            return Spectrum::ZERO;
        }
        let light_bsdf = Bsdf::at(self.scene, &z.hit, z.wo, wl);
        let light_f = light_bsdf.eval(z.wo, -dir);
        if light_f == Spectrum::ZERO {
            return Spectrum::ZERO;
        }
        let cos_camera = v.bsdf.normal().dot(dir).abs();
        let cos_light = light_bsdf.normal().dot(dir).abs();
        let pdfs = ConnectionPdfs {
            camera_to_light: v.bsdf.pdf(v.wo, dir) * cos_light / d2,
            camera_reverse: self.light_pdf(v.bsdf, v.hit.point, v.wo, v.bsdf.pdf_reverse(v.wo, dir)),
            light_to_camera: self.light_pdf(&light_bsdf, z.hit.point, -dir, light_bsdf.pdf(z.wo, -dir)) * cos_camera
                / d2,
            light_reverse: light_bsdf.pdf_reverse(z.wo, -dir),
        };
        // The camera vertex is smooth, so merging is no strategy at the light vertex.
        let weight = mis::connection(f, &v.partial, &z.partial, &pdfs, (camera_merges, false));
        let (ng_c, ng_l) = (v.hit.geometric_normal, z.hit.geometric_normal);
        let side_c = if ng_c.dot(dir) >= 0.0 { ng_c } else { -ng_c };
        let side_l = if ng_l.dot(dir) <= 0.0 { ng_l } else { -ng_l };
        if !self.scene.segment_clear(v.hit.point, side_c, z.hit.point, side_l) {
            return Spectrum::ZERO;
        }
        let g = cos_camera * cos_light / d2;
        v.throughput * camera_f * light_f * z.throughput * (g * weight * both_dispersed(v.dispersed, z.dispersed))
    }

    /// Merging: the light vertices within the radius of a camera vertex, as a density estimate.
    fn merge(&self, v: &CameraVertex, pass: &PassData, work: &mut CameraWork) -> Spectrum {
        let mut sum = Spectrum::ZERO;
        let focused = v.length == 1 && self.focus().contains(v.hit.point);
        let ng = v.hit.geometric_normal;
        let f = &pass.factors;
        // Most camera vertices are Lambertian: their f and reverse density are the same for
        // every candidate.
        let lambertian = v.bsdf.lambertian(v.wo);
        // A light subpath's aimed cones do not depend on where its light came from.
        let (plain_share, aimed) = match (&self.bounce_aim, &lambertian) {
            (Some(aim), Some(_)) => (1.0 - aim.share(), aim.share() * aim.pdf(v.hit.point, v.wo)),
            _ => (1.0, 0.0),
        };
        pass.grid.query(v.hit.point, pass.radius, |slot| {
            work.candidates += 1;
            let z = &pass.merge_vertices[slot];
            if v.length + z.length > self.max_length || (focused && z.direct_caustic) {
                return;
            }
            // Light on another face (a wall's far side, a corner) is not light here.
            if z.normal.dot(ng) < 0.7 {
                return;
            }
            let (value, pdf, reverse) = match &lambertian {
                Some(l) => match l.pdf(z.wo) {
                    Some(pdf) => (l.f, pdf, l.reverse),
                    None => return,
                },
                None => {
                    let value = v.bsdf.eval(v.wo, z.wo);
                    if value == Spectrum::ZERO {
                        return;
                    }
                    (value, v.bsdf.pdf(v.wo, z.wo), v.bsdf.pdf_reverse(v.wo, z.wo))
                }
            };
            let reverse = plain_share * reverse + aimed;
            let weight = mis::merge(f, &v.partial, &z.partial, pdf, reverse);
            sum += value * z.throughput * (weight * both_dispersed(v.dispersed, z.dispersed));
        });
        v.throughput * sum / (std::f32::consts::PI * pass.radius * pass.radius * f.light_paths)
    }
}

/// A light subpath's next direction at a surface with `bsdf` seen from `wo`: from the BSDF, or
/// with `aim` from the mixture of the BSDF and the cones towards the mirrors and glass (its
/// weight and density the mixture's). Also whether the direction lies in an aimed cone.
fn light_bounce(bsdf: &Bsdf, point: Vec3, wo: Vec3, aim: Option<&Aim>, rng: &mut Rng) -> Option<(BsdfSample, bool)> {
    let Some(aim) = aim else {
        return bsdf
            .sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance)
            .map(|s| (s, false));
    };
    let wi = if rng.uniform() < aim.share() {
        aim.sample(point, rng.uniform(), rng.uniform2())?
    } else {
        bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance)?
            .wi
    };
    let aimed = aim.pdf(point, wi);
    let pdf = (1.0 - aim.share()) * bsdf.pdf(wo, wi) + aim.share() * aimed;
    let value = bsdf.eval(wo, wi);
    if pdf.is_nan() || pdf <= 0.0 || value == Spectrum::ZERO {
        return None;
    }
    let sample = BsdfSample {
        wi,
        weight: value * (bsdf.normal().dot(wi).abs() / pdf),
        pdf,
        specular: false,
        transmitted: false,
        dispersive: false,
    };
    Some((sample, aimed > 0.0))
}

/// Light subpaths per pass when not given, for a `width`×`height` image.
pub fn default_light_paths(width: usize, height: usize) -> u64 {
    ((width * height) as u64 * LIGHT_PATHS_PER_PIXEL).clamp(1, MAX_DEFAULT_LIGHT_PATHS)
}

/// The mean of a colour's channels, in the image's units.
fn channel_mean(rgb: Vec3) -> f64 {
    if rgb.is_finite() {
        (rgb.x as f64 + rgb.y as f64 + rgb.z as f64) / 3.0
    } else {
        0.0
    }
}

/// Both subpaths kept only the hero wavelength, so each scaled it by the number of wavelengths:
/// one of the factors goes.
fn both_dispersed(a: bool, b: bool) -> f32 {
    if a && b {
        1.0 / SAMPLES as f32
    } else {
        1.0
    }
}

impl Progressive for Vcm<'_> {
    /// Its share of a full pass's light subpaths (their tracing takes most of a pass; the
    /// camera paths' fixed part makes a half pass a little dearer than this says, so a time
    /// limit's plan errs on the short side).
    fn pass_cost(&self, pass: u64) -> f64 {
        self.pass_light_paths(pass) as f64 / self.full_pass_paths() as f64
    }

    /// Light tracing and merging carry most of the image, and their noise falls with the
    /// number of light subpaths.
    fn pass_weight(&self, pass: u64) -> f64 {
        self.pass_cost(pass)
    }

    /// The balance pilot's count (the setting's when given).
    fn chosen_paths_per_pass(&self) -> Option<u64> {
        Some(self.full_pass_paths())
    }

    /// From the last pass's time per light subpath; before any pass, from the pilot run's
    /// (run here if it has not been) times [`PILOT_TO_PASS_COST`].
    fn share_within(&self, _pass: u64, seconds: f64) -> Option<f64> {
        if self.scene.lights().is_empty() || self.emitters.is_empty() {
            return None;
        }
        let start = std::time::Instant::now();
        self.focus();
        self.full_pass_paths();
        let left = seconds - start.elapsed().as_secs_f64();
        let last = *self.timing.lock().unwrap_or_else(|e| e.into_inner());
        let per_path = match (last, self.balance_seconds.get()) {
            (Some(t), _) => t.seconds_per_light_path,
            (None, Some(&balanced)) => balanced,
            (None, None) => self.pilot_seconds.get().copied().unwrap_or(0.0) * PILOT_TO_PASS_COST,
        };
        let full = per_path * self.full_pass_paths() as f64;
        Some(if full > 0.0 {
            (left / full).max(0.0)
        } else {
            f64::INFINITY
        })
    }

    fn render_share(&self, pass: u64, share: f64, control: Control) -> Option<Vec<Vec3>> {
        // A pass stretched to a time limit ends a run that had no room for the next (at most a
        // full one): it stays within twice a full pass's memory.
        let full = self.full_pass_paths() as f64;
        let count = (share * full).round().clamp(1.0, 2.0 * full);
        self.render_light_paths(pass, count as u64, control)
    }

    fn render_pass(&self, pass: u64, control: Control) -> Option<Vec<Vec3>> {
        self.render_light_paths(pass, self.pass_light_paths(pass), control)
    }
}

impl Vcm<'_> {
    /// Pass `pass` with `count` light subpaths.
    fn render_light_paths(&self, pass: u64, count: u64, control: Control) -> Option<Vec<Vec3>> {
        let wl = pass_wavelengths(self.spectral, self.seed, pass);
        if self.scene.lights().is_empty() {
            return Some(vec![Vec3::ZERO; self.width * self.height]);
        }
        // The pilot run, once, before the passes' parallel work asks for it.
        self.focus();
        let start = std::time::Instant::now();
        let radius = self.first_radius() * radius_factor(pass, self.settings.alpha);
        let f = Factors::new(radius, count as f32);
        // Another pass running at the same time (not the session's way) gets fresh memory.
        let mut scratch = self
            .scratch
            .try_lock()
            .map(|mut s| std::mem::take(&mut *s))
            .unwrap_or_default();
        if self.emitters.is_empty() {
            scratch.paths.clear();
        } else {
            self.light_paths((pass, count), &f, &wl, true, control.cancel, &mut scratch)?;
        }
        let paths = std::mem::take(&mut scratch.paths);
        let pass_data = PassData::arrange(
            paths,
            std::mem::take(&mut scratch.grid),
            std::mem::take(&mut scratch.merge_vertices),
            f,
            radius,
        );
        let camera = &self.camera;
        let (w, h) = (self.width, self.height);
        let focus_pixels = self.focus_pixels();
        let (mut film, complete) = shade_tiles(w, h, control, false, |x, y| {
            let pixel = y * w + x;
            let mut rng = Rng::new(self.seed, (pass << 32) ^ pixel as u64);
            let own = pixel % count as usize;
            let samples = if focus_pixels[pixel] {
                self.settings.focus_samples.max(1)
            } else {
                1
            };
            let mut sum = Vec3::ZERO;
            let mut work = CameraWork::default();
            for _ in 0..samples {
                let (jx, jy) = (rng.uniform(), rng.uniform());
                let ray = camera.generate_ray((x as f32 + jx) / w as f32, 1.0 - (y as f32 + jy) / h as f32);
                let v = wl.to_rgb(self.camera_path(ray, &pass_data, own, &wl, &mut rng, &mut work));
                if v.is_finite() {
                    sum += v;
                }
            }
            sum / samples as f32
        });
        if !complete {
            return None;
        }
        for &(pixel, value) in &pass_data.paths.splats {
            film[pixel as usize] += value;
        }
        scratch.paths = pass_data.paths;
        scratch.grid = pass_data.grid;
        scratch.merge_vertices = pass_data.merge_vertices;
        if let Ok(mut kept) = self.scratch.try_lock() {
            *kept = scratch;
        }
        let seconds = start.elapsed().as_secs_f64();
        *self.timing.lock().unwrap_or_else(|e| e.into_inner()) = Some(PassTiming {
            seconds_per_light_path: seconds / count as f64,
        });
        Some(film)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::aim::Target;
    use crate::material::{Lobes, SurfaceParams};

    /// A light subpath's bounce off a Lambertian surface with a share aimed at a sphere: every
    /// weight is f·cos over the mixture's density, the mean weight is the albedo, and the light
    /// sent into the sphere's cone is the same as without aiming, carried by many more samples.
    #[test]
    fn aimed_bounces_carry_the_bsdfs_light() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.3, -0.4, 0.866).normalize();
        let params = SurfaceParams {
            diffuse: Vec3::splat(0.7),
            ..SurfaceParams::default()
        };
        let bsdf = Bsdf::new(&Lobes::new(&params), n, n, wo, &Wavelengths::Rgb, None, None);
        assert!(bsdf.is_lambertian());
        let point = Vec3::ZERO;
        let target = Target {
            center: Vec3::new(1.0, 0.5, 0.8),
            radius: 0.3,
        };
        let aim = Aim::new(&[target], 0.3).unwrap();
        let (axis, cos_max) = target.cone_from(point);
        let count = 400_000;
        // (mean weight, mean weight into the cone, share of samples into the cone)
        let run = |aim: Option<&Aim>, seed: u64| {
            let mut rng = Rng::new(seed, 0);
            let (mut all, mut into, mut hits) = (0.0f64, 0.0f64, 0u32);
            for _ in 0..count {
                let Some((s, towards)) = light_bounce(&bsdf, point, wo, aim, &mut rng) else {
                    continue;
                };
                let inside = s.wi.dot(axis) >= cos_max;
                assert_eq!(towards, aim.is_some() && inside, "{s:?}");
                let plain = bsdf.pdf(wo, s.wi);
                let pdf = aim.map_or(plain, |a| (1.0 - a.share()) * plain + a.share() * a.pdf(point, s.wi));
                assert!((s.pdf - pdf).abs() <= 1e-5 * pdf, "{} against {pdf}", s.pdf);
                let expected = bsdf.eval(wo, s.wi) * (s.wi.z / pdf);
                assert!((s.weight - expected).length() <= 1e-4 * expected.length(), "{s:?}");
                all += s.weight.x as f64;
                if inside {
                    into += s.weight.x as f64;
                    hits += 1;
                }
            }
            (all / count as f64, into / count as f64, hits as f64 / count as f64)
        };
        let (plain_all, plain_into, plain_hits) = run(None, 1);
        let (aimed_all, aimed_into, aimed_hits) = run(Some(&aim), 2);
        assert!((plain_all - 0.7).abs() < 0.005, "{plain_all}");
        assert!((aimed_all - 0.7).abs() < 0.005, "{aimed_all}");
        assert!(
            (aimed_into / plain_into - 1.0).abs() < 0.02,
            "into the cone: aimed {aimed_into} against {plain_into}"
        );
        assert!(aimed_hits > 5.0 * plain_hits, "{aimed_hits} against {plain_hits}");
    }
}
