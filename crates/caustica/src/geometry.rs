//! Shapes and their ray intersections.
//!
//! Analytic shapes (sphere, box, square, cylinder and cone in `cone.rs`) are intersected in their own object
//! space: the world ray is mapped by `object_from_world` without renormalising its direction, so
//! the ray parameter `t` is the same in both spaces. Triangles are stored in world space.

pub mod box_shape;
pub mod cone;
pub mod csg;
pub mod disk;
pub mod metaballs;
pub mod roots;
pub mod shape;
pub mod sphere;
pub mod square;
pub mod tangents;
pub mod torus;
pub mod triangle;
pub mod triangle_packet;

pub use shape::{PacketForm, Shape, ShapeKind, ShapeSettings};

use crate::math::{Vec2, Vec3};

/// Where a ray meets an analytic shape, in the shape's object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalHit {
    /// Ray parameter.
    pub t: f32,
    /// The hit point moved onto the surface (`ray.at(t)` carries the rounding of `t`, which can
    /// leave it inside the shape by more than a secondary ray's offset).
    pub point: Vec3,
    /// Object-space normal as the shape defines it (not necessarily unit length).
    pub normal: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
}

/// The roots of `a t² + 2 b t + c = 0` in ascending order, computed without cancellation.
#[cfg(test)]
pub(crate) fn solve_quadratic_half_b(a: f32, half_b: f32, c: f32) -> Option<(f32, f32)> {
    quadratic_roots(a, half_b, c, half_b * half_b - a * c)
}

/// The roots of `a t² + 2 b t + c = 0` in ascending order, given its discriminant `b² − a c`
/// (which callers compute more precisely than from `b` and `c`: for a ray from far away both
/// are large and their difference is lost to rounding).
#[inline]
pub(crate) fn quadratic_roots(a: f32, half_b: f32, c: f32, disc: f32) -> Option<(f32, f32)> {
    if a == 0.0 {
        if half_b == 0.0 {
            return None;
        }
        let t = -c / (2.0 * half_b);
        return Some((t, t));
    }
    if disc < 0.0 || !disc.is_finite() {
        return None;
    }
    let q = -(half_b + disc.sqrt().copysign(half_b));
    let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (q / a, c / q) };
    Some((t0.min(t1), t0.max(t1)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_accurate() {
        let (t0, t1) = solve_quadratic_half_b(1.0, -3.0, 8.0).unwrap();
        assert!((t0 - 2.0).abs() < 1e-6 && (t1 - 4.0).abs() < 1e-6);
        assert!(solve_quadratic_half_b(1.0, 0.0, 1.0).is_none());
        let (a, b) = solve_quadratic_half_b(1.0, -1e4, 1.0).unwrap();
        assert!((a - 5e-5).abs() < 1e-9, "small root keeps precision: {a}");
        assert!((b - 2e4).abs() < 1.0);
    }

    /// A ray from 10⁴ radii away meets the unit sphere at its exact distance: the discriminant
    /// taken about the ray's closest approach keeps it, the plain one loses it to rounding.
    #[test]
    fn far_rays_meet_the_sphere_precisely() {
        let mut worst = (0.0f32, 0.0f32);
        for i in 0..200 {
            let offset = 0.9 * (i as f32 / 200.0);
            let origin = Vec3::new(1e4, offset, 0.3 * offset);
            let ray = crate::math::Ray::new(origin, Vec3::new(-1.0, 0.0, 0.0));
            let hit = sphere::intersect(&ray, f32::INFINITY, false).unwrap();
            let exact = 1e4 - (1.0 - (offset as f64).powi(2) * 1.09).sqrt();
            let plain = solve_quadratic_half_b(1.0, -1e4, origin.length_squared() - 1.0).map_or(f32::INFINITY, |r| r.0);
            worst.0 = worst.0.max((hit.t as f64 - exact).abs() as f32);
            worst.1 = worst.1.max((plain as f64 - exact).abs() as f32);
            assert!(
                (hit.point.length() - 1.0).abs() < 1e-6,
                "the point is put on the surface"
            );
        }
        // The parameter itself is rounded at 10⁴ (a unit in the last place is 1e-3).
        assert!(worst.0 <= 2e-3, "precise: {}", worst.0);
        assert!(worst.1 > 0.01, "the plain discriminant is not: {}", worst.1);
    }
}
