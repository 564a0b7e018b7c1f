//! Where the caustics seen directly are focused: cells of space where a pilot run's caustic
//! light (light vertices reached from the light through mirrors and glass only) is many times
//! denser than on average, grown by one cell on every side. There, merging at the camera path's first vertex
//! is left out for caustic light, so light tracing keeps the focus sharp; elsewhere the dim,
//! spread-out caustic light is merged like any other and comes out smooth.
//!
//! The pilot run has its own fixed random stream, so every pass (on any machine of a split
//! run) sees the same cells.

use super::grid::cell_of;
use crate::math::Vec3;
use std::collections::{BTreeMap, BTreeSet};

/// A cell is focused when its caustic flux is this many times the mean over the cells that
/// have any. 4 left most of the dim caustic around the focus to light tracing alone; 8 to 24
/// merge it, 16 was also best after 32 passes, the focus unchanged (measured:
/// docs/benchmarks/2026-12-02.md, "The caustics race, aimed vcm").
const FOCUSED: f32 = 16.0;

/// The focused cells.
#[derive(Debug, Default)]
pub struct CausticFocus {
    inv_cell: f32,
    cells: BTreeSet<[i32; 3]>,
}

impl CausticFocus {
    /// The focus of caustic light arriving at `points` with the flux beside each, in cells of
    /// width `cell`.
    pub fn new(points: impl IntoIterator<Item = (Vec3, f32)>, cell: f32) -> CausticFocus {
        if !(cell > 0.0 && cell.is_finite()) {
            return CausticFocus::default();
        }
        let inv_cell = 1.0 / cell;
        let mut flux: BTreeMap<[i32; 3], f32> = BTreeMap::new();
        for (p, power) in points {
            if power.is_finite() && power > 0.0 {
                *flux.entry(cell_of(p, inv_cell)).or_default() += power;
            }
        }
        if flux.is_empty() {
            return CausticFocus::default();
        }
        let mean = flux.values().sum::<f32>() / flux.len() as f32;
        let mut cells = BTreeSet::new();
        for (&[x, y, z], &f) in &flux {
            if f > FOCUSED * mean {
                for dx in -1..=1 {
                    for dy in -1..=1 {
                        for dz in -1..=1 {
                            cells.insert([x + dx, y + dy, z + dz]);
                        }
                    }
                }
            }
        }
        CausticFocus { inv_cell, cells }
    }

    /// Whether no cell is focused.
    pub fn is_empty(&self) -> bool {
        self.cells.is_empty()
    }

    /// Whether `p` lies in a focused cell.
    pub fn contains(&self, p: Vec3) -> bool {
        !self.cells.is_empty() && self.cells.contains(&cell_of(p, self.inv_cell))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bright_line_is_focused_and_its_dim_halo_is_not() {
        // A line of bright light along x at z = 0 over a wide dim halo, in cells of 0.1.
        let mut points = Vec::new();
        for i in 0..100 {
            let x = i as f32 * 0.01;
            points.push((Vec3::new(x, 0.0, 0.005), 100.0));
            for j in 0..20 {
                points.push((Vec3::new(x, 0.0, -1.0 + j as f32 * 0.1), 0.1));
            }
        }
        let focus = CausticFocus::new(points, 0.1);
        assert!(focus.contains(Vec3::new(0.5, 0.0, 0.01)));
        // One cell of margin around the line, then none.
        assert!(focus.contains(Vec3::new(0.5, 0.0, -0.05)));
        assert!(!focus.contains(Vec3::new(0.5, 0.0, -0.5)));
        assert!(!focus.contains(Vec3::new(0.5, 0.0, 0.55)));
        assert!(!CausticFocus::default().contains(Vec3::ZERO));
    }
}
