//! Lights, each with both of its readings: the course's (§5: a colour with the course's distance
//! falloff, summed by the Whitted shading) and the physical one (radiometric units, sampled for
//! next-event estimation and for photon emission). Units and conventions: docs/radiometry.md.
//!
//! In the physical model a point light's colour is its intensity I (W/sr) and it falls off with
//! the inverse square (the file's attenuation coefficients are ignored), a spot light's is the
//! intensity on its axis; a directional light's colour is the irradiance E (W/m²) on a surface
//! facing it, and so is a sun's, spread over its small disc; an emissive object emits radiance
//! ke (W/m²/sr) from both faces, or from the one its material names; the environment's colour (times its map) is the radiance of
//! the sky. In the course model emissive objects are not light sources (their `emissive` term
//! only colours themselves), a sun is a directional light and the environment is only seen, as
//! the background.
//!
//! Every light answers the same questions for every integrator: next-event estimation's sample
//! towards a point with its density ([`LightSet::sample_light`]), the emission sample of a
//! photon or light subpath with its densities ([`emission::Emitters`], aimed at the mirrors and
//! glass by [`aim`], far lights across a [`beam`]), and its power for choosing it. Each kind
//! answers in a file of its own: points and spots in `point`, directional lights and suns in
//! `distant`, emissive objects in [`area`], the sky in [`environment`], lights with a size in
//! [`soft`].

pub mod aim;
pub mod area;
pub mod beam;
pub mod cube_map;
mod distant;
pub mod emission;
pub mod environment;
mod point;
pub mod soft;

pub use area::AreaLight;
pub use environment::Environment;
pub use soft::SoftLight;

use aim::{camera_targets, Aim};
use emission::Emitters;

use crate::math::{luminance, Ray, Vec2, Vec3};
use crate::sampling::{power_heuristic, Rng};
use crate::scene::{ObjectRef, Scene, ShadowRay, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use std::cell::Cell;
use std::f32::consts::PI;

/// The closed set of lights.
#[derive(Clone, Debug)]
pub enum Light {
    /// A point light with the course's attenuation f(d) = min(1, 1 / (a + b d + c d²)) (§5).
    Point {
        /// World position.
        position: Vec3,
        /// Colour (intensity).
        color: Vec3,
        /// (a, b, c).
        attenuation: [f32; 3],
    },
    /// A light from infinitely far away; `direction` is the unit direction light travels.
    Directional {
        /// Unit travel direction.
        direction: Vec3,
        /// Colour (irradiance on a surface facing the light).
        color: Vec3,
    },
    /// A point light whose intensity falls off away from an axis: full inside the inner cone,
    /// none outside the outer cone, a smooth step between, times cos^exponent of the angle to
    /// the axis.
    Spot {
        /// World position.
        position: Vec3,
        /// Unit axis: the direction the light shines.
        direction: Vec3,
        /// Colour (intensity on the axis).
        color: Vec3,
        /// The course's (a, b, c) falloff with distance.
        attenuation: [f32; 3],
        /// Cosine of the inner cone's half-angle.
        cos_inner: f32,
        /// Cosine of the outer cone's half-angle.
        cos_outer: f32,
        /// Exponent of the cosine falloff (0: none).
        exponent: f32,
    },
    /// A far light of small angular size: the irradiance `color` on a surface facing it, spread
    /// uniformly over a disc of directions.
    Sun {
        /// Unit travel direction of its centre.
        direction: Vec3,
        /// Irradiance on a surface facing it.
        color: Vec3,
        /// Cosine of the disc's angular radius.
        cos_max: f32,
        /// 1 − `cos_max`, computed without cancellation.
        one_minus_cos: f32,
    },
    /// The sky around the scene.
    Environment(Environment),
    /// An emissive object (physical model only).
    Area(AreaLight),
    /// A light with a size that is not an object (the course forks' `area_light`): soft shadows
    /// in the course model, a sampled surface in the physical one ([`soft`]).
    Soft(SoftLight),
}

/// The course reading of light from `position` at `p`: its colour under the course falloff.
fn from_point(p: Vec3, position: Vec3, color: Vec3, attenuation: [f32; 3]) -> Option<LightSample> {
    let to_light = position - p;
    let distance = to_light.length();
    if distance == 0.0 || !distance.is_finite() {
        return None;
    }
    Some(LightSample {
        wi: to_light / distance,
        distance,
        intensity: color * distance_attenuation(attenuation, distance),
    })
}

/// What a light sends to a point under the course model: the unit direction towards the light,
/// the distance to it (infinite for a directional light) and the incident colour before shadowing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the point towards the light.
    pub wi: Vec3,
    /// Distance to the light.
    pub distance: f32,
    /// Colour × distance attenuation.
    pub intensity: Vec3,
}

impl Light {
    /// The course reading: illumination of point `p`; `None` for lights the course model does
    /// not shade with (emissive objects) and at the light itself.
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                color,
                attenuation,
            } => from_point(p, position, color, attenuation),
            Light::Spot {
                position,
                direction,
                color,
                attenuation,
                cos_inner,
                cos_outer,
                exponent,
            } => {
                let to_light = position - p;
                let distance = to_light.length();
                if distance == 0.0 || !distance.is_finite() {
                    return None;
                }
                let wi = to_light / distance;
                let profile = spot_profile(-wi.dot(direction), cos_inner, cos_outer, exponent);
                Some(LightSample {
                    wi,
                    distance,
                    intensity: color * (profile * distance_attenuation(attenuation, distance)),
                })
            }
            Light::Directional { direction, color } | Light::Sun { direction, color, .. } => Some(LightSample {
                wi: -direction,
                distance: f32::INFINITY,
                intensity: color,
            }),
            Light::Soft(ref soft) => from_point(p, soft.center(), soft.color, soft.attenuation),
            Light::Environment(_) | Light::Area(_) => None,
        }
    }

    /// A sun from the angular `diameter_degrees` of its disc; a directional light when that is 0.
    pub fn sun(direction: Vec3, color: Vec3, diameter_degrees: f32) -> Light {
        let half = (0.5 * diameter_degrees).to_radians().clamp(0.0, 0.5 * PI);
        if half <= 0.0 {
            return Light::Directional { direction, color };
        }
        let s = (0.5 * half).sin();
        Light::Sun {
            direction,
            color,
            cos_max: half.cos(),
            one_minus_cos: 2.0 * s * s,
        }
    }

    /// Whether the course model shades with this light and emits caustic photons from it
    /// (point, spot, directional lights, suns and lights with a size).
    pub fn is_course_light(&self) -> bool {
        !matches!(self, Light::Area(_) | Light::Environment(_))
    }

    /// The light's colour: intensity, irradiance, or radiance.
    pub fn color(&self) -> Vec3 {
        match self {
            Light::Point { color, .. }
            | Light::Spot { color, .. }
            | Light::Directional { color, .. }
            | Light::Sun { color, .. } => *color,
            Light::Environment(env) => env.color,
            Light::Area(area) => area.radiance,
            Light::Soft(soft) => soft.color,
        }
    }

    /// The points a course-model shadow ray from `p` aims at when the light has a size (its
    /// shadow is their average); `None` for a light with one shadow ray.
    pub fn shadow_targets(&self, p: Vec3) -> Option<soft::ShadowTargets> {
        match self {
            Light::Soft(soft) => Some(soft.shadow_targets(p)),
            _ => None,
        }
    }

    /// Emitted power (luminance) under the physical model; far lights' is the power through
    /// the disc of radius `scene_radius` across their beams.
    pub fn power(&self, scene_radius: f32) -> f32 {
        let disc = PI * scene_radius * scene_radius;
        match self {
            Light::Point { color, .. } => 4.0 * PI * luminance(*color).max(0.0),
            Light::Spot {
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => spot_solid_angle(*cos_inner, *cos_outer, *exponent) * luminance(*color).max(0.0),
            Light::Directional { color, .. } | Light::Sun { color, .. } => disc * luminance(*color).max(0.0),
            Light::Environment(env) => disc * env.luminance_integral(),
            Light::Area(area) => area.power(),
            Light::Soft(soft) => soft.power(),
        }
    }

    /// A sun's radiance within its disc: E / (π sin²θ), zero for other lights.
    pub(crate) fn sun_radiance(&self) -> Vec3 {
        match self {
            Light::Sun {
                color, one_minus_cos, ..
            } => *color / (PI * one_minus_cos * (2.0 - one_minus_cos)),
            _ => Vec3::ZERO,
        }
    }
}

/// A spot light's intensity relative to its axis at cosine `cos` from the axis.
#[inline]
pub fn spot_profile(cos: f32, cos_inner: f32, cos_outer: f32, exponent: f32) -> f32 {
    if cos <= cos_outer {
        return 0.0;
    }
    let step = if cos >= cos_inner || cos_inner <= cos_outer {
        1.0
    } else {
        let t = (cos - cos_outer) / (cos_inner - cos_outer);
        t * t * (3.0 - 2.0 * t)
    };
    if exponent > 0.0 {
        step * cos.max(0.0).powf(exponent)
    } else {
        step
    }
}

/// ∫ profile dω over the sphere: a spot light's power per unit intensity (numerically, in cos).
pub fn spot_solid_angle(cos_inner: f32, cos_outer: f32, exponent: f32) -> f32 {
    let steps = 1024;
    let span = 1.0 - cos_outer;
    let sum: f32 = (0..steps)
        .map(|i| {
            spot_profile(
                cos_outer + span * (i as f32 + 0.5) / steps as f32,
                cos_inner,
                cos_outer,
                exponent,
            )
        })
        .sum();
    2.0 * PI * span * sum / steps as f32
}

/// The course's falloff min(1, 1 / (a + b d + c d²)); 1 where the denominator is not positive.
#[inline]
pub fn distance_attenuation(abc: [f32; 3], d: f32) -> f32 {
    let denom = abc[0] + abc[1] * d + abc[2] * d * d;
    if denom <= 0.0 {
        1.0
    } else {
        (1.0 / denom).min(1.0)
    }
}

/// Next-event estimation's sample of one light for a shading point (physical model),
/// visibility included.
#[derive(Clone, Copy, Debug)]
pub struct DirectSample {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// Distance to the light's point (infinite for a far light).
    pub distance: f32,
    /// Incident radiance (area lights, suns, the sky) or irradiance (point, spot, directional)
    /// at the path's wavelengths, divided by the probability of the sample: multiplied by f·cos
    /// it is the estimate.
    pub contribution: Spectrum,
    /// Solid-angle pdf including the choice of light, for weighting against BSDF sampling; 0
    /// where no BSDF sample can reach the light (`delta`).
    pub pdf: f32,
    /// The density of the draw, the choice included: per solid angle, and for a point or spot
    /// light the choice × d², for a directional light the choice (vcm's measure).
    pub direct_pdf: f32,
    /// No ray meets the light (a point, spot, directional light, or a light with a size).
    pub delta: bool,
    /// The light's point (a point light's position; unused for far lights).
    pub point: Vec3,
    /// The light's unit normal there (emissive objects and lights with a size).
    pub normal: Vec3,
    /// Cosine at the light between its normal and the direction to the shading point (1 for
    /// lights without a surface).
    pub cos_light: f32,
}

/// What next-event estimation asks of one light: the shading point, the path's wavelengths,
/// and the probability with which the light was taken.
pub(crate) struct DirectQuery<'a> {
    /// The scene (for visibility).
    pub scene: &'a Scene,
    /// The shading point.
    pub hit: &'a SurfaceHit,
    /// The path's wavelengths.
    pub wl: &'a Wavelengths,
    /// The probability of taking this light.
    pub choice: f32,
    /// Whether the shading point can take light from a direction ([`Bsdf::may_take`]).
    pub takes: &'a dyn Fn(Vec3) -> bool,
    /// Where a shadow ray is left untested, for the caller to test with others; `None`:
    /// tested at once.
    pub deferred: Option<&'a Cell<Option<ShadowRay>>>,
}

impl DirectQuery<'_> {
    /// Whether light from `wi` counts at the shading point: it can take it, and nothing blocks
    /// the segment of `distance` towards it. Samples that cannot count skip their shadow rays.
    #[inline(always)]
    pub fn unoccluded(&self, wi: Vec3, distance: f32) -> bool {
        (self.takes)(wi) && self.clear(self.scene.shadow_ray(self.hit, wi, distance, u32::MAX))
    }

    /// Whether nothing blocks `shadow`; where the test is deferred, `true`, with the ray left
    /// for the caller.
    #[inline(always)]
    pub fn clear(&self, shadow: ShadowRay) -> bool {
        match self.deferred {
            Some(cell) => {
                cell.set(Some(shadow));
                true
            }
            None => !self.scene.blocks(&shadow),
        }
    }

    /// The sample of a light no ray meets, at `point` (its unit `normal` there, or zero), of
    /// solid-angle density `pdf` (a point light's: d², so that `value` is its intensity), its
    /// cosine at the light `cos_light`; `None` when something is in between.
    pub fn delta(&self, point: Vec3, normal: Vec3, value: Vec3, pdf: f32, cos_light: f32) -> Option<DirectSample> {
        let to = point - self.hit.point;
        let distance = to.length();
        if !(distance > 0.0 && distance.is_finite() && pdf > 0.0) {
            return None;
        }
        let wi = to / distance;
        self.unoccluded(wi, distance).then(|| DirectSample {
            wi,
            distance,
            contribution: self.wl.unbounded(value / pdf) / self.choice,
            pdf: 0.0,
            direct_pdf: self.choice * pdf,
            delta: true,
            point,
            normal,
            cos_light,
        })
    }
}

/// Every light of a scene: the file's lights in file order, then its emissive objects. Under
/// the physical model lights are chosen in proportion to their power.
#[derive(Clone, Debug, Default)]
pub struct LightSet {
    lights: Vec<Light>,
    /// Probability of choosing each light.
    probabilities: Vec<f32>,
    cdf: Vec<f32>,
    /// Light number of each shape and mesh (`u32::MAX` when it does not emit).
    shape_light: Vec<u32>,
    mesh_light: Vec<u32>,
    /// Numbers of the lights outside the scene (environments and suns), the only ones a ray
    /// that escapes can see.
    sky: Vec<usize>,
    /// Where photons leave the lights.
    emitters: Emitters,
    /// The sphere around the scene, across which directional light enters.
    scene_center: Vec3,
    scene_radius: f32,
}

/// Scenes with at most this many lights sample each of them at every point.
const SAMPLE_EVERY_LIGHT_UP_TO: usize = 8;

/// The share of a far light's photons sent at the mirrors and glass in view rather than over
/// the whole scene.
const FAR_LIGHT_AIM_SHARE: f32 = 0.5;

impl LightSet {
    /// The file's `lights` followed by the emissive objects of `scene`.
    pub fn new(scene: &Scene, mut lights: Vec<Light>) -> LightSet {
        let bounds = scene.bounds();
        let scene_center = bounds.center();
        let scene_radius = (0.5 * bounds.extent().length()).max(1e-3);
        let file_lights = lights.len();
        lights.extend(AreaLight::collect(scene).into_iter().map(Light::Area));
        let powers: Vec<f32> = lights.iter().map(|l| l.power(scene_radius)).collect();
        let total: f32 = powers.iter().sum();
        let probabilities: Vec<f32> = if total > 0.0 && total.is_finite() {
            powers.iter().map(|p| p / total).collect()
        } else {
            vec![0.0; powers.len()]
        };
        let mut acc = 0.0;
        let cdf = probabilities
            .iter()
            .map(|p| {
                acc += p;
                acc
            })
            .collect();
        let mut shape_light = vec![u32::MAX; scene.shapes().len()];
        let mut mesh_light = vec![u32::MAX; scene.meshes().len()];
        for (number, light) in lights.iter().enumerate().skip(file_lights) {
            if let Light::Area(area) = light {
                match area.object {
                    ObjectRef::Shape(s) => shape_light[s as usize] = number as u32,
                    ObjectRef::Mesh(m) => mesh_light[m as usize] = number as u32,
                }
            }
        }
        // Far lights shine on the whole scene: half their photons go to the mirrors and glass
        // in view, where caustics come from, half everywhere for the rest of the light.
        let far_aim = Aim::every(&camera_targets(scene), FAR_LIGHT_AIM_SHARE);
        let emitters = Emitters::new(&lights, (scene_center, scene_radius), None, far_aim);
        let sky = (0..lights.len())
            .filter(|&i| matches!(lights[i], Light::Environment(_) | Light::Sun { .. }))
            .collect();
        LightSet {
            sky,
            lights,
            emitters,
            probabilities,
            cdf,
            shape_light,
            mesh_light,
            scene_center,
            scene_radius,
        }
    }

    /// All lights: the file's, then the emissive objects.
    pub fn iter(&self) -> std::slice::Iter<'_, Light> {
        self.lights.iter()
    }

    /// All lights, as a slice (numbered as [`LightSet::get`] numbers them).
    pub fn as_slice(&self) -> &[Light] {
        &self.lights
    }

    /// The emission of photons under the physical model.
    pub fn emitters(&self) -> &Emitters {
        &self.emitters
    }

    /// Number of lights.
    pub fn len(&self) -> usize {
        self.lights.len()
    }

    /// Light `index`.
    pub fn get(&self, index: usize) -> Option<&Light> {
        self.lights.get(index)
    }

    /// The lights the course model shades with and emits caustic photons from: the file's
    /// point and directional lights, in file order.
    pub fn course_lights(&self) -> impl Iterator<Item = &Light> {
        self.lights.iter().filter(|l| l.is_course_light())
    }

    /// The emissive objects.
    pub fn area_lights(&self) -> impl Iterator<Item = &AreaLight> {
        self.lights.iter().filter_map(|l| match l {
            Light::Area(area) => Some(area),
            _ => None,
        })
    }

    /// Whether nothing emits light under the physical model.
    pub fn is_empty(&self) -> bool {
        self.probabilities.iter().all(|&p| p == 0.0)
    }

    /// Centre and radius of the sphere around the scene.
    pub fn scene_sphere(&self) -> (Vec3, f32) {
        (self.scene_center, self.scene_radius)
    }

    /// The light next-event estimation takes by power when it does not sample every light,
    /// with its probability.
    pub(crate) fn pick_for_direct(&self, u: f32) -> Option<(usize, f32)> {
        self.pick(u)
    }

    fn pick(&self, u: f32) -> Option<(usize, f32)> {
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len().checked_sub(1)?);
        let p = self.probabilities[i];
        (p > 0.0).then_some((i, p))
    }

    /// Whether next-event estimation samples every light at each point (few lights) rather
    /// than one chosen by power: a sun beside the sky, or two lamps, then add no noise by
    /// taking turns.
    pub fn samples_every_light(&self) -> bool {
        self.lights.len() <= SAMPLE_EVERY_LIGHT_UP_TO
    }

    /// The probability that next-event estimation takes light `index` at a point.
    pub(crate) fn direct_probability(&self, index: usize) -> f32 {
        match self.probabilities[index] {
            p if p > 0.0 && self.samples_every_light() => 1.0,
            p => p,
        }
    }

    /// Direct-light samples for the point `hit` (visibility included), each with its own pdf
    /// for MIS: one per light when [`LightSet::samples_every_light`], otherwise one light
    /// chosen by power; `add` receives each sample that carries light and comes from a
    /// direction the point `takes` light from (others may be dropped before their shadow rays).
    pub fn sample_direct(
        &self,
        (scene, hit, takes): (&Scene, &SurfaceHit, &dyn Fn(Vec3) -> bool),
        wl: &Wavelengths,
        rng: &mut Rng,
        mut add: impl FnMut(DirectSample),
    ) {
        // The loop written out: through `each_light_drawn`'s closure the sample was drawn out
        // of line (5% more instructions on the point box).
        if self.samples_every_light() {
            for index in 0..self.lights.len() {
                if self.probabilities[index] > 0.0 {
                    if let Some(sample) = self.sample_light(index, 1.0, (scene, hit, takes), wl, rng) {
                        add(sample);
                    }
                }
            }
        } else if let Some((index, p_pick)) = self.pick(rng.uniform()) {
            if let Some(sample) = self.sample_light(index, p_pick, (scene, hit, takes), wl, rng) {
                add(sample);
            }
        }
    }

    /// Calls `draw(index, p_pick, rng)` for each light next-event estimation samples at a
    /// point: every light, or one picked by power.
    #[inline(always)]
    fn each_light_drawn(&self, rng: &mut Rng, mut draw: impl FnMut(usize, f32, &mut Rng)) {
        if self.samples_every_light() {
            for index in 0..self.lights.len() {
                if self.probabilities[index] > 0.0 {
                    draw(index, 1.0, rng);
                }
            }
        } else if let Some((index, p_pick)) = self.pick(rng.uniform()) {
            draw(index, p_pick, rng);
        }
    }

    /// Samples light `index`, taken with probability `p_pick`, for the point `hit`; a sample
    /// from a direction the point does not `take` light from may be dropped before its shadow
    /// ray (not in scenes with media, where the transmittance's draws follow each sample).
    pub fn sample_light(
        &self,
        index: usize,
        p_pick: f32,
        (scene, hit, takes): (&Scene, &SurfaceHit, &dyn Fn(Vec3) -> bool),
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Option<DirectSample> {
        self.sample_light_deferring(index, p_pick, (scene, hit, takes), None, wl, rng)
    }

    /// [`LightSet::sample_direct`] with each sample's shadow ray left untested, for the caller
    /// to test with others ([`Scene::blocks_each`]): `add(sample, shadow)` is called for every
    /// sample that counts if nothing blocks `shadow` (`None`: nothing does). Only in scenes
    /// without media (whose shadow rays draw random numbers).
    pub fn sample_direct_deferred(
        &self,
        (scene, hit, takes): (&Scene, &SurfaceHit, &dyn Fn(Vec3) -> bool),
        wl: &Wavelengths,
        rng: &mut Rng,
        mut add: impl FnMut(DirectSample, Option<ShadowRay>),
    ) {
        debug_assert!(!scene.has_media(), "shadow rays through media are tested at once");
        let shadow = Cell::new(None);
        self.each_light_drawn(rng, |index, p_pick, rng| {
            let args = (scene, hit, takes);
            if let Some(sample) = self.sample_light_deferring(index, p_pick, args, Some(&shadow), wl, rng) {
                add(sample, shadow.take());
            }
            shadow.set(None);
        });
    }

    /// [`LightSet::sample_light`], its shadow ray left in `deferred` where given.
    #[inline(always)]
    fn sample_light_deferring(
        &self,
        index: usize,
        p_pick: f32,
        (scene, hit, takes): (&Scene, &SurfaceHit, &dyn Fn(Vec3) -> bool),
        deferred: Option<&Cell<Option<ShadowRay>>>,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Option<DirectSample> {
        let q = DirectQuery {
            scene,
            hit,
            wl,
            choice: p_pick,
            takes: if scene.has_media() { &|_| true } else { takes },
            deferred,
        };
        // Three numbers for each light with a size or a spread (the first, a point on a
        // mesh lamp, only an area light's); a point, spot or directional light has one
        // direction to offer and draws none (three unused were 1.7% of the point box).
        let mut draw = || (rng.uniform(), rng.uniform2());
        let sample = match &self.lights[index] {
            light @ (Light::Point { .. } | Light::Spot { .. }) => point::sample_direct(&q, light),
            light @ Light::Directional { .. } => distant::sample_direct(&q, light, Vec2::ZERO),
            light @ Light::Sun { .. } => distant::sample_direct(&q, light, draw().1),
            Light::Environment(env) => env.sample_direct(&q, draw().1),
            Light::Area(light) => light.sample_direct(&q, draw()),
            Light::Soft(light) => light.sample_direct(&q, draw().1),
        };
        if !scene.has_media() {
            return sample;
        }
        // Through fog, or through rough glass to a light inside it (a lamp in a frosted globe).
        sample.map(|mut s| {
            s.contribution *= scene.transmittance_towards(hit, s.wi, s.distance, wl, rng);
            s
        })
    }

    /// Solid-angle pdf of a sun's uniform cone.
    fn sun_pdf(&self, light: &Light) -> f32 {
        match light {
            Light::Sun { one_minus_cos, .. } => distant::sun_cone_pdf(*one_minus_cos),
            _ => 0.0,
        }
    }

    /// Radiance arriving along a ray that leaves the scene in direction `dir` (unit): the sky
    /// and any sun whose disc it points into (physical model), at the wavelengths `wl`.
    pub fn escaped(&self, dir: Vec3, wl: &Wavelengths) -> Spectrum {
        self.escaped_weighted(dir, None, wl)
    }

    /// [`LightSet::escaped`] for a BSDF sample of solid-angle pdf `bsdf_pdf` (when given):
    /// each light's radiance weighted against next-event estimation's chance of sampling it
    /// there (power heuristic).
    pub fn escaped_weighted(&self, dir: Vec3, bsdf_pdf: Option<f32>, wl: &Wavelengths) -> Spectrum {
        self.escaped_weighted_except(dir, bsdf_pdf, wl, |_| false)
    }

    /// [`LightSet::escaped_weighted`] leaving out the lights for which `skip` holds (an
    /// integrator that weighs them itself).
    pub(crate) fn escaped_weighted_except(
        &self,
        dir: Vec3,
        bsdf_pdf: Option<f32>,
        wl: &Wavelengths,
        skip: impl Fn(usize) -> bool,
    ) -> Spectrum {
        let mut l = Spectrum::ZERO;
        for &index in &self.sky {
            let light = &self.lights[index];
            if skip(index) {
                continue;
            }
            let (radiance, light_pdf) = match light {
                Light::Environment(env) => (env.radiance(dir), env.pdf(dir)),
                Light::Sun { direction, cos_max, .. } if -dir.dot(*direction) >= *cos_max => {
                    (light.sun_radiance(), self.sun_pdf(light))
                }
                _ => continue,
            };
            let weight = bsdf_pdf.map_or(1.0, |pdf| {
                power_heuristic(pdf, self.direct_probability(index) * light_pdf)
            });
            if weight > 0.0 {
                l += wl.unbounded(radiance) * weight;
            }
        }
        l
    }

    /// What a course-model ray that leaves the scene sees: the environment's radiance, black
    /// without one.
    pub fn background(&self, dir: Vec3) -> Vec3 {
        self.lights
            .iter()
            .filter_map(|l| match l {
                Light::Environment(env) => Some(env.radiance(dir)),
                _ => None,
            })
            .fold(Vec3::ZERO, |a, b| a + b)
    }

    /// Whether light arrives from outside the scene (an environment or a sun): rays that escape
    /// carry radiance.
    pub fn has_sky(&self) -> bool {
        !self.sky.is_empty()
    }

    /// Solid-angle pdf with which [`LightSet::sample_direct`] from `from` would sample the
    /// emissive point `hit` (its light's), for weighting BSDF samples that hit it; 0 when the
    /// object hit is not a light.
    pub fn pdf_direct(&self, from: Vec3, hit: &SurfaceHit) -> f32 {
        let Some((number, light)) = self.area_light_of(hit) else {
            return 0.0;
        };
        self.direct_probability(number) * light.pdf_towards(from, hit.point, hit.geometric_normal)
    }

    /// The emissive object hit at `hit` and its light number, if it emits.
    pub fn area_light_of(&self, hit: &SurfaceHit) -> Option<(usize, &AreaLight)> {
        let number = match hit.object {
            ObjectRef::Shape(s) => self.shape_light[s as usize],
            ObjectRef::Mesh(m) => self.mesh_light[m as usize],
        } as usize;
        match self.lights.get(number) {
            Some(Light::Area(light)) => Some((number, light)),
            _ => None,
        }
    }
}

/// The radiance the emissive object `light` sends from its point `drawn` (in direction `wi`,
/// `distance` from `hit`) to `hit`, or `None` if something is in between. A uniform light's
/// nearest point (a sphere drawn by its cone) needs only an occlusion test that skips the
/// light's own primitive; otherwise the closest hit towards the point must be that point, and
/// the radiance is read there (textures included). (An occlusion test short of the point
/// that did not skip the light lost a tenth of a small sphere light's light: the sphere itself
/// lies within rounding of the test's end.)
pub(crate) fn visible_emission(
    q: &DirectQuery,
    light: &AreaLight,
    drawn: &area::DirectionSample,
    wi: Vec3,
    distance: f32,
) -> Option<Spectrum> {
    let (scene, hit, wl) = (q.scene, q.hit, q.wl);
    let sample = &drawn.point;
    if drawn.nearest && light.uniform {
        if !light.faces.emit_towards(sample.normal, -wi) {
            return None;
        }
        return q
            .clear(scene.shadow_ray(hit, wi, distance, sample.prim))
            .then(|| emission::area_radiance(light, scene, sample, wl));
    }
    let (ray, isect) = scene.intersect_solid(&Ray::new(hit.ray_origin(wi), wi))?;
    if isect.prim != sample.prim || (isect.t - (sample.point - ray.origin).length()).abs() > 1e-3 * (1.0 + distance) {
        return None;
    }
    Some(scene.emission_towards(&scene.surface(&ray, &isect), -wi, wl))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attenuation_follows_the_course_formula() {
        assert_eq!(distance_attenuation([0.0, 0.0, 1.0], 2.0), 0.25);
        assert_eq!(distance_attenuation([0.0, 0.0, 1.0], 0.5), 1.0, "clamped to 1");
        let stock = [0.25, 0.003372407, 0.000045492];
        let d = 17.32;
        let expected = 1.0 / (0.25 + 0.003372407 * d + 0.000045492 * d * d);
        assert!((distance_attenuation(stock, d) - expected.min(1.0)).abs() < 1e-6);
    }

    #[test]
    fn directional_light_comes_from_against_its_direction() {
        let l = Light::Directional {
            direction: -Vec3::Z,
            color: Vec3::ONE,
        };
        let s = l.sample_li(Vec3::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::Z);
        assert!(s.distance.is_infinite());
    }
}
