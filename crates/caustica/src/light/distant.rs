//! Directional lights and suns: next-event estimation takes the light's direction (a sun's:
//! one in its cone); emission starts across the light's beam ([`super::beam::Beam`]).

use super::emission::{Emission, EmitArgs, Emitters};
use super::{DirectQuery, DirectSample, Light};
use crate::math::Ray;
use crate::sampling::{sample_uniform_cone, Rng};
use glam::Vec2;
use std::f32::consts::PI;

/// Solid-angle pdf of a sun's uniform cone of 1 − cos θ = `one_minus_cos`.
pub(super) fn sun_cone_pdf(one_minus_cos: f32) -> f32 {
    1.0 / (2.0 * PI * one_minus_cos)
}

/// Next-event estimation's sample of a directional light or a sun.
pub(super) fn sample_direct(q: &DirectQuery, light: &Light, u: Vec2) -> Option<DirectSample> {
    let (p, p_pick) = (q.hit.point, q.choice);
    match light {
        Light::Directional { direction, color } => {
            let wi = -*direction;
            q.unoccluded(wi, f32::INFINITY).then(|| DirectSample {
                wi,
                distance: f32::INFINITY,
                contribution: q.wl.unbounded(*color) / p_pick,
                pdf: 0.0,
                direct_pdf: p_pick,
                delta: true,
                point: p + wi,
                normal: *direction,
                cos_light: 1.0,
            })
        }
        Light::Sun {
            direction,
            cos_max,
            one_minus_cos,
            ..
        } => {
            let wi = sample_uniform_cone(u, -*direction, *cos_max);
            let pdf = p_pick * sun_cone_pdf(*one_minus_cos);
            q.unoccluded(wi, f32::INFINITY).then(|| DirectSample {
                wi,
                distance: f32::INFINITY,
                contribution: q.wl.unbounded(light.sun_radiance()) / pdf,
                pdf,
                direct_pdf: pdf,
                delta: false,
                point: p + wi,
                normal: -wi,
                cos_light: 1.0,
            })
        }
        _ => None,
    }
}

impl Emitters {
    /// A start from a directional light or a sun: a point across its beam, a direction along it (a
    /// sun's: in its cone).
    pub(super) fn emit_distant(&self, light: &Light, args: EmitArgs, rng: &mut Rng) -> Option<Emission> {
        let (number, pick, u, u_dir, wl) = args.parts();
        match light {
            light @ (Light::Directional { .. } | Light::Sun { .. }) => {
                let beam = self.beams[number].as_ref()?;
                let (origin, plane_pdf) = beam.sample(rng.uniform(), rng.uniform(), u)?;
                let (dir, radiance) = match beam.sun {
                    Some((cos_max, _)) => (
                        sample_uniform_cone(u_dir, beam.direction, cos_max),
                        light.sun_radiance(),
                    ),
                    None => (beam.direction, light.color()),
                };
                let lean = dir.dot(beam.direction);
                let pdf = pick * beam.direction_pdf() * plane_pdf / lean;
                (lean > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(origin, dir),
                    throughput: wl.unbounded(radiance) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: beam.sun.is_none(),
                    light: number,
                    normal: dir,
                    far: true,
                    origin: None,
                })
            }
            _ => None,
        }
    }
}
