//! A unidirectional path tracer with next-event estimation and multiple importance sampling
//! (power heuristic): the reference the photon-mapping integrators are checked against.
//!
//! It cannot see caustics of point or directional lights (a path can never hit a delta light
//! after a mirror or through glass); that is what photon mapping is for.

use super::direct::{direct_light, emitted, power_heuristic};
use crate::bsdf::{Bsdf, Transport};
use crate::math::{Ray, Vec3};
use crate::sampling::Rng;
use crate::scene::Scene;
use crate::spectrum::{Spectrum, Wavelengths};

/// Settings of the path tracer.
#[derive(Clone, Debug, PartialEq)]
pub struct PathSettings {
    /// Most surfaces a camera path scatters at, the first one it meets included: light reaches
    /// the eye from at most this many (0: only emission seen directly). Unlike the other
    /// integrators' `max_depth` this counts surfaces, not bounces after the first: `--depth` N
    /// sets it to N + 1 ([`scattering_surfaces`](super::config::scattering_surfaces)).
    pub max_depth: u32,
    /// Bounces before Russian roulette may end a path.
    pub roulette_depth: u32,
    /// Follow camera rays through mirrors and glass (off: what a camera sees by a mirror or
    /// through glass is black, as in a particle tracer's image — for comparing with one).
    pub specular_camera_paths: bool,
    /// Carry light at sampled wavelengths instead of RGB (`None`: when the scene has a
    /// dispersive glass).
    pub spectral: Option<bool>,
}

impl Default for PathSettings {
    fn default() -> Self {
        PathSettings {
            // `--depth`'s default, 64.
            max_depth: super::config::scattering_surfaces(64),
            roulette_depth: 3,
            specular_camera_paths: true,
            spectral: None,
        }
    }
}

/// Radiance arriving along `ray` (unit direction) at the wavelengths `wl`.
pub fn radiance(scene: &Scene, settings: &PathSettings, ray: Ray, wl: &Wavelengths, rng: &mut Rng) -> Spectrum {
    let lights = scene.lights();
    let mut ray = ray;
    let mut l = Spectrum::ZERO;
    let mut beta = wl.grey(1.0);
    let mut dispersed = false;
    // The last bounce's pdf and point, for weighting emitters that BSDF sampling hits.
    let mut specular = true;
    let mut last_pdf = 0.0f32;
    let mut last_point = ray.origin;
    for depth in 0..=settings.max_depth {
        let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
            // The sky and suns, weighted against having sampled them directly.
            l += beta * lights.escaped_weighted(ray.dir, (!specular).then_some(last_pdf), wl);
            break;
        };
        let hit = scene.surface(&ray, &isect);
        let wo = -ray.dir;
        let le = emitted(scene, &hit, wo, wl);
        if le != Spectrum::ZERO {
            let weight = if specular {
                1.0
            } else {
                power_heuristic(last_pdf, lights.pdf_direct(last_point, &hit))
            };
            l += beta * le * weight;
        }
        if depth == settings.max_depth {
            break;
        }
        let bsdf = Bsdf::at(scene, &hit, wo, wl);
        if bsdf.is_black() {
            break;
        }
        if bsdf.is_smooth() {
            l += beta * direct_light(scene, &hit, &bsdf, wo, true, wl, rng);
        }
        let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) else {
            break;
        };
        if depth == 0 && sample.specular && !settings.specular_camera_paths {
            break;
        }
        beta *= sample.weight;
        if sample.dispersive {
            wl.terminate_secondary(&mut beta, &mut dispersed);
        }
        specular = sample.specular;
        last_pdf = sample.pdf;
        last_point = hit.point;
        if depth + 1 >= settings.roulette_depth {
            let q = beta.max_element().min(0.95);
            if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
                break;
            }
            beta /= q;
        }
        ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
    }
    if l.is_finite() {
        l
    } else {
        Spectrum::ZERO
    }
}

/// The path tracer over a whole image, one sample per pixel per pass.
pub struct PathTracer<'a> {
    scene: &'a Scene,
    /// The scene's camera fitted to the image ([`Camera::fitted`]).
    camera: crate::camera::Camera,
    settings: PathSettings,
    width: usize,
    height: usize,
    seed: u64,
}

impl<'a> PathTracer<'a> {
    /// A path tracer for `scene` at `width`×`height`.
    pub fn new(scene: &'a Scene, settings: PathSettings, width: usize, height: usize, seed: u64) -> PathTracer<'a> {
        PathTracer {
            scene,
            camera: scene.camera().fitted(width, height),
            settings,
            width,
            height,
            seed,
        }
    }
}

impl super::Progressive for PathTracer<'_> {
    fn render_pass(&self, pass: u64, control: crate::progress::Control) -> Option<Vec<Vec3>> {
        let camera = &self.camera;
        let spectral = super::ppm::settings_spectral(&self.settings.spectral, self.scene);
        super::tiles::sample_pass(self.width, self.height, self.seed, pass, control, |sx, sy, rng| {
            // Each sample its own wavelengths: no photons need to agree with it.
            let wl = if spectral {
                Wavelengths::sample(rng.uniform())
            } else {
                Wavelengths::Rgb
            };
            wl.to_rgb(radiance(
                self.scene,
                &self.settings,
                camera.generate_ray(sx, sy),
                &wl,
                rng,
            ))
        })
    }
}
