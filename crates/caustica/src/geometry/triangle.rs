//! Triangles and a watertight ray–triangle test.
//!
//! The test follows Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection" (JCGT
//! 2013): vertices are translated to the ray origin and sheared so the ray runs along +z, then
//! the three 2D edge functions decide the hit. Each vertex is transformed the same way in
//! every triangle that shares it, and a 2D edge function `a·b − c·d` evaluated in floats has
//! the exact sign or is zero (rounding is monotone); zeros are redone in `f64`, where the
//! products are exact. So a ray through a shared edge or vertex always hits one of the
//! triangles (edges count as inside, so it may hit both).

use glam::{Vec4, Vec4Swizzles};

use crate::math::{Aabb, Ray, Vec3};

/// A triangle ready for intersection: per axis, the coordinates of its vertices `a`, `b`, `c`
/// in the first three lanes (the fourth repeats `a`), so the test runs on all three vertices at
/// once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Triangle {
    v: [Vec4; 3],
}

/// A ray–triangle hit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleHit {
    /// Ray parameter of the hit, in units of the ray direction.
    pub t: f32,
    /// Barycentric weight of vertex `b`.
    pub u: f32,
    /// Barycentric weight of vertex `c`.
    pub v: f32,
}

/// Per-ray constants of the triangle test; computing them once per ray and calling
/// [`Triangle::intersect_pre`] saves work when one ray meets many triangles.
#[derive(Clone, Copy, Debug)]
pub struct TriangleRay {
    /// Axes permuted so `dir[kz]` is the largest component.
    pub(crate) k: [usize; 3],
    /// Origin components in permuted order, splatted.
    pub(crate) origin: [Vec4; 3],
    /// Shear `dir[kx] / dir[kz]`, `dir[ky] / dir[kz]`, splatted.
    pub(crate) shear: [Vec4; 2],
    /// `1 / dir[kz]`.
    pub(crate) inv_dz: f32,
}

impl TriangleRay {
    /// Precomputes the shear for `ray`. A zero direction hits nothing.
    #[inline]
    pub fn new(ray: &Ray) -> TriangleRay {
        let d = ray.dir.abs();
        let kz = if d.x > d.y && d.x > d.z {
            0
        } else if d.y > d.z {
            1
        } else {
            2
        };
        let k = [(kz + 1) % 3, (kz + 2) % 3, kz];
        let dz = ray.dir[kz];
        TriangleRay {
            k,
            origin: k.map(|i| Vec4::splat(ray.origin[i])),
            shear: [Vec4::splat(ray.dir[k[0]] / dz), Vec4::splat(ray.dir[k[1]] / dz)],
            inv_dz: 1.0 / dz,
        }
    }
}

impl Triangle {
    /// A triangle from three world-space vertices.
    #[inline]
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Triangle {
        Triangle {
            v: [0, 1, 2].map(|i| Vec4::new(a[i], b[i], c[i], a[i])),
        }
    }

    /// Distance from `p` to the triangle's plane, a lower bound on the distance to the triangle
    /// (0 for a degenerate triangle).
    #[inline]
    pub fn plane_distance(&self, p: Vec3) -> f32 {
        let [a, b, c] = self.vertices();
        let n = (b - a).cross(c - a);
        let len = n.length();
        if len > 0.0 && len.is_finite() {
            // Shrunk a little against rounding in the cross product.
            ((p - a).dot(n) / len).abs() * (1.0 - 1e-4)
        } else {
            0.0
        }
    }

    /// The three vertices `[a, b, c]`.
    #[inline]
    pub fn vertices(&self) -> [Vec3; 3] {
        let [x, y, z] = self.v;
        [0, 1, 2].map(|i| Vec3::new(x[i], y[i], z[i]))
    }

    /// The hit with `0 < t < t_max`, if any. Both faces are hit; points on edges and vertices
    /// count as inside. Degenerate triangles and rays in the triangle's plane miss.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<TriangleHit> {
        self.intersect_pre(&TriangleRay::new(ray), t_max)
    }

    /// [`Triangle::intersect`] with the per-ray constants computed once by the caller.
    #[inline]
    pub fn intersect_pre(&self, ray: &TriangleRay, t_max: f32) -> Option<TriangleHit> {
        let [kx, ky, kz] = ray.k;
        // Vertex coordinates relative to the origin, sheared so the ray runs along +z; lanes
        // are the vertices a, b, c.
        let z = self.v[kz] - ray.origin[2];
        let x = (self.v[kx] - ray.origin[0]) - ray.shear[0] * z;
        let y = (self.v[ky] - ray.origin[1]) - ray.shear[1] * z;
        // Edge functions: lane i is the (unnormalised) barycentric weight of vertex i.
        let mut w = x.zxyw() * y.yzxw() - y.zxyw() * x.yzxw();
        if w.cmpeq(Vec4::ZERO).bitmask() & 7 != 0 {
            w = exact_edges(x, y);
        }
        let neg = w.cmplt(Vec4::ZERO).bitmask() & 7;
        let pos = w.cmpgt(Vec4::ZERO).bitmask() & 7;
        if neg != 0 && pos != 0 {
            return None;
        }
        let det = w.x + w.y + w.z;
        let p = w * z;
        let t = (p.x + p.y + p.z) * ray.inv_dz / det;
        // Also rejects det == 0 (t is then infinite or NaN).
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let inv = 1.0 / det;
        Some(TriangleHit {
            t,
            u: w.y * inv,
            v: w.z * inv,
        })
    }

    /// Bounding box of the three vertices.
    #[inline]
    pub fn bounds(&self) -> Aabb {
        let [x, y, z] = self.v;
        Aabb {
            min: Vec3::new(x.min_element(), y.min_element(), z.min_element()),
            max: Vec3::new(x.max_element(), y.max_element(), z.max_element()),
        }
    }

    /// Unit normal `normalize((b − a) × (c − a))`; zero for a degenerate triangle.
    #[inline]
    pub fn geometric_normal(&self) -> Vec3 {
        let [a, b, c] = self.vertices();
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// The point with barycentric weights `u` (of `b`) and `v` (of `c`).
    #[inline]
    pub fn point(&self, u: f32, v: f32) -> Vec3 {
        let [a, b, c] = self.vertices();
        a * (1.0 - u - v) + b * u + c * v
    }
}

/// Edge functions in `f64`, where the products are exact, to settle the sign of zeros.
#[cold]
fn exact_edges(x: Vec4, y: Vec4) -> Vec4 {
    let (x, y) = (x.to_array().map(f64::from), y.to_array().map(f64::from));
    let e = |i: usize, j: usize| (x[j] * y[i] - y[j] * x[i]) as f32;
    Vec4::new(e(1, 2), e(2, 0), e(0, 1), 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri() -> Triangle {
        Triangle::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
        )
    }

    /// Small deterministic generator (xorshift64*), so tests need no extra crate.
    struct Rng(u64);
    impl Rng {
        fn f(&mut self) -> f32 {
            self.0 ^= self.0 >> 12;
            self.0 ^= self.0 << 25;
            self.0 ^= self.0 >> 27;
            (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
        }
    }

    #[test]
    fn hit_matches_analytic_answer() {
        let ray = Ray::new(Vec3::new(0.5, 0.25, 3.0), Vec3::new(0.0, 0.0, -2.0));
        let h = tri().intersect(&ray, f32::INFINITY).unwrap();
        assert!((h.t - 1.5).abs() < 1e-6, "{h:?}");
        assert!((h.u - 0.25).abs() < 1e-6 && (h.v - 0.125).abs() < 1e-6, "{h:?}");
        // Back face, oblique, non-unit direction.
        let o = Vec3::new(-1.0, -2.0, -4.0);
        let target = tri().point(0.3, 0.5);
        let ray = Ray::new(o, (target - o) * 0.25);
        let h = tri().intersect(&ray, f32::INFINITY).unwrap();
        assert!(
            (h.t - 4.0).abs() < 1e-5 && (h.u - 0.3).abs() < 1e-5 && (h.v - 0.5).abs() < 1e-5,
            "{h:?}"
        );
    }

    #[test]
    fn misses_outside_behind_beyond_and_parallel() {
        let t = tri();
        let down = Vec3::new(0.0, 0.0, -1.0);
        assert!(t.intersect(&Ray::new(Vec3::new(1.5, 1.5, 1.0), down), 10.0).is_none());
        assert!(t.intersect(&Ray::new(Vec3::new(-0.1, 0.5, 1.0), down), 10.0).is_none());
        // Behind the origin.
        assert!(t.intersect(&Ray::new(Vec3::new(0.5, 0.5, -1.0), down), 10.0).is_none());
        // Beyond t_max, and exactly at t_max (exclusive).
        assert!(t.intersect(&Ray::new(Vec3::new(0.5, 0.5, 1.0), down), 0.5).is_none());
        assert!(t.intersect(&Ray::new(Vec3::new(0.5, 0.5, 1.0), down), 1.0).is_none());
        // Parallel above and within the plane.
        assert!(t
            .intersect(&Ray::new(Vec3::new(-1.0, 0.5, 1.0), Vec3::X), 10.0)
            .is_none());
        assert!(t
            .intersect(&Ray::new(Vec3::new(-1.0, 0.5, 0.0), Vec3::X), 10.0)
            .is_none());
        // Zero direction.
        assert!(t
            .intersect(&Ray::new(Vec3::new(0.5, 0.5, 1.0), Vec3::ZERO), 10.0)
            .is_none());
        // Degenerate triangles never hit.
        let line = Triangle::new(Vec3::ZERO, Vec3::X, Vec3::X * 2.0);
        assert!(line
            .intersect(&Ray::new(Vec3::new(0.5, 0.0, 1.0), down), 10.0)
            .is_none());
        let point = Triangle::new(Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
        assert!(point
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 1.0), down), 10.0)
            .is_none());
        assert_eq!(point.geometric_normal(), Vec3::ZERO);
    }

    #[test]
    fn edges_and_vertices_count_as_hits() {
        let t = tri();
        let down = Vec3::new(0.0, 0.0, -1.0);
        for p in [
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 1.0),
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(0.0, 0.0, 1.0),
        ] {
            let h = t.intersect(&Ray::new(p, down), 10.0);
            assert!(h.is_some(), "{p}");
            assert!((h.unwrap().t - 1.0).abs() < 1e-6);
        }
    }

    #[test]
    fn bounds_and_normal() {
        let t = tri();
        assert_eq!(t.bounds(), Aabb::new(Vec3::ZERO, Vec3::new(2.0, 2.0, 0.0)));
        assert_eq!(t.geometric_normal(), Vec3::Z);
    }

    /// Rays through the shared edges and vertices of a tessellated, irregular grid must hit at
    /// least one triangle: no cracks.
    #[test]
    fn tessellated_grid_is_watertight() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let n = 24;
        let mut verts = Vec::new();
        for j in 0..=n {
            for i in 0..=n {
                let jitter = |r: &mut Rng| (r.f() - 0.5) * 0.6;
                let x = i as f32 + if 0 < i && i < n { jitter(&mut rng) } else { 0.0 };
                let y = j as f32 + if 0 < j && j < n { jitter(&mut rng) } else { 0.0 };
                let z = (x * 0.37).sin() * 2.0 + (y * 0.23).cos() * 1.5;
                verts.push(Vec3::new(x, y, z) * 0.173);
            }
        }
        let idx = |i: usize, j: usize| j * (n + 1) + i;
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (
                    verts[idx(i, j)],
                    verts[idx(i + 1, j)],
                    verts[idx(i + 1, j + 1)],
                    verts[idx(i, j + 1)],
                );
                // Alternate diagonals and windings so shared edges appear in both orders.
                if (i + j) % 2 == 0 {
                    tris.push(Triangle::new(a, b, c));
                    tris.push(Triangle::new(a, c, d));
                } else {
                    tris.push(Triangle::new(b, d, a));
                    tris.push(Triangle::new(c, d, b));
                }
            }
        }
        let mut targets = Vec::new();
        for j in 1..n {
            for i in 1..n {
                let p = verts[idx(i, j)];
                targets.push(p); // interior vertex
                targets.push(p.lerp(verts[idx(i + 1, j)], rng.f())); // horizontal edge
                targets.push(p.lerp(verts[idx(i, j + 1)], rng.f())); // vertical edge
                let (d0, d1) = if (i + j) % 2 == 0 {
                    (p, verts[idx(i + 1, j + 1)])
                } else {
                    (verts[idx(i + 1, j)], verts[idx(i, j + 1)])
                };
                targets.push(d0.lerp(d1, rng.f())); // diagonal edge
            }
        }
        let mut tested = 0;
        for &target in &targets {
            for _ in 0..8 {
                // Steeper than any facet (slopes stay below 0.9), so no ray merely grazes a
                // silhouette vertex.
                let dir = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, -1.2 - rng.f()) * (0.5 + 4.0 * rng.f());
                let origin = target - dir * (1.0 + 3.0 * rng.f());
                let ray = Ray::new(origin, target - origin);
                let hit = tris.iter().any(|t| t.intersect(&ray, f32::INFINITY).is_some());
                assert!(hit, "crack at {target} for ray {ray:?}");
                tested += 1;
            }
        }
        assert!(tested > 10_000);
    }
}
