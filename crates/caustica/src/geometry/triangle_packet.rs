//! Four triangles tested against one ray at once.
//!
//! The same watertight test as [`Triangle::intersect_pre`], with the four triangles in the SIMD
//! lanes instead of their three vertices: one packet costs about as much as one scalar test, and
//! its branches depend on the four lanes together, so they mispredict less. The arithmetic is
//! the scalar test's, operation for operation, so hits (and their `t`, `u`, `v`) are the same
//! bits; lanes with an edge function of exactly zero are redone by the scalar test, which settles
//! them in `f64`. Where the CPU has AVX two packets are tested as one of eight lanes
//! ([`PacketPair`]), to the same bits again.

use glam::Vec4;

use super::triangle::{Triangle, TriangleHit, TriangleRay};
#[cfg(target_arch = "x86_64")]
use crate::accel::lanes::F32x8;
use crate::accel::lanes::Lanes;
use crate::math::{Aabb, Ray, Vec3};

/// Lanes per packet.
pub const LANES: usize = 4;

/// Lanes of a [`PacketPair`]: the first packet's, then the second's.
#[cfg(target_arch = "x86_64")]
const PAIR_LANES: usize = 2 * LANES;

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

    /// Hits with `0 < t < t_max` in each lane: the lanes hit (bit per lane, edge lanes in the
    /// bits above) and their `t` and barycentrics.
    #[inline(always)]
    fn hits(&self, ray: &TriangleRay, t_max: f32) -> (u32, LaneHits<LANES>) {
        lane_hits(self, ray, t_max)
    }

    /// The nearest hit with `0 < t < t_max` and its lane; ties go to the lower lane, as testing
    /// the triangles one by one in lane order would.
    #[inline(always)]
    pub fn closest_hit(&self, ray: &TriangleRay, t_max: f32) -> Option<(usize, TriangleHit)> {
        let (mask, lanes) = self.hits(ray, t_max);
        closest_of_lanes(mask, &lanes, |lane| self.triangle(lane), ray, t_max)
    }

    /// Calls `visit(lane, hit)` for each lane hit with `0 < t < t_max`, in lane order, until it
    /// returns `true`; returns whether it did.
    #[inline(always)]
    pub fn each_hit(&self, ray: &TriangleRay, t_max: f32, visit: impl FnMut(usize, TriangleHit) -> bool) -> bool {
        let (mask, lanes) = self.hits(ray, t_max);
        each_of_lanes(mask, &lanes, |lane| self.triangle(lane), ray, t_max, visit)
    }

    /// Whether any lane is hit with `0 < t < t_max`: [`TrianglePacket::each_hit`] with a visit
    /// that stops at once, without working out the hit.
    #[inline(always)]
    pub fn any_hit(&self, ray: &TriangleRay, t_max: f32) -> bool {
        let (mask, _) = self.hits(ray, t_max);
        any_of_lanes::<LANES>(mask, |lane| self.triangle(lane), ray, t_max)
    }
}

/// Two packets tested as one of eight lanes (the first packet's lanes, then the second's) in an
/// AVX register: the same answers, to the bit, as testing the two one after the other, in one
/// test instead of two. Its functions run AVX instructions: call them only inside
/// [`in_avx`](crate::accel::lanes::in_avx).
#[cfg(target_arch = "x86_64")]
#[derive(Clone, Copy, Debug)]
pub(crate) struct PacketPair<'a>(pub(crate) &'a [TrianglePacket; 2]);

#[cfg(target_arch = "x86_64")]
impl PacketPair<'_> {
    #[inline(always)]
    fn hits(&self, ray: &TriangleRay, t_max: f32) -> (u32, LaneHits<PAIR_LANES>) {
        lane_hits(self, ray, t_max)
    }

    /// The triangle in `lane` of the eight.
    fn triangle(&self, lane: usize) -> Triangle {
        self.0[(lane / LANES) % 2].triangle(lane % LANES)
    }

    /// [`TrianglePacket::closest_hit`] over the eight lanes.
    #[inline(always)]
    pub(crate) fn closest_hit(&self, ray: &TriangleRay, t_max: f32) -> Option<(usize, TriangleHit)> {
        let (mask, lanes) = self.hits(ray, t_max);
        closest_of_lanes(mask, &lanes, |lane| self.triangle(lane), ray, t_max)
    }

    /// [`TrianglePacket::each_hit`] over the eight lanes.
    #[inline(always)]
    pub(crate) fn each_hit(
        &self,
        ray: &TriangleRay,
        t_max: f32,
        visit: impl FnMut(usize, TriangleHit) -> bool,
    ) -> bool {
        let (mask, lanes) = self.hits(ray, t_max);
        each_of_lanes(mask, &lanes, |lane| self.triangle(lane), ray, t_max, visit)
    }

    /// [`TrianglePacket::any_hit`] over the eight lanes.
    #[inline(always)]
    pub(crate) fn any_hit(&self, ray: &TriangleRay, t_max: f32) -> bool {
        let (mask, _) = self.hits(ray, t_max);
        any_of_lanes::<PAIR_LANES>(mask, |lane| self.triangle(lane), ray, t_max)
    }
}

/// Where a packet test reads its triangles' coordinates, a vector of lanes at a time.
trait Coordinates<L> {
    /// That coordinate (`axis`) of vertex `a`, `b` or `c` (`vertex`) of each lane's triangle.
    fn coordinate(&self, vertex: usize, axis: usize) -> L;
}

impl Coordinates<Vec4> for TrianglePacket {
    #[inline(always)]
    fn coordinate(&self, vertex: usize, axis: usize) -> Vec4 {
        self.v[vertex][axis]
    }
}

#[cfg(target_arch = "x86_64")]
impl Coordinates<F32x8> for PacketPair<'_> {
    #[inline(always)]
    fn coordinate(&self, vertex: usize, axis: usize) -> F32x8 {
        let [first, second] = self.0;
        F32x8::from_halves(first.v[vertex][axis], second.v[vertex][axis])
    }
}

/// The watertight test of [`Triangle::intersect_pre`] with triangles in the lanes of `L`: the
/// lanes hit with `0 < t < t_max` (bit per lane), those with an edge function of exactly zero
/// (in the bits above), and per lane `t` and the unnormalised barycentric weights with their
/// sum. No closures: one left out of line would run eight lanes outside the AVX code.
#[inline(always)]
fn lane_hits<L: Lanes, const N: usize>(
    triangles: &impl Coordinates<L>,
    ray: &TriangleRay,
    t_max: f32,
) -> (u32, LaneHits<N>) {
    // No closures (an array's `map`): one left out of line would run its lanes outside the AVX
    // code.
    let vertices = [
        sheared(triangles, 0, ray),
        sheared(triangles, 1, ray),
        sheared(triangles, 2, ray),
    ];
    let (hit, on_edge, [t, wb, wc, det]) = edge_test(vertices, L::splat(ray.inv_dz), L::splat(t_max));
    let mut lanes = LaneHits {
        t: [0.0; N],
        wb: [0.0; N],
        wc: [0.0; N],
        det: [0.0; N],
    };
    t.write_to(&mut lanes.t);
    wb.write_to(&mut lanes.wb);
    wc.write_to(&mut lanes.wc);
    det.write_to(&mut lanes.det);
    (L::bitmask(hit) | (L::bitmask(on_edge) << N), lanes)
}

/// The watertight test on the vertices `a`, `b` and `c` sheared along their lanes' rays
/// (`inv_dz`: 1 / the ray's largest direction component): the lanes hit with `0 < t < t_max`,
/// those with an edge function of exactly zero, and per lane `t`, the weights of `b` and `c`
/// and their sum with `a`'s.
#[inline(always)]
fn edge_test<L: Lanes>(vertices: [(L, L, L); 3], inv_dz: L, t_max: L) -> (L::Mask, L::Mask, [L; 4]) {
    let [(xa, ya, za), (xb, yb, zb), (xc, yc, zc)] = vertices;
    // Edge functions: the unnormalised barycentric weights of a, b and c.
    let wa = xc * yb - yc * xb;
    let wb = xa * yc - ya * xc;
    let wc = xb * ya - yb * xa;
    let zero = L::splat(0.0);
    let neg = wa.lt(zero) | wb.lt(zero) | wc.lt(zero);
    let pos = wa.gt(zero) | wb.gt(zero) | wc.gt(zero);
    let det = wa + wb + wc;
    let t = (wa * za + wb * zb + wc * zc) * inv_dz / det;
    // NaN lanes (unused, or det == 0) fail both comparisons.
    let in_range = t.gt(zero) & t.lt(t_max);
    let hit = !(neg & pos) & in_range;
    let on_edge = wa.eq(zero) | wb.eq(zero) | wc.eq(zero);
    (hit, on_edge, [t, wb, wc, det])
}

/// A vertex's coordinates relative to the ray's origin, sheared so the ray runs along +z.
#[inline(always)]
fn sheared<L: Lanes>(triangles: &impl Coordinates<L>, vertex: usize, ray: &TriangleRay) -> (L, L, L) {
    let [kx, ky, kz] = ray.k;
    let z = triangles.coordinate(vertex, kz) - L::splat(ray.origin[2].x);
    let x = (triangles.coordinate(vertex, kx) - L::splat(ray.origin[0].x)) - L::splat(ray.shear[0].x) * z;
    let y = (triangles.coordinate(vertex, ky) - L::splat(ray.origin[1].x)) - L::splat(ray.shear[1].x) * z;
    (x, y, z)
}

/// The nearest of the lanes `mask` reports hit ([`lane_hits`]); ties go to the lower lane.
#[inline(always)]
fn closest_of_lanes<const N: usize>(
    mask: u32,
    lanes: &LaneHits<N>,
    triangle: impl Fn(usize) -> Triangle,
    ray: &TriangleRay,
    t_max: f32,
) -> Option<(usize, TriangleHit)> {
    if mask >> N != 0 {
        return closest_on_edge(mask, lanes, triangle, ray, t_max);
    }
    if mask == 0 {
        return None;
    }
    // Missed lanes hold NaN or out-of-range values: take the minimum over hit lanes only.
    let t = &lanes.t;
    let mut lane = mask.trailing_zeros() as usize % N;
    let mut rest = mask & (mask - 1);
    while rest != 0 {
        let other = rest.trailing_zeros() as usize % N;
        if t[other] < t[lane] {
            lane = other;
        }
        rest &= rest - 1;
    }
    Some((lane, lanes.hit(lane)))
}

/// [`closest_of_lanes`] when some lane has an edge function of exactly zero: those lanes are
/// settled by the scalar test, and the lanes taken in order, each closer than the last.
#[cold]
fn closest_on_edge<const N: usize>(
    mask: u32,
    lanes: &LaneHits<N>,
    triangle: impl Fn(usize) -> Triangle,
    ray: &TriangleRay,
    t_max: f32,
) -> Option<(usize, TriangleHit)> {
    let mut best: Option<(usize, TriangleHit)> = None;
    let mut t_max = t_max;
    for lane in 0..N {
        let hit = if mask & (1 << (N + lane)) != 0 {
            triangle(lane).intersect_pre(ray, t_max)
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

/// Calls `visit(lane, hit)` for each lane `mask` reports hit ([`lane_hits`]), in lane order,
/// until it returns `true`; returns whether it did.
#[inline(always)]
fn each_of_lanes<const N: usize>(
    mask: u32,
    lanes: &LaneHits<N>,
    triangle: impl Fn(usize) -> Triangle,
    ray: &TriangleRay,
    t_max: f32,
    mut visit: impl FnMut(usize, TriangleHit) -> bool,
) -> bool {
    if mask == 0 {
        return false;
    }
    for lane in 0..N {
        let hit = if mask & (1 << (N + lane)) != 0 {
            triangle(lane).intersect_pre(ray, t_max)
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

/// Whether [`each_of_lanes`] would visit a lane: one the packet test found hit off its edges,
/// or one on an edge (an edge function exactly zero) that the scalar test finds hit.
#[inline(always)]
fn any_of_lanes<const N: usize>(
    mask: u32,
    triangle: impl Fn(usize) -> Triangle,
    ray: &TriangleRay,
    t_max: f32,
) -> bool {
    let on_edge = mask >> N;
    mask & !on_edge & ((1 << N) - 1) != 0
        || (on_edge != 0
            && (0..N).any(|lane| on_edge & (1 << lane) != 0 && triangle(lane).intersect_pre(ray, t_max).is_some()))
}

/// Per-lane results of a packet test.
struct LaneHits<const N: usize> {
    t: [f32; N],
    wb: [f32; N],
    wc: [f32; N],
    det: [f32; N],
}

impl<const N: usize> LaneHits<N> {
    #[inline(always)]
    fn hit(&self, lane: usize) -> TriangleHit {
        let lane = lane % N;
        let inv = 1.0 / self.det[lane];
        TriangleHit {
            t: self.t[lane],
            u: self.wb[lane] * inv,
            v: self.wc[lane] * inv,
        }
    }
}

/// Rays a lane, sheared each its own way ([`TriangleRay`]), for testing triangles one after
/// another against all of them: each lane runs [`lane_hits`]'s arithmetic on its ray, the axes
/// picked lane by lane, so a lane finds the bits a packet test of that ray finds.
pub(crate) struct RayLanes<L: Lanes> {
    /// The origin's permuted coordinates.
    origin: [L; 3],
    shear: [L; 2],
    inv_dz: L,
    /// Lanes whose ray runs mostly along x, and along y.
    along_x: L::Mask,
    along_y: L::Mask,
}

impl<L: Lanes> RayLanes<L> {
    /// The first [`Lanes::N`] of `rays` (at least one), a lane each, sheared as
    /// [`TriangleRay::new`] shears a ray, to the same bits; and the lanes whose ray may meet
    /// something in `bounds` (bit per lane): a finite ray that does not start outside them
    /// on some axis and move away along it.
    #[inline(always)]
    pub(crate) fn new(rays: &[Ray], bounds: &Aabb) -> (RayLanes<L>, u32) {
        // No closures over lanes: one left out of line would run them outside the AVX code.
        // (`Lanes::from_fn` here left the whole test out of line: `glass` 25% more instructions.)
        let mut v = [[0.0f32; 2 * LANES]; 6];
        for lane in 0..L::N {
            let ray = rays.get(lane).unwrap_or(&rays[0]);
            let (o, d) = (ray.origin, ray.dir);
            for (row, value) in v.iter_mut().zip([o.x, o.y, o.z, d.x, d.y, d.z]) {
                row[lane] = value;
            }
        }
        let (ox, oy, oz) = (L::from_slice(&v[0]), L::from_slice(&v[1]), L::from_slice(&v[2]));
        let (dx, dy, dz) = (L::from_slice(&v[3]), L::from_slice(&v[4]), L::from_slice(&v[5]));
        let finite =
            ox.is_finite() & oy.is_finite() & oz.is_finite() & dx.is_finite() & dy.is_finite() & dz.is_finite();
        let (min, max) = (bounds.min, bounds.max);
        let away =
            heads_away(ox, dx, min.x, max.x) | heads_away(oy, dy, min.y, max.y) | heads_away(oz, dz, min.z, max.z);
        let live = L::bitmask(finite & !away) & ((1u32 << rays.len().min(L::N)) - 1);
        // The largest axis as `TriangleRay::new` picks it: x if above both, else y if above z.
        let (ax, ay, az) = (dx.abs(), dy.abs(), dz.abs());
        let along_x = ax.gt(ay) & ax.gt(az);
        let along_y = !along_x & ay.gt(az);
        let origin = permuted((along_x, along_y), ox, oy, oz);
        let [d_kx, d_ky, d_kz] = permuted((along_x, along_y), dx, dy, dz);
        let lanes = RayLanes {
            origin,
            shear: [d_kx / d_kz, d_ky / d_kz],
            inv_dz: L::splat(1.0) / d_kz,
            along_x,
            along_y,
        };
        (lanes, live)
    }

    /// The vertex `p` relative to each lane's origin, sheared as [`sheared`] shears it.
    #[inline(always)]
    fn sheared(&self, p: Vec3) -> (L, L, L) {
        let (px, py, pz) = (L::splat(p.x), L::splat(p.y), L::splat(p.z));
        let [kx, ky, kz] = permuted((self.along_x, self.along_y), px, py, pz);
        let z = kz - self.origin[2];
        let x = (kx - self.origin[0]) - self.shear[0] * z;
        let y = (ky - self.origin[1]) - self.shear[1] * z;
        (x, y, z)
    }

    /// The triangle `[a, b, c]` against each lane's ray with `0 < t < t_max`: the lanes hit (bit
    /// per lane), those with an edge function of exactly zero (for the scalar test to settle),
    /// and per lane `t`, the weights of `b` and `c` and their sum with `a`'s.
    #[inline(always)]
    pub(crate) fn hits(&self, vertices: &[Vec3; 3], t_max: L) -> (u32, u32, [L; 4]) {
        let [a, b, c] = vertices;
        let sheared = [self.sheared(*a), self.sheared(*b), self.sheared(*c)];
        let (hit, on_edge, lanes) = edge_test(sheared, self.inv_dz, t_max);
        (L::bitmask(hit), L::bitmask(on_edge), lanes)
    }
}

/// `(x, y, z)` lane by lane in the order [`TriangleRay`] permutes the axes: the two after the
/// largest, then the largest — `(y, z, x)` where the ray runs mostly along x (`along.0`),
/// `(z, x, y)` along y (`along.1`), else `(x, y, z)`.
#[inline(always)]
fn permuted<L: Lanes>((along_x, along_y): (L::Mask, L::Mask), x: L, y: L, z: L) -> [L; 3] {
    [
        L::select(along_x, y, L::select(along_y, z, x)),
        L::select(along_x, z, L::select(along_y, x, y)),
        L::select(along_x, x, L::select(along_y, y, z)),
    ]
}

/// Lanes whose ray starts outside `[min, max]` on this axis (origin `o`) and moves away from it
/// (direction `d`), as the triangle tree's `heads_away` tests.
#[inline(always)]
fn heads_away<L: Lanes>(o: L, d: L, min: f32, max: f32) -> L::Mask {
    let zero = L::splat(0.0);
    (o.lt(L::splat(min)) & d.le(zero)) | (o.gt(L::splat(max)) & d.ge(zero))
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

    /// Case `case` of a test: `count` random triangles, some sharing a vertex or an edge with
    /// the first, and a ray aimed at a vertex, an edge or the inside of one of them, with its
    /// segment's end (at times short).
    fn random_case(rng: &mut Rng, case: usize, count: usize) -> (Vec<Triangle>, TriangleRay, f32) {
        let shared = v(rng);
        let tris: Vec<Triangle> = (0..count)
            .map(|i| {
                let a = if i > 0 && case.is_multiple_of(3) {
                    shared
                } else {
                    v(rng)
                };
                Triangle::new(a, v(rng), if case.is_multiple_of(5) { shared * 0.5 } else { v(rng) })
            })
            .collect();
        let target = match case % 4 {
            0 => tris[0].vertices()[case % 3],
            1 => tris[count - 1].point(rng.uniform(), 0.0),
            _ => tris[case % count].point(rng.uniform() * 0.5, rng.uniform() * 0.5),
        };
        let origin = v(rng) * 3.0;
        let ray = Ray::new(origin, (target - origin) * (0.5 + rng.uniform()));
        let t_max = if case.is_multiple_of(7) {
            rng.uniform() * 2.0
        } else {
            f32::INFINITY
        };
        (tris, TriangleRay::new(&ray), t_max)
    }

    /// The packet's closest hit and hit list equal the scalar test's on each triangle, bit for
    /// bit, including rays through shared edges and vertices and partly filled packets.
    #[test]
    fn packet_agrees_with_scalar_test() {
        let mut rng = Rng::new(0x1234_5678_9abc_def1, 0);
        let mut hits = 0;
        for case in 0..20_000 {
            let (tris, tr, t_max) = random_case(&mut rng, case, 1 + case % LANES);
            let packet = TrianglePacket::new(&tris);

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
            assert_eq!(packet.any_hit(&tr, t_max), !expected_all.is_empty(), "case {case}");
            hits += usize::from(expected.is_some());
        }
        assert!(hits > 5_000, "the cases exercise hits: {hits}");
    }

    /// Two packets tested as one of eight lanes answer as the two tested one after the other,
    /// bit for bit: the nearest (ties to the first packet), and every hit in lane order;
    /// rays through shared edges and vertices included.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn a_pair_in_eight_lanes_agrees_with_its_packets_in_turn() {
        let Some(avx) = crate::accel::lanes::Avx::detect() else {
            eprintln!("skipped: this CPU has no AVX");
            return;
        };
        let mut rng = Rng::new(0x0e16_4715_0000_0001, 0);
        let (mut hits, mut seconds) = (0, 0);
        for case in 0..20_000 {
            let (tris, tr, t_max) = random_case(&mut rng, case, LANES + 1 + case % LANES);
            let packets = [TrianglePacket::new(&tris[..LANES]), TrianglePacket::new(&tris[LANES..])];
            // The packets in turn, the second searching only nearer than the first's hit.
            let first = packets[0].closest_hit(&tr, t_max);
            let second = packets[1].closest_hit(&tr, first.map_or(t_max, |(_, h)| h.t));
            let expected = second.map(|(lane, h)| (LANES + lane, h)).or(first);
            let mut expected_all = Vec::new();
            for (p, packet) in packets.iter().enumerate() {
                packet.each_hit(&tr, t_max, |lane, h| {
                    expected_all.push((p * LANES + lane, h));
                    false
                });
            }
            let pair = PacketPair(&packets);
            let (closest, all, any) = crate::accel::lanes::in_avx(
                avx,
                #[inline(always)]
                || {
                    let mut all = Vec::new();
                    pair.each_hit(&tr, t_max, |lane, h| {
                        all.push((lane, h));
                        false
                    });
                    (pair.closest_hit(&tr, t_max), all, pair.any_hit(&tr, t_max))
                },
            );
            assert_eq!(closest, expected, "case {case}");
            assert_eq!(all, expected_all, "case {case}");
            assert_eq!(any, !expected_all.is_empty(), "case {case}");
            hits += usize::from(expected.is_some());
            seconds += usize::from(second.is_some());
        }
        assert!(
            hits > 5_000 && seconds > 1_000,
            "the cases exercise hits: {hits}, {seconds} in the second packet"
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
