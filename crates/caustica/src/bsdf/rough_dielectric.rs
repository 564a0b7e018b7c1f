//! Rough glass: GGX microfacet reflection and refraction at a dielectric interface (Walter et
//! al. 2007), sampled through the microfacet normals visible from the outgoing direction
//! (Heitz 2018), as pbrt-v4 and Mitsuba 3 sample it.
//!
//! Directions are in a frame whose z faces `wo`'s side; `eta` is the index beyond the interface
//! over the index on `wo`'s side (below 1 from inside glass). Light that crosses the interface
//! is found through the generalised half vector wo + η·wi, which is the microfacet normal that
//! refracts one into the other.

use super::{fresnel_dielectric, Fresnel, Microfacet, Transport};
use crate::math::{refract, sin_cos_turns, Vec3};

/// One side's view of a rough dielectric interface.
#[derive(Clone, Copy, Debug)]
pub(super) struct Interface {
    ggx: Microfacet,
    eta: f32,
}

impl Interface {
    pub(super) fn new(alpha: f32, eta: f32) -> Interface {
        Interface {
            ggx: Microfacet {
                alpha,
                fresnel: Fresnel::Dielectric { eta, tint: Vec3::ONE },
            },
            eta,
        }
    }

    /// The microfacet normal (facing `wo`'s side) that turns `wo` into `wi`, with `wo·h` and
    /// `wi·h`; `None` where no microfacet does (a direction on the wrong side of it).
    fn half(&self, wo: Vec3, wi: Vec3) -> Option<(Vec3, f32, f32)> {
        let transmitted = wi.z < 0.0;
        let h = if transmitted { wo + wi * self.eta } else { wo + wi };
        let h = h.try_normalize()?;
        let h = if h.z < 0.0 { -h } else { h };
        let (oh, ih) = (wo.dot(h), wi.dot(h));
        let consistent = oh > 0.0 && if transmitted { ih < 0.0 } else { ih > 0.0 };
        consistent.then_some((h, oh, ih))
    }

    /// f(wo, wi): Fresnel-weighted GGX reflection for `wi` on `wo`'s side, transmission for
    /// `wi` beyond. Transmitted radiance is spread over the refracted cone (1/η² against
    /// importance), which is what makes the BTDF non-symmetric.
    pub(super) fn eval(&self, wo: Vec3, wi: Vec3, mode: Transport) -> f32 {
        if wo.z <= 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let Some((h, oh, ih)) = self.half(wo, wi) else {
            return 0.0;
        };
        let f = fresnel_dielectric(oh, self.eta);
        let dg = self.ggx.d(h.z) / (1.0 + self.ggx.lambda(wo.z) + self.ggx.lambda(wi.z));
        if wi.z > 0.0 {
            return f * dg / (4.0 * wo.z * wi.z);
        }
        let denom = oh + self.eta * ih;
        let radiance = (1.0 - f) * dg * (oh * ih).abs() / (wo.z * wi.z.abs() * denom * denom);
        match mode {
            Transport::Radiance => radiance,
            Transport::Importance => radiance * self.eta * self.eta,
        }
    }

    /// The density of [`Interface::sample`] drawing `wi`: the visible normals' density times
    /// the Jacobian of reflection (1/(4 wo·h)) or refraction (η²|wi·h|/(wo·h + η wi·h)²), times
    /// the Fresnel choice.
    pub(super) fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if wo.z <= 0.0 || wi.z == 0.0 {
            return 0.0;
        }
        let Some((h, oh, ih)) = self.half(wo, wi) else {
            return 0.0;
        };
        let visible = self.ggx.d(h.z) * oh / (wo.z * (1.0 + self.ggx.lambda(wo.z)));
        let f = fresnel_dielectric(oh, self.eta);
        if wi.z > 0.0 {
            return f * visible / (4.0 * oh);
        }
        let denom = oh + self.eta * ih;
        (1.0 - f) * visible * self.eta * self.eta * ih.abs() / (denom * denom)
    }

    /// Draws a visible microfacet normal with `u`, then reflects off it with the probability
    /// Fresnel gives (`x` in [0, 1) decides) or refracts through it. `None` where the direction
    /// lands on the wrong side of the macro surface (the sample is lost, as single scattering
    /// loses it).
    pub(super) fn sample(&self, wo: Vec3, x: f32, u: glam::Vec2) -> Option<Vec3> {
        if wo.z <= 0.0 {
            return None;
        }
        let h = self.ggx.sample_visible(wo, u);
        let oh = wo.dot(h);
        if oh <= 0.0 {
            return None;
        }
        if x < fresnel_dielectric(oh, self.eta) {
            let wi = 2.0 * oh * h - wo;
            return (wi.z > 0.0).then_some(wi);
        }
        let wi = refract(-wo, h, 1.0 / self.eta)?;
        (wi.z < 0.0).then_some(wi)
    }
}

impl Microfacet {
    /// A microfacet normal drawn with the density of the normals seen from `wo` (local, above
    /// the surface): G1(wo)·max(0, wo·h)·D(h)/cos θo. The ellipsoid of normals is stretched to
    /// a hemisphere, where the visible ones are a disc's projection.
    fn sample_visible(&self, wo: Vec3, u: glam::Vec2) -> Vec3 {
        let a = self.alpha;
        let v = Vec3::new(a * wo.x, a * wo.y, wo.z).normalize();
        let len2 = v.x * v.x + v.y * v.y;
        let t1 = if len2 > 1e-12 {
            Vec3::new(-v.y, v.x, 0.0) / len2.sqrt()
        } else {
            Vec3::X
        };
        let t2 = v.cross(t1);
        let r = u.x.sqrt();
        let (sin, cos) = sin_cos_turns(u.y);
        let p1 = r * cos;
        // The half of the disc hidden behind `wo` is squeezed onto the seen half.
        let s = 0.5 * (1.0 + v.z);
        let p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * r * sin;
        let pz = (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt();
        let n = p1 * t1 + p2 * t2 + pz * v;
        Vec3::new(a * n.x, a * n.y, n.z.max(1e-6)).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Bsdf, BsdfSample, PhysicalMaterial, Transport};
    use crate::math::Vec3;
    use crate::sampling::Rng;
    use crate::spectrum::Wavelengths;

    fn glass(alpha: f32, wo: Vec3) -> Bsdf {
        let m = PhysicalMaterial::RoughDielectric {
            eta: 1.5,
            roughness: alpha,
            tint: Vec3::ONE,
            abbe: None,
        };
        Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &Wavelengths::Rgb)
    }

    fn sample(bsdf: &Bsdf, wo: Vec3, rng: &mut Rng, mode: Transport) -> Option<BsdfSample> {
        bsdf.sample(wo, rng.uniform(), rng.uniform2(), mode)
    }

    fn albedo_by_quadrature(bsdf: &Bsdf, wo: Vec3, mode: Transport) -> f64 {
        super::super::tests::albedo_by_quadrature(bsdf, wo, true, mode)
    }

    /// Every sample weighs f·|cos|/pdf with the pdf [`Bsdf::pdf`] states; the mean weight is the
    /// albedo integrated by quadrature (the sampler covers both lobes), and no more than 1 for
    /// flux (single scattering loses what leaves towards the wrong side, and nothing else).
    #[test]
    fn samples_weigh_eval_over_pdf_and_their_mean_is_the_albedo() {
        for (alpha, theta, inside) in [
            (0.2f32, 0.0f32, false),
            (0.2, 1.2, false),
            (0.5, 0.6, false),
            (0.2, 0.3, true),
            (0.5, 0.9, true),
        ] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos()) * if inside { -1.0 } else { 1.0 };
            let bsdf = glass(alpha, wo);
            let mut rng = Rng::new(31, 0);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let Some(s) = sample(&bsdf, wo, &mut rng, Transport::Importance) else {
                    continue;
                };
                assert!(!s.specular && s.transmitted == (s.wi.z * wo.z < 0.0));
                let pdf = bsdf.pdf(wo, s.wi);
                assert!((s.pdf - pdf).abs() <= 1e-4 * pdf, "{s:?} against {pdf}");
                let expected = bsdf.eval_in(wo, s.wi, Transport::Importance) * (s.wi.z.abs() / pdf);
                assert!(
                    (s.weight - expected).length() <= 1e-3 * (1.0 + expected.length()),
                    "{s:?}"
                );
                sum += s.weight.x as f64;
            }
            let sampled = sum / n as f64;
            let quadrature = albedo_by_quadrature(&bsdf, wo, Transport::Importance);
            let name = format!("α {alpha} θ {theta} inside {inside}");
            assert!(
                (sampled - quadrature).abs() < 0.01,
                "{name}: sampled {sampled}, quadrature {quadrature}"
            );
            assert!(
                quadrature <= 1.0 + 2e-3 && quadrature > 0.6,
                "{name}: albedo {quadrature}"
            );
        }
    }

    /// The adjoint: importance carried from `wo` to `wi` is radiance carried the other way, seen
    /// from `wi`'s side, f*(wo, wi) = f(wi, wo), and the reverse density is the density from there.
    /// Radiance alone is not symmetric across the interface: it differs by η² (Veach §5.2).
    #[test]
    fn importance_one_way_is_radiance_the_other() {
        let mut rng = Rng::new(37, 0);
        let mut checked = [0; 2];
        for _ in 0..2000 {
            let wo = crate::sampling::sample_uniform_sphere(rng.uniform2());
            let wi = crate::sampling::sample_uniform_sphere(rng.uniform2());
            let (from_o, from_i) = (glass(0.3, wo), glass(0.3, wi));
            let importance = from_o.eval_in(wo, wi, Transport::Importance).x;
            let radiance = from_i.eval_in(wi, wo, Transport::Radiance).x;
            assert!(
                (importance - radiance).abs() <= 1e-3 * importance.max(1e-3),
                "{importance} vs {radiance}"
            );
            let (reverse, there) = (from_o.pdf_reverse(wo, wi), from_i.pdf(wi, wo));
            assert!(
                (reverse - there).abs() <= 1e-3 * reverse.max(1e-3),
                "{reverse} vs {there}"
            );
            if importance > 0.0 {
                let through = wo.z * wi.z < 0.0;
                checked[usize::from(through)] += 1;
                if through {
                    let eta2 = if wo.z > 0.0 { 2.25 } else { 1.0 / 2.25 };
                    let own = from_o.eval_in(wo, wi, Transport::Radiance).x;
                    assert!(
                        (importance - own * eta2).abs() <= 1e-3 * importance,
                        "{importance} vs {own}"
                    );
                }
            }
        }
        assert!(checked.iter().all(|&c| c > 100), "{checked:?}");
    }

    /// Nearly smooth, it is the smooth interface: Fresnel's share reflected about the normal,
    /// the rest refracted by Snell's law, flux kept.
    #[test]
    fn nearly_smooth_glass_splits_as_fresnel_and_snell_say() {
        let theta = 0.6f32;
        let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
        let bsdf = glass(0.002, wo);
        let mut rng = Rng::new(41, 0);
        let (mut reflected, mut total, mut off, n) = (0.0f64, 0.0f64, 0, 100_000);
        for _ in 0..n {
            let s = sample(&bsdf, wo, &mut rng, Transport::Importance).unwrap();
            total += s.weight.x as f64;
            // GGX's long tail sends a few samples further.
            let snell = if s.transmitted {
                Vec3::new(-theta.sin() / 1.5, 0.0, -(1.0 - (theta.sin() / 1.5).powi(2)).sqrt())
            } else {
                reflected += s.weight.x as f64;
                Vec3::new(-wo.x, 0.0, wo.z)
            };
            off += usize::from((s.wi - snell).length() > 0.01);
        }
        assert!(
            off < n / 50,
            "{off} of {n} samples further than 0.01 from Snell's and the mirror's"
        );
        let f = super::fresnel_dielectric(theta.cos(), 1.5) as f64;
        assert!(
            (reflected / n as f64 - f).abs() < 0.004,
            "{} vs {f}",
            reflected / n as f64
        );
        assert!((total / n as f64 - 1.0).abs() < 0.005, "{}", total / n as f64);
    }

    /// A dispersive rough glass refracts each wavelength by its own index: every lane of f is
    /// the value a glass of that lane's index gives.
    #[test]
    fn dispersive_rough_glass_gives_each_wavelength_its_index() {
        crate::spectrum::prepare();
        let wl = Wavelengths::Sampled {
            lambda: [450.0, 520.0, 590.0, 660.0],
            pdf: [1.0; 4],
        };
        let (wo, wi) = (Vec3::new(0.5, 0.0, 0.866), Vec3::new(-0.2, 0.1, -0.97).normalize());
        let dispersive = PhysicalMaterial::RoughDielectric {
            eta: 1.5,
            roughness: 0.1,
            tint: Vec3::ONE,
            abbe: Some(30.0),
        };
        let f = Bsdf::physical(&dispersive, Vec3::Z, Vec3::Z, wo, &wl).eval(wo, wi);
        let Wavelengths::Sampled { lambda, .. } = wl else {
            unreachable!()
        };
        for (i, l) in lambda.into_iter().enumerate() {
            let one = PhysicalMaterial::RoughDielectric {
                eta: crate::spectrum::cauchy_index(1.5, 30.0, l),
                roughness: 0.1,
                tint: Vec3::ONE,
                abbe: None,
            };
            let g = Bsdf::physical(&one, Vec3::Z, Vec3::Z, wo, &wl).eval(wo, wi)[i];
            assert!((f[i] - g).abs() <= 1e-3 * g, "{l} nm: {} vs {g}", f[i]);
        }
        assert!(f.x > 1.05 * f.w, "blue refracts more, towards this direction: {f:?}");
    }
}
