//! The `.ray` `box` primitive: the cube [-0.5, 0.5]³.

use super::LocalHit;
use crate::math::{Aabb, Ray, Vec2, Vec3};

/// Object-space bounds.
pub fn bounds() -> Aabb {
    Aabb::new(Vec3::splat(-0.5), Vec3::splat(0.5))
}

/// Nearest hit in `(0, t_max)` with the outward face normal (not flipped from inside, §7).
pub fn intersect(ray: &Ray, t_max: f32) -> Option<LocalHit> {
    let mut t_near = f32::NEG_INFINITY;
    let mut t_far = f32::INFINITY;
    let mut axis_near = 0;
    let mut axis_far = 0;
    for axis in 0..3 {
        let (o, d) = (ray.origin[axis], ray.dir[axis]);
        if d == 0.0 {
            if o.abs() > 0.5 {
                return None;
            }
            continue;
        }
        let inv = 1.0 / d;
        let (a, b) = ((-0.5 - o) * inv, (0.5 - o) * inv);
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        if lo > t_near {
            t_near = lo;
            axis_near = axis;
        }
        if hi < t_far {
            t_far = hi;
            axis_far = axis;
        }
    }
    if t_near > t_far {
        return None;
    }
    let (t, axis) = if t_near > 0.0 {
        (t_near, axis_near)
    } else {
        (t_far, axis_far)
    };
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let mut p = ray.at(t);
    let sign = if p[axis] >= 0.0 { 1.0 } else { -1.0 };
    // Exactly on the face.
    p[axis] = 0.5 * sign;
    let mut normal = Vec3::ZERO;
    normal[axis] = sign;
    Some(LocalHit {
        t,
        point: p,
        normal,
        uv: face_uv(p, axis, sign),
    })
}

/// §7 box UV: on the +k face u = 0.5 + p_i, on the −k face u = 0.5 − p_i; v = 0.5 + p_j.
fn face_uv(p: Vec3, axis: usize, sign: f32) -> Vec2 {
    let (i, j) = match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    };
    Vec2::new(0.5 + sign * p[i], 0.5 + p[j])
}
