//! Photons: their paths from the lights ([`trace`]), the photon map and its radiance estimates
//! ([`map`]; Jensen, "Rendering Caustics on Non-Lambertian Surfaces", GI 1996), and pictures of
//! them. Photons leave the lights by [`crate::light::emission`].
//!
//! A photon is stored compactly in 24 bytes: position (3 × f32), power as four 8-bit mantissas
//! sharing an 8-bit exponent (Ward's RGBE, as in Jensen's own photon map, with a fourth channel
//! for the physical model's fourth wavelength), the incoming direction in 32-bit octahedral
//! form, the receiver's normal in 16-bit octahedral form, and path flags.

pub mod budget;
pub mod kd_tree;
pub mod kernel;
pub mod light_walk;
pub mod map;
pub mod picture;
pub mod trace;

pub use budget::{NoCaustics, PhotonSettings, PhotonStats};
pub use map::{EstimateSettings, Estimator, PhotonMap};

use crate::math::{round_to_i32, Vec2, Vec3, Vec4};

/// The median distance to the k-th nearest item, measured around up to 256 items spread
/// through `items` (in tree order): how wide a gather of about k photons is where they are
/// typical. 0 for fewer than two items.
pub(crate) fn typical_knn_distance<T: kd_tree::KdPoint>(tree: &kd_tree::KdTree, items: &[T], k: usize) -> f32 {
    let n = items.len();
    if n < 2 || k == 0 {
        return 0.0;
    }
    let samples = 256.min(n);
    let mut out = Vec::new();
    let mut radii: Vec<f32> = (0..samples)
        .map(|i| {
            let p = items[i * n / samples].position();
            tree.k_nearest(items, p, k, f32::INFINITY, &mut out).sqrt()
        })
        .filter(|r| r.is_finite())
        .collect();
    if radii.is_empty() {
        return 0.0;
    }
    radii.sort_by(f32::total_cmp);
    radii[radii.len() / 2]
}

/// The path reached the surface by at least one specular reflection.
pub const REFLECTED: u8 = 1;
/// The path reached the surface by at least one refraction.
pub const REFRACTED: u8 = 2;
/// The path met a smooth (diffuse or glossy) surface before landing (physical model).
pub const DIFFUSE: u8 = 4;
/// The path went through a dispersive glass under spectral transport: only its hero wavelength
/// is left, its power already multiplied by the number of wavelengths. A camera path that
/// dispersed too has made that multiplication itself, so it divides such photons by it again.
pub const DISPERSED: u8 = 8;
/// The four flags of a photon's history; the high four bits of `flags` hold the bounces it had
/// left ([`Photon::bounces_left`]).
pub const HISTORY: u8 = REFLECTED | REFRACTED | DIFFUSE | DISPERSED;
/// The most bounces left a photon records: more read as this many.
pub const MAX_BOUNCES_LEFT: u8 = 15;

/// The least [`Photon::bounces_left`] a photon gathered at a surface needs when the camera path
/// may scatter at `surfaces_left` more surfaces beyond it and photons made at most
/// `max_bounces`: it may then have bounced `surfaces_left` times at most.
#[inline]
pub fn needed_bounces_left(max_bounces: u32, surfaces_left: u32) -> u8 {
    max_bounces.saturating_sub(surfaces_left).min(MAX_BOUNCES_LEFT as u32) as u8
}

/// Whether a photon arrived straight from its light.
#[inline]
pub fn is_direct(photon: &Photon) -> bool {
    photon.flags & HISTORY == 0
}

/// Whether a photon's path was specular only: light, then mirrors and glass (L S+ D).
#[inline]
pub fn is_caustic(photon: &Photon) -> bool {
    photon.flags & HISTORY != 0 && photon.flags & DIFFUSE == 0
}

/// A stored photon.
#[derive(Clone, Copy, Debug, PartialEq)]
#[repr(C)]
pub struct Photon {
    /// Where it landed.
    pub position: Vec3,
    power: [u8; 4],
    direction: [u16; 2],
    normal: [u8; 2],
    exponent: u8,
    /// [`REFLECTED`], [`REFRACTED`], [`DIFFUSE`], [`DISPERSED`] in the low bits; the high four
    /// hold [`Photon::bounces_left`] (physical model).
    pub flags: u8,
}

impl Photon {
    /// Packs a photon of RGB power (the course model); `direction` is the unit direction it
    /// travelled, `normal` the unit surface normal on the side it arrived from.
    pub fn new(position: Vec3, power: Vec3, direction: Vec3, normal: Vec3, flags: u8) -> Photon {
        Photon::with_spectrum(position, power.extend(0.0), direction, normal, flags)
    }

    /// Packs a photon carrying four values: RGB, or four wavelengths (the physical model).
    pub fn with_spectrum(position: Vec3, power: Vec4, direction: Vec3, normal: Vec3, flags: u8) -> Photon {
        let (power, exponent) = encode_shared_exponent(power);
        Photon {
            position,
            power,
            direction: encode_oct16(direction),
            normal: encode_oct8(normal),
            exponent,
            flags,
        }
    }

    /// RGB power (flux): the first three values.
    #[inline]
    pub fn power(&self) -> Vec3 {
        self.spectrum().truncate()
    }

    /// All four values of the power.
    #[inline]
    pub fn spectrum(&self) -> Vec4 {
        decode_shared_exponent(self.power, self.exponent)
    }

    /// Replaces the power.
    pub fn set_power(&mut self, power: Vec3) {
        (self.power, self.exponent) = encode_shared_exponent(power.extend(0.0));
    }

    /// Unit direction of travel.
    #[inline]
    pub fn direction(&self) -> Vec3 {
        decode_oct(Vec2::new(self.direction[0] as f32, self.direction[1] as f32) / 65535.0)
    }

    /// How many more bounces `--depth` would have let the photon make, at most
    /// [`MAX_BOUNCES_LEFT`] (physical model; 0 under the course model): a photon gathered past
    /// the first surface a camera path meets must not bring light from more surfaces than that
    /// path may still count (Jensen's final gather, [`crate::integrator::gi`]).
    #[inline]
    pub fn bounces_left(&self) -> u8 {
        self.flags >> 4
    }

    /// The packed normal: equal codes decode to equal normals.
    #[inline]
    pub fn normal_code(&self) -> [u8; 2] {
        self.normal
    }

    /// Unit normal of the surface it landed on, facing where it came from (8-bit precision).
    #[inline]
    pub fn normal(&self) -> Vec3 {
        decode_oct(Vec2::new(self.normal[0] as f32, self.normal[1] as f32) / 255.0)
    }
}

impl kd_tree::KdPoint for Photon {
    #[inline]
    fn position(&self) -> Vec3 {
        self.position
    }
}

/// Ward's RGBE with a fourth channel: four 8-bit mantissas sharing an 8-bit exponent (rounded
/// to nearest).
fn encode_shared_exponent(c: Vec4) -> ([u8; 4], u8) {
    let c = c.max(Vec4::ZERO);
    let m = c.max_element();
    if m.is_nan() || m <= 1e-32 || !m.is_finite() {
        return ([0; 4], 0);
    }
    // m = f · 2^e with f in [0.5, 1), read from its bits (m is a normal float here).
    let mut e = ((m.to_bits() >> 23) & 0xff) as i32 - 126;
    let mut scale = power_of_two(8 - e);
    if round_to_i32(m * scale) >= 256 {
        e += 1;
        scale *= 0.5;
    }
    let q = |x: f32| round_to_i32(x * scale).min(255) as u8;
    ([q(c.x), q(c.y), q(c.z), q(c.w)], (e + 128).clamp(0, 255) as u8)
}

/// 2^k for an exponent of a normal float, built from its bits.
fn power_of_two(k: i32) -> f32 {
    f32::from_bits(((k + 127) as u32) << 23)
}

fn decode_shared_exponent(c: [u8; 4], exponent: u8) -> Vec4 {
    if exponent == 0 {
        return Vec4::ZERO;
    }
    // 2^(e − 136) built from its bits (a normal float for every stored exponent but the lowest).
    let e = exponent as i32 - 136;
    let f = if e > -127 {
        f32::from_bits(((e + 127) as u32) << 23)
    } else {
        (e as f32).exp2()
    };
    Vec4::new(c[0] as f32, c[1] as f32, c[2] as f32, c[3] as f32) * f
}

/// Octahedral map of a unit vector to [0, 1]².
fn encode_oct(v: Vec3) -> Vec2 {
    let v = v / (v.x.abs() + v.y.abs() + v.z.abs()).max(1e-30);
    let p = if v.z >= 0.0 {
        Vec2::new(v.x, v.y)
    } else {
        Vec2::new((1.0 - v.y.abs()) * v.x.signum(), (1.0 - v.x.abs()) * v.y.signum())
    };
    p * 0.5 + Vec2::splat(0.5)
}

fn decode_oct(e: Vec2) -> Vec3 {
    let p = e * 2.0 - Vec2::ONE;
    let z = 1.0 - p.x.abs() - p.y.abs();
    let t = (-z).max(0.0);
    let x = p.x - t.copysign(p.x);
    let y = p.y - t.copysign(p.y);
    Vec3::new(x, y, z).normalize_or_zero()
}

fn encode_oct16(v: Vec3) -> [u16; 2] {
    let e = encode_oct(v);
    [round_to_i32(e.x * 65535.0) as u16, round_to_i32(e.y * 65535.0) as u16]
}

fn encode_oct8(v: Vec3) -> [u8; 2] {
    let e = encode_oct(v);
    [round_to_i32(e.x * 255.0) as u8, round_to_i32(e.y * 255.0) as u8]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn photon_is_24_bytes() {
        assert_eq!(std::mem::size_of::<Photon>(), 24);
    }

    #[test]
    fn power_round_trips_within_rgbe_precision() {
        for c in [
            Vec3::new(1.0, 0.5, 0.25),
            Vec3::new(3e-6, 1e-6, 0.0),
            Vec3::new(1234.5, 1.0, 700.0),
            Vec3::splat(0.999),
        ] {
            let (m, e) = encode_shared_exponent(c.extend(0.0));
            let back = decode_shared_exponent(m, e).truncate();
            let tol = c.max_element() / 256.0;
            assert!((back - c).abs().max_element() <= tol, "{c:?} -> {back:?}");
        }
        let round_trip = |c: Vec4| {
            let (m, e) = encode_shared_exponent(c);
            decode_shared_exponent(m, e)
        };
        assert_eq!(round_trip(Vec4::ZERO), Vec4::ZERO);
        assert_eq!(round_trip(Vec4::splat(f32::NAN)), Vec4::ZERO);
        let four = Vec4::new(0.5, 2.0, 0.25, 1.5);
        assert!((round_trip(four) - four).abs().max_element() <= 2.0 / 256.0);
    }

    #[test]
    fn rgbe_exponents_decode_exactly() {
        for e in 1..=255u8 {
            let want = Vec3::splat(200.0) * ((e as i32 - 136) as f32).exp2();
            assert_eq!(
                decode_shared_exponent([200, 200, 200, 0], e).truncate(),
                want,
                "exponent byte {e}"
            );
        }
    }

    #[test]
    fn rounding_matches_the_library() {
        let mut x = 0.0f32;
        let mut edges = vec![
            0.0, 0.49999997, 0.5, 0.50000006, 1.5, 2.5, 254.5, 255.49998, 255.5, 65534.5, 8388607.0,
        ];
        while x < 70_000.0 {
            edges.push(x);
            x = x * 1.01 + 0.013;
        }
        for x in edges {
            assert_eq!(round_to_i32(x) as u32, x.round() as u32, "{x}");
        }
    }

    #[test]
    fn directions_round_trip() {
        let dirs = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::new(0.3, -0.8, -0.52).normalize(),
            Vec3::new(-0.577, 0.577, 0.577).normalize(),
        ];
        for d in dirs {
            let p = Photon::new(Vec3::ZERO, Vec3::ONE, d, d, 0);
            assert!(p.direction().dot(d) > 0.99999, "{d:?} {:?}", p.direction());
            assert!(p.normal().dot(d) > 0.995);
        }
    }
}
