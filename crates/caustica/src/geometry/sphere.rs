//! The unit sphere at the origin.

use super::{quadratic_roots, LocalHit};
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
    let (a, half_b) = (d.dot(d), o.dot(d));
    // The discriminant from the ray's point nearest the centre, l: a (1 − |l|)(1 + |l|) loses
    // nothing to |o|² (pbrt-v4; Haines et al., Ray Tracing Gems ch. 7).
    let l = o - d * (half_b / a);
    let l_len = l.length();
    let disc = a * ((1.0 - l_len) * (1.0 + l_len));
    let (t0, t1) = quadratic_roots(a, half_b, o.dot(o) - 1.0, disc)?;
    let t = if t0 > 0.0 { t0 } else { t1 };
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let p = ray.at(t);
    let point = p / p.length();
    Some(LocalHit {
        t,
        point,
        normal: point,
        uv: if with_uv { uv(point) } else { Vec2::ZERO },
    })
}

/// Longitude around +z and latitude from the −z pole, both in [0, 1].
pub fn uv(p: Vec3) -> Vec2 {
    let phi = p.y.atan2(p.x);
    let u = if phi < 0.0 { phi + 2.0 * PI } else { phi } / (2.0 * PI);
    let v = (-p.z.clamp(-1.0, 1.0)).acos() / PI;
    Vec2::new(u, v)
}
