//! A BVH specialised to triangles: each leaf holds its triangles in [`TrianglePacket`]s of four,
//! stored in leaf order, so a leaf is read from consecutive memory and tested four triangles at
//! a time, or, where the CPU has AVX, a leaf of two packets eight at a time ([`PacketPair`]).
//! The tree is built with leaves priced per packet, so it favours full packets.

use super::build::LeafCost;
use super::{Bvh, RayPre, SlabTest, StackSized, Traversal, Visit, END, LARGE_STACK, LEAF, PAIR};
#[cfg(target_arch = "x86_64")]
use super::{SortingRayPre, WideRayPre};
#[cfg(target_arch = "x86_64")]
use crate::accel::lanes::{in_avx, in_avx2, Avx, F32x8};
use crate::accel::lanes::{Lanes, Width};
use crate::geometry::triangle::{Triangle, TriangleHit, TriangleRay};
#[cfg(target_arch = "x86_64")]
use crate::geometry::triangle_packet::PacketPair;
use crate::geometry::triangle_packet::{RayLanes, TrianglePacket, LANES};
use crate::math::{Aabb, Ray, Vec3};
use crate::progress::{NoProgress, Progress};
use std::cell::RefCell;

/// Packet leaves: a packet test costs about one binary node visit (measured with the `bvh`
/// bench: 1.0 to 2.0 change incoherent throughput by under 5%), and a leaf holds at most two.
const PACKET_LEAVES: LeafCost = LeafCost {
    block: LANES,
    block_cost: 1.0,
    max_leaf: 2 * LANES,
};

/// Rays walked together by [`TriangleBvh::closest_hits`]: enough independent node reads in
/// flight to overlap cache misses, few enough that their state stays in the L1 cache.
const STREAM: usize = 8;

/// The traversal stacks of a stream's lanes, each as large as any tree needs.
type LaneStacks = [[(u32, f32); LARGE_STACK]; STREAM];

thread_local! {
    /// The lane stacks each stream on the thread borrows: lanes that owned theirs had them
    /// cleared and moved when made, 4 KB each on a million triangles (`memmove` took 3% of a
    /// vcm render there).
    static STREAM_STACKS: RefCell<LaneStacks> = const { RefCell::new([[(0, 0.0); LARGE_STACK]; STREAM]) };
}

/// Cache lines of a leaf's packets loaded ahead by a stream's walk: a whole packet; both of a
/// pair (288 bytes).
const FETCH_LINES: usize = 3;
const PAIR_FETCH_LINES: usize = 5;

/// Trees of more bytes than this load ahead in streams (a triangle takes about 45 bytes). Loading
/// ahead made streams faster by 40–70% on a million triangles, 9–18% on 300k and 0–9% on 148k;
/// on 74k (3.3 MB) it was even, and on 37k (within this host's 2 MB L2 cache) it cost any-hit
/// streams 6–8% (`bvh` bench, both ways alternated).
const FETCH_AHEAD_BYTES: usize = 4 << 20;

/// Id of an unused packet lane.
const NO_TRIANGLE: u32 = u32::MAX;

/// Packets tested one after another, without a walk: for a floor of two triangles the walk's
/// set-up and box tests cost more than the packet they would cull.
const FEW_PACKETS: usize = 2;

/// Closest hit in a [`TriangleBvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleBvhHit {
    /// Ray parameter, in units of the ray direction.
    pub t: f32,
    /// Index of the triangle in the slice given to [`TriangleBvh::new`].
    pub prim: u32,
    /// Barycentric weight of vertex `b`.
    pub u: f32,
    /// Barycentric weight of vertex `c`.
    pub v: f32,
}

/// The closest hit found so far in a walk: a packet lane and its barycentrics.
#[derive(Clone, Copy, Debug)]
struct LeafHit {
    packet: usize,
    lane: usize,
    u: f32,
    v: f32,
}

/// A BVH over triangles that owns copies of them, packed four to a packet in leaf order.
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    /// The hierarchy, eight children a node; its leaf references and leaf order index `packets`
    /// (`END` marks the last packet of each leaf).
    pub(super) bvh: Bvh<2>,
    packets: Vec<TrianglePacket>,
    /// Triangle ids of each packet's lanes ([`NO_TRIANGLE`] for unused lanes).
    ids: Vec<[u32; LANES]>,
    /// The lanes the walks test a node's boxes in: eight in one AVX register where the CPU has
    /// it, else two rows of four.
    width: Width,
    /// Whether a stream's walks load their next node or leaf ahead ([`TriangleBvh::fetch_next`]):
    /// only for trees larger than [`FETCH_AHEAD_BYTES`].
    fetch_ahead: bool,
}

impl TriangleBvh {
    /// Builds over `tris` (see [`Bvh::build`]: triangles with non-finite or empty bounds are
    /// left out).
    pub fn new(tris: &[Triangle]) -> TriangleBvh {
        TriangleBvh::build_reporting(tris, &NoProgress)
    }

    /// [`TriangleBvh::new`], advancing `progress` by one unit per triangle placed in the tree.
    pub fn build_reporting(tris: &[Triangle], progress: &dyn Progress) -> TriangleBvh {
        // A triangle with two equal vertices is never hit (its two non-zero edge functions are
        // exact negatives of each other), so it is left out like a non-finite one.
        let bounds: Vec<Aabb> = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.vertices();
                if a == b || b == c || c == a {
                    Aabb::EMPTY
                } else {
                    t.bounds()
                }
            })
            .collect();
        let mut bvh = Bvh::<2>::build_priced(&bounds, PACKET_LEAVES, progress);
        // Pack each leaf (a run of the leaf order ending in `END`) and note where its packets
        // start, indexed by the leaf's first position in the old order.
        let mut packets = Vec::with_capacity(bvh.order.len().div_ceil(LANES));
        let mut ids = Vec::with_capacity(packets.capacity());
        let mut packet_order = Vec::with_capacity(packets.capacity());
        let mut first_packet = vec![0u32; bvh.order.len()];
        let mut start = 0;
        for (i, &p) in bvh.order.iter().enumerate() {
            if p & END == 0 {
                continue;
            }
            first_packet[start] = packets.len() as u32;
            let leaf: Vec<u32> = bvh.order[start..=i].iter().map(|&p| p & !END).collect();
            for chunk in leaf.chunks(LANES) {
                let lane_tris: Vec<Triangle> = chunk.iter().map(|&t| tris[t as usize]).collect();
                packet_order.push(packets.len() as u32);
                packets.push(TrianglePacket::new(&lane_tris));
                let mut lane_ids = [NO_TRIANGLE; LANES];
                lane_ids[..chunk.len()].copy_from_slice(chunk);
                ids.push(lane_ids);
            }
            *packet_order.last_mut().expect("a leaf has a packet") |= END;
            start = i + 1;
        }
        for node in &mut bvh.nodes {
            for child in node.children.iter_mut().flatten() {
                if *child & LEAF != 0 {
                    let first = first_packet[(*child & !LEAF) as usize];
                    let two = packet_order[first as usize] & END == 0
                        && packet_order.get(first as usize + 1).is_some_and(|&p| p & END != 0);
                    *child = LEAF | first | if two { PAIR } else { 0 };
                }
            }
        }
        bvh.order = packet_order;
        let bytes = std::mem::size_of_val(&bvh.nodes[..])
            + std::mem::size_of_val(&packets[..])
            + std::mem::size_of_val(&ids[..])
            + std::mem::size_of_val(&bvh.order[..]);
        TriangleBvh {
            bvh,
            packets,
            ids,
            width: Width::of_host(),
            fetch_ahead: bytes > FETCH_AHEAD_BYTES,
        }
    }

    /// This tree with its walks testing boxes `width` lanes at a time (the same hits at any).
    pub fn with_width(self, width: Width) -> TriangleBvh {
        TriangleBvh { width, ..self }
    }

    /// This tree with its streams loading ahead or not, whatever its size (the same hits).
    #[cfg(test)]
    pub(super) fn fetching_ahead(self, fetch_ahead: bool) -> TriangleBvh {
        TriangleBvh { fetch_ahead, ..self }
    }

    /// Whether this tree's streams load ahead: it is larger than the caches, and rays walked
    /// together overlap their misses.
    pub fn fetches_ahead(&self) -> bool {
        self.fetch_ahead
    }

    /// Whether this tree's streams sort a node's children without branches (the CPU has AVX2,
    /// [`SortingRayPre`]): they then outrun single walks even within the caches.
    pub fn streams_sort(&self) -> bool {
        #[cfg(target_arch = "x86_64")]
        if let Width::Eight(avx) = self.width {
            return avx.avx2().is_some();
        }
        false
    }

    /// Bounds of all hittable triangles (empty if there are none).
    pub fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }

    /// Number of (wide) nodes.
    pub fn node_count(&self) -> usize {
        self.bvh.node_count()
    }

    /// Depth of the tree.
    pub fn depth(&self) -> u32 {
        self.bvh.depth()
    }

    /// Number of triangle packets.
    pub fn packet_count(&self) -> usize {
        self.packets.len()
    }

    /// Whether the tree holds no triangle.
    pub fn is_empty(&self) -> bool {
        self.packets.is_empty()
    }

    /// Whether queries walk the tree ([`TriangleBvh::closest_hits`] then pays); with a few
    /// packets they test each one.
    pub fn walks(&self) -> bool {
        self.packets.len() > FEW_PACKETS
    }

    /// Whether `ray` starts outside the triangles' bounds on some axis and moves away from them
    /// along it, so it meets none: the rays leaving a floor, which would otherwise pay the
    /// packets' per-ray set-up and tests. Trees that walk test their root's boxes instead.
    #[inline(always)]
    pub(super) fn heads_away(&self, ray: &Ray) -> bool {
        let Aabb { min, max } = self.bvh.bounds();
        let below = ray.origin.cmplt(min) & ray.dir.cmple(Vec3::ZERO);
        let above = ray.origin.cmpgt(max) & ray.dir.cmpge(Vec3::ZERO);
        (below | above).any()
    }

    /// Closest hit with `0 < t < t_max`.
    #[inline]
    pub fn closest_hit(&self, ray: &Ray, t_max: f32) -> Option<TriangleBvhHit> {
        // Scenes without triangles skip the per-ray setup.
        if self.packets.is_empty() {
            return None;
        }
        if !self.walks() && self.heads_away(ray) {
            return None;
        }
        let tr = TriangleRay::new(ray);
        let mut t = t_max;
        let mut best = None;
        if !self.walks() {
            if super::walkable(ray) {
                for packet in 0..self.packets.len() {
                    self.closest_in_packet(&tr, packet, &mut t, &mut best);
                }
            }
            return best.map(|b| self.hit(t, b));
        }
        self.closest_walk(ray, &tr, t_max)
    }

    /// [`TriangleBvh::closest_hit`] by walking the tree. Out of line: the walk's code, inlined
    /// into every caller, crowded the instruction cache of scenes that never walk (a floor of
    /// two triangles: twice the instruction-cache misses, 5% slower).
    #[inline(never)]
    fn closest_walk(&self, ray: &Ray, tr: &TriangleRay, t_max: f32) -> Option<TriangleBvhHit> {
        match self.width {
            Width::Four => self.closest_walk_tested::<RayPre>(ray, tr, t_max),
            #[cfg(target_arch = "x86_64")]
            Width::Eight(avx) => in_avx(
                avx,
                #[inline(always)]
                || self.closest_walk_tested::<WideRayPre>(ray, tr, t_max),
            ),
        }
    }

    /// [`TriangleBvh::closest_walk`] with boxes tested by `T`.
    #[inline(always)]
    fn closest_walk_tested<T: SlabTest<2>>(&self, ray: &Ray, tr: &TriangleRay, t_max: f32) -> Option<TriangleBvhHit> {
        let (mut t, mut best) = (t_max, None);
        self.bvh.traverse_tested::<T, true, _>(ray, &mut t, |_, first, t_max| {
            self.closest_in_leaf(tr, first, t_max, &mut best);
            false
        });
        best.map(|b| self.hit(t, b))
    }

    /// The closest hit of each ray with `0 < t < t_max`, into `hits` (one per ray). The same
    /// answers as [`TriangleBvh::closest_hit`] ray by ray, found faster on large meshes: the walks
    /// of several rays are interleaved, so their cache misses overlap instead of queueing.
    ///
    /// # Panics
    /// If `hits` and `rays` differ in length.
    pub fn closest_hits(&self, rays: &[Ray], t_max: f32, hits: &mut [Option<TriangleBvhHit>]) {
        self.stream::<true, _, _>(
            rays,
            |_| t_max,
            hits,
            |tri, first, t_max, best: &mut Option<LeafHit>| {
                self.closest_in_leaf(tri, first, t_max, best);
                false
            },
            |t, best| best.map(|b| self.hit(t, b)),
        );
    }

    /// Whether each ray hits any triangle with `0 < t < t_max`, into `occluded` (one per ray):
    /// [`TriangleBvh::any_hit`] for many rays, with their walks interleaved as in
    /// [`TriangleBvh::closest_hits`].
    ///
    /// # Panics
    /// If `occluded` and `rays` differ in length.
    pub fn any_hits(&self, rays: &[Ray], t_max: f32, occluded: &mut [bool]) {
        self.any_hits_within(rays, |_| t_max, occluded);
    }

    /// [`TriangleBvh::any_hits`] with each ray's own `t_max(i)` (shadow rays' segments).
    ///
    /// # Panics
    /// If `occluded` and `rays` differ in length.
    pub fn any_hits_within(&self, rays: &[Ray], t_max: impl Fn(usize) -> f32, occluded: &mut [bool]) {
        self.stream::<false, _, _>(
            rays,
            t_max,
            occluded,
            |tri, first, t_max, hit: &mut bool| {
                *hit = self.any_in_leaf(tri, first, *t_max);
                *hit
            },
            |_, hit| hit,
        );
    }

    /// Walks `rays` [`STREAM`] at a time, interleaved, near child first with `NEAR_FIRST` (else,
    /// for any-hit queries, far child first where the CPU has AVX2 and in slot order where not).
    /// A node's children are sorted without branches where the CPU has AVX2 ([`SortingRayPre`]).
    /// Ray `i` is walked within `t_max(i)`. Each ray's lane keeps a `F` (default at the start);
    /// `leaf(ray, first, t_max, found)` tests
    /// the leaf starting at `first` and returns
    /// whether the ray's answer is settled; `answer(t_max, found)` is what goes to `out`.
    fn stream<const NEAR_FIRST: bool, F: Copy + Default, R: Default>(
        &self,
        rays: &[Ray],
        t_max: impl Fn(usize) -> f32,
        out: &mut [R],
        leaf: impl Fn(&TriangleRay, usize, &mut f32, &mut F) -> bool,
        answer: impl Fn(f32, F) -> R,
    ) {
        /// The interleaved walks, generic over their stack size.
        struct Stream<'a, 'b, const NEAR_FIRST: bool, F, R, M, L, A> {
            bvh: &'a TriangleBvh,
            rays: &'a [Ray],
            t_max: M,
            out: &'b mut [R],
            stacks: &'b mut LaneStacks,
            leaf: L,
            answer: A,
            found: std::marker::PhantomData<F>,
        }
        impl<const NEAR_FIRST: bool, F, R, M, L, A> Stream<'_, '_, NEAR_FIRST, F, R, M, L, A>
        where
            F: Copy + Default,
            M: Fn(usize) -> f32,
            L: Fn(&TriangleRay, usize, &mut f32, &mut F) -> bool,
            A: Fn(f32, F) -> R,
        {
            /// The walks with stacks of `N` entries and boxes tested by `T`.
            #[inline(always)]
            fn walk<const N: usize, T: SlabTest<2>>(self) {
                let slots = (self.out, self.stacks);
                self.bvh
                    .stream_with::<N, NEAR_FIRST, F, R, T>(self.rays, &self.t_max, slots, &self.leaf, &self.answer);
            }
        }
        impl<const NEAR_FIRST: bool, F, R, M, L, A> StackSized for Stream<'_, '_, NEAR_FIRST, F, R, M, L, A>
        where
            F: Copy + Default,
            M: Fn(usize) -> f32,
            L: Fn(&TriangleRay, usize, &mut f32, &mut F) -> bool,
            A: Fn(f32, F) -> R,
        {
            type Output = ();
            fn run<const N: usize>(self) {
                match self.bvh.width {
                    Width::Four => self.walk::<N, RayPre>(),
                    #[cfg(target_arch = "x86_64")]
                    Width::Eight(avx) => match avx.avx2() {
                        Some(avx2) => in_avx2(
                            avx2,
                            #[inline(always)]
                            || self.walk::<N, SortingRayPre>(),
                        ),
                        None => in_avx(
                            avx,
                            #[inline(always)]
                            || self.walk::<N, WideRayPre>(),
                        ),
                    },
                }
            }
        }
        assert_eq!(rays.len(), out.len(), "one answer slot per ray");
        out.iter_mut().for_each(|o| *o = R::default());
        if self.packets.is_empty() {
            return;
        }
        // The thread's lane stacks, or (within another stream on this thread) new ones.
        STREAM_STACKS.with(|cell| {
            let mut lent = cell.try_borrow_mut();
            let mut own;
            let stacks = match lent.as_deref_mut() {
                Ok(stacks) => stacks,
                Err(_) => {
                    own = Box::new([[(0, 0.0); LARGE_STACK]; STREAM]);
                    &mut *own
                }
            };
            self.bvh.with_stack(Stream::<NEAR_FIRST, _, _, _, _, _> {
                bvh: self,
                rays,
                t_max,
                out,
                stacks,
                leaf,
                answer,
                found: std::marker::PhantomData,
            });
        });
    }

    /// [`TriangleBvh::stream`] with traversal stacks of `N` entries and boxes tested by `T`.
    #[inline(always)]
    fn stream_with<const N: usize, const NEAR_FIRST: bool, F: Copy + Default, R, T: SlabTest<2>>(
        &self,
        rays: &[Ray],
        t_max: &impl Fn(usize) -> f32,
        (out, stacks): (&mut [R], &mut LaneStacks),
        leaf: &impl Fn(&TriangleRay, usize, &mut f32, &mut F) -> bool,
        answer: &impl Fn(f32, F) -> R,
    ) {
        /// One ray of the stream, walking with a stack it borrows.
        struct Lane<'s, const N: usize, F, T> {
            index: usize,
            walk: Traversal<N, &'s mut [(u32, f32); N], T>,
            tri: TriangleRay,
            found: F,
        }
        let mut pending = rays.iter().enumerate();
        let mut free = stacks.iter_mut();
        // A plain loop: an iterator adapter's closure, left out of line, would make the wide
        // test's lanes outside the AVX code.
        let mut lanes: Vec<Lane<N, F, T>> = Vec::with_capacity(STREAM);
        while lanes.len() < STREAM {
            let Some((index, ray)) = pending.next() else {
                break;
            };
            // A ray that cannot be walked keeps its default answer and takes no stack.
            if !super::walkable(ray) {
                continue;
            }
            let stack = free.next().expect("a stack for each lane");
            let stack: &mut [(u32, f32); N] = (&mut stack[..N]).try_into().expect("N entries at most LARGE_STACK");
            if let Some(walk) = Traversal::new(ray, t_max(index), stack) {
                lanes.push(Lane {
                    index,
                    walk,
                    tri: TriangleRay::new(ray),
                    found: F::default(),
                });
            }
        }
        while !lanes.is_empty() {
            let mut slot = 0;
            while slot < lanes.len() {
                let lane = &mut lanes[slot];
                let done = match lane.walk.step::<2, false, NEAR_FIRST>(&self.bvh.nodes) {
                    Visit::Node => false,
                    Visit::Leaf(first) => {
                        leaf(&lane.tri, first, &mut lane.walk.t_max, &mut lane.found) || !lane.walk.pop()
                    }
                    Visit::Done => true,
                };
                if !done {
                    if self.fetch_ahead {
                        self.fetch_next(lane.walk.cur);
                    }
                    slot += 1;
                    continue;
                }
                out[lane.index] = answer(lane.walk.t_max, lane.found);
                // The next ray reuses the lane, stack storage included.
                let next = pending.by_ref().find(|&(i, ray)| lane.walk.restart(ray, t_max(i)));
                match next {
                    Some((index, ray)) => {
                        lane.index = index;
                        lane.tri = TriangleRay::new(ray);
                        lane.found = F::default();
                    }
                    None => {
                        lanes.swap_remove(slot);
                    }
                }
            }
        }
    }

    /// Starts loading what a stream's walk visits next, node or leaf packets: the other rays'
    /// steps come first, so the load overlaps them instead of stalling this ray's next step.
    #[inline(always)]
    fn fetch_next(&self, next: u32) {
        if next & LEAF == 0 {
            super::fetch(&self.bvh.nodes, next);
        } else {
            let packet = self
                .packets
                .as_ptr()
                .wrapping_add((next & !(LEAF | PAIR)) as usize)
                .cast::<u8>();
            let lines = if next & PAIR != 0 {
                PAIR_FETCH_LINES
            } else {
                FETCH_LINES
            };
            for line in 0..lines {
                crate::accel::lanes::prefetch(packet.wrapping_add(64 * line));
            }
        }
    }

    /// The leaf `leaf` (its first packet's position, flagged [`PAIR`] for two) as a pair of
    /// packets to test in eight lanes, where the CPU has AVX, with the proof.
    #[cfg(target_arch = "x86_64")]
    #[inline(always)]
    fn leaf_pair(&self, leaf: usize) -> Option<(Avx, PacketPair<'_>)> {
        let Width::Eight(avx) = self.width else {
            return None;
        };
        if leaf as u32 & PAIR == 0 {
            return None;
        }
        let first = leaf & !(PAIR as usize);
        let pair: &[TrianglePacket; 2] = self.packets.get(first..first + 2)?.try_into().ok()?;
        Some((avx, PacketPair(pair)))
    }

    /// Tests the packets of leaf `leaf` (a pair in eight lanes where the CPU has AVX) for hits
    /// closer than `t_max`, shrinking `t_max` and recording the closest in `best`.
    #[inline(always)]
    fn closest_in_leaf(&self, tr: &TriangleRay, leaf: usize, t_max: &mut f32, best: &mut Option<LeafHit>) {
        let first = leaf & !(PAIR as usize);
        #[cfg(target_arch = "x86_64")]
        if let Some((avx, pair)) = self.leaf_pair(leaf) {
            if let Some((lane, h)) = in_avx(
                avx,
                #[inline(always)]
                || pair.closest_hit(tr, *t_max),
            ) {
                self.record(first + lane / LANES, lane % LANES, h, t_max, best);
            }
            return;
        }
        let mut i = first;
        loop {
            self.closest_in_packet(tr, i, t_max, best);
            if self.bvh.order[i] & END != 0 {
                return;
            }
            i += 1;
        }
    }

    /// Tests packet `i` for hits closer than `t_max`, shrinking `t_max` and recording the
    /// closest in `best`.
    #[inline(always)]
    fn closest_in_packet(&self, tr: &TriangleRay, i: usize, t_max: &mut f32, best: &mut Option<LeafHit>) {
        if let Some((lane, h)) = self.packets[i].closest_hit(tr, *t_max) {
            self.record(i, lane, h, t_max, best);
        }
    }

    /// Records the hit `h` in `lane` of packet `i` as the closest so far.
    #[inline(always)]
    fn record(&self, i: usize, lane: usize, h: TriangleHit, t_max: &mut f32, best: &mut Option<LeafHit>) {
        // The hit's id is read when the walk ends; on a large mesh it is a cache miss.
        crate::accel::lanes::prefetch(self.ids.as_ptr().wrapping_add(i));
        *t_max = h.t;
        *best = Some(LeafHit {
            packet: i,
            lane,
            u: h.u,
            v: h.v,
        });
    }

    /// Calls `visit(hit)` for the triangles of packet `i` hit with `0 < t < t_max`, until it
    /// returns `true`; returns whether it did.
    #[inline(always)]
    fn each_in_packet(
        &self,
        tr: &TriangleRay,
        i: usize,
        t_max: f32,
        visit: &mut impl FnMut(TriangleBvhHit) -> bool,
    ) -> bool {
        let ids = &self.ids[i];
        self.packets[i].each_hit(tr, t_max, |lane, h| visit(public_hit(ids[lane], h)))
    }

    /// [`TriangleBvh::each_in_packet`] for leaf `leaf` (a pair in eight lanes where the CPU has
    /// AVX).
    #[inline(always)]
    fn each_in_leaf(
        &self,
        tr: &TriangleRay,
        leaf: usize,
        t_max: f32,
        visit: &mut impl FnMut(TriangleBvhHit) -> bool,
    ) -> bool {
        let first = leaf & !(PAIR as usize);
        #[cfg(target_arch = "x86_64")]
        if let Some((avx, pair)) = self.leaf_pair(leaf) {
            return in_avx(
                avx,
                #[inline(always)]
                || {
                    pair.each_hit(tr, t_max, |lane, h| {
                        visit(public_hit(self.ids[first + lane / LANES][lane % LANES], h))
                    })
                },
            );
        }
        let mut i = first;
        loop {
            if self.each_in_packet(tr, i, t_max, visit) {
                return true;
            }
            if self.bvh.order[i] & END != 0 {
                return false;
            }
            i += 1;
        }
    }

    /// Whether any triangle of leaf `leaf` is hit with `0 < t < t_max`:
    /// [`TriangleBvh::each_in_leaf`] with a visit that stops at once, without working out the
    /// hit or reading its id.
    #[inline(always)]
    fn any_in_leaf(&self, tr: &TriangleRay, leaf: usize, t_max: f32) -> bool {
        let first = leaf & !(PAIR as usize);
        #[cfg(target_arch = "x86_64")]
        if let Some((avx, pair)) = self.leaf_pair(leaf) {
            return in_avx(
                avx,
                #[inline(always)]
                || pair.any_hit(tr, t_max),
            );
        }
        let mut i = first;
        loop {
            if self.packets[i].any_hit(tr, t_max) {
                return true;
            }
            if self.bvh.order[i] & END != 0 {
                return false;
            }
            i += 1;
        }
    }

    /// The public hit record of `best`, found at distance `t`.
    fn hit(&self, t: f32, best: LeafHit) -> TriangleBvhHit {
        TriangleBvhHit {
            t,
            prim: self.ids[best.packet][best.lane],
            u: best.u,
            v: best.v,
        }
    }

    /// [`TriangleBvh::closest_hit`] of each of `rays` with `t_max` ∞, into `out`: for a tree
    /// that does not walk, a ray a lane and the triangles one after another, to the same bits
    /// (in the same order, each hit kept only when nearer); ray by ray for one that walks.
    ///
    /// # Panics
    /// If `rays` and `out` differ in length.
    pub fn closest_each(&self, rays: &[Ray], out: &mut [Option<TriangleBvhHit>]) {
        assert_eq!(rays.len(), out.len(), "an answer per ray");
        if self.walks() {
            for (ray, out) in rays.iter().zip(out) {
                *out = self.closest_hit(ray, f32::INFINITY);
            }
            return;
        }
        match self.width {
            Width::Four => self.closest_each_in::<glam::Vec4>(rays, out),
            #[cfg(target_arch = "x86_64")]
            Width::Eight(avx) => in_avx(
                avx,
                #[inline(always)]
                || self.closest_each_in::<F32x8>(rays, out),
            ),
        }
    }

    /// [`TriangleBvh::closest_each`] at the width of `L`.
    #[inline(always)]
    fn closest_each_in<L: Lanes>(&self, rays: &[Ray], out: &mut [Option<TriangleBvhHit>]) {
        const MAX: usize = 2 * LANES;
        // The triangles in the packets' order, lane by lane.
        let mut triangles = [(0usize, 0usize, [Vec3::ZERO; 3]); LANES * FEW_PACKETS];
        let mut count = 0;
        for (packet, ids) in self.ids.iter().enumerate() {
            for (lane, _) in ids.iter().enumerate().filter(|&(_, &id)| id != NO_TRIANGLE) {
                triangles[count] = (packet, lane, self.packets[packet].triangle(lane).vertices());
                count += 1;
            }
        }
        let triangles = &triangles[..count];
        for (rays, out) in rays.chunks(L::N).zip(out.chunks_mut(L::N)) {
            // Lanes past the rays, and rays that meet no triangle (as `closest_hit` sees them
            // before any test), keep a `t_max` of zero: no `t` is below it.
            let (lanes, live) = RayLanes::<L>::new(rays, &self.bvh.bounds());
            if live == 0 {
                out.fill(None);
                continue;
            }
            let mut t_max = [0.0f32; MAX];
            for (lane, t_max) in t_max.iter_mut().enumerate() {
                if live & (1 << lane) != 0 {
                    *t_max = f32::INFINITY;
                }
            }
            let mut best = [None::<LeafHit>; MAX];
            for &(packet, lane, vertices) in triangles {
                let (hit, edge, [t, wb, wc, det]) = lanes.hits(&vertices, L::from_slice(&t_max));
                let (hit, edge) = (hit & live, edge & live);
                if hit | edge == 0 {
                    continue;
                }
                let mut values = [[0.0f32; MAX]; 4];
                for (lanes, row) in [t, wb, wc, det].into_iter().zip(&mut values) {
                    lanes.write_to(row);
                }
                let [t, wb, wc, det] = values;
                let mut rest = hit | edge;
                while rest != 0 {
                    let ray = rest.trailing_zeros() as usize;
                    rest &= rest - 1;
                    let found = if edge & (1 << ray) != 0 {
                        // An edge function exactly zero: the scalar test settles it, in `f64`.
                        let sheared = TriangleRay::new(&rays[ray]);
                        self.packets[packet].triangle(lane).intersect_pre(&sheared, t_max[ray])
                    } else {
                        let inv = 1.0 / det[ray];
                        Some(TriangleHit {
                            t: t[ray],
                            u: wb[ray] * inv,
                            v: wc[ray] * inv,
                        })
                    };
                    if let Some(h) = found {
                        t_max[ray] = h.t;
                        best[ray] = Some(LeafHit {
                            packet,
                            lane,
                            u: h.u,
                            v: h.v,
                        });
                    }
                }
            }
            for ((out, best), &t) in out.iter_mut().zip(best).zip(&t_max) {
                *out = best.map(|b| self.hit(t, b));
            }
        }
    }

    /// Whether any triangle is hit with `0 < t < t_max`.
    #[inline]
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        self.each_hit(ray, t_max, |_| true)
    }

    /// Calls `visit(hit)` for triangles hit with `0 < t < t_max`, until it returns `true`;
    /// returns whether it did. Visits each triangle at most once; order unspecified.
    #[inline]
    pub fn each_hit(&self, ray: &Ray, t_max: f32, mut visit: impl FnMut(TriangleBvhHit) -> bool) -> bool {
        if self.packets.is_empty() || (!self.walks() && self.heads_away(ray)) {
            return false;
        }
        let tr = TriangleRay::new(ray);
        if !self.walks() {
            return super::walkable(ray)
                && (0..self.packets.len()).any(|i| self.each_in_packet(&tr, i, t_max, &mut visit));
        }
        self.each_walk(ray, &tr, t_max, &mut visit)
    }

    /// [`TriangleBvh::each_hit`] by walking the tree, out of line as
    /// [`TriangleBvh::closest_walk`] is.
    #[inline(never)]
    fn each_walk(
        &self,
        ray: &Ray,
        tr: &TriangleRay,
        t_max: f32,
        visit: &mut impl FnMut(TriangleBvhHit) -> bool,
    ) -> bool {
        match self.width {
            Width::Four => self.each_walk_tested::<RayPre>(ray, tr, t_max, visit),
            #[cfg(target_arch = "x86_64")]
            Width::Eight(avx) => in_avx(
                avx,
                #[inline(always)]
                || self.each_walk_tested::<WideRayPre>(ray, tr, t_max, visit),
            ),
        }
    }

    /// [`TriangleBvh::each_walk`] with boxes tested by `T`.
    #[inline(always)]
    fn each_walk_tested<T: SlabTest<2>>(
        &self,
        ray: &Ray,
        tr: &TriangleRay,
        t_max: f32,
        visit: &mut impl FnMut(TriangleBvhHit) -> bool,
    ) -> bool {
        let mut t = t_max;
        self.bvh.traverse_tested::<T, false, _>(ray, &mut t, |_, first, t_max| {
            self.each_in_leaf(tr, first, *t_max, visit)
        })
    }

    /// Calls `visit(triangle)` for triangles in leaves whose boxes overlap `query`, until it
    /// returns `true`; returns whether it did. Visits each triangle at most once.
    pub fn any_overlap(&self, query: &Aabb, mut visit: impl FnMut(u32) -> bool) -> bool {
        self.bvh.any_overlap(query, |packet| {
            self.ids[packet as usize]
                .iter()
                .take_while(|&&id| id != NO_TRIANGLE)
                .any(|&id| visit(id))
        })
    }
}

/// The public record of a hit `h` on triangle `prim`.
#[inline(always)]
fn public_hit(prim: u32, h: TriangleHit) -> TriangleBvhHit {
    TriangleBvhHit {
        t: h.t,
        prim,
        u: h.u,
        v: h.v,
    }
}
