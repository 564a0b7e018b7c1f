//! Light tracing (a particle tracer): photons leave the lights as in [`ppm`](super::ppm), and
//! at every smooth surface they meet the light they scatter towards the eye is splatted onto the
//! pixel the point projects to. No kernel and no radius: the image is unbiased, and sharp where
//! photon mapping blurs (the focus of a caustic), but noisy where little light reaches the eye.
//!
//! A light with an area is seen directly: each photon's starting point is joined to the eye.
//! The camera is a pinhole, so a camera ray can never be continued from a photon path: mirrors
//! and glass seen by the camera are black (as in `--no-camera-specular`), and so are point
//! lights. What lies behind or beyond them, seen by a photon, is not.
//!
//! Determinism: a pass emits its photons in fixed batches; each batch records its splats and the
//! batches are added to the film in index order, so the thread count never changes the image.

use super::ppm::{pass_wavelengths, settings_spectral, PHOTON_SEED};
use super::Progressive;
use crate::bsdf::{Bsdf, Transport};
use crate::camera::Camera;
use crate::light::emission::EmissionPoint;
use crate::math::{offset_origin, Ray, Vec3};
use crate::photon::light_walk::{
    light_waves, walk_together, LightArrival, LightPath, LightVisitor, LightWalk, MediumArrival, Walker,
};
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use rayon::prelude::*;

/// Mixed into the seed of the streams shadow rays to the eye draw from.
const EYE_SEED: u64 = 0x6579_6573_6861_646f;

/// Settings of the light tracer.
#[derive(Clone, Debug, PartialEq)]
pub struct LtSettings {
    /// Photons emitted per pass.
    pub photons_per_pass: u64,
    /// `--depth` N: photons make at most N bounces before the surface they are seen on, so
    /// light reaches the eye after scattering at no more than N + 1 surfaces
    /// ([`scattering_surfaces`](super::config::scattering_surfaces)), the same paths as
    /// `ppm`'s photons.
    pub max_depth: u32,
    /// Carry light at sampled wavelengths instead of RGB (`None`: when the scene has a
    /// dispersive glass).
    pub spectral: Option<bool>,
}

impl Default for LtSettings {
    fn default() -> Self {
        LtSettings {
            photons_per_pass: 200_000,
            max_depth: 64,
            spectral: None,
        }
    }
}

/// Photons per batch: the unit of parallel work and of the fixed order of addition.
const BATCH: u64 = 4096;
/// Batches traced before their splats are added, so memory stays bounded at any photon count.
const ROUND: u64 = 64;

/// Where on the film a point is seen, and how much importance the eye gives it.
pub struct Sensor {
    /// The camera fitted to the film ([`Camera::fitted`]).
    camera: Camera,
    eye: Vec3,
    /// Unit normal of the image plane (towards the scene).
    normal: Vec3,
    /// W·H·d² / |u × v|: pixels per unit of image-plane area times the plane's distance squared.
    scale: f32,
    width: usize,
    height: usize,
}

/// A point's pixel and the factor that turns the light it sends to the eye into that pixel's
/// value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SensorSample {
    /// Pixel index, rows from the top.
    pub pixel: usize,
    /// Unit direction from the point to the eye.
    pub to_eye: Vec3,
    /// Distance from the point to the eye.
    pub distance: f32,
    /// The camera's importance We along the direction (per steradian).
    pub importance: f32,
}

impl Sensor {
    /// The sensor of `camera` with a film of `width`×`height` pixels (the camera fitted to it).
    pub fn new(camera: &Camera, width: usize, height: usize) -> Sensor {
        let camera = camera.fitted(width, height);
        let cross = camera.u.cross(camera.v);
        let area = cross.length();
        let normal = if area > 0.0 { cross / area } else { camera.look };
        let normal = if normal.dot(camera.look) < 0.0 { -normal } else { normal };
        let d = camera.look.dot(normal);
        let scale = if area > 0.0 && d > 0.0 {
            (width * height) as f32 * d * d / area
        } else {
            0.0
        };
        Sensor {
            eye: camera.eye,
            camera,
            normal,
            scale,
            width,
            height,
        }
    }

    /// The importance We of a unit direction leaving the eye (0 behind the image plane): also
    /// the solid-angle density of that direction among one sample per pixel.
    pub fn importance(&self, dir: Vec3) -> f32 {
        let cos = dir.dot(self.normal);
        if cos <= 0.0 {
            0.0
        } else {
            self.scale / (cos * cos * cos)
        }
    }

    /// Where `p` lands on the film (`None`: outside the view or behind the eye).
    ///
    /// A pixel's value is the mean radiance over its square of screen coordinates (sx, sy),
    /// of area 1/(W·H). Screen point (sx, sy) lies on the image plane at
    /// eye + look + (sx − ½)·u + (sy − ½)·v, so dA = |u × v| dsx dsy; seen from the eye
    /// dω = cos θ dA / ℓ² with ℓ = d / cos θ (d: the plane's distance, θ: the angle to its
    /// normal). So the pixel is ∫ W·H·d² / (|u × v| cos³θ) · L dω over its directions, and
    /// that factor is the importance We (docs/radiometry.md).
    pub fn sample(&self, p: Vec3) -> Option<SensorSample> {
        let camera = &self.camera;
        if self.scale <= 0.0 {
            return None;
        }
        // Through a thin lens: from a lens point drawn from p's bits, the pixel is where the ray
        // from it through p meets the focus plane, seen from the eye; the importance is the
        // pinhole's from that lens point (the lens's area and its density cancel).
        let (eye, seen) = match camera.lens {
            None => (self.eye, p),
            Some(lens) => {
                let l = camera.lens_point(lens, crate::camera::hash_point(&[p.x, p.y, p.z]));
                let w = p - l;
                let along = w.dot(self.normal);
                if along <= 0.0 {
                    return None;
                }
                (l, l + w * (lens.focus / along))
            }
        };
        let (sx, sy) = camera.project(seen)?;
        let x = sx * self.width as f32;
        let y = (1.0 - sy) * self.height as f32;
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
            return None;
        }
        let offset = eye - p;
        let distance = offset.length();
        if distance.is_nan() || distance <= 0.0 {
            return None;
        }
        let to_eye = offset / distance;
        let cos = -to_eye.dot(self.normal);
        if cos <= 0.0 {
            return None;
        }
        let (px, py) = ((x as usize).min(self.width - 1), (y as usize).min(self.height - 1));
        Some(SensorSample {
            pixel: py * self.width + px,
            to_eye,
            distance,
            importance: self.scale / (cos * cos * cos),
        })
    }
}

/// The light tracer over a whole image.
pub struct LightTracer<'a> {
    scene: &'a Scene,
    settings: LtSettings,
    width: usize,
    height: usize,
    seed: u64,
    sensor: Sensor,
    spectral: bool,
}

impl<'a> LightTracer<'a> {
    /// A light tracer for `scene` at `width`×`height`.
    pub fn new(scene: &'a Scene, settings: LtSettings, width: usize, height: usize, seed: u64) -> LightTracer<'a> {
        LightTracer {
            scene,
            sensor: Sensor::new(scene.camera(), width, height),
            spectral: settings_spectral(&settings.spectral, scene),
            settings,
            width,
            height,
            seed,
        }
    }

    /// Starts photon `index` of pass `pass`: records what the light's own point sends to the
    /// eye into `out`, and returns its walk, which records what each smooth surface it meets
    /// sends there, in film units (already divided by the pass's photon count).
    #[inline]
    fn start<'t>(
        &'t self,
        (pass, index): (u64, u64),
        wl: &'t Wavelengths,
        out: &'t mut Vec<(u32, Vec3)>,
    ) -> Option<LightPath<Splats<'t, 'a>>> {
        let scene = self.scene;
        let mut rng = Rng::new(self.seed ^ PHOTON_SEED, (pass << 40) ^ index);
        let emitted = scene.lights().emit(scene, wl, &mut rng)?;
        let share = 1.0 / self.settings.photons_per_pass as f32;
        // Shadow rays to the eye draw from a stream of their own (transmittance through a grid).
        let mut eye_rng = Rng::new(self.seed ^ EYE_SEED, (pass << 40) ^ index);
        let medium = scene.light_medium(emitted.light);
        if let Some(origin) = &emitted.origin {
            if let Some((pixel, value)) = self.connect_light(origin, medium, share, wl, &mut eye_rng) {
                let rgb = wl.to_rgb(value);
                if rgb.is_finite() {
                    out.push((pixel as u32, rgb));
                }
            }
        }
        // The walk's photons carry flux, as the photon tracer's do.
        let surfaces = self.settings.max_depth.saturating_add(1);
        Some(Walker {
            walk: LightWalk::new(scene, emitted.ray, (emitted.throughput * share, medium), surfaces),
            wl: *wl,
            rng,
            visitor: Splats {
                tracer: self,
                wl,
                out,
                rng: eye_rng,
            },
        })
    }

    /// Follows the photons `indices` of pass `pass`, a wave at a time, and returns what they
    /// add to the film, in photon order.
    fn trace(&self, pass: u64, indices: std::ops::Range<u64>, wl: &Wavelengths) -> Vec<(u32, Vec3)> {
        let mut out = Vec::new();
        let mut own: Vec<Vec<(u32, Vec3)>> = Vec::new();
        for wave in light_waves(self.scene.streams_pay(), indices) {
            if wave.end - wave.start == 1 {
                // One path a wave: straight into the batch's list.
                let mut path = self.start((pass, wave.start), wl, &mut out);
                walk_together(self.scene, path.as_mut_slice());
                continue;
            }
            // Each path splats into its own list, appended in photon order.
            own.resize_with(wave.clone().count(), Vec::new);
            let mut paths: Vec<_> = wave
                .zip(&mut own)
                .filter_map(|(i, path_out)| self.start((pass, i), wl, path_out))
                .collect();
            walk_together(self.scene, &mut paths);
            own.iter_mut().for_each(|path_out| out.append(path_out));
        }
        out
    }

    /// The pixel a photon of flux `power` arriving at `hit` from `wo` lights, and by how much:
    /// power · f(wo, ωe) · cos θ / r² · We, where θ is the angle at the surface to the eye
    /// direction ωe and r the distance to the eye (the geometry term, the pinhole being a
    /// point), and We the camera's importance ([`Sensor::sample`]). With shading normals the
    /// adjoint BSDF needs Veach's correction |wo·ns| |ωe·ng| / (|wo·ng| |ωe·ns|), so the cosine
    /// becomes |ωe·ng| |wo·ns| / |wo·ng|.
    fn connect(
        &self,
        hit: &SurfaceHit,
        bsdf: &Bsdf,
        wo: Vec3,
        power: Spectrum,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Option<(usize, Spectrum)> {
        let s = self.sensor.sample(hit.point)?;
        let f = bsdf.eval_in(wo, s.to_eye, Transport::Importance);
        if f == Spectrum::ZERO {
            return None;
        }
        let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
        let wo_ng = wo.dot(ng).abs();
        if wo_ng <= 0.0 {
            return None;
        }
        let cos = s.to_eye.dot(ng).abs() * wo.dot(ns).abs() / wo_ng;
        if !self.scene.unoccluded(hit, s.to_eye, s.distance) {
            return None;
        }
        let g = cos / (s.distance * s.distance);
        Some((s.pixel, power * f * self.to_eye(hit, &s, wl, rng) * (g * s.importance)))
    }

    /// As [`LightTracer::connect`] from a scattering point in a medium: its phase function in
    /// place of f · cos.
    fn connect_medium(&self, at: &MediumArrival, wl: &Wavelengths, rng: &mut Rng) -> Option<(usize, Spectrum)> {
        let s = self.sensor.sample(at.hit.point)?;
        let p = at.phase.eval(at.wo, s.to_eye);
        if p <= 0.0 || !self.scene.unoccluded(at.hit, s.to_eye, s.distance) {
            return None;
        }
        let g = 1.0 / (s.distance * s.distance);
        Some((
            s.pixel,
            at.throughput * self.to_eye(at.hit, &s, wl, rng) * (p * g * s.importance),
        ))
    }

    /// What the media between `hit` and the eye keep of the light (1 without media).
    #[inline]
    fn to_eye(&self, hit: &SurfaceHit, s: &SensorSample, wl: &Wavelengths, rng: &mut Rng) -> Spectrum {
        if self.scene.has_media() {
            self.scene.transmittance_towards(hit, s.to_eye, s.distance, wl, rng)
        } else {
            Spectrum::ONE
        }
    }
}

/// A light tracer's walk: every smooth surface it meets is joined to the eye and splatted.
struct Splats<'t, 'a> {
    tracer: &'t LightTracer<'a>,
    wl: &'t Wavelengths,
    out: &'t mut Vec<(u32, Vec3)>,
    rng: Rng,
}

impl Splats<'_, '_> {
    fn push(&mut self, splat: Option<(usize, Spectrum)>) {
        if let Some((pixel, value)) = splat {
            let rgb = self.wl.to_rgb(value);
            if rgb.is_finite() {
                self.out.push((pixel as u32, rgb));
            }
        }
    }
}

impl LightVisitor for Splats<'_, '_> {
    fn visit(&mut self, at: &LightArrival) -> bool {
        if at.bsdf.is_smooth() {
            let splat = self
                .tracer
                .connect(at.hit, at.bsdf, at.wo, at.throughput, self.wl, &mut self.rng);
            self.push(splat);
        }
        true
    }

    fn visit_medium(&mut self, at: &MediumArrival) -> bool {
        let splat = self.tracer.connect_medium(at, self.wl, &mut self.rng);
        self.push(splat);
        true
    }
}

impl LightTracer<'_> {
    /// The pixel the light's own point `origin` shows in, and what it adds there (the light seen
    /// directly): L/p(x) · |cos θ| / r² · We, times this photon's `share` of the pass.
    fn connect_light(
        &self,
        origin: &EmissionPoint,
        medium: u32,
        share: f32,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Option<(usize, Spectrum)> {
        let s = self.sensor.sample(origin.point)?;
        if !origin.faces.emit_towards(origin.normal, s.to_eye) {
            return None;
        }
        let ray = Ray::new(offset_origin(origin.point, origin.normal, s.to_eye), s.to_eye);
        let t_max = (s.distance - (ray.origin - origin.point).length()) * (1.0 - 1e-5);
        if self.scene.any_hit(&ray, t_max, |h| !self.scene.is_boundary(h)) {
            return None;
        }
        let g = origin.normal.dot(s.to_eye).abs() / (s.distance * s.distance);
        let kept = self.to_eye(&SurfaceHit::in_medium(ray.origin, medium), &s, wl, rng);
        Some((s.pixel, origin.radiance * kept * (share * g * s.importance)))
    }
}

impl Progressive for LightTracer<'_> {
    fn render_pass(&self, pass: u64, control: Control) -> Option<Vec<Vec3>> {
        let wl = pass_wavelengths(self.spectral, self.seed, pass);
        let mut film = vec![Vec3::ZERO; self.width * self.height];
        let count = self.settings.photons_per_pass;
        if self.scene.lights().is_empty() {
            return Some(film);
        }
        let batches = count.div_ceil(BATCH);
        let mut first = 0;
        while first < batches {
            let end = (first + ROUND).min(batches);
            let splats: Vec<Option<Vec<(u32, Vec3)>>> = (first..end)
                .into_par_iter()
                .map(|b| {
                    if control.cancelled() {
                        return None;
                    }
                    Some(self.trace(pass, b * BATCH..((b + 1) * BATCH).min(count), &wl))
                })
                .collect();
            // In batch order: the sums do not depend on which thread traced what.
            for batch in splats {
                for (pixel, value) in batch? {
                    film[pixel as usize] += value;
                }
            }
            first = end;
        }
        Some(film)
    }
}
