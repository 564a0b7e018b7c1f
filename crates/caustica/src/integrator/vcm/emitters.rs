//! The lights vertex connection and merging starts its light subpaths from, with the densities
//! its weights need: how likely emission made a point and direction, and how likely
//! next-event estimation would have drawn the same point.
//!
//! Points, spots and emissive objects take part in every strategy. Far lights (suns, the sky,
//! directional lights) and the course forks' lights with a size are reached from the camera
//! only, by next-event estimation and, for the sky and suns, by BSDF samples that escape,
//! weighted against each other as in the path tracer.

use crate::light::emission::area_radiance;
use crate::light::{spot_profile, AreaLight, Light, LightSet};
use crate::math::{offset_origin, Frame, Ray, Vec3};
use crate::sampling::{sample_cosine_hemisphere, sample_uniform_cone, uniform_cone_pdf, Distribution1D, Rng};
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use std::f32::consts::PI;

/// The lights that start light subpaths, chosen in proportion to their power.
pub struct Emitters {
    /// Probability of choosing each light of the scene's set (0: not an emitter here).
    probability: Vec<f32>,
    /// Light numbers of the emitters, and their choice distribution.
    numbers: Vec<usize>,
    choice: Option<Distribution1D>,
}

/// The start of a light subpath.
#[derive(Clone, Copy, Debug)]
pub struct Emission {
    /// Leaves the light.
    pub ray: Ray,
    /// Radiance × cosine over the density of the whole sample (choice of light included).
    pub throughput: Spectrum,
    /// Density of the point (area) × direction (solid angle), choice of light included.
    pub emission_pdf: f32,
    /// Cosine between the direction and the light's normal (1 for a point).
    pub cos: f32,
    /// The light is a point or spot.
    pub delta: bool,
    /// Light number.
    pub light: usize,
    /// The point's unit normal (for an emissive object; the direction for a point).
    pub normal: Vec3,
}

/// One next-event sample of an emitter.
#[derive(Clone, Copy, Debug)]
pub struct DirectSample {
    /// Unit direction to the light point.
    pub wi: Vec3,
    /// Distance to the light point.
    pub distance: f32,
    /// Radiance (intensity / d² for a point) over the solid-angle density.
    pub contribution: Spectrum,
    /// Solid-angle density of the sample, choice included (for a point: the choice × d²).
    pub direct_pdf: f32,
    /// Emission's density of the light point and of the direction towards the shading point.
    pub emission_pdf: f32,
    /// Cosine at the light (1 for a point).
    pub cos_light: f32,
    /// The light is a point or spot.
    pub delta: bool,
}

impl Emitters {
    /// The emitters of `scene`'s lights.
    pub fn new(lights: &LightSet) -> Emitters {
        let radius = lights.scene_sphere().1;
        let powers: Vec<f32> = lights
            .iter()
            .map(|light| match light {
                Light::Point { .. } | Light::Spot { .. } | Light::Area(_) => light.power(radius).max(0.0),
                _ => 0.0,
            })
            .collect();
        let numbers: Vec<usize> = (0..powers.len()).filter(|&i| powers[i] > 0.0).collect();
        let total: f32 = numbers.iter().map(|&i| powers[i]).sum();
        let probability = powers
            .iter()
            .map(|&p| {
                if total > 0.0 && total.is_finite() {
                    p / total
                } else {
                    0.0
                }
            })
            .collect();
        let weights: Vec<f32> = numbers.iter().map(|&i| powers[i]).collect();
        let choice = (total > 0.0 && total.is_finite()).then(|| Distribution1D::new(&weights));
        Emitters {
            probability,
            numbers,
            choice,
        }
    }

    /// Whether light `number` starts light subpaths.
    pub fn emits(&self, number: usize) -> bool {
        self.probability.get(number).is_some_and(|&p| p > 0.0)
    }

    /// Whether no light starts light subpaths.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// The start of a light subpath, at the wavelengths `wl`.
    pub fn emit(&self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng) -> Option<Emission> {
        let (_, slot, _) = self.choice.as_ref()?.sample(rng.uniform());
        let number = self.numbers[slot];
        let pick = self.probability[number];
        let (u, u_dir) = (rng.uniform2(), rng.uniform2());
        match scene.lights().get(number)? {
            Light::Point { position, color, .. } => {
                let dir = crate::sampling::sample_uniform_sphere(u);
                let pdf = pick / (4.0 * PI);
                Some(Emission {
                    ray: Ray::new(*position, dir),
                    throughput: wl.unbounded(*color) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: true,
                    light: number,
                    normal: dir,
                })
            }
            Light::Spot {
                position,
                direction,
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => {
                let dir = sample_uniform_cone(u, *direction, *cos_outer);
                let profile = spot_profile(dir.dot(*direction), *cos_inner, *cos_outer, *exponent);
                let pdf = pick * uniform_cone_pdf(*cos_outer);
                (profile > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(*position, dir),
                    throughput: wl.unbounded(*color) * (profile / pdf),
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: true,
                    light: number,
                    normal: dir,
                })
            }
            Light::Area(light) => {
                let sample = light.sample(scene, rng.uniform(), u)?;
                let le = area_radiance(light, scene, &sample, wl);
                // A face at random (only the outer one of a closed lamp), then a cosine-weighted
                // direction.
                let (side, u2) = if light.outward_only {
                    (1.0, u_dir)
                } else if u_dir.x < 0.5 {
                    (1.0, glam::Vec2::new(u_dir.x * 2.0, u_dir.y))
                } else {
                    (-1.0, glam::Vec2::new(u_dir.x * 2.0 - 1.0, u_dir.y))
                };
                let normal = sample.normal * side;
                let dir = Frame::from_normal(normal).to_world(sample_cosine_hemisphere(u2));
                let cos = dir.dot(normal);
                let pdf = pick * sample.pdf_area * cos / (PI * faces(light));
                (cos > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(offset_origin(sample.point, sample.normal, dir), dir),
                    throughput: le * (cos / pdf),
                    emission_pdf: pdf,
                    cos,
                    delta: false,
                    light: number,
                    normal,
                })
            }
            _ => None,
        }
    }

    /// Area density with which next-event estimation from `from` draws the start of `e`.
    pub fn direct_pdf(&self, scene: &Scene, e: &Emission, from: Vec3) -> f32 {
        let lights = scene.lights();
        let choice = lights.direct_probability(e.light);
        match lights.get(e.light) {
            Some(Light::Area(light)) => {
                let to = from - e.ray.origin;
                let d2 = to.length_squared();
                let cos = e.normal.dot(to).abs() / d2.sqrt();
                choice * light.pdf_towards(from, e.ray.origin, e.normal) * cos / d2
            }
            _ => choice,
        }
    }

    /// Emission's density (point × direction, choice included) of leaving emissive object
    /// `light` (number `number`) at a point of unit normal `normal` in direction `dir`.
    pub fn emission_pdf(&self, number: usize, light: &AreaLight, normal: Vec3, dir: Vec3) -> f32 {
        let cos = normal.dot(dir);
        if light.outward_only && cos <= 0.0 {
            return 0.0;
        }
        self.probability[number] * light.pdf_area(normal) * cos.abs() / (PI * faces(light))
    }

    /// A next-event sample of emitter `number` for the point `hit`, visibility included.
    pub fn sample_direct(
        &self,
        scene: &Scene,
        number: usize,
        hit: &SurfaceHit,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Option<DirectSample> {
        let lights = scene.lights();
        let choice = lights.direct_probability(number);
        let emit = self.probability[number];
        let (u_pick, u) = (rng.uniform(), rng.uniform2());
        let p = hit.point;
        let point_light = |position: Vec3, intensity: Vec3, dir_pdf: f32| {
            let to = position - p;
            let d2 = to.length_squared();
            if !(d2 > 0.0 && d2.is_finite()) || intensity == Vec3::ZERO {
                return None;
            }
            let distance = d2.sqrt();
            let wi = to / distance;
            scene.unoccluded(hit, wi, distance).then(|| DirectSample {
                wi,
                distance,
                contribution: wl.unbounded(intensity) / (choice * d2),
                direct_pdf: choice * d2,
                emission_pdf: emit * dir_pdf,
                cos_light: 1.0,
                delta: true,
            })
        };
        match lights.get(number)? {
            Light::Point { position, color, .. } => point_light(*position, *color, 1.0 / (4.0 * PI)),
            Light::Spot {
                position,
                direction,
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => {
                let out = (p - *position).normalize_or_zero();
                let profile = spot_profile(out.dot(*direction), *cos_inner, *cos_outer, *exponent);
                if profile <= 0.0 {
                    return None;
                }
                point_light(*position, *color * profile, uniform_cone_pdf(*cos_outer))
            }
            Light::Area(light) => {
                let drawn = light.sample_towards(scene, p, u_pick, u)?;
                let point = drawn.point;
                let to = point.point - p;
                let distance = to.length();
                if distance.is_nan() || distance <= 0.0 || drawn.pdf_solid <= 0.0 {
                    return None;
                }
                let wi = to / distance;
                let le = crate::light::visible_emission(scene, hit, &point, wi, distance, wl)?;
                let direct_pdf = choice * drawn.pdf_solid;
                let cos_light = point.normal.dot(wi).abs();
                Some(DirectSample {
                    wi,
                    distance,
                    contribution: le / direct_pdf,
                    direct_pdf,
                    emission_pdf: self.emission_pdf(number, light, point.normal, -wi),
                    cos_light,
                    delta: false,
                })
            }
            _ => None,
        }
    }
}

/// How many faces of an emissive object emit.
fn faces(light: &AreaLight) -> f32 {
    if light.outward_only {
        1.0
    } else {
        2.0
    }
}
