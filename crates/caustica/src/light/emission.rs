//! Photon emission: photons leaving the lights, with their flux. Every light emits through an
//! [`Emitter`], uniform or aimed:
//!
//! - uniform: point lights over the whole sphere, directional lights across a disc covering the
//!   scene, emissive objects from a point uniform by area in a cosine-weighted direction;
//! - aimed (point and directional lights): only towards the bounding spheres of the objects that
//!   can make caustics. Point lights sample a mixture of cones (one per target, weighted by solid
//!   angle); directional lights a mixture of discs on a plane across the beam (one per target,
//!   weighted by area).
//!
//! Each photon carries the light's intensity (or irradiance, or radiance) divided by the pdf
//! actually used, so aiming changes the noise, never the expected power. The physical model
//! picks a light in proportion to its power ([`LightSet::emit`]); the course model shares a
//! budget of stored caustic photons between its lights, each aimed.

use super::area::{AreaLight, AreaSample};
use super::{spot_profile, Light, LightSet};
use crate::description::EmittingFaces;
use crate::math::{luminance, offset_origin, Aabb, Frame, Ray, Vec2, Vec3};
use crate::sampling::{sample_cosine_hemisphere, sample_uniform_cone, sample_uniform_disc, Rng};
use crate::scene::{ObjectRef, Scene};
use crate::spectrum::{Spectrum, Wavelengths};
use std::f32::consts::PI;

/// A bounding sphere that photons are aimed at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
}

impl Target {
    /// The cone of directions from `from` that meet the sphere: its axis and the cosine of its
    /// half-angle (−1, every direction, from inside).
    pub fn cone_from(&self, from: Vec3) -> (Vec3, f32) {
        let to = self.center - from;
        let d2 = to.length_squared();
        let r2 = self.radius * self.radius;
        if d2 <= r2 * 1.0001 {
            return (Vec3::Z, -1.0);
        }
        (to / d2.sqrt(), (1.0 - r2 / d2).max(0.0).sqrt())
    }

    /// The sphere around a box (slightly enlarged so grazing paths are not lost).
    pub fn around(bounds: &Aabb) -> Target {
        Target {
            center: bounds.center(),
            radius: 0.5 * bounds.extent().length() * 1.001 + 1e-4,
        }
    }
}

#[derive(Clone, Debug)]
struct ConeLobe {
    axis: Vec3,
    cos_max: f32,
}

#[derive(Clone, Debug)]
struct DiscLobe {
    center: Vec2,
    radius: f32,
}

/// A spot light's cone: the axis and its profile (see [`spot_profile`]).
#[derive(Clone, Copy, Debug)]
struct SpotCone {
    axis: Vec3,
    cos_inner: f32,
    cos_outer: f32,
    exponent: f32,
}

#[derive(Clone, Debug)]
enum Kind {
    /// An emissive object, sampled by its own area sampler.
    Area,
    /// A point or spot light: a mixture of cones of directions.
    Point {
        position: Vec3,
        cones: Vec<ConeLobe>,
        spot: Option<SpotCone>,
    },
    /// A directional light or a sun: a mixture of discs on a plane across the beam; a sun's
    /// photons leave in directions spread over its cone (cos_max, 1 − cos_max).
    Directional {
        direction: Vec3,
        frame: Frame,
        plane_origin: Vec3,
        discs: Vec<DiscLobe>,
        sun: Option<(f32, f32)>,
    },
    /// The sky: a direction by the environment's own sampling, then a point on a disc across
    /// it, the scene's or the targets' as seen along that direction.
    Environment { scene: Target, discs: Vec<Target> },
    /// A light with a size: a point uniform on it, then a direction cosine-weighted about its
    /// normal, or drawn from the cones from that point to the targets when aimed.
    Soft { targets: Option<Vec<Target>> },
}

/// One light's photon source.
#[derive(Clone, Debug)]
pub struct Emitter {
    kind: Kind,
    color: Vec3,
    /// Mixture weights (sum 1) and their running sums.
    weights: Vec<f32>,
    cdf: Vec<f32>,
    power: f32,
}

/// Where photons are aimed: a share `1 − spread` goes towards `targets` (each in proportion
/// to its solid angle or cross-section), the share `spread` everywhere the light shines.
#[derive(Clone, Copy, Debug)]
pub struct Aim<'a> {
    /// The bounding spheres of the objects that make caustics.
    pub targets: &'a [Target],
    /// The share of photons sent everywhere (0: only at the targets).
    pub spread: f32,
}

/// Mixture weights: the target lobes' own weights scaled to `1 − spread`, then the uniform lobe
/// with `spread` (left out when 0).
fn mix(target_weights: Vec<f32>, spread: f32) -> Vec<f32> {
    if spread <= 0.0 {
        return target_weights;
    }
    let total: f32 = target_weights.iter().sum();
    let mut weights: Vec<f32> = if total > 0.0 {
        target_weights.iter().map(|w| w / total * (1.0 - spread)).collect()
    } else {
        Vec::new()
    };
    weights.push(spread);
    weights
}

impl Emitter {
    /// The emitter of `light`, aimed as `aim` says (or uniform when it is `None`; emissive
    /// objects are never aimed); `scene` is the sphere around the scene, across which directional
    /// light enters. `None` when the light cannot send a photon anywhere useful.
    pub fn new(light: &Light, aim: Option<Aim>, scene: Target) -> Option<Emitter> {
        let spread = aim.map_or(1.0, |a| a.spread.clamp(0.0, 1.0));
        let targets = aim.map(|a| a.targets).filter(|t| !t.is_empty() || spread <= 0.0);
        let point = |position: Vec3, color: Vec3, spot: Option<SpotCone>| {
            let everywhere = match spot {
                None => ConeLobe {
                    axis: Vec3::Z,
                    cos_max: -1.0,
                },
                Some(spot) => ConeLobe {
                    axis: spot.axis,
                    cos_max: spot.cos_outer,
                },
            };
            let (mut cones, weights): (Vec<ConeLobe>, Vec<f32>) = match targets {
                None => (vec![everywhere.clone()], vec![1.0]),
                Some(ts) => {
                    let cones: Vec<ConeLobe> = ts.iter().map(|t| cone_towards(position, t)).collect();
                    let weights = cones.iter().map(|c| 1.0 - c.cos_max).collect();
                    (cones, mix(weights, spread))
                }
            };
            if targets.is_some() && spread > 0.0 {
                cones.push(everywhere);
            }
            let power = light.power(scene.radius);
            Emitter::finish(Kind::Point { position, cones, spot }, color, weights, power)
        };
        let directional = |direction: Vec3, color: Vec3, sun: Option<(f32, f32)>| {
            let frame = Frame::from_normal(direction);
            let plane_origin = scene.center - direction * (scene.radius * 2.0 + 1.0);
            // A sun's photons lean by up to its angular radius: widen each disc so that every
            // leaning ray that can reach the target starts inside it.
            let lean = sun.map_or(0.0, |(cos_max, _)| (1.0 - cos_max * cos_max).max(0.0).sqrt() / cos_max);
            let to_disc = |t: &Target| {
                let local = frame.to_local(t.center - plane_origin);
                DiscLobe {
                    center: Vec2::new(local.x, local.y),
                    radius: t.radius + (local.z.max(0.0) + t.radius) * lean,
                }
            };
            let (discs, weights): (Vec<DiscLobe>, Vec<f32>) = match targets {
                None => (vec![to_disc(&scene)], vec![1.0]),
                Some(ts) => {
                    let mut discs: Vec<DiscLobe> = ts.iter().map(to_disc).collect();
                    let weights = mix(discs.iter().map(|d| d.radius * d.radius).collect(), spread);
                    if spread > 0.0 {
                        discs.push(to_disc(&scene));
                    }
                    (discs, weights)
                }
            };
            let power = luminance(color).max(0.0) * PI * scene.radius * scene.radius;
            let kind = Kind::Directional {
                direction,
                frame,
                plane_origin,
                discs,
                sun,
            };
            Emitter::finish(kind, color, weights, power)
        };
        match *light {
            Light::Point { position, color, .. } => point(position, color, None),
            Light::Spot {
                position,
                direction,
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => point(
                position,
                color,
                Some(SpotCone {
                    axis: direction,
                    cos_inner,
                    cos_outer,
                    exponent,
                }),
            ),
            Light::Area(ref area) => Emitter::finish(Kind::Area, area.radiance, vec![1.0], area.power()),
            Light::Soft(ref soft) => Emitter::finish(
                Kind::Soft {
                    targets: targets.map(<[Target]>::to_vec),
                },
                soft.color,
                vec![1.0],
                soft.power(),
            ),
            Light::Directional { direction, color } => directional(direction, color, None),
            Light::Sun {
                direction,
                color,
                cos_max,
                one_minus_cos,
            } => directional(direction, color, Some((cos_max, one_minus_cos))),
            Light::Environment(ref env) => {
                let (discs, weights): (Vec<Target>, Vec<f32>) = match targets {
                    None => (vec![scene], vec![1.0]),
                    Some(ts) => {
                        let mut discs = ts.to_vec();
                        let weights = mix(discs.iter().map(|d| d.radius * d.radius).collect(), spread);
                        if spread > 0.0 {
                            discs.push(scene);
                        }
                        (discs, weights)
                    }
                };
                let kind = Kind::Environment { scene, discs };
                Emitter::finish(
                    kind,
                    env.color.max(Vec3::splat(1e-30)),
                    weights,
                    light.power(scene.radius),
                )
            }
        }
    }

    fn finish(kind: Kind, color: Vec3, weights: Vec<f32>, power: f32) -> Option<Emitter> {
        let total: f32 = weights.iter().sum();
        if total.is_nan() || total <= 0.0 || !total.is_finite() || color.max_element() <= 0.0 {
            return None;
        }
        let weights: Vec<f32> = weights.iter().map(|w| w / total).collect();
        let mut acc = 0.0;
        let cdf = weights
            .iter()
            .map(|w| {
                acc += w;
                acc
            })
            .collect();
        Some(Emitter {
            kind,
            color,
            weights,
            cdf,
            power,
        })
    }

    /// The light's power (luminance), used to share a photon budget between lights.
    pub fn power(&self) -> f32 {
        self.power
    }

    /// A photon from `light` (the light this emitter was made for) with its flux before
    /// division by the number of photons emitted.
    pub fn sample(&self, light: &Light, scene: &Scene, wl: &Wavelengths, rng: &mut Rng) -> Option<EmittedPhoton> {
        if let (Kind::Area, Light::Area(area)) = (&self.kind, light) {
            let u_pick = rng.uniform();
            let (u, u_dir) = (rng.uniform2(), rng.uniform2());
            return emit_from_area(area, scene, (u_pick, u, u_dir), wl);
        }
        if let (Kind::Soft { targets }, Light::Soft(soft)) = (&self.kind, light) {
            return emit_from_soft(soft, targets.as_deref(), wl, rng);
        }
        let lobe = self.pick(rng.uniform());
        let u = rng.uniform2();
        let (ray, flux) = match &self.kind {
            Kind::Point { position, cones, spot } => {
                let dir = sample_uniform_cone(u, cones[lobe].axis, cones[lobe].cos_max);
                let pdf = self.cone_pdf(cones, dir);
                let profile = spot.map_or(1.0, |s| {
                    spot_profile(dir.dot(s.axis), s.cos_inner, s.cos_outer, s.exponent)
                });
                (pdf > 0.0 && profile > 0.0)
                    .then(|| (Ray::new(*position, dir), wl.unbounded(self.color) * (profile / pdf)))?
            }
            Kind::Directional {
                direction,
                frame,
                plane_origin,
                discs,
                sun,
            } => {
                let disc = &discs[lobe];
                let p = disc.center + sample_uniform_disc(u) * disc.radius;
                let pdf = self.disc_pdf(discs, p);
                let origin = *plane_origin + frame.x * p.x + frame.y * p.y;
                let (dir, spread) = match sun {
                    None => (*direction, 1.0),
                    // Over the sun's disc: radiance E / (π sin²θ) × cos × the cone's solid angle.
                    Some((cos_max, one_minus_cos)) => {
                        let dir = sample_uniform_cone(rng.uniform2(), *direction, *cos_max);
                        (dir, 2.0 * dir.dot(*direction) / (2.0 - one_minus_cos))
                    }
                };
                (pdf > 0.0).then(|| (Ray::new(origin, dir), wl.unbounded(self.color) * (spread / pdf)))?
            }
            Kind::Environment { scene, discs } => {
                let Light::Environment(env) = light else {
                    return None;
                };
                let sky = env.sample(rng.uniform2())?;
                let dir = -sky.wi;
                let frame = Frame::from_normal(dir);
                let plane_origin = scene.center - dir * (scene.radius * 2.0 + 1.0);
                let project = |t: &Target| {
                    let local = frame.to_local(t.center - plane_origin);
                    DiscLobe {
                        center: Vec2::new(local.x, local.y),
                        radius: t.radius,
                    }
                };
                let lobes: Vec<DiscLobe> = discs.iter().map(project).collect();
                let disc = &lobes[lobe];
                let p = disc.center + sample_uniform_disc(u) * disc.radius;
                let pdf_area = self.disc_pdf(&lobes, p);
                let origin = plane_origin + frame.x * p.x + frame.y * p.y;
                (pdf_area > 0.0 && sky.pdf > 0.0).then(|| {
                    let radiance = wl.unbounded(sky.radiance);
                    (Ray::new(origin, dir), radiance / (sky.pdf * pdf_area))
                })?
            }
            Kind::Area | Kind::Soft { .. } => return None,
        };
        Some(EmittedPhoton {
            ray,
            flux,
            origin: None,
        })
    }

    fn pick(&self, u: f32) -> usize {
        self.cdf.iter().position(|&c| u < c).unwrap_or(self.cdf.len() - 1)
    }

    /// Solid-angle pdf of the cone mixture.
    fn cone_pdf(&self, cones: &[ConeLobe], dir: Vec3) -> f32 {
        cones
            .iter()
            .zip(&self.weights)
            .filter(|(c, _)| c.cos_max <= -1.0 || dir.dot(c.axis) >= c.cos_max)
            .map(|(c, w)| w / (2.0 * PI * (1.0 - c.cos_max)))
            .sum()
    }

    /// Area pdf of the disc mixture on the emission plane.
    fn disc_pdf(&self, discs: &[DiscLobe], p: Vec2) -> f32 {
        discs
            .iter()
            .zip(&self.weights)
            .filter(|(d, _)| (p - d.center).length_squared() <= d.radius * d.radius * (1.0 + 1e-5))
            .map(|(d, w)| w / (PI * d.radius * d.radius))
            .sum()
    }
}

fn cone_towards(position: Vec3, target: &Target) -> ConeLobe {
    let (axis, cos_max) = target.cone_from(position);
    ConeLobe { axis, cos_max }
}

/// The bounding spheres photons are aimed at: one per reflective or transmissive object.
pub fn caustic_targets(scene: &Scene) -> Vec<Target> {
    specular_targets(scene).into_iter().map(|(_, target)| target).collect()
}

/// The targets of the mirrors and glass the camera sees, directly or through other mirrors and
/// glass (followed straight on, which is enough to find them): a sky or a sun lights the whole
/// scene, and photons aimed at objects out of view make caustics nobody sees.
pub fn camera_targets(scene: &Scene) -> Vec<Target> {
    let targets = specular_targets(scene);
    if targets.is_empty() {
        return Vec::new();
    }
    const GRID: usize = 48;
    const MAX_CHAIN: usize = 4;
    let mut seen = std::collections::HashSet::new();
    for j in 0..GRID {
        for i in 0..GRID {
            let (sx, sy) = ((i as f32 + 0.5) / GRID as f32, (j as f32 + 0.5) / GRID as f32);
            let mut ray = scene.camera().generate_ray(sx, sy);
            for _ in 0..MAX_CHAIN {
                let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
                    break;
                };
                let hit = scene.surface(&ray, &isect);
                if !scene.object_is_specular(hit.object) {
                    break;
                }
                seen.insert(hit.object);
                ray = Ray::new(hit.ray_origin(ray.dir), ray.dir);
            }
        }
    }
    targets
        .into_iter()
        .filter(|(object, _)| seen.contains(object))
        .map(|(_, target)| target)
        .collect()
}

/// Each reflective or transmissive object with its target: for a shape, the smaller of the
/// sphere around its world bounds and its own bounding sphere (a rotated ring's world box is
/// much larger than the ring, and every photon aimed past the ring is traced for nothing).
fn specular_targets(scene: &Scene) -> Vec<(ObjectRef, Target)> {
    scene
        .objects()
        .filter(|(object, bounds)| scene.object_is_specular(*object) && !bounds.is_empty())
        .map(|(object, bounds)| {
            let around = Target::around(&bounds);
            let ObjectRef::Shape(i) = object else {
                return (object, around);
            };
            let (center, radius) = scene.shapes()[i as usize].bounding_sphere();
            let own = Target {
                center,
                radius: radius * 1.001 + 1e-4,
            };
            if own.radius < around.radius && own.radius.is_finite() && center.is_finite() {
                (object, own)
            } else {
                (object, around)
            }
        })
        .collect()
}

/// A photon leaving a light: its ray and its flux before division by the photon count.
#[derive(Clone, Copy, Debug)]
pub struct EmittedPhoton {
    /// Origin and unit direction.
    pub ray: Ray,
    /// Flux at the wavelengths it was emitted for (RGB in RGB mode).
    pub flux: Spectrum,
    /// The surface point it left, when it left one (a light with an area), for the light tracer
    /// to show the light itself.
    pub origin: Option<EmissionPoint>,
}

/// A sampled point on an emitting surface.
#[derive(Clone, Copy, Debug)]
pub struct EmissionPoint {
    /// World position.
    pub point: Vec3,
    /// Unit geometric normal, naming its faces.
    pub normal: Vec3,
    /// The faces light leaves by.
    pub faces: EmittingFaces,
    /// Emitted radiance over the density of the point (area density × the light's choice).
    pub radiance: Spectrum,
}

impl LightSet {
    /// One photon from a light chosen by power, its flux divided by the probability of the
    /// choice; `None` if the sample carries nothing.
    pub fn emit(&self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng) -> Option<EmittedPhoton> {
        let (index, p_pick) = self.pick(rng.uniform())?;
        let emitter = self.emitters[index].as_ref()?;
        let photon = emitter.sample(&self.lights[index], scene, wl, rng)?;
        Some(EmittedPhoton {
            ray: photon.ray,
            flux: photon.flux / p_pick,
            origin: photon.origin.map(|o| EmissionPoint {
                radiance: o.radiance / p_pick,
                ..o
            }),
        })
    }
}

/// A photon from an emissive object: a point by area, a face, a cosine-weighted direction.
fn emit_from_area(
    light: &AreaLight,
    scene: &Scene,
    (u_pick, u, u_dir): (f32, Vec2, Vec2),
    wl: &Wavelengths,
) -> Option<EmittedPhoton> {
    let sample = light.sample(scene, u_pick, u)?;
    let le = area_radiance(light, scene, &sample, wl);
    // A face at random, or the one that emits, then a cosine-weighted direction: pdf ½·cos/π,
    // or cos/π.
    let (side, u2) = emitting_side(light, u_dir);
    let normal = sample.normal * side;
    let dir = Frame::from_normal(normal).to_world(sample_cosine_hemisphere(u2));
    if dir.dot(normal) <= 0.0 {
        return None;
    }
    Some(EmittedPhoton {
        ray: Ray::new(offset_origin(sample.point, sample.normal, dir), dir),
        flux: le * (light.faces.count() * PI / sample.pdf_area),
        origin: Some(EmissionPoint {
            point: sample.point,
            normal: sample.normal,
            faces: light.faces,
            radiance: le / sample.pdf_area,
        }),
    })
}

/// The sign of the normal a cosine-weighted emission leaves along, and the direction's own
/// random pair: the one emitting face, or either face with the first number split between them.
pub(crate) fn emitting_side(light: &AreaLight, u: Vec2) -> (f32, Vec2) {
    match light.faces.sign() {
        Some(side) => (side, u),
        None if u.x < 0.5 => (1.0, Vec2::new(u.x * 2.0, u.y)),
        None => (-1.0, Vec2::new(u.x * 2.0 - 1.0, u.y)),
    }
}

/// A photon from a light with a size: a point uniform on it, then a direction cosine-weighted
/// about its normal, or (aimed) from the mixture of the cones from that point to the targets;
/// its flux is L·cos·A / pdf(direction).
fn emit_from_soft(
    light: &super::SoftLight,
    targets: Option<&[Target]>,
    wl: &Wavelengths,
    rng: &mut Rng,
) -> Option<EmittedPhoton> {
    let s = light.sample_point(rng.uniform2());
    let u = rng.uniform2();
    let (dir, pdf) = match targets {
        None => {
            let dir = Frame::from_normal(s.normal).to_world(sample_cosine_hemisphere(u));
            (dir, dir.dot(s.normal).max(0.0) / PI)
        }
        Some(targets) => {
            let cones: Vec<ConeLobe> = targets.iter().map(|t| cone_towards(s.point, t)).collect();
            let weights: Vec<f32> = cones.iter().map(|c| 1.0 - c.cos_max).collect();
            let total: f32 = weights.iter().sum();
            if total.is_nan() || total <= 0.0 {
                return None;
            }
            let mut pick = rng.uniform() * total;
            let lobe = weights
                .iter()
                .position(|w| {
                    pick -= w;
                    pick < 0.0
                })
                .unwrap_or(cones.len() - 1);
            let dir = sample_uniform_cone(u, cones[lobe].axis, cones[lobe].cos_max);
            let pdf: f32 = cones
                .iter()
                .zip(&weights)
                .filter(|(c, _)| c.cos_max <= -1.0 || dir.dot(c.axis) >= c.cos_max)
                .map(|(c, w)| w / total / (2.0 * PI * (1.0 - c.cos_max)))
                .sum();
            (dir, pdf)
        }
    };
    let cos = dir.dot(s.normal);
    if !(cos > 0.0 && pdf > 0.0) {
        return None;
    }
    Some(EmittedPhoton {
        ray: Ray::new(s.point, dir),
        flux: wl.unbounded(s.radiance) * (cos * light.area() / pdf),
        origin: Some(EmissionPoint {
            point: s.point,
            normal: s.normal,
            faces: EmittingFaces::Front,
            radiance: wl.unbounded(s.radiance) * light.area(),
        }),
    })
}

/// The radiance an emissive object sends from its sampled point `sample`, at the wavelengths
/// `wl`.
pub(crate) fn area_radiance(light: &AreaLight, scene: &Scene, sample: &AreaSample, wl: &Wavelengths) -> Spectrum {
    match (light.uniform, wl.is_spectral()) {
        (true, false) => light.radiance.extend(0.0),
        (true, true) => scene
            .material_spectra(scene.object_material(light.object))
            .emission(light.radiance, wl),
        (false, _) => wl.unbounded(emission_at(scene, sample)),
    }
}

/// The emitted radiance at a sampled light point, read from its material by a short ray.
fn emission_at(scene: &Scene, sample: &AreaSample) -> Vec3 {
    let eps = 1e-3 * (1.0 + sample.point.abs().max_element());
    let ray = Ray::new(sample.point + sample.normal * eps, -sample.normal);
    match scene.intersect(&ray, 2.0 * eps) {
        Some(isect) => scene.emission(&scene.surface(&ray, &isect)),
        None => Vec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Uniform, aimed only, and aimed with a third spread everywhere: each must carry the same
    /// expected flux.
    fn aims(targets: &[Target]) -> [Option<Aim<'_>>; 3] {
        [
            None,
            Some(Aim { targets, spread: 0.0 }),
            Some(Aim { targets, spread: 0.3 }),
        ]
    }
    use crate::scene::build::test_scene as scene;

    fn bounds() -> Aabb {
        Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0))
    }

    /// The expected power per photon times the fraction of photons reaching a set must equal the
    /// light's power into that set, whatever the aiming.
    #[test]
    fn aimed_point_emission_preserves_power_into_a_target() {
        let light = Light::Point {
            position: Vec3::new(0.0, 0.0, 5.0),
            color: Vec3::ONE,
            attenuation: [0.0, 0.0, 1.0],
        };
        let targets = [
            Target {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            Target {
                center: Vec3::new(0.5, 0.0, 0.0),
                radius: 1.0,
            },
            Target {
                center: Vec3::new(3.0, 0.0, 0.0),
                radius: 0.5,
            },
        ];
        let target = &targets[0];
        let cos_max = (1.0f32 - 1.0 / 25.0).sqrt();
        let exact = 2.0 * PI * (1.0 - cos_max); // intensity 1 × solid angle of the first sphere
        for aim in aims(&targets) {
            let e = Emitter::new(&light, aim, Target::around(&bounds())).unwrap();
            let mut rng = Rng::new(1, 0);
            let empty = scene("");
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let photon = e.sample(&light, &empty, &Wavelengths::Rgb, &mut rng).unwrap();
                let (ray, power) = (photon.ray, photon.flux);
                let to = target.center - ray.origin;
                if ray.dir.dot(to.normalize()) >= cos_max {
                    sum += power.x as f64;
                }
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.02,
                "aim {aim:?}: {estimate} vs {exact}"
            );
        }
    }

    #[test]
    fn aimed_directional_emission_preserves_flux_through_a_target() {
        let light = Light::Directional {
            direction: Vec3::new(0.0, 0.0, -1.0),
            color: Vec3::splat(2.0),
        };
        let targets = [
            Target {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            Target {
                center: Vec3::new(0.8, 0.0, 0.0),
                radius: 1.0,
            },
        ];
        let exact = 2.0 * PI; // irradiance 2 through the unit disc across the beam
        for aim in aims(&targets) {
            let small = Aabb::new(Vec3::splat(-3.0), Vec3::splat(3.0));
            let e = Emitter::new(&light, aim, Target::around(&small)).unwrap();
            let mut rng = Rng::new(2, 0);
            let empty = scene("");
            let n = 2_000_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let photon = e.sample(&light, &empty, &Wavelengths::Rgb, &mut rng).unwrap();
                let (ray, power) = (photon.ray, photon.flux);
                let p = ray.origin;
                if p.x * p.x + p.y * p.y <= 1.0 {
                    sum += power.x as f64;
                }
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.02,
                "aim {aim:?}: {estimate} vs {exact}"
            );
        }
    }

    /// Photons carry the lamp's whole useful power: π·A·Le from each face that lights anything,
    /// the outer face only for a closed lamp that absorbs its own inward light.
    #[test]
    fn emitted_flux_is_the_lamps_power() {
        let lamp = "scale(0.5, sphere { material = { emissive = (2, 2, 2); } })";
        for (objects, faces, outward) in [
            (lamp.to_string(), 1.0, true),
            (
                format!("{lamp} scale(0.1, sphere {{ material = {{ diffuse = (1,1,1); }} }})"),
                2.0,
                false,
            ),
            (
                "scale(0.5, sphere { material = { emissive = (2, 2, 2); diffuse = (0.5, 0.5, 0.5); } })".to_string(),
                2.0,
                false,
            ),
        ] {
            let s = scene(&objects);
            let lights = s.lights();
            let faces_emitting = if outward {
                crate::description::EmittingFaces::Front
            } else {
                crate::description::EmittingFaces::Both
            };
            assert_eq!(lights.area_lights().next().unwrap().faces, faces_emitting, "{objects}");
            let mut rng = Rng::new(3, 0);
            let n = 100_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                if let Some(p) = lights.emit(&s, &Wavelengths::Rgb, &mut rng) {
                    sum += p.flux.x as f64;
                    let outside = (p.ray.origin - Vec3::ZERO).dot(p.ray.dir) > 0.0;
                    assert!(outside || !outward, "an outward-only lamp emitted inwards");
                }
            }
            let exact = faces * std::f64::consts::PI * (4.0 * std::f64::consts::PI * 0.25) * 2.0;
            assert!(
                (sum / n as f64 / exact - 1.0).abs() < 0.01,
                "{objects}: {} vs {exact}",
                sum / n as f64
            );
        }
    }

    /// The flux that far lights send through a sphere in the scene: E·πr² for a directional
    /// light or a sun, πr²·∫L dω for the sky — whether the photons are aimed at the sphere or
    /// spread over the scene.
    #[test]
    fn far_lights_send_their_flux_through_a_sphere_aimed_or_not() {
        use crate::light::Environment;
        use crate::texture::Texture;
        let sky_map = Texture::new(
            16,
            8,
            (0..128)
                .map(|i| if i == 20 { Vec3::splat(50.0) } else { Vec3::splat(0.3) })
                .collect(),
        )
        .unwrap();
        let sky = Environment::new(Vec3::new(1.0, 0.8, 0.6), Some(sky_map), crate::math::Mat3::IDENTITY);
        let sky_flux_density = sky.luminance_integral();
        let target = Target {
            center: Vec3::new(0.7, -0.2, 0.4),
            radius: 0.6,
        };
        let scene_sphere = Target {
            center: Vec3::ZERO,
            radius: 3.0,
        };
        let lights = [
            (
                Light::Directional {
                    direction: Vec3::new(0.2, -1.0, 0.1).normalize(),
                    color: Vec3::splat(2.0),
                },
                2.0 * PI * 0.36,
            ),
            (
                Light::sun(Vec3::new(-0.3, -1.0, 0.2).normalize(), Vec3::splat(2.0), 5.0),
                2.0 * PI * 0.36 * 2.0 / (1.0 + 2.5f32.to_radians().cos()),
            ),
            (Light::Environment(sky), PI * 0.36 * sky_flux_density),
        ];
        let empty = scene("");
        for (light, exact) in lights {
            let targets = [target];
            for aim in aims(&targets) {
                let e = Emitter::new(&light, aim, scene_sphere).unwrap();
                let mut rng = Rng::new(4, 0);
                let n = 400_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let Some(p) = e.sample(&light, &empty, &Wavelengths::Rgb, &mut rng) else {
                        continue;
                    };
                    // Does the ray pass through the sphere?
                    let oc = target.center - p.ray.origin;
                    let t = oc.dot(p.ray.dir);
                    if t > 0.0 && (oc - p.ray.dir * t).length_squared() <= target.radius * target.radius {
                        sum += crate::math::luminance(p.flux.truncate()) as f64;
                    }
                }
                let estimate = sum / n as f64;
                assert!(
                    (estimate / exact as f64 - 1.0).abs() < 0.02,
                    "{light:?} aim {aim:?}: {estimate} vs {exact}"
                );
            }
        }
    }
}
