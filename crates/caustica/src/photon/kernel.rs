//! The course model's default radiance estimate: every photon spread over a kernel of its own
//! width, the distance to its k-th nearest photon on the same surface, measured once per
//! kd-tree leaf (a variable-kernel, or sample-point, density estimate: Breiman, Meisel &
//! Purcell 1977; Silverman 1986, §5.3).
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
use crate::math::Vec3;
use crate::scene::{Scene, SurfaceHit};
use rayon::prelude::*;
use std::f32::consts::PI;

/// Each photon's kernel radius (in tree order): about the distance to its k-th nearest photon
/// whose surface faces within `min_normal_cosine` of its own (`max_radius` at most).
///
/// Searched once per leaf and surface, not per photon (exact radii, one search each, were a
/// tenth of the original's worst case): a representative, the leaf-mate nearest the leaf's
/// centre (or the first on another surface: normals apart by more than [`SHARE_COSINE`]), is
/// searched, and each photon's radius is blended from the representatives of its leaf and
/// the leaves beside it in tree order ([`blended`]). The k-th distance changes by at most the
/// distance moved (the triangle inequality), so each radius stays within its leaf's size of
/// its own, and a leaf holds at most 16 of the k photons a kernel spans: a small part of the
/// radius, where the k-th distance is itself noisy (about 1/(2√k) relative: 5% at k = 100).
pub(super) fn kernel_radii(
    tree: &KdTree,
    photons: &[Photon],
    k: usize,
    max_radius: f32,
    min_normal_cosine: f32,
) -> Vec<f32> {
    let max2 = max_radius * max_radius;
    let cells = tree.leaf_cells();
    let search = |photon: &Photon, neighbors: &mut Vec<Neighbor>| {
        let (code, normal) = (photon.normal_code(), photon.normal());
        let same = |q: &Photon| q.normal_code() == code || q.normal().dot(normal) >= min_normal_cosine;
        let r2 = tree.k_nearest_where(photons, photon.position, k, max2, same, neighbors);
        r2.sqrt().min(max_radius)
    };
    if k < SHARE_MIN_K {
        return photons
            .par_iter()
            .map_init(Vec::new, |neighbors, photon| search(photon, neighbors))
            .collect();
    }
    let reps: Vec<Vec<Rep>> = cells
        .par_iter()
        .map_init(Vec::new, |neighbors, (range, lo, hi)| {
            let leaf = &photons[range.clone()];
            let centre = (Vec3::from(*lo) + Vec3::from(*hi)) * 0.5;
            representatives(leaf, centre, |p| search(p, neighbors))
        })
        .collect();
    let per_leaf: Vec<Vec<f32>> = (0..cells.len())
        .into_par_iter()
        .map(|j| {
            let near = &reps[j.saturating_sub(BLEND_LEAVES)..(j + BLEND_LEAVES + 1).min(reps.len())];
            photons[cells[j].0.clone()]
                .iter()
                .map(|photon| blended(photon, near.iter().flatten(), max_radius))
                .collect()
        })
        .collect();
    per_leaf.concat()
}

/// Leaves each side (in tree order, so nearby) whose representatives a photon's radius blends.
const BLEND_LEAVES: usize = 2;

/// A photon searched for its leaf-mates on its surface.
struct Rep {
    code: [u8; 2],
    normal: Vec3,
    position: Vec3,
    radius: f32,
}

impl Rep {
    fn shares(&self, code: [u8; 2], normal: Vec3) -> bool {
        self.code == code || self.normal.dot(normal) >= SHARE_COSINE
    }
}

/// The radius of `photon` from the representatives around it on its surface. Each bounds it
/// to its own radius ± their distance (the triangle inequality; none above `max_radius`). Where
/// the bounds meet tightly (within half the nearest one's radius) it is the middle of them, so
/// widths blend from leaf to leaf: one width shared by a whole leaf left clumps of narrow
/// kernels as bright spots (1.77 × the mean glow, against 1.33 with each photon's own). Where
/// they say little (representatives far apart for their radii, or at the cap), it is the
/// nearest one's radius, kept within the bounds.
fn blended<'a>(photon: &Photon, reps: impl Iterator<Item = &'a Rep>, max_radius: f32) -> f32 {
    let (code, normal) = (photon.normal_code(), photon.normal());
    let (mut lo, mut hi) = (0.0f32, max_radius);
    let mut nearest = (f32::INFINITY, 0.0);
    for rep in reps.filter(|r| r.shares(code, normal)) {
        let d = rep.position.distance(photon.position);
        lo = lo.max(rep.radius - d);
        hi = hi.min(rep.radius + d);
        if d < nearest.0 {
            nearest = (d, rep.radius);
        }
    }
    let lo = lo.min(hi);
    if hi - lo <= 0.5 * nearest.1 {
        0.5 * (lo + hi)
    } else {
        nearest.1.clamp(lo, hi)
    }
}

/// The leaf's representatives: the photon nearest `centre`, searched, then each photon on no
/// surface of one found before, searched.
fn representatives(leaf: &[Photon], centre: Vec3, mut search: impl FnMut(&Photon) -> f32) -> Vec<Rep> {
    let mut by_centre: Vec<usize> = (0..leaf.len()).collect();
    by_centre.sort_by(|&a, &b| {
        let (da, db) = (
            leaf[a].position.distance_squared(centre),
            leaf[b].position.distance_squared(centre),
        );
        da.total_cmp(&db).then(a.cmp(&b))
    });
    let mut reps: Vec<Rep> = Vec::new();
    for i in by_centre {
        let photon = &leaf[i];
        let (code, normal) = (photon.normal_code(), photon.normal());
        if !reps.iter().any(|r| r.shares(code, normal)) {
            reps.push(Rep {
                code,
                normal,
                position: photon.position,
                radius: search(photon),
            });
        }
    }
    reps
}

/// Least k for which radii are blended from representatives: a leaf holds up to 16 photons, a
/// sixth of the k a kernel spans at k = 100 (radii then move by about 3% on average, measured in
/// the tests), but most of them where k is 10 or 3, so small k searches each photon.
pub(super) const SHARE_MIN_K: usize = 4 * super::kd_tree::LEAF_MAX;

/// Leaf-mates whose normals are this close share a representative (about 8 degrees: the
/// neighbours each counts are then the same, far inside any `min_normal_cosine` in use).
pub(super) const SHARE_COSINE: f32 = 0.99;

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
    let segments = (!occluders.is_empty()).then(|| scene.segments_from(&occluders, point, n));
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
        if segments
            .as_ref()
            .is_some_and(|s| !s.clear_to(photon.position, kernels.normals[nb.slot as usize]))
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

    /// Each photon's own k-th distance on its surface, from the tree.
    fn exact_radii(tree: &KdTree, p: &[Photon], k: usize, max_radius: f32) -> Vec<f32> {
        let mut out = Vec::new();
        p.iter()
            .map(|photon| {
                let (code, normal) = (photon.normal_code(), photon.normal());
                let same = |q: &Photon| q.normal_code() == code || q.normal().dot(normal) >= 0.7;
                tree.k_nearest_where(p, photon.position, k, max_radius * max_radius, same, &mut out)
                    .sqrt()
                    .min(max_radius)
            })
            .collect()
    }

    #[test]
    fn shared_radii_stay_within_a_leaf_of_each_photons_own() {
        for mut p in [photons(20_000), crossing(20_000)] {
            let tree = KdTree::build(&mut p);
            let cells = tree.leaf_cells();
            for (k, max_radius) in [(1, 0.3), (3, 0.3), (10, 0.05), (100, 0.2), (100, 0.01), (400, 10.0)] {
                let shared = kernel_radii(&tree, &p, k, max_radius, 0.7);
                let exact = exact_radii(&tree, &p, k, max_radius);
                let mut relative = 0.0f64;
                for (range, lo, hi) in &cells {
                    let (lo, hi) = (Vec3::from(*lo), Vec3::from(*hi));
                    // Each lies where its own leaf's representative bounds it: within the leaf's size.
                    let size = (hi - lo).length();
                    for i in range.clone() {
                        let off = (shared[i] - exact[i]).abs();
                        assert!(
                            off <= size * (1.0 + 1e-5) + 1e-6,
                            "k {k}, photon {i}: {off} past leaf {size}"
                        );
                        if exact[i] > 0.0 {
                            relative += f64::from(off / exact[i]);
                        }
                    }
                }
                let mean = relative / p.len() as f64;
                // Measured: 3.2–3.4% at k = 100 and max 0.2, 1.3–3.8% at k = 100 and max 0.01,
                // 1.3–2.2% at k = 400.
                assert!(mean < 0.05, "k {k}, max {max_radius}: mean relative change {mean}");
                if k < SHARE_MIN_K {
                    assert_eq!(mean, 0.0, "k {k}: each photon searched");
                }
            }
        }
    }
}
