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
mod beams;
mod camera_paths;
pub mod focus;
pub mod grid;
mod light_subpaths;
mod merging;
pub mod mis;
mod pilots;
mod settings;

use super::camera_walk::{bounce_as_surface, visit_as_surface, CameraArrival, CameraPath, CameraVisitor, CameraWalk};
use super::lt::Sensor;
use super::ppm::{pass_wavelengths, settings_spectral, PHOTON_SEED};
use super::radius::{radius_factor, InitialRadius};
use super::tiles::{shade_tile_blocks, shade_tiles};
use super::Progressive;
use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::light::aim::{caustic_targets, Aim};
use crate::light::emission::{Emission, Emitters};
use crate::math::{Ray, Vec3};
use crate::photon::kd_tree::{KdPoint, KdTree};
use crate::photon::light_walk::{walk_together, LightArrival, LightVisitor, Roulette};
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

use camera_paths::{both_dispersed, camera_radiance};
use pilots::PILOT_TO_PASS_COST;
pub use settings::*;

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

/// A light vertex in a medium that camera rays gather along their way ([`beams`]).
#[derive(Clone, Copy, Debug)]
struct VolumeVertex {
    point: Vec3,
    wo: Vec3,
    throughput: Spectrum,
    /// Light reaching it first: the subpath's first MIS sum (next-event estimation against
    /// it, distance densities left out) and its distance from the light ([`beams::direct_share`]);
    /// 0 after a bounce.
    direct: (f32, f32),
    medium: u32,
    length: u32,
    dispersed: bool,
}

impl KdPoint for VolumeVertex {
    #[inline]
    fn position(&self) -> Vec3 {
        self.point
    }
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
    /// Every light vertex in a medium that may be merged, in the kd-tree's order once arranged.
    volume_vertices: Vec<VolumeVertex>,
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
        self.volume_vertices.clear();
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
        self.volume_vertices.extend_from_slice(&batch.volume_vertices);
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
    /// Over `paths.volume_vertices`, for the camera rays' beam queries.
    volume_tree: KdTree,
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
        mut paths: LightPaths,
        mut grid: HashGrid,
        mut merge_vertices: Vec<MergeVertex>,
        factors: Factors,
        radius: f32,
    ) -> PassData {
        grid.rebuild(&paths.merge_points, radius);
        merge_vertices.clear();
        merge_vertices.extend(grid.order().iter().map(|&i| paths.merge_vertices[i as usize]));
        let volume_tree = KdTree::build(&mut paths.volume_vertices);
        PassData {
            paths,
            grid,
            merge_vertices,
            volume_tree,
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
    /// A next-event sample taken where a beam query's segment was cut by a free flight
    /// ([`beams`]): the medium's largest σt and the distance from the segment's start.
    along: Option<(f32, f32)>,
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
    /// Some medium scatters (beam queries have something to gather; a glass that only absorbs
    /// casts no ray for them).
    scatters: bool,
    /// Where a share of the light subpaths' diffuse bounces is aimed.
    bounce_aim: Option<Aim>,
    spectral: bool,
    /// Longest path in segments (eye to light).
    max_length: u32,
    /// The settings' first merging radius in scene units: the pilots' (the focus cells are
    /// twice it); the passes start from [`Balance::radius`].
    pilot_radius: f32,
    /// Light subpaths in a full pass and the first pass's merging radius: the settings', or the
    /// balance pilot's ([`Progressive::prepare`]); `None` until then.
    balanced: Option<Balance>,
    /// The first [`RAMP_PASSES`] passes trace half the light subpaths (the default count only).
    ramp: bool,
    /// Where caustics are focused, from the focus pilot (empty until prepared).
    focus: CausticFocus,
    /// The pixels that see a focused cell, from rays through their centres (empty until
    /// prepared).
    focus_pixels: Vec<bool>,
    /// Light subpaths and a tile's camera subpaths walk together, a wave of rays per bounce
    /// (where streams pay, [`Scene::streams_pay`]), or one at a time: the same image.
    waves: bool,
    /// The last pass's memory, reused by the next.
    scratch: std::sync::Mutex<Scratch>,
    /// Seconds a pilot light subpath took, for sizing a first pass to a time limit.
    pilot_seconds: Option<f64>,
    /// How long the last pass took, for sizing the next to a time limit.
    timing: std::sync::Mutex<Option<PassTiming>>,
}

/// What the balance pilot chose.
#[derive(Clone, Copy, Debug)]
struct Balance {
    light_paths: u64,
    /// The first pass's merging radius in scene units.
    radius: f32,
    /// The balance pilot's estimate of a full pass's seconds per light subpath.
    seconds_per_light_path: Option<f64>,
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
            scatters: settings.beams && scene.scatters(),
            // Segments: one more than the surfaces light may scatter at.
            max_length: super::config::scattering_surfaces(settings.max_depth).saturating_add(1),
            pilot_radius: radius,
            balanced: None,
            ramp: settings.light_paths_per_pass.is_none(),
            settings,
            width,
            height,
            seed,
            focus: CausticFocus::default(),
            focus_pixels: Vec::new(),
            waves: scene.streams_pay(),
            scratch: std::sync::Mutex::default(),
            pilot_seconds: None,
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

    /// What the pilots chose (`None` before [`Progressive::prepare`]).
    fn balance(&self) -> Option<&Balance> {
        self.balanced.as_ref()
    }

    /// Light subpaths in a full pass: the setting's, or else the balance pilot's count (the
    /// default count before the pilots).
    fn full_pass_paths(&self) -> u64 {
        match (self.balance(), self.settings.light_paths_per_pass) {
            (Some(b), _) => b.light_paths,
            (None, Some(count)) => count.max(1),
            (None, None) => default_light_paths(self.width, self.height),
        }
    }

    fn pixels(&self) -> usize {
        self.width * self.height
    }
}

/// Light subpaths per pass when not given, for a `width`×`height` image.
pub fn default_light_paths(width: usize, height: usize) -> u64 {
    ((width * height) as u64 * LIGHT_PATHS_PER_PIXEL).clamp(1, MAX_DEFAULT_LIGHT_PATHS)
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

    /// The balance pilot's count (the setting's when given); `None` before the pilots.
    fn chosen_paths_per_pass(&self) -> Option<u64> {
        self.balance().map(|b| b.light_paths)
    }

    /// The focus and balance pilots, before the first pass.
    fn prepare(&mut self, control: Control) -> bool {
        self.run_pilots(control.cancel)
    }

    /// From the last pass's time per light subpath; before any pass, from the balance pilot's
    /// estimate, or the focus pilot's time times [`PILOT_TO_PASS_COST`].
    fn share_within(&self, _pass: u64, seconds: f64) -> Option<f64> {
        if self.scene.lights().is_empty() || self.emitters.is_empty() {
            return None;
        }
        let last = *self.timing.lock().unwrap_or_else(|e| e.into_inner());
        let balanced = self.balance().and_then(|b| b.seconds_per_light_path);
        let per_path = match (last, balanced) {
            (Some(t), _) => t.seconds_per_light_path,
            (None, Some(balanced)) => balanced,
            (None, None) => self.pilot_seconds.unwrap_or(0.0) * PILOT_TO_PASS_COST,
        };
        let full = per_path * self.full_pass_paths() as f64;
        Some(if full > 0.0 {
            (seconds / full).max(0.0)
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

/// A pixel's camera samples in a pass: its random stream, the light subpath it connects to,
/// the samples still to take and what they have added.
struct CameraPixel {
    rng: Rng,
    own: usize,
    samples: usize,
    left: usize,
    sum: Vec3,
    work: CameraWork,
}

impl CameraPixel {
    /// Its next sample's camera ray through pixel `(x, y)`, jittered.
    fn next_ray(&mut self, vcm: &Vcm, (x, y): (usize, usize)) -> Ray {
        self.left -= 1;
        let (jx, jy) = (self.rng.uniform(), self.rng.uniform());
        let (w, h) = (vcm.width as f32, vcm.height as f32);
        vcm.camera.generate_ray((x as f32 + jx) / w, 1.0 - (y as f32 + jy) / h)
    }

    /// Adds a sample's value (left out if not finite).
    fn add(&mut self, v: Vec3) {
        if v.is_finite() {
            self.sum += v;
        }
    }

    /// The mean of its samples.
    fn value(&self) -> Vec3 {
        self.sum / self.samples as f32
    }
}

impl Vcm<'_> {
    /// Pixel `(x, y)`'s camera samples in pass `pass` of `count` light subpaths: focus pixels
    /// take several.
    fn camera_pixel(&self, (x, y): (usize, usize), (pass, count): (u64, u64)) -> CameraPixel {
        let pixel = y * self.width + x;
        let samples = if self.focus_pixels[pixel] {
            self.settings.focus_samples.max(1)
        } else {
            1
        };
        CameraPixel {
            rng: Rng::new(self.seed, (pass << 32) ^ pixel as u64),
            own: pixel % count as usize,
            samples,
            left: samples,
            sum: Vec3::ZERO,
            work: CameraWork::default(),
        }
    }

    /// The pixels of the tile from `from` to `to` (exclusive), row by row: each round of
    /// samples walks together (a focus pixel's next sample starts where its stream left off).
    fn camera_tile(
        &self,
        (from, to): ((usize, usize), (usize, usize)),
        pass: (u64, u64),
        pass_data: &PassData,
        wl: &Wavelengths,
    ) -> Vec<Vec3> {
        let tw = to.0 - from.0;
        let at = |i: usize| (from.0 + i % tw, from.1 + i / tw);
        let mut pixels: Vec<CameraPixel> = (0..tw * (to.1 - from.1))
            .map(|i| self.camera_pixel(at(i), pass))
            .collect();
        let mut values = Vec::new();
        while pixels.iter().any(|p| p.left > 0) {
            let (mut paths, mut walking) = (Vec::new(), Vec::new());
            for (i, p) in pixels.iter_mut().enumerate().filter(|(_, p)| p.left > 0) {
                let ray = p.next_ray(self, at(i));
                match self.camera_subpath(ray, (pass_data, p.own), wl, p.rng.clone(), &mut p.work) {
                    Some(path) => {
                        paths.push(path);
                        walking.push(i);
                    }
                    None => values.push((i, None, Vec3::ZERO)),
                }
            }
            walk_together(self.scene, &mut paths);
            let walked = paths
                .into_iter()
                .map(|path| (Some(path.rng.clone()), wl.to_rgb(camera_radiance(path))));
            values.extend(walking.iter().zip(walked).map(|(&i, (rng, v))| (i, rng, v)));
            for (i, rng, v) in values.drain(..) {
                if let Some(rng) = rng {
                    pixels[i].rng = rng;
                }
                pixels[i].add(v);
            }
        }
        pixels.iter().map(CameraPixel::value).collect()
    }

    /// Pass `pass` with `count` light subpaths.
    fn render_light_paths(&self, pass: u64, count: u64, control: Control) -> Option<Vec<Vec3>> {
        let wl = pass_wavelengths(self.spectral, self.seed, pass);
        if self.scene.lights().is_empty() {
            return Some(vec![Vec3::ZERO; self.width * self.height]);
        }
        // Nothing to render with before the pilots have run.
        let first_radius = self.balance()?.radius;
        let start = std::time::Instant::now();
        let radius = first_radius * radius_factor(pass, self.settings.alpha);
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
        let (mut film, complete) = if self.waves {
            shade_tile_blocks(self.width, self.height, control, false, |from, to| {
                self.camera_tile((from, to), (pass, count), &pass_data, &wl)
            })
        } else {
            shade_tiles(self.width, self.height, control, false, |x, y| {
                let mut pixel = self.camera_pixel((x, y), (pass, count));
                while pixel.left > 0 {
                    let ray = pixel.next_ray(self, (x, y));
                    let v = self.camera_path(ray, &pass_data, pixel.own, &wl, &mut pixel.rng, &mut pixel.work);
                    pixel.add(wl.to_rgb(v));
                }
                pixel.value()
            })
        };
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
