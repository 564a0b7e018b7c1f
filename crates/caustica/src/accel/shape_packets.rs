//! A scene of a few squares and round spheres (a Cornell box's walls and balls) tested without
//! a hierarchy: the squares four to a packet, the spheres four to a packet, each packet one SIMD
//! test. A ray meets every packet; for a handful of shapes that costs less than setting up a walk
//! and testing boxes, which is most of what a ray costs there.
//!
//! The lanes run the shapes' own scalar tests ([`Shape::intersect_object_normal`]) operation for
//! operation, so a lane hits exactly where the shape's test does, at the same `t`. The packets
//! only pick the shape; its hit record comes from its own test.

use glam::Vec4;

use crate::geometry::{PacketForm, Shape};
use crate::math::Ray;

/// Lanes per packet.
const LANES: usize = 4;

/// Most shapes tested this way: past it a hierarchy's box tests cull more than they cost.
pub const MAX_SHAPES: usize = 16;

/// Fewest shapes tested this way. One or two the hierarchy tests from its root's boxes without
/// a walk, which turns away most rays sooner than a sphere packet's test does (a glass ball
/// and a lamp rendered 5% slower in packets).
pub const MIN_SHAPES: usize = 3;

/// Id of an unused lane.
const NO_SHAPE: u32 = u32::MAX;

/// Up to four squares: the rows of each one's world-to-object rotation and scale, and its
/// origin, as lanes. Unused lanes have zero rows and never hit.
#[derive(Clone, Copy, Debug)]
struct SquarePacket {
    rows: [[Vec4; 3]; 3],
    origin: [Vec4; 3],
    ids: [u32; LANES],
}

/// Up to four spheres kept round by their transforms: world centres and radii as lanes.
/// Unused lanes have NaN radii and never hit.
#[derive(Clone, Copy, Debug)]
struct SpherePacket {
    center: [Vec4; 3],
    radius: Vec4,
    /// The lanes in use (bit per lane): the test stops early when the ray passes wide of all
    /// of them, which an unused lane must not prevent.
    used: u32,
    ids: [u32; LANES],
}

/// The shapes of a scene of few squares and round spheres, in packets.
#[derive(Clone, Debug, Default)]
pub struct ShapePackets {
    squares: Vec<SquarePacket>,
    spheres: Vec<SpherePacket>,
}

/// Per-ray values every packet uses.
struct PacketRay {
    origin: [Vec4; 3],
    dir: [Vec4; 3],
    /// `dir · dir`, as the sphere test forms it.
    dir2: f32,
}

impl PacketRay {
    #[inline(always)]
    fn new(ray: &Ray) -> PacketRay {
        let (o, d) = (ray.origin, ray.dir);
        PacketRay {
            origin: [o.x, o.y, o.z].map(Vec4::splat),
            dir: [d.x, d.y, d.z].map(Vec4::splat),
            dir2: d.dot(d),
        }
    }
}

/// `a · b` for three lanes of vectors, summed in the order of `Vec3::dot`.
#[inline(always)]
fn dot(a: &[Vec4; 3], b: &[Vec4; 3]) -> Vec4 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Lane-wise square root (exact, as the scalar one).
#[inline(always)]
fn sqrt(v: Vec4) -> Vec4 {
    Vec4::from_array(v.to_array().map(f32::sqrt))
}

impl ShapePackets {
    /// Packets of `shapes` (ids are indices into it), or `None` if there are fewer than
    /// [`MIN_SHAPES`] or more than [`MAX_SHAPES`], or one is neither a square nor a round
    /// sphere. Shapes a hierarchy would leave out (empty or non-finite bounds) are left out.
    pub fn new(shapes: &[Shape]) -> Option<ShapePackets> {
        if !(MIN_SHAPES..=MAX_SHAPES).contains(&shapes.len()) {
            return None;
        }
        let (mut squares, mut spheres) = (Vec::new(), Vec::new());
        for (id, shape) in shapes.iter().enumerate() {
            let b = shape.bounds;
            if b.is_empty() || !b.min.is_finite() || !b.max.is_finite() {
                continue;
            }
            match shape.packet_form()? {
                PacketForm::Square { rows, origin } => squares.push((id as u32, rows, origin)),
                PacketForm::Sphere { center, radius } => spheres.push((id as u32, center, radius)),
            }
        }
        let lanes = |v: &dyn Fn(usize) -> f32, n: usize, unused: f32| {
            Vec4::from_array(std::array::from_fn(|lane| if lane < n { v(lane) } else { unused }))
        };
        let ids = |chunk: &[u32]| std::array::from_fn(|lane| chunk.get(lane).copied().unwrap_or(NO_SHAPE));
        let squares = squares
            .chunks(LANES)
            .map(|c| SquarePacket {
                rows: std::array::from_fn(|row| {
                    std::array::from_fn(|axis| lanes(&|lane| c[lane].1[row][axis], c.len(), 0.0))
                }),
                origin: std::array::from_fn(|axis| lanes(&|lane| c[lane].2[axis], c.len(), 0.0)),
                ids: ids(&c.iter().map(|s| s.0).collect::<Vec<_>>()),
            })
            .collect();
        let spheres = spheres
            .chunks(LANES)
            .map(|c| SpherePacket {
                center: std::array::from_fn(|axis| lanes(&|lane| c[lane].1[axis], c.len(), 0.0)),
                radius: lanes(&|lane| c[lane].2, c.len(), f32::NAN),
                used: (1 << c.len()) - 1,
                ids: ids(&c.iter().map(|s| s.0).collect::<Vec<_>>()),
            })
            .collect();
        Some(ShapePackets { squares, spheres })
    }

    /// The shape whose own test finds the nearest hit with `0 < t < t_max`, and that `t`.
    /// Ties go to the shape tested first.
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let pr = PacketRay::new(ray);
        let mut best: Option<(u32, f32)> = None;
        let mut keep = |mask: u32, t: Vec4, ids: &[u32; LANES]| {
            let t = t.to_array();
            let mut rest = mask;
            while rest != 0 {
                let lane = rest.trailing_zeros() as usize;
                if best.is_none_or(|(_, b)| t[lane] < b) {
                    best = Some((ids[lane], t[lane]));
                }
                rest &= rest - 1;
            }
        };
        for p in &self.squares {
            let (mask, t) = p.hits(&pr, t_max);
            keep(mask, t, &p.ids);
        }
        for p in &self.spheres {
            let (mask, t) = p.hits(&pr, t_max);
            keep(mask, t, &p.ids);
        }
        best
    }

    /// Calls `visit(shape)` for each shape whose own test finds a hit with `0 < t < t_max`,
    /// until it returns `true`; returns whether it did.
    #[inline]
    pub fn each(&self, ray: &Ray, t_max: f32, mut visit: impl FnMut(u32) -> bool) -> bool {
        let pr = PacketRay::new(ray);
        let mut any = |mask: u32, ids: &[u32; LANES]| {
            let mut rest = mask;
            while rest != 0 {
                if visit(ids[rest.trailing_zeros() as usize]) {
                    return true;
                }
                rest &= rest - 1;
            }
            false
        };
        self.squares.iter().any(|p| any(p.hits(&pr, t_max).0, &p.ids))
            || self.spheres.iter().any(|p| any(p.hits(&pr, t_max).0, &p.ids))
    }
}

impl SquarePacket {
    /// The lanes hit with `0 < t < t_max` (bit per lane) and their `t`: the square test of
    /// `Shape::intersect_square`, lane by lane.
    #[inline(always)]
    fn hits(&self, ray: &PacketRay, t_max: f32) -> (u32, Vec4) {
        let [row_x, row_y, row_z] = &self.rows;
        let zero = Vec4::ZERO;
        let dir_z = dot(row_z, &ray.dir);
        let to_origin: [Vec4; 3] = std::array::from_fn(|axis| self.origin[axis] - ray.origin[axis]);
        let distance_z = dot(row_z, &to_origin);
        // Behind the ray, parallel to it, or beyond `t_max`.
        let facing = distance_z.cmpgt(zero) ^ dir_z.cmpgt(zero);
        let far = distance_z.abs().cmpge(Vec4::splat(t_max) * dir_z.abs());
        let turned_away = dir_z.cmpeq(zero) | facing | far;
        if (!turned_away).bitmask() == 0 {
            return (0, zero);
        }
        let t = distance_z / dir_z;
        let in_range = t.cmpgt(zero) & t.cmplt(Vec4::splat(t_max));
        let offset: [Vec4; 3] = std::array::from_fn(|axis| ray.origin[axis] + ray.dir[axis] * t - self.origin[axis]);
        let half = Vec4::splat(0.5);
        let outside = dot(row_x, &offset).abs().cmpgt(half) | dot(row_y, &offset).abs().cmpgt(half);
        ((!turned_away & in_range & !outside).bitmask(), t)
    }
}

impl SpherePacket {
    /// The lanes hit with `0 < t < t_max` (bit per lane) and their `t`: the round-sphere test of
    /// `Shape::intersect_round_sphere` with [`crate::geometry::quadratic_roots`], lane by lane.
    #[inline(always)]
    fn hits(&self, ray: &PacketRay, t_max: f32) -> (u32, Vec4) {
        let zero = Vec4::ZERO;
        let oc: [Vec4; 3] = std::array::from_fn(|axis| ray.origin[axis] - self.center[axis]);
        let a = Vec4::splat(ray.dir2);
        let half_b = dot(&oc, &ray.dir);
        let k = half_b / a;
        let l: [Vec4; 3] = std::array::from_fn(|axis| oc[axis] - ray.dir[axis] * k);
        let (l2, r2) = (dot(&l, &l), self.radius * self.radius);
        let near = !l2.cmpgt(r2);
        if near.bitmask() & self.used == 0 {
            return (0, zero);
        }
        let l_len = sqrt(l2);
        let disc = a * ((self.radius - l_len) * (self.radius + l_len));
        let c = dot(&oc, &oc) - r2;
        let real = disc.cmpge(zero) & disc.is_finite_mask();
        let q = -(half_b + sqrt(disc).copysign(half_b));
        let q_zero = q.cmpeq(zero);
        let t0 = Vec4::select(q_zero, zero, q / a);
        let t1 = Vec4::select(q_zero, zero, c / q);
        let (lo, hi) = (t0.min(t1), t0.max(t1));
        let t = Vec4::select(lo.cmpgt(zero), lo, hi);
        let in_range = t.cmpgt(zero) & t.cmplt(Vec4::splat(t_max));
        // `a == 0` (a zero direction) takes the scalar test's other branch: no lane claims it.
        let mask = if ray.dir2 == 0.0 {
            0
        } else {
            (near & real & in_range).bitmask()
        };
        (mask, t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::ShapeKind;
    use crate::math::{Mat4, Vec3};
    use crate::sampling::Rng;

    fn unit(v: Vec3) -> Vec3 {
        v / v.length()
    }

    /// A Cornell box's squares and balls, and a few odd ones (a tilted, stretched square; a
    /// tiny and a large ball).
    fn shapes() -> Vec<Shape> {
        use std::f32::consts::FRAC_PI_2;
        let square = |m: Mat4| Shape::new(ShapeKind::Square, m).unwrap();
        let sphere = |c: Vec3, r: f32| {
            Shape::new(
                ShapeKind::Sphere,
                Mat4::from_translation(c) * Mat4::from_scale(Vec3::splat(r)),
            )
            .unwrap()
        };
        vec![
            square(Mat4::from_rotation_x(-FRAC_PI_2) * Mat4::from_scale(Vec3::splat(2.0))),
            square(
                Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))
                    * Mat4::from_rotation_x(FRAC_PI_2)
                    * Mat4::from_scale(Vec3::splat(2.0)),
            ),
            square(Mat4::from_translation(Vec3::new(0.0, 1.0, -1.0)) * Mat4::from_scale(Vec3::splat(2.0))),
            square(
                Mat4::from_translation(Vec3::new(-1.0, 1.0, 0.0))
                    * Mat4::from_rotation_y(FRAC_PI_2)
                    * Mat4::from_scale(Vec3::splat(2.0)),
            ),
            square(
                Mat4::from_translation(Vec3::new(1.0, 1.0, 0.0))
                    * Mat4::from_rotation_y(-FRAC_PI_2)
                    * Mat4::from_scale(Vec3::splat(2.0)),
            ),
            square(
                Mat4::from_translation(Vec3::new(0.2, 0.6, 0.1))
                    * Mat4::from_axis_angle(unit(Vec3::new(1.0, 2.0, 3.0)), 0.7)
                    * Mat4::from_scale(Vec3::new(0.5, 0.3, 1.0)),
            ),
            sphere(Vec3::new(-0.45, 0.35, -0.2), 0.35),
            sphere(Vec3::new(0.45, 0.35, 0.3), 0.35),
            sphere(Vec3::new(0.0, 1.8, 0.0), 0.01),
            sphere(Vec3::new(0.0, 0.0, 0.0), 30.0),
        ]
    }

    /// On 200,000 random rays — from inside the box, from far outside, grazing, and bounded
    /// by a random `t_max` — the packets pick the shape and `t` (to the bit) that testing each
    /// shape by its own test picks, and `each` visits exactly the shapes those tests hit.
    #[test]
    fn packets_find_what_each_shapes_own_test_finds() {
        let shapes = shapes();
        let packets = ShapePackets::new(&shapes).expect("all squares and round spheres");
        let mut rng = Rng::new(7, 0);
        let mut random = |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
        let (mut hits, mut several) = (0, 0);
        for i in 0..200_000 {
            let origin = if i % 3 == 0 {
                random(200.0)
            } else {
                random(2.0) + Vec3::new(0.0, 1.0, 0.0)
            };
            let ray = Ray::new(origin, unit(random(2.0)));
            let t_max = if i % 2 == 0 {
                f32::INFINITY
            } else {
                4.0 * (i % 7) as f32 / 7.0
            };
            let mut expected: Option<(u32, f32)> = None;
            let mut each_expected = vec![];
            for (id, shape) in shapes.iter().enumerate() {
                if let Some(h) = shape.intersect_object_normal(&ray, t_max) {
                    each_expected.push(id as u32);
                    if expected.is_none_or(|(_, t)| h.t < t) {
                        expected = Some((id as u32, h.t));
                    }
                }
            }
            let found = packets.closest(&ray, t_max);
            assert_eq!(
                found.map(|(id, t)| (id, t.to_bits())),
                expected.map(|(id, t)| (id, t.to_bits())),
                "{ray:?} {t_max}"
            );
            let mut each_found = vec![];
            packets.each(&ray, t_max, |id| {
                each_found.push(id);
                false
            });
            each_found.sort();
            assert_eq!(each_found, each_expected, "{ray:?} {t_max}");
            hits += usize::from(expected.is_some());
            several += usize::from(each_expected.len() > 1);
        }
        assert!(
            hits > 100_000 && several > 50_000,
            "{hits} hits, {several} with several"
        );
    }

    /// Other shapes, and more than [`MAX_SHAPES`] or fewer than [`MIN_SHAPES`], keep the
    /// hierarchy.
    #[test]
    fn other_kinds_and_many_shapes_are_not_packed() {
        let boxed = Shape::new(ShapeKind::Box, Mat4::IDENTITY).unwrap();
        assert!(ShapePackets::new(&[boxed]).is_none());
        let stretched = Shape::new(ShapeKind::Sphere, Mat4::from_scale(Vec3::new(1.0, 2.0, 1.0))).unwrap();
        assert!(ShapePackets::new(&[stretched]).is_none());
        let many: Vec<Shape> = shapes().into_iter().cycle().take(MAX_SHAPES + 1).collect();
        assert!(ShapePackets::new(&many).is_none());
        assert!(ShapePackets::new(&many[..MAX_SHAPES]).is_some());
        assert!(ShapePackets::new(&many[..MIN_SHAPES]).is_some());
        assert!(ShapePackets::new(&many[..MIN_SHAPES - 1]).is_none());
    }
}
