//! Placeholder triangle (replaced by the fast version).
#![allow(missing_docs)]
use crate::math::{Aabb, Ray, Vec3};

#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    pub v0: Vec3,
    pub e1: Vec3,
    pub e2: Vec3,
}
#[derive(Clone, Copy, Debug)]
pub struct TriangleHit {
    pub t: f32,
    pub u: f32,
    pub v: f32,
}
impl Triangle {
    pub fn new(a: Vec3, b: Vec3, c: Vec3) -> Triangle {
        Triangle {
            v0: a,
            e1: b - a,
            e2: c - a,
        }
    }
    pub fn bounds(&self) -> Aabb {
        Aabb::new(self.v0, self.v0 + self.e1).with_point(self.v0 + self.e2)
    }
    pub fn geometric_normal(&self) -> Vec3 {
        self.e1.cross(self.e2).normalize_or_zero()
    }
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<TriangleHit> {
        let p = ray.dir.cross(self.e2);
        let det = self.e1.dot(p);
        if det == 0.0 {
            return None;
        }
        let inv = 1.0 / det;
        let s = ray.origin - self.v0;
        let u = s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let q = s.cross(self.e1);
        let v = ray.dir.dot(q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        let t = self.e2.dot(q) * inv;
        (t > 0.0 && t < t_max).then_some(TriangleHit { t, u, v })
    }
}
