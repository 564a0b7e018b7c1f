//! The camera paths of the photon-mapping integrators: a camera ray followed through mirrors,
//! glass and (for `ppm`) sharp highlights to the smooth surfaces where photons are gathered.

use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::math::{Ray, Vec3};
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
#[allow(clippy::too_many_arguments)]
pub fn camera_chain<S, B>(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    (through_specular, through_glossy): (bool, bool),
    wl: &Wavelengths,
    rng: &mut Rng,
    mut at_smooth: S,
    mut beyond: B,
) -> Spectrum
where
    S: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, bool, u32, bool, &mut Rng) -> Spectrum,
    B: FnMut(&SurfaceHit, &BsdfSample, f32, bool, u32, &mut Rng) -> Spectrum,
{
    let mut ray = ray;
    let mut beta = wl.grey(1.0);
    let mut terminated = false;
    let mut l = Spectrum::ZERO;
    let mut path_length = 0.0f32;
    // Set once the path has gone on through a highlight's glossy lobe: the emitters it meets
    // from there on were counted by that surface's BSDF sample (straight on) or its caustic
    // photons (by mirrors and glass). Not by its specular lobes, which no photon reaches.
    let mut past_highlight = false;
    for depth in 0..=max_depth {
        let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
            // Only the camera and specular chains get here: the sky counts in full.
            if !past_highlight {
                l += beta * scene.lights().escaped(ray.dir, wl);
            }
            break;
        };
        let hit = scene.surface(&ray, &isect);
        path_length += isect.t;
        let wo = -ray.dir;
        // Only the camera and specular chains reach here: emission counts in full.
        if !past_highlight {
            l += beta * super::direct::emitted(scene, &hit, wo, wl);
        }
        let bsdf = Bsdf::at(scene, &hit, wo, wl);
        if bsdf.is_black() {
            break;
        }
        let last = depth == max_depth || depth == 0 && !through_specular;
        let goes_on_glossy = through_glossy && through_specular && !last && bsdf.is_sharply_glossy();
        if bsdf.is_smooth() {
            let left = max_depth - depth;
            l += beta * at_smooth(&hit, &bsdf, wo, path_length, terminated, left, goes_on_glossy, rng);
        }
        let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) else {
            break;
        };
        if !sample.specular {
            // Even at the last depth: light that comes straight from an emitter has scattered
            // at this surface only (the BSDF half of its direct light).
            l += beta * beyond(&hit, &sample, path_length, terminated, max_depth - depth, rng);
            if !goes_on_glossy {
                break;
            }
            past_highlight = true;
        }
        if last {
            break;
        }
        beta *= sample.weight;
        if sample.dispersive {
            wl.terminate_secondary(&mut beta, &mut terminated);
        }
        ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
    }
    l
}
