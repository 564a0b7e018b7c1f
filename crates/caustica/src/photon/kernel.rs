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
use crate::math::Vec3;
use crate::scene::{Scene, SurfaceHit};
use rayon::prelude::*;
use std::f32::consts::PI;

/// Each photon's kernel radius (in tree order): the distance to its k-th nearest photon whose
/// surface faces within `min_normal_cosine` of its own, or `max_radius` when there are fewer
/// than k that near.
pub(super) fn kernel_radii(
    tree: &KdTree,
    photons: &[Photon],
    k: usize,
    max_radius: f32,
    min_normal_cosine: f32,
) -> Vec<f32> {
    let max2 = max_radius * max_radius;
    photons
        .par_iter()
        .map_init(Vec::new, |out: &mut Vec<Neighbor>, photon| {
            let (code, normal) = (photon.normal_code(), photon.normal());
            let same_surface = |q: &Photon| q.normal_code() == code || q.normal().dot(normal) >= min_normal_cosine;
            let r2 = tree.k_nearest_where(photons, photon.position, k, max2, same_surface, out);
            r2.sqrt().min(max_radius)
        })
        .collect()
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
    reach: &Reach,
    photons: &[Photon],
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
    // The photons on this surface whose kernel (widened to the floor) holds the point.
    candidates.clear();
    let mut widest = 0.0f32;
    let mut narrowest = f32::INFINITY;
    tree.for_each_reaching(reach, photons, point, floor, |slot, dist2| {
        let photon = &photons[slot as usize];
        let r = reach.radius(slot).max(floor);
        if dist2 >= r * r || (photon.position - point).dot(n).abs() > gather.max_plane_distance * r {
            return;
        }
        if photon.normal().dot(n) < gather.min_normal_cosine {
            return;
        }
        widest = widest.max(r);
        narrowest = narrowest.min(r);
        candidates.push(Neighbor { slot, dist2 });
    });
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
        let f = reflectance(-photon.direction());
        if f == Vec3::ZERO {
            continue;
        }
        if !occluders.is_empty() && !scene.segment_clear_of(&occluders, point, n, photon.position, photon.normal()) {
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
