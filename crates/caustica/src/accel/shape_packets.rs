//! A scene of a few squares and round spheres (a Cornell box's walls and balls) tested without
//! a hierarchy: the squares in packets, the spheres in packets, each packet one SIMD test, four
//! lanes wide or eight where the CPU has AVX ([`crate::accel::lanes`]). A ray meets every packet;
//! for a handful of shapes that costs less than setting up a walk and testing boxes, which is
//! most of what a ray costs there.
//!
//! The lanes run the shapes' own scalar tests ([`Shape::intersect_object_normal`]) operation for
//! operation, so a lane hits exactly where the shape's test does, at the same `t`, at either
//! width. The packets only pick the shape; its hit record comes from its own test.

use glam::Vec4;

#[cfg(target_arch = "x86_64")]
use super::lanes::{in_avx, Avx, F32x8};
use super::lanes::{Lanes, Width};
use crate::geometry::{PacketForm, Shape};
use crate::math::Ray;

/// Most lanes of any width.
const MAX_LANES: usize = 8;

/// Most shapes tested this way: past it a hierarchy's box tests cull more than they cost.
pub const MAX_SHAPES: usize = 16;

/// Fewest shapes tested this way. A glass ball and its lamp render 2.5% faster in a packet than
/// from the hierarchy's root boxes, now that the picked shape's record comes from the packet's
/// `t` (before, when its test ran again, 5% slower). A lone lamp measured the same either way ray
/// by ray, and a wave's rays test it eight at a time ([`ShapePackets::closest_each`]).
pub const MIN_SHAPES: usize = 1;

/// Id of an unused lane.
const NO_SHAPE: u32 = u32::MAX;

/// Squares, one a lane: the rows of each one's world-to-object rotation and scale, and its
/// origin. Unused lanes have zero rows and never hit.
#[derive(Clone, Copy, Debug)]
struct SquarePacket<L> {
    rows: [[L; 3]; 3],
    origin: [L; 3],
    ids: [u32; MAX_LANES],
}

/// Spheres kept round by their transforms, one a lane: world centres and radii. Unused lanes
/// have NaN radii and never hit.
#[derive(Clone, Copy, Debug)]
struct SpherePacket<L> {
    center: [L; 3],
    radius: L,
    /// The lanes in use (bit per lane): the test stops early when the ray passes wide of all
    /// of them, which an unused lane must not prevent.
    used: u32,
    ids: [u32; MAX_LANES],
}

/// The packets of one width.
#[derive(Clone, Debug)]
struct Packets<L> {
    squares: Vec<SquarePacket<L>>,
    spheres: Vec<SpherePacket<L>>,
    /// Each shape alone in every lane, in the packets' order: for testing a lane per ray
    /// ([`ShapePackets::closest_each`]).
    lone_squares: Vec<SquarePacket<L>>,
    lone_spheres: Vec<SpherePacket<L>>,
    /// Where each shape (by id) sits: its packet's place, squares' packets first, and its
    /// lane's bit; `(u32::MAX, 0)` for a shape left out.
    slots: [(u32, u32); MAX_SHAPES],
}

/// The shapes of a scene of few squares and round spheres, in packets.
#[derive(Clone, Debug)]
pub struct ShapePackets {
    lanes: PacketLanes,
    /// The one shape packed, where there is one (a lamp over a mesh): a shadow ray that ends on
    /// it meets nothing else here.
    lone: Option<u32>,
}

#[derive(Clone, Debug)]
enum PacketLanes {
    Four(Packets<Vec4>),
    #[cfg(target_arch = "x86_64")]
    Eight(Avx, Packets<F32x8>),
}

/// Per-ray values every packet uses: one ray in every lane, or a ray a lane.
struct PacketRay<L> {
    origin: [L; 3],
    dir: [L; 3],
    /// `dir · dir`, as the sphere test forms it.
    dir2: L,
}

impl<L: Lanes> PacketRay<L> {
    /// `ray` in every lane.
    #[inline(always)]
    fn new(ray: &Ray) -> PacketRay<L> {
        let (o, d) = (ray.origin, ray.dir);
        PacketRay {
            origin: [o.x, o.y, o.z].map(L::splat),
            dir: [d.x, d.y, d.z].map(L::splat),
            dir2: L::splat(d.dot(d)),
        }
    }

    /// `rays` (at most [`Lanes::N`], at least one) a lane each; lanes past them repeat the first.
    #[inline(always)]
    fn lanes(rays: &[Ray]) -> PacketRay<L> {
        let ray = |lane: usize| rays.get(lane).unwrap_or(&rays[0]);
        PacketRay {
            origin: [
                L::from_fn(|i| ray(i).origin.x),
                L::from_fn(|i| ray(i).origin.y),
                L::from_fn(|i| ray(i).origin.z),
            ],
            dir: [
                L::from_fn(|i| ray(i).dir.x),
                L::from_fn(|i| ray(i).dir.y),
                L::from_fn(|i| ray(i).dir.z),
            ],
            dir2: L::from_fn(|i| ray(i).dir.dot(ray(i).dir)),
        }
    }
}

/// `a · b` for three lanes of vectors, summed in the order of `Vec3::dot`.
#[inline(always)]
fn dot<L: Lanes>(a: &[L; 3], b: &[L; 3]) -> L {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// The forms of the shapes a packet test can take, with their ids.
struct Forms {
    squares: Vec<(u32, [[f32; 3]; 3], [f32; 3])>,
    spheres: Vec<(u32, [f32; 3], f32)>,
}

impl ShapePackets {
    /// Packets of `shapes` (ids are indices into it) as wide as the CPU runs, or `None` if
    /// there are fewer than [`MIN_SHAPES`] or more than [`MAX_SHAPES`], or one is neither a
    /// square nor a round sphere. Shapes a hierarchy would leave out (empty or non-finite
    /// bounds) are left out.
    pub fn new(shapes: &[Shape]) -> Option<ShapePackets> {
        ShapePackets::with_width(shapes, Width::of_host())
    }

    /// [`ShapePackets::new`] at the lane width `width`.
    pub fn with_width(shapes: &[Shape], width: Width) -> Option<ShapePackets> {
        if !(MIN_SHAPES..=MAX_SHAPES).contains(&shapes.len()) {
            return None;
        }
        let mut forms = Forms {
            squares: Vec::new(),
            spheres: Vec::new(),
        };
        for (id, shape) in shapes.iter().enumerate() {
            let b = shape.bounds;
            if b.is_empty() || !b.min.is_finite() || !b.max.is_finite() {
                continue;
            }
            match shape.packet_form()? {
                PacketForm::Square { rows, origin } => {
                    forms
                        .squares
                        .push((id as u32, rows.map(|r| r.to_array()), origin.to_array()))
                }
                PacketForm::Sphere { center, radius } => forms.spheres.push((id as u32, center.to_array(), radius)),
            }
        }
        let lanes = match width {
            Width::Four => PacketLanes::Four(Packets::new(&forms)),
            #[cfg(target_arch = "x86_64")]
            Width::Eight(avx) => PacketLanes::Eight(
                avx,
                in_avx(
                    avx,
                    #[inline(always)]
                    || Packets::new(&forms),
                ),
            ),
        };
        let lone = match (forms.squares.as_slice(), forms.spheres.as_slice()) {
            ([(id, ..)], []) | ([], [(id, ..)]) => Some(*id),
            _ => None,
        };
        Some(ShapePackets { lanes, lone })
    }

    /// The shape whose own test finds the nearest hit with `0 < t < t_max`, and that `t`.
    /// Ties go to the shape tested first.
    #[inline]
    pub fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        match &self.lanes {
            PacketLanes::Four(p) => p.closest(ray, t_max),
            #[cfg(target_arch = "x86_64")]
            PacketLanes::Eight(avx, p) => in_avx(
                *avx,
                #[inline(always)]
                || p.closest(ray, t_max),
            ),
        }
    }

    /// [`ShapePackets::closest`] of each of `rays` with its own `t_max`, into `out`: the same
    /// shapes and `t`, to the bit, with a ray in each lane and the shapes one after another,
    /// which costs a fraction of testing the shapes in the lanes ray by ray.
    ///
    /// # Panics
    /// If `rays`, `t_max` and `out` differ in length.
    pub fn closest_each(&self, rays: &[Ray], t_max: &[f32], out: &mut [Option<(u32, f32)>]) {
        assert!(
            rays.len() == t_max.len() && rays.len() == out.len(),
            "a t_max and an answer per ray"
        );
        match &self.lanes {
            PacketLanes::Four(p) => p.closest_each(rays, t_max, out),
            #[cfg(target_arch = "x86_64")]
            PacketLanes::Eight(avx, p) => in_avx(
                *avx,
                #[inline(always)]
                || p.closest_each(rays, t_max, out),
            ),
        }
    }

    /// Calls `visit(shape)` for each shape whose own test finds a hit with `0 < t < t_max`,
    /// until it returns `true`; returns whether it did.
    #[inline]
    pub fn each(&self, ray: &Ray, t_max: f32, visit: impl FnMut(u32) -> bool) -> bool {
        match &self.lanes {
            PacketLanes::Four(p) => p.each::<false>(ray, t_max, NO_SHAPE, visit),
            #[cfg(target_arch = "x86_64")]
            PacketLanes::Eight(avx, p) => in_avx(
                *avx,
                #[inline(always)]
                || p.each::<false>(ray, t_max, NO_SHAPE, visit),
            ),
        }
    }

    /// [`ShapePackets::each`] passing over shape `own`, whose lane neither counts nor keeps the
    /// test from stopping early: a shadow ray towards a sphere lamp ends on the lamp, which
    /// would otherwise take the whole test every time. (An instance of the test of its own:
    /// [`ShapePackets::each`] keeps one without the skipping.)
    #[inline]
    pub fn each_except(&self, ray: &Ray, t_max: f32, own: u32, visit: impl FnMut(u32) -> bool) -> bool {
        if self.lone == Some(own) {
            return false;
        }
        match &self.lanes {
            PacketLanes::Four(p) => p.each::<true>(ray, t_max, own, visit),
            #[cfg(target_arch = "x86_64")]
            PacketLanes::Eight(avx, p) => in_avx(
                *avx,
                #[inline(always)]
                || p.each::<true>(ray, t_max, own, visit),
            ),
        }
    }
}

impl<L: Lanes> Packets<L> {
    /// Packets of `forms`, [`Lanes::N`] shapes to a packet.
    #[inline(always)]
    fn new(forms: &Forms) -> Packets<L> {
        let lanes = |n: usize, value: &dyn Fn(usize) -> f32, unused: f32| {
            let v: [f32; MAX_LANES] = std::array::from_fn(|lane| if lane < n { value(lane) } else { unused });
            L::from_slice(&v)
        };
        let ids = |chunk: &mut dyn Iterator<Item = u32>| {
            let mut ids = [NO_SHAPE; MAX_LANES];
            ids.iter_mut().zip(chunk).for_each(|(slot, id)| *slot = id);
            ids
        };
        let squares: Vec<SquarePacket<L>> = forms
            .squares
            .chunks(L::N)
            .map(|c| SquarePacket {
                rows: std::array::from_fn(|row| {
                    std::array::from_fn(|axis| lanes(c.len(), &|lane| c[lane].1[row][axis], 0.0))
                }),
                origin: std::array::from_fn(|axis| lanes(c.len(), &|lane| c[lane].2[axis], 0.0)),
                ids: ids(&mut c.iter().map(|s| s.0)),
            })
            .collect();
        let spheres: Vec<SpherePacket<L>> = forms
            .spheres
            .chunks(L::N)
            .map(|c| SpherePacket {
                center: std::array::from_fn(|axis| lanes(c.len(), &|lane| c[lane].1[axis], 0.0)),
                radius: lanes(c.len(), &|lane| c[lane].2, f32::NAN),
                used: (1 << c.len()) - 1,
                ids: ids(&mut c.iter().map(|s| s.0)),
            })
            .collect();
        let lone_squares = forms
            .squares
            .iter()
            .map(|(id, rows, origin)| SquarePacket {
                rows: rows.map(|row| row.map(L::splat)),
                origin: origin.map(L::splat),
                ids: [*id; MAX_LANES],
            })
            .collect();
        let lone_spheres = forms
            .spheres
            .iter()
            .map(|(id, center, radius)| SpherePacket {
                center: center.map(L::splat),
                radius: L::splat(*radius),
                used: (1 << L::N) - 1,
                ids: [*id; MAX_LANES],
            })
            .collect();
        let mut slots = [(u32::MAX, 0); MAX_SHAPES];
        let packed = squares.iter().map(|p| &p.ids).chain(spheres.iter().map(|p| &p.ids));
        for (packet, ids) in packed.enumerate() {
            for (lane, &id) in ids.iter().enumerate().filter(|&(_, &id)| id != NO_SHAPE) {
                slots[id as usize] = (packet as u32, 1 << lane);
            }
        }
        Packets {
            squares,
            spheres,
            lone_squares,
            lone_spheres,
            slots,
        }
    }

    /// [`ShapePackets::closest_each`], [`Lanes::N`] rays at a time. The shapes are tested in
    /// [`Packets::closest`]'s order against each ray's own `t_max`, and a hit replaces the best
    /// only when nearer, as there.
    #[inline(always)]
    fn closest_each(&self, rays: &[Ray], t_max: &[f32], out: &mut [Option<(u32, f32)>]) {
        for ((rays, t_max), out) in rays.chunks(L::N).zip(t_max.chunks(L::N)).zip(out.chunks_mut(L::N)) {
            let pr = PacketRay::<L>::lanes(rays);
            // Lanes past the rays: no `t` is below zero.
            let bound = L::from_fn(|i| t_max.get(i).copied().unwrap_or(0.0));
            // Each lane's nearest hit so far and its shape (-1: none), kept without a branch: a
            // hit is below the lane's bound, and replaces the best only when nearer.
            let (mut nearest, mut shape) = (bound, L::splat(-1.0));
            for p in &self.lone_squares {
                let (hit, t) = p.lanes_hit::<false>(&pr, bound, 0);
                let nearer = hit & t.lt(nearest);
                nearest = L::select(nearer, t, nearest);
                shape = L::select(nearer, L::splat(p.ids[0] as f32), shape);
            }
            for p in &self.lone_spheres {
                let (hit, t) = p.lanes_hit::<false>(&pr, bound, 0);
                let nearer = hit & t.lt(nearest);
                nearest = L::select(nearer, t, nearest);
                shape = L::select(nearer, L::splat(p.ids[0] as f32), shape);
            }
            let (mut t, mut id) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
            nearest.write_to(&mut t);
            shape.write_to(&mut id);
            for (lane, slot) in out.iter_mut().enumerate() {
                *slot = (id[lane] >= 0.0).then_some((id[lane] as u32, t[lane]));
            }
        }
    }

    #[inline(always)]
    fn closest(&self, ray: &Ray, t_max: f32) -> Option<(u32, f32)> {
        let pr = PacketRay::<L>::new(ray);
        let mut best: Option<(u32, f32)> = None;
        let mut keep = |mask: u32, t: L, ids: &[u32; MAX_LANES]| {
            let mut ts = [0.0; MAX_LANES];
            t.write_to(&mut ts);
            let mut rest = mask;
            while rest != 0 {
                let lane = rest.trailing_zeros() as usize;
                if best.is_none_or(|(_, b)| ts[lane] < b) {
                    best = Some((ids[lane], ts[lane]));
                }
                rest &= rest - 1;
            }
        };
        for p in &self.squares {
            let (mask, t) = p.hits(&pr, L::splat(t_max), 0);
            keep(mask, t, &p.ids);
        }
        for p in &self.spheres {
            let (mask, t) = p.hits(&pr, L::splat(t_max), 0);
            keep(mask, t, &p.ids);
        }
        best
    }

    /// Calls `visit` for each shape hit, until it returns `true`; with `SKIPS`, passing over
    /// shape `own`.
    #[inline(always)]
    fn each<const SKIPS: bool>(&self, ray: &Ray, t_max: f32, own: u32, mut visit: impl FnMut(u32) -> bool) -> bool {
        let pr = PacketRay::<L>::new(ray);
        let (own_packet, own_lane) = match self.slots.get(own as usize) {
            Some(&slot) if SKIPS => slot,
            _ => (u32::MAX, 0),
        };
        // Plain loops: a closure around a packet's test, left out of line, would run its lanes
        // outside the AVX code.
        let mut packet = 0;
        for p in &self.squares {
            let skip = if SKIPS && packet == own_packet { own_lane } else { 0 };
            if visit_lanes(p.hits(&pr, L::splat(t_max), skip).0, &p.ids, &mut visit) {
                return true;
            }
            packet += 1;
        }
        for p in &self.spheres {
            let skip = if SKIPS && packet == own_packet { own_lane } else { 0 };
            if visit_lanes(p.hits(&pr, L::splat(t_max), skip).0, &p.ids, &mut visit) {
                return true;
            }
            packet += 1;
        }
        false
    }
}

/// Calls `visit(shape)` for the shape of each lane of `mask`, until it returns `true`; returns
/// whether it did.
#[inline(always)]
fn visit_lanes(mask: u32, ids: &[u32; MAX_LANES], visit: &mut impl FnMut(u32) -> bool) -> bool {
    let mut rest = mask;
    while rest != 0 {
        if visit(ids[rest.trailing_zeros() as usize]) {
            return true;
        }
        rest &= rest - 1;
    }
    false
}

impl<L: Lanes> SquarePacket<L> {
    /// The lanes hit with `0 < t < t_max` (bit per lane), but for the lanes of `skip`, and their
    /// `t`: the square test of `Shape::intersect_square`, lane by lane.
    #[inline(always)]
    fn hits(&self, ray: &PacketRay<L>, t_max: L, skip: u32) -> (u32, L) {
        let (hit, t) = self.lanes_hit::<true>(ray, t_max, skip);
        (L::bitmask(hit) & !skip, t)
    }

    /// The lanes hit with `0 < t < t_max`, and their `t`. With `STOPS`, none as soon as no lane
    /// but those of `skip` can be (a ray against shapes, where that is common); without, the
    /// whole test without a branch (a ray a lane, where a branch on the lanes mispredicts).
    #[inline(always)]
    fn lanes_hit<const STOPS: bool>(&self, ray: &PacketRay<L>, t_max: L, skip: u32) -> (L::Mask, L) {
        let [row_x, row_y, row_z] = &self.rows;
        let zero = L::splat(0.0);
        let dir_z = dot(row_z, &ray.dir);
        let to_origin: [L; 3] = std::array::from_fn(|axis| self.origin[axis] - ray.origin[axis]);
        let distance_z = dot(row_z, &to_origin);
        // Behind the ray, parallel to it, or beyond `t_max`.
        let facing = distance_z.gt(zero) ^ dir_z.gt(zero);
        let far = distance_z.abs().ge(t_max * dir_z.abs());
        let turned_away = dir_z.eq(zero) | facing | far;
        if STOPS && L::bitmask(!turned_away) & !skip == 0 {
            return (zero.lt(zero), zero);
        }
        let t = distance_z / dir_z;
        let in_range = t.gt(zero) & t.lt(t_max);
        let offset: [L; 3] = std::array::from_fn(|axis| ray.origin[axis] + ray.dir[axis] * t - self.origin[axis]);
        let half = L::splat(0.5);
        let outside = dot(row_x, &offset).abs().gt(half) | dot(row_y, &offset).abs().gt(half);
        (!turned_away & in_range & !outside, t)
    }
}

impl<L: Lanes> SpherePacket<L> {
    /// The lanes hit with `0 < t < t_max` (bit per lane), but for the lanes of `skip`, and their
    /// `t`: the round-sphere test of `Shape::intersect_round_sphere` with
    /// [`crate::geometry::quadratic_roots`], lane by lane.
    #[inline(always)]
    fn hits(&self, ray: &PacketRay<L>, t_max: L, skip: u32) -> (u32, L) {
        let (hit, t) = self.lanes_hit::<true>(ray, t_max, skip);
        (L::bitmask(hit) & !skip, t)
    }

    /// [`SquarePacket::lanes_hit`] for the spheres.
    #[inline(always)]
    fn lanes_hit<const STOPS: bool>(&self, ray: &PacketRay<L>, t_max: L, skip: u32) -> (L::Mask, L) {
        let zero = L::splat(0.0);
        let oc: [L; 3] = std::array::from_fn(|axis| ray.origin[axis] - self.center[axis]);
        let a = ray.dir2;
        let half_b = dot(&oc, &ray.dir);
        let k = half_b / a;
        let l: [L; 3] = std::array::from_fn(|axis| oc[axis] - ray.dir[axis] * k);
        let (l2, r2) = (dot(&l, &l), self.radius * self.radius);
        let near = !l2.gt(r2);
        if STOPS && L::bitmask(near) & self.used & !skip == 0 {
            return (zero.lt(zero), zero);
        }
        let l_len = l2.sqrt();
        let disc = a * ((self.radius - l_len) * (self.radius + l_len));
        let c = dot(&oc, &oc) - r2;
        let real = disc.ge(zero) & disc.is_finite();
        let q = -(half_b + disc.sqrt().copysign(half_b));
        let q_zero = q.eq(zero);
        let t0 = L::select(q_zero, zero, q / a);
        let t1 = L::select(q_zero, zero, c / q);
        let (lo, hi) = (t0.min(t1), t0.max(t1));
        let t = L::select(lo.gt(zero), lo, hi);
        let in_range = t.gt(zero) & t.lt(t_max);
        // `a == 0` (a zero direction) takes the scalar test's other branch: no lane claims it.
        (near & real & in_range & !a.eq(zero), t)
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
    /// by a random `t_max` — the packets of every width this CPU runs pick the shape and `t` (to
    /// the bit) that testing each shape by its own test picks, `each` visits exactly the
    /// shapes those tests hit, and `each_except` all of them but the one it passes over; and
    /// `closest_each`, a ray a lane, picks the same for all the rays at once (in runs of 1 to
    /// 13 rays, so lanes are left over).
    #[test]
    fn packets_find_what_each_shapes_own_test_finds() {
        let shapes = shapes();
        let widths = Width::on_host();
        let packets: Vec<ShapePackets> = widths
            .iter()
            .map(|&w| ShapePackets::with_width(&shapes, w).expect("all squares and round spheres"))
            .collect();
        let mut rng = Rng::new(7, 0);
        let mut random = |scale: f32| Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * scale;
        let (mut hits, mut several) = (0, 0);
        let mut all = (Vec::new(), Vec::new(), Vec::new());
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
                    // The record at the hit's `t` alone is the test's record.
                    assert_eq!(shape.packet_hit_at(&ray, h.t), Some(h), "{ray:?}");
                }
            }
            for (packets, width) in packets.iter().zip(&widths) {
                let found = packets.closest(&ray, t_max);
                assert_eq!(
                    found.map(|(id, t)| (id, t.to_bits())),
                    expected.map(|(id, t)| (id, t.to_bits())),
                    "{width:?}: {ray:?} {t_max}"
                );
                let mut each_found = vec![];
                packets.each(&ray, t_max, |id| {
                    each_found.push(id);
                    false
                });
                each_found.sort();
                assert_eq!(each_found, each_expected, "{width:?}: {ray:?} {t_max}");
                // Passing over one shape (or none) drops exactly that shape.
                let own = if i % 5 == 0 {
                    NO_SHAPE
                } else {
                    (i % shapes.len()) as u32
                };
                let mut except_found = vec![];
                packets.each_except(&ray, t_max, own, |id| {
                    except_found.push(id);
                    false
                });
                except_found.sort();
                let except_expected: Vec<u32> = each_expected.iter().copied().filter(|&id| id != own).collect();
                assert_eq!(except_found, except_expected, "{width:?}: {ray:?} {t_max} except {own}");
            }
            hits += usize::from(expected.is_some());
            several += usize::from(each_expected.len() > 1);
            all.0.push(ray);
            all.1.push(t_max);
            all.2.push(expected);
        }
        let (rays, t_max, expected) = all;
        for (packets, width) in packets.iter().zip(&widths) {
            let mut found = vec![Some((0, 0.0)); rays.len()];
            let mut start = 0;
            for run in (1..=13).cycle() {
                let end = (start + run).min(rays.len());
                packets.closest_each(&rays[start..end], &t_max[start..end], &mut found[start..end]);
                start = end;
                if start == rays.len() {
                    break;
                }
            }
            for i in 0..rays.len() {
                assert_eq!(
                    found[i].map(|(id, t)| (id, t.to_bits())),
                    expected[i].map(|(id, t)| (id, t.to_bits())),
                    "{width:?}, a ray a lane: {:?} {}",
                    rays[i],
                    t_max[i]
                );
            }
        }
        assert!(
            hits > 100_000 && several > 50_000,
            "{hits} hits, {several} with several"
        );
    }

    /// A shadow ray ending on a lone packed shape (a lamp over a mesh) meets nothing; one ending
    /// elsewhere still meets it, and so does every test that passes over nothing.
    #[test]
    fn a_lone_shape_passed_over_leaves_nothing() {
        let lamp = Shape::new(ShapeKind::Sphere, Mat4::from_translation(Vec3::new(0.0, 2.0, 0.0))).unwrap();
        let floor = Shape::new(ShapeKind::Square, Mat4::from_scale(Vec3::splat(4.0))).unwrap();
        let ray = Ray::new(Vec3::ZERO, Vec3::Y);
        for width in Width::on_host() {
            let lone = ShapePackets::with_width(std::slice::from_ref(&lamp), width).expect("a round sphere");
            assert_eq!(lone.lone, Some(0));
            let mut met = vec![];
            assert!(!lone.each_except(&ray, 10.0, 0, |id| {
                met.push(id);
                true
            }));
            assert!(met.is_empty(), "{width:?}");
            assert!(lone.each_except(&ray, 10.0, NO_SHAPE, |_| true), "{width:?}");
            assert!(lone.each(&ray, 10.0, |_| true), "{width:?}");
            let two = ShapePackets::with_width(&[lamp.clone(), floor.clone()], width).expect("packed");
            assert_eq!(two.lone, None);
            assert!(two.each_except(&ray, 10.0, 1, |_| true), "{width:?}");
        }
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
