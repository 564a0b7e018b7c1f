//! Photon paths under the physical model: photons leave every light (point, directional and
//! emissive objects, chosen by power), scatter by the same BSDF the camera paths use, and are
//! stored wherever they meet a smooth (diffuse or glossy) surface.
//!
//! Each stored photon records its history in its flags: [`REFLECTED`] / [`REFRACTED`] for
//! specular bounces, [`DIFFUSE`] for smooth ones; no flag means the photon came straight from
//! the light. Integrators select the paths they need from that (progressive photon mapping: all
//! but direct ones; Jensen's caustic map: specular-only ones). Russian roulette keeps each
//! photon's flux nearly constant and the estimate unbiased.

use super::{Photon, REFLECTED, REFRACTED};
use crate::bsdf::{Bsdf, Transport};
use crate::integrator::physical::Lights;
use crate::math::{offset_origin, Ray};
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::Scene;
use rayon::prelude::*;

/// The path met a smooth surface before landing.
pub const DIFFUSE: u8 = 4;

/// Whether a photon arrived straight from its light.
#[inline]
pub fn is_direct(photon: &Photon) -> bool {
    photon.flags == 0
}

/// Whether a photon's path was specular only: light, then mirrors and glass (L S+ D).
#[inline]
pub fn is_caustic(photon: &Photon) -> bool {
    photon.flags != 0 && photon.flags & DIFFUSE == 0
}

const BATCH: u64 = 4096;

/// Emits `count` photons from stream `stream` of `seed` and returns those stored, their flux
/// already divided by `count`. Deterministic whatever the thread count: photon `i` draws from
/// its own random stream and batches are concatenated in order.
pub fn trace(
    scene: &Scene,
    lights: &Lights,
    count: u64,
    seed: u64,
    stream: u64,
    max_bounces: u32,
    control: Control,
) -> Vec<Photon> {
    if lights.is_empty() || count == 0 {
        return Vec::new();
    }
    let batches = count.div_ceil(BATCH);
    let scale = 1.0 / count as f32;
    let parts: Vec<Vec<Photon>> = (0..batches)
        .into_par_iter()
        .map(|b| {
            let mut out = Vec::new();
            if control.cancelled() {
                return out;
            }
            let first = b * BATCH;
            for i in first..(first + BATCH).min(count) {
                let mut rng = Rng::new(seed, (stream << 40) ^ i);
                trace_one(scene, lights, max_bounces, scale, &mut rng, &mut out);
            }
            out
        })
        .collect();
    parts.concat()
}

fn trace_one(scene: &Scene, lights: &Lights, max_bounces: u32, scale: f32, rng: &mut Rng, out: &mut Vec<Photon>) {
    let Some(emitted) = lights.emit(scene, rng) else {
        return;
    };
    let mut ray = emitted.ray;
    let mut flux = emitted.flux * scale;
    let mut flags = 0u8;
    for _ in 0..=max_bounces {
        let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
            return;
        };
        let hit = scene.surface(&ray, &isect);
        let wo = -ray.dir;
        let bsdf = Bsdf::new(&hit.params, hit.shading_normal, hit.geometric_normal, wo);
        if bsdf.is_smooth() {
            out.push(Photon::new(hit.point, flux, ray.dir, bsdf.normal(), flags, 0));
        }
        let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance) else {
            return;
        };
        // Survive with the probability of the throughput kept, so flux stays nearly constant.
        let q = sample.weight.max_element().min(1.0);
        if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
            return;
        }
        flux *= sample.weight / q;
        flags |= if !sample.specular {
            DIFFUSE
        } else if sample.transmitted {
            REFRACTED
        } else {
            REFLECTED
        };
        ray = Ray::new(offset_origin(hit.point, hit.geometric_normal, sample.wi), sample.wi);
    }
}
