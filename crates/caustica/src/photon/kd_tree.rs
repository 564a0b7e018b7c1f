//! A balanced, pointer-free kd-tree over a slice of points, for photon gathering.
//!
//! [`KdTree::build`] reorders the caller's items in place into tree order and keeps, per
//! internal node, one small record (split value + axis, 8 bytes) and the tight bounds of the
//! points beneath it (24 bytes), and the tight bounds of each leaf's points (24 bytes). Leaves
//! hold `LEAF_MAX / 2 ..= LEAF_MAX` items, so there are `n / 16 .. n / 8` internal nodes and as
//! many leaves: 3.5–7 bytes per point.
//!
//! # Layout
//!
//! The item range of a node is split at its median (`len / 2`): the left child gets
//! `[lo, lo + len/2)`, the right child the rest. Sibling sizes at any depth differ by at most
//! one, so every leaf sits at the same depth `D` (the first depth whose ranges hold at most
//! [`LEAF_MAX`] items) and the internal nodes form a complete binary tree of `2^D - 1` nodes.
//! Those are stored in pre-order: a node's subtree is one contiguous run, its left child follows
//! it and its right child follows the left subtree. Nothing but the split records is stored;
//! item ranges are recomputed while descending.
//!
//! # Queries
//!
//! Depth-first, nearer child first, with the far child pruned by the exact squared distance from
//! the query to the child's cell (per-axis offsets carried down, as in Arya & Mount), computed
//! with the same rounding as a point distance so pruning never drops a point on the boundary.
//! A subtree or leaf is entered only if the tight bounds of its points come within the current
//! radius: photons lie on surfaces, often oblique to the axes, so a cell is mostly empty space,
//! and a query far from every photon ends at the root. One loop with an explicit stack does it.
//! k-NN candidates collect in the caller's `Vec` a leaf at a time (up to about `2k`, then a
//! selection keeps the `k` nearest and tightens the radius); the result is heapified at the end.
//! A query allocates nothing once that vector has grown.

use std::cmp::Ordering;

use crate::math::Vec3;

/// Something with a position: photons implement it.
pub trait KdPoint {
    /// The point's position.
    fn position(&self) -> Vec3;
}

impl KdPoint for Vec3 {
    #[inline]
    fn position(&self) -> Vec3 {
        *self
    }
}

/// One k-NN result: the item's slot in the reordered slice and its squared distance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor {
    /// Index into the slice the tree was built over.
    pub slot: u32,
    /// Squared distance from the query point.
    pub dist2: f32,
}

/// Most items a leaf holds; leaves hold between about `LEAF_MAX / 2` and `LEAF_MAX`.
pub const LEAF_MAX: usize = 16;

/// Subranges at least this large are built on two rayon tasks.
const PAR_MIN: usize = 1 << 14;

/// An internal node: items left of the split have `pos[axis] <= split`, right ones `>= split`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Node {
    split: f32,
    axis: u32,
}

/// A balanced kd-tree built in place over a slice; see the [module docs](self).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KdTree {
    /// Internal nodes in pre-order; `2^D - 1` of them.
    nodes: Vec<Node>,
    /// Bounds of the points under each internal node, parallel to `nodes`.
    inner: Vec<PointBounds>,
    /// Bounds of each leaf's points, leaves left to right; `2^D` of them.
    leaves: Vec<PointBounds>,
    /// Number of items the tree was built over.
    len: u32,
}

/// Tight bounds of the points of a leaf or under an inner node (empty, lo > hi, when none is
/// finite).
#[derive(Clone, Copy, Debug, PartialEq)]
struct PointBounds {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Default for PointBounds {
    fn default() -> Self {
        PointBounds {
            lo: [f32::INFINITY; 3],
            hi: [f32::NEG_INFINITY; 3],
        }
    }
}

impl PointBounds {
    /// Squared distance from `p` to the box, rounded as [`dist2`] so it never exceeds the
    /// distance to a point inside (infinite for an empty box).
    #[inline(always)]
    fn dist2(&self, p: [f32; 3]) -> f32 {
        // Spelled out per axis: `[0, 1, 2].map(..)` compiled to an out-of-line call whose result,
        // stored as floats and reloaded as a pair, stalled store forwarding (~4% of a render).
        let gap = |a: usize| max_f(max_f(self.lo[a] - p[a], p[a] - self.hi[a]), 0.0);
        dist2([gap(0), gap(1), gap(2)], [0.0; 3])
    }
}

/// Squared distance with a fixed summation order; the cell bounds use the same order, which
/// keeps pruning exact (never rounds a cell bound above a contained point's distance).
#[inline(always)]
fn dist2(a: [f32; 3], b: [f32; 3]) -> f32 {
    let dx = a[0] - b[0];
    let dy = a[1] - b[1];
    let dz = a[2] - b[2];
    dx * dx + dy * dy + dz * dz
}

/// Build key: NaN sorts as +inf, so splits are never NaN and NaN items end up in cells that
/// finite queries prune.
#[inline(always)]
fn key(p: Vec3, axis: usize) -> f32 {
    let v = p.to_array()[axis];
    if v.is_nan() {
        f32::INFINITY
    } else {
        v
    }
}

/// The smallest float above `x` (for `x >= 0`), turning an inclusive bound into a strict one.
#[inline]
fn strict_bound(x: f32) -> f32 {
    if x == f32::INFINITY {
        x
    } else if x == 0.0 {
        f32::from_bits(1)
    } else {
        f32::from_bits(x.to_bits() + 1)
    }
}

/// Number of internal levels for `n` items: the least `d` with `ceil(n / 2^d) <= LEAF_MAX`.
fn depth_for(n: usize) -> u32 {
    let mut d = 0;
    while n.div_ceil(1usize << d) > LEAF_MAX {
        d += 1;
    }
    d
}

/// Running bounds of a set of positions.
#[derive(Clone, Copy)]
struct Bounds {
    lo: [f32; 3],
    hi: [f32; 3],
    /// Sum of all coordinates: NaN iff some coordinate is NaN (or infinities of both signs,
    /// which merely takes the slower, NaN-safe path).
    sum: f32,
}

impl Bounds {
    const EMPTY: Bounds = Bounds {
        lo: [f32::INFINITY; 3],
        hi: [f32::NEG_INFINITY; 3],
        sum: 0.0,
    };

    /// Plain compares (one min/max instruction each) instead of NaN-aware `f32::min`.
    #[inline(always)]
    fn grow(mut self, p: Vec3) -> Bounds {
        let p = p.to_array();
        for ((lo, hi), x) in self.lo.iter_mut().zip(&mut self.hi).zip(p) {
            *lo = if x < *lo { x } else { *lo };
            *hi = if x > *hi { x } else { *hi };
        }
        self.sum += (p[0] + p[1]) + p[2];
        self
    }

    #[inline]
    fn union(mut self, o: Bounds) -> Bounds {
        for a in 0..3 {
            self.lo[a] = self.lo[a].min(o.lo[a]);
            self.hi[a] = self.hi[a].max(o.hi[a]);
        }
        // Only NaN-ness of the sum matters, so association order does not.
        self.sum += o.sum;
        self
    }
}

/// Bounds of the items' positions; exact, hence deterministic also when computed in parallel.
fn bounds<T: KdPoint + Send>(items: &mut [T]) -> Bounds {
    if items.len() >= PAR_MIN * 4 {
        use rayon::prelude::*;
        // `par_iter_mut` only because `T` is `Send` but maybe not `Sync`.
        items
            .par_iter_mut()
            .with_min_len(PAR_MIN)
            .fold(|| Bounds::EMPTY, |b, it| b.grow(it.position()))
            .reduce(|| Bounds::EMPTY, Bounds::union)
    } else {
        items.iter().fold(Bounds::EMPTY, |b, it| b.grow(it.position()))
    }
}

/// `select_nth_unstable` on a NaN-free key.
#[inline(always)]
fn select_by<T: KdPoint>(items: &mut [T], mid: usize, key: impl Fn(Vec3) -> f32) {
    items.select_nth_unstable_by(mid, |a, b| {
        let (a, b) = (key(a.position()), key(b.position()));
        if a < b {
            Ordering::Less
        } else if a > b {
            Ordering::Greater
        } else {
            Ordering::Equal
        }
    });
}

fn build_rec<T: KdPoint + Send>(
    nodes: &mut [Node],
    inner: &mut [PointBounds],
    leaves: &mut [PointBounds],
    items: &mut [T],
) {
    let n = items.len();
    let b = bounds(items);
    if nodes.is_empty() {
        leaves[0] = PointBounds { lo: b.lo, hi: b.hi };
        return;
    }
    inner[0] = PointBounds { lo: b.lo, hi: b.hi };
    let ext = [0, 1, 2].map(|a| b.hi[a] - b.lo[a]);
    // Widest axis; a NaN extent never wins a comparison.
    let mut axis = 0;
    if ext[1] > ext[0] {
        axis = 1;
    }
    if ext[2] > ext[axis] {
        axis = 2;
    }
    let nan = b.sum.is_nan();
    let mid = n / 2;
    if nan {
        items.select_nth_unstable_by(mid, |a, b| key(a.position(), axis).total_cmp(&key(b.position(), axis)));
    } else {
        // One closure per axis so the comparison is a plain field compare.
        match axis {
            0 => select_by(items, mid, |p| p.x),
            1 => select_by(items, mid, |p| p.y),
            _ => select_by(items, mid, |p| p.z),
        }
    }
    nodes[0] = Node {
        split: key(items[mid].position(), axis),
        axis: axis as u32,
    };
    let half = nodes.len() / 2;
    let (left_nodes, right_nodes) = nodes[1..].split_at_mut(half);
    let (left_inner, right_inner) = inner[1..].split_at_mut(half);
    let (left_items, right_items) = items.split_at_mut(mid);
    let (left_leaves, right_leaves) = leaves.split_at_mut(leaves.len() / 2);
    if n >= PAR_MIN {
        rayon::join(
            || build_rec(left_nodes, left_inner, left_leaves, left_items),
            || build_rec(right_nodes, right_inner, right_leaves, right_items),
        );
    } else {
        build_rec(left_nodes, left_inner, left_leaves, left_items);
        build_rec(right_nodes, right_inner, right_leaves, right_items);
    }
}

impl KdTree {
    /// Reorders `items` into tree order and builds the tree over them.
    ///
    /// Deterministic: the same input gives the same order and tree for any rayon thread count.
    /// Items with NaN coordinates are kept but never reported by queries.
    ///
    /// # Panics
    /// If there are more than `u32::MAX` items.
    pub fn build<T: KdPoint + Send>(items: &mut [T]) -> KdTree {
        let n = items.len();
        let len = u32::try_from(n).expect("KdTree holds at most u32::MAX items");
        let depth = depth_for(n);
        let mut nodes = vec![Node::default(); (1usize << depth) - 1];
        let mut inner = vec![PointBounds::default(); nodes.len()];
        let mut leaves = vec![PointBounds::default(); 1usize << depth];
        build_rec(&mut nodes, &mut inner, &mut leaves, items);
        KdTree {
            nodes,
            inner,
            leaves,
            len,
        }
    }

    /// Number of items the tree was built over.
    #[inline]
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// Whether the tree holds no items.
    #[inline]
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// Heap bytes the tree itself owns (the items are the caller's).
    pub fn heap_bytes(&self) -> usize {
        self.nodes.capacity() * std::mem::size_of::<Node>()
            + (self.inner.capacity() + self.leaves.capacity()) * std::mem::size_of::<PointBounds>()
    }

    /// The k nearest items within squared distance `max_dist2` (inclusive) of `p`.
    ///
    /// `out` is cleared, then holds up to `k` results as a max-heap on `dist2`: `out[0]` is the
    /// farthest one, the rest are in no particular order. Returns the squared radius that bounds
    /// them: the k-th distance (`out[0].dist2`) when `k` items were found, else `max_dist2`
    /// (also for `k == 0`). A NaN query point or `max_dist2` finds nothing.
    ///
    /// `items` must be the slice `build` reordered. Allocates only if `out` must grow.
    pub fn k_nearest<T: KdPoint>(
        &self,
        items: &[T],
        p: Vec3,
        k: usize,
        max_dist2: f32,
        out: &mut Vec<Neighbor>,
    ) -> f32 {
        let r2 = self.k_nearest_unordered(items, p, k, max_dist2, out);
        heapify(out);
        r2
    }

    /// [`KdTree::k_nearest`] without the heap order: the same items and radius, in no
    /// particular order (for callers that only sum over them).
    pub fn k_nearest_unordered<T: KdPoint>(
        &self,
        items: &[T],
        p: Vec3,
        k: usize,
        max_dist2: f32,
        out: &mut Vec<Neighbor>,
    ) -> f32 {
        self.k_nearest_where(items, p, k, max_dist2, |_| true, out)
    }

    /// [`KdTree::k_nearest_unordered`] among the items that pass `keep`.
    pub fn k_nearest_where<T: KdPoint>(
        &self,
        items: &[T],
        p: Vec3,
        k: usize,
        max_dist2: f32,
        keep: impl Fn(&T) -> bool,
        out: &mut Vec<Neighbor>,
    ) -> f32 {
        out.clear();
        assert_eq!(items.len(), self.len(), "items are not the tree's slice");
        if k == 0 || p.is_nan() || max_dist2.is_nan() || max_dist2 < 0.0 {
            return max_dist2;
        }
        let cap = k.saturating_mul(2);
        // A leaf's candidates are added at once, so the count may pass `cap` by a leaf's worth.
        out.reserve((cap + LEAF_MAX).min(items.len()));
        let mut q = Knn {
            items,
            p: p.to_array(),
            k,
            cap,
            bound: strict_bound(max_dist2),
            out,
            keep,
        };
        search(self, q.p, &mut q);
        if out.len() > k {
            keep_nearest(out, k);
        }
        if out.len() == k {
            out.iter().fold(0.0, |m, n| max_f(m, n.dist2))
        } else {
            max_dist2
        }
    }

    /// The leaves left to right: each one's items (a range of the slice `build` reordered) and
    /// the bounds of their finite positions (`lo > hi` when there are none).
    pub fn leaf_cells(&self) -> Vec<(std::ops::Range<usize>, [f32; 3], [f32; 3])> {
        let mut cells = Vec::with_capacity(self.leaves.len());
        let mut stack = vec![Subtree {
            size: self.nodes.len() as u32,
            len: self.len,
            ..Subtree::default()
        }];
        while let Some(cur) = stack.pop() {
            if cur.size == 0 {
                let b = self.leaves[cur.leaf as usize];
                cells.push((cur.lo as usize..(cur.lo + cur.len) as usize, b.lo, b.hi));
                continue;
            }
            let (left, right) = children(cur);
            stack.push(right);
            stack.push(left);
        }
        cells
    }

    /// The squared distance `k_nearest_where` measures from `p` to an item at `q`, rounded the
    /// same way, so that results computed elsewhere match the tree's to the bit.
    #[inline(always)]
    pub fn dist2(q: Vec3, p: Vec3) -> f32 {
        dist2(q.to_array(), p.to_array())
    }

    /// Calls `f(slot, dist2)` for every item within squared distance `r2` (inclusive) of `p`,
    /// in tree order. A NaN query point or `r2` finds nothing.
    ///
    /// `items` must be the slice `build` reordered.
    pub fn for_each_within<T: KdPoint>(&self, items: &[T], p: Vec3, r2: f32, mut f: impl FnMut(u32, f32)) {
        assert_eq!(items.len(), self.len(), "items are not the tree's slice");
        if p.is_nan() || r2.is_nan() || r2 < 0.0 {
            return;
        }
        let mut q = Within {
            items,
            p: p.to_array(),
            bound: strict_bound(r2),
            f: &mut f,
        };
        search(self, q.p, &mut q);
    }

    /// Calls `f(slot, t, dist2)` for every item within distance `radius` of the segment
    /// `origin + t dir`, `t0 <= t <= t1` (`dir` a unit vector), measured square to it: `t` is
    /// where the item lies along the segment, `dist2` its squared distance from it (a beam
    /// query, as the beam radiance estimate asks). Items project beyond either end are left
    /// out, so that consecutive segments of one ray find each item once. In tree order.
    ///
    /// `items` must be the slice `build` reordered.
    pub fn for_each_near_segment<T: KdPoint>(
        &self,
        items: &[T],
        (origin, dir): (Vec3, Vec3),
        (t0, t1): (f32, f32),
        radius: f32,
        mut f: impl FnMut(u32, f32, f32),
    ) {
        assert_eq!(items.len(), self.len(), "items are not the tree's slice");
        // (NaN bounds or radius find nothing.)
        let ordered = t0 <= t1 && radius >= 0.0;
        if self.len == 0 || !ordered || origin.is_nan() || dir.is_nan() {
            return;
        }
        let r2 = radius * radius;
        let (o, d) = (origin.to_array(), dir.to_array());
        let inv = d.map(|x| 1.0 / x);
        // The segment meets the box grown by the radius: a slab test.
        let meets = |b: &PointBounds| {
            let (mut near, mut far) = (t0, t1);
            for a in 0..3 {
                let (lo, hi) = (b.lo[a] - radius, b.hi[a] + radius);
                if d[a] == 0.0 {
                    if o[a] < lo || o[a] > hi {
                        return false;
                    }
                    continue;
                }
                let (ta, tb) = ((lo - o[a]) * inv[a], (hi - o[a]) * inv[a]);
                near = near.max(ta.min(tb));
                far = far.min(ta.max(tb));
            }
            near <= far
        };
        let mut stack = [Subtree::default(); SEARCH_STACK];
        let mut sp = 0;
        let mut cur = Subtree {
            size: self.nodes.len() as u32,
            len: self.len,
            ..Subtree::default()
        };
        loop {
            let bounds = if cur.size == 0 {
                &self.leaves[cur.leaf as usize]
            } else {
                &self.inner[cur.node as usize]
            };
            if meets(bounds) {
                if cur.size == 0 {
                    let range = cur.lo as usize..(cur.lo + cur.len) as usize;
                    for (slot, item) in range.clone().zip(&items[range]) {
                        let v = item.position() - origin;
                        let t = v.dot(dir);
                        let d2 = (v.length_squared() - t * t).max(0.0);
                        if t >= t0 && t <= t1 && d2 < r2 {
                            f(slot as u32, t, d2);
                        }
                    }
                } else {
                    let (left, right) = children(cur);
                    stack[sp] = right;
                    sp += 1;
                    cur = left;
                    continue;
                }
            }
            if sp == 0 {
                return;
            }
            sp -= 1;
            cur = stack[sp];
        }
    }
}

/// State of one k-NN query. `bound` is strict: a candidate must have `dist2 < bound`.
struct Knn<'a, T, K> {
    items: &'a [T],
    p: [f32; 3],
    k: usize,
    /// Candidates held before a selection: `2k`.
    cap: usize,
    bound: f32,
    out: &'a mut Vec<Neighbor>,
    /// Which items may be neighbours at all.
    keep: K,
}

/// A subtree waiting to be searched: `size` internal nodes from `node`, leftmost leaf `leaf`,
/// items `lo..lo + len`, the query's per-axis offsets `off` to its cell and their squared
/// length `dist2`.
#[derive(Clone, Copy, Default)]
struct Subtree {
    node: u32,
    size: u32,
    leaf: u32,
    lo: u32,
    len: u32,
    off: [f32; 3],
    dist2: f32,
}

/// Pending subtrees a search can hold: one per level, and there are at most 32 levels.
const SEARCH_STACK: usize = 40;

/// What a search does at the leaves it reaches, and how far it still looks.
trait Visitor {
    /// The strict squared-distance bound: cells at or beyond it are skipped.
    fn bound(&self) -> f32;
    /// Scans the items `lo..lo + len` of a leaf within the bound.
    fn leaf(&mut self, lo: usize, len: usize);
}

/// Searches the tree around `p`: depth-first, nearer child first, far children kept on a stack
/// and skipped when the bound has shrunk past them by the time they are reached. The order is
/// that of a recursive search, without a call per node (9% of a caustic render).
fn search(tree: &KdTree, p: [f32; 3], v: &mut impl Visitor) {
    let KdTree {
        nodes, inner, leaves, ..
    } = tree;
    let mut stack = [Subtree::default(); SEARCH_STACK];
    let mut sp = 0;
    let mut cur = Subtree {
        size: nodes.len() as u32,
        len: tree.len,
        ..Subtree::default()
    };
    loop {
        let mut at_leaf = true;
        while cur.size != 0 {
            // The points' own bounds prune subtrees that are mostly empty space around
            // surfaces, and whole searches far from every photon.
            if inner[cur.node as usize].dist2(p) >= v.bound() {
                at_leaf = false;
                break;
            }
            let Node { split, axis } = nodes[cur.node as usize];
            let axis = axis as usize;
            let diff = p[axis] - split;
            let child = cur.size / 2;
            let half = cur.len / 2;
            let left = Subtree {
                node: cur.node + 1,
                size: child,
                leaf: 2 * cur.leaf,
                lo: cur.lo,
                len: half,
                ..cur
            };
            let right = Subtree {
                node: cur.node + 1 + child,
                size: child,
                leaf: 2 * cur.leaf + 1,
                lo: cur.lo + half,
                len: cur.len - half,
                ..cur
            };
            let (near, mut far) = if diff < 0.0 { (left, right) } else { (right, left) };
            far.off = far_offsets(cur.off, axis, diff);
            far.dist2 = dist2(far.off, [0.0; 3]);
            if far.dist2 < v.bound() {
                stack[sp % SEARCH_STACK] = far;
                sp += 1;
            }
            cur = near;
        }
        if at_leaf && leaves[cur.leaf as usize].dist2(p) < v.bound() {
            v.leaf(cur.lo as usize, cur.len as usize);
        }
        loop {
            if sp == 0 {
                return;
            }
            sp -= 1;
            let next = stack[sp % SEARCH_STACK];
            if next.dist2 < v.bound() {
                cur = next;
                break;
            }
        }
    }
}

impl<T: KdPoint, K: Fn(&T) -> bool> Visitor for Knn<'_, T, K> {
    #[inline(always)]
    fn bound(&self) -> f32 {
        self.bound
    }

    /// Scans a leaf without a branch per item (whether a photon is a candidate is a coin flip
    /// near the radius): each is written to a buffer whose length advances only for candidates,
    /// and the bound is updated once per leaf. Candidates found with the bound of the leaf's
    /// start are a superset of those a per-item update would keep, so the result is the same.
    #[inline]
    fn leaf(&mut self, lo: usize, len: usize) {
        for (start, chunk) in (lo..).step_by(LEAF_MAX).zip(self.items[lo..lo + len].chunks(LEAF_MAX)) {
            let mut buf = [Neighbor { slot: 0, dist2: 0.0 }; LEAF_MAX];
            let mut found = 0;
            for (i, it) in chunk.iter().enumerate() {
                let d2 = dist2(it.position().to_array(), self.p);
                buf[found % LEAF_MAX] = Neighbor {
                    slot: (start + i) as u32,
                    dist2: d2,
                };
                found += usize::from(d2 < self.bound && (self.keep)(it));
            }
            if found > 0 {
                self.extend(&buf[..found]);
            }
        }
    }
}

impl<T: KdPoint, K> Knn<'_, T, K> {
    /// Adds candidates. When their count first reaches `k` the bound drops to their maximum,
    /// and whenever it reaches `2k` a selection keeps the `k` nearest and tightens the bound:
    /// O(1) amortised per candidate, against O(log k) mispredicted sifts for a heap.
    #[inline]
    fn extend(&mut self, candidates: &[Neighbor]) {
        let before = self.out.len();
        self.out.extend_from_slice(candidates);
        let len = self.out.len();
        if len >= self.cap {
            self.bound = keep_nearest(self.out, self.k);
        } else if before < self.k && len >= self.k {
            self.bound = self.out.iter().fold(0.0, |m, n| max_f(m, n.dist2));
        }
    }
}

#[inline(always)]
fn max_f(a: f32, b: f32) -> f32 {
    if b > a {
        b
    } else {
        a
    }
}

/// The far child's offsets: `off` with `axis` replaced by `diff`. Built by selects, not by a
/// store into the array: reading the array back right after a one-lane store stalls the CPU.
#[inline(always)]
fn far_offsets(off: [f32; 3], axis: usize, diff: f32) -> [f32; 3] {
    [
        if axis == 0 { diff } else { off[0] },
        if axis == 1 { diff } else { off[1] },
        if axis == 2 { diff } else { off[2] },
    ]
}

/// Keeps the `k` nearest of more than `k` candidates; returns the k-th distance.
fn keep_nearest(v: &mut Vec<Neighbor>, k: usize) -> f32 {
    // Distances here are never NaN.
    let (_, kth, _) = v.select_nth_unstable_by(k - 1, |a, b| {
        if a.dist2 < b.dist2 {
            Ordering::Less
        } else if a.dist2 > b.dist2 {
            Ordering::Greater
        } else {
            Ordering::Equal
        }
    });
    let bound = kth.dist2;
    v.truncate(k);
    bound
}

/// Turns `h` into a max-heap on `dist2`.
fn heapify(h: &mut [Neighbor]) {
    for i in (0..h.len() / 2).rev() {
        sift_down(h, i);
    }
}

/// Moves `h[i]` down until its subtree is a max-heap.
fn sift_down(h: &mut [Neighbor], mut i: usize) {
    let n = h.len();
    let x = h[i];
    loop {
        let l = 2 * i + 1;
        if l >= n {
            break;
        }
        let r = l + 1;
        let c = if r < n && h[r].dist2 > h[l].dist2 { r } else { l };
        if h[c].dist2 <= x.dist2 {
            break;
        }
        h[i] = h[c];
        i = c;
    }
    h[i] = x;
}

/// Each item's own radius, and per subtree the bounds of the balls those radii span around its
/// items: what a query needs to find every item whose ball reaches a point (variable-kernel
/// density estimates).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Reach {
    radius: Vec<f32>,
    inner: Vec<PointBounds>,
    leaves: Vec<PointBounds>,
}

impl Reach {
    /// The radius of item `slot` (in tree order).
    #[inline]
    pub fn radius(&self, slot: u32) -> f32 {
        self.radius[slot as usize]
    }

    /// Heap bytes it owns.
    pub fn heap_bytes(&self) -> usize {
        self.radius.capacity() * 4
            + (self.inner.capacity() + self.leaves.capacity()) * std::mem::size_of::<PointBounds>()
    }
}

impl KdTree {
    /// The reach of `radius` (one per item, in tree order) over this tree's subtrees.
    pub fn reach<T: KdPoint>(&self, items: &[T], radius: Vec<f32>) -> Reach {
        assert!(items.len() == self.len() && radius.len() == self.len());
        let mut reach = Reach {
            radius,
            inner: vec![PointBounds::default(); self.nodes.len()],
            leaves: vec![PointBounds::default(); self.leaves.len()],
        };
        let root = Subtree {
            size: self.nodes.len() as u32,
            len: self.len,
            ..Subtree::default()
        };
        reach_rec(items, &mut reach, root);
        reach
    }

    /// Calls `f(slot, dist2)` for every item whose ball (its radius in `reach`) holds `p`
    /// strictly inside, or that lies within `floor` of it, in tree order. A NaN query point
    /// finds nothing.
    pub fn for_each_reaching<T: KdPoint>(
        &self,
        reach: &Reach,
        items: &[T],
        p: Vec3,
        floor: f32,
        mut f: impl FnMut(u32, f32),
    ) {
        assert!(items.len() == self.len() && reach.radius.len() == self.len());
        if p.is_nan() || self.len == 0 {
            return;
        }
        let q = p.to_array();
        let floor2 = strict_bound(floor.max(0.0) * floor.max(0.0));
        self.descend_reach(reach, q, 0.0, floor2, |lo, len| {
            reaching_in_leaf(reach, items, lo..lo + len, q, floor2, &mut f)
        });
    }

    /// The items (their slots, in tree order) that [`KdTree::for_each_reaching`] may find for
    /// any point within `delta` of `p` and any floor up to `floor`: a superset, so
    /// [`KdTree::for_each_reaching_among`] over them finds, for such a point, what the whole
    /// tree would, in the same order. Nearby queries (the samples of one pixel) then share one
    /// descent of the tree and one pass over its leaves.
    pub fn reaching_near<T: KdPoint>(
        &self,
        reach: &Reach,
        items: &[T],
        p: Vec3,
        floor: f32,
        delta: f32,
        out: &mut Vec<u32>,
    ) {
        assert!(items.len() == self.len() && reach.radius.len() == self.len());
        out.clear();
        if p.is_nan() || self.len == 0 || delta.is_nan() || delta < 0.0 || floor.is_nan() || floor < 0.0 {
            return;
        }
        let q = p.to_array();
        // Rounding of the distances, which are taken from coordinates as large as |p|.
        let slack = delta * 1.01 + 1e-5 * (1.0 + p.abs().max_element());
        let near2 = slack * slack;
        let floor2 = (floor + slack) * (floor + slack);
        self.descend_reach(reach, q, near2, floor2, |lo, len| {
            // An item reaches a point within delta only if it reaches within delta of `p`.
            for slot in lo..lo + len {
                let d = dist2(items[slot as usize].position().to_array(), q).sqrt();
                let r = reach.radius[slot as usize].max(floor);
                if d <= (r + slack) * 1.0001 {
                    out.push(slot);
                }
            }
        });
    }

    /// Visits, in tree order, the leaves (`leaf(lo, len)`) whose subtrees are not pruned: a
    /// subtree is skipped when the bounds of its balls lie farther than `near2` (squared) from
    /// `q` and its points' bounds at `floor2` or farther.
    fn descend_reach(&self, reach: &Reach, q: [f32; 3], near2: f32, floor2: f32, mut leaf: impl FnMut(u32, u32)) {
        let mut stack = [Subtree::default(); SEARCH_STACK];
        let mut sp = 1;
        stack[0] = Subtree {
            size: self.nodes.len() as u32,
            len: self.len,
            ..Subtree::default()
        };
        while sp > 0 {
            sp -= 1;
            let cur = stack[sp];
            let (balls, points) = if cur.size == 0 {
                (&reach.leaves[cur.leaf as usize], &self.leaves[cur.leaf as usize])
            } else {
                (&reach.inner[cur.node as usize], &self.inner[cur.node as usize])
            };
            if balls.dist2(q) > near2 && points.dist2(q) >= floor2 {
                continue;
            }
            if cur.size == 0 {
                leaf(cur.lo, cur.len);
                continue;
            }
            let (left, right) = children(cur);
            stack[sp] = right;
            stack[sp + 1] = left;
            sp += 2;
        }
    }

    /// [`KdTree::for_each_reaching`] over the items [`KdTree::reaching_near`] found near `p`.
    pub fn for_each_reaching_among<T: KdPoint>(
        &self,
        reach: &Reach,
        items: &[T],
        slots: &[u32],
        p: Vec3,
        floor: f32,
        mut f: impl FnMut(u32, f32),
    ) {
        assert!(items.len() == self.len() && reach.radius.len() == self.len());
        if p.is_nan() {
            return;
        }
        let floor2 = strict_bound(floor.max(0.0) * floor.max(0.0));
        reaching_in_leaf(reach, items, slots.iter().copied(), p.to_array(), floor2, &mut f);
    }
}

/// Calls `f(slot, dist2)` for the items of `slots` whose ball, or the floor's, holds `q`.
#[inline(always)]
fn reaching_in_leaf<T: KdPoint>(
    reach: &Reach,
    items: &[T],
    slots: impl IntoIterator<Item = u32>,
    q: [f32; 3],
    floor2: f32,
    f: &mut impl FnMut(u32, f32),
) {
    for slot in slots {
        let d2 = dist2(items[slot as usize].position().to_array(), q);
        let r = reach.radius[slot as usize];
        if d2 < r * r || d2 < floor2 {
            f(slot, d2);
        }
    }
}

/// The two children of an inner subtree, as [`search`] lays them out.
#[inline]
fn children(cur: Subtree) -> (Subtree, Subtree) {
    let child = cur.size / 2;
    let half = cur.len / 2;
    let left = Subtree {
        node: cur.node + 1,
        size: child,
        leaf: 2 * cur.leaf,
        lo: cur.lo,
        len: half,
        ..cur
    };
    let right = Subtree {
        node: cur.node + 1 + child,
        size: child,
        leaf: 2 * cur.leaf + 1,
        lo: cur.lo + half,
        len: cur.len - half,
        ..cur
    };
    (left, right)
}

/// Fills the ball bounds of `cur` and below; returns those of `cur`.
fn reach_rec<T: KdPoint>(items: &[T], reach: &mut Reach, cur: Subtree) -> PointBounds {
    if cur.size == 0 {
        let mut b = PointBounds::default();
        let range = cur.lo as usize..(cur.lo + cur.len) as usize;
        for (item, &radius) in items[range.clone()].iter().zip(&reach.radius[range]) {
            let p = item.position().to_array();
            // A little wider than the radius, so rounding never leaves out a ball that reaches.
            let r = radius * (1.0 + 1e-5) + f32::MIN_POSITIVE;
            if p.iter().any(|c| c.is_nan()) || r.is_nan() {
                continue;
            }
            for ((lo, hi), c) in b.lo.iter_mut().zip(&mut b.hi).zip(p) {
                *lo = lo.min(c - r);
                *hi = hi.max(c + r);
            }
        }
        reach.leaves[cur.leaf as usize] = b;
        return b;
    }
    let (left, right) = children(cur);
    let (l, r) = (reach_rec(items, reach, left), reach_rec(items, reach, right));
    let mut b = l;
    for a in 0..3 {
        b.lo[a] = b.lo[a].min(r.lo[a]);
        b.hi[a] = b.hi[a].max(r.hi[a]);
    }
    reach.inner[cur.node as usize] = b;
    b
}

/// State of one fixed-radius query.
struct Within<'a, T, F> {
    items: &'a [T],
    p: [f32; 3],
    bound: f32,
    f: &'a mut F,
}

impl<T: KdPoint, F: FnMut(u32, f32)> Visitor for Within<'_, T, F> {
    #[inline(always)]
    fn bound(&self) -> f32 {
        self.bound
    }

    #[inline]
    fn leaf(&mut self, lo: usize, len: usize) {
        for (i, it) in self.items[lo..lo + len].iter().enumerate() {
            let d2 = dist2(it.position().to_array(), self.p);
            if d2 < self.bound {
                (self.f)((lo + i) as u32, d2);
            }
        }
    }
}

#[cfg(test)]
mod tests;
