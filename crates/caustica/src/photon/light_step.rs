//! The step every light-side walk takes after sampling a BSDF (photon tracing, the light
//! tracer's paths, vcm's light subpaths): Veach's correction for interpolated normals, Russian
//! roulette, and the spectral hero's termination at a dispersive surface, written once.

use crate::bsdf::{adjoint_correction, BsdfSample};
use crate::sampling::Rng;
use crate::scene::SurfaceHit;
use crate::spectrum::{Spectrum, Wavelengths};
use glam::Vec3;

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
