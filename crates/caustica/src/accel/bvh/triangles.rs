//! A BVH specialised to triangles, storing them in leaf order so a leaf's triangles are read
//! from consecutive memory instead of through the primitive index.

use super::{Bvh, END, SMALL_STACK};
use crate::geometry::triangle::{Triangle, TriangleRay};
use crate::math::{Aabb, Ray};

/// Closest hit in a [`TriangleBvh`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TriangleBvhHit {
    /// Ray parameter, in units of the ray direction.
    pub t: f32,
    /// Index of the triangle in the slice given to [`TriangleBvh::new`].
    pub prim: u32,
    /// Barycentric weight of vertex `b`.
    pub u: f32,
    /// Barycentric weight of vertex `c`.
    pub v: f32,
}

/// A BVH over triangles that owns copies of them in leaf order.
#[derive(Clone, Debug)]
pub struct TriangleBvh {
    bvh: Bvh,
    /// Triangles in leaf order (parallel to `bvh.order`).
    tris: Vec<Triangle>,
}

impl TriangleBvh {
    /// Builds over `tris` (see [`Bvh::build`]).
    pub fn new(tris: &[Triangle]) -> TriangleBvh {
        let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
        let bvh = Bvh::build(&bounds);
        let tris = bvh.leaf_order().map(|i| tris[i as usize]).collect();
        TriangleBvh { bvh, tris }
    }

    /// The underlying hierarchy.
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Closest hit with `0 < t < t_max`.
    pub fn closest_hit(&self, ray: &Ray, t_max: f32) -> Option<TriangleBvhHit> {
        if self.bvh.nodes.is_empty() {
            return None;
        }
        if self.bvh.small_stack() {
            self.closest_impl::<SMALL_STACK>(ray, t_max)
        } else {
            self.closest_impl::<{ super::LARGE_STACK }>(ray, t_max)
        }
    }

    /// Whether any triangle is hit with `0 < t < t_max`.
    pub fn any_hit(&self, ray: &Ray, t_max: f32) -> bool {
        if self.bvh.nodes.is_empty() {
            return false;
        }
        let mut t = t_max;
        let tr = TriangleRay::new(ray);
        let leaf = |order: &[u32], first: usize, t_max: &mut f32| {
            let mut i = first;
            loop {
                if self.tris[i].intersect_pre(&tr, *t_max).is_some() {
                    return true;
                }
                if order[i] & END != 0 {
                    return false;
                }
                i += 1;
            }
        };
        if self.bvh.small_stack() {
            self.bvh.traverse::<SMALL_STACK>(ray, &mut t, leaf)
        } else {
            self.bvh.traverse::<{ super::LARGE_STACK }>(ray, &mut t, leaf)
        }
    }

    #[inline(always)]
    fn closest_impl<const N: usize>(&self, ray: &Ray, t_max: f32) -> Option<TriangleBvhHit> {
        let mut t = t_max;
        let mut best = None;
        let tr = TriangleRay::new(ray);
        self.bvh.traverse::<N>(ray, &mut t, |order, first, t_max| {
            let mut i = first;
            loop {
                if let Some(h) = self.tris[i].intersect_pre(&tr, *t_max) {
                    *t_max = h.t;
                    best = Some((i, h.u, h.v));
                }
                if order[i] & END != 0 {
                    return false;
                }
                i += 1;
            }
        });
        best.map(|(i, u, v)| TriangleBvhHit {
            t,
            prim: self.bvh.order[i] & !END,
            u,
            v,
        })
    }
}
