//! Photon emission from point and directional lights, aimed or uniform.
//!
//! Aimed emission sends photons only towards the bounding spheres of objects that can make
//! caustics. Point lights sample a mixture of cones (one per target, weighted by solid angle);
//! directional lights sample a mixture of discs on a plane across the beam (one per target,
//! weighted by area). Each photon carries the light's intensity (or irradiance) divided by the
//! mixture pdf actually used, so aiming changes the noise, never the expected power.

use crate::light::Light;
use crate::math::{luminance, Aabb, Frame, Ray, Vec2, Vec3};
use crate::sampling::{sample_uniform_cone, sample_uniform_disc, Rng};
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

#[derive(Clone, Debug)]
enum Kind {
    Point {
        position: Vec3,
        cones: Vec<ConeLobe>,
    },
    Directional {
        direction: Vec3,
        frame: Frame,
        plane_origin: Vec3,
        discs: Vec<DiscLobe>,
    },
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

impl Emitter {
    /// The emitter of `light`, aimed at `targets` (or uniform over the scene when `targets` is
    /// `None`). `None` when the light cannot send a photon anywhere useful.
    pub fn new(light: &Light, targets: Option<&[Target]>, scene_bounds: &Aabb) -> Option<Emitter> {
        let scene = Target::around(scene_bounds);
        match *light {
            Light::Point { position, color, .. } => {
                let cones: Vec<ConeLobe> = match targets {
                    None => vec![ConeLobe {
                        axis: Vec3::Z,
                        cos_max: -1.0,
                    }],
                    Some(ts) => ts.iter().map(|t| cone_towards(position, t)).collect(),
                };
                let weights: Vec<f32> = cones.iter().map(|c| 1.0 - c.cos_max).collect();
                Emitter::finish(
                    Kind::Point { position, cones },
                    color,
                    weights,
                    4.0 * PI * luminance(color).max(0.0),
                )
            }
            Light::Directional { direction, color } => {
                let frame = Frame::from_normal(direction);
                let plane_origin = scene.center - direction * (scene.radius * 2.0 + 1.0);
                let to_disc = |t: &Target| {
                    let local = frame.to_local(t.center - plane_origin);
                    DiscLobe {
                        center: Vec2::new(local.x, local.y),
                        radius: t.radius,
                    }
                };
                let discs: Vec<DiscLobe> = match targets {
                    None => vec![to_disc(&scene)],
                    Some(ts) => ts.iter().map(to_disc).collect(),
                };
                let weights: Vec<f32> = discs.iter().map(|d| d.radius * d.radius).collect();
                let power = luminance(color).max(0.0) * PI * scene.radius * scene.radius;
                Emitter::finish(
                    Kind::Directional {
                        direction,
                        frame,
                        plane_origin,
                        discs,
                    },
                    color,
                    weights,
                    power,
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

    /// A photon ray and its power before division by the number of photons emitted.
    pub fn sample(&self, rng: &mut Rng) -> Option<(Ray, Vec3)> {
        let lobe = self.pick(rng.uniform());
        let u = rng.uniform2();
        match &self.kind {
            Kind::Point { position, cones } => {
                let dir = sample_uniform_cone(u, cones[lobe].axis, cones[lobe].cos_max);
                let pdf = self.cone_pdf(cones, dir);
                (pdf > 0.0).then(|| (Ray::new(*position, dir), self.color / pdf))
            }
            Kind::Directional {
                direction,
                frame,
                plane_origin,
                discs,
            } => {
                let disc = &discs[lobe];
                let p = disc.center + sample_uniform_disc(u) * disc.radius;
                let pdf = self.disc_pdf(discs, p);
                let origin = *plane_origin + frame.x * p.x + frame.y * p.y;
                (pdf > 0.0).then(|| (Ray::new(origin, *direction), self.color / pdf))
            }
        }
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
    let to = target.center - position;
    let d2 = to.length_squared();
    let r2 = target.radius * target.radius;
    if d2 <= r2 * 1.0001 {
        // The light is inside the target: every direction may reach it.
        return ConeLobe {
            axis: Vec3::Z,
            cos_max: -1.0,
        };
    }
    ConeLobe {
        axis: to / d2.sqrt(),
        cos_max: (1.0 - r2 / d2).max(0.0).sqrt(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
        for aimed in [true, false] {
            let e = Emitter::new(&light, aimed.then_some(&targets[..]), &bounds()).unwrap();
            let mut rng = Rng::new(1, 0);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let (ray, power) = e.sample(&mut rng).unwrap();
                let to = target.center - ray.origin;
                if ray.dir.dot(to.normalize()) >= cos_max {
                    sum += power.x as f64;
                }
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.02,
                "aimed {aimed}: {estimate} vs {exact}"
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
        for aimed in [true, false] {
            let small = Aabb::new(Vec3::splat(-3.0), Vec3::splat(3.0));
            let e = Emitter::new(&light, aimed.then_some(&targets[..]), &small).unwrap();
            let mut rng = Rng::new(2, 0);
            let n = 2_000_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let (ray, power) = e.sample(&mut rng).unwrap();
                let p = ray.origin;
                if p.x * p.x + p.y * p.y <= 1.0 {
                    sum += power.x as f64;
                }
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.02,
                "aimed {aimed}: {estimate} vs {exact}"
            );
        }
    }
}
