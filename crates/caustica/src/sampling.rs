//! Random numbers and sample warps, each warp beside its pdf.
//!
//! Every pixel and every photon draws from its own stream, derived from (seed, index), so images
//! and photon maps do not depend on the number of threads.

use crate::math::{sin_cos_turns, Frame, Vec2, Vec3};
use std::f32::consts::PI;

/// A small, fast generator (PCG-XSH-RR 64/32) with an independent stream per index.
#[derive(Clone, Debug)]
pub struct Rng {
    state: u64,
    inc: u64,
}

const MULTIPLIER: u64 = 6364136223846793005;

impl Rng {
    /// The stream for `index` under `seed`.
    pub fn new(seed: u64, index: u64) -> Rng {
        let mut rng = Rng {
            state: 0,
            inc: (mix64(seed ^ 0x9e37_79b9_7f4a_7c15) << 1) | 1,
        };
        rng.next_u32();
        rng.state = rng.state.wrapping_add(mix64(index.wrapping_add(seed.rotate_left(32))));
        rng.next_u32();
        rng
    }

    /// Next 32 random bits.
    #[inline]
    pub fn next_u32(&mut self) -> u32 {
        let old = self.state;
        self.state = old.wrapping_mul(MULTIPLIER).wrapping_add(self.inc);
        let xorshifted = (((old >> 18) ^ old) >> 27) as u32;
        let rot = (old >> 59) as u32;
        xorshifted.rotate_right(rot)
    }

    /// Uniform in [0, 1).
    #[inline]
    pub fn uniform(&mut self) -> f32 {
        (self.next_u32() >> 8) as f32 * (1.0 / 16_777_216.0)
    }

    /// Two uniforms in [0, 1).
    #[inline]
    pub fn uniform2(&mut self) -> Vec2 {
        Vec2::new(self.uniform(), self.uniform())
    }
}

/// SplitMix64's finaliser: a bijective mix of 64 bits.
#[inline]
pub fn mix64(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// A uniformly distributed unit vector.
#[inline]
pub fn sample_uniform_sphere(u: Vec2) -> Vec3 {
    let z = 1.0 - 2.0 * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3::new(r * cos, r * sin, z)
}

/// Solid-angle pdf of [`sample_uniform_sphere`].
#[inline]
pub fn uniform_sphere_pdf() -> f32 {
    1.0 / (4.0 * PI)
}

/// A direction in the cone of half-angle `acos(cos_max)` around `axis`, uniform in solid angle.
#[inline]
pub fn sample_uniform_cone(u: Vec2, axis: Vec3, cos_max: f32) -> Vec3 {
    Frame::from_normal(axis).to_world(sample_uniform_cone_local(u, cos_max))
}

/// [`sample_uniform_cone`] about +z.
#[inline]
pub fn sample_uniform_cone_local(u: Vec2, cos_max: f32) -> Vec3 {
    let cos_theta = 1.0 - u.x * (1.0 - cos_max);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3::new(sin_theta * cos, sin_theta * sin, cos_theta)
}

/// Solid-angle pdf of [`sample_uniform_cone`] inside the cone.
#[inline]
pub fn uniform_cone_pdf(cos_max: f32) -> f32 {
    1.0 / (2.0 * PI * (1.0 - cos_max))
}

/// A point on the unit disc, uniform in area (concentric mapping).
#[inline]
pub fn sample_uniform_disc(u: Vec2) -> Vec2 {
    let a = 2.0 * u - Vec2::ONE;
    if a.x == 0.0 && a.y == 0.0 {
        return Vec2::ZERO;
    }
    // The angle in turns: π/4·(y/x) is an eighth of a turn times y/x.
    let (r, turns) = if a.x.abs() > a.y.abs() {
        (a.x, 0.125 * (a.y / a.x))
    } else {
        (a.y, 0.25 - 0.125 * (a.x / a.y))
    };
    let (sin, cos) = sin_cos_turns(turns);
    Vec2::new(r * cos, r * sin)
}

/// A cosine-weighted direction about +z.
#[inline]
pub fn sample_cosine_hemisphere(u: Vec2) -> Vec3 {
    // A point of the unit disc by radius √u.x and angle (not the concentric map, whose
    // coin-flip branch and division cost more than its stratification gives random numbers),
    // lifted onto the hemisphere.
    let r = u.x.sqrt();
    let (sin, cos) = sin_cos_turns(u.y);
    Vec3::new(r * cos, r * sin, (1.0 - u.x).max(0.0).sqrt())
}

/// Solid-angle pdf of [`sample_cosine_hemisphere`] for a direction with `cos_theta` to +z.
#[inline]
pub fn cosine_hemisphere_pdf(cos_theta: f32) -> f32 {
    cos_theta.max(0.0) / PI
}

/// A piecewise-constant distribution over [0, 1) in `n` equal cells, weighted by `weights`.
#[derive(Clone, Debug)]
pub struct Distribution1D {
    /// Each cell's weight divided by the mean weight: the density within the cell.
    density: Vec<f32>,
    /// Running sums of the cell probabilities, ending at 1.
    cdf: Vec<f32>,
    /// The sum of the weights.
    total: f32,
}

impl Distribution1D {
    /// The distribution of non-negative `weights` (uniform when they are all zero).
    pub fn new(weights: &[f32]) -> Distribution1D {
        let n = weights.len().max(1);
        let clean: Vec<f32> = (0..n)
            .map(|i| {
                weights
                    .get(i)
                    .copied()
                    .filter(|w| w.is_finite() && *w > 0.0)
                    .unwrap_or(0.0)
            })
            .collect();
        let total: f32 = clean.iter().map(|&w| w as f64).sum::<f64>() as f32;
        let probabilities: Vec<f64> = if total > 0.0 {
            clean.iter().map(|&w| w as f64 / total as f64).collect()
        } else {
            vec![1.0 / n as f64; n]
        };
        let mut acc = 0.0f64;
        let mut cdf: Vec<f32> = probabilities
            .iter()
            .map(|p| {
                acc += p;
                acc as f32
            })
            .collect();
        if let Some(last) = cdf.last_mut() {
            *last = 1.0;
        }
        let density = probabilities.iter().map(|p| (p * n as f64) as f32).collect();
        Distribution1D { density, cdf, total }
    }

    /// Number of cells.
    pub fn len(&self) -> usize {
        self.cdf.len()
    }

    /// Whether the distribution has no cell (never: at least one).
    pub fn is_empty(&self) -> bool {
        self.cdf.is_empty()
    }

    /// The sum of the weights it was made from.
    pub fn total(&self) -> f32 {
        self.total
    }

    /// A point in [0, 1) drawn from the distribution, its cell, and the density there.
    pub fn sample(&self, u: f32) -> (f32, usize, f32) {
        let cell = self.cdf.partition_point(|&c| c <= u).min(self.cdf.len() - 1);
        let low = if cell == 0 { 0.0 } else { self.cdf[cell - 1] };
        let width = self.cdf[cell] - low;
        let t = if width > 0.0 {
            ((u - low) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let x = ((cell as f32 + t) / self.cdf.len() as f32).min(1.0 - f32::EPSILON);
        (x, cell, self.density[cell])
    }

    /// The density at `x` in [0, 1).
    pub fn pdf(&self, x: f32) -> f32 {
        let cell = ((x * self.cdf.len() as f32) as usize).min(self.cdf.len() - 1);
        self.density[cell]
    }
}

/// A piecewise-constant distribution over [0, 1)² on a grid of `width` × `height` cells (rows
/// from v = 0): a row by its total weight, then a column within it.
#[derive(Clone, Debug)]
pub struct Distribution2D {
    rows: Distribution1D,
    columns: Vec<Distribution1D>,
}

impl Distribution2D {
    /// The distribution of `weights`, `width` per row, rows from v = 0.
    pub fn new(weights: &[f32], width: usize) -> Distribution2D {
        let width = width.max(1);
        let columns: Vec<Distribution1D> = weights.chunks(width).map(Distribution1D::new).collect();
        let row_weights: Vec<f32> = columns.iter().map(Distribution1D::total).collect();
        Distribution2D {
            rows: Distribution1D::new(&row_weights),
            columns,
        }
    }

    /// A point (u, v) in [0, 1)² and the density there.
    pub fn sample(&self, u: Vec2) -> (Vec2, f32) {
        let (v, row, pdf_row) = self.rows.sample(u.y);
        let (x, _, pdf_column) = self.columns[row].sample(u.x);
        (Vec2::new(x, v), pdf_row * pdf_column)
    }

    /// The density at (u, v).
    pub fn pdf(&self, uv: Vec2) -> f32 {
        let row = ((uv.y * self.rows.len() as f32) as usize).min(self.rows.len() - 1);
        self.rows.pdf(uv.y) * self.columns[row].pdf(uv.x)
    }
}

/// Power heuristic (β = 2) weight of a strategy with pdf `a` against one with pdf `b`.
#[inline]
pub fn power_heuristic(a: f32, b: f32) -> f32 {
    let (a2, b2) = (a * a, b * b);
    if a2 + b2 > 0.0 && (a2 + b2).is_finite() {
        a2 / (a2 + b2)
    } else if a.is_infinite() {
        1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u32> = (0..4).map(|_| Rng::new(1, 7).next_u32()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]), "same stream, same numbers");
        let mut x = Rng::new(1, 7);
        let mut y = Rng::new(1, 8);
        let same = (0..64).filter(|_| x.next_u32() == y.next_u32()).count();
        assert!(same < 2);
    }

    #[test]
    fn uniform_mean_and_range() {
        let mut rng = Rng::new(3, 0);
        let n = 100_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let u = rng.uniform();
            assert!((0.0..1.0).contains(&u));
            sum += u as f64;
        }
        assert!((sum / n as f64 - 0.5).abs() < 0.005);
    }

    #[test]
    fn cone_samples_stay_in_cone_and_cover_its_solid_angle() {
        let mut rng = Rng::new(5, 0);
        let axis = Vec3::new(1.0, 2.0, -0.5).normalize();
        let cos_max = 0.9;
        let mut mean = Vec3::ZERO;
        for _ in 0..20_000 {
            let d = sample_uniform_cone(rng.uniform2(), axis, cos_max);
            assert!(d.dot(axis) >= cos_max - 1e-5);
            assert!((d.length() - 1.0).abs() < 1e-4);
            mean += d;
        }
        // The mean direction of a uniform cone is the axis scaled by (1 + cos_max) / 2.
        let m = mean / 20_000.0;
        assert!((m.dot(axis) - 0.95).abs() < 0.002);
        assert!((uniform_cone_pdf(-1.0) - uniform_sphere_pdf()).abs() < 1e-7);
    }

    #[test]
    fn cosine_hemisphere_mean_cosine_is_two_thirds() {
        let mut rng = Rng::new(9, 1);
        let n = 50_000;
        let s: f32 = (0..n).map(|_| sample_cosine_hemisphere(rng.uniform2()).z).sum();
        assert!((s / n as f32 - 2.0 / 3.0).abs() < 0.005);
    }

    /// Samples land in each cell in proportion to its weight, and the density they report is
    /// the weight over the mean weight.
    #[test]
    fn piecewise_constant_distributions_sample_their_weights() {
        let weights = [0.0, 1.0, 3.0, 0.0, 4.0];
        let d = Distribution1D::new(&weights);
        let mut rng = Rng::new(11, 0);
        let mut counts = [0u32; 5];
        let n = 200_000;
        for _ in 0..n {
            let (x, cell, pdf) = d.sample(rng.uniform());
            assert_eq!(cell, (x * 5.0) as usize);
            assert!((pdf - weights[cell] / 1.6).abs() < 1e-5);
            assert_eq!(pdf, d.pdf(x));
            counts[cell] += 1;
        }
        for (c, w) in counts.iter().zip(weights) {
            assert!((*c as f64 / n as f64 - w as f64 / 8.0).abs() < 0.005, "{counts:?}");
        }
        let flat = Distribution1D::new(&[0.0, 0.0]);
        assert_eq!(flat.pdf(0.7), 1.0);
        // In 2D, the estimate Σ f / pdf of ∫ f over the square is exact for f ∝ the weights.
        let grid = [1.0, 2.0, 0.0, 5.0, 1.0, 3.0];
        let d2 = Distribution2D::new(&grid, 3);
        let mut sum = 0.0f64;
        for _ in 0..10_000 {
            let (uv, pdf) = d2.sample(rng.uniform2());
            assert!((pdf - d2.pdf(uv)).abs() < 1e-4 * pdf);
            let cell = (uv.y * 2.0) as usize * 3 + (uv.x * 3.0) as usize;
            sum += (grid[cell] / pdf) as f64;
        }
        let integral = grid.iter().sum::<f32>() as f64 / 6.0;
        assert!((sum / 10_000.0 - integral).abs() < 1e-3, "{}", sum / 10_000.0);
    }
}
