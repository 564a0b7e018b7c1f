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
pub mod torus;
pub mod triangle;
pub mod triangle_packet;

pub use shape::{Shape, ShapeKind, ShapeSettings};

use crate::math::{Vec2, Vec3};

/// Where a ray meets an analytic shape, in the shape's object space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LocalHit {
    /// Ray parameter.
    pub t: f32,
    /// Object-space normal as the shape defines it (not necessarily unit length).
    pub normal: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
}

/// The roots of `a t² + 2 b t + c = 0` in ascending order, computed without cancellation.
#[inline]
pub(crate) fn solve_quadratic_half_b(a: f32, half_b: f32, c: f32) -> Option<(f32, f32)> {
    if a == 0.0 {
        if half_b == 0.0 {
            return None;
        }
        let t = -c / (2.0 * half_b);
        return Some((t, t));
    }
    let disc = half_b * half_b - a * c;
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
}
