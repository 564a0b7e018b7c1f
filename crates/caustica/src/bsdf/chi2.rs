//! χ² tests of each smooth lobe's sampling against its density: directions drawn by
//! [`Bsdf::sample`] are counted in bins of equal solid angle over the whole sphere, and the
//! counts compared with what [`Bsdf::pdf`] integrated over each bin predicts. A sampler that
//! draws from another distribution than the one its pdf states (a wrong Jacobian, a lobe of
//! the wrong width, a missing mixture weight) fails, though its weights still match eval/pdf.

use super::*;
use crate::sampling::Rng;

/// Bins in z = cos θ (equal solid angle each) and in φ.
const Z_BINS: usize = 24;
const PHI_BINS: usize = 48;
/// Samples drawn per test.
const SAMPLES: usize = 1_000_000;
/// Quadrature points per bin and axis (midpoint rule) for the expected counts.
const QUADRATURE: usize = 12;
/// The same for rough glass, whose density ends sharply: refraction through microfacets seen
/// edge-on sends light to a thin band (|wi·z| = |wo·z|/η) at the end of the transmitted lobe.
const FINE_QUADRATURE: usize = 64;
/// Bins expecting fewer samples than this are pooled into one.
const MIN_EXPECTED: f64 = 5.0;
/// The largest Wilson–Hilferty z-score of the χ² statistic accepted: p ≈ 3·10⁻⁵ for one test,
/// so a dozen tests together reject a correct sampler with probability under 10⁻³.
const MAX_Z: f64 = 4.0;

fn bin_of(d: Vec3) -> Option<usize> {
    let z = ((d.z as f64 + 1.0) * 0.5 * Z_BINS as f64).floor();
    let phi = (d.y as f64).atan2(d.x as f64).rem_euclid(2.0 * std::f64::consts::PI);
    let p = (phi / (2.0 * std::f64::consts::PI) * PHI_BINS as f64).floor();
    (z.is_finite() && p.is_finite()).then(|| (z as usize).min(Z_BINS - 1) * PHI_BINS + (p as usize).min(PHI_BINS - 1))
}

/// Smooth samples counted per bin, from `sampler`'s directions (None: no smooth sample).
fn observed(mut sampler: impl FnMut(&mut Rng) -> Option<Vec3>, seed: u64) -> Vec<f64> {
    let mut counts = vec![0.0; Z_BINS * PHI_BINS];
    let mut rng = Rng::new(seed, 0);
    for _ in 0..SAMPLES {
        if let Some(bin) = sampler(&mut rng).and_then(bin_of) {
            counts[bin] += 1.0;
        }
    }
    counts
}

/// `pdf` integrated over each bin, times the sample count.
fn expected(pdf: impl Fn(Vec3) -> f32, quadrature: usize) -> Vec<f64> {
    let (dz, dphi) = (2.0 / Z_BINS as f64, 2.0 * std::f64::consts::PI / PHI_BINS as f64);
    let area = dz * dphi / (quadrature * quadrature) as f64;
    let mut out = vec![0.0; Z_BINS * PHI_BINS];
    for (i, e) in out.iter_mut().enumerate() {
        let (zi, pi) = (i / PHI_BINS, i % PHI_BINS);
        let mut sum = 0.0f64;
        for a in 0..quadrature {
            let z = -1.0 + (zi as f64 + (a as f64 + 0.5) / quadrature as f64) * dz;
            let s = (1.0 - z * z).max(0.0).sqrt();
            for b in 0..quadrature {
                let phi = (pi as f64 + (b as f64 + 0.5) / quadrature as f64) * dphi;
                let d = Vec3::new((s * phi.cos()) as f32, (s * phi.sin()) as f32, z as f32);
                sum += pdf(d) as f64;
            }
        }
        *e = sum * area * SAMPLES as f64;
    }
    out
}

/// The χ² statistic's Wilson–Hilferty z-score (its cube root is nearly normal), with bins of
/// small expectation pooled; also the degrees of freedom.
fn chi2_z(observed: &[f64], expected: &[f64]) -> (f64, usize) {
    let (mut chi2, mut bins) = (0.0, 0usize);
    let (mut pooled_o, mut pooled_e) = (0.0, 0.0);
    for (&o, &e) in observed.iter().zip(expected) {
        if e < MIN_EXPECTED {
            pooled_o += o;
            pooled_e += e;
        } else {
            chi2 += (o - e) * (o - e) / e;
            bins += 1;
        }
    }
    if pooled_e >= MIN_EXPECTED {
        chi2 += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        bins += 1;
    } else if pooled_o > 10.0 {
        // Samples where the density says almost none may fall: a sampler's mass the pdf lacks.
        chi2 += pooled_o * pooled_o / pooled_e.max(1.0);
        bins += 1;
    }
    // The total is not fixed (samples may be lost below the horizon), so every bin counts.
    let k = bins.max(1) as f64;
    let t = 2.0 / (9.0 * k);
    (((chi2 / k).cbrt() - (1.0 - t)) / t.sqrt(), bins)
}

fn assert_samples_match_pdf(name: &str, bsdf: &Bsdf, wo: Vec3, seed: u64) {
    assert_samples_match_pdf_by(name, bsdf, wo, seed, QUADRATURE);
}

fn assert_samples_match_pdf_by(name: &str, bsdf: &Bsdf, wo: Vec3, seed: u64, quadrature: usize) {
    let sampler = |rng: &mut Rng| {
        let s = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?;
        (!s.specular).then_some(s.wi)
    };
    let (z, bins) = chi2_z(&observed(sampler, seed), &expected(|d| bsdf.pdf(wo, d), quadrature));
    assert!(
        z < MAX_Z,
        "{name}: sampling disagrees with pdf, χ² z-score {z:.2} over {bins} bins"
    );
}

fn phong(kd: f32, ks: f32, exponent: f32, wo: Vec3) -> Bsdf {
    let params = SurfaceParams {
        diffuse: Vec3::splat(kd),
        specular: Vec3::splat(ks),
        shininess: exponent,
        ..SurfaceParams::default()
    };
    Bsdf::new(
        &Lobes::new(&params),
        Vec3::Z,
        Vec3::Z,
        wo,
        &Wavelengths::Rgb,
        None,
        None,
    )
}

fn at(theta: f32) -> Vec3 {
    Vec3::new(theta.sin(), 0.0, theta.cos())
}

#[test]
fn course_lobes_sample_their_density() {
    for (i, (kd, ks, exponent, theta)) in [
        (0.8, 0.0, 1.0, 0.3),
        (0.0, 0.9, 10.0, 0.0),
        (0.0, 0.9, 10.0, 0.9),
        (0.0, 0.9, 200.0, 0.5),
        (0.5, 0.4, 30.0, 1.2),
    ]
    .into_iter()
    .enumerate()
    {
        let wo = at(theta);
        let name = format!("Phong kd {kd} ks {ks} n {exponent} θo {theta}");
        assert_samples_match_pdf(&name, &phong(kd, ks, exponent, wo), wo, 10 + i as u64);
    }
}

#[test]
fn physical_lobes_sample_their_density() {
    let conductor = |alpha| PhysicalMaterial::Conductor {
        eta: Vec3::ONE,
        k: Vec3::ZERO,
        reflectance: Some(Vec3::splat(0.9)),
        roughness: alpha,
    };
    let coated = PhysicalMaterial::CoatedDiffuse {
        reflectance: Vec3::splat(0.7),
        eta: 1.5,
        roughness: 0.3,
        coat_tint: Vec3::ONE,
        layering: crate::description::Coating::Layered,
    };
    let translucent = PhysicalMaterial::DiffuseTransmission {
        reflectance: Vec3::splat(0.3),
        transmittance: Vec3::splat(0.6),
    };
    let cases = [
        ("GGX conductor α 0.1", conductor(0.1), 0.4),
        ("GGX conductor α 0.3", conductor(0.3), 0.0),
        ("GGX conductor α 0.5", conductor(0.5), 1.2),
        ("GGX conductor α 0.9", conductor(0.9), 0.8),
        ("coated diffuse, rough coat", coated.clone(), 0.7),
        ("diffuse transmission", translucent, 0.5),
    ];
    for (i, (name, material, theta)) in cases.into_iter().enumerate() {
        let wo = at(theta);
        let bsdf = Bsdf::physical(&material, Vec3::Z, Vec3::Z, wo, &Wavelengths::Rgb);
        assert_samples_match_pdf(&format!("{name}, θo {theta}"), &bsdf, wo, 20 + i as u64);
    }
    // A rough clear coat over a rough metal and over a rough coated diffuse base.
    let coat = crate::description::ClearCoat {
        weight: 0.8,
        eta: 1.5,
        alpha: 0.1,
    };
    for (i, (material, theta)) in [(conductor(0.4), 0.6f32), (coated, 1.1)].into_iter().enumerate() {
        let wo = at(theta);
        let bsdf = Bsdf::physical(&material, Vec3::Z, Vec3::Z, wo, &Wavelengths::Rgb).with_clearcoat(coat, wo);
        assert_samples_match_pdf(&format!("clear coat {i}, θo {theta}"), &bsdf, wo, 30 + i as u64);
    }
}

/// Rough glass from outside and from inside (where much is reflected totally): reflection and
/// refraction through visible normals, both halves of the sphere.
#[test]
fn rough_glass_samples_its_density() {
    let glass = |alpha| PhysicalMaterial::RoughDielectric {
        eta: 1.5,
        roughness: alpha,
        tint: Vec3::ONE,
        abbe: None,
    };
    for (i, (alpha, theta)) in [
        (0.1f32, 0.5f32),
        (0.3, 0.9),
        (0.6, 0.0),
        (0.6, 1.2),
        (0.3, 2.6),
        (0.6, 2.0),
    ]
    .into_iter()
    .enumerate()
    {
        let wo = at(theta);
        let bsdf = Bsdf::physical(&glass(alpha), Vec3::Z, Vec3::Z, wo, &Wavelengths::Rgb);
        let name = format!("rough glass α {alpha}, θo {theta}");
        assert_samples_match_pdf_by(&name, &bsdf, wo, 40 + i as u64, FINE_QUADRATURE);
    }
}

/// The test has the power to fail: a Phong lobe 10% wider than its pdf says, or a GGX sampler
/// of the wrong roughness, is rejected.
#[test]
fn a_sampler_of_another_distribution_is_rejected() {
    let wo = at(0.4);
    let (drawn, stated) = (phong(0.0, 0.9, 20.0, wo), phong(0.0, 0.9, 22.0, wo));
    let sampler = |rng: &mut Rng| Some(drawn.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?.wi);
    let (z, _) = chi2_z(&observed(sampler, 3), &expected(|d| stated.pdf(wo, d), QUADRATURE));
    assert!(z > MAX_Z, "Phong n 20 against n 22 passed: z {z:.2}");
    let ggx = |alpha| {
        let m = PhysicalMaterial::Conductor {
            eta: Vec3::ONE,
            k: Vec3::ZERO,
            reflectance: Some(Vec3::splat(0.9)),
            roughness: alpha,
        };
        Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &Wavelengths::Rgb)
    };
    let (drawn, stated) = (ggx(0.3), ggx(0.33));
    let sampler = |rng: &mut Rng| Some(drawn.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?.wi);
    let (z, _) = chi2_z(&observed(sampler, 4), &expected(|d| stated.pdf(wo, d), QUADRATURE));
    assert!(z > MAX_Z, "GGX α 0.3 against α 0.33 passed: z {z:.2}");
    // Rough glass refracting by another index than its pdf states.
    let glass = |eta| {
        let m = PhysicalMaterial::RoughDielectric {
            eta,
            roughness: 0.3,
            tint: Vec3::ONE,
            abbe: None,
        };
        Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &Wavelengths::Rgb)
    };
    let (drawn, stated) = (glass(1.5), glass(1.55));
    let sampler = |rng: &mut Rng| Some(drawn.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?.wi);
    let (z, _) = chi2_z(&observed(sampler, 5), &expected(|d| stated.pdf(wo, d), FINE_QUADRATURE));
    assert!(z > MAX_Z, "rough glass of η 1.5 against η 1.55 passed: z {z:.2}");
}
