//! Vectors, rays, bounding boxes and orthonormal frames.
//!
//! caustica computes in `f32` (glam's `Vec3`); positions, directions and normals share that type.

pub use glam::{Affine2, Mat3, Mat4, Quat, Vec2, Vec3, Vec4};

/// A ray `origin + t · dir`; `dir` need not be unit length unless a caller says so.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Direction.
    pub dir: Vec3,
}

impl Ray {
    /// Creates a ray.
    #[inline]
    pub fn new(origin: Vec3, dir: Vec3) -> Ray {
        Ray { origin, dir }
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: f32) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// An axis-aligned bounding box; the empty box has `min > max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// Lower corner.
    pub min: Vec3,
    /// Upper corner.
    pub max: Vec3,
}

impl Default for Aabb {
    fn default() -> Self {
        Aabb::EMPTY
    }
}

impl Aabb {
    /// The box that contains nothing; growing it by a point gives that point.
    pub const EMPTY: Aabb = Aabb {
        min: Vec3::splat(f32::INFINITY),
        max: Vec3::splat(f32::NEG_INFINITY),
    };

    /// The box spanned by two corners.
    #[inline]
    pub fn new(a: Vec3, b: Vec3) -> Aabb {
        Aabb {
            min: a.min(b),
            max: a.max(b),
        }
    }

    /// Whether the box contains no point.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.min.x > self.max.x || self.min.y > self.max.y || self.min.z > self.max.z
    }

    /// The box grown to contain `p`.
    #[inline]
    pub fn with_point(self, p: Vec3) -> Aabb {
        Aabb {
            min: self.min.min(p),
            max: self.max.max(p),
        }
    }

    /// The smallest box containing both boxes.
    #[inline]
    pub fn union(self, other: Aabb) -> Aabb {
        Aabb {
            min: self.min.min(other.min),
            max: self.max.max(other.max),
        }
    }

    /// Centre point.
    #[inline]
    pub fn center(&self) -> Vec3 {
        (self.min + self.max) * 0.5
    }

    /// Edge lengths (zero for an empty box).
    #[inline]
    pub fn extent(&self) -> Vec3 {
        (self.max - self.min).max(Vec3::ZERO)
    }

    /// Surface area (zero for an empty box).
    #[inline]
    pub fn surface_area(&self) -> f32 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// The box of the eight transformed corners.
    pub fn transformed(&self, m: &Mat4) -> Aabb {
        if self.is_empty() {
            return *self;
        }
        let mut out = Aabb::EMPTY;
        for i in 0..8 {
            let corner = Vec3::new(
                if i & 1 == 0 { self.min.x } else { self.max.x },
                if i & 2 == 0 { self.min.y } else { self.max.y },
                if i & 4 == 0 { self.min.z } else { self.max.z },
            );
            out = out.with_point(m.transform_point3(corner));
        }
        out
    }

    /// The ray's entry and exit parameters, if it meets the box within `[t_min, t_max]`.
    #[inline]
    pub fn intersect(&self, origin: Vec3, inv_dir: Vec3, t_min: f32, t_max: f32) -> Option<(f32, f32)> {
        let t0 = (self.min - origin) * inv_dir;
        let t1 = (self.max - origin) * inv_dir;
        let near = t0.min(t1).max_element().max(t_min);
        let far = t0.max(t1).min_element().min(t_max);
        (near <= far).then_some((near, far))
    }
}

/// An orthonormal frame; `z` is the normal.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// First tangent.
    pub x: Vec3,
    /// Second tangent.
    pub y: Vec3,
    /// Normal.
    pub z: Vec3,
}

impl Frame {
    /// A frame around the unit vector `n` (Duff et al. 2017, branchless).
    pub fn from_normal(n: Vec3) -> Frame {
        let sign = 1.0f32.copysign(n.z);
        let a = -1.0 / (sign + n.z);
        let b = n.x * n.y * a;
        let x = Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x);
        let y = Vec3::new(b, sign + n.y * n.y * a, -n.y);
        Frame { x, y, z: n }
    }

    /// World vector expressed in this frame.
    #[inline]
    pub fn to_local(&self, v: Vec3) -> Vec3 {
        Vec3::new(v.dot(self.x), v.dot(self.y), v.dot(self.z))
    }

    /// Local vector expressed in world coordinates.
    #[inline]
    pub fn to_world(&self, v: Vec3) -> Vec3 {
        self.x * v.x + self.y * v.y + self.z * v.z
    }
}

/// Mirror reflection of `d` (pointing towards the surface) about the unit normal `n`.
#[inline]
pub fn reflect(d: Vec3, n: Vec3) -> Vec3 {
    d - 2.0 * d.dot(n) * n
}

/// Refraction of the unit direction `d` through a surface with unit normal `n` facing against `d`,
/// with `eta` = n_from / n_to; `None` on total internal reflection.
#[inline]
pub fn refract(d: Vec3, n: Vec3, eta: f32) -> Option<Vec3> {
    let cos_i = -d.dot(n);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    Some((eta * d + (eta * cos_i - cos_t) * n).normalize())
}

/// Moves `p` off a surface with geometric normal `ng` to the side `dir` points to, by an amount
/// scaled to the magnitude of `p`, so that a ray leaving `p` along `dir` does not hit the surface
/// it starts on (no fixed epsilon: the offset follows the floating-point error of `p`).
#[inline]
pub fn offset_origin(p: Vec3, ng: Vec3, dir: Vec3) -> Vec3 {
    let n = if ng.dot(dir) >= 0.0 { ng } else { -ng };
    offset_along(p, n)
}

/// [`offset_origin`] for a point whose coordinates may be off by up to `error` each: it moves at
/// least far enough along the normal to leave that box of uncertainty (pbrt's `OffsetRayOrigin`).
#[inline]
pub fn offset_origin_bounded(p: Vec3, ng: Vec3, dir: Vec3, error: Vec3) -> Vec3 {
    let n = if ng.dot(dir) >= 0.0 { ng } else { -ng };
    let by_magnitude = 1e-4 * (1.0 + p.abs().max_element()) * 0.0625;
    let by_error = 2.0 * n.abs().dot(error);
    p + n * by_magnitude.max(by_error)
}

/// Moves `p` off its surface to the side the unit normal `n` points to, by the same
/// magnitude-relative amount as [`offset_origin`].
#[inline]
pub fn offset_along(p: Vec3, n: Vec3) -> Vec3 {
    let scale = 1e-4 * (1.0 + p.abs().max_element()) * 0.0625;
    p + n * scale
}

/// Luminance with the skeleton's weights (0.299, 0.587, 0.114).
#[inline]
pub fn luminance(c: Vec3) -> f32 {
    0.299 * c.x + 0.587 * c.y + 0.114 * c.z
}

/// `(sin, cos)` of `turns` whole turns (the angle 2π·`turns`), to within 2·10⁻⁷ for |`turns`| up
/// to 2²². The sample warps' angles: inlined and without branches, where the C library's
/// `sincosf` was a call around which the caller kept its vector registers on the stack; plain
/// arithmetic, so the same bits on every host.
#[inline]
pub fn sin_cos_turns(turns: f32) -> (f32, f32) {
    // The nearest quarter turn, and the rest as an angle in [-π/4, π/4].
    let q = round_to_i32(turns * 4.0);
    let quarter = q as f32;
    let x = (turns - quarter * 0.25) * std::f32::consts::TAU;
    let x2 = x * x;
    // Taylor series to x⁹ and x⁸: their first terms left out are below 3·10⁻⁸ there.
    let sin = x * (1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0)))));
    let cos = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40_320.0))));
    // A quarter turn more swaps them and turns the new cosine's sign; two turn both.
    let q = q as u32;
    let (s, c) = if q & 1 == 0 { (sin, cos) } else { (cos, sin) };
    (
        f32::from_bits(s.to_bits() ^ ((q & 2) << 30)),
        f32::from_bits(c.to_bits() ^ ((q.wrapping_add(1) & 2) << 30)),
    )
}

/// `x.round()` as an integer, for |`x`| below 2³¹: halves away from zero, as `round`, without
/// the library call baseline x86-64 makes for it (the fraction left after truncating is exact).
#[inline]
pub fn round_to_i32(x: f32) -> i32 {
    let whole = x as i32;
    let rest = x - whole as f32;
    whole + i32::from(rest >= 0.5) - i32::from(rest <= -0.5)
}

/// `x.floor()` as an integer, exact for |x| ≤ 2⁴⁰ (the conversion truncates toward zero, and
/// an f32 that large is whole), without the library call baseline x86-64 makes for `floor`.
#[inline(always)]
pub fn floor_to_i64(x: f32) -> i64 {
    let whole = x as i64;
    whole.saturating_sub(i64::from(x < whole as f32))
}

/// `x.floor() as i32`, saturating as that conversion does (NaN to 0): [`floor_to_i64`] in
/// 32 bits, for a grid's cells (clamping the 64-bit floor cost vcm 0.4% more instructions).
#[inline(always)]
pub fn floor_to_i32(x: f32) -> i32 {
    let whole = x as i32;
    whole.saturating_sub(i32::from(x < whole as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Test values for the integer roundings: the multiples of `step` from −40 to 40 steps,
    /// each with its neighbours a ULP away, then 100,000 random values up to 2^`scales` drawn
    /// with `seed`.
    fn steps_and_scales((step, scales): (f32, i32), seed: u64) -> impl Iterator<Item = f32> {
        let steps = (-40..=40).map(move |k| k as f32 * step);
        let near = steps.clone().flat_map(|t| [t.next_down(), t.next_up()]);
        let mut rng = crate::sampling::Rng::new(seed, 0);
        let random =
            (0..100_000).map(move |_| (rng.uniform() - 0.5) * 2f32.powi((rng.uniform() * scales as f32) as i32));
        steps.chain(near).chain(random)
    }

    /// Both integer floors agree with `f32::floor` on whole numbers and halves, their
    /// neighbours, random values of every scale and the edges of the integer types.
    #[test]
    fn flooring_to_an_integer_matches_floor() {
        let edges = [
            0.0,
            -0.0,
            f32::NAN,
            f32::INFINITY,
            f32::NEG_INFINITY,
            f32::MAX,
            f32::MIN,
            2f32.powi(31),
            -(2f32.powi(31)),
            -(2f32.powi(31)).next_up(),
            -(2f32.powi(32)),
            2f32.powi(24) + 2.0,
            -(2f32.powi(24)) - 2.0,
            -1e-30,
            1e12,
            -1e12,
            16_777_217.0,
            -8_388_609.5,
        ];
        for x in steps_and_scales((0.5, 40), 9).chain(edges) {
            assert_eq!(floor_to_i32(x), x.floor() as i32, "{x}");
            if x.abs() <= 2f32.powi(40) {
                assert_eq!(floor_to_i64(x), x.floor() as i64, "{x}");
            }
        }
    }

    #[test]
    fn rounding_to_an_integer_matches_round_on_quarter_turns() {
        let edges = [2f32.powi(21) - 0.125, 0.125 - 2f32.powi(21), 0.0, -0.0];
        for turns in steps_and_scales((0.125, 23), 7).chain(edges) {
            assert_eq!(round_to_i32(turns * 4.0), (turns * 4.0).round() as i32, "{turns}");
        }
    }

    #[test]
    fn frame_is_orthonormal() {
        for n in [Vec3::Z, -Vec3::Z, Vec3::X, Vec3::new(0.3, -0.4, 0.866).normalize()] {
            let f = Frame::from_normal(n);
            assert!((f.x.length() - 1.0).abs() < 1e-5);
            assert!((f.y.length() - 1.0).abs() < 1e-5);
            assert!(f.x.dot(f.y).abs() < 1e-5 && f.x.dot(n).abs() < 1e-5 && f.y.dot(n).abs() < 1e-5);
            let v = Vec3::new(0.2, 0.5, -0.7);
            assert!((f.to_world(f.to_local(v)) - v).length() < 1e-5);
        }
    }

    #[test]
    fn refraction_obeys_snell_and_total_internal_reflection() {
        let d = Vec3::new(0.5f32.sin(), 0.0, -0.5f32.cos());
        let t = refract(d, Vec3::Z, 1.0 / 1.5).unwrap();
        assert!((t.x - 0.5f32.sin() / 1.5).abs() < 1e-6);
        let steep = Vec3::new(0.9f32.sin(), 0.0, -0.9f32.cos());
        assert!(refract(steep, Vec3::Z, 1.5).is_none());
    }

    #[test]
    fn box_transform_and_slab_test() {
        let b = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
        let hit = b.intersect(
            Vec3::new(-5.0, 0.0, 0.0),
            Vec3::new(1.0, f32::INFINITY, f32::INFINITY),
            0.0,
            100.0,
        );
        assert_eq!(hit, Some((4.0, 6.0)));
        let moved = b.transformed(&Mat4::from_translation(Vec3::new(2.0, 0.0, 0.0)));
        assert_eq!(moved.min, Vec3::new(1.0, -1.0, -1.0));
        assert!(Aabb::EMPTY.is_empty());
    }

    /// Against the library's double-precision sine and cosine, over whole turns, the quarter
    /// turns where the reduction switches, and negative and large arguments.
    #[test]
    fn sin_cos_turns_agree_with_the_library() {
        let mut worst = 0.0f64;
        let mut check = |turns: f32| {
            let (s, c) = sin_cos_turns(turns);
            let angle = turns as f64 * std::f64::consts::TAU;
            worst = worst
                .max((s as f64 - angle.sin()).abs())
                .max((c as f64 - angle.cos()).abs());
        };
        for i in 0..=100_000 {
            check(i as f32 / 100_000.0);
        }
        for q in -8..=8 {
            for d in [-1e-7f32, -1e-3, 0.0, 1e-3, 1e-7, 0.125, -0.125] {
                check(q as f32 * 0.25 + d);
            }
        }
        for turns in [-0.3f32, -7.9, 123.456, 4096.7] {
            check(turns);
        }
        assert!(worst < 2e-7, "largest error {worst}");
        // Exact at the quarter turns: the warps' axes stay on their axes.
        assert_eq!(sin_cos_turns(0.0), (0.0, 1.0));
        assert_eq!(sin_cos_turns(0.25), (1.0, -0.0));
        assert_eq!(sin_cos_turns(0.5), (-0.0, -1.0));
        assert_eq!(sin_cos_turns(0.75), (-1.0, 0.0));
    }
}

/// Whether a transform cannot place a shape: not finite, or its linear part flattens space (its
/// columns nearly coplanar). Scale-free, so a node scaled by 0.0001 still places its mesh.
pub fn is_degenerate_transform(m: &Mat4) -> bool {
    let linear = Mat3::from_mat4(*m);
    let det = linear.determinant();
    let size = linear.x_axis.length() * linear.y_axis.length() * linear.z_axis.length();
    !(det.is_finite() && size.is_finite() && m.is_finite()) || det.abs() <= 1e-6 * size || size == 0.0
}

#[cfg(test)]
mod transform_tests {
    use super::*;

    #[test]
    fn tiny_scales_place_shapes_and_flat_or_broken_transforms_do_not() {
        assert!(!is_degenerate_transform(&Mat4::from_scale(Vec3::splat(1e-4))));
        assert!(!is_degenerate_transform(&Mat4::from_scale(Vec3::new(1e-5, 3e3, 1.0))));
        assert!(is_degenerate_transform(&Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))));
        assert!(is_degenerate_transform(&Mat4::from_scale(Vec3::new(
            1.0,
            f32::NAN,
            1.0
        ))));
        let flat = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::new(1.0, 1.0, 0.0, 0.0), Vec4::W);
        assert!(is_degenerate_transform(&flat));
    }
}
