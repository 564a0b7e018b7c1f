//! Spectral light for the physical model: the wavelengths a path carries, colours turned into
//! smooth spectra, dispersion, and the conversion back to RGB.
//!
//! **Values.** Light along a path is a [`Spectrum`] of four values. In RGB mode they are the
//! red, green and blue channels (the fourth is unused and zero); in spectral mode they are the
//! radiance at four wavelengths chosen per path or per pass (hero-wavelength sampling, Wilkie
//! et al. 2014): the first one, the hero, decides at dispersive interfaces, where the others are
//! dropped ([`Wavelengths::terminate_secondary`]).
//!
//! **Colour.** CIE 1931 colour matching functions by the analytic multi-lobe fit of Wyman,
//! Sloan and Shirley (JCGT 2013). The renderer's white is the equal-energy spectrum: the XYZ to
//! linear sRGB matrix is balanced so that a constant spectrum gives RGB (1, 1, 1), and every RGB
//! colour of a scene (reflectances, lights, sky maps) becomes a smooth spectrum whose RGB under
//! that white is the colour again — so a scene without dispersive material renders as in RGB
//! mode, up to how products of spectra differ from products of RGB triples over several bounces.
//!
//! **Smooth spectra.** A reflectance is s(λ) = S(c₀ + c₁t + c₂t²), t = (λ − 360)/470,
//! S(x) = ½ + x / (2√(1 + x²)) — the sigmoid-of-a-quadratic model of Jakob and Hanika (CGF 2019),
//! always in (0, 1) and smooth. The coefficients come from a table over the RGB cube fitted at
//! first use by Gauss–Newton on the RGB residual, in Jakob and Hanika's layout (the largest
//! component, the other two relative to it), interpolated trilinearly. Colours above 1 (lights)
//! are scaled: s = 2m·fit(rgb / 2m) for m the largest component.

use crate::math::{Vec3, Vec4};
use rayon::prelude::*;
use std::sync::OnceLock;

/// Light at the four wavelengths (or RGB channels) of a path.
pub type Spectrum = Vec4;

/// The visible range the wavelengths are drawn from, in nm.
pub const LAMBDA_MIN: f32 = 360.0;
/// The visible range's end, in nm.
pub const LAMBDA_MAX: f32 = 830.0;
/// Wavelengths a path carries.
pub const SAMPLES: usize = 4;

/// Fraunhofer lines for dispersion: F (hydrogen), d (helium), C (hydrogen), in nm.
pub const LAMBDA_F: f32 = 486.1327;
/// The d line, where `index` is given.
pub const LAMBDA_D: f32 = 587.5618;
/// The C line.
pub const LAMBDA_C: f32 = 656.2725;

/// The index of refraction at `lambda` nm of a glass with index `n_d` at the d line and Abbe
/// number `abbe`, by Cauchy's law n = A + B/λ² through n_d with n_F − n_C = (n_d − 1)/V.
pub fn cauchy_index(n_d: f32, abbe: f32, lambda: f32) -> f32 {
    let (n_d, v, l) = (n_d as f64, abbe as f64, lambda as f64);
    let (f, d, c) = (LAMBDA_F as f64, LAMBDA_D as f64, LAMBDA_C as f64);
    let b = (n_d - 1.0) / (v * (1.0 / (f * f) - 1.0 / (c * c)));
    let a = n_d - b / (d * d);
    (a + b / (l * l)) as f32
}

/// The wavelength in nm that the course model's colour channels stand for when a dispersive
/// glass gives each its own index: the dominant wavelengths of the sRGB primaries.
pub const CHANNEL_WAVELENGTHS: [f32; 3] = [611.0, 549.0, 464.0];

/// One lobe of the analytic colour-matching fit: a Gaussian with different widths each side.
#[inline]
fn lobe(lambda: f32, mu: f32, sigma_low: f32, sigma_high: f32) -> f32 {
    let t = (lambda - mu) / if lambda < mu { sigma_low } else { sigma_high };
    (-0.5 * t * t).exp()
}

/// CIE 1931 2° colour matching functions x̄, ȳ, z̄ at `lambda` nm (Wyman, Sloan and Shirley's
/// multi-lobe fit; within 0.015, 0.009 and 0.034 of the tabulated functions).
#[inline]
pub fn cie_xyz(lambda: f32) -> Vec3 {
    let x = 1.056 * lobe(lambda, 599.8, 37.9, 31.0) + 0.362 * lobe(lambda, 442.0, 16.0, 26.7)
        - 0.065 * lobe(lambda, 501.1, 20.4, 26.2);
    let y = 0.821 * lobe(lambda, 568.8, 46.9, 40.5) + 0.286 * lobe(lambda, 530.9, 16.3, 31.1);
    let z = 1.217 * lobe(lambda, 437.0, 11.8, 36.0) + 0.681 * lobe(lambda, 459.0, 26.0, 13.8);
    Vec3::new(x, y, z)
}

/// XYZ to linear sRGB (IEC 61966-2-1), rows.
const XYZ_TO_SRGB: [[f32; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266, 1.876_010_8, 0.041_556],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

/// Quadrature of the visible range: 1 nm steps.
const QUADRATURE_STEP: f32 = 1.0;

/// The colour conversion: each wavelength's RGB contribution (the balanced matrix applied to the
/// matching functions), tabulated at 1 nm.
struct Colour {
    /// RGB of a unit of radiance at each integer wavelength from 360 nm, per nm.
    rgb_per_nm: Vec<Vec3>,
}

impl Colour {
    fn get() -> &'static Colour {
        static COLOUR: OnceLock<Colour> = OnceLock::new();
        COLOUR.get_or_init(|| {
            let srgb = |xyz: Vec3| {
                Vec3::new(
                    XYZ_TO_SRGB[0][0] * xyz.x + XYZ_TO_SRGB[0][1] * xyz.y + XYZ_TO_SRGB[0][2] * xyz.z,
                    XYZ_TO_SRGB[1][0] * xyz.x + XYZ_TO_SRGB[1][1] * xyz.y + XYZ_TO_SRGB[1][2] * xyz.z,
                    XYZ_TO_SRGB[2][0] * xyz.x + XYZ_TO_SRGB[2][1] * xyz.y + XYZ_TO_SRGB[2][2] * xyz.z,
                )
            };
            let n = ((LAMBDA_MAX - LAMBDA_MIN) / QUADRATURE_STEP) as usize + 1;
            let raw: Vec<Vec3> = (0..n).map(|i| srgb(cie_xyz(LAMBDA_MIN + i as f32))).collect();
            // Balance: the equal-energy spectrum integrates to white.
            let white: Vec3 = trapezoid(&raw);
            let rgb_per_nm = raw.iter().map(|c| *c / white).collect();
            Colour { rgb_per_nm }
        })
    }

    /// The RGB of a unit of radiance per nm at `lambda` (linear between the tabulated nm).
    fn rgb_at(&self, lambda: f32) -> Vec3 {
        let x = (lambda - LAMBDA_MIN).clamp(0.0, LAMBDA_MAX - LAMBDA_MIN);
        let i = (x as usize).min(self.rgb_per_nm.len() - 2);
        let f = x - i as f32;
        self.rgb_per_nm[i] * (1.0 - f) + self.rgb_per_nm[i + 1] * f
    }
}

/// The trapezoid rule over values at 1 nm steps.
fn trapezoid(values: &[Vec3]) -> Vec3 {
    let n = values.len();
    let inner: Vec3 = values[1..n - 1].iter().copied().sum();
    (inner + 0.5 * (values[0] + values[n - 1])) * QUADRATURE_STEP
}

/// The RGB (under the equal-energy white) of the spectrum `s`, by quadrature.
pub fn spectrum_to_rgb(s: impl Fn(f32) -> f32) -> Vec3 {
    let colour = Colour::get();
    let values: Vec<Vec3> = colour
        .rgb_per_nm
        .iter()
        .enumerate()
        .map(|(i, c)| *c * s(LAMBDA_MIN + i as f32))
        .collect();
    trapezoid(&values)
}

/// Density of the visible-wavelength sampling (that of pbrt-v4's `SampleVisibleWavelengths`):
/// 0.0039398042 / cosh²(0.0072 (λ − 538)) on [360, 830], which follows the eye's sensitivity.
#[inline]
pub fn visible_pdf(lambda: f32) -> f32 {
    if !(LAMBDA_MIN..=LAMBDA_MAX).contains(&lambda) {
        return 0.0;
    }
    let c = (0.0072 * (lambda - 538.0)).cosh();
    0.003_939_804 / (c * c)
}

/// A wavelength drawn from [`visible_pdf`].
#[inline]
pub fn sample_visible(u: f32) -> f32 {
    (538.0 - 138.888_89 * (0.856_910_6 - 1.827_502 * u).atanh()).clamp(LAMBDA_MIN, LAMBDA_MAX)
}

/// The wavelengths a path carries, or RGB channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Wavelengths {
    /// The channels are red, green and blue.
    Rgb,
    /// Four wavelengths in nm with the densities they were drawn with.
    Sampled {
        /// Wavelengths, the hero first.
        lambda: [f32; SAMPLES],
        /// Their densities.
        pdf: [f32; SAMPLES],
    },
}

/// Fits the table that turns colours into spectra now, if it is not yet (it takes a few tenths
/// of a second, once per process), so that a timed part of a render does not pay for it.
pub fn prepare() {
    Uplift::get();
}

/// A reflectance colour at sampled wavelengths `lambda` (the sigmoid-polynomial fit of `rgb`).
#[inline(never)]
fn sampled_reflectance(lambda: &[f32; SAMPLES], rgb: Vec3) -> Spectrum {
    let c = Uplift::get().coefficients(rgb.clamp(Vec3::ZERO, Vec3::ONE));
    Vec4::from_array(lambda.map(|l| c.eval(l)))
}

impl Wavelengths {
    /// Four wavelengths from one uniform number: the hero from `u`, the others from u + i/4,
    /// each distributed by [`visible_pdf`] and together stratified.
    pub fn sample(u: f32) -> Wavelengths {
        let mut lambda = [0.0; SAMPLES];
        let mut pdf = [0.0; SAMPLES];
        for i in 0..SAMPLES {
            let ui = (u + i as f32 / SAMPLES as f32).fract();
            lambda[i] = sample_visible(ui);
            pdf[i] = visible_pdf(lambda[i]);
        }
        Wavelengths::Sampled { lambda, pdf }
    }

    /// One wavelength alone (its density 1): what a test of a single wavelength traces.
    pub fn single(lambda: f32) -> Wavelengths {
        Wavelengths::Sampled {
            lambda: [lambda; SAMPLES],
            pdf: [1.0, 0.0, 0.0, 0.0],
        }
    }

    /// Whether these are wavelengths rather than RGB channels.
    pub fn is_spectral(&self) -> bool {
        matches!(self, Wavelengths::Sampled { .. })
    }

    /// The hero wavelength (none in RGB mode).
    pub fn hero(&self) -> Option<f32> {
        match self {
            Wavelengths::Rgb => None,
            Wavelengths::Sampled { lambda, .. } => Some(lambda[0]),
        }
    }

    /// A reflectance colour (components in [0, 1]) at these wavelengths.
    #[inline(always)]
    pub fn reflectance(&self, rgb: Vec3) -> Spectrum {
        match self {
            // Kept inline: every surface hit asks for four colours, and in RGB mode a call
            // costs more than the answer.
            Wavelengths::Rgb => rgb.extend(0.0),
            Wavelengths::Sampled { lambda, .. } => sampled_reflectance(lambda, rgb),
        }
    }

    /// A colour of any positive size (a light's, a sky's) at these wavelengths.
    #[inline]
    pub fn unbounded(&self, rgb: Vec3) -> Spectrum {
        match self {
            Wavelengths::Rgb => rgb.extend(0.0),
            Wavelengths::Sampled { .. } => {
                let rgb = rgb.max(Vec3::ZERO);
                let m = rgb.max_element();
                if !(m > 0.0 && m.is_finite()) {
                    return Vec4::ZERO;
                }
                self.reflectance(rgb / (2.0 * m)) * (2.0 * m)
            }
        }
    }

    /// A grey value: the same at every wavelength or channel.
    #[inline]
    pub fn grey(&self, value: f32) -> Spectrum {
        match self {
            Wavelengths::Rgb => Vec4::new(value, value, value, 0.0),
            Wavelengths::Sampled { .. } => Vec4::splat(value),
        }
    }

    /// The RGB of the light `s` carried at these wavelengths (the Monte Carlo estimate of
    /// ∫ s(λ) rgb(λ) dλ over the four).
    #[inline]
    pub fn to_rgb(&self, s: Spectrum) -> Vec3 {
        match self {
            Wavelengths::Rgb => s.truncate(),
            Wavelengths::Sampled { lambda, pdf } => {
                let colour = Colour::get();
                let mut rgb = Vec3::ZERO;
                for i in 0..SAMPLES {
                    if pdf[i] > 0.0 && s[i] != 0.0 {
                        rgb += colour.rgb_at(lambda[i]) * (s[i] / pdf[i]);
                    }
                }
                rgb / SAMPLES as f32
            }
        }
    }

    /// A dispersive interface: only the hero wavelength can follow the direction it takes, so
    /// the others are dropped from `s` and the hero carries the whole estimate (its value times
    /// the number of wavelengths, which cancels the average in [`Wavelengths::to_rgb`]). Once
    /// per path: `terminated` remembers it.
    #[inline]
    pub fn terminate_secondary(&self, s: &mut Spectrum, terminated: &mut bool) {
        if self.is_spectral() && !*terminated {
            *s = Vec4::new(s.x * SAMPLES as f32, 0.0, 0.0, 0.0);
            *terminated = true;
        }
    }
}

/// Sigmoid-polynomial coefficients of a reflectance spectrum (in t = (λ − 360)/470).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SigmoidPolynomial(pub [f32; 3]);

impl SigmoidPolynomial {
    /// The reflectance at `lambda` nm.
    #[inline]
    pub fn eval(&self, lambda: f32) -> f32 {
        let t = (lambda - LAMBDA_MIN) / (LAMBDA_MAX - LAMBDA_MIN);
        let x = self.0[0] + t * (self.0[1] + t * self.0[2]);
        if x.is_infinite() {
            return if x > 0.0 { 1.0 } else { 0.0 };
        }
        0.5 + x / (2.0 * (1.0 + x * x).sqrt())
    }

    /// The RGB of this reflectance under the equal-energy white.
    pub fn rgb(&self) -> Vec3 {
        spectrum_to_rgb(|l| self.eval(l))
    }
}

/// The smooth spectrum of the reflectance colour `rgb` (components in [0, 1]), fitted exactly
/// (the table's interpolation can be off by up to 3% for dark, saturated colours): what a
/// material's constant colours use. No table is needed: about 0.1 ms a colour.
pub fn fit_reflectance(rgb: Vec3) -> SigmoidPolynomial {
    let rgb = rgb.clamp(Vec3::ZERO, Vec3::ONE);
    if rgb.x == rgb.y && rgb.y == rgb.z {
        return grey_coefficients(rgb.x);
    }
    let samples = quadrature();
    let project = |c: [f64; 3]| project_rgb(&samples, c);
    let target = [rgb.x as f64, rgb.y as f64, rgb.z as f64];
    // From a flat spectrum of the colour's brightness; the fit tries other shapes if it stalls.
    let seed = grey_coefficients(rgb.max_element().clamp(0.02, 0.98)).0.map(f64::from);
    SigmoidPolynomial(gauss_newton(target, seed, &project).map(|v| v as f32))
}

/// The coefficients of a constant spectrum of value `v`: S(c) = v.
fn grey_coefficients(v: f32) -> SigmoidPolynomial {
    let c = if v <= 0.0 {
        f32::NEG_INFINITY
    } else if v >= 1.0 {
        f32::INFINITY
    } else {
        (v - 0.5) / (v * (1.0 - v)).sqrt()
    };
    SigmoidPolynomial([c, 0.0, 0.0])
}

/// Quadrature nodes for fitting: t = (λ − 360)/470 at 5 nm and each one's RGB weight.
fn quadrature() -> Vec<(f64, [f64; 3])> {
    let colour = Colour::get();
    (0..=94)
        .map(|i| {
            let lambda = LAMBDA_MIN + 5.0 * i as f32;
            let w = colour.rgb_at(lambda) * if i == 0 || i == 94 { 2.5 } else { 5.0 };
            (
                ((lambda - LAMBDA_MIN) / (LAMBDA_MAX - LAMBDA_MIN)) as f64,
                [w.x as f64, w.y as f64, w.z as f64],
            )
        })
        .collect()
}

/// The model's RGB and its derivatives in the coefficients, in one pass over the quadrature.
fn project_rgb(samples: &[(f64, [f64; 3])], c: [f64; 3]) -> ([f64; 3], [[f64; 3]; 3]) {
    let mut rgb = [0.0f64; 3];
    let mut jac = [[0.0f64; 3]; 3];
    for (t, w) in samples {
        let x = c[0] + t * (c[1] + t * c[2]);
        let root = (1.0 + x * x).sqrt();
        let s = 0.5 + x / (2.0 * root);
        let ds = 0.5 / (root * root * root);
        let dc = [ds, ds * t, ds * t * t];
        for i in 0..3 {
            rgb[i] += s * w[i];
            for j in 0..3 {
                jac[i][j] += dc[j] * w[i];
            }
        }
    }
    (rgb, jac)
}

/// Table resolution per axis.
const TABLE_RES: usize = 28;

/// The fitted coefficient table (see the module's note).
struct Uplift {
    /// [largest component][z][y][x] → coefficients.
    table: Vec<[f32; 3]>,
    /// The largest component's value at each z node (denser towards 0 and 1).
    z_nodes: [f32; TABLE_RES],
}

/// The node spacing along the largest component: smoothstep twice, denser near 0 and 1 where
/// the coefficients change fastest.
fn z_node(k: usize) -> f32 {
    let smoothstep = |x: f32| x * x * (3.0 - 2.0 * x);
    smoothstep(smoothstep(k as f32 / (TABLE_RES - 1) as f32))
}

impl Uplift {
    fn get() -> &'static Uplift {
        static UPLIFT: OnceLock<Uplift> = OnceLock::new();
        UPLIFT.get_or_init(Uplift::fit)
    }

    fn fit() -> Uplift {
        let z_nodes: [f32; TABLE_RES] = std::array::from_fn(z_node);
        let mut table = vec![[0.0f32; 3]; 3 * TABLE_RES * TABLE_RES * TABLE_RES];
        let samples = quadrature();
        let project = |c: [f64; 3]| project_rgb(&samples, c);
        // Each (largest component, y) row of the table is fitted on its own, in parallel.
        let rows: Vec<(usize, usize, Vec<[f32; 3]>)> = (0..3 * TABLE_RES)
            .into_par_iter()
            .map(|row| {
                let (largest, y) = (row / TABLE_RES, row % TABLE_RES);
                let mut out = vec![[0.0f32; 3]; TABLE_RES * TABLE_RES];
                // Start from the middle of the z range and walk outwards, each fit seeded by
                // its neighbour's coefficients (they change smoothly along z).
                let start = TABLE_RES / 5;
                for x in 0..TABLE_RES {
                    let mut seed = [0.0f64; 3];
                    let mut at_start = [0.0f64; 3];
                    let order = (start..TABLE_RES).chain((0..start).rev());
                    for k in order {
                        if k == start - 1 {
                            seed = at_start;
                        }
                        let z = z_nodes[k] as f64;
                        let (fx, fy) = (x as f64 / (TABLE_RES - 1) as f64, y as f64 / (TABLE_RES - 1) as f64);
                        let mut target = [0.0f64; 3];
                        target[largest] = z;
                        target[(largest + 1) % 3] = fx * z;
                        target[(largest + 2) % 3] = fy * z;
                        let c = gauss_newton(target, seed, &project);
                        if k == start {
                            at_start = c;
                        }
                        seed = c;
                        out[k * TABLE_RES + x] = c.map(|v| v as f32);
                    }
                }
                (largest, y, out)
            })
            .collect();
        for (largest, y, out) in rows {
            for k in 0..TABLE_RES {
                for x in 0..TABLE_RES {
                    table[index(largest, k, y, x)] = out[k * TABLE_RES + x];
                }
            }
        }
        Uplift { table, z_nodes }
    }

    /// The coefficients of `rgb` (components in [0, 1]), interpolated in the table.
    fn coefficients(&self, rgb: Vec3) -> SigmoidPolynomial {
        let (r, g, b) = (rgb.x, rgb.y, rgb.z);
        if r == g && g == b {
            return grey_coefficients(r);
        }
        let largest = if r >= g && r >= b {
            0
        } else if g >= b {
            1
        } else {
            2
        };
        let z = rgb[largest];
        let x = rgb[(largest + 1) % 3] / z;
        let y = rgb[(largest + 2) % 3] / z;
        let scale = (TABLE_RES - 1) as f32;
        let (xf, yf) = (x * scale, y * scale);
        let (xi, yi) = ((xf as usize).min(TABLE_RES - 2), (yf as usize).min(TABLE_RES - 2));
        let zi = self.z_nodes.partition_point(|&n| n <= z).clamp(1, TABLE_RES - 1) - 1;
        let (dx, dy) = (xf - xi as f32, yf - yi as f32);
        let dz = ((z - self.z_nodes[zi]) / (self.z_nodes[zi + 1] - self.z_nodes[zi])).clamp(0.0, 1.0);
        let mut c = [0.0f32; 3];
        for (k, wz) in [(zi, 1.0 - dz), (zi + 1, dz)] {
            for (j, wy) in [(yi, 1.0 - dy), (yi + 1, dy)] {
                for (i, wx) in [(xi, 1.0 - dx), (xi + 1, dx)] {
                    let w = wx * wy * wz;
                    if w > 0.0 {
                        let node = table_get(&self.table, largest, k, j, i);
                        for (ci, ni) in c.iter_mut().zip(node) {
                            *ci += w * ni;
                        }
                    }
                }
            }
        }
        SigmoidPolynomial(c)
    }
}

fn index(largest: usize, z: usize, y: usize, x: usize) -> usize {
    ((largest * TABLE_RES + z) * TABLE_RES + y) * TABLE_RES + x
}

fn table_get(table: &[[f32; 3]], largest: usize, z: usize, y: usize, x: usize) -> [f32; 3] {
    table[index(largest, z, y, x)]
}

/// Levenberg–Marquardt on the RGB residual of the sigmoid-polynomial model, from `seed`; other
/// starting shapes (a bump, a dip, rising, falling) are tried when it stalls far from the target,
/// and the best fit is kept.
fn gauss_newton(
    target: [f64; 3],
    seed: [f64; 3],
    project: &impl Fn([f64; 3]) -> ([f64; 3], [[f64; 3]; 3]),
) -> [f64; 3] {
    let residual = |c: [f64; 3]| {
        let (rgb, jac) = project(c);
        ([rgb[0] - target[0], rgb[1] - target[1], rgb[2] - target[2]], jac)
    };
    let norm = |r: [f64; 3]| r.iter().map(|v| v * v).sum::<f64>();
    let descend = |start: [f64; 3], iterations: usize| {
        let mut c = start;
        let (mut r, mut jac) = residual(c);
        let mut damping = 1e-3;
        for _ in 0..iterations {
            if norm(r) < 1e-12 {
                break;
            }
            // (JᵀJ + λ·diag(JᵀJ)) δ = Jᵀr
            let mut a = [[0.0f64; 3]; 3];
            let mut g = [0.0f64; 3];
            for p in 0..3 {
                for q in 0..3 {
                    a[p][q] = (0..3).map(|i| jac[i][p] * jac[i][q]).sum();
                }
                g[p] = (0..3).map(|i| jac[i][p] * r[i]).sum();
            }
            let mut improved = false;
            for _ in 0..8 {
                let mut m = a;
                for (p, row) in m.iter_mut().enumerate() {
                    row[p] += damping * a[p][p].max(1e-12);
                }
                let Some(step) = solve3(m, g) else { break };
                let candidate = [c[0] - step[0], c[1] - step[1], c[2] - step[2]];
                if candidate.iter().any(|v| !v.is_finite() || v.abs() > 400.0) {
                    damping *= 10.0;
                    continue;
                }
                let (rc, jc) = residual(candidate);
                if norm(rc) < norm(r) {
                    c = candidate;
                    r = rc;
                    jac = jc;
                    damping = (damping * 0.3).max(1e-9);
                    improved = true;
                    break;
                }
                damping *= 10.0;
            }
            if !improved {
                break;
            }
        }
        (c, norm(r))
    };
    let mut best = descend(seed, 60);
    // Colours outside what a reflectance can give never reach the target: try other shapes only
    // when the fit is clearly off.
    if best.1 > 1e-6 {
        for start in [
            [0.0, 0.0, 0.0],
            [-6.0, 30.0, -30.0],
            [6.0, -30.0, 30.0],
            [-4.0, 8.0, 0.0],
            [4.0, -8.0, 0.0],
        ] {
            let fit = descend(start, 30);
            if fit.1 < best.1 {
                best = fit;
            }
        }
    }
    best.0
}

/// Solves the 3×3 system a·x = b by Cramer's rule; `None` when singular.
fn solve3(a: [[f64; 3]; 3], b: [f64; 3]) -> Option<[f64; 3]> {
    let det = |m: [[f64; 3]; 3]| {
        m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) - m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0])
            + m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])
    };
    let d = det(a);
    if d.abs() < 1e-300 || !d.is_finite() {
        return None;
    }
    let mut x = [0.0; 3];
    for (j, xj) in x.iter_mut().enumerate() {
        let mut m = a;
        for i in 0..3 {
            m[i][j] = b[i];
        }
        *xj = det(m) / d;
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    #[test]
    fn white_is_the_equal_energy_spectrum() {
        let white = spectrum_to_rgb(|_| 1.0);
        assert!((white - Vec3::ONE).abs().max_element() < 1e-5, "{white}");
        // The wavelength sampling estimates the same integral.
        let mut rng = Rng::new(1, 0);
        let mut sum = Vec3::ZERO;
        let n = 20_000;
        for _ in 0..n {
            let wl = Wavelengths::sample(rng.uniform());
            sum += wl.to_rgb(wl.grey(1.0));
        }
        let mean = sum / n as f32;
        assert!((mean - Vec3::ONE).abs().max_element() < 0.01, "{mean}");
        // The matching functions' integrals are near the tabulated 106.9 each.
        let xyz: Vec3 = (360..=830).map(|l| cie_xyz(l as f32)).sum();
        assert!((xyz - Vec3::splat(106.87)).abs().max_element() < 0.3, "{xyz}");
    }

    #[test]
    fn visible_sampling_follows_its_density() {
        let total: f32 = (0..4700)
            .map(|i| visible_pdf(360.0 + (i as f32 + 0.5) * 0.1) * 0.1)
            .sum();
        assert!((total - 1.0).abs() < 1e-3, "{total}");
        for u in [0.01, 0.3, 0.5, 0.77, 0.99] {
            // The inverse CDF: the density's integral up to the sample is u.
            let l = sample_visible(u);
            let cdf: f32 = (0..2000)
                .map(|i| {
                    let x = 360.0 + (l - 360.0) * (i as f32 + 0.5) / 2000.0;
                    visible_pdf(x) * (l - 360.0) / 2000.0
                })
                .sum();
            assert!((cdf - u).abs() < 2e-3, "u {u}: λ {l}, cdf {cdf}");
        }
    }

    /// Every colour of the cube comes back as itself from its fitted spectrum (within 0.3% of the
    /// largest component; 3% through the table alone), and the spectrum stays a reflectance.
    #[test]
    fn smooth_spectra_reproduce_their_colours() {
        let mut rng = Rng::new(2, 0);
        let uplift = Uplift::get();
        let (mut worst, mut worst_table) = (0.0f32, 0.0f32);
        let mut colours: Vec<Vec3> = (0..300)
            .map(|_| Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()))
            .collect();
        colours.extend([
            Vec3::new(0.63, 0.065, 0.05),
            Vec3::new(0.14, 0.45, 0.091),
            Vec3::new(0.9, 0.75, 0.3),
            Vec3::new(0.02, 0.02, 0.6),
            Vec3::splat(0.5),
        ]);
        for rgb in colours {
            let c = fit_reflectance(rgb);
            let back = c.rgb();
            let error = (back - rgb).abs().max_element() / rgb.max_element().max(0.05);
            worst = worst.max(error);
            let table = uplift.coefficients(rgb).rgb();
            worst_table = worst_table.max((table - rgb).abs().max_element() / rgb.max_element().max(0.05));
            for l in [380.0, 450.0, 550.0, 650.0, 780.0] {
                let s = c.eval(l);
                assert!((0.0..=1.0).contains(&s), "{rgb}: s({l}) = {s}");
            }
        }
        assert!(worst < 0.003, "worst relative error {worst}");
        assert!(
            worst_table < 0.03,
            "worst relative error through the table {worst_table}"
        );
    }

    #[test]
    fn cauchy_dispersion_meets_its_definition() {
        let (n_d, v) = (1.5168, 64.17);
        assert!((cauchy_index(n_d, v, LAMBDA_D) - n_d).abs() < 1e-6);
        let spread = cauchy_index(n_d, v, LAMBDA_F) - cauchy_index(n_d, v, LAMBDA_C);
        assert!((spread - (n_d - 1.0) / v).abs() < 1e-6, "{spread}");
        // N-BK7 by Sellmeier at 450 / 550 / 650 nm: 1.52532 / 1.51852 / 1.51452.
        for (l, n) in [(450.0, 1.52532), (550.0, 1.51852), (650.0, 1.51452)] {
            assert!((cauchy_index(n_d, v, l) - n).abs() < 4e-4, "{l}");
        }
    }

    #[test]
    fn terminating_keeps_the_hero_and_its_weight() {
        let wl = Wavelengths::sample(0.3);
        let mut s = Vec4::new(1.0, 2.0, 3.0, 4.0);
        let mut terminated = false;
        wl.terminate_secondary(&mut s, &mut terminated);
        assert_eq!(s, Vec4::new(4.0, 0.0, 0.0, 0.0));
        wl.terminate_secondary(&mut s, &mut terminated);
        assert_eq!(s, Vec4::new(4.0, 0.0, 0.0, 0.0), "once per path");
        let mut rgb = Vec4::new(1.0, 2.0, 3.0, 0.0);
        Wavelengths::Rgb.terminate_secondary(&mut rgb, &mut false);
        assert_eq!(rgb, Vec4::new(1.0, 2.0, 3.0, 0.0), "nothing to drop in RGB mode");
    }
}
