//! Participating media: fog, smoke, murky water, and the absorbing inside of a coloured glass.
//! A medium fills the inside or outside of surfaces whose material carries an [`Interface`]
//! (or the whole scene: the ambient medium). Walks sample free flights through it by spectral
//! tracking (Kutz et al. 2017: null collisions against one majorant for every wavelength, the
//! event chosen by the largest weighted coefficient), shadow rays pay its transmittance
//! (closed form when homogeneous, ratio tracking on a grid), and a scattering point turns the
//! path by a Henyey–Greenstein phase function.

use crate::math::{Frame, Ray};
use crate::sampling::Rng;
use crate::spectrum::{Spectrum, Wavelengths};
use glam::{Affine3A, Vec3};
use std::f32::consts::PI;

/// No medium: vacuum (or air, which we treat as clear).
pub const VACUUM: u32 = u32::MAX;

/// The media on the two sides of a surface point a walk has reached: `front` where the
/// geometric normal points, `back` behind it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Media {
    /// The medium on the geometric normal's side.
    pub front: u32,
    /// The medium behind the surface.
    pub back: u32,
}

impl Media {
    /// Vacuum on both sides.
    pub const VACUUM: Media = Media {
        front: VACUUM,
        back: VACUUM,
    };

    /// One medium on both sides (a scattering point inside it).
    pub fn both(medium: u32) -> Media {
        Media {
            front: medium,
            back: medium,
        }
    }

    /// The medium a direction `dir` leaving the point (geometric normal `ng`) goes into.
    #[inline]
    pub fn towards(&self, ng: Vec3, dir: Vec3) -> u32 {
        if dir.dot(ng) > 0.0 {
            self.front
        } else {
            self.back
        }
    }
}

/// What one side of a medium boundary holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// This medium ([`VACUUM`]: none).
    Medium(u32),
    /// Whatever surrounded the walk before it went in (a coloured glass standing in fog).
    Surrounding,
}

/// The media a material's surface separates: inside (against the outward normal) and outside.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Interface {
    /// Behind the surface.
    pub inside: Side,
    /// On the outward normal's side.
    pub outside: Side,
}

/// A Henyey–Greenstein phase function of mean cosine `g` (0: isotropic; > 0: forward).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Phase {
    /// The mean cosine of the scattering angle, in (−1, 1).
    pub g: f32,
}

impl Phase {
    /// The density of turning from a walk arriving along −`wo` into `wi` (both unit, away from
    /// the point), per solid angle.
    #[inline]
    pub fn eval(&self, wo: Vec3, wi: Vec3) -> f32 {
        henyey_greenstein(wo.dot(wi), self.g)
    }

    /// A direction drawn exactly by the density (the weight is 1), and its density.
    pub fn sample(&self, wo: Vec3, u: glam::Vec2) -> (Vec3, f32) {
        let g = self.g;
        // The cosine between wo and wi, by inverting the phase function's distribution.
        let cos = if g.abs() < 1e-3 {
            1.0 - 2.0 * u.x
        } else {
            let s = (1.0 - g * g) / (1.0 + g - 2.0 * g * u.x);
            -(1.0 + g * g - s * s) / (2.0 * g)
        }
        .clamp(-1.0, 1.0);
        let sin = (1.0 - cos * cos).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let wi = Frame::from_normal(wo).to_world(Vec3::new(sin * phi.cos(), sin * phi.sin(), cos));
        (wi, henyey_greenstein(cos, g))
    }
}

/// Henyey–Greenstein's density for the cosine `cos` between the two directions pointing away
/// from the point (so forward scattering is `cos` = −1).
#[inline]
pub fn henyey_greenstein(cos: f32, g: f32) -> f32 {
    let d = (1.0 + g * g + 2.0 * g * cos).max(1e-12);
    (1.0 - g * g) / (4.0 * PI * d * d.sqrt())
}

/// A density on a regular grid (pbrt-v4's `uniformgrid`), trilinear between sample centres (a
/// missing neighbour reads 0) and zero outside its box. Tracked against its largest density, or
/// against each coarse cell's largest ([`Majorants`]) along a ray where that pays: through a
/// sparse grid, thick enough for many null collisions.
#[derive(Clone, Debug)]
pub struct DensityGrid {
    /// Samples along x, y, z.
    dims: [usize; 3],
    /// x fastest, then y, then z.
    values: Vec<f32>,
    /// From world space to the grid's unit cube.
    to_grid: Affine3A,
    /// The largest density.
    max: f32,
    /// Per coarse cell, when the grid is sparse enough for them to pay.
    majorants: Option<Majorants>,
}

impl DensityGrid {
    /// A grid of `dims` samples (x fastest) spanning the unit cube under `to_grid`.
    pub fn new(dims: [usize; 3], values: Vec<f32>, to_grid: Affine3A) -> DensityGrid {
        let max = values.iter().copied().fold(0.0f32, f32::max);
        let mut grid = DensityGrid {
            dims,
            values,
            to_grid,
            max,
            majorants: None,
        };
        let majorants = Majorants::of(&grid);
        grid.majorants = (majorants.mean_share < 1.0).then_some(majorants);
        grid
    }

    /// The grid tracked cell by cell (`on`) or against its largest density, whether that pays
    /// or not: for tests that compare the two.
    #[cfg(test)]
    fn with_majorant_grid(mut self, on: bool) -> DensityGrid {
        self.majorants = on.then(|| Majorants {
            step_cost: 0.0,
            ..Majorants::of(&self)
        });
        self
    }

    /// Whether tracking walks coarse cells with their own majorants.
    pub fn has_majorant_grid(&self) -> bool {
        self.majorants.is_some()
    }

    /// The sample at `(x, y, z)`, 0 outside the grid.
    fn sample(&self, x: i64, y: i64, z: i64) -> f32 {
        let [nx, ny, nz] = self.dims;
        if x < 0 || y < 0 || z < 0 || x >= nx as i64 || y >= ny as i64 || z >= nz as i64 {
            return 0.0;
        }
        self.values[(z as usize * ny + y as usize) * nx + x as usize]
    }

    /// Tentative collisions along `ray` from `a` to `b` (inside the grid's cube) against
    /// majorants `scale` × the largest density (of the grid, or of each coarse cell in turn):
    /// `at(t, majorant)` at each, until it says stop (false) or the walk passes `b`.
    fn collisions(
        &self,
        ray: &Ray,
        (a, b): (f32, f32),
        scale: f32,
        rng: &mut Rng,
        mut at: impl FnMut(f32, f32, &mut Rng) -> bool,
    ) {
        // The optical depth (against the majorants) left to the next collision, carried from
        // cell to cell: one random number per collision, none per cell.
        let mut depth = -(1.0 - rng.uniform()).ln();
        let mut flight = |(t0, t1): (f32, f32), majorant: f32, rng: &mut Rng| {
            if majorant.is_nan() || majorant <= 0.0 {
                return true;
            }
            let mut t = t0;
            loop {
                let next = t + depth / majorant;
                if next >= t1 {
                    depth = (depth - majorant * (t1 - t)).max(0.0);
                    return true;
                }
                t = next;
                if !at(t, majorant, rng) {
                    return false;
                }
                depth = -(1.0 - rng.uniform()).ln();
            }
        };
        match &self.majorants {
            None => {
                flight((a, b), self.max * scale, rng);
            }
            Some(majorants) => {
                let o = self.to_grid.transform_point3(ray.origin);
                let d = self.to_grid.transform_vector3(ray.dir);
                if majorants.pays(d, b - a, self.max * scale * (b - a)) {
                    majorants.walk((o, d), (a, b), |span, max| flight(span, max * scale, rng));
                } else {
                    flight((a, b), self.max * scale, rng);
                }
            }
        }
    }

    /// Samples along x, y and z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// The density at the world point `p`.
    pub fn density(&self, p: Vec3) -> f32 {
        let g = self.to_grid.transform_point3(p);
        // Nothing outside the grid's box (as pbrt-v4's grid media, whose rays are clipped to it).
        if !(g.cmpge(Vec3::ZERO).all() && g.cmple(Vec3::ONE).all()) {
            return 0.0;
        }
        // Sample centres sit at (i + ½)/n.
        let [nx, ny, nz] = self.dims;
        let s = g * Vec3::new(nx as f32, ny as f32, nz as f32) - 0.5;
        let i = s.floor();
        let f = s - i;
        let (i0, j0, k0) = (i.x as i64, i.y as i64, i.z as i64);
        let at = |x: i64, y: i64, z: i64| self.sample(x, y, z);
        let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
        let x00 = lerp(at(i0, j0, k0), at(i0 + 1, j0, k0), f.x);
        let x10 = lerp(at(i0, j0 + 1, k0), at(i0 + 1, j0 + 1, k0), f.x);
        let x01 = lerp(at(i0, j0, k0 + 1), at(i0 + 1, j0, k0 + 1), f.x);
        let x11 = lerp(at(i0, j0 + 1, k0 + 1), at(i0 + 1, j0 + 1, k0 + 1), f.x);
        lerp(lerp(x00, x10, f.y), lerp(x01, x11, f.y), f.z)
    }

    /// The part `(t0, t1)` of the segment `(a, b)` of `ray` inside the grid's cube.
    fn clip(&self, ray: &Ray, (a, b): (f32, f32)) -> Option<(f32, f32)> {
        let o = self.to_grid.transform_point3(ray.origin);
        let d = self.to_grid.transform_vector3(ray.dir);
        let (mut t0, mut t1) = (a, b);
        for axis in 0..3 {
            let inv = 1.0 / d[axis];
            let (mut near, mut far) = ((0.0 - o[axis]) * inv, (1.0 - o[axis]) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            if near.is_nan() || far.is_nan() {
                // Parallel to the slab: inside it or not at all.
                if o[axis] < 0.0 || o[axis] > 1.0 {
                    return None;
                }
                continue;
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
        }
        (t0 < t1).then_some((t0, t1))
    }
}

/// The largest density of each coarse cell of a [`DensityGrid`] (at most 16 along an axis): a
/// walk through a sparse grid makes null collisions only where there is something, at the cost
/// of stepping from cell to cell.
#[derive(Clone, Debug)]
struct Majorants {
    /// Cells along x, y, z.
    cells: [usize; 3],
    /// x fastest, then y, then z.
    max: Vec<f32>,
    /// The cells' mean largest density over the grid's largest.
    mean_share: f32,
    /// What stepping into a cell costs, in tentative collisions.
    step_cost: f32,
}

impl Majorants {
    /// Coarse cells along an axis, at most.
    const CELLS: usize = 16;
    /// What stepping into a cell costs, in tentative collisions. At 0.25 the smoke scene (two
    /// collisions across its box) keeps one majorant and a dense puff in an empty box walks
    /// cells: its path tracer twice as fast (BENCHMARKS.md); at 1 the puff kept one too.
    const STEP_COST: f32 = 0.25;

    fn of(grid: &DensityGrid) -> Majorants {
        let cells = grid.dims.map(|n| n.clamp(1, Self::CELLS));
        let mut max = vec![0.0f32; cells[0] * cells[1] * cells[2]];
        // The samples a point in cell c reads lie within one sample of its span: from the one
        // below its lower end to the one above its upper end.
        let range = |axis: usize, c: usize| {
            let (n, m) = (grid.dims[axis] as f64, cells[axis] as f64);
            let lo = (c as f64 / m * n - 0.5).floor() as i64;
            let hi = ((c + 1) as f64 / m * n - 0.5).floor() as i64 + 1;
            lo..=hi
        };
        for (k, i) in (0..cells[2]).flat_map(|k| (0..cells[1] * cells[0]).map(move |i| (k, i))) {
            let (cx, cy) = (i % cells[0], i / cells[0]);
            let mut m = 0.0f32;
            for z in range(2, k) {
                for y in range(1, cy) {
                    for x in range(0, cx) {
                        m = m.max(grid.sample(x, y, z));
                    }
                }
            }
            max[(k * cells[1] + cy) * cells[0] + cx] = m;
        }
        let largest = max.iter().copied().fold(0.0f32, f32::max);
        let mean = max.iter().map(|&m| m as f64).sum::<f64>() / max.len() as f64;
        Majorants {
            cells,
            mean_share: if largest > 0.0 {
                (mean / largest as f64) as f32
            } else {
                1.0
            },
            max,
            step_cost: Self::STEP_COST,
        }
    }

    /// Whether walking the cells pays along a line of direction `d` (in the grid's unit cube)
    /// over a length `len`, against `collisions` tentative collisions expected with one majorant
    /// for the grid: when the collisions it saves (the cells' mean share of the largest density
    /// less) cost more than the cells it steps through.
    fn pays(&self, d: Vec3, len: f32, collisions: f32) -> bool {
        let cells = Vec3::new(self.cells[0] as f32, self.cells[1] as f32, self.cells[2] as f32);
        let crossed = len * (d.abs() * cells).element_sum() + 1.0;
        collisions * (1.0 - self.mean_share) > self.step_cost * crossed
    }

    /// The spans of the line `o + t d` (in the grid's unit cube) from `a` to `b` in each cell
    /// it crosses, in order, with that cell's largest density: `span((t0, t1), max)` until it
    /// returns false (a 3D DDA, Amanatides & Woo 1987).
    fn walk(&self, (o, d): (Vec3, Vec3), (a, b): (f32, f32), mut span: impl FnMut((f32, f32), f32) -> bool) {
        let n = self.cells.map(|c| c as i64);
        let start = o + d * a;
        let mut cell = [0i64; 3];
        let (mut next, mut delta, mut step) = ([f32::INFINITY; 3], [f32::INFINITY; 3], [0i64; 3]);
        for axis in 0..3 {
            let m = n[axis] as f32;
            cell[axis] = ((start[axis] * m).floor() as i64).clamp(0, n[axis] - 1);
            if d[axis] > 0.0 {
                step[axis] = 1;
                next[axis] = ((cell[axis] + 1) as f32 / m - o[axis]) / d[axis];
                delta[axis] = 1.0 / (m * d[axis]);
            } else if d[axis] < 0.0 {
                step[axis] = -1;
                next[axis] = (cell[axis] as f32 / m - o[axis]) / d[axis];
                delta[axis] = -1.0 / (m * d[axis]);
            }
        }
        let mut t = a;
        loop {
            let axis = if next[0] < next[1] {
                if next[0] < next[2] {
                    0
                } else {
                    2
                }
            } else if next[1] < next[2] {
                1
            } else {
                2
            };
            // (Not before t: a start on a cell's face may round to either side.)
            let end = next[axis].min(b).max(t);
            let index = (cell[2] * n[1] + cell[1]) * n[0] + cell[0];
            if end > t && !span((t, end), self.max[index as usize]) {
                return;
            }
            if end >= b {
                return;
            }
            t = end;
            cell[axis] += step[axis];
            if cell[axis] < 0 || cell[axis] >= n[axis] {
                return;
            }
            next[axis] += delta[axis];
        }
    }
}

/// A participating medium: absorption and scattering coefficients (per unit of length, RGB),
/// scaled by a density grid where it has one, and its phase function.
#[derive(Clone, Debug)]
pub struct Medium {
    /// σa: absorption.
    pub sigma_a: Vec3,
    /// σs: scattering.
    pub sigma_s: Vec3,
    /// The phase function.
    pub phase: Phase,
    /// A density multiplying both coefficients (`None`: homogeneous).
    pub grid: Option<DensityGrid>,
}

impl Medium {
    /// A homogeneous medium.
    pub fn homogeneous(sigma_a: Vec3, sigma_s: Vec3, g: f32) -> Medium {
        Medium {
            sigma_a: sigma_a.max(Vec3::ZERO),
            sigma_s: sigma_s.max(Vec3::ZERO),
            phase: Phase {
                g: g.clamp(-0.99, 0.99),
            },
            grid: None,
        }
    }

    /// Whether the medium only absorbs (a coloured glass): no walk ever stops in it.
    #[inline]
    pub fn only_absorbs(&self) -> bool {
        self.sigma_s == Vec3::ZERO
    }

    /// Whether the medium has no effect at all (zero coefficients or zero density): walks pass
    /// it untouched.
    pub fn is_clear(&self) -> bool {
        (self.sigma_a + self.sigma_s) == Vec3::ZERO || self.grid.as_ref().is_some_and(|g| g.max <= 0.0)
    }

    /// σs and σt at the wavelengths `wl`.
    #[inline]
    fn coefficients(&self, wl: &Wavelengths) -> (Spectrum, Spectrum) {
        let s = wl.unbounded(self.sigma_s);
        (s, s + wl.unbounded(self.sigma_a))
    }

    /// The largest σt of any channel (a homogeneous medium's; a grid's at density one).
    pub fn majorant(&self) -> f32 {
        (self.sigma_a + self.sigma_s).max_element()
    }

    /// σs at the point `p`, at the wavelengths `wl` (the grid's density included).
    pub fn sigma_s_at(&self, p: Vec3, wl: &Wavelengths) -> Spectrum {
        let s = wl.unbounded(self.sigma_s);
        match &self.grid {
            None => s,
            Some(grid) => s * grid.density(p),
        }
    }

    /// Samples where a walk along `ray` (unit direction) between `t0` and `t1` first scatters:
    /// `Some(t)` with `throughput` multiplied by the event's weight, or `None` when it passes
    /// the segment, `throughput` multiplied by what it keeps.
    pub fn sample_flight(
        &self,
        ray: &Ray,
        (t0, t1): (f32, f32),
        wl: &Wavelengths,
        throughput: &mut Spectrum,
        rng: &mut Rng,
    ) -> Option<f32> {
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) || self.is_clear() {
            return None;
        }
        if self.only_absorbs() && self.grid.is_none() {
            *throughput *= beer_lambert(self.sigma_a, t1 - t0, wl);
            return None;
        }
        let (sigma_s, sigma_t) = self.coefficients(wl);
        match &self.grid {
            None => track((t0, t1), (sigma_s, sigma_t), throughput, rng),
            Some(grid) => {
                let span = grid.clip(ray, (t0, t1))?;
                let mut scattered = None;
                grid.collisions(ray, span, sigma_t.max_element(), rng, |t, majorant, rng| {
                    let density = grid.density(ray.at(t));
                    match collide((sigma_s, sigma_t), density, majorant, throughput, rng) {
                        Some(true) => {
                            scattered = Some(t);
                            false
                        }
                        Some(false) => true,
                        None => false,
                    }
                });
                scattered
            }
        }
    }

    /// What light keeps along `ray` (unit direction) between `t0` and `t1`: exp(−σt d) when
    /// homogeneous, an unbiased estimate by ratio tracking on a grid.
    pub fn transmittance(&self, ray: &Ray, (t0, t1): (f32, f32), wl: &Wavelengths, rng: &mut Rng) -> Spectrum {
        if t0.partial_cmp(&t1) != Some(std::cmp::Ordering::Less) || self.is_clear() {
            return wl.grey(1.0);
        }
        let Some(grid) = &self.grid else {
            return self.kept_homogeneous(t1 - t0, wl);
        };
        let mut tr = wl.grey(1.0);
        self.ratio_tracking(grid, ray, (t0, t1), wl, rng, |_, kept| tr = kept);
        tr
    }

    /// What light keeps over `distance` of the medium were it homogeneous (its grid left out):
    /// exp(−σt d).
    pub fn kept_homogeneous(&self, distance: f32, wl: &Wavelengths) -> Spectrum {
        if self.only_absorbs() {
            return beer_lambert(self.sigma_a, distance, wl);
        }
        let (_, sigma_t) = self.coefficients(wl);
        kept(sigma_t, distance)
    }

    /// What light keeps along `ray` from `t0` to every point up to `t1`, at once: an unbiased
    /// estimate of each, a step function (exp(−σt d) itself when homogeneous). `steps` is
    /// emptied and gets `(t, kept from t0 to any point past t)` at each step, in order; before
    /// the first step everything is kept.
    pub fn transmittance_steps(
        &self,
        ray: &Ray,
        (t0, t1): (f32, f32),
        wl: &Wavelengths,
        rng: &mut Rng,
        steps: &mut Vec<(f32, Spectrum)>,
    ) {
        steps.clear();
        if let Some(grid) = &self.grid {
            if t0 < t1 && !self.is_clear() {
                self.ratio_tracking(grid, ray, (t0, t1), wl, rng, |t, kept| steps.push((t, kept)));
            }
        }
    }

    /// Ratio tracking along `ray` from `t0` to `t1` through `grid`: `step(t, kept)` at each
    /// tentative collision with the estimate of what is kept from `t0` on past it.
    fn ratio_tracking(
        &self,
        grid: &DensityGrid,
        ray: &Ray,
        (t0, t1): (f32, f32),
        wl: &Wavelengths,
        rng: &mut Rng,
        mut step: impl FnMut(f32, Spectrum),
    ) {
        let Some((a, b)) = grid.clip(ray, (t0, t1)) else {
            return;
        };
        let (_, sigma_t) = self.coefficients(wl);
        let mut tr = wl.grey(1.0);
        grid.collisions(ray, (a, b), sigma_t.max_element(), rng, |t, majorant, rng| {
            let density = grid.density(ray.at(t));
            tr *= (Spectrum::splat(1.0) - sigma_t * (density / majorant)).max(Spectrum::ZERO);
            // Roulette once little is left, so a thick grid does not cost a step per unit.
            let m = tr.max_element();
            if m < 0.1 {
                if rng.uniform() >= m / 0.1 {
                    step(t, Spectrum::ZERO);
                    return false;
                }
                tr /= m / 0.1;
            }
            step(t, tr);
            true
        });
    }
}

/// exp(−σ d) per channel; a zero coefficient keeps everything even over an endless length.
#[inline]
fn kept(sigma: Spectrum, distance: f32) -> Spectrum {
    let e = (-sigma * distance).exp();
    Spectrum::select(sigma.cmpgt(Spectrum::ZERO), e, Spectrum::ONE)
}

/// What a path keeps of its light after a length `distance` inside a glass absorbing `sigma`
/// per unit of length, at the wavelengths `wl` (Beer–Lambert: exp(−σ d), nothing past an
/// endless length): the kept colour, fitted as a reflectance.
#[inline]
pub fn beer_lambert(sigma: Vec3, distance: f32, wl: &Wavelengths) -> Spectrum {
    let kept = Vec3::select(sigma.cmpgt(Vec3::ZERO), (-sigma * distance).exp(), Vec3::ONE);
    wl.reflectance(kept)
}

/// Spectral tracking from `t0` to `t1` through a homogeneous medium, against its largest σt:
/// `Some(t)` where it scatters (see [`collide`]).
fn track(
    (t0, t1): (f32, f32),
    (sigma_s, sigma_t): (Spectrum, Spectrum),
    throughput: &mut Spectrum,
    rng: &mut Rng,
) -> Option<f32> {
    let majorant = sigma_t.max_element();
    if majorant.is_nan() || majorant <= 0.0 {
        return None;
    }
    let mut t = t0;
    loop {
        t -= (1.0 - rng.uniform()).ln() / majorant;
        if t >= t1 {
            return None;
        }
        match collide((sigma_s, sigma_t), 1.0, majorant, throughput, rng) {
            Some(true) => return Some(t),
            Some(false) => {}
            None => return None,
        }
    }
}

/// A tentative collision of spectral tracking against the scalar `majorant` ≥ σt × `density`
/// (Kutz et al. 2017): the event, scatter (`Some(true)`) or null (`Some(false)`), is chosen in
/// proportion to the largest channel of coefficient × throughput, and the throughput weighted by
/// each channel's own coefficient over its probability; absorption is carried in the weights.
/// `None`: nothing is left to carry.
#[inline]
fn collide(
    (sigma_s, sigma_t): (Spectrum, Spectrum),
    density: f32,
    majorant: f32,
    throughput: &mut Spectrum,
    rng: &mut Rng,
) -> Option<bool> {
    let scatter = sigma_s * density;
    let null = (Spectrum::splat(majorant) - sigma_t * density).max(Spectrum::ZERO);
    let (ps, pn) = (
        (scatter * *throughput).max_element(),
        (null * *throughput).max_element(),
    );
    if (ps + pn).is_nan() || ps + pn <= 0.0 {
        *throughput = Spectrum::ZERO;
        return None;
    }
    let p_scatter = ps / (ps + pn);
    if rng.uniform() < p_scatter {
        *throughput *= scatter / (majorant * p_scatter);
        return Some(true);
    }
    *throughput *= null / (majorant * (1.0 - p_scatter));
    Some(false)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The phase function integrates to one, its samples follow it (their mean cosine is g
    /// towards the walk's direction) and their densities are the function's.
    #[test]
    fn henyey_greenstein_is_normalised_and_sampled_exactly() {
        for g in [-0.7f32, 0.0, 0.3, 0.9] {
            let phase = Phase { g };
            let n = 20_000;
            let integral: f64 = (0..n)
                .map(|i| {
                    let cos = -1.0 + 2.0 * (i as f64 + 0.5) / n as f64;
                    henyey_greenstein(cos as f32, g) as f64 * 2.0 * std::f64::consts::PI * 2.0 / n as f64
                })
                .sum();
            assert!((integral - 1.0).abs() < 1e-3, "g {g}: {integral}");
            let wo = Vec3::new(0.3, -0.2, 0.9).normalize();
            let mut rng = Rng::new(3, 0);
            let mut mean = 0.0f64;
            for _ in 0..n {
                let (wi, pdf) = phase.sample(wo, rng.uniform2());
                assert!((wi.length() - 1.0).abs() < 1e-4);
                assert!((pdf - phase.eval(wo, wi)).abs() <= 1e-3 * pdf.max(1e-3), "g {g}");
                mean += (-wo).dot(wi) as f64;
            }
            mean /= n as f64;
            assert!((mean - g as f64).abs() < 0.02, "g {g}: mean cosine {mean}");
        }
    }

    /// Free flights in a homogeneous medium scatter at the rate σt: the share that passes a
    /// slab of thickness d is exp(−σt d) (weighted by the albedo where it scatters), and a grid of
    /// constant density gives the same as the homogeneous medium, by tracking and by ratio
    /// tracking.
    #[test]
    fn free_flights_and_transmittance_match_beer_lambert() {
        let wl = Wavelengths::Rgb;
        let ray = Ray::new(Vec3::ZERO, Vec3::Z);
        let sigma_a = Vec3::new(0.2, 0.5, 1.0);
        let sigma_s = Vec3::new(0.8, 0.5, 0.1);
        let homogeneous = Medium::homogeneous(sigma_a, sigma_s, 0.0);
        let mut grid = homogeneous.clone();
        grid.grid = Some(DensityGrid::new(
            [2, 2, 2],
            vec![0.5; 8],
            Affine3A::from_scale(Vec3::splat(0.1)) * Affine3A::from_translation(Vec3::splat(5.0)),
        ));
        grid.sigma_a *= 2.0;
        grid.sigma_s *= 2.0;
        let d = 1.5;
        let expected = (-(sigma_a + sigma_s) * d).exp();
        for (name, medium) in [("homogeneous", &homogeneous), ("grid", &grid)] {
            let mut rng = Rng::new(9, 1);
            let n = 200_000;
            let (mut passed, mut ratio, mut scattered) = (Vec3::ZERO, Vec3::ZERO, Vec3::ZERO);
            for _ in 0..n {
                let mut throughput = wl.grey(1.0);
                match medium.sample_flight(&ray, (0.0, d), &wl, &mut throughput, &mut rng) {
                    None => passed += throughput.truncate(),
                    Some(_) => scattered += throughput.truncate(),
                }
                ratio += medium.transmittance(&ray, (0.0, d), &wl, &mut rng).truncate();
            }
            let (passed, ratio, scattered) = (passed / n as f32, ratio / n as f32, scattered / n as f32);
            // What scatters carries the albedo's share of what is lost.
            let lost = (Vec3::ONE - expected) * sigma_s / (sigma_a + sigma_s);
            for c in 0..3 {
                assert!(
                    (passed[c] - expected[c]).abs() < 0.01,
                    "{name} passed {passed} vs {expected}"
                );
                assert!(
                    (ratio[c] - expected[c]).abs() < 0.01,
                    "{name} ratio {ratio} vs {expected}"
                );
                assert!(
                    (scattered[c] - lost[c]).abs() < 0.01,
                    "{name} scattered {scattered} vs {lost}"
                );
            }
        }
    }

    /// A grid whose density varies (empty on one side) along an oblique ray that enters and
    /// leaves it, tracked against its largest density and cell by cell.
    #[test]
    fn a_varying_grid_keeps_exp_minus_its_optical_depth() {
        let dims = [9, 6, 7];
        let values: Vec<f32> = (0..dims[0] * dims[1] * dims[2])
            .map(|i| {
                let (x, y, z) = (i % dims[0], i / dims[0] % dims[1], i / (dims[0] * dims[1]));
                if x < 4 {
                    0.0
                } else {
                    ((x * 7 + y * 3 + z * 5) % 11) as f32 * 0.3
                }
            })
            .collect();
        let grid = DensityGrid::new(dims, values, Affine3A::from_scale(Vec3::splat(0.5)));
        let ray = Ray::new(Vec3::new(-0.5, 0.3, 0.2), Vec3::new(1.0, 0.5, 0.6).normalize());
        for cells in [false, true] {
            let depth = keeps_exp_minus_optical_depth(grid.clone().with_majorant_grid(cells), &ray, (0.0, 4.0));
            assert!(depth > 0.5, "the ray crosses some density: {depth}");
        }
    }

    /// A sparse grid (a small dense blob in a corner) is tracked cell by cell, each cell's
    /// majorant bounding every density in it (along random rays, the spans of the cells are
    /// contiguous and cover the ray), and keeps exp(−σt ∫ density) along rays that miss the
    /// blob, graze it and cross it.
    #[test]
    fn a_sparse_grid_is_tracked_cell_by_cell() {
        let n = 40;
        let values: Vec<f32> = (0..n * n * n)
            .map(|i| {
                let p = Vec3::new((i % n) as f32, (i / n % n) as f32, (i / (n * n)) as f32) + 0.5;
                let r2 = (p / n as f32 - Vec3::new(0.3, 0.35, 0.4)).length_squared();
                5.0 * (-r2 / (2.0 * 0.06 * 0.06)).exp()
            })
            .collect();
        let to_grid = Affine3A::from_scale(Vec3::splat(0.5)) * Affine3A::from_translation(Vec3::ONE);
        let grid = DensityGrid::new([n, n, n], values, to_grid);
        assert!(grid.has_majorant_grid(), "a sparse grid walks its cells");
        let mut rng = Rng::new(5, 5);
        for _ in 0..2000 {
            let origin = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, -1.5) * 2.0;
            let target = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - 1.0;
            let ray = Ray::new(origin, (target - origin).normalize());
            let Some((a, b)) = grid.clip(&ray, (0.0, 10.0)) else {
                continue;
            };
            let majorants = grid.majorants.as_ref().unwrap();
            let (o, d) = (to_grid.transform_point3(ray.origin), to_grid.transform_vector3(ray.dir));
            let mut reached = a;
            majorants.walk((o, d), (a, b), |(t0, t1), max| {
                assert!((t0 - reached).abs() < 1e-5, "spans meet: {reached} then {t0}");
                for i in 0..8 {
                    let t = t0 + (t1 - t0) * (i as f32 + 0.5) / 8.0;
                    let density = grid.density(ray.at(t));
                    assert!(density <= max * (1.0 + 1e-5), "{density} over the cell's {max}");
                }
                reached = t1;
                true
            });
            assert!((reached - b).abs() < 1e-4, "the spans reach {reached}, not {b}");
        }
        let mut depths = Vec::new();
        for (origin, target) in [
            (Vec3::new(-1.5, 0.9, 0.9), Vec3::new(0.0, 0.9, 0.9)),
            (Vec3::new(-1.5, -0.3, -0.2), Vec3::new(0.0, -0.3, -0.2)),
            (Vec3::new(-1.5, -1.5, -1.5), Vec3::new(0.0, -0.4, -0.2)),
        ] {
            let ray = Ray::new(origin, (target - origin).normalize());
            depths.push(keeps_exp_minus_optical_depth(grid.clone(), &ray, (0.0, 6.0)));
        }
        assert!(
            depths[0] < 1e-3 && depths[1] > 1.0,
            "one ray misses, one crosses: {depths:?}"
        );
    }

    /// Along `ray` from `t0` to `t1` in a medium of density `grid`: the share of free flights
    /// that pass, weighted, and ratio tracking both give exp(−σt ∫ density), the integral
    /// taken by the midpoint rule.
    fn keeps_exp_minus_optical_depth(grid: DensityGrid, ray: &Ray, (t0, t1): (f32, f32)) -> f32 {
        let wl = Wavelengths::Rgb;
        let mut medium = Medium::homogeneous(Vec3::new(0.3, 0.2, 0.1), Vec3::new(0.4, 0.3, 0.2), 0.0);
        medium.grid = Some(grid.clone());
        let n = 200_000;
        let depth: f32 = (0..n)
            .map(|i| grid.density(ray.at(t0 + (t1 - t0) * (i as f32 + 0.5) / n as f32)))
            .sum::<f32>()
            * (t1 - t0)
            / n as f32;
        let expected = (-(medium.sigma_a + medium.sigma_s) * depth).exp();
        let (mut passed, mut ratio) = (Vec3::ZERO, Vec3::ZERO);
        let mut rng = Rng::new(4, 4);
        let runs = 100_000;
        for _ in 0..runs {
            let mut throughput = wl.grey(1.0);
            if medium
                .sample_flight(ray, (t0, t1), &wl, &mut throughput, &mut rng)
                .is_none()
            {
                passed += throughput.truncate();
            }
            ratio += medium.transmittance(ray, (t0, t1), &wl, &mut rng).truncate();
        }
        let (passed, ratio) = (passed / runs as f32, ratio / runs as f32);
        for c in 0..3 {
            assert!((passed[c] - expected[c]).abs() < 0.01, "passed {passed} vs {expected}");
            assert!((ratio[c] - expected[c]).abs() < 0.01, "ratio {ratio} vs {expected}");
        }
        depth
    }

    /// A coloured glass only absorbs: its flight is Beer–Lambert exactly, and a clear medium
    /// changes nothing.
    #[test]
    fn absorbing_and_clear_media_are_exact() {
        let wl = Wavelengths::Rgb;
        let ray = Ray::new(Vec3::ZERO, Vec3::X);
        let mut rng = Rng::new(1, 2);
        let glass = Medium::homogeneous(Vec3::new(0.5, 0.0, 2.0), Vec3::ZERO, 0.0);
        let mut t = wl.grey(1.0);
        assert_eq!(glass.sample_flight(&ray, (0.0, 2.0), &wl, &mut t, &mut rng), None);
        assert_eq!(t, beer_lambert(Vec3::new(0.5, 0.0, 2.0), 2.0, &wl));
        let clear = Medium::homogeneous(Vec3::ZERO, Vec3::ZERO, 0.0);
        let mut t = wl.grey(1.0);
        assert_eq!(
            clear.sample_flight(&ray, (0.0, f32::INFINITY), &wl, &mut t, &mut rng),
            None
        );
        assert_eq!(t, wl.grey(1.0));
        assert_eq!(
            clear.transmittance(&ray, (0.0, f32::INFINITY), &wl, &mut rng),
            wl.grey(1.0)
        );
    }
}
