//! pbrt-v4's named spectra read as caustica's RGB numbers: glasses as n_d and Abbe number V_d,
//! metals as an RGB complex index, black bodies and sampled spectra as linear sRGB.

use glam::Vec3;

/// n_d and V_d of pbrt-v4's named glasses, computed from its tables (refractiveindex.info data
/// for the Schott N- glasses; `glass-F5/F10/F11` are N-SF5/N-SF10/N-SF11).
pub fn glass(name: &str) -> Option<(f32, f32)> {
    Some(match name {
        "glass-BK7" => (1.5168, 64.17),
        "glass-BAF10" => (1.67003, 47.11),
        "glass-FK51A" => (1.48656, 84.47),
        "glass-LASF9" => (1.85025, 32.17),
        "glass-F5" => (1.67271, 32.25),
        "glass-F10" => (1.72828, 28.53),
        "glass-F11" => (1.78472, 25.68),
        _ => return None,
    })
}

/// RGB complex indices (η, k) of pbrt-v4's named metals at about 650, 550 and 450 nm (the
/// values renderers commonly fit to the measured data pbrt also tabulates).
pub fn metal(name: &str) -> Option<(Vec3, Vec3)> {
    let v = Vec3::new;
    Some(match name {
        "metal-Cu" => (v(0.200438, 0.924033, 1.10221), v(3.91295, 2.45285, 2.14219)),
        "metal-Au" => (v(0.143119, 0.374957, 1.44248), v(3.98316, 2.38572, 1.60322)),
        "metal-Ag" => (v(0.155265, 0.116723, 0.138342), v(4.82835, 3.12225, 2.14696)),
        "metal-Al" => (v(1.65746, 0.880369, 0.521229), v(9.22387, 6.26952, 4.837)),
        "metal-CuZn" => (v(0.444, 0.527, 1.094), v(3.695, 2.765, 1.829)),
        "metal-MgO" => (v(1.732, 1.7357, 1.7435), Vec3::ZERO),
        "metal-TiO2" => (v(2.5423, 2.6204, 2.7929), Vec3::ZERO),
        _ => return None,
    })
}

/// The η or k half of a named metal spectrum (`metal-Au-eta`, `metal-Au-k`).
pub fn metal_part(name: &str) -> Option<Vec3> {
    if let Some(base) = name.strip_suffix("-eta") {
        return metal(base).map(|m| m.0);
    }
    name.strip_suffix("-k").and_then(metal).map(|m| m.1)
}

/// Linear sRGB of CIE XYZ.
fn xyz_to_rgb(xyz: Vec3) -> Vec3 {
    Vec3::new(
        3.240_454 * xyz.x - 1.537_138 * xyz.y - 0.498_531 * xyz.z,
        -0.969_266 * xyz.x + 1.876_011 * xyz.y + 0.041_556 * xyz.z,
        0.055_643 * xyz.x - 0.204_026 * xyz.y + 1.057_225 * xyz.z,
    )
}

/// The colour of a black body at `kelvin`, as linear sRGB of luminance 1: the Planckian
/// locus's chromaticity by Kim et al.'s cubic fit (2002, valid 1667–25000 K).
pub fn blackbody(kelvin: f32) -> Vec3 {
    let t = kelvin.clamp(1667.0, 25000.0) as f64;
    let x = if t <= 4000.0 {
        -0.2661239e9 / (t * t * t) - 0.2343589e6 / (t * t) + 0.8776956e3 / t + 0.179910
    } else {
        -3.0258469e9 / (t * t * t) + 2.1070379e6 / (t * t) + 0.2226347e3 / t + 0.240390
    };
    let y = if t <= 2222.0 {
        -1.1063814 * x * x * x - 1.34811020 * x * x + 2.18555832 * x - 0.20219683
    } else if t <= 4000.0 {
        -0.9549476 * x * x * x - 1.37418593 * x * x + 2.09137015 * x - 0.16748867
    } else {
        3.0817580 * x * x * x - 5.87338670 * x * x + 3.75112997 * x - 0.37001483
    };
    let xyz = Vec3::new((x / y) as f32, 1.0, ((1.0 - x - y) / y) as f32);
    xyz_to_rgb(xyz).max(Vec3::ZERO)
}

/// A sampled spectrum's value at `lambda` nm (linear between samples, constant beyond).
pub fn sample(pairs: &[(f32, f32)], lambda: f32) -> f32 {
    match pairs.iter().position(|p| p.0 >= lambda) {
        None => pairs.last().map_or(0.0, |p| p.1),
        Some(0) => pairs[0].1,
        Some(i) => {
            let (a, b) = (pairs[i - 1], pairs[i]);
            a.1 + (b.1 - a.1) * (lambda - a.0) / (b.0 - a.0)
        }
    }
}

/// A sampled reflectance as RGB: its mean over the red (600–700 nm), green (500–600 nm) and
/// blue (400–500 nm) bands — a coarse reading, documented as such.
pub fn sampled_to_rgb(pairs: &[(f32, f32)]) -> Vec3 {
    let band = |a: f32, b: f32| {
        (0..=20)
            .map(|i| sample(pairs, a + (b - a) * i as f32 / 20.0))
            .sum::<f32>()
            / 21.0
    };
    Vec3::new(band(600.0, 700.0), band(500.0, 600.0), band(400.0, 500.0))
}

/// n_d (587.6 nm) and, where the samples reach the F and C lines, the Abbe number.
pub fn sampled_index(pairs: &[(f32, f32)]) -> (f32, Option<f32>) {
    let nd = sample(pairs, 587.6);
    let covered = pairs.first().is_some_and(|p| p.0 <= 486.1) && pairs.last().is_some_and(|p| p.0 >= 656.3);
    let dn = sample(pairs, 486.1) - sample(pairs, 656.3);
    let abbe = (covered && dn > 1e-6 && nd > 1.0).then(|| (nd - 1.0) / dn);
    (nd, abbe)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blackbody_is_white_near_6500k_and_red_when_cool() {
        let d65ish = blackbody(6504.0);
        assert!(
            (d65ish / d65ish.max_element() - Vec3::ONE).abs().max_element() < 0.08,
            "{d65ish:?}"
        );
        let lum = 0.2126 * d65ish.x + 0.7152 * d65ish.y + 0.0722 * d65ish.z;
        assert!((lum - 1.0).abs() < 1e-3);
        let warm = blackbody(2700.0);
        assert!(warm.x > warm.y && warm.y > warm.z, "{warm:?}");
    }

    #[test]
    fn metals_reflect_their_colours() {
        // Normal-incidence reflectance ((η−1)² + k²) / ((η+1)² + k²): gold is yellow.
        let (eta, k) = metal("metal-Au").unwrap();
        let r = ((eta - Vec3::ONE) * (eta - Vec3::ONE) + k * k) / ((eta + Vec3::ONE) * (eta + Vec3::ONE) + k * k);
        assert!(r.x > 0.9 && r.z < 0.45, "{r:?}");
        assert_eq!(metal_part("metal-Au-k"), Some(k));
        assert!(metal_part("metal-Xx-eta").is_none());
    }

    #[test]
    fn sampled_glass_gives_its_abbe_number() {
        // A Cauchy glass n = A + B/λ² with n_d 1.5168 and V 64.17.
        let (nd, v) = (1.5168f32, 64.17f32);
        let b = (nd - 1.0) / v / (1.0 / 486.1f32.powi(2) - 1.0 / 656.3f32.powi(2));
        let a = nd - b / 587.6f32.powi(2);
        let pairs: Vec<(f32, f32)> = (0..=40)
            .map(|i| {
                let l = 380.0 + 10.0 * i as f32;
                (l, a + b / (l * l))
            })
            .collect();
        let (n, abbe) = sampled_index(&pairs);
        assert!((n - nd).abs() < 2e-4);
        assert!((abbe.unwrap() - v).abs() < 1.5, "{abbe:?}");
    }
}
