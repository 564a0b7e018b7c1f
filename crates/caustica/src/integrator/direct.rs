//! Next-event estimation under the physical model: one light sample per smooth surface point,
//! weighted against BSDF sampling by multiple importance sampling (power heuristic) where the
//! caller also counts the emitters its BSDF samples hit.

use crate::bsdf::Bsdf;
use crate::math::Vec3;
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};

/// Power heuristic (β = 2) weight of a strategy with pdf `a` against one with pdf `b`.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

/// Direct light at a smooth surface point by one light sample, weighted against BSDF sampling
/// when `mis` is set (the caller then also counts emitters its BSDF samples hit).
pub fn direct_light(scene: &Scene, hit: &SurfaceHit, bsdf: &Bsdf, wo: Vec3, mis: bool, rng: &mut Rng) -> Vec3 {
    let Some(sample) = scene.lights().sample_direct(scene, hit, rng) else {
        return Vec3::ZERO;
    };
    let f = bsdf.eval(wo, sample.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let cos = bsdf.normal().dot(sample.wi).abs();
    let weight = if mis && sample.pdf > 0.0 {
        power_heuristic(sample.pdf, bsdf.pdf(wo, sample.wi))
    } else {
        1.0
    };
    f * sample.contribution * (cos * weight)
}

/// Emitted radiance of a surface towards any direction (two-sided).
#[inline]
pub fn emitted(scene: &Scene, hit: &SurfaceHit) -> Vec3 {
    scene.emission(hit).max(Vec3::ZERO)
}
