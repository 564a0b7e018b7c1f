//! A hashed uniform grid over one pass's light vertices, for finding those within the merging
//! radius of a camera vertex. Cells are one diameter wide, so a query ball touches at most
//! 2×2×2 cells; cells share buckets by hash, and the distance test sorts out collisions. Each
//! bucket keeps its points' positions side by side, so that test reads memory in order.

use crate::math::Vec3;

/// The grid: bucket `b` holds `indices[starts[b]..starts[b + 1]]`, at `positions` of the same
/// range.
pub struct HashGrid {
    inv_cell: f32,
    mask: u32,
    starts: Vec<u32>,
    indices: Vec<u32>,
    positions: Vec<Vec3>,
}

impl HashGrid {
    /// The grid over `points` for queries of radius `radius`.
    pub fn new(points: &[Vec3], radius: f32) -> HashGrid {
        let buckets = points.len().next_power_of_two().max(1);
        let inv_cell = if radius > 0.0 { 0.5 / radius } else { 0.0 };
        let mask = (buckets - 1) as u32;
        let mut grid = HashGrid {
            inv_cell,
            mask,
            starts: vec![0; buckets + 1],
            indices: vec![0; points.len()],
            positions: vec![Vec3::ZERO; points.len()],
        };
        let keys: Vec<u32> = points.iter().map(|&p| grid.bucket(grid.cell(p))).collect();
        for &k in &keys {
            grid.starts[k as usize + 1] += 1;
        }
        for b in 0..buckets {
            grid.starts[b + 1] += grid.starts[b];
        }
        let mut fill = grid.starts.clone();
        for (i, &k) in keys.iter().enumerate() {
            let slot = fill[k as usize] as usize;
            grid.indices[slot] = i as u32;
            grid.positions[slot] = points[i];
            fill[k as usize] += 1;
        }
        grid
    }

    fn cell(&self, p: Vec3) -> [i32; 3] {
        let c = (p * self.inv_cell).floor();
        [c.x as i32, c.y as i32, c.z as i32]
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
}
