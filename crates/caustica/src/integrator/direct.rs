//! Direct light under the physical model: one light sample per smooth surface point
//! (next-event estimation), weighted against BSDF sampling by multiple importance sampling
//! (power heuristic) where the caller also counts the emitters and sky its BSDF samples reach.

use crate::bsdf::{Bsdf, BsdfSample};
use crate::light::DirectSample;
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::MediumArrival;
use crate::sampling::Rng;
use crate::scene::{Scene, ShadowRay, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};

pub use crate::sampling::power_heuristic;

/// Direct light at a smooth surface point by one light sample, weighted against BSDF sampling
/// when `mis` is set (the caller then also counts emitters its BSDF samples hit).
pub fn direct_light(
    scene: &Scene,
    hit: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    mis: bool,
    wl: &Wavelengths,
    rng: &mut Rng,
) -> Spectrum {
    let mut l = Spectrum::ZERO;
    let takes = |wi: Vec3| bsdf.may_take(wi);
    // A wall's f, cosine and density at once: the values asked one by one, for less.
    let lambertian = bsdf.plain_lambertian(wo);
    scene.lights().sample_direct((scene, hit, &takes), wl, rng, |sample| {
        if let Some(t) = light_term((bsdf, lambertian.as_ref()), wo, mis, &sample) {
            l += t;
        }
    });
    l
}

/// [`direct_light`] with the shadow rays left untested: `add(term, shadow)` for each light
/// sample, which counts `term` if nothing blocks `shadow` (`None`: nothing does), in the order
/// `direct_light` sums them. Only in scenes without media.
pub fn direct_light_deferred(
    scene: &Scene,
    (hit, bsdf, wo): (&SurfaceHit, &Bsdf, Vec3),
    mis: bool,
    wl: &Wavelengths,
    rng: &mut Rng,
    mut add: impl FnMut(Spectrum, Option<ShadowRay>),
) {
    let takes = |wi: Vec3| bsdf.may_take(wi);
    let lambertian = bsdf.plain_lambertian(wo);
    scene
        .lights()
        .sample_direct_deferred((scene, hit, &takes), wl, rng, |sample, shadow| {
            if let Some(t) = light_term((bsdf, lambertian.as_ref()), wo, mis, &sample) {
                add(t, shadow);
            }
        });
}

/// What a light sample adds at a surface point seen from `wo`: f · cos · its contribution,
/// weighted by MIS when `mis` is set; `None` where the BSDF takes none of it. `lambertian`:
/// the BSDF's plain Lambertian lobe, where that is all it is.
#[inline(always)]
fn light_term(
    (bsdf, lambertian): (&Bsdf, Option<&crate::bsdf::Lambertian>),
    wo: Vec3,
    mis: bool,
    sample: &DirectSample,
) -> Option<Spectrum> {
    let lit = lambertian.and_then(|lambertian| lambertian.toward(sample.wi));
    let f = lit.map_or_else(|| bsdf.eval(wo, sample.wi), |(f, _, _)| f);
    if f == Spectrum::ZERO {
        return None;
    }
    let cos = lit.map_or_else(|| bsdf.cos(sample.wi), |(_, cos, _)| cos);
    let weight = if mis && sample.pdf > 0.0 {
        power_heuristic(
            sample.pdf,
            lit.map_or_else(|| bsdf.pdf(wo, sample.wi), |(_, _, pdf)| pdf),
        )
    } else {
        1.0
    };
    Some(f * sample.contribution * (cos * weight))
}

/// Direct light in-scattered at a point in a medium by one light sample, weighted against
/// phase-function sampling when `mis` is set (the caller then also counts emitters its phase
/// samples hit).
pub fn direct_in_medium(scene: &Scene, at: &MediumArrival, mis: bool, wl: &Wavelengths, rng: &mut Rng) -> Spectrum {
    let mut l = Spectrum::ZERO;
    scene
        .lights()
        .sample_direct((scene, at.hit, &|_| true), wl, rng, |sample| {
            let p = at.phase.eval(at.wo, sample.wi);
            let weight = if mis && sample.pdf > 0.0 {
                power_heuristic(sample.pdf, p)
            } else {
                1.0
            };
            l += sample.contribution * (p * weight);
        });
    l
}

/// Emitted radiance of a surface towards `wo`, at the wavelengths `wl`.
#[inline]
pub fn emitted(scene: &Scene, hit: &SurfaceHit, wo: Vec3, wl: &Wavelengths) -> Spectrum {
    if hit.is_in_medium() {
        return Spectrum::ZERO;
    }
    scene.emission_towards(hit, wo, wl)
}

/// Whether BSDF samples can reach light at all: only emissive objects and the sky can be hit
/// (point, spot and directional lights are deltas). Without them next-event estimation alone is
/// direct lighting.
pub fn bsdf_can_reach_light(scene: &Scene) -> bool {
    let lights = scene.lights();
    lights.has_sky() || lights.area_lights().next().is_some()
}

/// The light that the smooth-lobe sample `sample` from the surface point `hit` reaches directly —
/// an emitter's surface or the sky — weighted against next-event estimation: the BSDF half of
/// direct lighting by MIS (the caller multiplies by `sample.weight`).
pub fn direct_by_bsdf(
    scene: &Scene,
    hit: &SurfaceHit,
    sample: &BsdfSample,
    wl: &Wavelengths,
    rng: &mut Rng,
) -> Spectrum {
    let lights = scene.lights();
    let ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
    let (seen, distance) = match scene.intersect_solid(&ray) {
        None => (lights.escaped_weighted(sample.wi, Some(sample.pdf), wl), f32::INFINITY),
        Some((ray_there, isect)) => {
            let reached = scene.surface(&ray_there, &isect);
            let le = emitted(scene, &reached, -sample.wi, wl);
            if le == Spectrum::ZERO {
                return Spectrum::ZERO;
            }
            let weight = power_heuristic(sample.pdf, lights.pdf_direct(hit.point, &reached));
            (le * weight, (reached.point - hit.point).length())
        }
    };
    if scene.has_media() && seen != Spectrum::ZERO {
        // The media on the way take their share, as next-event estimation's shadow rays pay.
        return seen * scene.transmittance_towards(hit, sample.wi, distance, wl, rng);
    }
    seen
}
