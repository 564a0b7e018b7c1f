//! How many light subpaths a pass traces against its camera paths.
//!
//! A pass's image is the camera strategies' estimate (emitters hit, next-event estimation), whose
//! noise does not depend on the light subpaths, plus light tracing's and merging's, whose noise
//! falls as one over their number `L`. For a pass of cost `c_C + c_L L`, the image's variance at
//! equal time, `(V_C + v / L) (c_C + c_L L)`, is least at `L = sqrt(v c_C / (V_C c_L))`: where
//! each side's share of the variance equals its share of the time. Where that lies differs by
//! two orders of magnitude between scenes (a Cornell box lit through a glass ball wants many
//! light subpaths a pixel, a pool seen through its water a few, a lens in the sun fewer than
//! one; measured: docs/benchmarks/2026-12-03.md, "Balanced passes"), so a pilot measures both
//! sides on the scene itself ([`super::Vcm`]).
//!
//! Merging's part grows as the radius shrinks pass by pass (a density estimate's variance goes
//! as one over the area it gathers from), so the pilot's merging variance, measured at the first
//! pass's radius, is weighed as it stands averaged over a run ([`merging_growth`]).

use crate::integrator::radius::radius_factor;

/// What the balance pilot measured at one pixel, in the image's units (the mean of R, G, B).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PixelSpread {
    /// The variance of one camera sample's estimate with the light subpaths held fixed.
    pub camera: f64,
    /// One light subpath's variance in light tracing's part (its splats on the film): the
    /// variance of the light subpaths' part times their number.
    pub traced: f64,
    /// The same for merging's part, at the first pass's radius.
    pub merged: f64,
    /// The two parts' covariance, on the same terms.
    pub covariance: f64,
    /// The pixel's value.
    pub mean: f64,
}

impl PixelSpread {
    /// One light subpath's variance where merging's is `growth` times the first pass's.
    pub fn light(&self, growth: f64) -> f64 {
        self.traced + growth * self.merged + 2.0 * growth.sqrt() * self.covariance
    }
}

/// How many times the first pass's merging variance merging's variance is, averaged over
/// passes `0..passes`: the radius's area shrinks by `radius_factor²`.
pub fn merging_growth(passes: u64, alpha: f32) -> f64 {
    let passes = passes.max(1);
    (0..passes)
        .map(|pass| 1.0 / (radius_factor(pass, alpha) as f64).powi(2))
        .sum::<f64>()
        / passes as f64
}

/// What a pass costs, in rays (a gathered light vertex counts as [`CANDIDATE_COST`] of one).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassCosts {
    /// The camera paths of a whole pass, less their merging.
    pub camera: f64,
    /// One light subpath: its rays, and the merging its vertices add to the camera paths.
    pub per_light_path: f64,
}

/// A gathered light vertex's cost in rays: a distance, a normal and a BSDF test, a weight.
/// Fitted to the balance pilot's own timings on seven scenes (docs/benchmarks/2026-12-03.md,
/// "Balanced passes"): a camera path's time is about one light ray's per ray it casts plus a
/// quarter of one per light vertex it gathers.
pub const CANDIDATE_COST: f64 = 0.25;

/// Pixels darker than this share of the image's mean count their noise against it rather than
/// against themselves, as a dark pixel's noise does not show as its relative error says.
const DARK_SHARE: f64 = 0.1;

/// The number of light subpaths a pass should trace, within `bounds` (least, most): the one
/// that minimises the sum over `pixels` of each pixel's relative variance at equal time, with
/// merging's variance `growth` times the pilot's. `None` when the pilot saw no noise at all on
/// one side (nothing to balance).
pub fn balanced_light_paths(pixels: &[PixelSpread], growth: f64, costs: PassCosts, bounds: (u64, u64)) -> Option<u64> {
    if pixels.is_empty() {
        return None;
    }
    let image_mean = pixels.iter().map(|p| p.mean.abs()).sum::<f64>() / pixels.len() as f64;
    let floor = (DARK_SHARE * image_mean).powi(2);
    let (mut camera, mut light) = (0.0, 0.0);
    for p in pixels {
        let scale = 1.0 / (p.mean * p.mean + floor).max(f64::MIN_POSITIVE);
        camera += scale * p.camera;
        light += scale * p.light(growth);
    }
    let (least, most) = bounds;
    if !(camera.is_finite() && light.is_finite() && costs.camera.is_finite() && costs.per_light_path.is_finite()) {
        return None;
    }
    if light <= 0.0 && camera <= 0.0 {
        return None;
    }
    if camera <= 0.0 || costs.per_light_path <= 0.0 {
        return Some(most);
    }
    if light <= 0.0 || costs.camera <= 0.0 {
        return Some(least);
    }
    let best = (light * costs.camera / (camera * costs.per_light_path)).sqrt();
    Some((best.round() as u64).clamp(least, most))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spread(camera: f64, light: f64) -> PixelSpread {
        PixelSpread {
            camera,
            traced: light,
            merged: 0.0,
            covariance: 0.0,
            mean: 1.0,
        }
    }

    /// The chosen count minimises (V_C + v/L)(c_C + c_L L) over every count in the bounds.
    #[test]
    fn the_count_minimises_the_variance_at_equal_time() {
        let pixels: Vec<PixelSpread> = (0..50)
            .map(|i| spread(0.5 + 0.01 * i as f64, 400.0 + i as f64))
            .collect();
        let costs = PassCosts {
            camera: 3000.0,
            per_light_path: 2.0,
        };
        let chosen = balanced_light_paths(&pixels, 1.0, costs, (1, 100_000)).unwrap();
        let (vc, vl): (f64, f64) = pixels
            .iter()
            .fold((0.0, 0.0), |(c, l), p| (c + p.camera, l + p.light(1.0)));
        let cost = |l: u64| (vc + vl / l as f64) * (costs.camera + costs.per_light_path * l as f64);
        let best = (1..100_000).min_by(|a, b| cost(*a).total_cmp(&cost(*b))).unwrap();
        assert!(chosen.abs_diff(best) <= 1, "chose {chosen}, the minimum is at {best}");
    }

    /// A dark pixel counts against the image's mean; the bounds hold; a side without noise
    /// takes the bound away from it.
    #[test]
    fn darkness_and_bounds() {
        let costs = PassCosts {
            camera: 100.0,
            per_light_path: 1.0,
        };
        assert_eq!(
            balanced_light_paths(&[spread(1.0, 100.0)], 1.0, costs, (1, 1000)),
            Some(100)
        );
        // A black pixel counts its noise against a tenth of the image's mean (here 0.05): its
        // light noise of 0.25 weighs as much as the bright pixel's 100.
        let dark = PixelSpread {
            mean: 0.0,
            ..spread(0.0, 0.25)
        };
        let with_dark = balanced_light_paths(&[spread(1.0, 100.0), dark], 1.0, costs, (1, 1000)).unwrap();
        assert!(with_dark.abs_diff(141) <= 1, "{with_dark}");
        assert_eq!(
            balanced_light_paths(&[spread(1.0, 100.0)], 1.0, costs, (150, 1000)),
            Some(150)
        );
        assert_eq!(
            balanced_light_paths(&[spread(0.0, 100.0)], 1.0, costs, (7, 1000)),
            Some(1000)
        );
        assert_eq!(
            balanced_light_paths(&[spread(1.0, 0.0)], 1.0, costs, (7, 1000)),
            Some(7)
        );
        assert_eq!(balanced_light_paths(&[spread(0.0, 0.0)], 1.0, costs, (7, 1000)), None);
        assert_eq!(balanced_light_paths(&[], 1.0, costs, (7, 1000)), None);
    }

    /// Over one pass the growth is one; over a run it follows the radius's shrinking, r² falling
    /// like pass^(α−1), so the mean of 1/r² grows like pass^(1−α) / (2 − α).
    #[test]
    fn merging_grows_as_the_radius_shrinks() {
        assert_eq!(merging_growth(1, 2.0 / 3.0), 1.0);
        assert_eq!(merging_growth(0, 2.0 / 3.0), 1.0);
        let g64 = merging_growth(64, 2.0 / 3.0);
        let g512 = merging_growth(512, 2.0 / 3.0);
        assert!(g64 > 2.0 && g64 < 4.0, "{g64}");
        // Eight times the passes: about 8^(1/3) = 2 times the growth.
        assert!((g512 / g64 - 2.0).abs() < 0.1, "{g64} {g512}");
        // α = 1 keeps the radius.
        assert!((merging_growth(64, 1.0) - 1.0).abs() < 1e-6);
    }

    /// Merging's variance weighs `growth` times; its covariance with light tracing's √growth
    /// times; a count chosen for merging alone grows by √growth.
    #[test]
    fn merging_variance_is_weighed_by_its_growth() {
        let p = PixelSpread {
            camera: 1.0,
            traced: 2.0,
            merged: 3.0,
            covariance: -0.5,
            mean: 1.0,
        };
        assert!((p.light(4.0) - (2.0 + 12.0 - 2.0)).abs() < 1e-12);
        let merging = PixelSpread {
            traced: 0.0,
            merged: 100.0,
            covariance: 0.0,
            ..p
        };
        let costs = PassCosts {
            camera: 100.0,
            per_light_path: 1.0,
        };
        assert_eq!(balanced_light_paths(&[merging], 1.0, costs, (1, 1000)), Some(100));
        assert_eq!(balanced_light_paths(&[merging], 4.0, costs, (1, 1000)), Some(200));
    }
}
