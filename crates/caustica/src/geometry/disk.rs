//! The disc of radius 1 in the z = 0 plane, with a hole of radius `inner`: thin and two-sided
//! like the square (pbrt-v4's `disk`, placed by its height and radius).

use super::LocalHit;
use crate::math::{Aabb, Ray, Vec2, Vec3};
use std::f32::consts::PI;

/// Object-space bounds (flat in z).
pub fn bounds() -> Aabb {
    Aabb::new(Vec3::new(-1.0, -1.0, 0.0), Vec3::new(1.0, 1.0, 0.0))
}

/// Hit in `(0, t_max)`; the normal is ±z, turned to face the incoming ray. Texture coordinates
/// are pbrt's: u the angle around +z over 2π, v from the rim (0) to the hole (1).
pub fn intersect(ray: &Ray, t_max: f32, inner: f32) -> Option<LocalHit> {
    if ray.dir.z == 0.0 {
        return None;
    }
    let t = -ray.origin.z / ray.dir.z;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let p = ray.at(t);
    let r2 = p.x * p.x + p.y * p.y;
    if r2 > 1.0 || r2 < inner * inner {
        return None;
    }
    let normal = if ray.dir.z > 0.0 { -Vec3::Z } else { Vec3::Z };
    let phi = p.y.atan2(p.x);
    let u = if phi < 0.0 { phi + 2.0 * PI } else { phi } / (2.0 * PI);
    let v = (1.0 - r2.sqrt()) / (1.0 - inner).max(1e-6);
    Some(LocalHit {
        t,
        // On the plane exactly, as the square does.
        point: Vec3::new(p.x, p.y, 0.0),
        normal,
        uv: Vec2::new(u, v),
    })
}

/// Distance from `p` to the annulus.
pub fn distance(p: Vec3, inner: f32) -> f32 {
    let rho = (p.x * p.x + p.y * p.y).sqrt();
    let dr = (rho - 1.0).max(inner - rho).max(0.0);
    (dr * dr + p.z * p.z).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hits_the_ring_and_not_the_hole() {
        let down = |x: f32| intersect(&Ray::new(Vec3::new(x, 0.0, 2.0), -Vec3::Z), f32::INFINITY, 0.5);
        assert!(down(0.2).is_none(), "the hole");
        assert!(down(1.2).is_none(), "outside");
        let hit = down(0.75).unwrap();
        assert_eq!(hit.t, 2.0);
        assert_eq!(hit.normal, Vec3::Z);
        assert!((hit.uv.y - 0.5).abs() < 1e-6);
        let up = intersect(&Ray::new(Vec3::new(0.75, 0.0, -1.0), Vec3::Z), f32::INFINITY, 0.5).unwrap();
        assert_eq!(up.normal, -Vec3::Z);
        assert!((distance(Vec3::new(0.0, 0.0, 0.0), 0.5) - 0.5).abs() < 1e-6);
        assert!((distance(Vec3::new(3.0, 0.0, 4.0), 0.0) - (4.0f32 + 16.0).sqrt()).abs() < 1e-5);
    }
}
