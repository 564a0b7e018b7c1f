//! Placeholder kd-tree (brute force), replaced by the real one.
#![allow(missing_docs)]
use crate::math::Vec3;

pub trait KdPoint {
    fn position(&self) -> Vec3;
}
impl KdPoint for Vec3 {
    fn position(&self) -> Vec3 {
        *self
    }
}
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbor {
    pub slot: u32,
    pub dist2: f32,
}
pub struct KdTree {
    n: usize,
}
impl KdTree {
    pub fn build<T: KdPoint + Send>(items: &mut [T]) -> KdTree {
        KdTree { n: items.len() }
    }
    pub fn len(&self) -> usize {
        self.n
    }
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
    pub fn k_nearest<T: KdPoint>(
        &self,
        items: &[T],
        p: Vec3,
        k: usize,
        max_dist2: f32,
        out: &mut Vec<Neighbor>,
    ) -> f32 {
        out.clear();
        for (i, it) in items.iter().enumerate() {
            let d2 = it.position().distance_squared(p);
            if d2 <= max_dist2 {
                out.push(Neighbor {
                    slot: i as u32,
                    dist2: d2,
                });
            }
        }
        out.sort_by(|a, b| a.dist2.total_cmp(&b.dist2));
        out.truncate(k);
        if out.len() == k && k > 0 {
            out[k - 1].dist2
        } else {
            max_dist2
        }
    }
    pub fn for_each_within<T: KdPoint>(&self, items: &[T], p: Vec3, r2: f32, mut f: impl FnMut(u32, f32)) {
        for (i, it) in items.iter().enumerate() {
            let d2 = it.position().distance_squared(p);
            if d2 <= r2 {
                f(i as u32, d2);
            }
        }
    }
}
