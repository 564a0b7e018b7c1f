//! A unidirectional path tracer with next-event estimation and multiple importance sampling
//! (power heuristic): the reference the photon-mapping integrators are checked against.
//!
//! It cannot see caustics of point or directional lights (a path can never hit a delta light
//! after a mirror or through glass); that is what photon mapping is for.

use super::camera_walk::{walk_camera, CameraArrival, CameraPath, CameraVisitor, CameraWalk};
use super::direct::{direct_in_medium, direct_light, direct_light_deferred, emitted, power_heuristic};
use super::tiles::PixelSample;
use crate::bsdf::{BsdfSample, Transport};
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::{in_waves, walk_together, walk_together_settling, MediumArrival, Walker};
use crate::sampling::Rng;
use crate::scene::{Scene, ShadowRay};
use crate::spectrum::{Spectrum, Wavelengths};
use std::cell::RefCell;

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
    let shared = PathsShared { settings, wave: None };
    let mut path = PathRadiance::new(scene, &shared, &ray, *wl, 0);
    walk_camera(scene, ray, wl, path.limits(), rng, &mut path);
    path.radiance()
}

/// A path tracer's walk: emission weighted against next-event estimation, which each smooth
/// vertex makes.
struct PathRadiance<'p> {
    scene: &'p Scene,
    shared: &'p PathsShared<'p>,
    wl: Wavelengths,
    /// Radiance gathered so far.
    l: Spectrum,
    /// The last bounce was specular (or the path just left the eye): emitters it hits count in
    /// full.
    specular: bool,
    /// The last bounce's pdf and point, for weighting emitters that BSDF sampling hits.
    last_pdf: f32,
    last_point: Vec3,
    /// The path's number in its tile (for the wave's shadow rays).
    number: u32,
}

/// What a tile's paths share: their settings, and the wave where next-event estimation leaves
/// their shadow rays to be tested together (`None`: each tested at once).
struct PathsShared<'p> {
    settings: &'p PathSettings,
    wave: Option<RefCell<WaveShadows>>,
}

/// A wave's light samples whose shadow rays are tested together ([`Scene::blocks_each`]),
/// in the order the paths drew them.
#[derive(Default)]
struct WaveShadows {
    terms: Vec<DeferredTerm>,
    shadows: Vec<ShadowRay>,
    blocked: Vec<bool>,
}

/// One light sample's term at a path's vertex, counted if its shadow ray is clear.
struct DeferredTerm {
    path: u32,
    throughput: Spectrum,
    term: Spectrum,
    /// Its shadow ray's number, `None` for a sample already known clear.
    shadow: Option<u32>,
}

impl WaveShadows {
    /// Tests the wave's shadow rays and adds each vertex's clear terms to its path, summed as
    /// [`direct_light`] sums them; then empties.
    fn settle(&mut self, scene: &Scene, paths: &mut [CameraPath<PathRadiance>]) {
        if self.terms.is_empty() {
            return;
        }
        self.blocked.resize(self.shadows.len(), false);
        scene.blocks_each(&self.shadows, &mut self.blocked);
        // A path has at most one vertex in a wave: its terms follow each other.
        let mut terms = self.terms.iter().peekable();
        while let Some(first) = terms.peek() {
            let (path, throughput) = (first.path, first.throughput);
            let mut sum = Spectrum::ZERO;
            while let Some(t) = terms.next_if(|t| t.path == path) {
                if t.shadow.is_none_or(|k| !self.blocked[k as usize]) {
                    sum += t.term;
                }
            }
            paths[path as usize].visitor.l += throughput * sum;
        }
        self.terms.clear();
        self.shadows.clear();
    }
}

impl<'p> PathRadiance<'p> {
    /// Nothing gathered yet along the eye's `ray`.
    fn new(scene: &'p Scene, shared: &'p PathsShared<'p>, ray: &Ray, wl: Wavelengths, number: u32) -> PathRadiance<'p> {
        PathRadiance {
            scene,
            shared,
            number,
            wl,
            l: Spectrum::ZERO,
            specular: true,
            last_pdf: 0.0,
            last_point: ray.origin,
        }
    }

    /// The walk's surfaces and roulette start ([`walk_camera`]).
    fn limits(&self) -> (u32, u32) {
        (
            self.shared.settings.max_depth.saturating_add(1),
            self.shared.settings.roulette_depth,
        )
    }

    /// Next-event estimation at `at` with its shadow rays left to the `wave`. Out of line: the
    /// paths that test at once keep their code as it was.
    #[inline(never)]
    fn defer_direct(&mut self, at: &CameraArrival, wave: &RefCell<WaveShadows>, rng: &mut Rng) {
        let (wave, path) = (&mut *wave.borrow_mut(), self.number);
        let drawn = wave.terms.len();
        let at_vertex = (at.hit, at.bsdf, at.wo);
        direct_light_deferred(self.scene, at_vertex, true, &self.wl, rng, |term, shadow| {
            let shadow = shadow.map(|s| {
                wave.shadows.push(s);
                wave.shadows.len() as u32 - 1
            });
            let throughput = at.throughput;
            wave.terms.push(DeferredTerm {
                path,
                throughput,
                term,
                shadow,
            });
        });
        if wave.terms.len() == drawn {
            // As `direct_light`'s zero would.
            self.l += at.throughput * Spectrum::ZERO;
        }
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
        if at.length > self.shared.settings.max_depth || at.bsdf.is_black() {
            return false;
        }
        if at.bsdf.is_smooth() {
            match &self.shared.wave {
                Some(wave) => self.defer_direct(at, wave, rng),
                None => self.l += at.throughput * direct_light(scene, hit, at.bsdf, wo, true, &self.wl, rng),
            }
        }
        true
    }

    fn visit_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> bool {
        if at.length > self.shared.settings.max_depth {
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
        if at.length == 1 && sample.specular && !self.shared.settings.specular_camera_paths {
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
    /// A wave's shadow rays tested together ([`Scene::shadows_stream`]; off in tests, to
    /// compare).
    shadows_in_waves: bool,
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
            shadows_in_waves: scene.shadows_stream(),
        }
    }
}

impl super::Progressive for PathTracer<'_> {
    fn render_pass(&self, pass: u64, control: crate::progress::Control) -> Option<Vec<Vec3>> {
        let camera = &self.camera;
        let spectral = super::ppm::settings_spectral(&self.settings.spectral, self.scene);
        // A tile's paths walk together, a wave of rays per bounce.
        super::tiles::sample_pass_tiles(self.width, self.height, self.seed, pass, control, |points| {
            // Shadow rays tested a wave at a time where streams pay for them.
            let shared = PathsShared {
                settings: &self.settings,
                wave: (self.shadows_in_waves && in_waves(self.scene, points.len())).then(RefCell::default),
            };
            let mut paths: Vec<CameraPath<PathRadiance>> = points
                .into_iter()
                .enumerate()
                .map(
                    |(
                        number,
                        PixelSample {
                            screen: (sx, sy),
                            mut rng,
                            ..
                        },
                    )| {
                        // Each sample its own wavelengths: no photons need to agree with it.
                        let wl = if spectral {
                            Wavelengths::sample(rng.uniform())
                        } else {
                            Wavelengths::Rgb
                        };
                        let ray = camera.generate_ray(sx, sy);
                        let visitor = PathRadiance::new(self.scene, &shared, &ray, wl, number as u32);
                        Walker {
                            walk: CameraWalk::new(self.scene, ray, &wl, visitor.limits()),
                            wl,
                            rng,
                            visitor,
                        }
                    },
                )
                .collect();
            match &shared.wave {
                Some(wave) => walk_together_settling(self.scene, &mut paths, |paths| {
                    wave.borrow_mut().settle(self.scene, paths)
                }),
                None => walk_together(self.scene, &mut paths),
            }
            paths.iter().map(|p| p.wl.to_rgb(p.visitor.radiance())).collect()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrator::Progressive;
    use crate::progress::{Control, NoProgress};

    /// A wave's shadow rays tested together make the image they make one by one, bit for bit:
    /// a bumpy sheet of 135,000 triangles (a tree beyond the caches) under a point light, a
    /// glowing ball and a glowing triangle (whose shadow rays pass over it, so go alone).
    #[test]
    fn shadow_rays_in_waves_make_the_image_one_by_one_makes() {
        let lamps = "point_light { position = (0.5, -0.3, 2); colour = (4, 4, 4); }
            translate(-0.8, 0.6, 1.2, scale(0.25, sphere { material = { emissive = (6, 5, 4); } }))
            polymesh { points = ((1,1,1.2),(1.6,1,1.3),(1,1.6,1.1)); faces = ((0,1,2),(0,2,1));
                       material = { emissive = (5, 5, 8); } }";
        let scene = crate::scene::build::test_scene(&format!("{lamps}\n{}", crate::scene::build::bumpy_sheet(260)));
        assert!(scene.shadows_stream());
        assert_eq!(scene.lights().area_lights().count(), 2);
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let control = Control {
            progress: &NoProgress,
            cancel: &cancel,
        };
        let settings = PathSettings {
            max_depth: 4,
            ..PathSettings::default()
        };
        let mut tracer = PathTracer::new(&scene, settings, 48, 40, 3);
        let images = [true, false].map(|waves| {
            tracer.shadows_in_waves = waves;
            tracer.render_pass(1, control).expect("not cancelled")
        });
        let lit = images[1].iter().filter(|p| p.max_element() > 0.0).count();
        assert!(lit > 48 * 40 / 2, "{lit} pixels lit");
        assert!(images[0] == images[1], "the same image, bit for bit");
    }
}
