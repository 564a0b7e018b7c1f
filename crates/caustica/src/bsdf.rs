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
//! Where the colours of one channel sum above 1 the lobes are scaled down together, and the
//! dielectric, whose Fresnel reflection may reach all the light at grazing angles whatever kt
//! is, keeps at each direction only the room the other lobes leave; so no material creates
//! energy. The other lobes coat the outside only: seen from inside, a dielectric is the bare
//! interface, reflecting the exact Fresnel fraction (all of it under total internal reflection)
//! and transmitting what crosses the coated outside, the same share both ways (reciprocal).
//! Directions point away from the surface; `n` is the outward shading normal as the shape
//! defines it.
//!
//! Materials with a physical description of their own (pbrt-v4 and glTF scenes, see
//! [`PhysicalMaterial`]) add lobes, built by [`Bsdf::physical`]:
//! - a GGX microfacet reflection lobe (Trowbridge–Reitz distribution, Smith's height-correlated
//!   shadowing, sampled by the distribution of normals, Walter et al. 2007) with the Fresnel
//!   reflectance of a conductor (complex index η + ik) or of a dielectric coat;
//! - a coated diffuse base: Lambert times (1 − F(θo))(1 − F(θi)), the light that crosses the
//!   coat both ways (reciprocal, and never more than the coat lets through);
//! - Lambertian transmission to the far side;
//! - a thin-walled dielectric: Fresnel reflection of the sheet's two faces, 2R/(1 + R), and the
//!   rest straight through;
//! - a rough dielectric (frosted glass): GGX reflection and refraction ([`rough_dielectric`]),
//!   a smooth lobe on both sides of the surface.

mod rough_dielectric;

use crate::description::{ClearCoat, Coating};
use crate::material::{Lobes, MaterialRef, MaterialSpectra, PhysicalMaterial, SurfaceParams};
use crate::math::{reflect, sin_cos_turns, Frame, Vec3, Vec4};
use crate::medium::{henyey_greenstein, Phase};
use crate::sampling::sample_cosine_hemisphere;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{cauchy_index, SigmoidPolynomial, Spectrum, Wavelengths};
use std::f32::consts::PI;

/// The roughness that marks a [`Bsdf::phase`].
const PHASE: f32 = f32::INFINITY;

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
    /// Lobe selection probabilities: diffuse, glossy, mirror, dielectric, then the physical
    /// lobes: microfacet, diffuse transmission.
    pick: [f32; 6],
    /// Index of a clear coat over the diffuse lobe (0: none).
    coat: f32,
    /// The largest share that coat reflects (its tint's largest channel): what the diffuse
    /// lobe loses is that times the coat's Fresnel reflectance, each way.
    coat_weight: f32,
    /// The GGX reflection lobe, if any.
    microfacet: Option<Microfacet>,
    /// Lambertian transmission albedo.
    diffuse_transmission: Spectrum,
    /// The dielectric is a thin sheet: it passes light straight through.
    thin: bool,
    /// GGX α of a rough dielectric ([`rough_dielectric`]); 0 for a smooth one.
    rough: f32,
    /// A rough dielectric's index at the d line and Abbe number (0: not dispersive), for the
    /// index at each wavelength.
    index_d: f32,
    abbe: f32,
    /// A clear coat over the other lobes (weight 0: none); a smooth one is part of `mirror`.
    clear: ClearCoat,
    /// The chance of drawing a rough coat's GGX lobe (the picks share the rest).
    p_coat: f32,
    /// The outside's diffuse, glossy and mirror lobes' albedo bound ([`Lobes::reflection_bound`]).
    reflection_bound: f32,
    /// The wavelengths, for colours computed per direction (a conductor's Fresnel reflectance).
    wl: Wavelengths,
}

/// [`Bsdf::lambertian`]'s answer: the same values as [`Bsdf::eval`], [`Bsdf::pdf`] and
/// [`Bsdf::pdf_reverse`] for directions on the lit side.
#[derive(Clone, Copy, Debug)]
pub struct Lambertian {
    n: Vec3,
    ng: Vec3,
    /// f, the same for every pair of directions on the lit side.
    pub f: Spectrum,
    pick: f32,
    /// The density of drawing `wo` back from any direction on the lit side.
    pub reverse: f32,
}

impl Lambertian {
    /// The density of drawing `wi`, or `None` where `wi` is not on the lit side (f is zero).
    #[inline]
    pub fn pdf(&self, wi: Vec3) -> Option<f32> {
        lit_pdf(self.n, self.ng, self.pick, wi)
    }

    /// f, the cosine at `wi` ([`Bsdf::cos`]) and the density of drawing `wi`, where f is not
    /// zero (`None` off the lit side, or for a black surface).
    #[inline]
    pub fn toward(&self, wi: Vec3) -> Option<(Spectrum, f32, f32)> {
        let pdf = lit_pdf(self.n, self.ng, self.pick, wi)?;
        (self.f != Spectrum::ZERO).then(|| (self.f, self.n.dot(wi), pdf))
    }
}

/// The density of drawing `wi` from a Lambertian lobe picked with probability `pick`, under
/// shading normal `n` and geometric normal `ng`, or `None` off the lit side.
#[inline]
fn lit_pdf(n: Vec3, ng: Vec3, pick: f32, wi: Vec3) -> Option<f32> {
    let cos_i = n.dot(wi);
    if cos_i <= 0.0 || ng.dot(wi) <= 0.0 {
        return None;
    }
    Some(pick * cos_i / PI)
}

/// Whose Fresnel reflectance a microfacet lobe has.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Fresnel {
    /// A conductor of complex index η + ik per channel.
    Conductor { eta: Vec3, k: Vec3 },
    /// A dielectric of index η (a coat), its reflectance times `tint`.
    Dielectric { eta: f32, tint: Vec3 },
}

/// A GGX reflection lobe.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Microfacet {
    alpha: f32,
    fresnel: Fresnel,
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
        if scene.has_clearcoats() {
            return Bsdf::coated_at(scene, hit, wo, wl);
        }
        Bsdf::uncoated(scene, hit, wo, wl)
    }

    /// [`Bsdf::at`] in a scene with clear coats.
    #[inline(never)]
    fn coated_at(scene: &Scene, hit: &SurfaceHit, wo: Vec3, wl: &Wavelengths) -> Bsdf {
        let b = Bsdf::uncoated(scene, hit, wo, wl);
        match scene.clearcoat(hit) {
            Some(coat) => b.with_clearcoat(coat, wo),
            None => b,
        }
    }

    /// The lobes at a surface point without its clear coat.
    #[inline(always)]
    fn uncoated(scene: &Scene, hit: &SurfaceHit, wo: Vec3, wl: &Wavelengths) -> Bsdf {
        if let Some(physical) = scene.physical(hit) {
            return Bsdf::physical(&physical, hit.shading_normal, hit.geometric_normal, wo, wl);
        }
        let abbe = scene.abbe(hit);
        let spectra = match (wl.is_spectral(), hit.material) {
            (true, MaterialRef::One(id)) => Some(scene.material_spectra(id)),
            _ => None,
        };
        let (ns, ng) = (hit.shading_normal, hit.geometric_normal);
        match scene.constant_lobes(hit) {
            Some(lobes) => Bsdf::new(lobes, ns, ng, wo, wl, spectra, abbe),
            None => Bsdf::new(&Lobes::new(&scene.phong(hit)), ns, ng, wo, wl, spectra, abbe),
        }
    }

    /// A medium's phase function of mean cosine `g` at a scattering point, seen from `wo`, as
    /// lobes: smooth, its density its value (f·cos with a cosine of 1, [`Bsdf::cos`]). It is
    /// kept as a rough glass whose roughness is [`PHASE`] and whose index is g, so surfaces pay
    /// nothing for it: only the rough glass's own branches look.
    pub fn phase(g: f32, wo: Vec3, wl: &Wavelengths) -> Bsdf {
        Bsdf {
            frame: Frame::from_normal(wo),
            ng: Vec3::ZERO,
            outside: true,
            diffuse: Spectrum::ZERO,
            glossy: Spectrum::ZERO,
            exponent: 0.0,
            mirror: Spectrum::ZERO,
            transmission: wl.grey(1.0),
            index: g,
            dispersive: false,
            pick: [0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            coat: 0.0,
            coat_weight: 0.0,
            microfacet: None,
            diffuse_transmission: Spectrum::ZERO,
            thin: false,
            rough: PHASE,
            index_d: g,
            abbe: 0.0,
            clear: NO_COAT,
            p_coat: 0.0,
            reflection_bound: 1.0,
            wl: *wl,
        }
    }

    /// Whether these lobes are a medium's phase function ([`Bsdf::phase`]).
    #[inline]
    pub fn is_phase(&self) -> bool {
        self.rough == PHASE
    }

    /// The cosine that multiplies f towards `dir`: |n · dir| at a surface, 1 in a medium.
    #[inline]
    pub fn cos(&self, dir: Vec3) -> f32 {
        if self.is_phase() {
            1.0
        } else {
            self.frame.z.dot(dir).abs()
        }
    }

    /// The lobes of a course material (`lobes`, from its values) at a point with outward
    /// shading normal `ns` and geometric normal `ng`, seen from direction `wo` (unit, away from
    /// the surface), for light at wavelengths `wl`. A material's fitted spectra (`spectra`) are
    /// used for its constant colours; `abbe` makes its dielectric dispersive.
    #[inline]
    pub fn new(
        lobes: &Lobes,
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
        let Lobes {
            kd, ks, kr, kt, scale, ..
        } = *lobes;
        // Inside a dielectric the other lobes, which coat its outside, do not act.
        let bare_interface = !outside && lobes.pick[3] > 0.0;
        let (kd, ks, kr, pick) = if bare_interface {
            (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
        } else {
            (kd, ks, kr, lobes.pick)
        };
        // A colour at the wavelengths: the material's fitted spectrum (scaled like the colour)
        // where it has one, else the table's.
        let spectrum = |rgb: Vec3, fit: Option<SigmoidPolynomial>| match (wl, fit) {
            (Wavelengths::Sampled { lambda, .. }, Some(fit)) => Vec4::from_array(lambda.map(|l| fit.eval(l))) * scale,
            _ => wl.reflectance(rgb),
        };
        let [diffuse, glossy, mirror, transmission] = match wl {
            // The colours as they are, without the closure: called four times per hit, it took
            // each colour through memory and stalled on reading it back (6% of `path`).
            Wavelengths::Rgb => [kd, ks, kr, kt].map(|c| c.extend(0.0)),
            Wavelengths::Sampled { .. } => {
                let fits = spectra.copied().unwrap_or_default();
                [
                    spectrum(kd, fits.diffuse),
                    spectrum(ks, fits.specular),
                    spectrum(kr, fits.reflective),
                    spectrum(kt, fits.transmissive),
                ]
            }
        };
        let (index, dispersive) = match (abbe, wl.hero()) {
            (Some(v), Some(lambda)) if kt != Vec3::ZERO => (cauchy_index(lobes.index, v, lambda), true),
            _ => (lobes.index, false),
        };
        Bsdf {
            frame: Frame::from_normal(facing),
            ng: ng_facing,
            outside,
            diffuse,
            glossy,
            exponent: lobes.exponent,
            mirror,
            transmission,
            index,
            dispersive,
            pick,
            coat: 0.0,
            coat_weight: 0.0,
            microfacet: None,
            diffuse_transmission: Spectrum::ZERO,
            thin: false,
            rough: 0.0,
            index_d: lobes.index,
            abbe: 0.0,
            clear: NO_COAT,
            p_coat: 0.0,
            reflection_bound: lobes.reflection_bound,
            wl: *wl,
        }
    }

    /// The lobes of a material with its own physical description, at a point with outward
    /// shading normal `ns` and geometric normal `ng`, seen from `wo`.
    pub fn physical(material: &PhysicalMaterial<Vec3>, ns: Vec3, ng: Vec3, wo: Vec3, wl: &Wavelengths) -> Bsdf {
        let mut b = Bsdf::new(&Lobes::new(&SurfaceParams::default()), ns, ng, wo, wl, None, None);
        let cos_o = b.frame.z.dot(wo).clamp(0.0, 1.0);
        let clamp01 = |c: Vec3| c.clamp(Vec3::ZERO, Vec3::ONE);
        b.pick = [0.0; 6];
        // No physical material joins a dielectric to other lobes: the thin sheet stands alone.
        b.reflection_bound = 0.0;
        match *material {
            PhysicalMaterial::Conductor {
                eta,
                k,
                reflectance,
                roughness,
            } => {
                let (eta, k) = match reflectance {
                    // The index whose normal reflectance is r: η = 1, k = 2√r / √(1 − r).
                    Some(r) => {
                        let r = r.clamp(Vec3::ZERO, Vec3::splat(0.9999));
                        (Vec3::ONE, 2.0 * r.powf(0.5) / (Vec3::ONE - r).powf(0.5))
                    }
                    None => (eta.max(Vec3::splat(1e-4)), k.max(Vec3::ZERO)),
                };
                if roughness < SMOOTH_ALPHA {
                    b.mirror = wl.reflectance(fresnel_conductor_rgb(cos_o, eta, k));
                    b.pick[2] = 1.0;
                } else {
                    b.microfacet = Some(Microfacet {
                        alpha: roughness.min(1.0),
                        fresnel: Fresnel::Conductor { eta, k },
                    });
                    b.pick[4] = 1.0;
                }
            }
            PhysicalMaterial::CoatedDiffuse {
                reflectance,
                eta,
                roughness,
                coat_tint,
                layering,
            } => {
                let eta = eta.max(1.0);
                let tint = clamp01(coat_tint);
                let weight = tint.max_element();
                let f = weight * fresnel_dielectric(cos_o, eta);
                b.diffuse = wl.reflectance(clamp01(reflectance));
                if layering == Coating::Layered {
                    // The base's light reflected back down by the coat, again and again, and
                    // spread over the wider cone it leaves by (radiance over η²).
                    let inside = internal_diffuse_reflectance(eta);
                    b.diffuse /= (Spectrum::ONE - b.diffuse * inside) * (eta * eta);
                }
                b.coat = eta;
                // An added coat takes nothing from the base.
                b.coat_weight = if layering == Coating::Added { 0.0 } else { weight };
                b.pick[0] = b.diffuse.max_element() * (1.0 - f);
                if roughness < SMOOTH_ALPHA {
                    b.mirror = if tint == Vec3::ONE {
                        wl.grey(f)
                    } else {
                        wl.reflectance(tint) * fresnel_dielectric(cos_o, eta)
                    };
                    b.pick[2] = f;
                } else {
                    b.microfacet = Some(Microfacet {
                        alpha: roughness.min(1.0),
                        fresnel: Fresnel::Dielectric { eta, tint },
                    });
                    b.pick[4] = f.max(0.04 * weight);
                }
            }
            PhysicalMaterial::DiffuseTransmission {
                reflectance,
                transmittance,
            } => {
                let (mut r, mut t) = (reflectance.max(Vec3::ZERO), transmittance.max(Vec3::ZERO));
                let total = (r + t).max_element();
                if total > 1.0 {
                    r /= total;
                    t /= total;
                }
                b.diffuse = wl.reflectance(r);
                b.diffuse_transmission = wl.reflectance(t);
                b.pick[0] = r.max_element();
                b.pick[5] = t.max_element();
            }
            PhysicalMaterial::ThinDielectric { eta, tint } => {
                b.transmission = wl.reflectance(clamp01(tint));
                b.index = if eta > 0.0 { eta } else { 1.0 };
                b.thin = true;
                b.pick[3] = 1.0;
            }
            PhysicalMaterial::RoughDielectric {
                eta,
                roughness,
                tint,
                abbe,
            } => {
                let eta = if eta > 0.0 { eta } else { 1.0 };
                b.transmission = wl.reflectance(clamp01(tint));
                b.index_d = eta;
                b.index = eta;
                if let (Some(v), Some(lambda)) = (abbe, wl.hero()) {
                    b.index = cauchy_index(eta, v, lambda);
                    b.abbe = v;
                }
                if roughness < SMOOTH_ALPHA {
                    // A smooth interface: the hero alone follows a dispersive refraction.
                    b.dispersive = b.abbe > 0.0;
                    b.abbe = 0.0;
                } else {
                    b.rough = roughness.min(1.0);
                }
                b.pick[3] = 1.0;
            }
        }
        let sum: f32 = b.pick.iter().sum();
        if sum > 0.0 {
            b.pick.iter_mut().for_each(|p| *p /= sum);
        }
        b
    }

    /// These lobes under a clear coat seen from `wo` (glass takes none: its coat would be
    /// another interface). The coat reflects weight·F(θo) (a mirror when smooth, drawn with that
    /// chance; a GGX lobe drawn with at least 4% of it when rough); the lobes under it lose
    /// what the coat reflects on the way in and on the way out.
    pub fn with_clearcoat(mut self, coat: ClearCoat, wo: Vec3) -> Bsdf {
        self.add_clearcoat(coat, wo);
        self
    }

    /// [`Bsdf::with_clearcoat`] in place.
    pub fn add_clearcoat(&mut self, coat: ClearCoat, wo: Vec3) {
        if coat.weight <= 0.0 || self.pick[3] > 0.0 || self.rough > 0.0 {
            return;
        }
        let coat = ClearCoat {
            weight: coat.weight.min(1.0),
            eta: coat.eta.max(1.0),
            alpha: coat.alpha.min(1.0),
        };
        let f = coat.weight * fresnel_dielectric(self.frame.z.dot(wo).clamp(0.0, 1.0), coat.eta);
        self.mirror *= (1.0 - f) * (1.0 - f);
        self.clear = coat;
        let base: f32 = self.pick.iter().sum();
        let smooth = coat.alpha < SMOOTH_ALPHA;
        let p = match (base > 0.0, smooth) {
            (false, _) => 1.0,
            (true, true) => f,
            (true, false) => f.max(0.04 * coat.weight),
        };
        if base > 0.0 {
            self.pick.iter_mut().for_each(|x| *x *= (1.0 - p) / base);
        }
        if smooth {
            self.mirror += self.wl.grey(f);
            self.pick[2] += p;
        } else {
            self.p_coat = p;
        }
    }

    /// The rough coat's GGX lobe.
    #[inline]
    fn coat_lobe(&self) -> Microfacet {
        Microfacet {
            alpha: self.clear.alpha,
            fresnel: Fresnel::Dielectric {
                eta: self.clear.eta,
                tint: Vec3::ONE,
            },
        }
    }

    /// The share of the light under the coat that crosses it at cosine `cos` (1 without one).
    #[inline]
    fn through_coat(&self, cos: f32) -> f32 {
        1.0 - self.clear.weight * fresnel_dielectric(cos.clamp(0.0, 1.0), self.clear.eta)
    }

    /// Whether the surface has a smooth (non-delta) lobe: where light is sampled and photons
    /// are stored.
    #[inline]
    pub fn is_smooth(&self) -> bool {
        self.pick[0] > 0.0
            || self.pick[1] > 0.0
            || self.pick[4] > 0.0
            || self.pick[5] > 0.0
            || self.rough > 0.0
            || self.p_coat > 0.0
    }

    /// Whether every smooth lobe is narrow: a Phong lobe of exponent at least
    /// [`SHARP_EXPONENT`] or a GGX lobe of α at most [`SHARP_ALPHA`], with no diffuse lobe. A
    /// photon estimate there weighs each photon by a peaked f and is noisy; a direction drawn
    /// from the lobe is not, so photon mapping's camera paths go on through such a surface.
    #[inline]
    pub fn is_sharply_glossy(&self) -> bool {
        let no_diffuse = self.pick[0] == 0.0 && self.pick[5] == 0.0;
        let phong_sharp = self.pick[1] == 0.0 || self.exponent >= SHARP_EXPONENT;
        let ggx_sharp = self.pick[4] == 0.0 || self.microfacet.is_some_and(|m| m.alpha <= SHARP_ALPHA);
        let glass_sharp = self.rough <= SHARP_ALPHA;
        let coat_sharp = self.p_coat == 0.0 || self.clear.alpha <= SHARP_ALPHA;
        no_diffuse && phong_sharp && ggx_sharp && glass_sharp && coat_sharp && self.is_smooth()
    }

    /// Whether light arriving on the far side reaches `wo` through a smooth lobe (diffuse
    /// transmission, rough glass): photons on both faces count at such a point.
    #[inline]
    pub fn transmits_smoothly(&self) -> bool {
        self.pick[5] > 0.0 || self.rough > 0.0
    }

    /// Whether light can leave the surface at all.
    #[inline]
    pub fn is_black(&self) -> bool {
        self.pick.iter().all(|&p| p == 0.0) && self.p_coat == 0.0
    }

    /// The shading normal on the side of `wo`.
    #[inline]
    pub fn normal(&self) -> Vec3 {
        self.frame.z
    }

    /// The smooth lobes' f(wo, wi) for radiance (delta lobes are never hit by a given
    /// direction).
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> Spectrum {
        self.eval_in(wo, wi, Transport::Radiance)
    }

    /// Whether light arriving from `wi` can reach the smooth lobes: `false` only where
    /// [`Bsdf::eval_in`] is zero whatever `wo` (a surface that only reflects, lit from behind),
    /// so that next-event estimation spares such a sample its shadow ray.
    #[inline]
    pub fn may_take(&self, wi: Vec3) -> bool {
        if self.rough > 0.0 {
            return true;
        }
        let (cos_i, cos_g) = (self.frame.z.dot(wi), self.ng.dot(wi));
        if cos_i < 0.0 && cos_g < 0.0 {
            return self.diffuse_transmission != Spectrum::ZERO || self.clear.weight > 0.0;
        }
        // As `eval_in` tests it, so that NaN cosines go on to the evaluation as there.
        !(cos_i <= 0.0 || cos_g <= 0.0)
    }

    /// The smooth lobes' f(wo, wi) for the transport `mode`: a walk from a light evaluates the
    /// adjoint, which differs where rough glass refracts (by η²).
    #[inline]
    pub fn eval_in(&self, wo: Vec3, wi: Vec3, mode: Transport) -> Spectrum {
        if self.rough > 0.0 {
            return self.rough_eval(wo, wi, mode);
        }
        let n = self.frame.z;
        let cos_i = n.dot(wi);
        if cos_i < 0.0 && self.ng.dot(wi) < 0.0 {
            let f = self.diffuse_transmission * (1.0 / PI);
            return if self.clear.weight > 0.0 {
                f * self.through_coat(n.dot(wo))
            } else {
                f
            };
        }
        if cos_i <= 0.0 || self.ng.dot(wi) <= 0.0 {
            return Spectrum::ZERO;
        }
        let mut f = self.diffuse * (self.coat_transmittance(n.dot(wo), cos_i) / PI);
        if let Some(m) = &self.microfacet {
            f += m.eval(n, wo, wi, &self.wl);
        }
        if self.glossy != Spectrum::ZERO {
            let cos_a = reflect(-wo, n).dot(wi);
            if cos_a > 0.0 {
                f += self.glossy * ((self.exponent + 2.0) / (2.0 * PI) * cos_a.powf(self.exponent));
            }
        }
        if self.clear.weight > 0.0 {
            return self.under_coat(f, wo, wi);
        }
        f
    }

    /// `f` of the lobes under the clear coat, seen through it both ways, plus a rough coat's own
    /// reflection.
    #[inline(never)]
    fn under_coat(&self, f: Spectrum, wo: Vec3, wi: Vec3) -> Spectrum {
        let n = self.frame.z;
        let f = f * (self.through_coat(n.dot(wo)) * self.through_coat(n.dot(wi)));
        if self.p_coat > 0.0 {
            return f + self.coat_lobe().eval(n, wo, wi, &self.wl) * self.clear.weight;
        }
        f
    }

    /// Whether the surface is a purely Lambertian reflector.
    #[inline]
    pub fn is_lambertian(&self) -> bool {
        let only_diffuse = self.pick[0] > 0.0 && self.pick[1..].iter().all(|&p| p == 0.0);
        only_diffuse && self.coat <= 0.0 && self.microfacet.is_none() && self.clear.weight == 0.0
    }

    /// A purely Lambertian reflection seen from `wo`, for asking about many light directions
    /// (merging's candidates) at the cost of one; `None` for any other lobes.
    pub fn lambertian(&self, wo: Vec3) -> Option<Lambertian> {
        if !self.is_lambertian() {
            return None;
        }
        let cos_o = self.frame.z.dot(wo);
        let reverse = if cos_o > 0.0 && self.ng.dot(wo) > 0.0 {
            self.pick[0] * cos_o / PI
        } else {
            0.0
        };
        Some(Lambertian {
            n: self.frame.z,
            ng: self.ng,
            f: self.lambertian_f(),
            pick: self.pick[0],
            reverse,
        })
    }

    /// [`Bsdf::lambertian`] where the Lambertian lobe is all there is to evaluate: no
    /// highlight, diffuse transmission or rough glass, so that its f, cosine and density are
    /// [`Bsdf::eval`]'s, [`Bsdf::cos`]'s and [`Bsdf::pdf`]'s to the bit, for a fraction of their
    /// cost (next-event estimation asks all three).
    #[inline]
    pub fn plain_lambertian(&self, wo: Vec3) -> Option<Lambertian> {
        let plain = self.rough == 0.0
            && self.p_coat == 0.0
            && self.glossy == Spectrum::ZERO
            && self.diffuse_transmission == Spectrum::ZERO;
        if plain {
            self.lambertian(wo)
        } else {
            None
        }
    }

    /// f of a purely Lambertian reflection, as [`Bsdf::eval_in`] computes it.
    #[inline]
    fn lambertian_f(&self) -> Spectrum {
        self.diffuse * (1.0 / PI)
    }

    /// Solid-angle pdf with which [`Bsdf::sample`] draws `wi` through its smooth lobes.
    pub fn pdf(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.rough > 0.0 {
            return self.rough_pdf(wo, wi, false);
        }
        let n = self.frame.z;
        let cos_i = n.dot(wi);
        if cos_i < 0.0 && self.ng.dot(wi) < 0.0 {
            return self.pick[5] * -cos_i / PI;
        }
        if cos_i <= 0.0 || self.ng.dot(wi) <= 0.0 {
            return 0.0;
        }
        let mut pdf = self.pick[0] * cos_i / PI;
        if let Some(m) = &self.microfacet {
            pdf += self.pick[4] * m.pdf(n, wo, wi);
        }
        if self.pick[1] > 0.0 {
            let cos_a = reflect(-wo, n).dot(wi);
            if cos_a > 0.0 {
                pdf += self.pick[1] * (self.exponent + 1.0) / (2.0 * PI) * cos_a.powf(self.exponent);
            }
        }
        if self.p_coat > 0.0 {
            pdf += self.p_coat * self.coat_lobe().pdf(n, wo, wi);
        }
        pdf
    }

    /// Solid-angle pdf with which the smooth lobes would draw `wo` had the path arrived from
    /// `wi`: the reverse density bidirectional methods weight with. The lobes are reciprocal
    /// and chosen with fixed probabilities, so reflection swaps the arguments; transmission
    /// is Lambertian either way.
    pub fn pdf_reverse(&self, wo: Vec3, wi: Vec3) -> f32 {
        if self.rough > 0.0 {
            return self.rough_pdf(wo, wi, true);
        }
        if self.ng.dot(wi) < 0.0 {
            return self.pick[5] * self.frame.z.dot(wo).abs() / PI;
        }
        self.pdf(wi, wo)
    }

    /// Draws a direction: `u_lobe` picks the lobe (and Fresnel's choice), `u` the direction.
    pub fn sample(&self, wo: Vec3, u_lobe: f32, u: glam::Vec2, mode: Transport) -> Option<BsdfSample> {
        let n = self.frame.z;
        let [p_diffuse, p_glossy, p_mirror, p_dielectric, _, _] = self.pick;
        let mut x = u_lobe;
        if self.p_coat > 0.0 {
            if x < self.p_coat {
                let wi = self.coat_lobe().sample(&self.frame, wo, u)?;
                if n.dot(wi) <= 0.0 || self.ng.dot(wi) <= 0.0 {
                    return None;
                }
                return self.smooth_sample(wo, wi);
            }
            x -= self.p_coat;
        }
        if x < p_diffuse + p_glossy {
            let wi = if x < p_diffuse {
                let wi = self.frame.to_world(sample_cosine_hemisphere(u));
                if self.rough == 0.0 && self.p_coat == 0.0 && self.glossy == Spectrum::ZERO && self.is_lambertian() {
                    return self.lambertian_sample(wi);
                }
                wi
            } else {
                let r = reflect(-wo, n);
                let cos_a = u.x.powf(1.0 / (self.exponent + 1.0));
                let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
                let (sin, cos) = sin_cos_turns(u.y);
                Frame::from_normal(r).to_world(Vec3::new(sin_a * cos, sin_a * sin, cos_a))
            };
            return self.smooth_sample(wo, wi);
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
        if p_dielectric <= 0.0 || (x - p_mirror >= p_dielectric && self.pick[4] + self.pick[5] > 0.0) {
            return self.sample_physical(wo, x - p_mirror - p_dielectric, u);
        }
        if self.thin {
            return self.sample_thin(wo, (x - p_mirror) / p_dielectric);
        }
        if self.rough > 0.0 {
            return self.sample_rough(wo, (x - p_mirror) / p_dielectric, u, mode);
        }
        // The dielectric: reflect with probability F, else refract.
        let x = ((x - p_mirror) / p_dielectric).clamp(0.0, 1.0);
        let eta = if self.outside { self.index } else { 1.0 / self.index };
        let cos_o = n.dot(wo).clamp(0.0, 1.0);
        let f = fresnel_dielectric(cos_o, eta);
        let room = self.dielectric_room(f);
        if x < f {
            let wi = reflect(-wo, n);
            // Inside, the bare interface reflects all that Fresnel says.
            let kept = if self.outside { room } else { 1.0 };
            return Some(BsdfSample {
                wi,
                weight: Spectrum::ONE * (kept / p_dielectric),
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
            weight: self.transmission * (room * scale / p_dielectric),
            pdf: p_dielectric * (1.0 - f),
            specular: true,
            transmitted: true,
            dispersive: self.dispersive,
        })
    }
}

/// Veach's correction of the adjoint BSDF for shading normals (thesis, §5.3): a particle
/// carrying importance-transport flux (a photon) that arrives from `wo` and leaves towards
/// `wi` (both unit, away from the surface) must be multiplied by f·|wo·ns|·|wi·ng| / (|wo·ng|·pdf),
/// not by [`BsdfSample::weight`]'s f·|wi·ns| / pdf, for its density to give the radiance that
/// camera paths compute with the shading normal `ns` (`ng`: the geometric normal). This returns
/// the ratio of the two, |wo·ns|·|wi·ng| / (|wo·ng|·|wi·ns|), for every lobe, delta lobes
/// included; exactly 1 where the shading normal is the geometric one, and `None` where it is
/// undefined (a direction in the surface's plane): the particle is dropped there.
#[inline]
pub fn adjoint_correction(ns: Vec3, ng: Vec3, wo: Vec3, wi: Vec3) -> Option<f32> {
    if ns == ng {
        return Some(1.0);
    }
    let denominator = wo.dot(ng).abs() * wi.dot(ns).abs();
    if denominator.is_nan() || denominator <= 0.0 {
        return None;
    }
    let c = wo.dot(ns).abs() * wi.dot(ng).abs() / denominator;
    c.is_finite().then_some(c)
}

impl Bsdf {
    /// The sample of a smooth lobe in direction `wi`, weighted by the whole mixture.
    /// [`Bsdf::smooth_sample`] of a purely Lambertian reflector: the same arithmetic as its
    /// `pdf` and `eval` there, without their tests for the lobes it lacks.
    #[inline]
    fn lambertian_sample(&self, wi: Vec3) -> Option<BsdfSample> {
        let pdf = lit_pdf(self.frame.z, self.ng, self.pick[0], wi)?;
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.lambertian_f() * self.frame.z.dot(wi).abs() / pdf,
            pdf,
            specular: false,
            transmitted: false,
            dispersive: false,
        })
    }

    fn smooth_sample(&self, wo: Vec3, wi: Vec3) -> Option<BsdfSample> {
        let pdf = self.pdf(wo, wi);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        let cos = self.frame.z.dot(wi);
        let weight = self.eval(wo, wi) * cos.abs() / pdf;
        Some(BsdfSample {
            wi,
            weight,
            pdf,
            specular: false,
            transmitted: cos < 0.0,
            dispersive: false,
        })
    }

    /// The physical lobes after the course's four: `x` in [0, pick[4] + pick[5]).
    fn sample_physical(&self, wo: Vec3, x: f32, u: glam::Vec2) -> Option<BsdfSample> {
        let n = self.frame.z;
        if x < self.pick[4] {
            let m = self.microfacet.as_ref()?;
            let wi = m.sample(&self.frame, wo, u)?;
            if n.dot(wi) <= 0.0 || self.ng.dot(wi) <= 0.0 {
                return None;
            }
            return self.smooth_sample(wo, wi);
        }
        if self.pick[5] > 0.0 {
            let wi = -self.frame.to_world(sample_cosine_hemisphere(u));
            if self.ng.dot(wi) >= 0.0 {
                return None;
            }
            return self.smooth_sample(wo, wi);
        }
        None
    }

    /// The relative index of a rough dielectric from `wo`'s side, at the hero wavelength.
    #[inline]
    fn rough_interface(&self, index: f32) -> rough_dielectric::Interface {
        rough_dielectric::Interface::new(self.rough, if self.outside { index } else { 1.0 / index })
    }

    /// Whether `wi` leaves on the side the shading normal says: reflection above both normals,
    /// transmission below both (light never leaks through the geometric surface).
    #[inline]
    fn sides_agree(&self, wi: Vec3) -> bool {
        (self.frame.z.dot(wi) > 0.0) == (self.ng.dot(wi) > 0.0)
    }

    /// A rough dielectric's f: each wavelength refracts by its own index where the glass is
    /// dispersive, so every wavelength follows any direction (no hero termination).
    fn rough_eval(&self, wo: Vec3, wi: Vec3, mode: Transport) -> Spectrum {
        if self.is_phase() {
            return self.wl.grey(henyey_greenstein(wo.dot(wi), self.index));
        }
        if !self.sides_agree(wi) {
            return Spectrum::ZERO;
        }
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        let f = match self.wl {
            Wavelengths::Sampled { lambda, .. } if self.abbe > 0.0 => Vec4::from_array(lambda.map(|l| {
                self.rough_interface(cauchy_index(self.index_d, self.abbe, l))
                    .eval(lo, li, mode)
            })),
            _ => self.wl.grey(self.rough_interface(self.index).eval(lo, li, mode)),
        };
        if li.z < 0.0 {
            f * self.transmission
        } else {
            f
        }
    }

    /// The density of drawing `wi` from `wo` (`reverse`: of drawing `wo` had the walk arrived
    /// from `wi`, seen from `wi`'s side, where the relative index is inverted).
    fn rough_pdf(&self, wo: Vec3, wi: Vec3, reverse: bool) -> f32 {
        if self.is_phase() {
            return henyey_greenstein(wo.dot(wi), self.index);
        }
        if !self.sides_agree(wi) {
            return 0.0;
        }
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        match (reverse, li.z < 0.0) {
            (false, _) => self.rough_interface(self.index).pdf(lo, li),
            (true, false) => self.rough_interface(self.index).pdf(li, lo),
            // Seen from the far side the relative index is inverted.
            (true, true) => self.rough_interface(1.0 / self.index).pdf(-li, -lo),
        }
    }

    /// Reflection or refraction off a visible microfacet of a rough dielectric (`x` in [0, 1)
    /// makes Fresnel's choice).
    fn sample_rough(&self, wo: Vec3, x: f32, u: glam::Vec2, mode: Transport) -> Option<BsdfSample> {
        if self.is_phase() {
            let (wi, pdf) = Phase { g: self.index }.sample(wo, u);
            return Some(BsdfSample {
                wi,
                weight: self.wl.grey(1.0),
                pdf,
                specular: false,
                transmitted: false,
                dispersive: false,
            });
        }
        let li = self.rough_interface(self.index).sample(self.frame.to_local(wo), x, u)?;
        let wi = self.frame.to_world(li);
        let pdf = self.rough_pdf(wo, wi, false);
        if pdf.is_nan() || pdf <= 0.0 {
            return None;
        }
        Some(BsdfSample {
            wi,
            weight: self.rough_eval(wo, wi, mode) * (li.z.abs() / pdf),
            pdf,
            specular: false,
            transmitted: li.z < 0.0,
            dispersive: false,
        })
    }

    /// A thin dielectric sheet: reflect with the two faces' reflectance 2R/(1 + R), else pass
    /// straight through (`x` in [0, 1)).
    fn sample_thin(&self, wo: Vec3, x: f32) -> Option<BsdfSample> {
        let n = self.frame.z;
        let p = self.pick[3];
        let r = fresnel_dielectric(n.dot(wo).clamp(0.0, 1.0), self.index);
        let r = if r < 1.0 { 2.0 * r / (1.0 + r) } else { 1.0 };
        let room = self.dielectric_room(r);
        if x < r {
            return Some(BsdfSample {
                wi: reflect(-wo, n),
                weight: self.wl.grey(room / p),
                pdf: p * r,
                specular: true,
                transmitted: false,
                dispersive: false,
            });
        }
        Some(BsdfSample {
            wi: -wo,
            weight: self.transmission * (room / p),
            pdf: p * (1.0 - r),
            specular: true,
            transmitted: true,
            dispersive: false,
        })
    }

    /// The share of the dielectric kept on the outside where it reflects `reflectance` (and
    /// transmits the rest times kt): all of it unless with the other lobes' albedo (at most
    /// kd + ks + kr) it would reflect more than all the light. Refraction keeps the outside's
    /// share from either side: Fresnel's reflectance, and so this share, is the same at both
    /// ends of a refracted pair.
    #[inline]
    fn dielectric_room(&self, reflectance: f32) -> f32 {
        let others = self.reflection_bound;
        if others <= 0.0 {
            return 1.0;
        }
        let albedo = reflectance + (1.0 - reflectance) * self.transmission.max_element();
        let room = (1.0 - others).max(0.0);
        if albedo > room {
            room / albedo
        } else {
            1.0
        }
    }

    /// The share of light that crosses a clear coat on the way in and out (1 without a coat).
    #[inline]
    fn coat_transmittance(&self, cos_o: f32, cos_i: f32) -> f32 {
        if self.coat <= 0.0 {
            return 1.0;
        }
        let w = self.coat_weight;
        (1.0 - w * fresnel_dielectric(cos_o.clamp(0.0, 1.0), self.coat))
            * (1.0 - w * fresnel_dielectric(cos_i, self.coat))
    }
}

pub use crate::description::SMOOTH_ALPHA;

/// No clear coat.
const NO_COAT: ClearCoat = ClearCoat {
    weight: 0.0,
    eta: 1.0,
    alpha: 0.0,
};

/// From this Phong exponent on, a lobe is sharp ([`Bsdf::is_sharply_glossy`]): its peak f is
/// 16 times a white Lambertian surface's.
pub const SHARP_EXPONENT: f32 = 30.0;

/// The GGX α of about the same width as [`SHARP_EXPONENT`]'s lobe (α = √(2 / (n + 2)), Walter
/// et al. 2007).
pub const SHARP_ALPHA: f32 = 0.25;

impl Microfacet {
    /// Trowbridge–Reitz (GGX) density of microfacet normals at cosine `cos_h` from `n`.
    fn d(&self, cos_h: f32) -> f32 {
        if cos_h <= 0.0 {
            return 0.0;
        }
        let a2 = self.alpha * self.alpha;
        let c2 = cos_h * cos_h;
        let denom = c2 * (a2 - 1.0) + 1.0;
        a2 / (PI * denom * denom)
    }

    /// Smith's Λ for a direction at cosine `cos` from the normal.
    fn lambda(&self, cos: f32) -> f32 {
        let c2 = (cos * cos).clamp(1e-12, 1.0);
        let tan2 = (1.0 - c2) / c2;
        0.5 * ((1.0 + self.alpha * self.alpha * tan2).sqrt() - 1.0)
    }

    fn fresnel(&self, cos: f32) -> Vec3 {
        match self.fresnel {
            Fresnel::Conductor { eta, k } => fresnel_conductor_rgb(cos, eta, k),
            Fresnel::Dielectric { eta, tint } => tint * fresnel_dielectric(cos, eta),
        }
    }

    /// F D G / (4 cos θo cos θi), with the height-correlated G = 1 / (1 + Λo + Λi); F (a
    /// colour in [0, 1]) taken to the wavelengths `wl`.
    fn eval(&self, n: Vec3, wo: Vec3, wi: Vec3, wl: &Wavelengths) -> Spectrum {
        let (cos_o, cos_i) = (n.dot(wo), n.dot(wi));
        if cos_o <= 0.0 || cos_i <= 0.0 {
            return Spectrum::ZERO;
        }
        let h = (wo + wi).normalize_or_zero();
        if h == Vec3::ZERO {
            return Spectrum::ZERO;
        }
        let g = 1.0 / (1.0 + self.lambda(cos_o) + self.lambda(cos_i));
        wl.reflectance(self.fresnel(wo.dot(h).clamp(0.0, 1.0))) * (self.d(n.dot(h)) * g / (4.0 * cos_o * cos_i))
    }

    /// Solid-angle pdf of [`Microfacet::sample`]: D(h) cos θh / (4 |ωo·h|).
    fn pdf(&self, n: Vec3, wo: Vec3, wi: Vec3) -> f32 {
        let h = (wo + wi).normalize_or_zero();
        let wo_h = wo.dot(h);
        if h == Vec3::ZERO || wo_h <= 0.0 {
            return 0.0;
        }
        let cos_h = n.dot(h);
        self.d(cos_h) * cos_h / (4.0 * wo_h)
    }

    /// Reflects `wo` about a microfacet normal drawn with density D(h) cos θh.
    fn sample(&self, frame: &Frame, wo: Vec3, u: glam::Vec2) -> Option<Vec3> {
        let a2 = self.alpha * self.alpha;
        let x = u.x.min(1.0 - 1e-7);
        let tan2 = a2 * x / (1.0 - x);
        let cos_h = 1.0 / (1.0 + tan2).sqrt();
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let (sin, cos) = sin_cos_turns(u.y);
        let h = frame.to_world(Vec3::new(sin_h * cos, sin_h * sin, cos_h));
        let wo_h = wo.dot(h);
        (wo_h > 0.0).then(|| 2.0 * wo_h * h - wo)
    }
}

/// Fresnel reflectance of a conductor of complex index η + ik for unpolarised light arriving at
/// cosine `cos_i`, per channel.
pub fn fresnel_conductor_rgb(cos_i: f32, eta: Vec3, k: Vec3) -> Vec3 {
    Vec3::new(
        fresnel_conductor(cos_i, eta.x, k.x),
        fresnel_conductor(cos_i, eta.y, k.y),
        fresnel_conductor(cos_i, eta.z, k.z),
    )
}

/// Fresnel reflectance of a conductor (one channel): the two polarisations' amplitude ratios
/// with the complex index, averaged in power.
pub fn fresnel_conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    #[derive(Clone, Copy)]
    struct C(f64, f64);
    let mul = |a: C, b: C| C(a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        C((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let sqrt = |a: C| {
        let m = (a.0 * a.0 + a.1 * a.1).sqrt();
        let re = (0.5 * (m + a.0)).max(0.0).sqrt();
        let im = (0.5 * (m - a.0)).max(0.0).sqrt().copysign(a.1);
        C(re, im)
    };
    let norm2 = |a: C| a.0 * a.0 + a.1 * a.1;
    let c = (cos_i as f64).clamp(0.0, 1.0);
    let n = C(eta as f64, k as f64);
    let sin2 = C(1.0 - c * c, 0.0);
    let sin2_t = div(sin2, mul(n, n));
    let cos_t = sqrt(C(1.0 - sin2_t.0, -sin2_t.1));
    let n_cos_i = C(n.0 * c, n.1 * c);
    let parallel = div(
        C(n_cos_i.0 - cos_t.0, n_cos_i.1 - cos_t.1),
        C(n_cos_i.0 + cos_t.0, n_cos_i.1 + cos_t.1),
    );
    let n_cos_t = mul(n, cos_t);
    let perpendicular = div(C(c - n_cos_t.0, -n_cos_t.1), C(c + n_cos_t.0, n_cos_t.1));
    (0.5 * (norm2(parallel) + norm2(perpendicular))) as f32
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

/// The share of cosine-distributed (diffuse) light inside a dielectric of relative index
/// `eta` ≥ 1 that its smooth surface reflects back in: 1 − (1 − F̄)/η², F̄ the cosine-weighted mean
/// of the reflectance from outside (what crosses inwards equals what crosses outwards, and
/// inside, light beyond the critical angle is all reflected). Read from a table over η in
/// [1, 4] built on first use.
pub fn internal_diffuse_reflectance(eta: f32) -> f32 {
    const STEPS: usize = 512;
    const MAX: f32 = 4.0;
    static TABLE: std::sync::OnceLock<Vec<f32>> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        (0..=STEPS)
            .map(|i| {
                let eta = 1.0 + (MAX - 1.0) * i as f32 / STEPS as f32;
                // F̄ = 2∫F(μ)μ dμ = ∫F(√s) ds over s = μ², by the midpoint rule.
                let n = 1024;
                let mean = (0..n)
                    .map(|j| fresnel_dielectric(((j as f32 + 0.5) / n as f32).sqrt(), eta) as f64)
                    .sum::<f64>()
                    / n as f64;
                1.0 - (1.0 - mean as f32) / (eta * eta)
            })
            .collect()
    });
    let x = ((eta.clamp(1.0, MAX) - 1.0) / (MAX - 1.0)) * STEPS as f32;
    let i = (x as usize).min(STEPS - 1);
    let t = x - i as f32;
    table[i] + (table[i + 1] - table[i]) * t
}

#[cfg(test)]
mod chi2;

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
    /// Veach's factor is exactly 1 on flat geometry, 1 for a photon leaving the way it came,
    /// the ratio of the cosines otherwise, and undefined for a photon arriving in the plane.
    #[test]
    fn adjoint_correction_is_one_on_flat_geometry() {
        let ng = Vec3::Z;
        let ns = Vec3::new(0.5, 0.0, 0.75f32.sqrt());
        let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
        let wi = Vec3::new(-0.6, 0.1, 0.5).normalize();
        assert_eq!(adjoint_correction(ng, ng, wo, wi), Some(1.0));
        assert_eq!(adjoint_correction(-ng, -ng, wo, -wi), Some(1.0));
        let same = adjoint_correction(ns, ng, wo, wo).unwrap();
        assert!((same - 1.0).abs() < 1e-6, "{same}");
        let c = adjoint_correction(ns, ng, wo, wi).unwrap();
        let expected = wo.dot(ns) * wi.dot(ng) / (wo.dot(ng) * wi.dot(ns));
        assert!((c - expected).abs() < 1e-6 * expected, "{c} vs {expected}");
        assert_eq!(adjoint_correction(ns, ng, Vec3::X, wi), None);
    }

    /// A Lambertian reflector's samples skip the generic `pdf` and `eval`, with the same
    /// arithmetic: the same bits as `smooth_sample` of the same direction, under tilted shading
    /// normals too (where some directions fall below the geometric surface).
    #[test]
    fn lambertian_samples_are_the_generic_samples_bit_for_bit() {
        let mut rng = Rng::new(7, 0);
        let (mut taken, mut tried) = (0, 0);
        for kd in [0.8, 0.25] {
            for _ in 0..20_000 {
                let ng = Vec3::Z;
                let tilt = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 0.0);
                let ns = (ng + tilt).normalize();
                let wo = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform()).normalize();
                let bsdf = Bsdf::new(&Lobes::new(&params(kd, 0.0, 1.0)), ns, ng, wo, &RGB, None, None);
                assert!(bsdf.is_lambertian());
                let (u_lobe, u) = (rng.uniform(), rng.uniform2());
                let wi = bsdf.frame.to_world(sample_cosine_hemisphere(u));
                let fast = bsdf.sample(wo, u_lobe, u, Transport::Radiance);
                let generic = bsdf.smooth_sample(wo, wi);
                tried += 1;
                taken += usize::from(fast.is_some());
                match (fast, generic) {
                    (Some(a), Some(b)) => {
                        assert_eq!(a.wi, b.wi);
                        assert_eq!(
                            a.weight.to_array().map(f32::to_bits),
                            b.weight.to_array().map(f32::to_bits)
                        );
                        assert_eq!(a.pdf.to_bits(), b.pdf.to_bits());
                        assert_eq!(
                            (a.specular, a.transmitted, a.dispersive),
                            (b.specular, b.transmitted, b.dispersive)
                        );
                    }
                    (None, None) => {}
                    (a, b) => panic!("{a:?} vs {b:?}"),
                }
            }
        }
        // Most samples are taken, and some fall below the geometric surface.
        assert!(taken > tried * 3 / 4 && taken < tried, "{taken} of {tried}");
    }

    /// Next-event estimation's shortcut for a plain Lambertian reflector gives `eval`'s f,
    /// `cos`'s cosine, and `pdf`'s and `pdf_reverse`'s densities to the bit wherever f is not
    /// zero, and says so exactly where f is zero; surfaces with other lobes take no shortcut.
    #[test]
    fn a_plain_lambertian_answers_as_eval_cos_and_pdf_bit_for_bit() {
        let mut rng = Rng::new(11, 0);
        let bits = |s: Spectrum| s.to_array().map(f32::to_bits);
        let (mut lit, mut unlit) = (0, 0);
        // Walls, a black one, and two with a highlight: more than the lobe, no shortcut.
        for (kd, ks) in [(0.8, 0.0), (0.25, 0.0), (0.0, 0.0), (0.5, 0.4), (0.0, 0.9)] {
            for _ in 0..20_000 {
                let ng = Vec3::Z;
                let tilt = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 0.0);
                let ns = (ng + tilt).normalize();
                let wo = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform()).normalize();
                let wi = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.3).normalize();
                let bsdf = Bsdf::new(&Lobes::new(&params(kd, ks, 30.0)), ns, ng, wo, &RGB, None, None);
                let Some(lambertian) = bsdf.plain_lambertian(wo) else {
                    // A black surface has no lobe to pick; a highlight is more than the lobe.
                    assert!(kd == 0.0 || ks > 0.0, "{kd} {ks}");
                    continue;
                };
                assert_eq!(ks, 0.0);
                let f = bsdf.eval(wo, wi);
                match lambertian.toward(wi) {
                    Some((fast_f, cos, pdf)) => {
                        lit += 1;
                        assert_eq!(bits(fast_f), bits(f));
                        assert_eq!(cos.to_bits(), bsdf.cos(wi).to_bits());
                        assert_eq!(pdf.to_bits(), bsdf.pdf(wo, wi).to_bits());
                        assert_eq!(lambertian.reverse.to_bits(), bsdf.pdf_reverse(wo, wi).to_bits());
                    }
                    None => {
                        unlit += 1;
                        assert_eq!(f, Spectrum::ZERO, "{wo} {wi}");
                    }
                }
            }
        }
        assert!(lit > 10_000 && unlit > 5_000, "{lit} lit, {unlit} unlit");
    }

    #[test]
    fn smooth_lobes_conserve_energy_and_weights_match_eval() {
        let n = Vec3::Z;
        let wo = Vec3::Z;
        for (kd, ks, exp) in [(0.8, 0.0, 1.0), (0.0, 0.9, 10.0), (0.0, 0.9, 200.0), (0.5, 0.4, 30.0)] {
            let bsdf = Bsdf::new(&Lobes::new(&params(kd, ks, exp)), n, n, wo, &RGB, None, None);
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
        let bsdf = Bsdf::new(&Lobes::new(&params(0.3, 0.5, 5.0)), n, n, wo, &RGB, None, None);
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
        let bsdf = Bsdf::new(&Lobes::new(&glass), n, n, wo, &RGB, None, None);
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
            &Lobes::new(&glass),
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

    fn conductor(r: f32, alpha: f32) -> PhysicalMaterial<Vec3> {
        PhysicalMaterial::Conductor {
            eta: Vec3::ONE,
            k: Vec3::ZERO,
            reflectance: Some(Vec3::splat(r)),
            roughness: alpha,
        }
    }

    /// Mean weight of many samples (the directional albedo), checking on the way that every
    /// smooth sample's weight is eval·|cos|/pdf.
    fn albedo(bsdf: &Bsdf, wo: Vec3, seed: u64) -> f64 {
        let mut rng = Rng::new(seed, 0);
        let count = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..count {
            if let Some(s) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance) {
                if !s.specular {
                    let expected = bsdf.eval(wo, s.wi) * s.wi.z.abs() / bsdf.pdf(wo, s.wi);
                    assert!(
                        (s.weight - expected).length() < 1e-3 * (1.0 + expected.length()),
                        "{s:?}"
                    );
                    assert!((s.pdf - bsdf.pdf(wo, s.wi)).abs() <= 1e-4 * s.pdf);
                }
                sum += s.weight.x as f64;
            }
        }
        sum / count as f64
    }

    /// ∫ f·|cos θi| dωi of the smooth lobes over the upper hemisphere by the midpoint rule in θ
    /// and φ (an independent check on the sampled albedo; delta lobes are not included).
    fn smooth_albedo_by_quadrature(bsdf: &Bsdf, wo: Vec3) -> f64 {
        albedo_by_quadrature(bsdf, wo, false, Transport::Radiance)
    }

    /// ∫ f·|cos θi| dωi for transport `mode` over the upper hemisphere (or the whole sphere) by
    /// the midpoint rule in θ and φ.
    pub(super) fn albedo_by_quadrature(bsdf: &Bsdf, wo: Vec3, whole_sphere: bool, mode: Transport) -> f64 {
        let (nt, np, theta_max) = if whole_sphere {
            (3000, 720, std::f64::consts::PI)
        } else {
            (1500, 360, std::f64::consts::FRAC_PI_2)
        };
        let (dt, dp) = (theta_max / nt as f64, 2.0 * std::f64::consts::PI / np as f64);
        let mut sum = 0.0f64;
        for i in 0..nt {
            let t = (i as f64 + 0.5) * dt;
            for j in 0..np {
                let p = (j as f64 + 0.5) * dp;
                let wi = Vec3::new((t.sin() * p.cos()) as f32, (t.sin() * p.sin()) as f32, t.cos() as f32);
                sum += bsdf.eval_in(wo, wi, mode).x as f64 * t.cos().abs() * t.sin() * dt * dp;
            }
        }
        sum
    }

    #[test]
    fn conductor_fresnel_matches_its_closed_forms() {
        // The index made from a reflectance gives it back at normal incidence.
        for r in [0.04f32, 0.5, 0.9] {
            let k = 2.0 * r.sqrt() / (1.0 - r).sqrt();
            assert!((fresnel_conductor(1.0, 1.0, k) - r).abs() < 1e-5, "{r}");
        }
        // Normal incidence in general: ((η−1)² + k²) / ((η+1)² + k²); with k = 0 the dielectric's.
        let (eta, k) = (0.2f32, 3.9f32);
        let normal = ((eta - 1.0).powi(2) + k * k) / ((eta + 1.0).powi(2) + k * k);
        assert!((fresnel_conductor(1.0, eta, k) - normal).abs() < 1e-5);
        for cos in [0.1f32, 0.5, 0.9] {
            assert!((fresnel_conductor(cos, 1.5, 0.0) - fresnel_dielectric(cos, 1.5)).abs() < 1e-5);
        }
        assert!(fresnel_conductor(0.0, eta, k) > 0.999, "grazing light is reflected");
    }

    /// GGX: samples weigh eval·cos/pdf, their mean is the albedo integrated by quadrature (so
    /// the sampler covers the lobe), the lobe is reciprocal, and a perfect reflector (k large)
    /// never gains energy; it loses what single scattering loses (quadrature: 6% at α 0.2 and
    /// 34°, 31% at α 0.5 — a fifth of GGX's normals at α 0.5 tilt past 45° and reflect below
    /// the horizon).
    #[test]
    fn ggx_conductor_conserves_energy_and_samples_its_pdf() {
        for (alpha, theta) in [(0.05f32, 0.0f32), (0.2, 0.6), (0.5, 0.3), (0.5, 1.2), (0.9, 0.8)] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            let bsdf = Bsdf::physical(&conductor(0.9999, alpha), Vec3::Z, Vec3::Z, wo, &RGB);
            assert!(bsdf.is_smooth() && !bsdf.transmits_smoothly());
            let a = albedo(&bsdf, wo, 7);
            let q = smooth_albedo_by_quadrature(&bsdf, wo);
            assert!((a - q).abs() < 0.01, "α {alpha} θ {theta}: sampled {a}, quadrature {q}");
            let floor = if alpha <= 0.05 { 0.99 } else { 0.3 };
            assert!(q <= 1.0 + 1e-3 && q > floor, "α {alpha} θ {theta}: albedo {q}");
            // Reciprocity.
            let wi = Vec3::new(-0.3, 0.4, 0.866).normalize();
            let (f1, f2) = (bsdf.eval(wo, wi), bsdf.eval(wi, wo));
            assert!((f1 - f2).length() <= 1e-4 * (1.0 + f1.length()), "{f1:?} vs {f2:?}");
        }
        // Seen from above, the pdf integrates to the share of normals within 45° of the
        // surface's (the others reflect below the horizon): P(tan²θh < 1) = 1 / (1 + α²) for GGX.
        let wo = Vec3::Z;
        let bsdf = Bsdf::physical(&conductor(0.8, 0.3), Vec3::Z, Vec3::Z, wo, &RGB);
        let mut rng = Rng::new(9, 0);
        let n = 400_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let d = crate::sampling::sample_uniform_sphere(rng.uniform2());
            let d = Vec3::new(d.x, d.y, d.z.abs());
            sum += bsdf.pdf(wo, d) as f64 * 2.0 * std::f64::consts::PI;
        }
        let integral = sum / n as f64;
        let expected = 1.0 / (1.0 + 0.3f64 * 0.3);
        assert!((integral - expected).abs() < 0.01, "{integral} vs {expected}");
        // Below α 1e-3 it is a mirror with the conductor's Fresnel reflectance.
        let mirror = Bsdf::physical(&conductor(0.5, 0.0), Vec3::Z, Vec3::Z, Vec3::Z, &RGB);
        assert!(!mirror.is_smooth());
        let s = mirror
            .sample(Vec3::Z, 0.5, glam::Vec2::splat(0.5), Transport::Radiance)
            .unwrap();
        assert!(s.specular && (s.weight.x - 0.5).abs() < 1e-4 && (s.wi - Vec3::Z).length() < 1e-6);
    }

    /// A white base under a coat reflects at most everything: the coat takes F, the base what
    /// crosses the coat both ways. The sampled albedo matches quadrature of the smooth lobes
    /// plus, for a smooth coat, its mirror reflectance F(θo).
    #[test]
    fn coated_diffuse_conserves_energy() {
        for roughness in [0.0f32, 0.3] {
            for theta in [0.0f32, 0.7, 1.3] {
                let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
                let m = PhysicalMaterial::CoatedDiffuse {
                    reflectance: Vec3::ONE,
                    eta: 1.5,
                    roughness,
                    coat_tint: Vec3::ONE,
                    layering: Coating::Fresnel,
                };
                let bsdf = Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &RGB);
                let a = albedo(&bsdf, wo, 11);
                let mirror = if roughness == 0.0 {
                    fresnel_dielectric(theta.cos(), 1.5) as f64
                } else {
                    0.0
                };
                let q = smooth_albedo_by_quadrature(&bsdf, wo) + mirror;
                assert!(
                    (a - q).abs() < 0.01,
                    "rough {roughness} θ {theta}: sampled {a}, quadrature {q}"
                );
                assert!(q <= 1.0 + 1e-3 && q > 0.75, "rough {roughness} θ {theta}: {q}");
                let black = PhysicalMaterial::CoatedDiffuse {
                    reflectance: Vec3::ZERO,
                    eta: 1.5,
                    roughness: 0.0,
                    coat_tint: Vec3::ONE,
                    layering: Coating::Layered,
                };
                if theta == 0.0 {
                    // A black base shows the coat alone: 4% at normal incidence for η 1.5.
                    let coat = albedo(&Bsdf::physical(&black, Vec3::Z, Vec3::Z, wo, &RGB), wo, 3);
                    assert!((coat - 0.04).abs() < 1e-3, "{coat}");
                }
            }
        }
    }

    /// Under a layered smooth coat the base's light comes back down from the coat's underside:
    /// the directional albedo is F(θo) + (1 − F(θo))·r(1 − F̄ᵢ)/(1 − r·F̄ᵢ), so a white base
    /// reflects everything (the furnace shows nothing) and a grey one less than a single crossing
    /// gives. F̄ᵢ for glass of index 1.5 is 0.596 (the published internal diffuse reflectance).
    #[test]
    fn layered_coat_returns_the_light_it_reflects_inside() {
        assert_eq!(internal_diffuse_reflectance(1.0), 0.0);
        let inside = internal_diffuse_reflectance(1.5);
        assert!((inside - 0.596).abs() < 0.002, "{inside}");
        for r in [1.0f32, 0.5] {
            for theta in [0.0f32, 0.7, 1.3] {
                let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
                let m = PhysicalMaterial::CoatedDiffuse {
                    reflectance: Vec3::splat(r),
                    eta: 1.5,
                    roughness: 0.0,
                    coat_tint: Vec3::ONE,
                    layering: Coating::Layered,
                };
                let bsdf = Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &RGB);
                let f = fresnel_dielectric(theta.cos(), 1.5);
                let q = smooth_albedo_by_quadrature(&bsdf, wo) + f as f64;
                let want = f + (1.0 - f) * r * (1.0 - inside) / (1.0 - r * inside);
                assert!((q - want as f64).abs() < 2e-3, "r {r} θ {theta}: {q} vs {want}");
                let sampled = albedo(&bsdf, wo, 13);
                assert!(
                    (sampled - q).abs() < 0.01,
                    "r {r} θ {theta}: sampled {sampled}, quadrature {q}"
                );
            }
        }
    }

    /// A clear coat: a smooth one over a black base reflects its Fresnel share alone (4% at
    /// normal incidence); over Lambert ρ the albedo is F(θo) + (1 − F(θo))·ρ·(1 − F̄), F̄ the
    /// coat's cosine-weighted mean reflectance (what crosses the coat in and out); a rough
    /// coat over a metal samples what it evaluates, is reciprocal and never gains energy.
    #[test]
    fn a_clear_coat_reflects_its_share_and_passes_the_rest_both_ways() {
        let smooth = ClearCoat {
            weight: 1.0,
            eta: 1.5,
            alpha: 0.0,
        };
        let lambert = |r: f32, wo: Vec3| {
            let m = PhysicalMaterial::DiffuseTransmission {
                reflectance: Vec3::splat(r),
                transmittance: Vec3::ZERO,
            };
            Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &RGB)
        };
        let black = lambert(0.0, Vec3::Z).with_clearcoat(smooth, Vec3::Z);
        assert!((albedo(&black, Vec3::Z, 3) - 0.04).abs() < 1e-4);
        // F̄ by the midpoint rule over μ² (cosine-weighted).
        let n = 4096;
        let mean_f = (0..n)
            .map(|j| fresnel_dielectric(((j as f32 + 0.5) / n as f32).sqrt(), 1.5) as f64)
            .sum::<f64>()
            / n as f64;
        for (theta, rho, weight) in [(0.0f32, 0.8f32, 1.0f32), (1.0, 0.5, 1.0), (0.5, 0.8, 0.5)] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            let coat = ClearCoat { weight, ..smooth };
            let bsdf = lambert(rho, wo).with_clearcoat(coat, wo);
            let f = weight as f64 * fresnel_dielectric(theta.cos(), 1.5) as f64;
            let want = f + (1.0 - f) * rho as f64 * (1.0 - weight as f64 * mean_f);
            let q = smooth_albedo_by_quadrature(&bsdf, wo) + f;
            let sampled = albedo(&bsdf, wo, 5);
            assert!(
                (q - want).abs() < 2e-3,
                "θ {theta} ρ {rho} c {weight}: quadrature {q}, want {want}"
            );
            assert!(
                (sampled - want).abs() < 0.01,
                "θ {theta}: sampled {sampled}, want {want}"
            );
        }
        let rough = ClearCoat { alpha: 0.2, ..smooth };
        for theta in [0.0f32, 0.8, 1.3] {
            let wo = Vec3::new(theta.sin(), 0.0, theta.cos());
            let bsdf = Bsdf::physical(&conductor(0.9, 0.4), Vec3::Z, Vec3::Z, wo, &RGB).with_clearcoat(rough, wo);
            let (a, q) = (albedo(&bsdf, wo, 7), smooth_albedo_by_quadrature(&bsdf, wo));
            assert!(
                (a - q).abs() < 0.01 && q <= 1.0,
                "θ {theta}: sampled {a}, quadrature {q}"
            );
            let wi = Vec3::new(-0.3, 0.4, 0.866).normalize();
            let (f1, f2) = (bsdf.eval(wo, wi), bsdf.eval(wi, wo));
            assert!((f1 - f2).length() <= 1e-4 * (1.0 + f1.length()), "{f1:?} vs {f2:?}");
        }
        // Glass takes no coat.
        let glass = Bsdf::new(
            &Lobes::new(&SurfaceParams {
                transmissive: Vec3::ONE,
                index: 1.5,
                ..SurfaceParams::default()
            }),
            Vec3::Z,
            Vec3::Z,
            Vec3::Z,
            &RGB,
            None,
            None,
        );
        assert_eq!(glass.with_clearcoat(smooth, Vec3::Z).mirror, glass.mirror);
    }

    #[test]
    fn diffuse_transmission_sends_light_through_lambertian() {
        let m = PhysicalMaterial::DiffuseTransmission {
            reflectance: Vec3::splat(0.3),
            transmittance: Vec3::splat(0.5),
        };
        let wo = Vec3::new(0.3, 0.0, 0.954);
        let bsdf = Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &RGB);
        assert!(bsdf.transmits_smoothly());
        let mut rng = Rng::new(13, 0);
        let (mut through, mut back, n) = (0.0f64, 0.0f64, 200_000);
        for _ in 0..n {
            let s = bsdf
                .sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)
                .unwrap();
            let expected = bsdf.eval(wo, s.wi) * s.wi.z.abs() / bsdf.pdf(wo, s.wi);
            assert!((s.weight - expected).length() < 1e-4);
            assert_eq!(s.transmitted, s.wi.z < 0.0);
            if s.transmitted {
                through += s.weight.x as f64;
            } else {
                back += s.weight.x as f64;
            }
        }
        assert!((through / n as f64 - 0.5).abs() < 0.01 && (back / n as f64 - 0.3).abs() < 0.01);
        assert_eq!(bsdf.eval(wo, -Vec3::Z), Vec4::new(0.5 / PI, 0.5 / PI, 0.5 / PI, 0.0));
    }

    /// Next-event estimation drops a light sample without its shadow ray where `may_take`
    /// says no: there `eval` must be zero for every `wo`. Checked on 20,000 random pairs of
    /// directions for Phong lobes under a tilted shading normal, a coated diffuse (smooth and
    /// rough coat), a diffuse transmitter and an opaque Lambertian under a clear coat; the
    /// reflectors must also turn away a good share of directions (the samples it saves).
    #[test]
    fn may_take_is_false_only_where_eval_is_zero() {
        let tilted = Vec3::new(0.3, 0.1, 1.0).normalize();
        let coat = |roughness: f32| PhysicalMaterial::CoatedDiffuse {
            reflectance: Vec3::splat(0.7),
            eta: 1.5,
            roughness,
            coat_tint: Vec3::ONE,
            layering: Coating::Fresnel,
        };
        let through = PhysicalMaterial::DiffuseTransmission {
            reflectance: Vec3::splat(0.3),
            transmittance: Vec3::splat(0.5),
        };
        let opaque = PhysicalMaterial::DiffuseTransmission {
            reflectance: Vec3::splat(0.6),
            transmittance: Vec3::ZERO,
        };
        let clear = ClearCoat {
            weight: 1.0,
            eta: 1.5,
            alpha: 0.0,
        };
        let mut rng = Rng::new(17, 0);
        let direction = |rng: &mut Rng| {
            let (z, phi) = (2.0 * rng.uniform() - 1.0, 2.0 * PI * rng.uniform());
            let r = (1.0 - z * z).max(0.0).sqrt();
            Vec3::new(r * phi.cos(), r * phi.sin(), z)
        };
        let wo0 = Vec3::new(0.2, 0.0, 0.98).normalize();
        let cases: Vec<(&str, Bsdf, bool)> = vec![
            (
                "phong",
                Bsdf::new(
                    &Lobes::new(&params(0.5, 0.4, 30.0)),
                    tilted,
                    Vec3::Z,
                    wo0,
                    &RGB,
                    None,
                    None,
                ),
                true,
            ),
            (
                "smooth coat",
                Bsdf::physical(&coat(0.0), tilted, Vec3::Z, wo0, &RGB),
                true,
            ),
            (
                "rough coat",
                Bsdf::physical(&coat(0.3), Vec3::Z, Vec3::Z, wo0, &RGB),
                false,
            ),
            (
                "transmitter",
                Bsdf::physical(&through, Vec3::Z, Vec3::Z, wo0, &RGB),
                false,
            ),
            (
                "clear-coated",
                Bsdf::physical(&opaque, Vec3::Z, Vec3::Z, wo0, &RGB).with_clearcoat(clear, wo0),
                false,
            ),
        ];
        for (name, bsdf, reflector) in cases {
            let mut refused = 0;
            for _ in 0..20_000 {
                let (wo, wi) = (direction(&mut rng), direction(&mut rng));
                if !bsdf.may_take(wi) {
                    refused += 1;
                    assert_eq!(bsdf.eval(wo, wi), Spectrum::ZERO, "{name}: wo {wo} wi {wi}");
                }
            }
            assert!(!reflector || refused > 8_000, "{name}: {refused} refused");
        }
    }

    #[test]
    fn thin_glass_reflects_both_faces_and_passes_the_rest_straight() {
        let m = PhysicalMaterial::ThinDielectric {
            eta: 1.5,
            tint: Vec3::ONE,
        };
        let wo = Vec3::new(0.0, 0.6, 0.8);
        let bsdf = Bsdf::physical(&m, Vec3::Z, Vec3::Z, wo, &RGB);
        let r = fresnel_dielectric(0.8, 1.5) as f64;
        let expected = 2.0 * r / (1.0 + r);
        let mut rng = Rng::new(17, 0);
        let (mut reflected, mut total, n) = (0.0f64, 0.0f64, 100_000);
        for _ in 0..n {
            let s = bsdf
                .sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)
                .unwrap();
            total += s.weight.x as f64;
            if s.transmitted {
                assert_eq!(s.wi, -wo, "straight through, no bending, no 1/η²");
            } else {
                reflected += s.weight.x as f64;
            }
        }
        assert!(
            (reflected / n as f64 - expected).abs() < 0.005,
            "{} vs {expected}",
            reflected / n as f64
        );
        assert!((total / n as f64 - 1.0).abs() < 1e-4);
    }

    /// A glass with a highlight (kt + ks at 1 after scaling) never reflects more than all the
    /// light: from outside, and from inside where the dielectric reflects totally (it gained
    /// ks at every such bounce, and photons trapped in a lens grew without bound).
    #[test]
    fn glass_with_a_highlight_conserves_energy_inside_and_out() {
        let lobes = Lobes::new(&highlighted_glass());
        for (wo, total_inside) in [
            (Vec3::new(0.0, 0.0, 1.0), false),
            (Vec3::new(0.6, 0.0, 0.8), false),
            (Vec3::new(0.866, 0.0, -0.5), true),
            (Vec3::new(0.3, 0.0, -0.954), false),
        ] {
            let wo = wo.normalize();
            let bsdf = Bsdf::new(&lobes, Vec3::Z, Vec3::Z, wo, &RGB, None, None);
            let a = albedo(&bsdf, wo, 5);
            assert!(a <= 1.0 + 0.01, "{wo}: albedo {a}");
            if total_inside {
                // The highlight coats the outside only: total reflection inside loses nothing.
                assert!((a - 1.0).abs() < 1e-6, "{wo}: albedo {a}");
            }
        }
    }

    /// A course glass with a highlight whose colours sum above 1 (scaled to kt 0.74, ks 0.26).
    fn highlighted_glass() -> SurfaceParams {
        SurfaceParams {
            specular: Vec3::splat(0.3),
            shininess: 64.0,
            transmissive: Vec3::splat(0.85),
            index: 1.5,
            ..SurfaceParams::default()
        }
    }

    #[test]
    fn a_dielectric_seen_from_inside_is_the_bare_interface() {
        let p = SurfaceParams {
            diffuse: Vec3::splat(0.2),
            reflective: Vec3::splat(0.1),
            ..highlighted_glass()
        };
        let lobes = Lobes::new(&p);
        let wo = Vec3::new(0.3, 0.0, -0.954).normalize();
        let inside = Bsdf::new(&lobes, Vec3::Z, Vec3::Z, wo, &RGB, None, None);
        assert!(!inside.is_smooth(), "no diffuse or glossy lobe inside");
        let up = Vec3::new(0.1, 0.2, -0.97).normalize();
        assert_eq!(inside.eval(wo, up), Spectrum::ZERO);
        assert_eq!(inside.pdf(wo, up), 0.0);
        let outside = Bsdf::new(&lobes, Vec3::Z, Vec3::Z, -wo, &RGB, None, None);
        assert!(outside.is_smooth(), "the coat's lobes act outside");
        // Every sample inside is the dielectric's: reflection by Fresnel, refraction otherwise.
        let mut rng = Rng::new(9, 0);
        for _ in 0..1000 {
            let s = inside
                .sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance)
                .unwrap();
            assert!(s.specular);
        }
    }

    #[test]
    fn refraction_through_a_coated_glass_is_the_same_both_ways() {
        // Under importance transport a refracted pair carries the same weight in either
        // direction (radiance differs by the η² the transport mode says); the coat's room
        // is taken at the outside end both ways.
        let p = SurfaceParams {
            diffuse: Vec3::splat(0.1),
            ..highlighted_glass()
        };
        let lobes = Lobes::new(&p);
        // u_lobe just below 1 picks refraction (the dielectric is the last course lobe).
        for wo in [
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.6, 0.0, 0.8),
            Vec3::new(0.97, 0.0, 0.243),
        ] {
            let wo = wo.normalize();
            let out = Bsdf::new(&lobes, Vec3::Z, Vec3::Z, wo, &RGB, None, None);
            let s = out
                .sample(wo, 0.999_999, glam::Vec2::ZERO, Transport::Importance)
                .unwrap();
            assert!(s.transmitted);
            // Back from inside along the refracted direction.
            let inside = Bsdf::new(&lobes, Vec3::Z, Vec3::Z, s.wi, &RGB, None, None);
            let t = inside
                .sample(s.wi, 0.999_999, glam::Vec2::ZERO, Transport::Importance)
                .unwrap();
            assert!(t.transmitted && (t.wi - wo).length() < 1e-4, "{t:?}");
            // Weight times the event's probability is the lobe's throughput, whatever the pick.
            let (a, b) = (s.weight.x * s.pdf, t.weight.x * t.pdf);
            assert!((a - b).abs() < 1e-5 * a.max(b), "{wo}: {a} outside in, {b} inside out");
            assert!(a <= lobes.kt.x * (1.0 - fresnel_dielectric(wo.z, 1.5)) + 1e-6);
        }
    }

    #[test]
    fn overbright_materials_are_scaled_to_conserve_energy() {
        let p = SurfaceParams {
            diffuse: Vec3::splat(0.8),
            reflective: Vec3::splat(0.6),
            ..SurfaceParams::default()
        };
        let bsdf = Bsdf::new(&Lobes::new(&p), Vec3::Z, Vec3::Z, Vec3::Z, &RGB, None, None);
        assert!((bsdf.diffuse.x + bsdf.mirror.x - 1.0).abs() < 1e-6);
        assert!((bsdf.diffuse.x / bsdf.mirror.x - 0.8 / 0.6).abs() < 1e-5);
    }
}
