//! The film: linear RGB pixels, rows from the top, and their conversion to 8-bit output.

use crate::error::Result;
use crate::image_io::{self, ImageFormat};
use crate::math::Vec3;
use std::path::Path;

/// How linear values become 8-bit PNG values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ToneMap {
    /// The course's convention: clamp to [0, 1], scale by 255 and truncate; no gamma. With an
    /// exposure other than 0, the values are first multiplied by 2^exposure.
    Clamp {
        /// Exposure in stops.
        exposure: f32,
    },
    /// Multiply by 2^exposure, map with x / (1 + x) per channel (Reinhard), then encode with
    /// the sRGB transfer curve and round: the physical model's default, and a way to show a
    /// course caustic brighter than 1 without clipping it.
    Reinhard {
        /// Exposure in stops.
        exposure: f32,
    },
    /// Without compression: 2^exposure, clamp, sRGB curve.
    Linear {
        /// Exposure in stops.
        exposure: f32,
    },
}

/// An image of linear RGB values.
#[derive(Clone, Debug, PartialEq)]
pub struct Film {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Pixels, row-major from the top-left.
    pub pixels: Vec<Vec3>,
}

impl Film {
    /// A black film.
    pub fn new(width: usize, height: usize) -> Film {
        Film {
            width,
            height,
            pixels: vec![Vec3::ZERO; width * height],
        }
    }

    /// The pixel at column `x`, row `y` (from the top).
    pub fn pixel(&self, x: usize, y: usize) -> Vec3 {
        self.pixels[y * self.width + x]
    }

    /// Mean over the inclusive rectangle of rows `r0..=r1` and columns `c0..=c1`, leaving out
    /// pixels that are not finite (a reference renderer's stray NaN).
    pub fn region_mean(&self, rows: (usize, usize), cols: (usize, usize)) -> Vec3 {
        let mut sum = Vec3::ZERO;
        let mut n = 0.0;
        for y in rows.0..=rows.1.min(self.height - 1) {
            for x in cols.0..=cols.1.min(self.width - 1) {
                let p = self.pixel(x, y);
                if p.is_finite() {
                    sum += p;
                    n += 1.0;
                }
            }
        }
        sum / n
    }

    /// 8-bit RGB bytes under `tone_map`.
    pub fn to_rgb8(&self, tone_map: ToneMap) -> Vec<u8> {
        // The exposure's factor once, not per value (the same bytes).
        let scale = exposure_scale(tone_map);
        let mut bytes = vec![0; self.pixels.len() * 3];
        for (rgb, p) in bytes.chunks_exact_mut(3).zip(&self.pixels) {
            rgb[0] = encode_scaled(p.x, tone_map, scale);
            rgb[1] = encode_scaled(p.y, tone_map, scale);
            rgb[2] = encode_scaled(p.z, tone_map, scale);
        }
        bytes
    }

    /// Writes the film as PNG or EXR by the extension of `path`, atomically.
    pub fn save(&self, path: &Path, tone_map: ToneMap) -> Result<()> {
        match ImageFormat::from_path(path)? {
            ImageFormat::Png => image_io::write_png(path, self.width, self.height, &self.to_rgb8(tone_map)),
            ImageFormat::Exr => image_io::write_exr(path, self.width, self.height, &self.pixels),
        }
    }
}

/// 2^exposure, the factor a tone map applies first.
fn exposure_scale(tone_map: ToneMap) -> f32 {
    match tone_map {
        ToneMap::Clamp { exposure } | ToneMap::Reinhard { exposure } | ToneMap::Linear { exposure } => exposure.exp2(),
    }
}

#[cfg(test)]
fn encode_channel(c: f32, tone_map: ToneMap) -> u8 {
    encode_scaled(c, tone_map, exposure_scale(tone_map))
}

/// One channel under `tone_map`, whose exposure factor is `scale`.
fn encode_scaled(c: f32, tone_map: ToneMap, scale: f32) -> u8 {
    let c = if c.is_finite() { c } else { 0.0 };
    match tone_map {
        ToneMap::Clamp { .. } => ((c * scale).clamp(0.0, 1.0) * 255.0) as u8,
        ToneMap::Reinhard { .. } => {
            let x = (c * scale).max(0.0);
            (srgb_encode(x / (1.0 + x)) * 255.0).round() as u8
        }
        ToneMap::Linear { .. } => (srgb_encode((c * scale).clamp(0.0, 1.0)) * 255.0).round() as u8,
    }
}

/// The sRGB transfer curve for a linear value in [0, 1].
pub fn srgb_encode(x: f32) -> f32 {
    if x <= 0.0031308 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn course_conversion_clamps_and_truncates() {
        assert_eq!(encode_channel(0.5, ToneMap::Clamp { exposure: 0.0 }), 127);
        assert_eq!(encode_channel(7.0, ToneMap::Clamp { exposure: 0.0 }), 255);
        assert_eq!(encode_channel(-1.0, ToneMap::Clamp { exposure: 0.0 }), 0);
        assert_eq!(encode_channel(f32::NAN, ToneMap::Clamp { exposure: 0.0 }), 0);
        // One stop down halves the value before clamping.
        assert_eq!(encode_channel(1.0, ToneMap::Clamp { exposure: -1.0 }), 127);
    }

    /// A NaN pixel is left out of a region's mean, not spread over it.
    #[test]
    fn region_means_leave_out_pixels_that_are_not_finite() {
        let mut film = Film::new(2, 2);
        film.pixels = vec![
            Vec3::ONE,
            Vec3::splat(3.0),
            Vec3::new(f32::NAN, 0.0, 0.0),
            Vec3::splat(f32::INFINITY),
        ];
        assert_eq!(film.region_mean((0, 1), (0, 1)), Vec3::splat(2.0));
        assert_eq!(film.region_mean((0, 0), (1, 1)), Vec3::splat(3.0));
    }

    #[test]
    fn srgb_and_reinhard() {
        assert!((srgb_encode(0.5) - 0.7354).abs() < 1e-3);
        // x = 1 maps to 0.5 before the sRGB curve.
        assert_eq!(
            encode_channel(1.0, ToneMap::Reinhard { exposure: 0.0 }),
            (srgb_encode(0.5) * 255.0).round() as u8
        );
        assert_eq!(encode_channel(0.25, ToneMap::Linear { exposure: 2.0 }), 255);
    }
}
