//! Light from the sky around the scene: a constant radiance, optionally times an image in
//! latitude–longitude layout, importance-sampled by its luminance.
//!
//! The image's axis is +y in its own frame: v = 0 (the top row) looks straight up, v = 1
//! straight down, and u runs once around with the image's centre (u = 0.5, v = 0.5) looking
//! down −z — the default camera's view — and u = 0.75 towards +x. `rotation` turns that frame
//! into the world's.

use crate::math::{luminance, Mat3, Vec2, Vec3};
use crate::sampling::{sample_uniform_sphere, uniform_sphere_pdf, Distribution2D};
use crate::texture::Texture;
use std::f32::consts::PI;

/// The environment: radiance `color` × the map (1 without a map) in each direction.
#[derive(Clone, Debug)]
pub struct Environment {
    /// Radiance scale.
    pub color: Vec3,
    map: Option<Map>,
    world_from_map: Mat3,
    map_from_world: Mat3,
}

#[derive(Clone, Debug)]
struct Map {
    texture: Texture,
    /// Texels weighted by luminance × sin θ (their solid angle), rows from the top.
    distribution: Distribution2D,
    /// ∫ luminance(map) dω.
    luminance_integral: f32,
}

/// A direction drawn towards the environment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EnvironmentSample {
    /// Unit world direction towards the sky.
    pub wi: Vec3,
    /// Radiance arriving from it.
    pub radiance: Vec3,
    /// Solid-angle pdf.
    pub pdf: f32,
}

impl Environment {
    /// The environment of radiance `color` × `map` with the map's frame turned by `rotation`
    /// (a rotation matrix, world from map).
    pub fn new(color: Vec3, map: Option<Texture>, rotation: Mat3) -> Environment {
        let map = map.map(|texture| {
            let (w, h) = (texture.width(), texture.height());
            let mut weights = Vec::with_capacity(w * h);
            let mut integral = 0.0f64;
            let texel_solid_angle = |row: usize| {
                let theta = (row as f32 + 0.5) / h as f32 * PI;
                theta.sin() * (2.0 * PI / w as f32) * (PI / h as f32)
            };
            for row in 0..h {
                let sin_theta = ((row as f32 + 0.5) / h as f32 * PI).sin();
                for column in 0..w {
                    let l = luminance(texture.texel(column, row) * color).max(0.0);
                    weights.push(l * sin_theta);
                    integral += (l * texel_solid_angle(row)) as f64;
                }
            }
            Map {
                distribution: Distribution2D::new(&weights, w),
                texture,
                luminance_integral: integral as f32,
            }
        });
        Environment {
            color,
            map,
            world_from_map: rotation,
            map_from_world: rotation.transpose(),
        }
    }

    /// Whether an image modulates the radiance.
    pub fn has_map(&self) -> bool {
        self.map.is_some()
    }

    /// Radiance arriving from the unit world direction `dir`.
    pub fn radiance(&self, dir: Vec3) -> Vec3 {
        match &self.map {
            None => self.color,
            Some(map) => {
                let uv = direction_to_uv(self.map_from_world * dir);
                self.color * texel_at(&map.texture, uv)
            }
        }
    }

    /// ∫ luminance(L) dω over the sphere: the irradiance-like quantity that sets its power.
    pub fn luminance_integral(&self) -> f32 {
        match &self.map {
            None => 4.0 * PI * luminance(self.color).max(0.0),
            Some(map) => map.luminance_integral,
        }
    }

    /// A direction drawn in proportion to luminance × solid angle (uniform without a map).
    pub fn sample(&self, u: Vec2) -> Option<EnvironmentSample> {
        let Some(map) = &self.map else {
            let wi = sample_uniform_sphere(u);
            return Some(EnvironmentSample {
                wi,
                radiance: self.color,
                pdf: uniform_sphere_pdf(),
            });
        };
        let (uv, pdf_uv) = map.distribution.sample(u);
        let sin_theta = (uv.y * PI).sin();
        if pdf_uv <= 0.0 || sin_theta <= 0.0 {
            return None;
        }
        let wi = self.world_from_map * uv_to_direction(uv);
        Some(EnvironmentSample {
            wi,
            radiance: self.color * texel_at(&map.texture, uv),
            pdf: pdf_uv / (2.0 * PI * PI * sin_theta),
        })
    }

    /// The solid-angle pdf with which [`Environment::sample`] draws the unit world direction `dir`.
    pub fn pdf(&self, dir: Vec3) -> f32 {
        let Some(map) = &self.map else {
            return uniform_sphere_pdf();
        };
        let uv = direction_to_uv(self.map_from_world * dir);
        let sin_theta = (uv.y * PI).sin();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        map.distribution.pdf(uv) / (2.0 * PI * PI * sin_theta)
    }
}

/// The texel containing `uv` (nearest: the importance sampling is piecewise constant on texels,
/// so the radiance must be too).
fn texel_at(texture: &Texture, uv: Vec2) -> Vec3 {
    let x = ((uv.x * texture.width() as f32) as usize).min(texture.width() - 1);
    let y = ((uv.y * texture.height() as f32) as usize).min(texture.height() - 1);
    texture.texel(x, y)
}

/// Latitude–longitude coordinates of a unit direction in the map's frame (v from the top).
pub fn direction_to_uv(d: Vec3) -> Vec2 {
    let theta = d.y.clamp(-1.0, 1.0).acos();
    let phi = d.x.atan2(-d.z);
    let u = (0.5 + phi / (2.0 * PI)).rem_euclid(1.0);
    Vec2::new(u, theta / PI)
}

/// The unit direction in the map's frame at latitude–longitude coordinates `uv`.
pub fn uv_to_direction(uv: Vec2) -> Vec3 {
    let phi = (uv.x - 0.5) * 2.0 * PI;
    let theta = uv.y * PI;
    let (sin_t, cos_t) = theta.sin_cos();
    let (sin_p, cos_p) = phi.sin_cos();
    Vec3::new(sin_t * sin_p, cos_t, -sin_t * cos_p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn map(w: usize, h: usize, f: impl Fn(usize, usize) -> Vec3) -> Texture {
        let texels = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        Texture::new(w, h, texels).unwrap()
    }

    #[test]
    fn the_layout_looks_down_minus_z_at_the_centre() {
        assert!((uv_to_direction(Vec2::new(0.5, 0.5)) - -Vec3::Z).length() < 1e-6);
        assert!((uv_to_direction(Vec2::new(0.75, 0.5)) - Vec3::X).length() < 1e-6);
        assert!((uv_to_direction(Vec2::new(0.3, 0.0)) - Vec3::Y).length() < 1e-6);
        for d in [Vec3::new(0.3, 0.4, -0.866), Vec3::new(-0.6, -0.2, 0.77), Vec3::X] {
            let d = d.normalize();
            assert!((uv_to_direction(direction_to_uv(d)) - d).length() < 1e-5, "{d}");
        }
    }

    /// Σ L/pdf over sampled directions estimates ∫ L dω, which the environment also reports; the
    /// pdf it gives back for a sampled direction is the one it sampled with.
    #[test]
    fn sampling_integrates_the_sky() {
        // A dim sky with a bright patch, turned a quarter around y.
        let texture = map(64, 32, |x, y| {
            if (10..14).contains(&x) && (8..11).contains(&y) {
                Vec3::new(40.0, 30.0, 20.0)
            } else {
                Vec3::splat(0.2)
            }
        });
        let rotation = Mat3::from_rotation_y(0.5 * PI);
        let env = Environment::new(Vec3::new(1.0, 0.9, 0.8), Some(texture), rotation);
        let mut rng = Rng::new(2, 0);
        let n = 200_000;
        let mut sum = 0.0f64;
        // A direction drawn within a hair of a texel's edge may map back to its neighbour.
        let mut disagree = 0;
        for _ in 0..n {
            let Some(s) = env.sample(rng.uniform2()) else { continue };
            let same_pdf = (env.pdf(s.wi) - s.pdf).abs() <= 2e-3 * s.pdf;
            let same_radiance = (env.radiance(s.wi) - s.radiance).length() <= 1e-4 * s.radiance.length();
            disagree += usize::from(!(same_pdf && same_radiance));
            sum += (luminance(s.radiance) / s.pdf) as f64;
        }
        assert!(
            disagree < n / 2000,
            "{disagree} of {n} samples disagree with pdf() or radiance()"
        );
        let estimate = sum / n as f64;
        assert!(
            (estimate / env.luminance_integral() as f64 - 1.0).abs() < 0.01,
            "{estimate} vs {}",
            env.luminance_integral()
        );
        // Uniform sampling of the sphere gives the same integral.
        let mut sum = 0.0f64;
        for _ in 0..n {
            let d = sample_uniform_sphere(rng.uniform2());
            sum += (luminance(env.radiance(d)) / uniform_sphere_pdf()) as f64;
        }
        assert!((sum / n as f64 / env.luminance_integral() as f64 - 1.0).abs() < 0.03);
    }
}
