//! The cone: a surface of revolution about +z from z = 0 (bottom radius) to z = height (top
//! radius), with optional end discs. A cylinder is the cone with equal radii.

use super::{quadratic_roots, LocalHit};
use crate::math::{Aabb, Ray, Vec2, Vec3};
use std::f32::consts::PI;

/// Cone parameters after the course's clamps (if enabled).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    /// Radius at z = 0.
    pub bottom_radius: f32,
    /// Radius at z = height.
    pub top_radius: f32,
    /// Height (> 0).
    pub height: f32,
    /// End discs present.
    pub capped: bool,
    /// Reproduce the skeleton's side normal, whose z component is twice the true one (§7).
    pub doubled_normal_z: bool,
}

impl Cone {
    /// The `.ray` cylinder: radius 1 about +z, z ∈ [0, 1] — a cone with equal radii, built
    /// exactly (no course slope clamp: that quirk belongs to `cone`).
    pub fn cylinder(capped: bool) -> Cone {
        Cone {
            bottom_radius: 1.0,
            top_radius: 1.0,
            height: 1.0,
            capped,
            doubled_normal_z: false,
        }
    }

    /// A cone as the file describes it. With `course_quirks`, radii are clamped to ≥ 1e-4 and
    /// the slope to magnitude ≥ 0.001, and the side normal has the skeleton's doubled z (§7).
    pub fn new(height: f32, bottom_radius: f32, top_radius: f32, capped: bool, course_quirks: bool) -> Cone {
        let (mut bottom, mut top) = (bottom_radius.abs(), top_radius.abs());
        if course_quirks {
            bottom = bottom.max(1e-4);
            top = top.max(1e-4);
            let slope = (top - bottom) / height;
            if slope.abs() < 1e-3 {
                top = bottom + 1e-3 * height;
            }
        }
        Cone {
            bottom_radius: bottom,
            top_radius: top,
            height,
            capped,
            doubled_normal_z: course_quirks,
        }
    }

    /// Object-space bounds.
    pub fn bounds(&self) -> Aabb {
        let r = self.bottom_radius.max(self.top_radius);
        Aabb::new(Vec3::new(-r, -r, 0.0), Vec3::new(r, r, self.height))
    }

    /// A lower bound on the distance from `p` to the surface: the side lies in the annulus
    /// between the two radii over `0 ≤ z ≤ height`, the caps are discs.
    pub fn distance_lower_bound(&self, p: Vec3) -> f32 {
        let rho = (p.x * p.x + p.y * p.y).sqrt();
        let (r_min, r_max) = (
            self.bottom_radius.min(self.top_radius),
            self.bottom_radius.max(self.top_radius),
        );
        let dz = (-p.z).max(p.z - self.height).max(0.0);
        let dr = (rho - r_max).max(r_min - rho).max(0.0);
        let side = (dr * dr + dz * dz).sqrt();
        if !self.capped {
            return side;
        }
        let disc = |z: f32, radius: f32| {
            let d = (rho - radius).max(0.0);
            (d * d + (p.z - z) * (p.z - z)).sqrt()
        };
        side.min(disc(0.0, self.bottom_radius))
            .min(disc(self.height, self.top_radius))
    }

    /// Whether `p` lies inside the solid by more than `1 − inside` of its radius there: within
    /// the cone ρ < r0 + s z (a convex set the side never enters), and between the caps when
    /// there are caps.
    pub fn interior_holds(&self, p: Vec3, inside: f32) -> bool {
        let rho2 = p.x * p.x + p.y * p.y;
        let radius = (self.bottom_radius + self.slope() * p.z) * inside;
        let between_caps = !self.capped || (p.z > self.height * (1.0 - inside) && p.z < self.height * inside);
        radius > 0.0 && rho2 < radius * radius && between_caps
    }

    fn slope(&self) -> f32 {
        (self.top_radius - self.bottom_radius) / self.height
    }

    /// Nearest hit in `(0, t_max)`. Side normals point outward, except on an uncapped cone hit
    /// from inside, where they face the ray; cap normals are −z at the bottom and +z at the top.
    /// Side texture coordinates (an arctangent) only `with_uv`, zero otherwise.
    pub fn intersect(&self, ray: &Ray, t_max: f32, with_uv: bool) -> Option<LocalHit> {
        let mut best: Option<LocalHit> = None;
        let mut t_best = t_max;
        if let Some(hit) = self.intersect_side(ray, t_best, with_uv) {
            t_best = hit.t;
            best = Some(hit);
        }
        if self.capped {
            for (z, radius, nz) in [(0.0, self.bottom_radius, -1.0), (self.height, self.top_radius, 1.0)] {
                if let Some(hit) = intersect_disc(ray, z, radius, nz, t_best) {
                    t_best = hit.t;
                    best = Some(hit);
                }
            }
        }
        best
    }

    /// The side's quadratic x² + y² − (r0 + s z)² along the ray from `o`: (half b, c).
    fn side_coefficients(&self, o: Vec3, d: Vec3) -> (f32, f32) {
        let s = self.slope();
        let r_o = self.bottom_radius + s * o.z;
        (o.x * d.x + o.y * d.y - s * d.z * r_o, o.x * o.x + o.y * o.y - r_o * r_o)
    }

    fn intersect_side(&self, ray: &Ray, t_max: f32, with_uv: bool) -> Option<LocalHit> {
        let (o, d) = (ray.origin, ray.dir);
        let s = self.slope();
        let r0 = self.bottom_radius;
        let a = d.x * d.x + d.y * d.y - s * s * d.z * d.z;
        let (half_b, c) = self.side_coefficients(o, d);
        // The discriminant is the same from every point of the ray: taken from the point where
        // the quadratic turns (b = 0 there), it keeps the precision a far origin loses.
        let turn = -half_b / a;
        let disc = if turn.is_finite() {
            let (half_b_turn, c_turn) = self.side_coefficients(o + d * turn, d);
            half_b_turn * half_b_turn - a * c_turn
        } else {
            half_b * half_b - a * c
        };
        let (t0, t1) = quadratic_roots(a, half_b, c, disc)?;
        for t in [t0, t1] {
            if !(t > 0.0 && t < t_max) {
                continue;
            }
            let p = ray.at(t);
            let radius = r0 + s * p.z;
            if p.z < 0.0 || p.z > self.height || radius < 0.0 {
                continue;
            }
            // Onto the side: the radius at this height, the direction around the axis kept.
            let rho = (p.x * p.x + p.y * p.y).sqrt();
            let point = if rho > 0.0 {
                Vec3::new(p.x * (radius / rho), p.y * (radius / rho), p.z)
            } else {
                p
            };
            let z_scale = if self.doubled_normal_z { 2.0 } else { 1.0 };
            let mut normal = Vec3::new(point.x, point.y, -z_scale * s * radius);
            if !self.capped && normal.dot(d) > 0.0 {
                normal = -normal;
            }
            let uv = if with_uv {
                let phi = point.y.atan2(point.x);
                let u = if phi < 0.0 { phi + 2.0 * PI } else { phi } / (2.0 * PI);
                Vec2::new(u, point.z / self.height)
            } else {
                Vec2::ZERO
            };
            return Some(LocalHit { t, point, normal, uv });
        }
        None
    }
}

fn intersect_disc(ray: &Ray, z: f32, radius: f32, nz: f32, t_max: f32) -> Option<LocalHit> {
    if ray.dir.z == 0.0 || radius <= 0.0 {
        return None;
    }
    let t = (z - ray.origin.z) / ray.dir.z;
    if !(t > 0.0 && t < t_max) {
        return None;
    }
    let p = ray.at(t);
    if p.x * p.x + p.y * p.y > radius * radius {
        return None;
    }
    Some(LocalHit {
        t,
        point: Vec3::new(p.x, p.y, z),
        normal: Vec3::new(0.0, 0.0, nz),
        uv: Vec2::new(0.5 + 0.5 * p.x / radius, 0.5 + 0.5 * p.y / radius),
    })
}
