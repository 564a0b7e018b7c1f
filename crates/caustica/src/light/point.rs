//! Point and spot lights: next-event estimation joins the shading point to the light's
//! position; emission leaves over the sphere (a spot: over its outer cone), a share aimed at the
//! mirrors and glass.

use super::emission::{Emission, EmitArgs, Emitters};
use super::{spot_profile, DirectQuery, DirectSample, Light};
use crate::math::{Ray, Vec3};
use crate::sampling::{sample_uniform_cone, sample_uniform_sphere, uniform_cone_pdf, uniform_sphere_pdf, Rng};

/// Next-event estimation's sample of a point or spot light.
pub(super) fn sample_direct(q: &DirectQuery, light: &Light) -> Option<DirectSample> {
    let p = q.hit.point;
    match light {
        Light::Point { position, color, .. } => {
            q.delta(*position, Vec3::ZERO, *color, (*position - p).length_squared(), 1.0)
        }
        Light::Spot {
            position,
            direction,
            color,
            cos_inner,
            cos_outer,
            exponent,
            ..
        } => {
            let out = (p - *position).normalize_or_zero();
            let profile = spot_profile(out.dot(*direction), *cos_inner, *cos_outer, *exponent);
            if profile <= 0.0 {
                return None;
            }
            let d2 = (*position - p).length_squared();
            q.delta(*position, Vec3::ZERO, *color * profile, d2, 1.0)
        }
        _ => None,
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
        let EmitArgs {
            number, pick, u, wl, ..
        } = args;
        match light {
            light @ Light::Point { position, color, .. } => {
                let dir = match self.aimed(*position, rng) {
                    Some(aimed) => aimed?,
                    None => sample_uniform_sphere(u),
                };
                let pdf = pick * self.direction_pdf(*position, dir, super::point::plain_pdf(light, dir));
                (pdf > 0.0).then(|| Emission {
                    ray: Ray::new(*position, dir),
                    throughput: wl.unbounded(*color) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: true,
                    light: number,
                    normal: dir,
                    far: false,
                    origin: None,
                })
            }
            light @ Light::Spot {
                position,
                direction,
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => {
                let dir = match self.aimed(*position, rng) {
                    Some(aimed) => aimed?,
                    None => sample_uniform_cone(u, *direction, *cos_outer),
                };
                let profile = spot_profile(dir.dot(*direction), *cos_inner, *cos_outer, *exponent);
                let pdf = pick * self.direction_pdf(*position, dir, super::point::plain_pdf(light, dir));
                (profile > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(*position, dir),
                    throughput: wl.unbounded(*color) * (profile / pdf),
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: true,
                    light: number,
                    normal: dir,
                    far: false,
                    origin: None,
                })
            }
            _ => None,
        }
    }
}
