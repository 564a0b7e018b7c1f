//! Construction: a binned-SAH binary BVH built top-down (in parallel, deterministically), then
//! collapsed into the wide node layout used for traversal.

use glam::{Vec3A, Vec4};
use rayon::prelude::*;

use super::{Node, END, LEAF, MAX_WIDTH, PAIR};
use crate::math::Aabb;
use crate::progress::Progress;

/// SAH bins per axis.
const BINS: usize = 32;
/// Cost of visiting a binary node, the unit of [`LeafCost`].
const TRAVERSAL_COST: f32 = 1.0;
/// Beyond this depth splits become object medians, so the depth stays below about
/// `MEDIAN_DEPTH + log2(n)` and the traversal stack stays bounded.
const MEDIAN_DEPTH: u32 = 40;
/// Nodes with at most this many primitives use an exact SAH sweep instead of bins.
const SWEEP_MAX: usize = 32;
/// Subtrees with fewer primitives than this are built on the current thread.
const PARALLEL_MIN: usize = 4096;
/// Binning runs in parallel chunks of this many primitives for large nodes.
const BIN_CHUNK: usize = 1 << 15;

/// How the surface-area heuristic prices primitives in leaves.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LeafCost {
    /// Primitives are intersected in blocks of this many (1, or a packet's lanes).
    pub(crate) block: usize,
    /// Cost of one block, relative to visiting a binary node.
    pub(crate) block_cost: f32,
    /// Leaves never hold more primitives than this (unless the depth limit forces them to).
    pub(crate) max_leaf: usize,
}

impl LeafCost {
    /// One primitive at a time, each costing a node visit.
    pub(crate) const SINGLE: LeafCost = LeafCost {
        block: 1,
        block_cost: 1.0,
        max_leaf: 8,
    };

    #[inline]
    fn of(&self, n: usize) -> f32 {
        n.div_ceil(self.block) as f32 * self.block_cost
    }
}

/// A primitive's bounds; the primitive id rides in the w lanes as two exact 16-bit halves
/// (plain small floats, so no NaN payloads to lose).
#[derive(Clone, Copy)]
struct PrimRef {
    lo: Vec4,
    hi: Vec4,
}

impl PrimRef {
    #[inline]
    fn id(&self) -> u32 {
        (self.hi.w as u32) << 16 | self.lo.w as u32
    }
    /// Twice the centroid (only xyz meaningful).
    #[inline]
    fn centroid2(&self) -> Vec4 {
        self.lo + self.hi
    }
}

/// A box over xyz lanes of `Vec4`s (w is ignored).
#[derive(Clone, Copy)]
struct Box4 {
    lo: Vec4,
    hi: Vec4,
}

impl Box4 {
    const EMPTY: Box4 = Box4 {
        lo: Vec4::splat(f32::INFINITY),
        hi: Vec4::splat(f32::NEG_INFINITY),
    };

    #[inline]
    fn grow(&mut self, lo: Vec4, hi: Vec4) {
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
    }
    #[inline]
    fn union(self, o: Box4) -> Box4 {
        Box4 {
            lo: self.lo.min(o.lo),
            hi: self.hi.max(o.hi),
        }
    }
    /// Half the surface area; zero when empty.
    #[inline]
    fn half_area(&self) -> f32 {
        let e = Vec3A::from_vec4(self.hi - self.lo);
        if e.x < 0.0 || e.y < 0.0 || e.z < 0.0 {
            return 0.0;
        }
        e.x * e.y + e.y * e.z + e.z * e.x
    }
    fn to_aabb(self) -> Aabb {
        Aabb {
            min: self.lo.truncate(),
            max: self.hi.truncate(),
        }
    }
}

/// A binary node; `count == 0` marks an inner node with children `a` and `b`, otherwise a leaf
/// holding `count` primitives from position `a` of the leaf order.
#[derive(Clone, Copy)]
pub(super) struct Node2 {
    bounds: Box4,
    a: u32,
    b: u32,
    count: u32,
}

impl Default for Node2 {
    fn default() -> Self {
        Node2 {
            bounds: Box4::EMPTY,
            a: 0,
            b: 0,
            count: 0,
        }
    }
}

/// Per-axis bins.
#[derive(Clone, Copy)]
struct Bins {
    bounds: [[Box4; BINS]; 3],
    counts: [[u32; BINS]; 3],
}

impl Bins {
    fn new() -> Bins {
        Bins {
            bounds: [[Box4::EMPTY; BINS]; 3],
            counts: [[0; BINS]; 3],
        }
    }
    fn merge(mut self, o: &Bins) -> Bins {
        for axis in 0..3 {
            for i in 0..BINS {
                self.bounds[axis][i] = self.bounds[axis][i].union(o.bounds[axis][i]);
                self.counts[axis][i] += o.counts[axis][i];
            }
        }
        self
    }
}

/// Maps centroids to bins; the same arithmetic is used for binning and partitioning, so both
/// agree exactly.
#[derive(Clone, Copy)]
struct Binner {
    origin: Vec4,
    scale: Vec4,
}

impl Binner {
    fn new(cb: &Box4) -> Binner {
        let extent = cb.hi - cb.lo;
        let k = BINS as f32 * (1.0 - 1e-6);
        let scale = Vec4::from_array(extent.to_array().map(|e| if e > 0.0 { k / e } else { 0.0 }));
        Binner { origin: cb.lo, scale }
    }
    #[inline]
    fn bins(&self, c: Vec4) -> [usize; 3] {
        let f = ((c - self.origin) * self.scale).to_array();
        [0, 1, 2].map(|a| (f[a] as i32).clamp(0, BINS as i32 - 1) as usize)
    }
    #[inline]
    fn bin(&self, c: Vec4, axis: usize) -> usize {
        let f = (c[axis] - self.origin[axis]) * self.scale[axis];
        (f as i32).clamp(0, BINS as i32 - 1) as usize
    }
    fn fill(&self, refs: &[PrimRef]) -> Bins {
        let mut bins = Bins::new();
        for r in refs {
            let b = self.bins(r.centroid2());
            for (axis, &bin) in b.iter().enumerate() {
                bins.bounds[axis][bin].grow(r.lo, r.hi);
                bins.counts[axis][bin] += 1;
            }
        }
        bins
    }
}

struct Split {
    axis: usize,
    /// First bin of the right side.
    bin: usize,
    /// Sum of half-area × count of both sides.
    cost: f32,
}

fn best_split(bins: &Bins, leaf: &LeafCost) -> Option<Split> {
    let mut best: Option<Split> = None;
    for axis in 0..3 {
        let counts = &bins.counts[axis];
        let mut right_cost = [0.0f32; BINS];
        let mut acc = Box4::EMPTY;
        let mut n = 0u32;
        for i in (1..BINS).rev() {
            acc = acc.union(bins.bounds[axis][i]);
            n += counts[i];
            right_cost[i] = acc.half_area() * leaf.of(n as usize);
        }
        let mut acc = Box4::EMPTY;
        let mut left_n = 0u32;
        let total: u32 = counts.iter().sum();
        for i in 1..BINS {
            acc = acc.union(bins.bounds[axis][i - 1]);
            left_n += counts[i - 1];
            if left_n == 0 || left_n == total {
                continue;
            }
            let cost = acc.half_area() * leaf.of(left_n as usize) + right_cost[i];
            // Strict comparison keeps the first minimum: deterministic ties.
            if !matches!(&best, Some(b) if b.cost <= cost) {
                best = Some(Split { axis, bin: i, cost });
            }
        }
    }
    best
}

/// Bounds and centroid bounds of a range of references.
fn range_bounds(refs: &[PrimRef]) -> (Box4, Box4) {
    let one = |refs: &[PrimRef]| {
        let (mut b, mut c) = (Box4::EMPTY, Box4::EMPTY);
        for r in refs {
            b.grow(r.lo, r.hi);
            let cc = r.centroid2();
            c.grow(cc, cc);
        }
        (b, c)
    };
    if refs.len() >= 4 * BIN_CHUNK {
        refs.par_chunks(BIN_CHUNK)
            .map(one)
            .reduce(|| (Box4::EMPTY, Box4::EMPTY), |x, y| (x.0.union(y.0), x.1.union(y.1)))
    } else {
        one(refs)
    }
}

/// A binary BVH in a node array with one slot per possible node (`2n - 1`); unused slots
/// stay default. Slots are assigned by subtree size, so parallel subtrees never race and the
/// layout is independent of scheduling.
pub(super) struct Bvh2 {
    pub(super) nodes: Vec<Node2>,
    /// Primitive ids in leaf order.
    pub(super) ids: Vec<u32>,
}

/// Builds the binary tree over the hittable primitives (finite, non-empty bounds).
/// Progress is reported per subtree built on one thread, so the report costs nothing per node.
pub(super) fn build_bvh2(prim_bounds: &[Aabb], leaf: LeafCost, progress: &dyn Progress) -> Bvh2 {
    // Leaf positions stay below the child references' flags (`LEAF`, and `PAIR` for triangle
    // trees).
    assert!(
        prim_bounds.len() < PAIR as usize,
        "BVH supports fewer than 2^30 primitives"
    );
    let make = |(i, b): (usize, &Aabb)| {
        let ok = b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all();
        let (id_lo, id_hi) = ((i & 0xffff) as f32, (i >> 16) as f32);
        ok.then(|| PrimRef {
            lo: b.min.extend(id_lo),
            hi: b.max.extend(id_hi),
        })
    };
    let mut refs: Vec<PrimRef> = if prim_bounds.len() >= 4 * BIN_CHUNK {
        prim_bounds.par_iter().enumerate().filter_map(make).collect()
    } else {
        prim_bounds.iter().enumerate().filter_map(make).collect()
    };
    progress.advance((prim_bounds.len() - refs.len()) as u64);
    if refs.is_empty() {
        return Bvh2 {
            nodes: Vec::new(),
            ids: Vec::new(),
        };
    }
    let mut nodes = vec![Node2::default(); 2 * refs.len() - 1];
    let (bounds, cbounds) = range_bounds(&refs);
    build_node(&mut nodes, 0, &mut refs, 0, bounds, cbounds, 0, &leaf, progress);
    if refs.len() < PARALLEL_MIN {
        progress.advance(refs.len() as u64);
    }
    let ids = refs.iter().map(PrimRef::id).collect();
    Bvh2 { nodes, ids }
}

#[allow(clippy::too_many_arguments)]
fn build_node(
    nodes: &mut [Node2],
    node_base: u32,
    refs: &mut [PrimRef],
    prim_base: u32,
    bounds: Box4,
    cbounds: Box4,
    depth: u32,
    leaf_cost: &LeafCost,
    progress: &dyn Progress,
) {
    let n = refs.len();
    let max_leaf = leaf_cost.max_leaf;
    let leaf = Node2 {
        bounds,
        a: prim_base,
        b: 0,
        count: n as u32,
    };
    if n == 1 {
        nodes[0] = leaf;
        return;
    }
    let degenerate = (cbounds.hi - cbounds.lo).truncate().max_element() <= 0.0;
    let mut split_at = None;
    if n <= SWEEP_MAX && depth < MEDIAN_DEPTH {
        let (m, cost) = sweep_split(refs, leaf_cost);
        let split_cost = TRAVERSAL_COST + cost / bounds.half_area();
        if n <= max_leaf && (split_cost >= leaf_cost.of(n) || split_cost.is_nan()) {
            nodes[0] = leaf;
            return;
        }
        let (lr, rr) = refs.split_at(m);
        split_at = Some((m, range_bounds(lr), range_bounds(rr)));
    } else if depth < MEDIAN_DEPTH && !degenerate {
        let binner = Binner::new(&cbounds);
        let bins = if n >= 4 * BIN_CHUNK {
            refs.par_chunks(BIN_CHUNK)
                .map(|c| binner.fill(c))
                .reduce(Bins::new, |a, b| a.merge(&b))
        } else {
            binner.fill(refs)
        };
        if let Some(split) = best_split(&bins, leaf_cost) {
            let area = bounds.half_area();
            let split_cost = TRAVERSAL_COST + split.cost / area;
            // Also reached when the parent area is zero (cost NaN): then only size decides.
            if n <= max_leaf && (split_cost >= leaf_cost.of(n) || split_cost.is_nan()) {
                nodes[0] = leaf;
                return;
            }
            split_at = Some(partition(refs, |r| binner.bin(r.centroid2(), split.axis) < split.bin));
        }
    }
    let parallel = n >= PARALLEL_MIN;
    let (m, (lb, lc), (rb, rc)) = match split_at {
        Some(split) => split,
        None if n <= max_leaf => {
            nodes[0] = leaf;
            return;
        }
        None => {
            let m = median_split(refs, &cbounds);
            let (lr, rr) = refs.split_at_mut(m);
            let (l, r) = if parallel {
                rayon::join(|| range_bounds(lr), || range_bounds(rr))
            } else {
                (range_bounds(lr), range_bounds(rr))
            };
            (m, l, r)
        }
    };
    let (lr, rr) = refs.split_at_mut(m);
    let (root, rest) = nodes.split_first_mut().expect("slot for the node");
    let (ln, rn) = rest.split_at_mut(2 * m - 1);
    *root = Node2 {
        bounds,
        a: node_base + 1,
        b: node_base + 2 * m as u32,
        count: 0,
    };
    let mut left = move || build_node(ln, node_base + 1, lr, prim_base, lb, lc, depth + 1, leaf_cost, progress);
    let mut right = move || {
        build_node(
            rn,
            node_base + 2 * m as u32,
            rr,
            prim_base + m as u32,
            rb,
            rc,
            depth + 1,
            leaf_cost,
            progress,
        )
    };
    if parallel {
        // A child small enough to be built on one thread reports all its primitives at once.
        let report = |size: usize| {
            if size < PARALLEL_MIN {
                progress.advance(size as u64);
            }
        };
        rayon::join(
            || {
                left();
                report(m);
            },
            || {
                right();
                report(n - m);
            },
        );
    } else {
        left();
        right();
    }
}

/// Exact SAH over all object splits along each axis (for small nodes, where it is cheaper
/// than binning); leaves `refs` ordered for the best split and returns its left size and cost.
fn sweep_split(refs: &mut [PrimRef], leaf: &LeafCost) -> (usize, f32) {
    let n = refs.len();
    let mut best = (f32::INFINITY, 0, 1);
    let mut right_cost = [0.0f32; SWEEP_MAX];
    for axis in 0..3 {
        sort_axis(refs, axis);
        let mut acc = Box4::EMPTY;
        for i in (1..n).rev() {
            acc.grow(refs[i].lo, refs[i].hi);
            right_cost[i] = acc.half_area() * leaf.of(n - i);
        }
        let mut acc = Box4::EMPTY;
        for i in 1..n {
            acc.grow(refs[i - 1].lo, refs[i - 1].hi);
            let cost = acc.half_area() * leaf.of(i) + right_cost[i];
            // Ties (e.g. identical boxes) go to the most balanced split.
            let balance = |m: usize| m.abs_diff(n / 2);
            if cost < best.0 || (cost == best.0 && balance(i) < balance(best.2)) {
                best = (cost, axis, i);
            }
        }
    }
    sort_axis(refs, best.1);
    (best.2, best.0)
}

/// Sorts by centroid along `axis`, ties by id (deterministic).
fn sort_axis(refs: &mut [PrimRef], axis: usize) {
    refs.sort_unstable_by(|a, b| {
        a.centroid2()[axis]
            .total_cmp(&b.centroid2()[axis])
            .then(a.id().cmp(&b.id()))
    });
}

/// Moves references satisfying `left` to the front; returns how many there are, and the
/// bounds and centroid bounds of both sides (gathered here to save a pass over the data).
fn partition(refs: &mut [PrimRef], left: impl Fn(&PrimRef) -> bool) -> (usize, (Box4, Box4), (Box4, Box4)) {
    let (mut i, mut j) = (0, refs.len());
    let (mut lb, mut lc, mut rb, mut rc) = (Box4::EMPTY, Box4::EMPTY, Box4::EMPTY, Box4::EMPTY);
    while i < j {
        let r = refs[i];
        let c = r.centroid2();
        if left(&r) {
            lb.grow(r.lo, r.hi);
            lc.grow(c, c);
            i += 1;
        } else {
            rb.grow(r.lo, r.hi);
            rc.grow(c, c);
            j -= 1;
            refs.swap(i, j);
        }
    }
    (i, (lb, lc), (rb, rc))
}

/// Object median along the widest centroid axis (ties broken by id, so deterministic).
fn median_split(refs: &mut [PrimRef], cbounds: &Box4) -> usize {
    let e = (cbounds.hi - cbounds.lo).to_array();
    let axis = if e[0] >= e[1] && e[0] >= e[2] {
        0
    } else if e[1] >= e[2] {
        1
    } else {
        2
    };
    let m = refs.len() / 2;
    refs.select_nth_unstable_by(m, |a, b| {
        a.centroid2()[axis]
            .total_cmp(&b.centroid2()[axis])
            .then(a.id().cmp(&b.id()))
    });
    m
}

/// The traversal tree: wide nodes collapsed from the binary tree, and the leaf order with
/// the last primitive of each leaf flagged by `END`.
pub(super) struct Collapsed<const R: usize> {
    pub(super) nodes: Vec<Node<R>>,
    pub(super) order: Vec<u32>,
    pub(super) bounds: Aabb,
    /// Depth of the wide tree (root = 1).
    pub(super) depth: u32,
}

pub(super) fn collapse<const R: usize>(bvh2: Bvh2) -> Collapsed<R> {
    let Bvh2 { nodes: n2, mut ids } = bvh2;
    if n2.is_empty() {
        return Collapsed {
            nodes: Vec::new(),
            order: Vec::new(),
            bounds: Aabb::EMPTY,
            depth: 0,
        };
    }
    let mut out = Vec::with_capacity(n2.len() / 2 + 1);
    let depth = emit(&n2, 0, &mut out, &mut ids);
    Collapsed {
        nodes: out,
        order: ids,
        bounds: n2[0].bounds.to_aabb(),
        depth,
    }
}

/// Emits the wide node for binary node `i` and its subtree (pre-order); returns the depth.
fn emit<const R: usize>(n2: &[Node2], i: usize, out: &mut Vec<Node<R>>, ids: &mut [u32]) -> u32 {
    let width = Node::<R>::WIDTH;
    let mut kids = [0usize; MAX_WIDTH];
    let mut k;
    if n2[i].count > 0 {
        // Only a leaf root gets here.
        kids[0] = i;
        k = 1;
    } else {
        kids[0] = n2[i].a as usize;
        kids[1] = n2[i].b as usize;
        k = 2;
        // Open the inner child with the largest area until the node is full.
        while k < width {
            let best = (0..k)
                .filter(|&s| n2[kids[s]].count == 0)
                .fold(None, |best: Option<usize>, s| match best {
                    Some(b) if n2[kids[b]].bounds.half_area() >= n2[kids[s]].bounds.half_area() => Some(b),
                    _ => Some(s),
                });
            let Some(s) = best else { break };
            let node = n2[kids[s]];
            kids.copy_within(s + 1..k, s + 2);
            kids[s] = node.a as usize;
            kids[s + 1] = node.b as usize;
            k += 1;
        }
    }
    let me = out.len();
    out.push(Node::EMPTY);
    let mut depth = 1;
    for (slot, &kid) in kids[..k].iter().enumerate() {
        let node = &n2[kid];
        let child = if node.count > 0 {
            ids[(node.a + node.count - 1) as usize] |= END;
            LEAF | node.a
        } else {
            let index = out.len() as u32;
            depth = depth.max(1 + emit(n2, kid, out, ids));
            index
        };
        out[me].set_child(slot, node.bounds.lo.truncate(), node.bounds.hi.truncate(), child);
    }
    depth
}
