//! Placeholder BVH (brute force), replaced by the real one.
#![allow(missing_docs)]
use crate::math::{Aabb, Ray};

pub struct Bvh {
    bounds: Vec<Aabb>,
    all: Aabb,
}
impl Bvh {
    pub fn build(prim_bounds: &[Aabb]) -> Bvh {
        let all = prim_bounds.iter().fold(Aabb::EMPTY, |a, b| a.union(*b));
        Bvh {
            bounds: prim_bounds.to_vec(),
            all,
        }
    }
    pub fn bounds(&self) -> Aabb {
        self.all
    }
    pub fn node_count(&self) -> usize {
        1
    }
    pub fn closest_hit<F: FnMut(u32, f32) -> Option<f32>>(
        &self,
        _ray: &Ray,
        t_max: f32,
        mut intersect: F,
    ) -> Option<(f32, u32)> {
        let mut best = None;
        let mut t = t_max;
        for i in 0..self.bounds.len() as u32 {
            if let Some(h) = intersect(i, t) {
                if h < t {
                    t = h;
                    best = Some((h, i));
                }
            }
        }
        best
    }
    pub fn any_hit<F: FnMut(u32, f32) -> bool>(&self, _ray: &Ray, t_max: f32, mut visit: F) -> bool {
        (0..self.bounds.len() as u32).any(|i| visit(i, t_max))
    }
    pub fn any_overlap<F: FnMut(u32) -> bool>(&self, query: &Aabb, mut f: F) -> bool {
        (0..self.bounds.len() as u32).any(|i| {
            let b = self.bounds[i as usize];
            b.min.cmple(query.max).all() && b.max.cmpge(query.min).all() && f(i)
        })
    }
}
