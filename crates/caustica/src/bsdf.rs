//! The physically based reading of a `.ray` material (`--model physical`, docs/radiometry.md).
//!
//! A material becomes a sum of four lobes, each weighted by one of its colours:
//! - `diffuse` kd: Lambertian, f = kd / π;
//! - `specular` ks with `shininess` n: normalised Phong, f = ks (n + 2) / (2π) · cos^n α, with α
//!   the angle between ωi and the mirror direction of ωo (energy-conserving for any n);
//! - `reflective` kr: a perfect mirror of reflectance kr;
//! - `transmissive` kt with `index` η: a smooth dielectric, reflecting the exact Fresnel fraction F
//!   and transmitting (1 − F)·kt.
//!
//! Where the colours of one channel sum above 1 the lobes are scaled down together, so no
//! material creates energy. Directions point away from the surface; `n` is the outward shading
//! normal as the shape defines it.

use crate::material::{MaterialRef, MaterialSpectra, SurfaceParams};
use crate::math::{reflect, Frame, Vec3, Vec4};
use crate::sampling::sample_cosine_hemisphere;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{cauchy_index, SigmoidPolynomial, Spectrum, Wavelengths};
use std::f32::consts::PI;

/// Whether a path carries radiance (from the camera) or importance (from a light): refraction
/// scales radiance by 1/η² but not flux.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Transport {
    /// Camera paths.
    Radiance,
    /// Photon paths.
    Importance,
}

/// The lobes of one surface point, seen from one side.
#[derive(Clone, Copy, Debug)]
pub struct Bsdf {
    /// Shading frame whose z faces the side `wo` is on.
    frame: Frame,
    /// Geometric normal, turned to the side `wo` is on.
    ng: Vec3,
    /// Whether `wo` is on the outward side (a ray arriving from outside).
    outside: bool,
    diffuse: Spectrum,
    glossy: Spectrum,
    exponent: f32,
    mirror: Spectrum,
    transmission: Spectrum,
    /// Index of refraction (at the hero wavelength for a dispersive glass).
    index: f32,
    /// Whether the dielectric's index depends on the wavelength (a glass with an Abbe number,
    /// under spectral transport).
    dispersive: bool,
    /// Lobe selection probabilities: diffuse, glossy, mirror, dielectric.
    pick: [f32; 4],
}

/// A sampled direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BsdfSample {
    /// Unit direction away from the surface.
    pub wi: Vec3,
    /// f · |cos θi| / pdf: the factor the path's throughput is multiplied by.
    pub weight: Spectrum,
    /// Solid-angle pdf of the whole mixture for a smooth lobe; the discrete probability of the
    /// event for a specular one.
    pub pdf: f32,
    /// Whether a delta lobe (mirror, Fresnel reflection or refraction) was taken.
    pub specular: bool,
    /// Whether the direction crossed the surface.
    pub transmitted: bool,
    /// Whether the direction holds for the hero wavelength only (a dispersive glass): the path
    /// must drop its other wavelengths.
    pub dispersive: bool,
}

impl Bsdf {
    /// The lobes at a surface point of `scene`, seen from direction `wo` (unit, away from it),
    /// for light at wavelengths `wl`.
    #[inline]
    pub fn at(scene: &Scene, hit: &SurfaceHit, wo: Vec3, wl: &Wavelengths) -> Bsdf {
        let params = scene.phong(hit);
        let abbe = scene.abbe(hit);
        let spectra = match (wl.is_spectral(), hit.material) {
            (true, MaterialRef::One(id)) => Some(scene.material_spectra(id)),
            _ => None,
        };
        Bsdf::new(&params, hit.shading_normal, hit.geometric_normal, wo, wl, spectra, abbe)
    }

    /// The lobes of `params` at a point with outward shading normal `ns` and geometric normal
    /// `ng`, seen from direction `wo` (unit, away from the surface), for light at wavelengths
    /// `wl`. A material's fitted spectra (`spectra`) are used for its constant colours; `abbe`
    /// makes its dielectric dispersive.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        params: &SurfaceParams,
        ns: Vec3,
        ng: Vec3,
        wo: Vec3,
        wl: &Wavelengths,
        spectra: Option<&MaterialSpectra>,
        abbe: Option<f32>,
    ) -> Bsdf {
        let outside = wo.dot(ng) >= 0.0;
        let facing = if wo.dot(ns) >= 0.0 { ns } else { -ns };
        let ng_facing = if outside { ng } else { -ng };
        let clamp = |c: Vec3| c.max(Vec3::ZERO);
        let (mut kd, mut ks, mut kr, mut kt) = (
            clamp(params.diffuse),
            clamp(params.specular),
            clamp(params.reflective),
            clamp(params.transmissive),
        );
        let total = (kd + ks + kr + kt).max_element();
        let scale = if total > 1.0 { 1.0 / total } else { 1.0 };
        if total > 1.0 {
            kd *= scale;
            ks *= scale;
            kr *= scale;
            kt *= scale;
        }
        // A colour at the wavelengths: the material's fitted spectrum (scaled like the colour)
        // where it has one, else the table's.
        let spectrum = |rgb: Vec3, fit: Option<SigmoidPolynomial>| match (wl, fit) {
            (Wavelengths::Sampled { lambda, .. }, Some(fit)) => Vec4::from_array(lambda.map(|l| fit.eval(l))) * scale,
            _ => wl.reflectance(rgb),
        };
        let fits = spectra.copied().unwrap_or_default();
        let index = if params.index > 0.0 { params.index } else { 1.0 };
        let (index, dispersive) = match (abbe, wl.hero()) {
            (Some(v), Some(lambda)) if kt != Vec3::ZERO => (cauchy_index(index, v, lambda), true),
            _ => (index, false),
        };
        let mut pick = [kd.max_element(), ks.max_element(), kr.max_element(), 0.0];
        if kt != Vec3::ZERO {
            // The dielectric reflects even where kt is small; sample it by its larger part.
            pick[3] = kt.max_element().max(0.04);
        }
        let sum: f32 = pick.iter().sum();
        if sum > 0.0 {
            pick.iter_mut().for_each(|p| *p /= sum);
        }
        Bsdf {
            frame: Frame::from_normal(facing),
            ng: ng_facing,
            outside,
            diffuse: spectrum(kd, fits.diffuse),
            glossy: spectrum(ks, fits.specular),
            exponent: params.shininess.max(0.0),
            mirror: spectrum(kr, fits.reflective),
            transmission: spectrum(kt, fits.transmissive),
            index,
            dispersive,
            pick,
        }
    }

    /// Whether the surface has a smooth (non-delta) lobe: where light is sampled and photons
    /// are stored.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.pick[0] > 0.0 || self.pick[1] > 0.0
    }

    /// Whether light can leave the surface at all.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.pick.iter().all(|&p| p == 0.0)
    }

    /// The shading normal on the side of `wo`.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.frame.z
    }

    /// The smooth lobes' f(wo, wi) (delta lobes are never hit by a given direction).
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Spectrum {
        let n = self.frame.z;
        let cos_i = n.dot(wi);
        if cos_i <= 0.0 || self.ng.dot(wi) <= 0.0 {
            return Spectrum::ZERO;
        }
        let mut f = self.diffuse * (1.0 / PI);
        if self.glossy != Spectrum::ZERO {
            let cos_a = reflect(-wo, n).dot(wi);
            if cos_a > 0.0 {
                f += self.glossy * ((self.exponent + 2.0) / (2.0 * PI) * cos_a.powf(self.exponent));
            }
        }
        f
    }

    /// Solid-angle pdf with which [`Bsdf::sample`] draws `wi` through its smooth lobes.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        let n = self.frame.z;
        let cos_i = n.dot(wi);
        if cos_i <= 0.0 || self.ng.dot(wi) <= 0.0 {
            return 0.0;
        }
        let mut pdf = self.pick[0] * cos_i / PI;
        if self.pick[1] > 0.0 {
            let cos_a = reflect(-wo, n).dot(wi);
            if cos_a > 0.0 {
                pdf += self.pick[1] * (self.exponent + 1.0) / (2.0 * PI) * cos_a.powf(self.exponent);
            }
        }
        pdf
    }

    /// Draws a direction: `u_lobe` picks the lobe (and Fresnel's choice), `u` the direction.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: glam::Vec2, mode: Transport) -> Option<BsdfSample> {
        let n = self.frame.z;
        let [p_diffuse, p_glossy, p_mirror, p_dielectric] = self.pick;
        let mut x = u_lobe;
        if x < p_diffuse + p_glossy {
            let wi = if x < p_diffuse {
                self.frame.to_world(sample_cosine_hemisphere(u))
            } else {
                let r = reflect(-wo, n);
                let cos_a = u.x.powf(1.0 / (self.exponent + 1.0));
                let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
                let phi = 2.0 * PI * u.y;
                Frame::from_normal(r).to_world(Vec3::new(sin_a * phi.cos(), sin_a * phi.sin(), cos_a))
            };
            let pdf = self.pdf(wo, wi);
            if pdf <= 0.0 {
                return None;
            }
            let weight = self.eval(wo, wi) * n.dot(wi) / pdf;
            return Some(BsdfSample {
                wi,
                weight,
                pdf,
                specular: false,
                transmitted: false,
                dispersive: false,
            });
        }
        x -= p_diffuse + p_glossy;
        if x < p_mirror {
            let wi = reflect(-wo, n);
            return (self.ng.dot(wi) > 0.0).then(|| BsdfSample {
                wi,
                weight: self.mirror / p_mirror,
                pdf: p_mirror,
                specular: true,
                transmitted: false,
                dispersive: false,
            });
        }
        if p_dielectric <= 0.0 {
            return None;
        }
        // The dielectric: reflect with probability F, else refract.
        let x = ((x - p_mirror) / p_dielectric).clamp(0.0, 1.0);
        let eta = if self.outside { self.index } else { 1.0 / self.index };
        let cos_o = n.dot(wo).clamp(0.0, 1.0);
        let f = fresnel_dielectric(cos_o, eta);
        if x < f {
            let wi = reflect(-wo, n);
            return Some(BsdfSample {
                wi,
                weight: Spectrum::ONE / p_dielectric,
                pdf: p_dielectric * f,
                specular: true,
                transmitted: false,
                dispersive: self.dispersive,
            });
        }
        let wi = crate::math::refract(-wo, n, 1.0 / eta)?;
        let scale = match mode {
            Transport::Radiance => 1.0 / (eta * eta),
            Transport::Importance => 1.0,
        };
        Some(BsdfSample {
            wi,
            weight: self.transmission * (scale / p_dielectric),
            pdf: p_dielectric * (1.0 - f),
            specular: true,
            transmitted: true,
            dispersive: self.dispersive,
        })
    }
}

/// Fresnel reflectance of a smooth dielectric for unpolarised light: `cos_i` on the incident
/// side, `eta` = η_transmitted / η_incident. 1 under total internal reflection.
pub fn fresnel_dielectric(cos_i: f32, eta: f32) -> f32 {
    let cos_i = cos_i.clamp(0.0, 1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_parallel = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perpendicular = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_parallel * r_parallel + r_perpendicular * r_perpendicular)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    const RGB: Wavelengths = Wavelengths::Rgb;

    fn params(kd: f32, ks: f32, n: f32) -> SurfaceParams {
        SurfaceParams {
            diffuse: Vec3::splat(kd),
            specular: Vec3::splat(ks),
            shininess: n,
            ..SurfaceParams::default()
        }
    }

    #[test]
    fn fresnel_matches_closed_forms() {
        // Normal incidence: ((η − 1) / (η + 1))² = 0.04 for glass.
        assert!((fresnel_dielectric(1.0, 1.5) - 0.04).abs() < 1e-6);
        assert!((fresnel_dielectric(1.0, 1.0 / 1.5) - 0.04).abs() < 1e-6);
        // Brewster's angle: the parallel part vanishes, F = r_perp² / 2.
        let theta_b = 1.5f32.atan();
        let f = fresnel_dielectric(theta_b.cos(), 1.5);
        let cos_t = (1.0 - (theta_b.sin() / 1.5).powi(2)).sqrt();
        let rs = (theta_b.cos() - 1.5 * cos_t) / (theta_b.cos() + 1.5 * cos_t);
        assert!((f - 0.5 * rs * rs).abs() < 1e-5);
        // Past the critical angle inside glass: total reflection.
        assert_eq!(fresnel_dielectric(0.5, 1.0 / 1.5), 1.0);
        assert!((fresnel_dielectric(0.0, 1.5) - 1.0).abs() < 1e-6, "grazing");
    }

    /// ∫ f cos dω by importance sampling equals the albedo: kd for Lambert, ks for normalised
    /// Phong at normal incidence (any exponent), and the weights average to the same.
    #[test]
    fn smooth_lobes_conserve_energy_and_weights_match_eval() {
        let n = Vec3::Z;
        let wo = Vec3::Z;
        for (kd, ks, exp) in [(0.8, 0.0, 1.0), (0.0, 0.9, 10.0), (0.0, 0.9, 200.0), (0.5, 0.4, 30.0)] {
            let bsdf = Bsdf::new(&params(kd, ks, exp), n, n, wo, &RGB, None, None);
            let mut rng = Rng::new(1, 0);
            let count = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..count {
                let u_lobe = rng.uniform();
                if let Some(s) = bsdf.sample(wo, u_lobe, rng.uniform2(), Transport::Radiance) {
                    assert!(!s.specular);
                    let expected = bsdf.eval(wo, s.wi) * s.wi.z / bsdf.pdf(wo, s.wi);
                    assert!((s.weight - expected).length() < 1e-3 * (1.0 + expected.length()));
                    sum += s.weight.x as f64;
                }
            }
            let albedo = sum / count as f64;
            // Normalised Phong loses the part of its lobe below the horizon only off normal incidence.
            let expected = kd as f64 + ks as f64;
            assert!(
                (albedo - expected).abs() < 0.01,
                "kd {kd} ks {ks} n {exp}: {albedo} vs {expected}"
            );
        }
    }

    /// The pdf integrates to the smooth lobes' share of the selection probability.
    #[test]
    fn pdf_integrates_to_one_over_the_hemisphere() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.6, 0.0, 0.8);
        let bsdf = Bsdf::new(&params(0.3, 0.5, 5.0), n, n, wo, &RGB, None, None);
        let mut rng = Rng::new(2, 0);
        let count = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..count {
            // Uniform hemisphere: pdf 1 / 2π.
            let d = crate::sampling::sample_uniform_sphere(rng.uniform2());
            let d = Vec3::new(d.x, d.y, d.z.abs());
            sum += bsdf.pdf(wo, d) as f64 * 2.0 * std::f64::consts::PI;
        }
        let integral = sum / count as f64;
        // The Phong lobe around the mirror direction at 37° loses a little below the horizon.
        assert!(integral > 0.95 && integral <= 1.005, "{integral}");
    }

    #[test]
    fn glass_splits_by_fresnel_and_conserves_flux() {
        let glass = SurfaceParams {
            transmissive: Vec3::ONE,
            index: 1.5,
            ..SurfaceParams::default()
        };
        let n = Vec3::Z;
        let wo = Vec3::new(0.0, 0.5f32.sin(), 0.5f32.cos());
        let bsdf = Bsdf::new(&glass, n, n, wo, &RGB, None, None);
        assert!(!bsdf.is_smooth());
        let mut rng = Rng::new(3, 0);
        let count = 100_000;
        let (mut reflected, mut total) = (0.0f64, 0.0f64);
        for _ in 0..count {
            let s = bsdf
                .sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance)
                .unwrap();
            assert!(s.specular);
            total += s.weight.x as f64;
            if !s.transmitted {
                reflected += s.weight.x as f64;
                assert!((s.wi - Vec3::new(0.0, -wo.y, wo.z)).length() < 1e-5);
            } else {
                // Snell: sin θt = sin θi / 1.5, on the far side.
                assert!(s.wi.z < 0.0);
                assert!((s.wi.y.abs() - 0.5f32.sin() / 1.5).abs() < 1e-5);
            }
        }
        let f = fresnel_dielectric(0.5f32.cos(), 1.5) as f64;
        assert!((reflected / count as f64 - f).abs() < 0.004);
        assert!((total / count as f64 - 1.0).abs() < 1e-4, "photons keep their flux");
        // From inside, a steep ray is totally reflected.
        let inside = Bsdf::new(
            &glass,
            n,
            n,
            -Vec3::new(0.0, 0.9f32.sin(), 0.9f32.cos()),
            &RGB,
            None,
            None,
        );
        let s = inside
            .sample(
                -Vec3::new(0.0, 0.9f32.sin(), 0.9f32.cos()),
                0.99,
                glam::Vec2::ZERO,
                Transport::Radiance,
            )
            .unwrap();
        assert!(!s.transmitted);
    }

    #[test]
    fn overbright_materials_are_scaled_to_conserve_energy() {
        let p = SurfaceParams {
            diffuse: Vec3::splat(0.8),
            reflective: Vec3::splat(0.6),
            ..SurfaceParams::default()
        };
        let bsdf = Bsdf::new(&p, Vec3::Z, Vec3::Z, Vec3::Z, &RGB, None, None);
        assert!((bsdf.diffuse.x + bsdf.mirror.x - 1.0).abs() < 1e-6);
        assert!((bsdf.diffuse.x / bsdf.mirror.x - 0.8 / 0.6).abs() < 1e-5);
    }
}
