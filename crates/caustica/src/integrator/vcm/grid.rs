//! A hashed uniform grid over one pass's light vertices, for finding those within the merging
//! radius of a camera vertex. Cells are one diameter wide, so a query ball touches at most
//! 2×2×2 cells; cells share buckets by hash, and the distance test sorts out collisions. Each
//! bucket keeps its points' positions side by side, so that test reads memory in order.

use crate::math::{floor_to_i32, Vec3};

/// The grid: bucket `b` holds `indices[starts[b]..starts[b + 1]]`, at `positions` of the same
/// range.
#[derive(Default)]
pub struct HashGrid {
    inv_cell: f32,
    mask: u32,
    starts: Vec<u32>,
    indices: Vec<u32>,
    positions: Vec<Vec3>,
    /// Each point's bucket while building (kept for the next build's memory).
    keys: Vec<u32>,
}

impl HashGrid {
    /// The grid over `points` for queries of radius `radius`.
    pub fn new(points: &[Vec3], radius: f32) -> HashGrid {
        let mut grid = HashGrid::default();
        grid.rebuild(points, radius);
        grid
    }

    /// Makes it the grid over `points` for queries of radius `radius`, in the memory it has.
    pub fn rebuild(&mut self, points: &[Vec3], radius: f32) {
        let buckets = points.len().next_power_of_two().max(1);
        self.inv_cell = if radius > 0.0 { 0.5 / radius } else { 0.0 };
        self.mask = (buckets - 1) as u32;
        let mut keys = std::mem::take(&mut self.keys);
        keys.clear();
        keys.extend(points.iter().map(|&p| self.bucket(self.cell(p))));
        // A counting sort: each bucket's end, then filled from its end backwards, so that a
        // bucket keeps its points in their order and `starts` ends at each bucket's start.
        self.starts.clear();
        self.starts.resize(buckets + 1, 0);
        for &k in &keys {
            self.starts[k as usize] += 1;
        }
        for b in 1..buckets {
            self.starts[b] += self.starts[b - 1];
        }
        self.starts[buckets] = points.len() as u32;
        self.indices.resize(points.len(), 0);
        self.positions.resize(points.len(), Vec3::ZERO);
        for (i, &k) in keys.iter().enumerate().rev() {
            self.starts[k as usize] -= 1;
            let slot = self.starts[k as usize] as usize;
            self.indices[slot] = i as u32;
            self.positions[slot] = points[i];
        }
        self.keys = keys;
    }

    fn cell(&self, p: Vec3) -> [i32; 3] {
        cell_of(p, self.inv_cell)
    }

    fn bucket(&self, [x, y, z]: [i32; 3]) -> u32 {
        let h = (x as u32).wrapping_mul(73_856_093)
            ^ (y as u32).wrapping_mul(19_349_663)
            ^ (z as u32).wrapping_mul(83_492_791);
        h & self.mask
    }

    /// The points in bucket order: slot `s` holds point `order()[s]`, so data kept in the same
    /// order is read in sequence by [`HashGrid::query`]'s callers.
    pub fn order(&self) -> &[u32] {
        &self.indices
    }

    /// Calls `visit` with the slot (see [`HashGrid::order`]) of every point within `radius` of
    /// `p`.
    pub fn query(&self, p: Vec3, radius: f32, mut visit: impl FnMut(usize)) {
        if self.indices.is_empty() {
            return;
        }
        let lo = self.cell(p - Vec3::splat(radius));
        let hi = self.cell(p + Vec3::splat(radius));
        let r2 = radius * radius;
        let mut seen = [u32::MAX; 8];
        let mut count = 0;
        for x in lo[0]..=hi[0].min(lo[0] + 1) {
            for y in lo[1]..=hi[1].min(lo[1] + 1) {
                for z in lo[2]..=hi[2].min(lo[2] + 1) {
                    let b = self.bucket([x, y, z]);
                    if seen[..count].contains(&b) {
                        continue;
                    }
                    seen[count] = b;
                    count += 1;
                    let range = self.starts[b as usize] as usize..self.starts[b as usize + 1] as usize;
                    for slot in range {
                        if (self.positions[slot] - p).length_squared() <= r2 {
                            visit(slot);
                        }
                    }
                }
            }
        }
    }
}

/// The cell of side `1 / inv_cell` that holds `p`, as integer coordinates (floored, without
/// `floor`'s library call: 1% of a vcm render on the Cornell box).
pub(super) fn cell_of(p: Vec3, inv_cell: f32) -> [i32; 3] {
    let c = p * inv_cell;
    [c.x, c.y, c.z].map(floor_to_i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn finds_every_point_within_the_radius() {
        let mut rng = Rng::new(3, 0);
        let points: Vec<Vec3> = (0..5000)
            .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0)
            .collect();
        let radius = 0.07;
        let grid = HashGrid::new(&points, radius);
        for q in 0..200 {
            let p = points[q * 7] + Vec3::new(0.01, -0.02, 0.015);
            let mut found: Vec<usize> = Vec::new();
            grid.query(p, radius, |slot| found.push(grid.order()[slot] as usize));
            found.sort_unstable();
            let expected: Vec<usize> = (0..points.len())
                .filter(|&i| (points[i] - p).length_squared() <= radius * radius)
                .collect();
            assert_eq!(found, expected);
        }
    }

    #[test]
    fn a_rebuilt_grid_is_the_new_grid_over_its_points() {
        let mut rng = Rng::new(5, 0);
        let mut cloud = |n: usize| -> Vec<Vec3> {
            (0..n)
                .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
                .collect()
        };
        let (first, second) = (cloud(3000), cloud(700));
        let mut reused = HashGrid::new(&first, 0.05);
        reused.rebuild(&second, 0.03);
        let fresh = HashGrid::new(&second, 0.03);
        assert_eq!(reused.order(), fresh.order());
        assert_eq!(reused.starts, fresh.starts);
        for p in second.iter().take(100) {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            reused.query(*p, 0.03, |slot| a.push(slot));
            fresh.query(*p, 0.03, |slot| b.push(slot));
            assert_eq!(a, b);
        }
    }
}
