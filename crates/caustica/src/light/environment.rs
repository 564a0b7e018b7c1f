//! Light from the sky around the scene: a constant radiance, optionally times an image in
//! latitude–longitude layout, importance-sampled by its luminance.
//!
//! The image's axis is +y in its own frame: v = 0 (the top row) looks straight up, v = 1
//! straight down, and u runs once around with the image's centre (u = 0.5, v = 0.5) looking
//! down −z — the default camera's view — and u = 0.75 towards +x. `rotation` turns that frame
//! into the world's.

use super::emission::{Emission, EmitArgs, Emitters};
use super::{DirectQuery, DirectSample, Light};
use crate::math::Ray;
use crate::math::{luminance, Mat3, Vec2, Vec3};
use crate::sampling::Rng;
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

/// The direction in an equal-area octahedral square map's frame (+z up) at square coordinates
/// `uv` ∈ [0, 1]² (Clarberg's equal-area mapping, the layout of pbrt-v4's sky maps).
pub fn equal_area_square_to_direction(uv: Vec2) -> Vec3 {
    let (u, v) = (2.0 * uv.x - 1.0, 2.0 * uv.y - 1.0);
    let (up, vp) = (u.abs(), v.abs());
    let signed = 1.0 - (up + vp);
    let r = 1.0 - signed.abs();
    let phi = if r == 0.0 { 1.0 } else { (vp - up) / r + 1.0 } * PI / 4.0;
    let z = (1.0 - r * r).copysign(signed);
    let s = r * (2.0 - r * r).max(0.0).sqrt();
    Vec3::new(phi.cos().copysign(u) * s, phi.sin().copysign(v) * s, z)
}

/// The inverse of [`equal_area_square_to_direction`]: square coordinates of a unit direction.
pub fn direction_to_equal_area_square(d: Vec3) -> Vec2 {
    let r = (1.0 - d.z.abs().min(1.0)).sqrt();
    let phi = d.y.abs().atan2(d.x.abs());
    let diff = r * (4.0 * phi / PI - 1.0);
    let sum = if d.z >= 0.0 { r } else { 2.0 - r };
    let (vp, up) = ((sum + diff) * 0.5, (sum - diff) * 0.5);
    Vec2::new((up.copysign(d.x) + 1.0) * 0.5, (vp.copysign(d.y) + 1.0) * 0.5)
}

/// The frame turn from a latitude–longitude map's frame (+y up, centre towards −z) to an
/// equal-area map's (+z up, +x at the lat-long centre): what [`equal_area_to_lat_long`] resamples by.
pub fn equal_area_from_lat_long() -> Mat3 {
    Mat3::from_cols(
        Vec3::new(0.0, -1.0, 0.0),
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(-1.0, 0.0, 0.0),
    )
}

/// An equal-area octahedral square map resampled to latitude–longitude (twice as wide as
/// tall, as many rows as the square has), bilinearly, with rows from the top as stored.
pub fn equal_area_to_lat_long(square: &Texture) -> Texture {
    let n = square.width().max(square.height()).clamp(1, 8192);
    let (w, h) = (2 * n, n);
    let frame = equal_area_from_lat_long();
    let fetch = |x: f32, y: f32| {
        let (sw, sh) = (square.width(), square.height());
        let x = (x * sw as f32 - 0.5).clamp(0.0, (sw - 1) as f32);
        let y = (y * sh as f32 - 0.5).clamp(0.0, (sh - 1) as f32);
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(sw - 1), (y0 + 1).min(sh - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let top = square.texel(x0, y0).lerp(square.texel(x1, y0), fx);
        let bottom = square.texel(x0, y1).lerp(square.texel(x1, y1), fx);
        top.lerp(bottom, fy)
    };
    let mut texels = Vec::with_capacity(w * h);
    for row in 0..h {
        for column in 0..w {
            let uv = Vec2::new((column as f32 + 0.5) / w as f32, (row as f32 + 0.5) / h as f32);
            let st = direction_to_equal_area_square(frame * uv_to_direction(uv));
            texels.push(fetch(st.x, st.y));
        }
    }
    Texture::new(w, h, texels).expect("sizes match")
}

impl Environment {
    /// Next-event estimation's sample: a direction by the sky's own sampling, visibility
    /// included.
    pub(super) fn sample_direct(&self, q: &DirectQuery, u: Vec2) -> Option<DirectSample> {
        let s = self.sample(u)?;
        if s.radiance == Vec3::ZERO || !q.unoccluded(s.wi, f32::INFINITY) {
            return None;
        }
        let pdf = q.choice * s.pdf;
        Some(DirectSample {
            wi: s.wi,
            distance: f32::INFINITY,
            contribution: q.wl.unbounded(s.radiance) / pdf,
            pdf,
            direct_pdf: pdf,
            delta: false,
            point: q.hit.point + s.wi,
            normal: -s.wi,
            cos_light: 1.0,
        })
    }
}

impl Emitters {
    /// A start from the sky: a direction by its own sampling, then a point across that beam.
    pub(super) fn emit_sky(&self, light: &Light, args: EmitArgs, rng: &mut Rng) -> Option<Emission> {
        let (number, pick, u, u_dir, wl) = args.parts();
        match light {
            Light::Environment(env) => {
                // A direction by the sky's own sampling, then a start across that beam.
                let sky = env.sample(u_dir)?;
                let dir = -sky.wi;
                let (origin, plane_pdf) = self.sky_beam(dir).sample(rng.uniform(), rng.uniform(), u)?;
                let pdf = pick * sky.pdf * plane_pdf;
                (pdf > 0.0).then(|| Emission {
                    ray: Ray::new(origin, dir),
                    throughput: wl.unbounded(sky.radiance) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: false,
                    light: number,
                    normal: dir,
                    far: true,
                    origin: None,
                })
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn equal_area_mapping_round_trips_and_keeps_areas() {
        let mut rng = Rng::new(5, 0);
        for _ in 0..2000 {
            let d = sample_uniform_sphere(rng.uniform2());
            let back = equal_area_square_to_direction(direction_to_equal_area_square(d));
            assert!((back - d).length() < 1e-3, "{d:?} -> {back:?}");
        }
        // Equal area: uniform square points land uniformly on the sphere (mean z 0, mean z² 1/3).
        let (mut z, mut z2) = (0.0f64, 0.0f64);
        for _ in 0..20_000 {
            let d = equal_area_square_to_direction(rng.uniform2());
            z += d.z as f64;
            z2 += (d.z * d.z) as f64;
        }
        assert!((z / 20_000.0).abs() < 0.01 && (z2 / 20_000.0 - 1.0 / 3.0).abs() < 0.01);
        // The centre is +z, the corners −z.
        assert!((equal_area_square_to_direction(Vec2::splat(0.5)) - Vec3::Z).length() < 1e-6);
        assert!((equal_area_square_to_direction(Vec2::ZERO) + Vec3::Z).length() < 1e-6);
    }

    #[test]
    fn resampled_sky_keeps_its_bright_spot_where_it_was() {
        // A square map bright only around the direction (1, 0, 0) of its frame.
        let n = 64;
        let texels = (0..n * n)
            .map(|i| {
                let uv = Vec2::new(((i % n) as f32 + 0.5) / n as f32, ((i / n) as f32 + 0.5) / n as f32);
                let d = equal_area_square_to_direction(uv);
                Vec3::splat(if d.x > 0.95 { 1.0 } else { 0.0 })
            })
            .collect();
        let lat_long = equal_area_to_lat_long(&Texture::new(n, n, texels).unwrap());
        // The lat-long map's frame sees that direction at frame⁻¹ · (1, 0, 0).
        let d = equal_area_from_lat_long().transpose() * Vec3::X;
        let uv = direction_to_uv(d);
        let (x, y) = ((uv.x * 128.0) as usize, (uv.y * 64.0) as usize);
        assert_eq!(lat_long.texel(x.min(127), y.min(63)), Vec3::ONE);
        assert_eq!(lat_long.texel(0, 32), Vec3::ZERO);
    }
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
