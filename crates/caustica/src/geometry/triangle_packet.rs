//! Four triangles tested against one ray at once.
//!
//! The same watertight test as [`Triangle::intersect_pre`], with the four triangles in the SIMD
//! lanes instead of their three vertices: one packet costs about as much as one scalar test, and
//! its branches depend on the four lanes together, so they mispredict less. The arithmetic is
//! the scalar test's, operation for operation, so hits (and their `t`, `u`, `v`) are the same
//! bits; lanes with an edge function of exactly zero are redone by the scalar test, which settles
//! them in `f64`.

use glam::Vec4;

use super::triangle::{Triangle, TriangleHit, TriangleRay};
use crate::accel::lanes::Lanes;
use crate::math::Vec3;

/// Lanes per packet.
pub const LANES: usize = 4;

/// Up to four triangles, vertex coordinates as lanes: `v[vertex][axis]` holds that coordinate of
/// vertex `a`, `b` or `c` for each triangle. Unused lanes hold NaN and never hit.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(16))]
pub struct TrianglePacket {
    v: [[Vec4; 3]; 3],
}

impl TrianglePacket {
    /// A packet of up to [`LANES`] triangles, in lane order.
    ///
    /// # Panics
    /// If given more than [`LANES`] triangles.
    pub fn new(tris: &[Triangle]) -> TrianglePacket {
        assert!(tris.len() <= LANES, "a packet holds at most {LANES} triangles");
        let mut v = [[Vec4::NAN; 3]; 3];
        for (lane, tri) in tris.iter().enumerate() {
            for (vertex, p) in tri.vertices().into_iter().enumerate() {
                for axis in 0..3 {
                    v[vertex][axis][lane] = p[axis];
                }
            }
        }
        TrianglePacket { v }
    }

    /// The triangle in `lane` (NaN vertices for an unused lane).
    pub fn triangle(&self, lane: usize) -> Triangle {
        let vertex = |i: usize| Vec3::new(self.v[i][0][lane], self.v[i][1][lane], self.v[i][2][lane]);
        Triangle::new(vertex(0), vertex(1), vertex(2))
    }

    /// The nearest hit with `0 < t < t_max` and its lane; ties go to the lower lane, as testing
    /// the triangles one by one in lane order would.
    #[inline(always)]
    pub fn closest_hit(&self, ray: &TriangleRay, t_max: f32) -> Option<(usize, TriangleHit)> {
        let hits = lane_hits(&self.v, ray, t_max);
        hits.closest(|lane| self.triangle(lane), ray, t_max)
    }

    /// Calls `visit(lane, hit)` for each lane hit with `0 < t < t_max`, in lane order, until it
    /// returns `true`; returns whether it did.
    #[inline(always)]
    pub fn each_hit(&self, ray: &TriangleRay, t_max: f32, visit: impl FnMut(usize, TriangleHit) -> bool) -> bool {
        let hits = lane_hits(&self.v, ray, t_max);
        hits.each(|lane| self.triangle(lane), ray, t_max, visit)
    }
}

/// Two packets tested as one of eight lanes in AVX registers, `first`'s triangles in lanes 0–3
/// and `second`'s in lanes 4–7: the same operations on each lane as [`TrianglePacket`]'s own
/// tests, so the same hits to the bit, and the same answers as testing `first` and then
/// `second` (ties to the lower lane). Only inside [`in_avx`](crate::accel::lanes::in_avx).
#[cfg(target_arch = "x86_64")]
pub(crate) mod pair {
    use super::{lane_hits, TriangleHit, TrianglePacket, TriangleRay, LANES};
    use crate::accel::lanes::{F32x8, Lanes};

    /// The pair's coordinates as eight lanes, by loops (see [`lane_hits`]).
    #[inline(always)]
    fn joined([first, second]: [&TrianglePacket; 2]) -> [[F32x8; 3]; 3] {
        let mut c = [[F32x8::splat(0.0); 3]; 3];
        for (row, (a, b)) in c.iter_mut().zip(first.v.iter().zip(&second.v)) {
            for (lanes, (&low, &high)) in row.iter_mut().zip(a.iter().zip(b)) {
                *lanes = F32x8::from_halves(low, high);
            }
        }
        c
    }

    /// [`TrianglePacket::closest_hit`] of the pair; lanes 4–7 are `second`'s.
    #[inline(always)]
    pub(crate) fn closest_hit(
        [first, second]: [&TrianglePacket; 2],
        ray: &TriangleRay,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        let hits = lane_hits(&joined([first, second]), ray, t_max);
        let triangle = |lane: usize| [first, second][lane / LANES].triangle(lane % LANES);
        hits.closest(triangle, ray, t_max)
    }

    /// [`TrianglePacket::each_hit`] of the pair; lanes 4–7 are `second`'s.
    #[inline(always)]
    pub(crate) fn each_hit(
        [first, second]: [&TrianglePacket; 2],
        ray: &TriangleRay,
        t_max: f32,
        visit: impl FnMut(usize, TriangleHit) -> bool,
    ) -> bool {
        let hits = lane_hits(&joined([first, second]), ray, t_max);
        let triangle = |lane: usize| [first, second][lane / LANES].triangle(lane % LANES);
        hits.each(triangle, ray, t_max, visit)
    }
}

/// The watertight test of one ray against a triangle in each lane, `coord(vertex, axis)` the
/// lanes' coordinates: which lanes hit with `0 < t < t_max` and which have an edge function of
/// exactly zero (left to the scalar test), with each lane's `t` and unnormalised barycentric
/// weights.
///
/// No closures here or in what calls it with eight lanes: one left out of line would be
/// compiled for the baseline CPU and call each AVX intrinsic as a function.
#[inline(always)]
fn lane_hits<L: Lanes>(coords: &[[L; 3]; 3], ray: &TriangleRay, t_max: f32) -> LaneHits {
    let [kx, ky, kz] = ray.k;
    let (ox, oy, oz) = (
        L::splat(ray.origin[0].x),
        L::splat(ray.origin[1].x),
        L::splat(ray.origin[2].x),
    );
    let (sx, sy) = (L::splat(ray.shear[0].x), L::splat(ray.shear[1].x));
    let origin = [ox, oy, oz];
    let (xa, ya, za) = sheared(&coords[0], [kx, ky, kz], origin, [sx, sy]);
    let (xb, yb, zb) = sheared(&coords[1], [kx, ky, kz], origin, [sx, sy]);
    let (xc, yc, zc) = sheared(&coords[2], [kx, ky, kz], origin, [sx, sy]);
    // Edge functions: the unnormalised barycentric weights of a, b and c.
    let wa = xc * yb - yc * xb;
    let wb = xa * yc - ya * xc;
    let wc = xb * ya - yb * xa;
    let zero = L::splat(0.0);
    let neg = wa.lt(zero) | wb.lt(zero) | wc.lt(zero);
    let pos = wa.gt(zero) | wb.gt(zero) | wc.gt(zero);
    let det = wa + wb + wc;
    let t = (wa * za + wb * zb + wc * zc) * L::splat(ray.inv_dz) / det;
    // NaN lanes (unused, or det == 0) fail both comparisons.
    let in_range = t.gt(zero) & t.lt(L::splat(t_max));
    let hit = !(neg & pos) & in_range;
    let on_edge = wa.eq(zero) | wb.eq(zero) | wc.eq(zero);
    let mut lanes = LaneHits {
        hit: L::bitmask(hit),
        on_edge: L::bitmask(on_edge),
        t: [0.0; MAX_LANES],
        wb: [0.0; MAX_LANES],
        wc: [0.0; MAX_LANES],
        det: [0.0; MAX_LANES],
    };
    if lanes.hit | lanes.on_edge != 0 {
        t.write_to(&mut lanes.t);
        wb.write_to(&mut lanes.wb);
        wc.write_to(&mut lanes.wc);
        det.write_to(&mut lanes.det);
    }
    lanes
}

/// A vertex's coordinates `c` relative to the ray's origin, in the permuted axes `k`, sheared
/// so the ray runs along +z.
#[inline(always)]
fn sheared<L: Lanes>(c: &[L; 3], [kx, ky, kz]: [usize; 3], [ox, oy, oz]: [L; 3], [sx, sy]: [L; 2]) -> (L, L, L) {
    let z = c[kz] - oz;
    let x = (c[kx] - ox) - sx * z;
    let y = (c[ky] - oy) - sy * z;
    (x, y, z)
}

/// Most lanes a test runs at once.
const MAX_LANES: usize = 2 * LANES;

/// Per-lane results of a packet test.
struct LaneHits {
    /// Lanes hit (bit per lane).
    hit: u32,
    /// Lanes with an edge function of exactly zero, settled by the scalar test.
    on_edge: u32,
    t: [f32; MAX_LANES],
    wb: [f32; MAX_LANES],
    wc: [f32; MAX_LANES],
    det: [f32; MAX_LANES],
}

impl LaneHits {
    #[inline(always)]
    fn hit(&self, lane: usize) -> TriangleHit {
        let lane = lane % MAX_LANES;
        let inv = 1.0 / self.det[lane];
        TriangleHit {
            t: self.t[lane],
            u: self.wb[lane] * inv,
            v: self.wc[lane] * inv,
        }
    }

    /// The nearest hit and its lane, ties to the lower lane; `triangle(lane)` for the lanes
    /// on an edge.
    #[inline(always)]
    fn closest(
        &self,
        triangle: impl Fn(usize) -> Triangle,
        ray: &TriangleRay,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        if self.on_edge != 0 {
            return self.closest_on_edge(triangle, ray, t_max);
        }
        let mask = self.hit;
        if mask == 0 {
            return None;
        }
        // Missed lanes hold NaN or out-of-range values: take the minimum over hit lanes only.
        let mut lane = mask.trailing_zeros() as usize;
        let mut rest = mask & (mask - 1);
        while rest != 0 {
            let other = rest.trailing_zeros() as usize;
            if self.t[other % MAX_LANES] < self.t[lane % MAX_LANES] {
                lane = other;
            }
            rest &= rest - 1;
        }
        Some((lane, self.hit(lane)))
    }

    /// [`LaneHits::closest`] when some lane has an edge function of exactly zero: those lanes
    /// are settled by the scalar test, the lanes taken in order as one by one.
    #[cold]
    fn closest_on_edge(
        &self,
        triangle: impl Fn(usize) -> Triangle,
        ray: &TriangleRay,
        t_max: f32,
    ) -> Option<(usize, TriangleHit)> {
        let mut best: Option<(usize, TriangleHit)> = None;
        let mut t_max = t_max;
        for lane in 0..MAX_LANES {
            let hit = if self.on_edge & (1 << lane) != 0 {
                triangle(lane).intersect_pre(ray, t_max)
            } else if self.hit & (1 << lane) != 0 && self.t[lane] < t_max {
                Some(self.hit(lane))
            } else {
                None
            };
            if let Some(h) = hit {
                t_max = h.t;
                best = Some((lane, h));
            }
        }
        best
    }

    /// Calls `visit(lane, hit)` for each lane hit, in lane order, until it returns `true`;
    /// returns whether it did.
    #[inline(always)]
    fn each(
        &self,
        triangle: impl Fn(usize) -> Triangle,
        ray: &TriangleRay,
        t_max: f32,
        mut visit: impl FnMut(usize, TriangleHit) -> bool,
    ) -> bool {
        let (mask, on_edge) = (self.hit, self.on_edge);
        if mask | on_edge == 0 {
            return false;
        }
        for lane in 0..MAX_LANES {
            let hit = if on_edge & (1 << lane) != 0 {
                triangle(lane).intersect_pre(ray, t_max)
            } else if mask & (1 << lane) != 0 {
                Some(self.hit(lane))
            } else {
                None
            };
            if let Some(h) = hit {
                if visit(lane, h) {
                    return true;
                }
            }
        }
        false
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;
    use crate::sampling::Rng;

    /// A point in [-1, 1)³.
    fn v(rng: &mut Rng) -> Vec3 {
        Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE
    }

    /// The packet's closest hit and hit list equal the scalar test's on each triangle, bit for
    /// bit, including rays through shared edges and vertices and partly filled packets.
    #[test]
    fn packet_agrees_with_scalar_test() {
        let mut rng = Rng::new(0x1234_5678_9abc_def1, 0);
        let mut hits = 0;
        for case in 0..20_000 {
            let count = 1 + case % LANES;
            let shared = v(&mut rng);
            let tris: Vec<Triangle> = (0..count)
                .map(|i| {
                    // Some triangles share a vertex or an edge with the first.
                    let a = if i > 0 && case % 3 == 0 { shared } else { v(&mut rng) };
                    Triangle::new(a, v(&mut rng), if case % 5 == 0 { shared * 0.5 } else { v(&mut rng) })
                })
                .collect();
            let packet = TrianglePacket::new(&tris);
            // Aim at a vertex, an edge or the inside of one of the triangles.
            let target = match case % 4 {
                0 => tris[0].vertices()[case % 3],
                1 => tris[count - 1].point(rng.uniform(), 0.0),
                _ => tris[case % count].point(rng.uniform() * 0.5, rng.uniform() * 0.5),
            };
            let origin = v(&mut rng) * 3.0;
            let ray = Ray::new(origin, (target - origin) * (0.5 + rng.uniform()));
            let tr = TriangleRay::new(&ray);
            let t_max = if case % 7 == 0 {
                rng.uniform() * 2.0
            } else {
                f32::INFINITY
            };

            let mut expected = None;
            let mut t_best = t_max;
            let mut expected_all = Vec::new();
            for (lane, tri) in tris.iter().enumerate() {
                if let Some(h) = tri.intersect_pre(&tr, t_max) {
                    expected_all.push((lane, h));
                }
                if let Some(h) = tri.intersect_pre(&tr, t_best) {
                    t_best = h.t;
                    expected = Some((lane, h));
                }
            }
            assert_eq!(packet.closest_hit(&tr, t_max), expected, "case {case}");
            let mut all = Vec::new();
            packet.each_hit(&tr, t_max, |lane, h| {
                all.push((lane, h));
                false
            });
            assert_eq!(all, expected_all, "case {case}");
            hits += usize::from(expected.is_some());
        }
        assert!(hits > 5_000, "the cases exercise hits: {hits}");
    }

    /// Two packets tested as one of eight lanes give what testing the first and then the
    /// second gives: the closest hit (ties to the first), every hit in the same order, the same
    /// bits; with rays through shared edges and vertices, so the scalar test settles some lanes.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn a_pair_is_the_two_packets_one_after_the_other() {
        let Some(avx) = crate::accel::lanes::Avx::detect() else {
            eprintln!("skipped: this CPU has no AVX");
            return;
        };
        let mut rng = Rng::new(0x5eed_0f9a_1c5e, 0);
        let (mut hits, mut edges) = (0, 0);
        for case in 0..20_000usize {
            let shared = v(&mut rng);
            let mut tri = |i: usize| {
                let a = if i.is_multiple_of(3) { shared } else { v(&mut rng) };
                Triangle::new(
                    a,
                    v(&mut rng),
                    if case.is_multiple_of(4) {
                        shared * 0.5
                    } else {
                        v(&mut rng)
                    },
                )
            };
            let counts = [1 + case % LANES, 1 + (case / LANES) % LANES];
            let first: Vec<Triangle> = (0..counts[0]).map(&mut tri).collect();
            let second: Vec<Triangle> = (0..counts[1]).map(&mut tri).collect();
            // A duplicate across the pair: the tie goes to the first packet.
            let mut second = second;
            if case.is_multiple_of(6) {
                second[0] = first[0];
            }
            let packets = [TrianglePacket::new(&first), TrianglePacket::new(&second)];
            let target = match case % 3 {
                0 => shared,
                1 => first[0].point(rng.uniform() * 0.5, rng.uniform() * 0.5),
                _ => second[0].point(rng.uniform() * 0.5, rng.uniform() * 0.5),
            };
            let origin = v(&mut rng) * 3.0;
            let ray = Ray::new(origin, target - origin);
            let tr = TriangleRay::new(&ray);
            let t_max = if case.is_multiple_of(5) {
                rng.uniform() * 2.0
            } else {
                f32::INFINITY
            };

            let one = packets[0].closest_hit(&tr, t_max);
            let other = packets[1].closest_hit(&tr, one.map_or(t_max, |(_, h)| h.t));
            let expected = other.map(|(lane, h)| (lane + LANES, h)).or(one);
            let mut expected_all = Vec::new();
            for (p, packet) in packets.iter().enumerate() {
                packet.each_hit(&tr, t_max, |lane, h| {
                    expected_all.push((lane + p * LANES, h));
                    false
                });
            }
            let (closest, all) = crate::accel::lanes::in_avx(avx, || {
                let mut all = Vec::new();
                pair::each_hit([&packets[0], &packets[1]], &tr, t_max, |lane, h| {
                    all.push((lane, h));
                    false
                });
                (pair::closest_hit([&packets[0], &packets[1]], &tr, t_max), all)
            });
            assert_eq!(closest, expected, "case {case}");
            assert_eq!(all, expected_all, "case {case}");
            hits += usize::from(expected.is_some_and(|(lane, _)| lane >= LANES));
            edges += usize::from(target == shared && expected.is_some());
        }
        assert!(
            hits > 2_000 && edges > 1_000,
            "the cases exercise both halves and shared vertices: {hits}, {edges}"
        );
    }

    #[test]
    fn each_hit_stops_when_asked_and_empty_lanes_never_hit() {
        let tri = Triangle::new(Vec3::ZERO, Vec3::X * 2.0, Vec3::Y * 2.0);
        let packet = TrianglePacket::new(&[tri, tri]);
        let ray = Ray::new(Vec3::new(0.5, 0.5, 1.0), -Vec3::Z);
        let tr = TriangleRay::new(&ray);
        let mut seen = 0;
        assert!(packet.each_hit(&tr, 10.0, |_, _| {
            seen += 1;
            true
        }));
        assert_eq!(seen, 1);
        let (lane, h) = packet.closest_hit(&tr, 10.0).unwrap();
        assert_eq!((lane, h.t), (0, 1.0));
        assert!(packet.triangle(3).vertices()[0].is_nan());
        let empty = TrianglePacket::new(&[]);
        assert!(empty.closest_hit(&tr, f32::INFINITY).is_none());
    }
}
