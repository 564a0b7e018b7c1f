//! The camera paths of the photon-mapping integrators: a camera ray followed through mirrors,
//! glass and (for `ppm`) sharp highlights to the smooth surfaces where photons are gathered.

use super::camera_walk::{bounce_as_surface, visit_as_surface, walk_camera, CameraArrival, CameraVisitor};
use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::{MediumArrival, Passage};
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};

/// Follows a camera ray through at most `max_depth` mirrors and glass at the wavelengths `wl`,
/// adding the emission it meets. At each smooth surface it adds
/// `beta · at_smooth(hit, bsdf, wo, path length, dispersed, left)`; where the surface's BSDF
/// then samples a smooth lobe the chain ends with
/// `beta · beyond(hit, sample, path length, dispersed, left)` (the BSDF half of direct light
/// for photon mapping, a final gather for Jensen's method). `left` is how many more surfaces
/// light may have scattered at beyond this one (`--depth` less the mirrors and glass before
/// it): photons gathered here may have bounced that often at most. With `through_specular` off, a camera ray that meets a
/// mirror or glass first stops there. A dispersive glass leaves the hero wavelength alone; both
/// closures are told whether that happened (photons that dispersed too must then not count the
/// hero's weight twice, see [`crate::photon::DISPERSED`]).
///
/// With `through_glossy` (and `through_specular`), at a surface whose smooth lobes are all
/// sharp ([`Bsdf::is_sharply_glossy`]: a glass's or a metal's highlight) the path goes on in
/// the direction its BSDF draws, glossy or specular, until the last depth, and `at_smooth` is
/// told (its `caustic_only` argument) to gather only the photons that came by mirrors and glass
/// alone (L S+): the light the path going on cannot find from a point lamp. What comes by a
/// diffuse bounce, which a photon estimate would weigh by the lobe's peak, is found further
/// along instead; emitters and the sky the path meets after going on through the glossy lobe
/// count no more (the BSDF sample there and those photons have counted them).
///
/// `along` may have the chain pass media up to its first smooth surface and gather the light
/// scattered along the way instead ([`Along`]).
#[allow(clippy::too_many_arguments)]
pub fn camera_chain<S, B>(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    (through_specular, through_glossy): (bool, bool),
    wl: &Wavelengths,
    rng: &mut Rng,
    (at_smooth, beyond): (S, B),
    along: &mut dyn Along,
) -> Spectrum
where
    S: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, bool, u32, bool, &mut Rng) -> Spectrum,
    B: FnMut(&SurfaceHit, &BsdfSample, f32, bool, u32, &mut Rng) -> Spectrum,
{
    let mut chain = Chain {
        scene,
        wl,
        max_depth,
        through: (through_specular, through_glossy),
        at_smooth,
        beyond,
        along,
        smooth_seen: false,
        l: Spectrum::ZERO,
        path_length: 0.0,
        past_highlight: false,
        last: false,
    };
    // No roulette: a chain ends at its first smooth surface, or after `max_depth` mirrors.
    walk_camera(scene, ray, wl, (max_depth.saturating_add(1), u32::MAX), rng, &mut chain);
    chain.l
}

/// What a camera chain gathers along its segments through media before its first smooth
/// surface, passing those media without stopping ([`BeamEstimate`](super::beam_estimate::BeamEstimate)).
pub trait Along {
    /// Whether the chain passes `medium` and gathers along it.
    fn passes(&self, medium: u32) -> bool;

    /// The light gathered along `ray` (from the chain's last vertex, `path_length` from the
    /// eye), the chain carrying `(throughput, dispersed)`, light gathered there having
    /// scattered at most `left` more times.
    fn gather(
        &mut self,
        ray: &Ray,
        passage: &Passage,
        carried: (Spectrum, bool),
        path_length_left: (f32, u32),
        rng: &mut Rng,
    ) -> Spectrum;
}

/// A camera chain on its walk (see [`camera_chain`]).
struct Chain<'c, S, B> {
    scene: &'c Scene,
    wl: &'c Wavelengths,
    max_depth: u32,
    /// (through_specular, through_glossy)
    through: (bool, bool),
    at_smooth: S,
    beyond: B,
    /// Radiance gathered so far.
    l: Spectrum,
    path_length: f32,
    /// Set once the path has gone on through a highlight's glossy lobe: the emitters it meets
    /// from there on were counted by that surface's BSDF sample (straight on) or its caustic
    /// photons (by mirrors and glass). Not by its specular lobes, which no photon reaches.
    past_highlight: bool,
    /// The surface reached is the chain's last: its sample is drawn, but not followed.
    last: bool,
    along: &'c mut dyn Along,
    /// A smooth surface was reached: no more gathering along segments.
    smooth_seen: bool,
}

impl<S, B> CameraVisitor for Chain<'_, S, B>
where
    S: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, bool, u32, bool, &mut Rng) -> Spectrum,
    B: FnMut(&SurfaceHit, &BsdfSample, f32, bool, u32, &mut Rng) -> Spectrum,
{
    fn escaped(&mut self, dir: Vec3, throughput: Spectrum, _length: u32) {
        // Only the camera and specular chains get here: the sky counts in full.
        if !self.past_highlight {
            self.l += throughput * self.scene.lights().escaped(dir, self.wl);
        }
    }

    fn passes(&self, medium: u32) -> bool {
        !self.smooth_seen && self.along.passes(medium)
    }

    fn segment(&mut self, ray: &Ray, passage: &Passage, carried: (Spectrum, bool), length: u32, rng: &mut Rng) {
        let depth = length - 1;
        if self.smooth_seen || depth > self.max_depth {
            return;
        }
        let left = self.max_depth - depth;
        self.l += carried.0 * self.along.gather(ray, passage, carried, (self.path_length, left), rng);
    }

    fn visit(&mut self, at: &CameraArrival, rng: &mut Rng) -> bool {
        let (hit, bsdf, wo) = (at.hit, at.bsdf, at.wo);
        self.path_length += at.t;
        self.smooth_seen |= bsdf.is_smooth();
        // Only the camera and specular chains reach here: emission counts in full.
        if !self.past_highlight {
            self.l += at.throughput * super::direct::emitted(self.scene, hit, wo, self.wl);
        }
        if bsdf.is_black() {
            return false;
        }
        let depth = at.length - 1;
        let (through_specular, through_glossy) = self.through;
        self.last = depth == self.max_depth || depth == 0 && !through_specular;
        if bsdf.is_smooth() {
            let left = self.max_depth - depth;
            let goes_on_glossy = self.goes_on_glossy(bsdf, through_glossy && through_specular);
            self.l += at.throughput
                * (self.at_smooth)(hit, bsdf, wo, self.path_length, at.dispersed, left, goes_on_glossy, rng);
        }
        true
    }

    // A scattering point is a smooth vertex whose lobes are the phase function: the chain
    // gathers there and ends.
    fn visit_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> bool {
        let wl = self.wl;
        visit_as_surface(self, at, wl, rng)
    }

    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let wl = self.wl;
        bounce_as_surface(self, at, wl, rng)
    }

    fn bounce(&mut self, at: &CameraArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let sample = at
            .bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?;
        if !sample.specular {
            // Even at the last depth: light that comes straight from an emitter has scattered
            // at this surface only (the BSDF half of its direct light).
            let left = self.max_depth - (at.length - 1);
            self.l += at.throughput * (self.beyond)(at.hit, &sample, self.path_length, at.dispersed, left, rng);
            let (through_specular, through_glossy) = self.through;
            if !self.goes_on_glossy(at.bsdf, through_glossy && through_specular) {
                return None;
            }
            self.past_highlight = true;
        }
        (!self.last).then_some(sample)
    }
}

impl<S, B> Chain<'_, S, B> {
    /// Whether the chain goes on through this surface's sharp highlight (`through`: glossy and
    /// specular chains are asked for), not at its last surface.
    fn goes_on_glossy(&self, bsdf: &Bsdf, through: bool) -> bool {
        through && !self.last && bsdf.is_sharply_glossy()
    }
}
