//! The beam of a far light (a directional light, a sun, the sky in one of its directions):
//! emission starts on a plane across it outside the scene, so its densities are per unit area
//! across the beam, with no distance to the first vertex.

use super::aim::Target;
use crate::math::{Frame, Vec2, Vec3};
use crate::sampling::sample_uniform_disc;
use std::f32::consts::PI;

/// Where a directional light's or sun's subpaths start: a plane across the beam outside the
/// scene, a point on it from a mixture of discs (the scene's, and each target's as the beam
/// sees it, by area), then a direction along the beam (a sun's: uniform in its cone).
#[derive(Clone, Debug)]
pub struct Beam {
    /// Unit travel direction of the beam's centre.
    pub(crate) direction: Vec3,
    frame: Frame,
    plane_origin: Vec3,
    /// The scene's disc, centred on the plane's origin.
    scene_radius: f32,
    /// The targets' discs on the plane.
    targets: Vec<(Vec2, f32)>,
    /// π Σ r² over the targets.
    target_area: f32,
    /// The share of starts on the targets' discs (0 without targets).
    share: f32,
    /// A sun's cone: cos θ and 1 − cos θ of its angular radius.
    pub(crate) sun: Option<(f32, f32)>,
}

impl Beam {
    /// The beam of a light travelling in `direction` (a sun's centre; `sun`: its cone) across
    /// the scene's sphere (`center`, `radius`), `share` of it aimed at `targets`.
    pub fn new(
        direction: Vec3,
        sun: Option<(f32, f32)>,
        (center, radius): (Vec3, f32),
        targets: &[Target],
        share: f32,
    ) -> Beam {
        let frame = Frame::from_normal(direction);
        let plane_origin = center - direction * (radius * 2.0 + 1.0);
        // A sun's subpaths lean by up to its angular radius: each disc widens so that every
        // leaning ray that can reach its sphere starts inside it.
        let lean = sun.map_or(0.0, |(cos_max, _)| (1.0 - cos_max * cos_max).max(0.0).sqrt() / cos_max);
        let disc = |t: &Target| {
            let local = frame.to_local(t.center - plane_origin);
            (
                Vec2::new(local.x, local.y),
                t.radius + (local.z.max(0.0) + t.radius) * lean,
            )
        };
        let scene_radius = disc(&Target { center, radius }).1;
        let discs: Vec<(Vec2, f32)> = targets.iter().map(disc).collect();
        let target_area: f32 = discs.iter().map(|(_, r)| PI * r * r).sum();
        let share = if target_area > 0.0 { share.clamp(0.0, 1.0) } else { 0.0 };
        Beam {
            direction,
            frame,
            plane_origin,
            scene_radius,
            targets: discs,
            target_area,
            share,
            sun,
        }
    }

    /// A start on the plane: the point and its area density there.
    pub(crate) fn sample(&self, u_lobe: f32, u_pick: f32, u: Vec2) -> Option<(Vec3, f32)> {
        let (center, radius) = if u_lobe < self.share {
            let mut x = u_pick * self.target_area;
            let mut chosen = *self.discs().last()?;
            for &(c, r) in self.discs() {
                let a = PI * r * r;
                if x < a {
                    chosen = (c, r);
                    break;
                }
                x -= a;
            }
            chosen
        } else {
            (Vec2::ZERO, self.scene_radius)
        };
        let p = center + sample_uniform_disc(u) * radius;
        let pdf = self.plane_pdf(p);
        (pdf > 0.0).then(|| (self.plane_origin + self.frame.x * p.x + self.frame.y * p.y, pdf))
    }

    /// The targets' discs on the plane.
    fn discs(&self) -> &[(Vec2, f32)] {
        &self.targets
    }

    /// Area density of a start at `p` on the plane (the mixture's).
    fn plane_pdf(&self, p: Vec2) -> f32 {
        let inside = |c: Vec2, r: f32| (p - c).length_squared() <= r * r * (1.0 + 1e-5);
        let mut pdf = 0.0;
        if inside(Vec2::ZERO, self.scene_radius) {
            pdf += (1.0 - self.share) / (PI * self.scene_radius * self.scene_radius);
        }
        if self.share > 0.0 {
            let count = self.discs().iter().filter(|&&(c, r)| inside(c, r)).count();
            pdf += self.share * count as f32 / self.target_area;
        }
        pdf
    }

    /// Density, per unit area across the ray, of a start whose ray travels in `dir` through
    /// `point`: the plane's density where that ray leaves it, over the cosine of its lean.
    pub(crate) fn across_pdf(&self, point: Vec3, dir: Vec3) -> f32 {
        let lean = dir.dot(self.direction);
        if lean.is_nan() || lean <= 0.0 {
            return 0.0;
        }
        let back = (point - self.plane_origin).dot(self.direction) / lean;
        let local = self.frame.to_local(point - dir * back - self.plane_origin);
        self.plane_pdf(Vec2::new(local.x, local.y)) / lean
    }

    /// Solid-angle density of a direction within a sun's cone (1 for a directional light,
    /// whose one direction is a delta).
    pub(crate) fn direction_pdf(&self) -> f32 {
        self.sun
            .map_or(1.0, |(_, one_minus_cos)| 1.0 / (2.0 * PI * one_minus_cos))
    }

    /// Whether `dir` (travelling) lies in the beam: a sun's cone (a directional light's never).
    pub(crate) fn holds(&self, dir: Vec3) -> bool {
        self.sun.is_some_and(|(cos_max, _)| dir.dot(self.direction) >= cos_max)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::{sample_uniform_cone, Rng};

    /// A sun's beam 3° across, a third aimed at two targets, over a scene of radius 4.
    fn sun_beam() -> Beam {
        let cos_max = (1.5f32).to_radians().cos();
        Beam::new(
            Vec3::new(-1.2, -1.5, 0.3).normalize(),
            Some((cos_max, 1.0 - cos_max)),
            (Vec3::ZERO, 4.0),
            &[Target::at(0.0, 0.5, 0.0, 0.5), Target::at(1.0, 0.3, 1.0, 0.3)],
            1.0 / 3.0,
        )
    }

    #[test]
    fn beam_density_integrates_to_one_over_its_plane() {
        let beam = sun_beam();
        // The scene's disc holds the targets' discs: uniform points over its bounding square.
        let half = beam.scene_radius;
        let mut rng = Rng::new(3, 0);
        let n = 1_000_000;
        let mean: f64 = (0..n)
            .map(|_| {
                let u = rng.uniform2();
                beam.plane_pdf(Vec2::new((2.0 * u.x - 1.0) * half, (2.0 * u.y - 1.0) * half)) as f64
            })
            .sum::<f64>()
            / n as f64;
        let integral = mean * (2.0 * half as f64).powi(2);
        assert!((integral - 1.0).abs() < 0.01, "∫ pdf dA = {integral}");
    }

    #[test]
    fn beam_starts_carry_their_density_along_the_ray() {
        // The density across the ray, read anywhere along it, is the start's on the plane
        // over the cosine of its lean; the aimed share lands on the targets' discs.
        let beam = sun_beam();
        let mut rng = Rng::new(4, 0);
        let mut on_targets = 0;
        let n = 20_000;
        for _ in 0..n {
            let (origin, pdf) = beam.sample(rng.uniform(), rng.uniform(), rng.uniform2()).unwrap();
            let (cos_max, _) = beam.sun.unwrap();
            let dir = sample_uniform_cone(rng.uniform2(), beam.direction, cos_max);
            let along = beam.across_pdf(origin + dir * (3.0 + 6.0 * rng.uniform()), dir);
            let expected = pdf / dir.dot(beam.direction);
            assert!((along / expected - 1.0).abs() < 1e-3, "{along} vs {expected}");
            let local = beam.frame.to_local(origin - beam.plane_origin);
            let p = Vec2::new(local.x, local.y);
            on_targets += beam.discs().iter().any(|&(c, r)| (p - c).length_squared() <= r * r) as usize;
        }
        // A third aimed, plus the uniform starts that fall on the targets' discs anyway.
        let share = on_targets as f64 / n as f64;
        let area_share = (beam.target_area / (PI * beam.scene_radius * beam.scene_radius)) as f64;
        let expected = 1.0 / 3.0 + 2.0 / 3.0 * area_share;
        assert!((share - expected).abs() < 0.02, "{share} vs {expected}");
    }
}
