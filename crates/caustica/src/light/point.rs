//! Point and spot lights: next-event estimation joins the shading point to the light's
//! position; emission leaves over the sphere (a spot: over its outer cone), a share aimed at the
//! mirrors and glass.

use super::emission::{Emission, EmitArgs, Emitters};
use super::{spot_profile, DirectQuery, DirectSample, Light};
use crate::math::{Ray, Vec3};
use crate::sampling::{sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf, uniform_sphere_pdf, Rng};

/// A point or spot light's position, and its profile towards the unit direction `out` leaving
/// it (`None` for a point light, whose intensity is the same everywhere).
fn position_and_profile(light: &Light, out: Vec3) -> Option<(Vec3, Option<f32>)> {
    match light {
        Light::Point { position, .. } => Some((*position, None)),
        Light::Spot {
            position,
            direction,
            cos_inner,
            cos_outer,
            exponent,
            ..
        } => Some((
            *position,
            Some(spot_profile(out.dot(*direction), *cos_inner, *cos_outer, *exponent)),
        )),
        _ => None,
    }
}

/// A point or spot light's position.
fn position(light: &Light) -> Option<Vec3> {
    match light {
        Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
        _ => None,
    }
}

/// Next-event estimation's sample of a point or spot light.
#[inline(always)]
pub(super) fn sample_direct(q: &DirectQuery, light: &Light) -> Option<DirectSample> {
    let p = q.hit.point;
    let at = position(light)?;
    let (position, profile) = position_and_profile(light, (p - at).normalize_or_zero())?;
    let d2 = (position - p).length_squared();
    match profile {
        None => q.delta(position, Vec3::ZERO, light.color(), d2, 1.0),
        Some(profile) if profile > 0.0 => q.delta(position, Vec3::ZERO, light.color() * profile, d2, 1.0),
        Some(_) => None,
    }
}

/// Solid-angle density, without aiming, of a point or spot light's direction `dir`.
pub(super) fn plain_pdf(light: &Light, dir: Vec3) -> f32 {
    match light {
        Light::Spot {
            direction, cos_outer, ..
        } if dir.dot(*direction) < *cos_outer => 0.0,
        Light::Spot { cos_outer, .. } => uniform_cone_pdf(*cos_outer),
        _ => uniform_sphere_pdf(),
    }
}

impl Emitters {
    /// A start from a point or spot light: a direction over its sphere or cone, or aimed.
    pub(super) fn emit_point(&self, light: &Light, args: EmitArgs, rng: &mut Rng) -> Option<Emission> {
        let (number, pick, u, _, wl) = args.parts();
        let position = position(light)?;
        let dir = match (self.aimed(position, rng), light) {
            (Some(aimed), _) => aimed?,
            (
                None,
                Light::Spot {
                    direction, cos_outer, ..
                },
            ) => sample_uniform_cone(u, *direction, *cos_outer),
            (None, _) => sample_uniform_sphere(u),
        };
        let (_, profile) = position_and_profile(light, dir)?;
        let pdf = pick * self.direction_pdf(position, dir, plain_pdf(light, dir));
        let color = wl.unbounded(light.color());
        let throughput = match profile {
            None => color / pdf,
            Some(profile) if profile > 0.0 => color * (profile / pdf),
            Some(_) => return None,
        };
        (pdf > 0.0).then(|| Emission {
            ray: Ray::new(position, dir),
            throughput,
            emission_pdf: pdf,
            cos: 1.0,
            delta: true,
            light: number,
            normal: dir,
            far: false,
            origin: None,
        })
    }
}
