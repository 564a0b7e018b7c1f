//! Materials of the `.ray` format (§6): constant or texture-mapped parameters, evaluated at a hit.

pub use crate::description::PhysicalMaterial;
use crate::math::{luminance, Vec2, Vec3, Vec4};
use crate::spectrum::{cauchy_index, fit_reflectance, SigmoidPolynomial, Spectrum, Wavelengths, CHANNEL_WAVELENGTHS};
use crate::texture::Texture;

/// A parameter: a constant or an index into the scene's textures.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Channel {
    /// A constant colour (scalars are grey).
    Constant(Vec3),
    /// A texture, looked up by the hit's texture coordinates.
    Texture(u32),
}

impl Channel {
    /// The value at texture coordinates `uv`.
    #[inline]
    pub fn eval(&self, textures: &[Texture], uv: Vec2) -> Vec3 {
        match *self {
            Channel::Constant(c) => c,
            Channel::Texture(i) => textures[i as usize].lookup(uv),
        }
    }

    /// Whether the parameter can be non-zero anywhere.
    pub fn may_be_nonzero(&self) -> bool {
        match self {
            Channel::Constant(c) => *c != Vec3::ZERO,
            Channel::Texture(_) => true,
        }
    }
}

/// Which material a surface point has: one, or (per-vertex materials of a mesh) three blended
/// by barycentric weights.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MaterialRef {
    /// One material id.
    One(u32),
    /// The materials of a triangle's three vertices and their weights at the point.
    Blend {
        /// Material ids.
        ids: [u32; 3],
        /// Barycentric weights (sum 1).
        weights: [f32; 3],
    },
}

/// A material: the eight `.ray` parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// ke
    pub emissive: Channel,
    /// ka
    pub ambient: Channel,
    /// ks
    pub specular: Channel,
    /// kr
    pub reflective: Channel,
    /// kd
    pub diffuse: Channel,
    /// kt
    pub transmissive: Channel,
    /// Phong exponent (texture: luminance × 128, §6.1).
    pub shininess: Channel,
    /// Index of refraction (luminance of the value); with `abbe`, n_d at 587.6 nm.
    pub index: Channel,
    /// Abbe number V_d of a dispersive glass.
    pub abbe: Option<f32>,
    /// The physical model's reading when it is not the course fields' own (a metal, a coated
    /// or translucent surface, thin glass).
    pub physical: Option<PhysicalMaterial<Channel>>,
    /// A tangent-space normal map on meshes with texture coordinates: the texture and the
    /// scale of the normal's x and y.
    pub normal_map: Option<(u32, f32)>,
    /// glTF's metallic-roughness texture, which decides the physical reading point by point.
    pub metallic_roughness: Option<crate::description::MetallicRoughness<Channel>>,
    /// Coverage of a mesh's surface ([`crate::description::Alpha`]).
    pub alpha: Option<crate::description::Alpha<Channel>>,
    /// Which faces send out `emissive`.
    pub emitting_faces: crate::description::EmittingFaces,
    /// Absorption per unit of length inside a solid glass ([`crate::description::MaterialDesc::absorption`]).
    pub absorption: Option<Vec3>,
    /// The media its surface separates (`None`: paths keep theirs).
    pub interface: Option<crate::medium::Interface>,
    /// Only a boundary between media: paths pass it unchanged.
    pub boundary: bool,
    /// pbrt's `mix`: one of two materials at each point ([`Mix`]).
    pub mix: Option<Mix>,
    /// A clear coat over the physical reading.
    pub clearcoat: Option<crate::description::ClearCoat>,
    /// Its textures.
    pub clearcoat_maps: Option<crate::description::ClearCoatMaps<Channel>>,
    /// The physical reading's roughness from a texture.
    pub roughness_map: Option<crate::description::RoughnessMap<Channel>>,
}

/// A mix of two materials in a built scene: at each point the second with probability
/// `amount` (its first channel), else the first (`description::MixDesc`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Mix {
    /// The two materials' ids.
    pub materials: [u32; 2],
    /// The second's share.
    pub amount: Channel,
}

/// A material's constant colours as fitted smooth spectra (for spectral transport); `None`
/// where the colour comes from a texture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct MaterialSpectra {
    /// kd
    pub diffuse: Option<SigmoidPolynomial>,
    /// ks
    pub specular: Option<SigmoidPolynomial>,
    /// kr
    pub reflective: Option<SigmoidPolynomial>,
    /// kt
    pub transmissive: Option<SigmoidPolynomial>,
    /// ke, fitted to its colour scaled to a largest component of ½ (see
    /// [`MaterialSpectra::emission`]).
    pub emissive: Option<SigmoidPolynomial>,
}

impl MaterialSpectra {
    /// The fits of `material`'s constant colours (a colour above 1 is fitted clamped: the
    /// physical model scales such materials down anyway).
    pub fn of(material: &Material) -> MaterialSpectra {
        let fit = |c: &Channel| match c {
            Channel::Constant(rgb) => Some(fit_reflectance(*rgb)),
            Channel::Texture(_) => None,
        };
        let emissive = match material.emissive {
            Channel::Constant(rgb) if rgb.max_element() > 0.0 => Some(fit_reflectance(rgb / (2.0 * rgb.max_element()))),
            _ => None,
        };
        MaterialSpectra {
            diffuse: fit(&material.diffuse),
            specular: fit(&material.specular),
            reflective: fit(&material.reflective),
            transmissive: fit(&material.transmissive),
            emissive,
        }
    }

    /// The emitted radiance `le` (this material's constant `emissive`) at the wavelengths.
    pub fn emission(&self, le: Vec3, wl: &Wavelengths) -> Spectrum {
        match (self.emissive, wl) {
            (Some(fit), Wavelengths::Sampled { lambda, .. }) => {
                Vec4::from_array(lambda.map(|l| fit.eval(l))) * (2.0 * le.max_element())
            }
            _ => wl.unbounded(le),
        }
    }
}

/// A material's values at one surface point.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SurfaceParams {
    /// ke
    pub emissive: Vec3,
    /// ka
    pub ambient: Vec3,
    /// ks
    pub specular: Vec3,
    /// kr
    pub reflective: Vec3,
    /// kd
    pub diffuse: Vec3,
    /// kt
    pub transmissive: Vec3,
    /// Phong exponent.
    pub shininess: f32,
    /// Index of refraction.
    pub index: f32,
}

/// A course material's lobes before a point's shading frame: its colours clamped and scaled
/// so that they reflect at most all light, the chance of picking each lobe, its exponent and
/// index. The same at every point of an untextured material: scenes keep them per material,
/// which spares every hit the work.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lobes {
    /// Diffuse colour.
    pub kd: Vec3,
    /// Glossy colour.
    pub ks: Vec3,
    /// Mirror colour.
    pub kr: Vec3,
    /// Transmitted colour.
    pub kt: Vec3,
    /// What the colours were scaled by (fitted spectra are scaled alike).
    pub scale: f32,
    /// Phong exponent of the glossy lobe.
    pub exponent: f32,
    /// Index of refraction.
    pub index: f32,
    /// The chance of picking each lobe: diffuse, glossy, mirror, dielectric (and the physical
    /// model's microfacet and diffuse transmission, none here).
    pub pick: [f32; 6],
    /// A bound on the diffuse, glossy and mirror lobes' albedo together (the largest channel of
    /// kd + ks + kr): the dielectric keeps only the room below 1 they leave.
    pub reflection_bound: f32,
}

impl Lobes {
    /// The lobes of the course's material values `params`.
    pub fn new(params: &SurfaceParams) -> Lobes {
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
        let mut pick = [kd.max_element(), ks.max_element(), kr.max_element(), 0.0, 0.0, 0.0];
        if kt != Vec3::ZERO {
            // The dielectric reflects even where kt is small; sample it by its larger part.
            pick[3] = kt.max_element().max(0.04);
        }
        let sum: f32 = pick.iter().sum();
        if sum > 0.0 {
            pick.iter_mut().for_each(|p| *p /= sum);
        }
        Lobes {
            kd,
            ks,
            kr,
            kt,
            scale,
            exponent: params.shininess.max(0.0),
            index: if params.index > 0.0 { params.index } else { 1.0 },
            pick,
            reflection_bound: (kd + ks + kr).max_element(),
        }
    }
}

impl Material {
    /// The values at texture coordinates `uv`.
    #[inline]
    pub fn eval(&self, textures: &[Texture], uv: Vec2) -> SurfaceParams {
        let shininess = match self.shininess {
            Channel::Constant(c) => luminance(c),
            Channel::Texture(i) => luminance(textures[i as usize].lookup(uv)) * 128.0,
        };
        SurfaceParams {
            emissive: self.emissive.eval(textures, uv),
            ambient: self.ambient.eval(textures, uv),
            specular: self.specular.eval(textures, uv),
            reflective: self.reflective.eval(textures, uv),
            diffuse: self.diffuse.eval(textures, uv),
            transmissive: self.transmissive.eval(textures, uv),
            shininess,
            index: luminance(self.index.eval(textures, uv)),
        }
    }

    /// Whether any parameter is read from a texture (and so needs texture coordinates).
    pub fn is_textured(&self) -> bool {
        [
            &self.emissive,
            &self.ambient,
            &self.specular,
            &self.reflective,
            &self.diffuse,
            &self.transmissive,
            &self.shininess,
            &self.index,
        ]
        .iter()
        .any(|c| matches!(c, Channel::Texture(_)))
            || self.normal_map.is_some()
            || self.metallic_roughness.is_some()
            || self.alpha.is_some()
            || self.physical.as_ref().is_some_and(|p| {
                p.try_map(|c| {
                    if matches!(c, Channel::Texture(_)) {
                        Err(())
                    } else {
                        Ok(())
                    }
                })
                .is_err()
            })
    }

    /// Whether the material can turn a photon specularly (mirror or glass): what makes caustics.
    pub fn is_specular(&self) -> bool {
        self.reflective.may_be_nonzero() || self.transmissive.may_be_nonzero()
    }

    /// Whether the emission is read from a texture.
    pub fn emissive_is_textured(&self) -> bool {
        matches!(self.emissive, Channel::Texture(_))
    }

    /// The physical reading's values at texture coordinates `uv`, if it has its own.
    #[inline(always)]
    pub fn physical_at(&self, textures: &[Texture], uv: Vec2) -> Option<PhysicalMaterial<Vec3>> {
        if let Some(mr) = &self.metallic_roughness {
            let texel = mr.texture.eval(textures, uv);
            let base = mr.base.eval(textures, uv);
            let roughness = (texel.y * mr.roughness).clamp(0.0, 1.0);
            let alpha = roughness * roughness;
            return if texel.z * mr.metallic >= 0.5 {
                Some(PhysicalMaterial::Conductor {
                    eta: Vec3::ONE,
                    k: Vec3::ZERO,
                    reflectance: Some(base),
                    roughness: alpha,
                })
            } else if let Some((eta, abbe)) = mr.glass {
                // Smooth glass is the course fields' dielectric.
                (alpha >= crate::description::SMOOTH_ALPHA).then_some(PhysicalMaterial::RoughDielectric {
                    eta,
                    roughness: alpha,
                    tint: base,
                    abbe,
                })
            } else {
                mr.coat.map(|eta| PhysicalMaterial::CoatedDiffuse {
                    reflectance: base,
                    eta,
                    roughness: alpha,
                    coat_tint: mr.coat_tint.eval(textures, uv),
                    layering: crate::description::Coating::Fresnel,
                })
            };
        }
        let physical = self.physical.as_ref()?;
        let mut physical = physical.try_map(|c| Ok::<Vec3, ()>(c.eval(textures, uv))).ok()?;
        if let Some(map) = &self.roughness_map {
            let r = map.texture.eval(textures, uv).x.max(0.0);
            let alpha = map.remap.alpha(r);
            match &mut physical {
                PhysicalMaterial::Conductor { roughness, .. } | PhysicalMaterial::CoatedDiffuse { roughness, .. } => {
                    *roughness = alpha
                }
                // Smooth glass is the course fields' dielectric.
                PhysicalMaterial::RoughDielectric { .. } if alpha < crate::description::SMOOTH_ALPHA => return None,
                PhysicalMaterial::RoughDielectric { roughness, .. } => *roughness = alpha,
                _ => {}
            }
        }
        Some(physical)
    }

    /// Whether a caustic can show on it: some `diffuse` or `specular` value may be non-zero.
    pub fn may_receive(&self) -> bool {
        self.diffuse.may_be_nonzero() || self.specular.may_be_nonzero()
    }

    /// Whether any emissive value is non-zero.
    pub fn is_emissive(&self) -> bool {
        self.emissive.may_be_nonzero()
    }
}

impl SurfaceParams {
    /// Barycentric blend of three vertices' values (per-vertex materials of a mesh).
    pub fn blend(p: [&SurfaceParams; 3], w: [f32; 3]) -> SurfaceParams {
        let mix = |f: fn(&SurfaceParams) -> Vec3| f(p[0]) * w[0] + f(p[1]) * w[1] + f(p[2]) * w[2];
        let mix_scalar = |f: fn(&SurfaceParams) -> f32| f(p[0]) * w[0] + f(p[1]) * w[1] + f(p[2]) * w[2];
        SurfaceParams {
            emissive: mix(|s| s.emissive),
            ambient: mix(|s| s.ambient),
            specular: mix(|s| s.specular),
            reflective: mix(|s| s.reflective),
            diffuse: mix(|s| s.diffuse),
            transmissive: mix(|s| s.transmissive),
            shininess: mix_scalar(|s| s.shininess),
            index: mix_scalar(|s| s.index),
        }
    }
}

impl SurfaceParams {
    /// The course's Phong reflectance per unit irradiance from direction `wi`, seen from `wo`
    /// (all unit, `n` facing `wo`): kd + ks·max(0, wo·r)^ns / (n·wi), where r mirrors `wi`.
    ///
    /// Multiplied by irradiance I·f(d)·(n·wi) it gives the Whitted term of §9 exactly; the photon
    /// map multiplies it by photon flux per area, so caustics on glossy receivers follow the same
    /// lobe as direct light (Jensen 1996).
    #[inline]
    pub fn phong_reflectance(&self, n: Vec3, wo: Vec3, wi: Vec3) -> Vec3 {
        let cos_i = n.dot(wi);
        if cos_i <= 0.0 {
            return Vec3::ZERO;
        }
        let mut f = self.diffuse;
        if self.specular != Vec3::ZERO {
            let r = 2.0 * cos_i * n - wi;
            let rv = r.dot(wo).max(0.0);
            f += self.specular * rv.powf(self.shininess) / cos_i.max(MIN_COSINE);
        }
        f
    }
}

/// §9's refraction convention: entering, η = 1/index with the outward normal; leaving,
/// η = index with the inward normal. Returns (η, normal facing the incoming ray).
#[inline]
pub fn refraction_geometry(index: f32, entering: bool, outward_normal: Vec3) -> (f32, Vec3) {
    let index = if index > 0.0 { index } else { 1.0 };
    if entering {
        (1.0 / index, outward_normal)
    } else {
        (index, -outward_normal)
    }
}

/// Each colour channel's index of refraction: all `index`, or with an Abbe number each by
/// Cauchy's law at the wavelength the channel stands for.
pub fn channel_indices(index: f32, abbe: Option<f32>) -> Option<[f32; 3]> {
    let abbe = abbe?;
    let index = if index > 0.0 { index } else { 1.0 };
    Some(CHANNEL_WAVELENGTHS.map(|l| cauchy_index(index, abbe, l)))
}

/// The smallest cosine divided by, so that grazing light does not blow the specular lobe up.
const MIN_COSINE: f32 = 1e-2;
