//! The course model's default radiance estimate: every photon spread over a kernel of its own
//! width, the distance to its k-th nearest photon on the same surface (a variable-kernel, or
//! sample-point, density estimate: Breiman, Meisel & Purcell 1977; Silverman 1986, §5.3).
//!
//! ```text
//! L(x, ωo) ≈ Σ_p f(x, ωo, ωp) Φp K(|x − xp|, rp),   K(d, r) = (1 − d/(c r)) / (π r² (1 − 2/(3c)))
//! ```
//!
//! K is Jensen's cone filter normalised over the disc of radius r (a box, 1/(π r²), without the
//! filter), so each photon adds exactly its power to the picture whatever its width. Where
//! photons are sparse their kernels are wide and overlap into a smooth, low glow; where they are
//! dense the kernels are narrow, so a caustic keeps its sharp edge and throws no halo around it
//! (a k-nearest gather there reaches out to the bright photons from far outside). About k
//! kernels overlap at any point, the count a k-nearest estimate averages.
//!
//! No kernel is narrower than `min_radius` at the gather (half a pixel where the camera sees
//! it): more photons then average into each pixel and the noise keeps falling as the photon count
//! grows, instead of turning into per-pixel grain. None is wider than the largest radius.

use super::kd_tree::{KdTree, Neighbor, Reach};
use super::Photon;
use crate::math::{Vec3, Vec4};
use crate::scene::{Scene, SurfaceHit};
use rayon::prelude::*;
use std::f32::consts::PI;

/// Each photon's kernel radius (in tree order): the distance to its k-th nearest photon whose
/// surface faces within `min_normal_cosine` of its own, or `max_radius` when there are fewer
/// than k that near.
///
/// Computed a leaf at a time: the photon nearest the leaf's centre is searched in the tree, and
/// its radius bounds its leaf-mates' (the triangle inequality), so one ball query around the leaf
/// gathers every candidate its photons need. Each result is the tree's own to the bit: a photon
/// whose k-th neighbour the gathered ball does not surely hold is searched in the tree.
pub(super) fn kernel_radii(
    tree: &KdTree,
    photons: &[Photon],
    normals: &[Vec3],
    k: usize,
    max_radius: f32,
    min_normal_cosine: f32,
) -> Vec<f32> {
    let max2 = max_radius * max_radius;
    let cells = tree.leaf_cells();
    let per_leaf: Vec<Vec<f32>> = cells
        .par_iter()
        .map_init(LeafScratch::default, |scratch, (range, lo, hi)| {
            leaf_radii(
                tree,
                (photons, normals),
                range.clone(),
                (*lo, *hi),
                k,
                max2,
                min_normal_cosine,
                scratch,
            )
            .into_iter()
            .map(|r2| r2.sqrt().min(max_radius))
            .collect()
        })
        .collect();
    per_leaf.concat()
}

/// A relative margin far above f32 rounding that keeps every coverage and band test on the safe
/// side.
const MARGIN: f32 = 1e-4;

/// Buffers one thread reuses from leaf to leaf.
#[derive(Default)]
struct LeafScratch {
    neighbors: Vec<Neighbor>,
    /// Gathered candidates: position, normal code and normal.
    candidates: Vec<(Vec3, [u8; 2], Vec3)>,
    /// Their coordinates by axis, padded to whole lanes with far-away points, for the band scan.
    lanes: [Vec<f32>; 3],
    /// Which candidates lie on the surface of the normal code `same_code` (1 or 0, padded).
    same: Vec<f32>,
    same_code: Option<[u8; 2]>,
    dist2: Vec<f32>,
}

/// Candidates the band scan tests at once.
const LANES: usize = 4;

impl LeafScratch {
    /// Lays the gathered candidates out for the band scan.
    fn lay_out(&mut self) {
        for (axis, lane) in self.lanes.iter_mut().enumerate() {
            lane.clear();
            lane.extend(self.candidates.iter().map(|c| c.0[axis]));
            // Padding no band holds: +inf away (and never NaN).
            lane.resize(self.candidates.len().div_ceil(LANES) * LANES, f32::INFINITY);
        }
        self.same_code = None;
    }

    /// Marks the candidates on the surface of a photon with `code` and `normal`.
    fn mark_same(&mut self, code: [u8; 2], normal: Vec3, min_normal_cosine: f32) {
        if self.same_code == Some(code) {
            return;
        }
        self.same.clear();
        self.same.extend(self.candidates.iter().map(|&(_, c, n)| {
            if c == code || n.dot(normal) >= min_normal_cosine {
                1.0
            } else {
                0.0
            }
        }));
        self.same.resize(self.lanes[0].len(), 0.0);
        self.same_code = Some(code);
    }
}

/// The squared kernel radii of the photons of one leaf.
#[allow(clippy::too_many_arguments)]
fn leaf_radii(
    tree: &KdTree,
    (photons, normals): (&[Photon], &[Vec3]),
    range: std::ops::Range<usize>,
    (lo, hi): ([f32; 3], [f32; 3]),
    k: usize,
    max2: f32,
    min_normal_cosine: f32,
    scratch: &mut LeafScratch,
) -> Vec<f32> {
    let same_surface = |code: [u8; 2], normal: Vec3, q: &Photon| {
        q.normal_code() == code || q.normal().dot(normal) >= min_normal_cosine
    };
    let tree_search = |photon: &Photon, out: &mut Vec<Neighbor>| {
        let (code, normal) = (photon.normal_code(), photon.normal());
        tree.k_nearest_where(
            photons,
            photon.position,
            k,
            max2,
            |q| same_surface(code, normal, q),
            out,
        )
    };
    let leaf = &photons[range];
    let (lo, hi) = (Vec3::from(lo), Vec3::from(hi));
    let finite = leaf.iter().all(|p| p.position.is_finite());
    if leaf.len() <= 1 || !finite || !(lo.cmple(hi).all()) || k == 0 {
        return leaf.iter().map(|p| tree_search(p, &mut scratch.neighbors)).collect();
    }
    // The photon nearest the leaf's centre is searched in the tree: its radius bounds its
    // leaf-mates' (each within it ± their distance) most tightly, so the ball around the leaf
    // that surely holds every photon's k-th neighbour is the smallest.
    let centre = (lo + hi) * 0.5;
    let first = (0..leaf.len())
        .min_by(|&a, &b| {
            leaf[a]
                .position
                .distance_squared(centre)
                .total_cmp(&leaf[b].position.distance_squared(centre))
        })
        .unwrap_or(0);
    let r0 = tree_search(&leaf[first], &mut scratch.neighbors).sqrt();
    let max_radius = max2.sqrt();
    let x0 = leaf[first].position;
    let reach = leaf
        .iter()
        .map(|p| (p.position - centre).length() + (r0 + p.position.distance(x0)).min(max_radius))
        .fold(0.0f32, f32::max)
        * (1.0 + 3.0 * MARGIN);
    scratch.candidates.clear();
    tree.for_each_within(photons, centre, reach * reach, |slot, _| {
        let q = &photons[slot as usize];
        scratch
            .candidates
            .push((q.position, q.normal_code(), normals[slot as usize]));
    });
    scratch.lay_out();
    let mut done: Vec<Option<f32>> = vec![None; leaf.len()];
    done[first] = Some(r0);
    let mut radii = vec![0.0; leaf.len()];
    radii[first] = r0 * r0;
    for (i, photon) in leaf.iter().enumerate() {
        if i == first {
            continue;
        }
        // The ball around this photon that the gathered candidates surely cover.
        let covered = reach - (photon.position - centre).length() - MARGIN * reach;
        // Each leaf-mate done on the same surface (the same normal code, so the same photons
        // count for both) bounds this one's radius to its own ± their distance: the band is
        // where all those bounds meet.
        let band = (0..leaf.len())
            .filter_map(|j| {
                let r = done[j]?;
                (leaf[j].normal_code() == photon.normal_code()).then(|| {
                    let e = leaf[j].position.distance(photon.position);
                    (r - e, r + e)
                })
            })
            .reduce(|(a, b), (c, d)| (a.max(c), b.min(d)));
        let r2 = band
            .and_then(|(inner, outer)| band_kth(photon, (inner, outer), covered, k, max2, min_normal_cosine, scratch))
            .or_else(|| covered_kth(photon, covered, k, max2, min_normal_cosine, scratch));
        let r2 = r2.unwrap_or_else(|| tree_search(photon, &mut scratch.neighbors));
        done[i] = Some(r2.sqrt());
        radii[i] = r2;
    }
    radii
}

/// The k-th squared distance from `photon` among the gathered candidates on its surface, when
/// it lies between `inner` and `outer`: those nearer are counted and only those between ranked.
/// `None` when the band does not hold the k-th, or reaches past what the candidates cover.
#[allow(clippy::too_many_arguments)]
fn band_kth(
    photon: &Photon,
    (inner, outer): (f32, f32),
    covered: f32,
    k: usize,
    max2: f32,
    min_normal_cosine: f32,
    scratch: &mut LeafScratch,
) -> Option<f32> {
    let outer = outer * (1.0 + MARGIN);
    if outer.is_nan() || outer >= covered || k == 0 {
        return None;
    }
    let inner = inner * (1.0 - MARGIN);
    let inner2 = if inner > 0.0 { inner * inner } else { -1.0 };
    let outer2 = (outer * outer).min(max2);
    scratch.mark_same(photon.normal_code(), photon.normal(), min_normal_cosine);
    let [px, py, pz] = photon.position.to_array().map(Vec4::splat);
    let (inner2, outer2) = (Vec4::splat(inner2), Vec4::splat(outer2));
    let band = &mut scratch.dist2;
    band.clear();
    // Room for a whole chunk past the last in-band candidate: every lane is written.
    band.resize(scratch.same.len() + LANES, 0.0);
    let (mut nearer, mut in_band) = (0usize, 0usize);
    let [xs, ys, zs] = &scratch.lanes;
    let lanes = xs
        .chunks_exact(LANES)
        .zip(ys.chunks_exact(LANES))
        .zip(zs.chunks_exact(LANES));
    // Four candidates at a time in glam's Vec4 (vector registers where the target has them),
    // rounded as `KdTree::dist2` rounds.
    for (((x, y), z), same) in lanes.zip(scratch.same.chunks_exact(LANES)) {
        let (dx, dy, dz) = (
            Vec4::from_slice(x) - px,
            Vec4::from_slice(y) - py,
            Vec4::from_slice(z) - pz,
        );
        let d2 = dx * dx + dy * dy + dz * dz;
        let same = Vec4::from_slice(same).cmpeq(Vec4::ONE);
        nearer += ONES[(same & d2.cmplt(inner2)).bitmask() as usize] as usize;
        let inside = (same & d2.cmpge(inner2) & d2.cmple(outer2)).bitmask();
        // Every lane is written and the end moves past those in the band: no branch on which
        // (a branch per lane mispredicted at about every other chunk).
        for lane in 0..LANES {
            band[in_band] = d2[lane];
            in_band += ((inside >> lane) & 1) as usize;
        }
    }
    if nearer >= k || nearer + in_band < k {
        return None;
    }
    let (_, kth, _) = band[..in_band].select_nth_unstable_by(k - 1 - nearer, f32::total_cmp);
    Some(*kth)
}

/// Set bits in each 4-bit mask.
const ONES: [u8; 16] = [0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4];

/// The k-th squared distance from `photon` among all the gathered candidates on its surface
/// (`max2` when fewer than k lie within it), or `None` when they may not hold it.
fn covered_kth(
    photon: &Photon,
    covered: f32,
    k: usize,
    max2: f32,
    min_normal_cosine: f32,
    scratch: &mut LeafScratch,
) -> Option<f32> {
    let max_radius = max2.sqrt();
    let (code, normal) = (photon.normal_code(), photon.normal());
    scratch.dist2.clear();
    for &(position, c, n) in &scratch.candidates {
        if c == code || n.dot(normal) >= min_normal_cosine {
            let d2 = KdTree::dist2(position, photon.position);
            if d2 <= max2 {
                scratch.dist2.push(d2);
            }
        }
    }
    let everything = covered > max_radius * (1.0 + MARGIN);
    if scratch.dist2.len() >= k && k > 0 {
        let (_, kth, _) = scratch.dist2.select_nth_unstable_by(k - 1, f32::total_cmp);
        let kth = *kth;
        (everything || (covered > 0.0 && kth < covered * covered)).then_some(kth)
    } else {
        everything.then_some(max2)
    }
}

/// The kernels over a photon map: each photon's radius with the tree's reach over them, and the
/// photons' normals and incoming directions decoded once, in tree order (an estimate visits a
/// hundred kernels, and decoding them at every visit was a third of its time).
pub(super) struct Kernels {
    pub reach: Reach,
    /// Unit normals, per photon.
    normals: Vec<Vec3>,
    /// The directions the light came from (toward where it came from), per photon.
    incoming: Vec<Vec3>,
}

impl Kernels {
    /// Kernels of `radii` over `photons` with their decoded `normals` (all in tree order).
    pub fn new(tree: &KdTree, photons: &[Photon], normals: Vec<Vec3>, radii: Vec<f32>) -> Kernels {
        Kernels {
            reach: tree.reach(photons, radii),
            normals,
            incoming: photons.iter().map(|p| -p.direction()).collect(),
        }
    }

    /// Heap bytes they own.
    pub fn heap_bytes(&self) -> usize {
        self.reach.heap_bytes() + (self.normals.capacity() + self.incoming.capacity()) * std::mem::size_of::<Vec3>()
    }
}

/// The leaves around the last few points estimated on one thread, each list good for any point
/// within its `delta` and any floor up to its own: the samples of a pixel, and of the pixels
/// next to it, share one descent of the tree (it was two thirds of an estimate's visits).
#[derive(Default)]
pub(super) struct NearLeaves {
    entries: Vec<NearEntry>,
    next: usize,
}

struct NearEntry {
    /// [`super::map::PhotonMap`]'s identity: the lists belong to one map's tree.
    map: u64,
    centre: Vec3,
    delta: f32,
    floor: f32,
    slots: Vec<u32>,
}

/// Lists kept per thread: a camera path's points at its first few depths.
const NEAR_ENTRIES: usize = 4;
/// How far around its point a list serves, in floors (half a pixel each): three pixels, so a
/// list serves a pixel's samples and its neighbours' (the original's ring rendered in 1.12 s
/// with 2 floors, 1.10 with 3, 1.08 with 6).
const NEAR_FLOORS: f32 = 6.0;
/// The widest floor a list serves, in floors of the point it was made for (the floor grows
/// with the camera distance, a little across a pixel).
const NEAR_FLOOR_SLACK: f32 = 1.25;

impl NearLeaves {
    /// The leaves an estimate at `p` with `floor` visits, from a list made nearby or a new one.
    fn slots(&mut self, map: u64, tree: &KdTree, (reach, photons): (&Reach, &[Photon]), p: Vec3, floor: f32) -> &[u32] {
        let found = self
            .entries
            .iter()
            .position(|e| e.map == map && floor <= e.floor && p.distance(e.centre) <= e.delta);
        let i = match found {
            Some(i) => i,
            None => {
                let entry = NearEntry {
                    map,
                    centre: p,
                    delta: NEAR_FLOORS * floor,
                    floor: NEAR_FLOOR_SLACK * floor,
                    slots: Vec::new(),
                };
                let i = if self.entries.len() < NEAR_ENTRIES {
                    self.entries.push(entry);
                    self.entries.len() - 1
                } else {
                    let i = self.next;
                    self.next = (self.next + 1) % NEAR_ENTRIES;
                    let slots = std::mem::take(&mut self.entries[i].slots);
                    self.entries[i] = NearEntry { slots, ..entry };
                    i
                };
                let e = &mut self.entries[i];
                tree.reaching_near(reach, photons, e.centre, e.floor, e.delta, &mut e.slots);
                i
            }
        };
        &self.entries[i].slots
    }
}

/// How one estimate gathers.
pub(super) struct Gather<'a> {
    pub scene: &'a Scene,
    pub hit: &'a SurfaceHit,
    /// Unit normal on the side the point is seen from.
    pub n: Vec3,
    /// Least kernel radius here.
    pub min_radius: f32,
    /// Largest kernel radius.
    pub max_radius: f32,
    pub cone_filter: Option<f32>,
    pub min_normal_cosine: f32,
    pub max_plane_distance: f32,
}

/// Σ f(ωp) Φp K(|x − xp|, rp) over the photons whose kernel reaches the point and that lie on
/// its surface and in its sight, and the narrowest kernel among them (0 when none).
pub(super) fn estimate(
    gather: &Gather,
    tree: &KdTree,
    kernels: &Kernels,
    photons: &[Photon],
    (map, near): (u64, &mut NearLeaves),
    candidates: &mut Vec<Neighbor>,
    reflectance: impl Fn(Vec3) -> Vec3,
) -> (Vec3, f32) {
    let Gather {
        scene,
        hit,
        n,
        min_radius,
        max_radius,
        ..
    } = *gather;
    let point = hit.point;
    let floor = min_radius.min(max_radius);
    let reach = &kernels.reach;
    // The photons on this surface whose kernel (widened to the floor) holds the point.
    candidates.clear();
    let mut widest = 0.0f32;
    let mut narrowest = f32::INFINITY;
    let mut accept = |slot, dist2| {
        let photon = &photons[slot as usize];
        let r = reach.radius(slot).max(floor);
        if dist2 >= r * r || (photon.position - point).dot(n).abs() > gather.max_plane_distance * r {
            return;
        }
        if kernels.normals[slot as usize].dot(n) < gather.min_normal_cosine {
            return;
        }
        widest = widest.max(r);
        narrowest = narrowest.min(r);
        candidates.push(Neighbor { slot, dist2 });
    };
    if floor > 0.0 && floor.is_finite() {
        let slots = near.slots(map, tree, (reach, photons), point, floor);
        tree.for_each_reaching_among(reach, photons, slots, point, floor, &mut accept);
    } else {
        tree.for_each_reaching(reach, photons, point, floor, &mut accept);
    }
    if candidates.is_empty() {
        return (Vec3::ZERO, 0.0);
    }
    let occluders = scene.occluders_near(point, widest, hit.prim);
    let normalisation = match gather.cone_filter {
        Some(c) => 1.0 - 2.0 / (3.0 * c),
        None => 1.0,
    };
    let mut sum = Vec3::ZERO;
    for nb in candidates.iter() {
        let photon = &photons[nb.slot as usize];
        let f = reflectance(kernels.incoming[nb.slot as usize]);
        if f == Vec3::ZERO {
            continue;
        }
        if !occluders.is_empty()
            && !scene.segment_clear_of(&occluders, point, n, photon.position, kernels.normals[nb.slot as usize])
        {
            continue;
        }
        let r = reach.radius(nb.slot).max(floor);
        let weight = match gather.cone_filter {
            Some(c) => (1.0 - nb.dist2.sqrt() / (c * r)).max(0.0),
            None => 1.0,
        };
        sum += f * photon.power() * (weight / (PI * r * r * normalisation));
    }
    (sum, narrowest)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Photons on two facing walls and a floor, clustered and sparse, with normals that vary
    /// within a surface: leaves mix surfaces, densities and predicates.
    fn photons(n: usize) -> Vec<Photon> {
        let mut state = 7u64;
        let mut next = move || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            (state >> 40) as f32 / (1u64 << 24) as f32
        };
        (0..n)
            .map(|i| {
                let (u, v, w) = (next(), next(), next());
                let (u, v) = if i % 3 == 0 {
                    (0.5 + 0.05 * u, 0.5 + 0.05 * v)
                } else {
                    (u, v)
                };
                let (position, normal) = match i % 4 {
                    0 => (Vec3::new(u, 0.0, v), Vec3::new(0.2 * w, 1.0, 0.0)),
                    1 => (Vec3::new(0.0, u, v), Vec3::X),
                    2 => (Vec3::new(u, v, 0.001 * w), Vec3::new(0.0, 0.5 * w, 1.0)),
                    _ => (Vec3::new(1.0, u, v), -Vec3::X),
                };
                Photon::new(position, Vec3::ONE, -normal, normal.normalize(), 0)
            })
            .collect()
    }

    /// A dense surface and a sparse one crossing it at right angles through the same points:
    /// leaf-mates whose neighbours lie far apart.
    fn crossing(n: usize) -> Vec<Photon> {
        let mut p = photons(n);
        for (i, photon) in p.iter_mut().enumerate() {
            let normal = if i % 10 == 0 { Vec3::X } else { Vec3::Y };
            let at = Vec3::new(photon.position.x, 0.0, photon.position.z);
            *photon = Photon::new(at, Vec3::ONE, -normal, normal, 0);
        }
        p
    }

    #[test]
    fn leaf_batched_radii_are_the_trees_own_to_the_bit() {
        for mut p in [photons(20_000), crossing(20_000)] {
            let tree = KdTree::build(&mut p);
            for (k, max_radius) in [(1, 0.3), (3, 0.3), (10, 0.05), (100, 0.2), (100, 0.01), (400, 10.0)] {
                let normals: Vec<Vec3> = p.iter().map(Photon::normal).collect();
                let batched = kernel_radii(&tree, &p, &normals, k, max_radius, 0.7);
                let mut out = Vec::new();
                for (i, photon) in p.iter().enumerate() {
                    let (code, normal) = (photon.normal_code(), photon.normal());
                    let same = |q: &Photon| q.normal_code() == code || q.normal().dot(normal) >= 0.7;
                    let r2 = tree.k_nearest_where(&p, photon.position, k, max_radius * max_radius, same, &mut out);
                    let expected = r2.sqrt().min(max_radius);
                    assert_eq!(
                        batched[i].to_bits(),
                        expected.to_bits(),
                        "k {k}, max {max_radius}, photon {i}"
                    );
                }
            }
        }
    }
}
