//! The unit sphere at the origin.

use super::{solve_quadratic_half_b, LocalHit};
use crate::math::{Aabb, Ray, Vec2, Vec3};
use std::f32::consts::PI;

/// Object-space bounds.
pub fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0))
}

/// Nearest hit in `(0, t_max)`; the normal is outward, also when the ray starts inside. Texture
/// coordinates (two inverse trigonometric calls) only `with_uv`, zero otherwise.
pub fn intersect(ray: &Ray, t_max: f32, with_uv: bool) -> Option<LocalHit> {
    let (o, d) = (ray.origin, ray.dir);
    let (t0, t1) = solve_quadratic_half_b(d.dot(d), o.dot(d), o.dot(o) - 1.0)?;
    let t = if t0 > 0.0 { t0 } else { t1 };
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let p = ray.at(t);
    Some(LocalHit {
        t,
        normal: p,
        uv: if with_uv { uv(p) } else { Vec2::ZERO },
    })
}

/// Longitude around +z and latitude from the −z pole, both in [0, 1].
pub fn uv(p: Vec3) -> Vec2 {
    let phi = p.y.atan2(p.x);
    let u = if phi < 0.0 { phi + 2.0 * PI } else { phi } / (2.0 * PI);
    let v = (-p.z.clamp(-1.0, 1.0)).acos() / PI;
    Vec2::new(u, v)
}
