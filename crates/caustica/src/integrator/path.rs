//! A unidirectional path tracer with next-event estimation and multiple importance sampling
//! (power heuristic): the reference the photon-mapping integrators are checked against.
//!
//! It cannot see caustics of point or directional lights (a path can never hit a delta light
//! after a mirror or through glass); that is what photon mapping is for.

use super::camera_walk::{walk_camera, CameraArrival, CameraPath, CameraVisitor, CameraWalk};
use super::direct::{direct_in_medium, direct_light, emitted, power_heuristic};
use super::tiles::PixelSample;
use crate::bsdf::{BsdfSample, Transport};
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::{walk_together, MediumArrival, Walker};
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
    let mut path = PathRadiance::new(scene, settings, &ray, *wl);
    walk_camera(scene, ray, wl, path.limits(), rng, &mut path);
    path.radiance()
}

/// A path tracer's walk: emission weighted against next-event estimation, which each smooth
/// vertex makes.
struct PathRadiance<'p> {
    scene: &'p Scene,
    settings: &'p PathSettings,
    wl: Wavelengths,
    /// Radiance gathered so far.
    l: Spectrum,
    /// The last bounce was specular (or the path just left the eye): emitters it hits count in
    /// full.
    specular: bool,
    /// The last bounce's pdf and point, for weighting emitters that BSDF sampling hits.
    last_pdf: f32,
    last_point: Vec3,
}

impl<'p> PathRadiance<'p> {
    /// Nothing gathered yet along the eye's `ray`.
    fn new(scene: &'p Scene, settings: &'p PathSettings, ray: &Ray, wl: Wavelengths) -> PathRadiance<'p> {
        PathRadiance {
            scene,
            settings,
            wl,
            l: Spectrum::ZERO,
            specular: true,
            last_pdf: 0.0,
            last_point: ray.origin,
        }
    }

    /// The walk's surfaces and roulette start ([`walk_camera`]).
    fn limits(&self) -> (u32, u32) {
        (self.settings.max_depth.saturating_add(1), self.settings.roulette_depth)
    }

    /// What the walk gathered, zero if it is not finite.
    fn radiance(&self) -> Spectrum {
        if self.l.is_finite() {
            self.l
        } else {
            Spectrum::ZERO
        }
    }
}

impl CameraVisitor for PathRadiance<'_> {
    fn escaped(&mut self, dir: Vec3, throughput: Spectrum, _length: u32) {
        // The sky and suns, weighted against having sampled them directly.
        let lights = self.scene.lights();
        self.l += throughput * lights.escaped_weighted(dir, (!self.specular).then_some(self.last_pdf), &self.wl);
    }

    fn visit(&mut self, at: &CameraArrival, rng: &mut Rng) -> bool {
        let (scene, hit, wo) = (self.scene, at.hit, at.wo);
        let le = emitted(scene, hit, wo, &self.wl);
        if le != Spectrum::ZERO {
            let weight = if self.specular {
                1.0
            } else {
                power_heuristic(self.last_pdf, scene.lights().pdf_direct(self.last_point, hit))
            };
            self.l += at.throughput * le * weight;
        }
        // The last surface only shows its emission.
        if at.length > self.settings.max_depth || at.bsdf.is_black() {
            return false;
        }
        if at.bsdf.is_smooth() {
            self.l += at.throughput * direct_light(scene, hit, at.bsdf, wo, true, &self.wl, rng);
        }
        true
    }

    fn visit_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> bool {
        if at.length > self.settings.max_depth {
            return false;
        }
        self.l += at.throughput * direct_in_medium(self.scene, at, true, &self.wl, rng);
        true
    }

    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let sample = at.sample_phase(rng);
        self.specular = false;
        self.last_pdf = sample.pdf;
        self.last_point = at.hit.point;
        Some(sample)
    }

    fn bounce(&mut self, at: &CameraArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let sample = at
            .bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?;
        if at.length == 1 && sample.specular && !self.settings.specular_camera_paths {
            return None;
        }
        self.specular = sample.specular;
        self.last_pdf = sample.pdf;
        self.last_point = at.hit.point;
        Some(sample)
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
        // A tile's paths walk together, a wave of rays per bounce.
        super::tiles::sample_pass_tiles(self.width, self.height, self.seed, pass, control, |points| {
            let mut paths: Vec<CameraPath<PathRadiance>> = points
                .into_iter()
                .map(
                    |PixelSample {
                         screen: (sx, sy),
                         mut rng,
                         ..
                     }| {
                        // Each sample its own wavelengths: no photons need to agree with it.
                        let wl = if spectral {
                            Wavelengths::sample(rng.uniform())
                        } else {
                            Wavelengths::Rgb
                        };
                        let ray = camera.generate_ray(sx, sy);
                        let visitor = PathRadiance::new(self.scene, &self.settings, &ray, wl);
                        Walker {
                            walk: CameraWalk::new(self.scene, ray, &wl, visitor.limits()),
                            wl,
                            rng,
                            visitor,
                        }
                    },
                )
                .collect();
            walk_together(self.scene, &mut paths);
            paths.iter().map(|p| p.wl.to_rgb(p.visitor.radiance())).collect()
        })
    }
}
