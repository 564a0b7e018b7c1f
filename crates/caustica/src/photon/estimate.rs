//! Radiance estimates from photons under the physical model, for a fixed radius (progressive
//! photon mapping) or the k nearest photons (Jensen's global and caustic maps):
//!
//! ```text
//! L(x, ωo) ≈ Σ_p f(x, ωo, ωp) Φp / (π r²)
//! ```
//!
//! with the same BSDF the camera paths use, evaluated for each photon's own incoming direction.
//! The gather is a disc: photons whose surface faces away from the receiver (the other side of
//! a thin wall, the next face at a corner) or that lie off its tangent plane do not count.

use super::kd_tree::{KdTree, Neighbor};
use super::Photon;
use crate::bsdf::Bsdf;
use crate::math::Vec3;
use std::cell::RefCell;
use std::f32::consts::PI;

/// Least cosine between a photon's stored normal and the receiver's.
const MIN_NORMAL_COSINE: f32 = 0.7;
/// Largest distance off the receiver's tangent plane, as a fraction of the radius.
const MAX_PLANE_DISTANCE: f32 = 0.25;

/// Photons in kd-tree order.
pub struct DensityMap {
    photons: Vec<Photon>,
    tree: KdTree,
}

thread_local! {
    static NEIGHBORS: RefCell<Vec<Neighbor>> = const { RefCell::new(Vec::new()) };
}

impl DensityMap {
    /// Builds the tree over `photons` (reordering them).
    pub fn new(mut photons: Vec<Photon>) -> DensityMap {
        let tree = KdTree::build(&mut photons);
        DensityMap { photons, tree }
    }

    /// Number of photons.
    pub fn len(&self) -> usize {
        self.photons.len()
    }

    /// Whether the map holds no photon.
    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// The photons, in tree order.
    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    #[inline]
    fn accepts(photon: &Photon, point: Vec3, n: Vec3, r: f32) -> bool {
        (photon.position - point).dot(n).abs() <= MAX_PLANE_DISTANCE * r && photon.normal().dot(n) >= MIN_NORMAL_COSINE
    }

    /// Reflected radiance at `point` towards `wo` from the photons within radius `r`.
    pub fn radiance_within(&self, point: Vec3, bsdf: &Bsdf, wo: Vec3, r: f32) -> Vec3 {
        if self.photons.is_empty() || r.is_nan() || r <= 0.0 {
            return Vec3::ZERO;
        }
        let n = bsdf.normal();
        let mut sum = Vec3::ZERO;
        self.tree.for_each_within(&self.photons, point, r * r, |slot, _| {
            let photon = &self.photons[slot as usize];
            if Self::accepts(photon, point, n, r) {
                sum += bsdf.eval(wo, -photon.direction()) * photon.power();
            }
        });
        sum / (PI * r * r)
    }

    /// Reflected radiance at `point` towards `wo` from the `k` nearest photons within
    /// `max_radius`, the radius being the distance to the k-th.
    pub fn radiance_nearest(&self, point: Vec3, bsdf: &Bsdf, wo: Vec3, k: usize, max_radius: f32) -> Vec3 {
        if self.photons.is_empty() || k == 0 || max_radius.is_nan() || max_radius <= 0.0 {
            return Vec3::ZERO;
        }
        let n = bsdf.normal();
        NEIGHBORS.with(|cell| {
            let mut neighbors = cell.borrow_mut();
            let r2 = self
                .tree
                .k_nearest(&self.photons, point, k, max_radius * max_radius, &mut neighbors);
            if neighbors.is_empty() || r2.is_nan() || r2 <= 0.0 {
                return Vec3::ZERO;
            }
            let r = r2.sqrt();
            let mut sum = Vec3::ZERO;
            // The k-th photon only marks the radius: counting it too would bias the density by
            // k / (k − 1) (the k-th nearest lies on the disc's rim, not inside it).
            let skip = usize::from(neighbors.len() == k && k > 1);
            for nb in neighbors.iter().skip(skip) {
                let photon = &self.photons[nb.slot as usize];
                if Self::accepts(photon, point, n, r) {
                    sum += bsdf.eval(wo, -photon.direction()) * photon.power();
                }
            }
            sum / (PI * r2)
        })
    }

    /// Twice the median distance to the k-th nearest photon around up to 256 photons spread
    /// through the map: a gather radius that holds about k photons where they are typical.
    pub fn typical_radius(&self, k: usize) -> f32 {
        2.0 * super::typical_knn_distance(&self.tree, &self.photons, k)
    }
}
