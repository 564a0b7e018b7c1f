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

    /// Hits with `0 < t < t_max` in each lane: the lanes hit (bit per lane) and, per lane, `t`
    /// and the unnormalised barycentric weights with their sum.
    #[inline(always)]
    fn hits(&self, ray: &TriangleRay, t_max: f32) -> (u32, Lanes) {
        let [kx, ky, kz] = ray.k;
        let [ox, oy, oz] = ray.origin;
        let [sx, sy] = ray.shear;
        // Per vertex: coordinates relative to the origin, sheared so the ray runs along +z.
        let sheared = |vertex: usize| {
            let z = self.v[vertex][kz] - oz;
            let x = (self.v[vertex][kx] - ox) - sx * z;
            let y = (self.v[vertex][ky] - oy) - sy * z;
            (x, y, z)
        };
        let (xa, ya, za) = sheared(0);
        let (xb, yb, zb) = sheared(1);
        let (xc, yc, zc) = sheared(2);
        // Edge functions: the unnormalised barycentric weights of a, b and c.
        let wa = xc * yb - yc * xb;
        let wb = xa * yc - ya * xc;
        let wc = xb * ya - yb * xa;
        let zero = Vec4::ZERO;
        let neg = wa.cmplt(zero) | wb.cmplt(zero) | wc.cmplt(zero);
        let pos = wa.cmpgt(zero) | wb.cmpgt(zero) | wc.cmpgt(zero);
        let det = wa + wb + wc;
        let t = (wa * za + wb * zb + wc * zc) * ray.inv_dz / det;
        // NaN lanes (unused, or det == 0) fail both comparisons.
        let in_range = t.cmpgt(zero) & t.cmplt(Vec4::splat(t_max));
        let hit = !(neg & pos) & in_range;
        let on_edge = wa.cmpeq(zero) | wb.cmpeq(zero) | wc.cmpeq(zero);
        let lanes = Lanes { t, wb, wc, det };
        (hit.bitmask() | (on_edge.bitmask() << LANES), lanes)
    }

    /// The nearest hit with `0 < t < t_max` and its lane; ties go to the lower lane, as testing
    /// the triangles one by one in lane order would.
    #[inline(always)]
    pub fn closest_hit(&self, ray: &TriangleRay, t_max: f32) -> Option<(usize, TriangleHit)> {
        let (mask, lanes) = self.hits(ray, t_max);
        if mask >> LANES != 0 {
            return self.closest_hit_on_edge(ray, t_max, mask, &lanes);
        }
        if mask == 0 {
            return None;
        }
        // Missed lanes hold NaN or out-of-range values: take the minimum over hit lanes only.
        let t = lanes.t.to_array();
        let mut lane = mask.trailing_zeros() as usize;
        let mut rest = mask & (mask - 1);
        while rest != 0 {
            let other = rest.trailing_zeros() as usize;
            if t[other] < t[lane] {
                lane = other;
            }
            rest &= rest - 1;
        }
        Some((lane, lanes.hit(lane)))
    }

    /// [`TrianglePacket::closest_hit`] when some lane has an edge function of exactly zero:
    /// those lanes are settled by the scalar test.
    #[cold]
    fn closest_hit_on_edge(
        &self,
        ray: &TriangleRay,
        t_max: f32,
        mask: u32,
        lanes: &Lanes,
    ) -> Option<(usize, TriangleHit)> {
        let mut best: Option<(usize, TriangleHit)> = None;
        let mut t_max = t_max;
        for lane in 0..LANES {
            let hit = if mask & (1 << (LANES + lane)) != 0 {
                self.triangle(lane).intersect_pre(ray, t_max)
            } else if mask & (1 << lane) != 0 && lanes.t[lane] < t_max {
                Some(lanes.hit(lane))
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

    /// Calls `visit(lane, hit)` for each lane hit with `0 < t < t_max`, in lane order, until it
    /// returns `true`; returns whether it did.
    #[inline(always)]
    pub fn each_hit(&self, ray: &TriangleRay, t_max: f32, mut visit: impl FnMut(usize, TriangleHit) -> bool) -> bool {
        let (mask, lanes) = self.hits(ray, t_max);
        if mask == 0 {
            return false;
        }
        for lane in 0..LANES {
            let hit = if mask & (1 << (LANES + lane)) != 0 {
                self.triangle(lane).intersect_pre(ray, t_max)
            } else if mask & (1 << lane) != 0 {
                Some(lanes.hit(lane))
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

/// Per-lane results of the packet test.
struct Lanes {
    t: Vec4,
    wb: Vec4,
    wc: Vec4,
    det: Vec4,
}

impl Lanes {
    #[inline(always)]
    fn hit(&self, lane: usize) -> TriangleHit {
        let inv = 1.0 / self.det[lane];
        TriangleHit {
            t: self.t[lane],
            u: self.wb[lane] * inv,
            v: self.wc[lane] * inv,
        }
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
