//! The square [-0.5, 0.5]² in the z = 0 plane: thin and two-sided.

use super::LocalHit;
use crate::math::{Aabb, Ray, Vec2, Vec3};

/// Object-space bounds (flat in z).
pub fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-0.5, -0.5, 0.0), Vec3::new(0.5, 0.5, 0.0))
}

/// Hit in `(0, t_max)`; the normal is ±z, turned to face the incoming ray (§7).
pub fn intersect(ray: &Ray, t_max: f32) -> Option<LocalHit> {
    if ray.dir.z == 0.0 {
        return None;
    }
    let t = -ray.origin.z / ray.dir.z;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let p = ray.at(t);
    if p.x.abs() > 0.5 || p.y.abs() > 0.5 {
        return None;
    }
    let normal = if ray.dir.z > 0.0 { -Vec3::Z } else { Vec3::Z };
    Some(LocalHit {
        t,
        point: Vec3::new(p.x, p.y, 0.0),
        normal,
        uv: Vec2::new(p.x + 0.5, p.y + 0.5),
    })
}
