//! Bounding volume hierarchy over arbitrary primitives, given by their bounds.
//!
//! Built as a binned-SAH binary tree and collapsed into wide nodes whose child boxes are
//! stored as structure-of-arrays, so one node visit tests its boxes with SSE arithmetic: four
//! children a node for a scene's shapes, eight for a triangle mesh's [`TriangleBvh`], where
//! fewer levels mean fewer dependent cache misses a ray, and where the CPU has AVX the eight
//! are tested in one register ([`SlabTest`]), to the same bits.
//! Traversal is near-first with a fixed-size stack; primitives are handed to a caller's
//! closure (generic, so it inlines).

mod build;
#[cfg(test)]
mod tests;
mod triangles;

use std::borrow::BorrowMut;
use std::cell::RefCell;

use glam::Vec4;

use super::lanes::Lanes;
#[cfg(target_arch = "x86_64")]
use super::lanes::{F32x8, M32x8};
use crate::math::{Aabb, Ray, Vec3};
use crate::progress::{NoProgress, Progress};

pub use triangles::{TriangleBvh, TriangleBvhHit};

/// Child reference flag: the child is a leaf starting at position `ref & !LEAF` of the leaf order.
const LEAF: u32 = 1 << 31;
/// Child reference flag of a [`TriangleBvh`]'s leaf of two packets, which its walks test as one
/// of eight lanes where the CPU has AVX: known from the reference, the test need not wait on the
/// leaf order's end marks. Leaf positions stay below it; walks hand it on with the position.
const PAIR: u32 = 1 << 30;
/// Leaf-order flag: this primitive is the last of its leaf.
const END: u32 = 1 << 31;
/// Ize's robust slab-test factor `1 + 2γ(3)`: widens exits so rounding cannot lose a box the
/// ray touches (flat boxes of axis-aligned triangles included).
/// Applied to the inverse direction, so it also covers that product's rounding.
const ROBUST: f32 = 1.0 + 4.0 * f32::EPSILON;
/// Children per node, at most.
const MAX_WIDTH: usize = 8;

/// Leaf entries (primitives, or a triangle BVH's packets of four) at most this many are tested
/// leaf by leaf from the root's boxes, without the walk's stack: a floor of two triangles, two
/// balls. The glass ball over a floor renders 7% faster (BENCHMARKS.md); brute force at 8
/// entries cost the Cornell box's seven shapes 6% more instructions.
const FEW: usize = 2;
/// Stack sizes of the traversal variants: a query uses the smallest that the tree's depth
/// allows, because a stack the query owns (ray streams, queries nested in another's callback)
/// is cleared when made, and clearing a larger one than needed cost 5–10% of an incoherent query
/// (the `bvh` bench, 37k and 1M triangles). Single queries borrow the thread's scratch stack,
/// which needs no clearing. Each level pushes at most one entry fewer than a node's width: in
/// four-wide trees 8 entries hold two levels (scenes of a few shapes), 32 ten, 64 twenty-one;
/// in eight-wide ones, with room for a node's eight entries written at once, 64 hold eight
/// levels (millions of triangles).
const TINY_STACK: usize = 8;
const SMALL_STACK: usize = 32;
const MEDIUM_STACK: usize = 64;
const LARGE_STACK: usize = 512;

/// A wide node of `R` rows of four children: child boxes as `[axis][min, max]` rows of lanes,
/// then child references (inner node index, or `LEAF | first` for leaves). A whole number of
/// cache lines.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(64))]
pub(crate) struct Node<const R: usize> {
    bounds: [[[Vec4; R]; 2]; 3],
    children: [[u32; 4]; R],
}

impl<const R: usize> Node<R> {
    /// Children per node.
    const WIDTH: usize = 4 * R;
    /// The low bits of a child's sort key, which hold its slot ([`sorted_keys`]).
    const SLOT_BITS: u32 = Self::WIDTH as u32 - 1;

    /// Unused slots have inverted infinite boxes, which every slab test rejects.
    const EMPTY: Node<R> = Node {
        bounds: [[[Vec4::splat(f32::INFINITY); R], [Vec4::splat(f32::NEG_INFINITY); R]]; 3],
        children: [[0; 4]; R],
    };

    fn set_child(&mut self, slot: usize, min: Vec3, max: Vec3, child: u32) {
        for axis in 0..3 {
            self.bounds[axis][0][slot / 4][slot % 4] = min[axis];
            self.bounds[axis][1][slot / 4][slot % 4] = max[axis];
        }
        self.children[slot / 4][slot % 4] = child;
    }

    /// Child reference of `slot`.
    #[inline(always)]
    fn child(&self, slot: usize) -> u32 {
        self.children[(slot / 4) % R][slot % 4]
    }

    /// Box of child `slot` (inverted for unused slots).
    #[cfg(test)]
    fn child_box(&self, slot: usize) -> (Vec3, Vec3) {
        let get = |side: usize| Vec3::from_array([0, 1, 2].map(|axis| self.bounds[axis][side][slot / 4][slot % 4]));
        (get(0), get(1))
    }
}

/// Per-ray constants for the slab tests.
struct RayPre {
    origin: [Vec4; 3],
    inv_dir: [Vec4; 3],
    /// `inv_dir` widened by [`ROBUST`], for exit distances.
    inv_dir_far: [Vec4; 3],
    /// Index (0 = min, 1 = max) of the plane entered first on each axis.
    near: [usize; 3],
}

impl RayPre {
    #[inline(always)]
    fn new(ray: &Ray) -> RayPre {
        // Zero (or denormal) components become the smallest normal float: the inverse stays
        // finite, so `(plane - origin) * inv` is never 0 · ∞ = NaN.
        let safe = |d: f32| {
            if d.abs() < f32::MIN_POSITIVE {
                f32::MIN_POSITIVE.copysign(d)
            } else {
                d
            }
        };
        let inv = [ray.dir.x, ray.dir.y, ray.dir.z].map(|d| 1.0 / safe(d));
        RayPre {
            origin: [ray.origin.x, ray.origin.y, ray.origin.z].map(Vec4::splat),
            inv_dir: inv.map(Vec4::splat),
            inv_dir_far: inv.map(|i| Vec4::splat(i * ROBUST)),
            near: inv.map(|i| usize::from(i < 0.0)),
        }
    }

    /// Which of the node's boxes the segment `[0, t_max]` meets (bit per slot), and the entry
    /// distances.
    #[inline(always)]
    fn hit<const R: usize>(&self, node: &Node<R>, t_max: f32) -> (u32, [Vec4; R]) {
        let mut mask = 0;
        let mut t_nears = [Vec4::ZERO; R];
        for (h, t_near_out) in t_nears.iter_mut().enumerate() {
            let (bits, t_near) = self.row(node, h, t_max);
            mask |= bits << (4 * h);
            *t_near_out = t_near;
        }
        (mask, t_nears)
    }

    /// [`RayPre::hit`]'s mask for a node of four children or fewer.
    #[inline(always)]
    fn hit_first_row<const R: usize>(&self, node: &Node<R>, t_max: f32) -> u32 {
        self.row(node, 0, t_max).0
    }

    /// The slab tests of row `h` of a node's boxes: the lanes met and their entry distances.
    /// Reductions are balanced trees: traversal is bound by this dependency chain.
    #[inline(always)]
    fn row<const R: usize>(&self, node: &Node<R>, h: usize, t_max: f32) -> (u32, Vec4) {
        let ray = (&self.origin, &self.inv_dir, &self.inv_dir_far, self.near);
        slabs(|axis, side| node.bounds[axis][side][h], ray, t_max)
    }
}

/// The slab tests of one ray against boxes in lanes, `bound(axis, side)` their planes (side 0
/// the minimum): the lanes the segment `[0, t_max]` meets and their entry distances. `ray` is
/// the splatted origin, inverse direction, the same widened by [`ROBUST`] and which side each
/// axis enters by. Reductions are balanced trees: traversal is bound by this dependency chain.
#[inline(always)]
fn slabs<L: Lanes>(
    bound: impl Fn(usize, usize) -> L,
    ray: (&[L; 3], &[L; 3], &[L; 3], [usize; 3]),
    t_max: f32,
) -> (u32, L) {
    let (hit, t_near) = slab_lanes(bound, ray, t_max);
    (L::bitmask(hit), t_near)
}

/// [`slabs`] with the lanes met as a mask.
#[inline(always)]
fn slab_lanes<L: Lanes>(
    bound: impl Fn(usize, usize) -> L,
    (origin, inv_dir, inv_dir_far, [nx, ny, nz]): (&[L; 3], &[L; 3], &[L; 3], [usize; 3]),
    t_max: f32,
) -> (L::Mask, L) {
    let near = |axis: usize, side: usize| (bound(axis, side & 1) - origin[axis]) * inv_dir[axis];
    let far = |axis: usize, side: usize| (bound(axis, side & 1) - origin[axis]) * inv_dir_far[axis];
    let t_near = near(0, nx).max(near(1, ny)).max(near(2, nz).max(L::splat(0.0)));
    let t_far = far(0, nx ^ 1)
        .min(far(1, ny ^ 1))
        .min(far(2, nz ^ 1).min(L::splat(t_max)));
    (t_near.le(t_far), t_near)
}

/// A ray's slab tests against a node's child boxes, at some lane width: which children the
/// segment `[0, t_max]` meets (bit per slot) and their entry distances, by slot.
pub(crate) trait SlabTest<const R: usize> {
    fn new(ray: &Ray) -> Self;
    fn hit(&self, node: &Node<R>, t_max: f32) -> (u32, [f32; MAX_WIDTH]);

    /// Whether [`SlabTest::hit_sorted`] is faster than [`SlabTest::hit`] and sorting after.
    const SORTS: bool = false;

    /// The entries (child, entry distance) of the children met into the first places of `out`,
    /// the one to visit first last: farthest first with `NEAR_LAST`, else nearest first;
    /// returns how many. Ordered by [`sorted_keys`], the distances with their low bits (which
    /// hold the slot in the key) cleared.
    #[inline(always)]
    fn hit_sorted<const NEAR_LAST: bool>(
        &self,
        node: &Node<R>,
        t_max: f32,
        out: &mut [(u32, f32); MAX_WIDTH],
    ) -> usize {
        let (mask, t_near) = self.hit(node, t_max);
        let (mut keys, count) = sorted_keys::<R>(mask, &t_near);
        if !NEAR_LAST {
            keys[..count].reverse();
        }
        for (entry, &key) in out.iter_mut().zip(&keys[..count]) {
            *entry = key_entry(node, key);
        }
        count
    }
}

/// Sort keys of the children in `mask`, farthest first, and how many: each the bits of the
/// child's entry distance (non-negative floats order as their bits) with its slot in the low
/// bits ([`Node::SLOT_BITS`]), so no two are equal and a tie goes to the lower slot.
#[inline(always)]
fn sorted_keys<const R: usize>(mask: u32, t_near: &[f32; MAX_WIDTH]) -> ([u32; MAX_WIDTH], usize) {
    let slot_bits = Node::<R>::SLOT_BITS;
    let mut keys = [0u32; MAX_WIDTH];
    let mut count = 0;
    let mut m = mask;
    while m != 0 {
        let slot = m.trailing_zeros();
        m &= m - 1;
        let key = (t_near[slot as usize % MAX_WIDTH].to_bits() & !slot_bits) | slot;
        let mut j = count;
        while j > 0 && keys[j - 1] < key {
            keys[j] = keys[j - 1];
            j -= 1;
        }
        keys[j % MAX_WIDTH] = key;
        count += 1;
    }
    (keys, count)
}

/// The stack entry (child, rounded entry distance) of sort key `key`.
#[inline(always)]
fn key_entry<const R: usize>(node: &Node<R>, key: u32) -> (u32, f32) {
    (
        node.child((key & Node::<R>::SLOT_BITS) as usize),
        f32::from_bits(key & !Node::<R>::SLOT_BITS),
    )
}

impl<const R: usize> SlabTest<R> for RayPre {
    #[inline(always)]
    fn new(ray: &Ray) -> RayPre {
        RayPre::new(ray)
    }

    #[inline(always)]
    fn hit(&self, node: &Node<R>, t_max: f32) -> (u32, [f32; MAX_WIDTH]) {
        let (mask, t_near) = RayPre::hit(self, node, t_max);
        (mask, std::array::from_fn(|i| t_near[(i / 4) % R][i % 4]))
    }
}

/// [`RayPre`]'s tests of an eight-wide node in one AVX register per operand: the same
/// operations in the same order on each lane, so the same masks and distances to the bit.
/// Made only by a tree that holds the proof the CPU has AVX (`Width::Eight`), and used inside
/// [`in_avx`](super::lanes::in_avx) but for the cold nested walk ([`Bvh::traverse_nested`]).
#[cfg(target_arch = "x86_64")]
pub(crate) struct WideRayPre {
    origin: [F32x8; 3],
    inv_dir: [F32x8; 3],
    inv_dir_far: [F32x8; 3],
    near: [usize; 3],
}

#[cfg(target_arch = "x86_64")]
impl SlabTest<2> for WideRayPre {
    #[inline(always)]
    fn new(ray: &Ray) -> WideRayPre {
        let pre = RayPre::new(ray);
        let splat = |v: [Vec4; 3]| v.map(|lanes| F32x8::splat(lanes.x));
        WideRayPre {
            origin: splat(pre.origin),
            inv_dir: splat(pre.inv_dir),
            inv_dir_far: splat(pre.inv_dir_far),
            near: pre.near,
        }
    }

    #[inline(always)]
    fn hit(&self, node: &Node<2>, t_max: f32) -> (u32, [f32; MAX_WIDTH]) {
        let (hit, t_near) = self.lanes(node, t_max);
        (F32x8::bitmask(hit), t_near.to_array())
    }
}

#[cfg(target_arch = "x86_64")]
impl WideRayPre {
    /// The lanes of the boxes met, and the entry distances.
    #[inline(always)]
    fn lanes(&self, node: &Node<2>, t_max: f32) -> (M32x8, F32x8) {
        let ray = (&self.origin, &self.inv_dir, &self.inv_dir_far, self.near);
        slab_lanes(|axis, side| F32x8::from_pair(&node.bounds[axis][side]), ray, t_max)
    }
}

/// [`WideRayPre`] with its hits sorted by AVX2's integer operations, without a branch: the
/// same entries as [`sorted_keys`] gives, to the bit. Made only by a tree that holds the proof
/// the CPU has AVX2, and used inside [`in_avx2`](super::lanes::in_avx2).
#[cfg(target_arch = "x86_64")]
pub(crate) struct SortingRayPre(WideRayPre);

#[cfg(target_arch = "x86_64")]
impl SlabTest<2> for SortingRayPre {
    #[inline(always)]
    fn new(ray: &Ray) -> SortingRayPre {
        SortingRayPre(WideRayPre::new(ray))
    }

    #[inline(always)]
    fn hit(&self, node: &Node<2>, t_max: f32) -> (u32, [f32; MAX_WIDTH]) {
        self.0.hit(node, t_max)
    }

    const SORTS: bool = true;

    #[inline(always)]
    fn hit_sorted<const NEAR_LAST: bool>(
        &self,
        node: &Node<2>,
        t_max: f32,
        out: &mut [(u32, f32); MAX_WIDTH],
    ) -> usize {
        let (hit, t_near) = self.0.lanes(node, t_max);
        super::lanes::sorted_entries::<NEAR_LAST>(
            t_near,
            hit,
            node.children.as_flattened().try_into().expect("two rows of four"),
            out,
        )
    }
}

/// A bounding volume hierarchy over primitives given by bounding boxes.
///
/// Primitives are referred to by their index in the slice passed to [`Bvh::build`].
/// Primitives with non-finite or empty bounds are left out and never reported. Nodes have `R`
/// rows of four children.
#[derive(Clone, Debug)]
pub struct Bvh<const R: usize = 1> {
    nodes: Vec<Node<R>>,
    /// Primitive ids in leaf order; `END` marks the last of each leaf.
    order: Vec<u32>,
    bounds: Aabb,
    /// Tree depth, which bounds the traversal stack.
    depth: u32,
}

impl Bvh {
    /// Builds over primitive bounds with binned SAH. Deterministic: the same input gives the
    /// same tree whatever the thread count.
    ///
    /// # Panics
    /// If there are 2^30 or more primitives.
    pub fn build(prim_bounds: &[Aabb]) -> Bvh {
        Bvh::build_reporting(prim_bounds, &NoProgress)
    }

    /// [`Bvh::build`], advancing `progress` by one unit per primitive placed in the tree (the
    /// caller starts and finishes the phase).
    pub fn build_reporting(prim_bounds: &[Aabb], progress: &dyn Progress) -> Bvh {
        Bvh::build_priced(prim_bounds, build::LeafCost::SINGLE, progress)
    }
}

impl<const R: usize> Bvh<R> {
    /// [`Bvh::build_reporting`] with leaves priced by `leaf`.
    fn build_priced(prim_bounds: &[Aabb], leaf: build::LeafCost, progress: &dyn Progress) -> Bvh<R> {
        let c = build::collapse(build::build_bvh2(prim_bounds, leaf, progress));
        Bvh {
            nodes: c.nodes,
            order: c.order,
            bounds: c.bounds,
            depth: c.depth,
        }
    }

    /// Bounds of all hittable primitives (empty if there are none).
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// Number of (wide) nodes.
    pub fn node_count(&self) -> usize {
        self.nodes.len()
    }

    /// Depth of the tree (0 when empty, 1 for a single node).
    pub fn depth(&self) -> u32 {
        self.depth
    }

    /// Hittable primitive ids in leaf order: primitives stored in this order are visited with
    /// good locality.
    pub fn leaf_order(&self) -> impl ExactSizeIterator<Item = u32> + '_ {
        self.order.iter().map(|&p| p & !END)
    }

    /// Whether a traversal stack of `entries` suffices: each level pushes at most one entry
    /// fewer than a node's width, and the walks of eight-wide trees may sort
    /// ([`SortingRayPre`]), writing a node's eight entries at once above the deepest.
    #[inline(always)]
    fn stack_fits(&self, entries: usize) -> bool {
        let sorted_room = if Node::<R>::WIDTH == MAX_WIDTH { MAX_WIDTH } else { 0 };
        (Node::<R>::WIDTH - 1) * self.depth as usize + sorted_room <= entries
    }

    /// Closest hit. `intersect(prim, t_max)` tests primitive `prim` (an index into the bounds
    /// given to [`Bvh::build`]) and returns `Some(t)` if it is hit at `t < t_max` (the closure
    /// keeps its own hit record). Returns the closest `(t, prim)`.
    #[inline]
    pub fn closest_hit<F: FnMut(u32, f32) -> Option<f32>>(
        &self,
        ray: &Ray,
        t_max: f32,
        mut intersect: F,
    ) -> Option<(f32, u32)> {
        let mut best = None;
        let mut t_max = t_max;
        self.traverse_any_stack::<true, _>(ray, &mut t_max, |order, first, t_max| {
            let mut i = first;
            loop {
                let p = order[i];
                let prim = p & !END;
                if let Some(t) = intersect(prim, *t_max) {
                    if t < *t_max {
                        *t_max = t;
                        best = Some(prim);
                    }
                }
                if p & END != 0 {
                    return false;
                }
                i += 1;
            }
        });
        best.map(|prim| (t_max, prim))
    }

    /// Any-hit / filtered shadow query: calls `visit(prim, t_max)` for primitives whose leaf
    /// bounds the segment `[0, t_max]` meets; stops and returns `true` as soon as `visit`
    /// returns `true` (an opaque blocker). Visits each primitive at most once; order unspecified.
    #[inline]
    pub fn any_hit<F: FnMut(u32, f32) -> bool>(&self, ray: &Ray, t_max: f32, mut visit: F) -> bool {
        let mut t_max = t_max;
        self.traverse_any_stack::<false, _>(ray, &mut t_max, |order, first, t_max| {
            let mut i = first;
            loop {
                let p = order[i];
                if visit(p & !END, *t_max) {
                    return true;
                }
                if p & END != 0 {
                    return false;
                }
                i += 1;
            }
        })
    }

    /// Calls `visit(prim)` for primitives whose leaf boxes overlap `query`, until `visit` returns
    /// true; returns whether it did. Visits each primitive at most once; order unspecified.
    pub fn any_overlap<F: FnMut(u32) -> bool>(&self, query: &Aabb, mut visit: F) -> bool {
        if self.nodes.is_empty() || query.is_empty() {
            return false;
        }
        let (qmin, qmax) = (query.min.to_array(), query.max.to_array());
        // Each level leaves at most `WIDTH - 1` siblings waiting, and the last pushes `WIDTH`.
        // A stack that deep and no more: clearing a fixed 8 KiB one per query was 0.4% of the
        // original's ring (135k queries around gather points).
        let need = (Node::<R>::WIDTH - 1) * self.depth as usize + 1;
        let mut small = [0u32; 1 + 3 * 21];
        let mut large = Vec::new();
        let stack: &mut [u32] = if need <= small.len() {
            &mut small
        } else {
            large.resize(need, 0);
            &mut large
        };
        let mut sp = 1usize;
        stack[0] = 0;
        while sp > 0 {
            sp -= 1;
            let current = stack[sp];
            if current & LEAF != 0 {
                let mut i = (current & !(LEAF | PAIR)) as usize;
                loop {
                    let p = self.order[i];
                    if visit(p & !END) {
                        return true;
                    }
                    if p & END != 0 {
                        break;
                    }
                    i += 1;
                }
                continue;
            }
            let node = &self.nodes[current as usize];
            for slot in 0..Node::<R>::WIDTH {
                let overlaps = (0..3).all(|axis| {
                    let lo = node.bounds[axis][0][slot / 4][slot % 4];
                    let hi = node.bounds[axis][1][slot / 4][slot % 4];
                    lo <= qmax[axis] && hi >= qmin[axis]
                });
                if overlaps && sp < stack.len() {
                    stack[sp] = node.child(slot);
                    sp += 1;
                }
            }
        }
        false
    }

    /// Runs `work` with the smallest traversal stack the tree's depth allows.
    #[inline(always)]
    fn with_stack<W: StackSized>(&self, work: W) -> W::Output {
        if self.stack_fits(TINY_STACK) {
            work.run::<TINY_STACK>()
        } else if self.stack_fits(SMALL_STACK) {
            work.run::<SMALL_STACK>()
        } else if self.stack_fits(MEDIUM_STACK) {
            work.run::<MEDIUM_STACK>()
        } else {
            work.run::<LARGE_STACK>()
        }
    }

    /// [`Bvh::traverse`] with the stack size the tree needs, boxes tested by [`RayPre`].
    #[inline(always)]
    fn traverse_any_stack<const NEAR_FIRST: bool, F: FnMut(&[u32], usize, &mut f32) -> bool>(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        leaf: F,
    ) -> bool {
        self.traverse_tested::<RayPre, NEAR_FIRST, F>(ray, t_max, leaf)
    }

    /// [`Bvh::traverse_any_stack`] with boxes tested by `T`.
    #[inline(always)]
    fn traverse_tested<T: SlabTest<R>, const NEAR_FIRST: bool, F: FnMut(&[u32], usize, &mut f32) -> bool>(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        mut leaf: F,
    ) -> bool {
        /// One ray's traversal, generic over its stack size.
        struct Walk<'a, const R: usize, const NEAR_FIRST: bool, T, F> {
            bvh: &'a Bvh<R>,
            ray: &'a Ray,
            t_max: &'a mut f32,
            leaf: F,
            test: std::marker::PhantomData<T>,
        }
        impl<const R: usize, const NEAR_FIRST: bool, T: SlabTest<R>, F: FnMut(&[u32], usize, &mut f32) -> bool>
            StackSized for Walk<'_, R, NEAR_FIRST, T, F>
        {
            type Output = bool;
            #[inline(always)]
            fn run<const N: usize>(self) -> bool {
                self.bvh.traverse::<N, NEAR_FIRST, T>(self.ray, self.t_max, self.leaf)
            }
        }
        if self.nodes.is_empty() {
            return false;
        }
        if self.order.len() <= FEW && walkable(ray) {
            // The root's leaves the ray meets, tested in turn: the walk's stack costs more.
            let root = &self.nodes[0];
            // At most `FEW` children: the first row holds them.
            let mask = RayPre::new(ray).hit_first_row(root, *t_max);
            let slots = (0..4).filter(|&slot| mask & (1 << slot) != 0);
            if slots.clone().all(|slot| root.child(slot) & LEAF != 0) {
                return slots
                    .into_iter()
                    .any(|slot| leaf(&self.order, (root.child(slot) & !LEAF) as usize, t_max));
            }
        }
        self.with_stack(Walk::<R, NEAR_FIRST, T, F> {
            bvh: self,
            ray,
            t_max,
            leaf,
            test: std::marker::PhantomData::<T>,
        })
    }

    /// Traversal, near child first with `NEAR_FIRST` (else in slot order, for queries whose
    /// answer does not depend on the order). `leaf(order, first, t_max)` handles the leaf
    /// starting at `first` and may shrink `t_max`; returning `true` ends the traversal (and
    /// this returns `true`).
    #[inline(always)]
    fn traverse<const N: usize, const NEAR_FIRST: bool, T: SlabTest<R>>(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        mut leaf: impl FnMut(&[u32], usize, &mut f32) -> bool,
    ) -> bool {
        // The thread's scratch stack, so a query does not clear a fresh one; a query made from
        // inside another's callback finds it in use and takes its own.
        SCRATCH_STACK.with(|scratch| match scratch.try_borrow_mut() {
            Ok(mut scratch) => {
                let stack = scratch
                    .first_chunk_mut::<N>()
                    .expect("no tier exceeds the scratch stack");
                Traversal::<N, _, T>::new(ray, *t_max, stack)
                    .is_some_and(|walk| self.walk::<N, NEAR_FIRST, _, T>(walk, t_max, &mut leaf))
            }
            Err(_) => self.traverse_nested::<N, NEAR_FIRST, T>(ray, t_max, &mut leaf),
        })
    }

    /// [`Bvh::traverse`] for a query made inside another's callback, with a stack of its own.
    /// Kept out of line: inlined, its stack array grows every query's frame past a page.
    #[cold]
    #[inline(never)]
    fn traverse_nested<const N: usize, const NEAR_FIRST: bool, T: SlabTest<R>>(
        &self,
        ray: &Ray,
        t_max: &mut f32,
        leaf: &mut impl FnMut(&[u32], usize, &mut f32) -> bool,
    ) -> bool {
        // Out of line, this is compiled for the baseline CPU: a wide test's lanes call their
        // AVX intrinsics here (correct, the CPU has AVX; slower, and rare).
        Traversal::<N, _, T>::new(ray, *t_max, [(0, 0.0); N])
            .is_some_and(|walk| self.walk::<N, NEAR_FIRST, _, T>(walk, t_max, leaf))
    }

    /// Runs `walk` to its end, handing leaves to `leaf` (see [`Bvh::traverse`]).
    #[inline(always)]
    fn walk<const N: usize, const NEAR_FIRST: bool, S: BorrowMut<[(u32, f32); N]>, T: SlabTest<R>>(
        &self,
        mut walk: Traversal<N, S, T>,
        t_max: &mut f32,
        leaf: &mut impl FnMut(&[u32], usize, &mut f32) -> bool,
    ) -> bool {
        let found = loop {
            match walk.step::<R, true, NEAR_FIRST>(&self.nodes) {
                Visit::Node => {}
                Visit::Leaf(first) => {
                    if leaf(&self.order, first, &mut walk.t_max) {
                        break true;
                    }
                    if !walk.pop() {
                        break false;
                    }
                }
                Visit::Done => break false,
            }
        };
        *t_max = walk.t_max;
        found
    }
}

thread_local! {
    /// Storage for traversal stacks, one per thread (tiers use its start).
    static SCRATCH_STACK: RefCell<[(u32, f32); LARGE_STACK]> = const { RefCell::new([(0, 0.0); LARGE_STACK]) };
}

/// Work generic over the traversal stack size, run by [`Bvh::with_stack`].
trait StackSized {
    type Output;
    fn run<const N: usize>(self) -> Self::Output;
}

/// Whether a ray can be walked: a non-finite one could turn slab tests into NaN, which min/max
/// would drop.
#[inline(always)]
fn walkable(ray: &Ray) -> bool {
    ray.origin.is_finite() && ray.dir.is_finite()
}

/// What one [`Traversal::step`] reached.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Visit {
    /// An inner node was visited; the walk goes on.
    Node,
    /// The leaf starting at this leaf-order position is next: the caller tests it, then calls
    /// [`Traversal::pop`].
    Leaf(usize),
    /// Nothing is left to visit.
    Done,
}

/// Starts loading inner node `child` into the cache. A child put off for later is read after
/// its sibling's subtree, so its memory latency overlaps that walk instead of stalling it: on a
/// million triangles, +13–18% single-ray throughput (`bvh` bench). Prefetching leaves' triangle
/// packets as well measured no better.
#[inline(always)]
fn fetch<const R: usize>(nodes: &[Node<R>], child: u32) {
    if child & LEAF == 0 {
        let node = nodes.as_ptr().wrapping_add(child as usize);
        for line in 0..std::mem::size_of::<Node<R>>() / 64 {
            super::lanes::prefetch(node.cast::<u8>().wrapping_add(64 * line));
        }
    }
}

/// The state of one ray's near-first walk through a [`Bvh`], advanced one node at a time, so
/// a caller can interleave the walks of several rays (see [`TriangleBvh::closest_hits`]).
struct Traversal<const N: usize, S: BorrowMut<[(u32, f32); N]> = [(u32, f32); N], T = RayPre> {
    ray: T,
    /// Pending children with their entry distances, nearest on top: owned, or borrowed from
    /// the thread's scratch stack.
    stack: S,
    sp: usize,
    /// The node or leaf to visit next.
    cur: u32,
    /// End of the searched segment; leaf tests shrink it.
    t_max: f32,
}

impl<const N: usize, S: BorrowMut<[(u32, f32); N]>, T> Traversal<N, S, T> {
    /// A walk from the root using `stack`, whose contents need not be cleared, or `None` for a
    /// ray that is not [`walkable`].
    #[inline(always)]
    fn new<const R: usize>(ray: &Ray, t_max: f32, stack: S) -> Option<Traversal<N, S, T>>
    where
        T: SlabTest<R>,
    {
        // Not `bool::then`: its closure, left out of line, would make the wide test's lanes
        // outside the AVX code and call each intrinsic.
        if !walkable(ray) {
            return None;
        }
        Some(Traversal {
            ray: T::new(ray),
            stack,
            sp: 0,
            cur: 0,
            t_max,
        })
    }

    /// Starts over from the root with another ray, keeping the stack's storage (entries above
    /// the top are never read, so they need no clearing); `false`, leaving the walk finished,
    /// for a non-finite ray.
    #[inline(always)]
    fn restart<const R: usize>(&mut self, ray: &Ray, t_max: f32) -> bool
    where
        T: SlabTest<R>,
    {
        self.sp = 0;
        if !walkable(ray) {
            return false;
        }
        self.ray = T::new(ray);
        self.cur = 0;
        self.t_max = t_max;
        true
    }

    /// Visits the next inner node, or reports the next leaf or the end of the walk. With
    /// `FETCH`, children put off are prefetched ([`fetch`]): a single walk gains, while
    /// interleaved walks already overlap their misses and only pay the extra instructions.
    #[inline(always)]
    fn step<const R: usize, const FETCH: bool, const NEAR_FIRST: bool>(&mut self, nodes: &[Node<R>]) -> Visit
    where
        T: SlabTest<R>,
    {
        let width = Node::<R>::WIDTH;
        if self.cur & LEAF != 0 {
            return Visit::Leaf((self.cur & !LEAF) as usize);
        }
        let node = &nodes[self.cur as usize];
        if T::SORTS && !FETCH {
            // All the children met go on the stack at once, sorted without a branch, and the one
            // to visit first comes off: no branch on how many were met, which a stream's
            // interleaved walks mispredict (`bvh` bench, 37k triangles: +21-25% closest hits).
            // Any-hit walks take the farthest first: a ray leaving a surface meets the boxes
            // around its origin first, and rarely an occluder in them (+30-45% on bounce rays).
            // Single walks (`FETCH`) keep the branches, prefetching each child they put off.
            // The stack's tiers leave a node's width free above its deepest entry
            // ([`Bvh::stack_fits`]).
            let sp = self.sp;
            if let Some(out) = self.stack.borrow_mut().get_mut(sp..).and_then(|s| s.first_chunk_mut()) {
                self.sp += self.ray.hit_sorted::<NEAR_FIRST>(node, self.t_max, out);
                return if self.pop() { Visit::Node } else { Visit::Done };
            }
        }
        let (mask, t_near) = self.ray.hit(node, self.t_max);
        if mask == 0 {
            return if self.pop() { Visit::Node } else { Visit::Done };
        }
        // Most visits hit one or two children: handle those without sorting.
        let first = mask.trailing_zeros() as usize % width;
        let rest = mask & (mask - 1);
        if rest == 0 {
            self.cur = node.child(first);
            return Visit::Node;
        }
        let t = |slot: usize| t_near[slot % MAX_WIDTH];
        if !NEAR_FIRST {
            // Any order finds the same answer: the first child next, the rest pushed unsorted.
            let mut m = rest;
            while m != 0 {
                let slot = m.trailing_zeros() as usize % width;
                m &= m - 1;
                let child = node.child(slot);
                if FETCH {
                    fetch(nodes, child);
                }
                self.stack.borrow_mut()[self.sp % N] = (child, t(slot));
                self.sp += 1;
            }
            self.cur = node.child(first);
            return Visit::Node;
        }
        if rest & (rest - 1) == 0 {
            let second = rest.trailing_zeros() as usize % width;
            let (c0, c1) = (node.child(first), node.child(second));
            let (t0, t1) = (t(first), t(second));
            let (near, far, far_t) = if t1 < t0 { (c1, c0, t0) } else { (c0, c1, t1) };
            if FETCH {
                fetch(nodes, far);
            }
            self.stack.borrow_mut()[self.sp % N] = (far, far_t);
            self.sp += 1;
            self.cur = near;
            return Visit::Node;
        }
        // Three or more: sorted by their keys, farthest first.
        let (keys, count) = sorted_keys::<R>(mask, &t_near);
        for &key in &keys[..count - 1] {
            let entry = key_entry(node, key);
            if FETCH {
                fetch(nodes, entry.0);
            }
            self.stack.borrow_mut()[self.sp % N] = entry;
            self.sp += 1;
        }
        self.cur = key_entry(node, keys[(count - 1) % MAX_WIDTH]).0;
        Visit::Node
    }

    /// Moves to the nearest pending child that can still beat `t_max`; `false` when none is left.
    #[inline(always)]
    fn pop(&mut self) -> bool {
        while self.sp > 0 {
            self.sp -= 1;
            let (child, t_near) = self.stack.borrow_mut()[self.sp % N];
            if t_near <= self.t_max {
                self.cur = child;
                return true;
            }
        }
        false
    }
}
