//! What the physically based integrators share: every light of the scene (point, directional and
//! emissive objects) behind one power-proportional choice, next-event estimation with multiple
//! importance sampling, and photon emission. Units and conventions: docs/radiometry.md.
//!
//! In the physical model a point light's colour is its intensity I (W/sr) and it falls off with
//! the inverse square (the file's attenuation coefficients are ignored); a directional light's
//! colour is the irradiance E (W/m²) on a surface facing it; an emissive object emits radiance
//! ke (W/m²/sr) from both faces.

use crate::area_light::{AreaLight, AreaSample};
use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::light::Light;
use crate::math::{luminance, offset_origin, Frame, Ray, Vec2, Vec3};
use crate::sampling::{sample_cosine_hemisphere, sample_uniform_disc, sample_uniform_sphere, Rng};
use crate::scene::{ObjectRef, Scene, SurfaceHit};
use std::f32::consts::PI;

/// All lights of a scene, chosen in proportion to their power.
pub struct Lights {
    /// Emissive objects (after the scene's point and directional lights in the numbering).
    pub area: Vec<AreaLight>,
    /// Probability of choosing each light: `scene.lights` first, then `area`.
    probabilities: Vec<f32>,
    cdf: Vec<f32>,
    /// Light number of each shape and mesh (`u32::MAX` when it does not emit).
    shape_light: Vec<u32>,
    mesh_light: Vec<u32>,
    /// The sphere around the scene, across which directional light enters.
    scene_center: Vec3,
    scene_radius: f32,
    point_count: usize,
}

/// A light sample for a shading point.
#[derive(Clone, Copy, Debug)]
pub struct DirectSample {
    /// Unit direction towards the light.
    pub wi: Vec3,
    /// Incident radiance (area lights) or irradiance (point, directional) divided by the
    /// probability of the sample: multiplied by f·cos it is the estimate.
    pub contribution: Vec3,
    /// Solid-angle pdf including the choice of light, for MIS; 0 for delta lights.
    pub pdf: f32,
}

/// A photon leaving a light: its ray and its flux before division by the photon count.
#[derive(Clone, Copy, Debug)]
pub struct EmittedPhoton {
    /// Origin and unit direction.
    pub ray: Ray,
    /// Flux.
    pub flux: Vec3,
}

impl Lights {
    /// The lights of `scene`.
    pub fn new(scene: &Scene) -> Lights {
        let area = AreaLight::collect(scene);
        let bounds = scene.bounds();
        let scene_center = bounds.center();
        let scene_radius = (0.5 * bounds.extent().length()).max(1e-3);
        let mut powers: Vec<f32> = scene
            .lights
            .iter()
            .map(|light| match light {
                Light::Point { color, .. } => 4.0 * PI * luminance(*color).max(0.0),
                Light::Directional { color, .. } => PI * scene_radius * scene_radius * luminance(*color).max(0.0),
            })
            .collect();
        powers.extend(area.iter().map(AreaLight::power));
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
        let mut shape_light = vec![u32::MAX; scene.shapes.len()];
        let mut mesh_light = vec![u32::MAX; scene.meshes.len()];
        let point_count = scene.lights.len();
        for (i, light) in area.iter().enumerate() {
            let number = (point_count + i) as u32;
            match light.object {
                ObjectRef::Shape(s) => shape_light[s as usize] = number,
                ObjectRef::Mesh(m) => mesh_light[m as usize] = number,
            }
        }
        Lights {
            area,
            probabilities,
            cdf,
            shape_light,
            mesh_light,
            scene_center,
            scene_radius,
            point_count,
        }
    }

    /// Whether nothing emits light.
    pub fn is_empty(&self) -> bool {
        self.probabilities.iter().all(|&p| p == 0.0)
    }

    fn pick(&self, u: f32) -> Option<(usize, f32)> {
        let i = self
            .cdf
            .partition_point(|&c| c <= u)
            .min(self.cdf.len().checked_sub(1)?);
        let p = self.probabilities[i];
        (p > 0.0).then_some((i, p))
    }

    /// Samples one light for the point `hit` (visibility included): `None` when the light
    /// chosen sends nothing there.
    pub fn sample_direct(&self, scene: &Scene, hit: &SurfaceHit, rng: &mut Rng) -> Option<DirectSample> {
        let (index, p_pick) = self.pick(rng.uniform())?;
        let (u_pick, u) = (rng.uniform(), rng.uniform2());
        let p = hit.point;
        let ng = hit.geometric_normal;
        if index < self.point_count {
            let (wi, distance, value) = match scene.lights[index] {
                Light::Point { position, color, .. } => {
                    let to = position - p;
                    let d2 = to.length_squared();
                    if !(d2 > 0.0 && d2.is_finite()) {
                        return None;
                    }
                    let d = d2.sqrt();
                    (to / d, d, color / d2)
                }
                Light::Directional { direction, color } => (-direction, f32::INFINITY, color),
            };
            if !unoccluded(scene, p, ng, wi, distance) {
                return None;
            }
            return Some(DirectSample {
                wi,
                contribution: value / p_pick,
                pdf: 0.0,
            });
        }
        let light = &self.area[index - self.point_count];
        let drawn = light.sample_towards(scene, p, u_pick, u)?;
        let sample = drawn.point;
        let to = sample.point - p;
        let d = to.length();
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let wi = to / d;
        // The closest hit towards the sampled point must be that point: this tests visibility
        // and reads the emitted radiance there (textures included).
        let origin = offset_origin(p, ng, wi);
        let ray = Ray::new(origin, wi);
        let isect = scene.intersect(&ray, f32::INFINITY)?;
        if isect.prim != sample.prim || (isect.t - (sample.point - origin).length()).abs() > 1e-3 * (1.0 + d) {
            return None;
        }
        let le = scene.surface(&ray, &isect).params.emissive;
        let pdf = p_pick * drawn.pdf_solid;
        Some(DirectSample {
            wi,
            contribution: le / pdf,
            pdf,
        })
    }

    /// Solid-angle pdf with which [`Lights::sample_direct`] from `from` would pick the emissive
    /// point `hit`; 0 when the object hit is not a light.
    pub fn pdf_direct(&self, from: Vec3, hit: &SurfaceHit) -> f32 {
        let number = match hit.object {
            ObjectRef::Shape(s) => self.shape_light[s as usize],
            ObjectRef::Mesh(m) => self.mesh_light[m as usize],
        };
        if number == u32::MAX {
            return 0.0;
        }
        let light = &self.area[number as usize - self.point_count];
        self.probabilities[number as usize] * light.pdf_towards(from, hit.point, hit.geometric_normal)
    }

    /// One photon from a light chosen by power; `None` if the sample carries nothing.
    pub fn emit(&self, scene: &Scene, rng: &mut Rng) -> Option<EmittedPhoton> {
        let (index, p_pick) = self.pick(rng.uniform())?;
        let (u_pick, u, u_dir) = (rng.uniform(), rng.uniform2(), rng.uniform2());
        if index < self.point_count {
            return match scene.lights[index] {
                Light::Point { position, color, .. } => Some(EmittedPhoton {
                    ray: Ray::new(position, sample_uniform_sphere(u_dir)),
                    flux: color * (4.0 * PI / p_pick),
                }),
                Light::Directional { direction, color } => {
                    let frame = Frame::from_normal(direction);
                    let d = sample_uniform_disc(u) * self.scene_radius;
                    let origin =
                        self.scene_center - direction * (2.0 * self.scene_radius + 1.0) + frame.x * d.x + frame.y * d.y;
                    let area = PI * self.scene_radius * self.scene_radius;
                    Some(EmittedPhoton {
                        ray: Ray::new(origin, direction),
                        flux: color * (area / p_pick),
                    })
                }
            };
        }
        let light = &self.area[index - self.point_count];
        let sample = light.sample(scene, u_pick, u)?;
        let le = if light.uniform {
            light.radiance
        } else {
            emission_at(scene, &sample)
        };
        // A face at random (the outer one of a closed lamp that absorbs its own inward light),
        // then a cosine-weighted direction: pdf ½·cos/π, or cos/π.
        let (side, u2, faces) = if light.outward_only {
            (1.0, u_dir, 1.0)
        } else if u_dir.x < 0.5 {
            (1.0, Vec2::new(u_dir.x * 2.0, u_dir.y), 2.0)
        } else {
            (-1.0, Vec2::new(u_dir.x * 2.0 - 1.0, u_dir.y), 2.0)
        };
        let normal = sample.normal * side;
        let dir = Frame::from_normal(normal).to_world(sample_cosine_hemisphere(u2));
        if dir.dot(normal) <= 0.0 {
            return None;
        }
        Some(EmittedPhoton {
            ray: Ray::new(offset_origin(sample.point, sample.normal, dir), dir),
            flux: le * (faces * PI / (sample.pdf_area * p_pick)),
        })
    }
}

/// The emitted radiance at a sampled light point, read from its material by a short ray.
fn emission_at(scene: &Scene, sample: &AreaSample) -> Vec3 {
    let eps = 1e-3 * (1.0 + sample.point.abs().max_element());
    let ray = Ray::new(sample.point + sample.normal * eps, -sample.normal);
    match scene.intersect(&ray, 2.0 * eps) {
        Some(isect) => scene.surface(&ray, &isect).params.emissive,
        None => Vec3::ZERO,
    }
}

/// Whether nothing blocks the segment from a surface point towards `wi` for `distance`.
/// In the physical model glass blocks shadow rays: light through it arrives as caustics.
pub fn unoccluded(scene: &Scene, point: Vec3, geometric_normal: Vec3, wi: Vec3, distance: f32) -> bool {
    let origin = offset_origin(point, geometric_normal, wi);
    let t_max = if distance.is_finite() {
        (distance - (origin - point).length()) * (1.0 - 1e-5)
    } else {
        f32::INFINITY
    };
    !scene.any_hit(&Ray::new(origin, wi), t_max, |_| true)
}

/// Power heuristic (β = 2) weight of a strategy with pdf `a` against one with pdf `b`.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

/// Direct light at a smooth surface point by one light sample, weighted against BSDF sampling
/// when `mis` is set (the caller then also counts emitters its BSDF samples hit).
pub fn direct_light(
    scene: &Scene,
    lights: &Lights,
    hit: &SurfaceHit,
    bsdf: &Bsdf,
    wo: Vec3,
    mis: bool,
    rng: &mut Rng,
) -> Vec3 {
    let Some(sample) = lights.sample_direct(scene, hit, rng) else {
        return Vec3::ZERO;
    };
    let f = bsdf.eval(wo, sample.wi);
    if f == Vec3::ZERO {
        return Vec3::ZERO;
    }
    let cos = bsdf.normal().dot(sample.wi).abs();
    let weight = if mis && sample.pdf > 0.0 {
        power_heuristic(sample.pdf, bsdf.pdf(wo, sample.wi))
    } else {
        1.0
    };
    f * sample.contribution * (cos * weight)
}

/// Emitted radiance of a surface towards any direction (two-sided).
#[inline]
pub fn emitted(hit: &SurfaceHit) -> Vec3 {
    hit.params.emissive.max(Vec3::ZERO)
}

/// Follows a camera ray through mirrors and glass, adding the emission it meets. At each smooth
/// surface it adds `beta · at_smooth(hit, bsdf, wo, path length)`; where the surface's BSDF then
/// samples a smooth lobe the chain ends with `beta · beyond(hit, sample, path length)` (nothing
/// for photon mapping, a final gather for Jensen's method). With `through_specular` off, a
/// camera ray that meets a mirror or glass first stops there.
#[allow(clippy::too_many_arguments)]
pub fn camera_chain<S, B>(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    through_specular: bool,
    rng: &mut Rng,
    mut at_smooth: S,
    mut beyond: B,
) -> Vec3
where
    S: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, &mut Rng) -> Vec3,
    B: FnMut(&SurfaceHit, &BsdfSample, f32, &mut Rng) -> Vec3,
{
    let mut ray = ray;
    let mut beta = Vec3::ONE;
    let mut l = Vec3::ZERO;
    let mut path_length = 0.0f32;
    for depth in 0..=max_depth {
        let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
            break;
        };
        let hit = scene.surface(&ray, &isect);
        path_length += isect.t;
        let wo = -ray.dir;
        // Only the camera and specular chains reach here: emission counts in full.
        l += beta * emitted(&hit);
        let bsdf = Bsdf::new(&hit.params, hit.shading_normal, hit.geometric_normal, wo);
        if bsdf.is_black() {
            break;
        }
        if bsdf.is_smooth() {
            l += beta * at_smooth(&hit, &bsdf, wo, path_length, rng);
        }
        if depth == max_depth {
            break;
        }
        let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) else {
            break;
        };
        if !sample.specular {
            l += beta * beyond(&hit, &sample, path_length, rng);
            break;
        }
        if depth == 0 && !through_specular {
            break;
        }
        beta *= sample.weight;
        ray = Ray::new(offset_origin(hit.point, hit.geometric_normal, sample.wi), sample.wi);
    }
    l
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::build::test_scene as scene;

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
            let lights = Lights::new(&s);
            assert_eq!(lights.area[0].outward_only, outward, "{objects}");
            let mut rng = Rng::new(3, 0);
            let n = 100_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                if let Some(p) = lights.emit(&s, &mut rng) {
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
}
