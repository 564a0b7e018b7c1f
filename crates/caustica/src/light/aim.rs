//! Aiming light at the mirrors and glass that make caustics: their bounding spheres
//! ([`Target`]) and the mixture of cones towards them that a share of emitted light, or of a
//! light subpath's diffuse bounces, follows ([`Aim`]). Every density is the mixture's, so
//! aiming changes where samples go, never the expected image.

use crate::math::{Aabb, Ray, Vec2, Vec3};
use crate::sampling::{sample_uniform_cone, uniform_cone_pdf};
use crate::scene::{ObjectRef, Scene};
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

    /// The sphere of `radius` about (x, y, z), for tests.
    #[cfg(test)]
    pub(crate) fn at(x: f32, y: f32, z: f32, radius: f32) -> Target {
        Target {
            center: Vec3::new(x, y, z),
            radius,
        }
    }

    /// The sphere around a box (slightly enlarged so grazing paths are not lost).
    pub fn around(bounds: &Aabb) -> Target {
        Target {
            center: bounds.center(),
            radius: 0.5 * bounds.extent().length() * 1.001 + 1e-4,
        }
    }
}

/// Where a share of the light subpaths is aimed: cones from the light point towards the
/// targets, each chosen in proportion to its solid angle.
#[derive(Clone, Debug)]
pub struct Aim {
    targets: Vec<Target>,
    /// The share of subpaths aimed (the rest leave as without aiming).
    share: f32,
}

/// More targets than this are aimed at as one sphere around them all: every density
/// evaluation visits each target.
pub const MAX_TARGETS: usize = 8;

/// A sphere around all of `targets` (not empty).
pub(crate) fn enclosing(targets: &[Target]) -> Target {
    let center = targets.iter().map(|t| t.center).sum::<Vec3>() / targets.len() as f32;
    let radius = targets
        .iter()
        .map(|t| (t.center - center).length() + t.radius)
        .fold(0.0, f32::max);
    Target { center, radius }
}

impl Aim {
    /// Aiming `share` of the subpaths at `targets` (`None` when there is nothing to aim at).
    pub fn new(targets: &[Target], share: f32) -> Option<Aim> {
        if targets.is_empty() || !(share > 0.0 && share <= 1.0) {
            return None;
        }
        let targets = if targets.len() <= MAX_TARGETS {
            targets.to_vec()
        } else {
            vec![enclosing(targets)]
        };
        Some(Aim { targets, share })
    }

    /// Aiming `share` at each of `targets`, however many (`None` when there is nothing to
    /// aim at): for emission alone, whose density is evaluated once per sample.
    pub fn every(targets: &[Target], share: f32) -> Option<Aim> {
        if targets.is_empty() || !(share > 0.0 && share <= 1.0) {
            return None;
        }
        Some(Aim {
            targets: targets.to_vec(),
            share,
        })
    }

    /// The share of samples aimed.
    pub fn share(&self) -> f32 {
        self.share
    }

    /// The spheres aimed at.
    pub fn targets(&self) -> &[Target] {
        &self.targets
    }

    /// A target, chosen in proportion to the solid angle it subtends from `from` (`None`: none
    /// subtends any).
    fn pick(&self, from: Vec3, u_pick: f32) -> Option<&Target> {
        let total: f32 = self.targets.iter().map(|t| 1.0 - t.cone_from(from).1).sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let mut x = u_pick * total;
        for (i, t) in self.targets.iter().enumerate() {
            let w = 1.0 - t.cone_from(from).1;
            if x < w || i + 1 == self.targets.len() {
                return Some(t);
            }
            x -= w;
        }
        None
    }

    /// A direction from `from` into one of the cones (`None`: they have no solid angle).
    pub fn sample(&self, from: Vec3, u_pick: f32, u: Vec2) -> Option<Vec3> {
        let (axis, cos_max) = self.pick(from, u_pick)?.cone_from(from);
        Some(sample_uniform_cone(u, axis, cos_max))
    }

    /// The solid-angle density of [`Aim::sample`] at `dir`: each cone holding `dir` adds
    /// its share 1/(2π Σ(1 − cos)) (its weight over its own solid angle).
    pub fn pdf(&self, from: Vec3, dir: Vec3) -> f32 {
        let (mut total, mut inside) = (0.0, 0u32);
        for t in &self.targets {
            let (axis, cos_max) = t.cone_from(from);
            total += 1.0 - cos_max;
            if dir.dot(axis) >= cos_max {
                inside += 1;
            }
        }
        if total > 0.0 {
            inside as f32 / (2.0 * PI * total)
        } else {
            0.0
        }
    }

    /// The targets as a sphere lamp (centre, radius) aims at them ([`LampAim`]).
    pub(crate) fn seen_from_lamp(&self, center: Vec3, radius: f32) -> LampAim {
        let cones: Vec<(Target, Vec3, f32)> = self
            .targets
            .iter()
            .map(|t| {
                let (facing, cos) = t.cone_from(center);
                (*t, facing, 1.0 - cos)
            })
            .collect();
        LampAim {
            center,
            radius,
            total: cones.iter().map(|c| c.2).sum(),
            cones,
        }
    }
}

/// An aim's targets seen from a sphere lamp's centre, worked out once per lamp: each aimed start
/// and each density of one reads them (they took a third of a sphere lamp's emission).
#[derive(Clone, Debug)]
pub(crate) struct LampAim {
    center: Vec3,
    radius: f32,
    /// Each target, the axis towards it from the centre and its weight: the solid angle it
    /// subtends there over 2π.
    cones: Vec<(Target, Vec3, f32)>,
    /// The weights' sum.
    total: f32,
}

impl LampAim {
    /// Whether some target subtends a solid angle from the lamp.
    fn aims(&self) -> bool {
        !self.total.is_nan() && self.total > 0.0
    }

    /// An aimed start from a point drawn uniformly on the lamp (`normal`, its unit normal): a
    /// target by its solid angle from the centre, the point mirrored onto the half of the lamp
    /// facing that target, then a direction in the target's cone from it. Drawn anywhere on
    /// the lamp, half the aimed starts would face away from their target. Returns the start's
    /// normal and direction.
    pub(crate) fn sample(&self, normal: Vec3, u_pick: f32, u: Vec2) -> Option<(Vec3, Vec3)> {
        if !self.aims() {
            return None;
        }
        let mut x = u_pick * self.total;
        let last = self.cones.len() - 1;
        let (target, facing, _) = self
            .cones
            .iter()
            .enumerate()
            .find(|&(i, &(_, _, w))| {
                let found = x < w || i == last;
                x -= w;
                found
            })?
            .1;
        let along = normal.dot(*facing);
        let normal = if along < 0.0 {
            normal - 2.0 * along * *facing
        } else {
            normal
        };
        let (axis, cos_max) = target.cone_from(self.center + normal * self.radius);
        Some((normal, sample_uniform_cone(u, axis, cos_max)))
    }

    /// The density (area × solid angle) of [`LampAim::sample`]'s start at the lamp's point
    /// `point`, leaving in `dir`.
    pub(crate) fn pdf(&self, point: Vec3, dir: Vec3) -> f32 {
        if !self.aims() {
            return 0.0;
        }
        // From the point, not a caller's normal (which may face either way).
        let normal = point - self.center;
        let half_area = 2.0 * PI * self.radius * self.radius;
        let mut pdf = 0.0;
        for (t, facing, weight) in &self.cones {
            if normal.dot(*facing) < 0.0 {
                continue;
            }
            let (axis, cos_max) = t.cone_from(point);
            if dir.dot(axis) >= cos_max {
                pdf += weight / self.total * uniform_cone_pdf(cos_max) / half_area;
            }
        }
        pdf
    }

    /// The area density over the lamp of [`LampAim::sample`]'s start point `point`: each
    /// target's share on the half of the lamp that faces it.
    pub(crate) fn point_pdf(&self, point: Vec3) -> f32 {
        if !self.aims() {
            return 0.0;
        }
        let half_area = 2.0 * PI * self.radius * self.radius;
        self.cones
            .iter()
            .filter(|(_, facing, _)| (point - self.center).dot(*facing) >= 0.0)
            .map(|(_, _, weight)| weight / self.total / half_area)
            .sum()
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{sample_uniform_sphere, uniform_sphere_pdf, Rng};

    #[test]
    fn aimed_density_integrates_to_one_over_the_sphere() {
        // Two overlapping cones and one apart, seen from the origin.
        let aim = Aim::new(
            &[
                Target::at(0.0, 0.0, -2.0, 0.5),
                Target::at(0.3, 0.0, -2.0, 0.4),
                Target::at(2.0, 1.0, 0.0, 0.3),
            ],
            1.0,
        )
        .unwrap();
        let mut rng = Rng::new(7, 0);
        let n = 400_000;
        let mean: f64 = (0..n)
            .map(|_| aim.pdf(Vec3::ZERO, sample_uniform_sphere(rng.uniform2())) as f64)
            .sum::<f64>()
            / n as f64;
        let integral = mean * 4.0 * std::f64::consts::PI;
        assert!((integral - 1.0).abs() < 0.01, "∫ pdf dω = {integral}");
    }

    #[test]
    fn aimed_samples_follow_their_density() {
        // Apart cones: E[1 / pdf] over the samples is the solid angle they cover, Σ 2π(1 − cos).
        let targets = [
            Target::at(0.0, 0.0, -2.0, 0.5),
            Target::at(2.0, 1.0, 0.0, 0.3),
            Target::at(0.0, 3.0, 0.0, 0.2),
        ];
        let aim = Aim::new(&targets, 1.0).unwrap();
        let from = Vec3::new(0.1, -0.2, 0.3);
        let exact: f32 = targets.iter().map(|t| 2.0 * PI * (1.0 - t.cone_from(from).1)).sum();
        let mut rng = Rng::new(11, 0);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let dir = aim.sample(from, rng.uniform(), rng.uniform2()).unwrap();
            let pdf = aim.pdf(from, dir);
            assert!(pdf > 0.0, "a sample outside every cone: {dir:?}");
            sum += 1.0 / pdf as f64;
        }
        let estimate = sum / n as f64;
        assert!((estimate / exact as f64 - 1.0).abs() < 0.01, "{estimate} vs {exact}");
    }

    /// A sphere lamp of radius 0.5 at the origin and two targets in different directions.
    fn lamp_aim() -> (LampAim, f32) {
        let aim = Aim::new(&[Target::at(0.0, -3.0, 0.0, 1.0), Target::at(2.5, -2.0, 0.5, 0.8)], 1.0).unwrap();
        (aim.seen_from_lamp(Vec3::ZERO, 0.5), 0.5)
    }

    #[test]
    fn aimed_sphere_lamp_density_integrates_to_one() {
        // Over the lamp's area and every direction: E[pdf] over uniform points and directions
        // times 4πr² · 4π.
        let (aim, radius) = lamp_aim();
        let mut rng = Rng::new(5, 0);
        let n = 1_000_000;
        let mean: f64 = (0..n)
            .map(|_| {
                let point = sample_uniform_sphere(rng.uniform2()) * radius;
                aim.pdf(point, sample_uniform_sphere(rng.uniform2())) as f64
            })
            .sum::<f64>()
            / n as f64;
        let measure = 4.0 * std::f64::consts::PI * (radius * radius) as f64 * 4.0 * std::f64::consts::PI;
        let integral = mean * measure;
        assert!((integral - 1.0).abs() < 0.02, "∫∫ pdf dA dω = {integral}");
    }

    #[test]
    fn aimed_sphere_lamp_starts_follow_their_density() {
        // E[q / pdf] over the aimed starts, q the uniform density over the lamp's points and
        // directions, is the share of all (point, direction) pairs the aiming can draw, which
        // uniform pairs estimate independently. Only starts near the rim of the half facing
        // the target can leave inwards (17% with these wide cones), against about half when
        // drawn anywhere on the lamp.
        let (aim, radius) = lamp_aim();
        let q = 1.0 / (4.0 * PI * radius * radius * 4.0 * PI);
        let mut rng = Rng::new(9, 0);
        let n = 400_000;
        let (mut sum, mut inwards) = (0.0f64, 0);
        for _ in 0..n {
            let uniform = sample_uniform_sphere(rng.uniform2());
            let (normal, dir) = aim.sample(uniform, rng.uniform(), rng.uniform2()).unwrap();
            inwards += (dir.dot(normal) <= 0.0) as usize;
            let pdf = aim.pdf(normal * radius, dir);
            assert!(pdf > 0.0, "a start the density says cannot be drawn");
            sum += (q / pdf) as f64;
        }
        let drawn_share = sum / n as f64;
        let m = 2_000_000;
        let reachable = (0..m)
            .filter(|_| {
                let point = sample_uniform_sphere(rng.uniform2()) * radius;
                aim.pdf(point, sample_uniform_sphere(rng.uniform2())) > 0.0
            })
            .count() as f64
            / m as f64;
        assert!(
            (drawn_share / reachable - 1.0).abs() < 0.03,
            "{drawn_share} vs {reachable}"
        );
        let inwards = inwards as f64 / n as f64;
        assert!(inwards < 0.25, "{inwards} of the aimed starts leave inwards");
    }

    #[test]
    fn from_inside_a_target_every_direction_is_aimed() {
        let aim = Aim::new(&[Target::at(0.0, 0.0, 0.0, 1.0)], 1.0).unwrap();
        let pdf = aim.pdf(Vec3::new(0.1, 0.0, 0.0), Vec3::X);
        assert!((pdf - uniform_sphere_pdf()).abs() < 1e-6, "{pdf}");
    }

    #[test]
    fn many_targets_become_one_around_them_all() {
        let targets: Vec<Target> = (0..20).map(|i| Target::at(i as f32, 0.0, -5.0, 0.25)).collect();
        let aim = Aim::new(&targets, 0.5).unwrap();
        assert_eq!(aim.targets.len(), 1);
        let all = aim.targets[0];
        for t in &targets {
            assert!((t.center - all.center).length() + t.radius <= all.radius * 1.0001);
        }
        assert!(Aim::new(&[], 0.5).is_none() && Aim::new(&targets, 0.0).is_none());
    }
}
