//! The one random walk on the light side: physical photons, the light tracer's paths and vcm's
//! light subpaths all leave a light through [`walk_light`], which finds each surface, makes its
//! BSDF, hands the vertex to the walk's [`LightVisitor`] (store a photon, join it to the eye,
//! keep it for connections and merging), lets the visitor draw the bounce (the BSDF's sample,
//! or vcm's mixture aimed at mirrors and glass), and carries the throughput on through
//! [`continue_light`]: Veach's correction for interpolated normals, Russian roulette, the
//! spectral hero's termination at a dispersive surface, absorption inside glass and the depth,
//! written once. (The course
//! model's caustic photons follow the course's own Phong rules, not a BSDF: their loop is
//! [`super::trace::trace_path`].)

use crate::bsdf::{adjoint_correction, Bsdf, BsdfSample, Transport};
use crate::math::Ray;
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use glam::Vec3;

/// A surface a light walk has reached, as its visitor sees it.
pub struct LightArrival<'a> {
    /// The surface point.
    pub hit: &'a SurfaceHit,
    /// Unit direction back along the arriving ray.
    pub wo: Vec3,
    /// Its BSDF, seen from `wo`.
    pub bsdf: &'a Bsdf,
    /// What the walk carries on arrival (flux for photons).
    pub throughput: Spectrum,
    /// Only the hero wavelength is left (a dispersive surface was passed).
    pub dispersed: bool,
    /// Surfaces met so far, this one included (1 at the first).
    pub length: u32,
}

/// What a light walk's user does at each vertex and how the walk bounces there.
pub trait LightVisitor {
    /// At each surface reached: stores, splats or records the vertex. `false` ends the walk here.
    fn visit(&mut self, at: &LightArrival) -> bool;

    /// The bounce at `at` and the roulette that judges it: by default the BSDF's own sample, the
    /// flux kept nearly constant.
    fn bounce(&mut self, at: &LightArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        at.bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Importance)
            .map(|s| (s, Roulette::KeepFlux))
    }
}

pub use crate::scene::transmittance;

/// What both walks carry from surface to surface: the glass they are inside, whose absorption
/// each segment pays. A walk starts where it is (a lamp inside a glass ball, a camera in a
/// block of glass): its first segment is inside a glass if it meets that glass from within.
#[derive(Clone, Copy, Debug, Default)]
pub struct Passage {
    absorbing: Option<Vec3>,
    /// Whether the first segment has been traced (from then on, crossings decide).
    started: bool,
}

impl Passage {
    /// The next surface along `ray` (`None`: the ray leaves the scene), the throughput
    /// attenuated by the glass on the way, at the wavelengths `wl`.
    #[inline]
    pub fn next(
        &mut self,
        scene: &Scene,
        ray: &Ray,
        throughput: &mut Spectrum,
        wl: &Wavelengths,
    ) -> Option<(SurfaceHit, f32)> {
        let isect = scene.intersect(ray, f32::INFINITY);
        if !self.started {
            self.started = true;
            if scene.absorbs() {
                return self.first(scene, ray, isect, throughput, wl);
            }
        }
        if let Some(sigma) = self.absorbing {
            let distance = isect.as_ref().map_or(f32::INFINITY, |i| i.t * ray.dir.length());
            *throughput *= transmittance(sigma, distance, wl);
        }
        let isect = isect?;
        Some((scene.surface(ray, &isect), isect.t))
    }

    /// The walk's first segment in a scene with absorbing glass: inside a glass if it meets
    /// that glass from within.
    #[cold]
    fn first(
        &mut self,
        scene: &Scene,
        ray: &Ray,
        isect: Option<crate::scene::Intersection>,
        throughput: &mut Spectrum,
        wl: &Wavelengths,
    ) -> Option<(SurfaceHit, f32)> {
        let isect = isect?;
        let hit = scene.surface(ray, &isect);
        self.absorbing = scene.absorption_beyond(&hit, -ray.dir);
        if let Some(sigma) = self.absorbing {
            *throughput *= transmittance(sigma, isect.t * ray.dir.length(), wl);
        }
        Some((hit, isect.t))
    }

    /// After a bounce at `hit` that goes on along `sample`: through the surface, the walk is
    /// inside its glass or out of it.
    #[inline]
    pub fn cross(&mut self, scene: &Scene, hit: &SurfaceHit, sample: &BsdfSample) {
        if sample.transmitted {
            self.absorbing = scene.absorption_beyond(hit, sample.wi);
        }
    }
}

/// Follows light from `ray` carrying `throughput` at the wavelengths `wl` through at most
/// `max_surfaces` surfaces, handing each to `visitor`. Returns the rays traced (surfaces found
/// and the last ray's miss).
pub fn walk_light(
    scene: &Scene,
    mut ray: Ray,
    mut throughput: Spectrum,
    wl: &Wavelengths,
    max_surfaces: u32,
    rng: &mut Rng,
    visitor: &mut impl LightVisitor,
) -> u64 {
    let mut dispersed = false;
    let mut passage = Passage::default();
    let mut rays = 0;
    for length in 1..=max_surfaces {
        rays += 1;
        let Some((hit, _)) = passage.next(scene, &ray, &mut throughput, wl) else {
            break;
        };
        let wo = -ray.dir;
        let bsdf = Bsdf::at(scene, &hit, wo, wl);
        let at = LightArrival {
            hit: &hit,
            wo,
            bsdf: &bsdf,
            throughput,
            dispersed,
            length,
        };
        if !visitor.visit(&at) {
            break;
        }
        let Some((sample, roulette)) = visitor.bounce(&at, rng) else {
            break;
        };
        if !continue_light(&hit, wo, &sample, roulette, (&mut throughput, &mut dispersed), wl, rng) {
            break;
        }
        passage.cross(scene, &hit, &sample);
        ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
    }
    rays
}

/// How a light-side walk decides to go on.
#[derive(Clone, Copy, Debug)]
pub enum Roulette {
    /// Survive with the share of the throughput the bounce keeps, so that flux stays nearly
    /// constant along the path (photon mapping, light tracing).
    KeepFlux,
    /// As `KeepFlux` at mirrors and glass; elsewhere also in proportion to how far the
    /// throughput has fallen below `start`, its value at the light (vcm); `aimed`: the bounce
    /// was aimed at a mirror or glass and goes on with the little it carries.
    TowardsStart {
        /// The throughput's largest channel as it left the light.
        start: f32,
        /// The bounce was aimed at a mirror or glass.
        aimed: bool,
    },
}

/// Carries the walk's `(throughput, dispersed)` through the bounce `sample` drawn at `hit`
/// (seen from `wo`), or ends the walk (`false`): the sample's weight with Veach's correction,
/// the roulette, and at a dispersive surface only the hero wavelength onwards (`dispersed`
/// records it).
pub fn continue_light(
    hit: &SurfaceHit,
    wo: Vec3,
    sample: &BsdfSample,
    roulette: Roulette,
    (throughput, dispersed): (&mut Spectrum, &mut bool),
    wl: &Wavelengths,
    rng: &mut Rng,
) -> bool {
    let Some(correction) = adjoint_correction(hit.shading_normal, hit.geometric_normal, wo, sample.wi) else {
        return false;
    };
    let weight = sample.weight * correction;
    let q = match roulette {
        Roulette::TowardsStart { aimed: true, .. } => 1.0,
        Roulette::TowardsStart { start, .. } if !sample.specular => {
            (weight.max_element() * (throughput.max_element() / start).min(1.0)).min(1.0)
        }
        _ => weight.max_element().min(1.0),
    };
    if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
        return false;
    }
    *throughput *= weight / q;
    if sample.dispersive {
        wl.terminate_secondary(throughput, dispersed);
    }
    true
}
