//! The gather radius of the photon-mapping integrators: where the first pass starts (a few
//! pixels' footprint at the gather point, or a fixed world radius) and how it shrinks pass by pass
//! (Knaus & Zwicker, "Progressive photon mapping: a probabilistic approach", TOG 2011).

use crate::camera::Camera;

/// How the first pass's gather radius is chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InitialRadius {
    /// This many pixels wide where the camera path meets the surface (its footprint), so the
    /// blur starts at a size the user sees and shrinks from there.
    Pixels(f32),
    /// A fixed radius in scene units.
    World(f32),
}

impl InitialRadius {
    /// The first pass's radius at a point `path_length` from the eye along the camera path,
    /// for pixels `pixel_angle` wide at unit distance.
    pub fn at(self, pixel_angle: f32, path_length: f32) -> f32 {
        match self {
            InitialRadius::Pixels(px) => px * pixel_angle * path_length,
            InitialRadius::World(r) => r,
        }
    }
}

/// Width of a pixel at unit distance from the eye, `height` pixels high.
pub fn pixel_angle(camera: &Camera, height: usize) -> f32 {
    camera.v.length() / camera.look.length().max(1e-30) / height.max(1) as f32
}

/// The radius factor of pass `pass` (0-based) in Knaus & Zwicker's progressive photon mapping:
/// r²ᵢ₊₁ = r²ᵢ (i + α) / (i + 1) for 1-based i, so r_pass = r_0 · √(Π_{k=1}^{pass} (k + α)/(k + 1)).
pub fn radius_factor(pass: u64, alpha: f32) -> f32 {
    let alpha = alpha as f64;
    let log = if pass <= DIRECT_PRODUCT_PASSES {
        (1..=pass).map(|k| ((k as f64 + alpha) / (k as f64 + 1.0)).ln()).sum()
    } else {
        // The product is Γ(n + 1 + α) / (Γ(1 + α) Γ(n + 2)): constant time for any pass.
        let n = pass as f64;
        ln_gamma(n + 1.0 + alpha) - ln_gamma(1.0 + alpha) - ln_gamma(n + 2.0)
    };
    (0.5 * log).exp() as f32
}

/// Passes up to which the radius product is summed term by term.
const DIRECT_PRODUCT_PASSES: u64 = 4096;

/// ln Γ(x) for x ≥ 1: shifted up to 8, then Stirling's series (error below 1e-10).
fn ln_gamma(mut x: f64) -> f64 {
    let mut shift = 0.0;
    while x < 8.0 {
        shift -= x.ln();
        x += 1.0;
    }
    let inv = 1.0 / x;
    let inv2 = inv * inv;
    shift + (x - 0.5) * x.ln() - x
        + 0.5 * (2.0 * std::f64::consts::PI).ln()
        + inv * (1.0 / 12.0 - inv2 * (1.0 / 360.0 - inv2 / 1260.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn radius_schedule_follows_the_recurrence() {
        assert_eq!(radius_factor(0, 0.7), 1.0);
        let r1 = radius_factor(1, 0.7);
        assert!((r1 * r1 - 1.7 / 2.0).abs() < 1e-6);
        let (r9, r10) = (radius_factor(9, 0.7), radius_factor(10, 0.7));
        assert!((r10 * r10 / (r9 * r9) - 10.7 / 11.0).abs() < 1e-5);
        // r² falls like i^(α−1): a thousand passes shrink it by about 1000^0.3.
        let r1000 = radius_factor(1000, 0.7);
        assert!(r1000 * r1000 < 0.2 && r1000 * r1000 > 0.05, "{r1000}");
        // The closed form used past 4096 passes continues the product.
        let direct: f64 = (1..=5000u64).map(|k| ((k as f64 + 0.7) / (k as f64 + 1.0)).ln()).sum();
        let direct = (0.5 * direct).exp() as f32;
        assert!((radius_factor(5000, 0.7) / direct - 1.0).abs() < 1e-5);
        let far = radius_factor(u32::MAX as u64, 0.7);
        assert!(far > 0.0 && far < radius_factor(5000, 0.7));
    }
}
