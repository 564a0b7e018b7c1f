//! A torus about the z axis: the tube of radius `minor` around the circle of radius `major` in
//! the z = 0 plane (the forks' convention: HKUST `torus { a; b; }`, UT `torus {}`).
//!
//! The intersection solves the quartic in f64 after moving the ray's origin to where it enters
//! the torus's box and making its direction unit length, so the coefficients stay of the
//! torus's own size whatever the transform; the roots come from the monotone-interval method
//! of [`roots`](super::roots).

use super::roots::roots_in;
use super::LocalHit;
use crate::math::{Aabb, Ray, Vec2, Vec3};
use glam::DVec3;
use std::f32::consts::PI;

/// A torus about z.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Torus {
    /// Radius of the ring's centre line.
    pub major: f32,
    /// Radius of the tube.
    pub minor: f32,
}

impl Torus {
    /// Object-space bounds.
    pub fn bounds(&self) -> Aabb {
        let r = self.major + self.minor;
        Aabb::new(Vec3::new(-r, -r, -self.minor), Vec3::new(r, r, self.minor))
    }

    /// The exact distance from `p` to the surface.
    #[inline]
    pub fn distance(&self, p: Vec3) -> f32 {
        let ring = Vec2::new(p.x, p.y).length() - self.major;
        (Vec2::new(ring, p.z).length() - self.minor).abs()
    }

    /// All crossings of the object-space ray in `(0, t_max)`, ascending (at most four).
    pub fn crossings(&self, ray: &Ray, t_max: f32) -> super::roots::Roots {
        let none = super::roots::Roots::default();
        let (o, d) = (ray.origin.as_dvec3(), ray.dir.as_dvec3());
        let len = d.length();
        if len.is_nan() || len <= 0.0 || !len.is_finite() {
            return none;
        }
        let u = d / len;
        // Clip to the box, with a margin for rounding.
        let b = self.bounds();
        let pad = 1e-4 * f64::from(self.major + self.minor);
        let (lo, hi) = (b.min.as_dvec3() - pad, b.max.as_dvec3() + pad);
        let (mut s0, mut s1) = (0.0f64, f64::from(t_max) * len);
        for axis in 0..3 {
            if u[axis] == 0.0 {
                if o[axis] < lo[axis] || o[axis] > hi[axis] {
                    return none;
                }
                continue;
            }
            let (a, c) = ((lo[axis] - o[axis]) / u[axis], (hi[axis] - o[axis]) / u[axis]);
            s0 = s0.max(a.min(c));
            s1 = s1.min(a.max(c));
        }
        if s0.is_nan() || s1.is_nan() || s0 > s1 {
            return none;
        }
        // The quartic in s for the origin moved to s0.
        let q = o + u * s0;
        let (big, small) = (f64::from(self.major), f64::from(self.minor));
        let r2 = big * big;
        let g = q.length_squared() + r2 - small * small;
        let b = q.dot(u);
        let uxy = u.x * u.x + u.y * u.y;
        let coefficients = [
            g * g - 4.0 * r2 * (q.x * q.x + q.y * q.y),
            4.0 * b * g - 8.0 * r2 * (q.x * u.x + q.y * u.y),
            4.0 * b * b + 2.0 * g - 4.0 * r2 * uxy,
            4.0 * b,
            1.0,
        ];
        let found = roots_in(&coefficients, 0.0, s1 - s0);
        let mut out = super::roots::Roots::default();
        for &s in found.as_slice() {
            let t = (s0 + s) / len;
            if t > 0.0 && t < f64::from(t_max) {
                out.push(t);
            }
        }
        out
    }

    /// The nearest hit in `(0, t_max)` of the object-space ray.
    pub fn intersect(&self, ray: &Ray, t_max: f32, needs_uv: bool) -> Option<LocalHit> {
        let t = *self.crossings(ray, t_max).as_slice().first()?;
        let p = ray.origin.as_dvec3() + ray.dir.as_dvec3() * t;
        let (normal, uv) = self.normal_and_uv(p, needs_uv);
        Some(LocalHit {
            t: t as f32,
            // From the f64 root: on the surface to f32 rounding.
            point: p.as_vec3(),
            normal,
            uv,
        })
    }

    /// The outward normal at (near) a surface point, and its texture coordinates: u once around
    /// the ring from +x, v once around the tube from its outer side.
    pub fn normal_and_uv(&self, p: DVec3, needs_uv: bool) -> (Vec3, Vec2) {
        let rho = (p.x * p.x + p.y * p.y).sqrt();
        let ring = if rho > 0.0 {
            DVec3::new(p.x / rho, p.y / rho, 0.0) * f64::from(self.major)
        } else {
            DVec3::X * f64::from(self.major)
        };
        let normal = (p - ring).as_vec3();
        let uv = if needs_uv {
            let u = (p.y.atan2(p.x) as f32 / (2.0 * PI)).rem_euclid(1.0);
            let v = ((p.z.atan2(rho - f64::from(self.major))) as f32 / (2.0 * PI)).rem_euclid(1.0);
            Vec2::new(u, v)
        } else {
            Vec2::ZERO
        };
        (normal, uv)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const RING: Torus = Torus {
        major: 1.0,
        minor: 0.25,
    };

    #[test]
    fn hits_on_the_axis_plane_match_the_circle_radii() {
        // Along −x from far away in the z = 0 plane: crossings at x = 1.25, 0.75, −0.75, −1.25.
        let ray = Ray::new(Vec3::new(10.0, 0.0, 0.0), -Vec3::X);
        let c = RING.crossings(&ray, f32::INFINITY);
        let expected = [8.75, 9.25, 10.75, 11.25];
        assert_eq!(c.as_slice().len(), 4);
        for (t, e) in c.as_slice().iter().zip(expected) {
            assert!((t - e).abs() < 1e-9, "{t} vs {e}");
        }
        let hit = RING.intersect(&ray, f32::INFINITY, true).unwrap();
        assert!((hit.normal.normalize() - Vec3::X).length() < 1e-6);
        assert!(hit.uv.x.abs() < 1e-6 && hit.uv.y.abs() < 1e-6, "{:?}", hit.uv);
        // Down the axis: through the hole.
        assert!(RING
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z), f32::INFINITY, false)
            .is_none());
        // Down onto the top of the tube at x = 1: t = 5 − 0.25, normal +z.
        let top = RING
            .intersect(
                &Ray::new(Vec3::new(1.0, 0.0, 5.0), -Vec3::Z * 2.0),
                f32::INFINITY,
                false,
            )
            .unwrap();
        assert!(
            (top.t - 2.375).abs() < 1e-6,
            "t in units of the (non-unit) direction: {}",
            top.t
        );
        assert!((top.normal.normalize() - Vec3::Z).length() < 1e-6);
    }

    /// Random rays: every reported crossing lies on the surface (to 1e-5 of its size), and a
    /// ray from inside the tube finds its way out.
    #[test]
    fn crossings_lie_on_the_surface() {
        let mut rng = crate::sampling::Rng::new(11, 0);
        let mut count = 0;
        for _ in 0..20_000 {
            let origin = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE) * 40.0;
            let target = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE) * 1.3;
            let ray = Ray::new(origin, (target - origin) * 0.37);
            for &t in RING.crossings(&ray, f32::INFINITY).as_slice() {
                let p = ray.origin.as_dvec3() + ray.dir.as_dvec3() * t;
                assert!(RING.distance(p.as_vec3()) < 1e-5, "{ray:?} at {t}");
                count += 1;
            }
        }
        assert!(count > 10_000, "{count} crossings");
        let inside = Ray::new(Vec3::new(1.0, 0.0, 0.1), Vec3::new(0.3, 0.7, 0.2));
        assert_eq!(RING.crossings(&inside, f32::INFINITY).as_slice().len() % 2, 1);
    }
}
