//! Lights with a size (the course forks' `area_light`): a ball or a parallelogram that is not an
//! object of the scene (rays never hit it), so it adds light without being seen.
//!
//! - Course reading: a point light at the centre (its colour times the course's falloff, the
//!   same Phong shading), whose shadow is the average of shadow rays towards
//!   [`SOFT_SHADOW_SAMPLES`] points spread over the light: over the disc of the ball facing the
//!   shaded point (what the forks sample), or over the parallelogram. The points are a
//!   stratified pattern shifted by a hash of the shaded point, so the result depends on the
//!   point alone (never on threads or sample order) and neighbouring pixels average the pattern.
//! - Physical reading: a ball emits like a point light of intensity `color` spread over its
//!   surface (radiance I / (πR²), outwards); a parallelogram emits radiance `color` from its front
//!   face (the side u × v points to). Next-event samples pick a point on the light; photons leave
//!   from a point on it, cosine-weighted or aimed at the caustic targets.

use super::emission::{Emission, EmissionPoint, EmitArgs, Emitters};
use super::{DirectQuery, DirectSample, Light};
use crate::description::EmittingFaces;
use crate::math::Ray;
use crate::math::{Frame, Vec2, Vec3};
use crate::sampling::{mix64, sample_uniform_cone, sample_uniform_disc, sample_uniform_sphere, uniform_cone_pdf};
use crate::sampling::{sample_cosine_hemisphere, Rng};
use std::f32::consts::PI;

/// Shadow rays per light for the course model's soft shadows (a 5 × 5 stratified pattern).
pub const SOFT_SHADOW_SAMPLES: usize = 25;
const STRATA: usize = 5;

/// The shape of a light with a size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SoftShape {
    /// A ball.
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius (positive).
        radius: f32,
    },
    /// `corner + s·u + t·v`, lit on the side of `normal` = (u × v)/|u × v|; with `ellipse`,
    /// the ellipse inscribed in it.
    Parallelogram {
        /// One corner.
        corner: Vec3,
        /// First edge.
        u: Vec3,
        /// Second edge.
        v: Vec3,
        /// Unit normal of the lit face.
        normal: Vec3,
        /// Area.
        area: f32,
        /// The inscribed ellipse rather than the whole parallelogram.
        ellipse: bool,
    },
}

/// A light with a size.
#[derive(Clone, Debug, PartialEq)]
pub struct SoftLight {
    /// Shape and place.
    pub shape: SoftShape,
    /// A ball's intensity, or a parallelogram's radiance.
    pub color: Vec3,
    /// The course's (a, b, c) falloff with distance from the centre.
    pub attenuation: [f32; 3],
}

/// A point on a light's surface drawn for emission or next-event estimation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoftPoint {
    /// The point.
    pub point: Vec3,
    /// Unit outward normal there (the lit side).
    pub normal: Vec3,
    /// Radiance leaving it outwards.
    pub radiance: Vec3,
}

impl SoftLight {
    /// A parallelogram light; `None` if the edges span no area.
    pub fn parallelogram(corner: Vec3, u: Vec3, v: Vec3, color: Vec3, attenuation: [f32; 3]) -> Option<SoftLight> {
        let n = u.cross(v);
        let area = n.length();
        (area > 0.0 && area.is_finite()).then(|| SoftLight {
            shape: SoftShape::Parallelogram {
                corner,
                u,
                v,
                normal: n / area,
                area,
                ellipse: false,
            },
            color,
            attenuation,
        })
    }

    /// The ellipse inscribed in the parallelogram `corner + s·u + t·v`, lit on the side
    /// u × v points to; `None` if the edges span no area.
    pub fn ellipse(corner: Vec3, u: Vec3, v: Vec3, color: Vec3, attenuation: [f32; 3]) -> Option<SoftLight> {
        let mut light = SoftLight::parallelogram(corner, u, v, color, attenuation)?;
        if let SoftShape::Parallelogram { area, ellipse, .. } = &mut light.shape {
            *area *= 0.25 * PI;
            *ellipse = true;
        }
        Some(light)
    }

    /// The centre: where the course model shades from.
    pub fn center(&self) -> Vec3 {
        match self.shape {
            SoftShape::Sphere { center, .. } => center,
            SoftShape::Parallelogram { corner, u, v, .. } => corner + 0.5 * (u + v),
        }
    }

    /// Area of the emitting surface.
    pub fn area(&self) -> f32 {
        match self.shape {
            SoftShape::Sphere { radius, .. } => 4.0 * PI * radius * radius,
            SoftShape::Parallelogram { area, .. } => area,
        }
    }

    /// Radiance leaving the surface outwards.
    pub fn radiance(&self) -> Vec3 {
        match self.shape {
            SoftShape::Sphere { radius, .. } => self.color / (PI * radius * radius),
            SoftShape::Parallelogram { .. } => self.color,
        }
    }

    /// Emitted power (luminance) under the physical model: 4π·I for a ball, π·A·L for a
    /// parallelogram.
    pub fn power(&self) -> f32 {
        let l = crate::math::luminance(self.color).max(0.0);
        match self.shape {
            SoftShape::Sphere { .. } => 4.0 * PI * l,
            SoftShape::Parallelogram { area, .. } => PI * area * l,
        }
    }

    /// The points the course model's shadow rays from `p` aim at.
    pub fn shadow_targets(&self, p: Vec3) -> ShadowTargets {
        // Cranley–Patterson shift of the strata, from the bits of the shaded point.
        let h = mix64((u64::from(p.x.to_bits()) << 32 | u64::from(p.y.to_bits())) ^ mix64(u64::from(p.z.to_bits())));
        let shift = Vec2::new(
            (h >> 40) as f32 / (1u64 << 24) as f32,
            ((h >> 16) & 0xff_ffff) as f32 / (1u64 << 24) as f32,
        );
        let frame = match self.shape {
            SoftShape::Sphere { center, .. } => {
                let to = center - p;
                let axis = to.normalize_or_zero();
                Frame::from_normal(if axis == Vec3::ZERO { Vec3::Z } else { axis })
            }
            SoftShape::Parallelogram { normal, .. } => Frame::from_normal(normal),
        };
        ShadowTargets {
            light: self.shape,
            frame,
            shift,
            next: 0,
        }
    }

    /// A point uniform by area on the light, with the pdf 1/area.
    pub fn sample_point(&self, u: Vec2) -> SoftPoint {
        let (point, normal) = match self.shape {
            SoftShape::Sphere { center, radius } => {
                let n = sample_uniform_sphere(u);
                (center + n * radius, n)
            }
            SoftShape::Parallelogram {
                corner,
                u: eu,
                v: ev,
                normal,
                ellipse,
                ..
            } => (parallelogram_point(corner, eu, ev, ellipse, u), normal),
        };
        SoftPoint {
            point,
            normal,
            radiance: self.radiance(),
        }
    }

    /// The area density with which [`SoftLight::sample_towards`] from `from` draws the light's
    /// point `point` of unit normal `normal` (0 where it cannot: the side of a ball or the
    /// face of a parallelogram turned away from `from`).
    pub fn pdf_area_towards(&self, from: Vec3, point: Vec3, normal: Vec3) -> f32 {
        let to = point - from;
        let d2 = to.length_squared();
        let cos_light = -normal.dot(to) / d2.sqrt();
        if !(cos_light > 1e-7 && d2 > 0.0) {
            return 0.0;
        }
        match self.shape {
            SoftShape::Sphere { center, radius } => {
                let c2 = (center - from).length_squared();
                if c2 <= radius * radius * (1.0 + 1e-4) {
                    return 0.0;
                }
                let cos_max = (1.0 - radius * radius / c2).max(0.0).sqrt();
                uniform_cone_pdf(cos_max) * cos_light / d2
            }
            SoftShape::Parallelogram { area, .. } => 1.0 / area,
        }
    }

    /// A point of the light seen from `from` and the solid-angle pdf of having drawn it: a ball
    /// by the cone it subtends, a parallelogram by area. `None` when nothing of the light's
    /// lit side can be seen from there.
    pub fn sample_towards(&self, from: Vec3, u: Vec2) -> Option<(SoftPoint, f32)> {
        match self.shape {
            SoftShape::Sphere { center, radius } => {
                let to = center - from;
                let d2 = to.length_squared();
                if d2 <= radius * radius * (1.0 + 1e-4) {
                    return None;
                }
                let d = d2.sqrt();
                let cos_max = (1.0 - radius * radius / d2).max(0.0).sqrt();
                let dir = sample_uniform_cone(u, to / d, cos_max);
                // The nearer crossing of the ray with the ball (clamped to the tangent).
                let b = (from - center).dot(dir);
                let c = d2 - radius * radius;
                let t = -b - (b * b - c).max(0.0).sqrt();
                let point = from + dir * t.max(0.0);
                let normal = (point - center).normalize_or_zero();
                Some((
                    SoftPoint {
                        point,
                        normal,
                        radiance: self.radiance(),
                    },
                    uniform_cone_pdf(cos_max),
                ))
            }
            SoftShape::Parallelogram { area, .. } => {
                let s = self.sample_point(u);
                let to = s.point - from;
                let d2 = to.length_squared();
                let cos = -s.normal.dot(to) / d2.sqrt();
                (cos > 1e-7 && d2 > 0.0).then(|| (s, d2 / (area * cos)))
            }
        }
    }
}

/// The point at `s` ∈ [0, 1]² of a parallelogram, or of the ellipse inscribed in it (uniform by
/// area either way).
fn parallelogram_point(corner: Vec3, u: Vec3, v: Vec3, ellipse: bool, s: Vec2) -> Vec3 {
    if ellipse {
        let d = sample_uniform_disc(s);
        corner + 0.5 * (u + v) + 0.5 * (u * d.x + v * d.y)
    } else {
        corner + u * s.x + v * s.y
    }
}

/// The points shadow rays aim at (see [`SoftLight::shadow_targets`]).
#[derive(Clone, Debug)]
pub struct ShadowTargets {
    light: SoftShape,
    frame: Frame,
    shift: Vec2,
    next: usize,
}

impl Iterator for ShadowTargets {
    type Item = Vec3;

    fn next(&mut self) -> Option<Vec3> {
        if self.next >= SOFT_SHADOW_SAMPLES {
            return None;
        }
        let (i, j) = (self.next % STRATA, self.next / STRATA);
        self.next += 1;
        let cell = Vec2::new(i as f32 + 0.5, j as f32 + 0.5) / STRATA as f32;
        let u = (cell + self.shift).fract();
        Some(match self.light {
            // The disc through the centre facing the shaded point.
            SoftShape::Sphere { center, radius } => {
                let d = sample_uniform_disc(u) * radius;
                center + self.frame.x * d.x + self.frame.y * d.y
            }
            SoftShape::Parallelogram {
                corner,
                u: eu,
                v: ev,
                ellipse,
                ..
            } => parallelogram_point(corner, eu, ev, ellipse, u),
        })
    }
}

impl SoftLight {
    /// Next-event estimation's sample: a point of the light's lit side seen from the query's
    /// point. Rays never hit this light, so its sample takes no MIS weight (as a point light's).
    pub(super) fn sample_direct(&self, q: &DirectQuery, u: Vec2) -> Option<DirectSample> {
        let (s, pdf) = self.sample_towards(q.hit.point, u)?;
        let to = s.point - q.hit.point;
        let cos_light = -s.normal.dot(to) / to.length();
        if cos_light.is_nan() || cos_light <= 0.0 {
            return None;
        }
        q.delta(s.point, s.normal, s.radiance, pdf, cos_light)
    }
}

impl Emitters {
    /// A start from a light with a size: a point uniform by area, then a cosine-weighted direction
    /// (or an aimed one).
    pub(super) fn emit_soft(&self, light: &Light, args: EmitArgs, rng: &mut Rng) -> Option<Emission> {
        let (number, pick, u, u_dir, wl) = args.parts();
        match light {
            Light::Soft(light) => {
                // A point uniform by area, then a cosine-weighted direction (or an aimed one).
                let s = light.sample_point(u);
                let dir = match self.aimed(s.point, rng) {
                    Some(aimed) => aimed?,
                    None => Frame::from_normal(s.normal).to_world(sample_cosine_hemisphere(u_dir)),
                };
                let cos = dir.dot(s.normal);
                let pdf = pick * self.direction_pdf(s.point, dir, cos.max(0.0) / PI) / light.area();
                (cos > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(s.point, dir),
                    throughput: wl.unbounded(s.radiance) * (cos / pdf),
                    emission_pdf: pdf,
                    cos,
                    // No ray meets it: camera paths never reach it but by next-event estimation.
                    delta: true,
                    light: number,
                    normal: s.normal,
                    far: false,
                    origin: Some(EmissionPoint {
                        point: s.point,
                        normal: s.normal,
                        faces: EmittingFaces::Front,
                        radiance: wl.unbounded(s.radiance) * (light.area() / pick),
                    }),
                })
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    fn ball() -> SoftLight {
        SoftLight {
            shape: SoftShape::Sphere {
                center: Vec3::new(0.0, 0.0, 4.0),
                radius: 0.5,
            },
            color: Vec3::splat(3.0),
            attenuation: [0.0, 0.0, 1.0],
        }
    }

    #[test]
    fn shadow_targets_cover_the_disc_facing_the_point_and_depend_on_it_alone() {
        let light = ball();
        let p = Vec3::new(0.3, -0.2, 0.0);
        let targets: Vec<Vec3> = light.shadow_targets(p).collect();
        assert_eq!(targets.len(), SOFT_SHADOW_SAMPLES);
        let axis = (light.center() - p).normalize();
        for t in &targets {
            let off = *t - light.center();
            assert!(off.length() <= 0.5 + 1e-5 && off.dot(axis).abs() < 1e-5, "{t}");
        }
        // The mean of a stratified uniform pattern is near the centre.
        let mean = targets.iter().copied().sum::<Vec3>() / targets.len() as f32;
        assert!((mean - light.center()).length() < 0.1, "{mean}");
        assert_eq!(targets, light.shadow_targets(p).collect::<Vec<_>>());
        assert_ne!(targets, light.shadow_targets(p + Vec3::X * 1e-3).collect::<Vec<_>>());
    }

    /// A ball seen from outside: Σ L cos/pdf over sampled points is the irradiance of a point
    /// light of the same intensity, I cosθ/d² (the ball's radiance I/(πR²) over the cone it
    /// subtends, whose projected solid angle is π sin²α = πR²/d² when the ball faces the point).
    #[test]
    fn a_ball_lights_like_a_point_light_of_its_intensity() {
        let light = ball();
        let from = Vec3::ZERO;
        let n = Vec3::Z;
        let mut rng = Rng::new(5, 0);
        let count = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..count {
            let (s, pdf) = light.sample_towards(from, rng.uniform2()).unwrap();
            let wi = (s.point - from).normalize();
            sum += (s.radiance.x * wi.dot(n).max(0.0) / pdf) as f64;
        }
        let estimate = sum / count as f64;
        let exact = 3.0 / 16.0;
        assert!((estimate / exact - 1.0).abs() < 0.005, "{estimate} vs {exact}");
    }

    /// A parallelogram of radiance L seen head-on from distance h along its axis, a square of
    /// side s: E = L·∫cos dω, which for h ≫ s tends to L·s²/h².
    #[test]
    fn a_parallelogram_sends_its_radiance_from_its_front_only() {
        let light = SoftLight::parallelogram(
            Vec3::new(-0.5, -0.5, 10.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::splat(2.0),
            [0.01, 0.0, 1.0],
        )
        .unwrap();
        // u × v = −z: the lit face looks down at the origin.
        assert_eq!(light.shadow_targets(Vec3::ZERO).count(), SOFT_SHADOW_SAMPLES);
        let mut rng = Rng::new(6, 0);
        let count = 50_000;
        let mut sum = 0.0f64;
        for _ in 0..count {
            let (s, pdf) = light.sample_towards(Vec3::ZERO, rng.uniform2()).unwrap();
            let wi = s.point.normalize();
            sum += (s.radiance.x * wi.z / pdf) as f64;
        }
        // Below the centre of a square of side 1 at height h the irradiance is
        // L·∫∫ h²/(h² + x² + y²)² dx dy = (L/h²)(1 − 2⟨x² + y²⟩/h² + …) = (L/h²)(1 − 0.0033) at
        // h = 10: within 0.35 % of L/h².
        let estimate = sum / count as f64;
        assert!((estimate / (2.0 / 100.0) - 1.0).abs() < 0.005, "{estimate}");
        assert!(
            light
                .sample_towards(Vec3::new(0.0, 0.0, 20.0), Vec2::splat(0.5))
                .is_none(),
            "back face"
        );
    }

    /// A disc of radius R and radiance L seen from its axis at height h gives the irradiance
    /// π L R²/(h² + R²) exactly; its points lie on the disc, and its area is π R².
    #[test]
    fn an_ellipse_light_is_the_disc_inscribed_in_its_square() {
        let (r, h, l) = (1.0f32, 2.0f32, 3.0f32);
        let light = SoftLight::ellipse(
            Vec3::new(-r, -r, h),
            Vec3::new(0.0, 2.0 * r, 0.0),
            Vec3::new(2.0 * r, 0.0, 0.0),
            Vec3::splat(l),
            [0.0, 0.0, 1.0],
        )
        .unwrap();
        assert!((light.area() - PI * r * r).abs() < 1e-5);
        let mut rng = Rng::new(7, 0);
        let count = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..count {
            let (s, pdf) = light.sample_towards(Vec3::ZERO, rng.uniform2()).unwrap();
            assert!(s.point.truncate().length() <= r * 1.0001 && (s.point.z - h).abs() < 1e-6);
            let wi = s.point.normalize();
            sum += (s.radiance.x * wi.z / pdf) as f64;
        }
        let exact = (PI * l * r * r / (h * h + r * r)) as f64;
        let estimate = sum / count as f64;
        assert!((estimate / exact - 1.0).abs() < 0.005, "{estimate} against {exact}");
        assert!(light
            .shadow_targets(Vec3::ZERO)
            .all(|p| p.truncate().length() <= r * 1.0001));
    }
}
