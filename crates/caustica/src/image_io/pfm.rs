//! Portable float maps (PFM), the float images of Bitterli's scenes and other research files,
//! which the image crate does not read: a text header `PF` (colour) or `Pf` (grey), the width
//! and height, and a scale whose sign gives the byte order (negative: little-endian); then
//! 32-bit floats, rows from the bottom up.

use crate::math::Vec3;

/// Whether `bytes` begin like a PFM file.
pub fn is_pfm(bytes: &[u8]) -> bool {
    bytes.len() >= 3 && (bytes.starts_with(b"PF") || bytes.starts_with(b"Pf")) && bytes[2].is_ascii_whitespace()
}

/// The image's width, height and linear texels, rows from the top. Non-finite values read as
/// black; `max_pixels` bounds the size before anything is allocated.
pub fn decode(bytes: &[u8], max_pixels: u64) -> Result<(usize, usize, Vec<Vec3>), String> {
    let mut at = 0;
    // Header words: the magic, width, height and scale, each followed by whitespace.
    let mut word = || -> Result<&str, String> {
        while at < bytes.len() && bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        let start = at;
        while at < bytes.len() && !bytes[at].is_ascii_whitespace() {
            at += 1;
        }
        if start == at || at >= bytes.len() {
            return Err("the PFM header is cut short".into());
        }
        let word = std::str::from_utf8(&bytes[start..at]).map_err(|_| "the PFM header is not text".to_string())?;
        // The single whitespace byte that ends the word (the last one before the data).
        at += 1;
        Ok(word)
    };
    let channels = match word()? {
        "PF" => 3,
        "Pf" => 1,
        other => return Err(format!("`{other}` is not a PFM header (PF or Pf)")),
    };
    let size = |w: &str| w.parse::<usize>().ok().filter(|&n| n > 0);
    let width = word()?;
    let width = size(width).ok_or_else(|| format!("the PFM width `{width}` is not a positive whole number"))?;
    let height = word()?;
    let height = size(height).ok_or_else(|| format!("the PFM height `{height}` is not a positive whole number"))?;
    let scale = word()?;
    let scale: f32 = scale
        .parse()
        .ok()
        .filter(|s: &f32| s.is_finite() && *s != 0.0)
        .ok_or_else(|| format!("the PFM scale `{scale}` is not a non-zero number"))?;
    let pixels = width as u64 * height as u64;
    if pixels > max_pixels {
        return Err(format!(
            "the image is {width}×{height}, too large: at most {max_pixels} pixels are accepted"
        ));
    }
    let floats = pixels as usize * channels;
    let data = &bytes[at.min(bytes.len())..];
    if data.len() < floats * 4 {
        return Err(format!(
            "the PFM data is cut short: {width}×{height}×{channels} floats need {} bytes, {} are there",
            floats * 4,
            data.len()
        ));
    }
    let read = |i: usize| {
        let b = [data[4 * i], data[4 * i + 1], data[4 * i + 2], data[4 * i + 3]];
        let v = if scale < 0.0 {
            f32::from_le_bytes(b)
        } else {
            f32::from_be_bytes(b)
        };
        if v.is_finite() {
            v
        } else {
            0.0
        }
    };
    let mut texels = Vec::with_capacity(pixels as usize);
    // Stored bottom row first.
    for row in (0..height).rev() {
        for x in 0..width {
            let i = (row * width + x) * channels;
            texels.push(if channels == 3 {
                Vec3::new(read(i), read(i + 1), read(i + 2))
            } else {
                Vec3::splat(read(i))
            });
        }
    }
    Ok((width, height, texels))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(magic: &str, w: usize, h: usize, scale: &str, values: &[f32], little: bool) -> Vec<u8> {
        let mut bytes = format!("{magic}\n{w} {h}\n{scale}\n").into_bytes();
        for v in values {
            bytes.extend(if little { v.to_le_bytes() } else { v.to_be_bytes() });
        }
        bytes
    }

    /// Rows are stored bottom-up; the scale's sign chooses the byte order; grey files fill all
    /// three channels.
    #[test]
    fn colour_and_grey_in_either_byte_order() {
        // Two rows: the bottom one (stored first) 1, 2; the top one 3, 4 (in red).
        let values: Vec<f32> = [1.0, 2.0, 3.0, 4.0].iter().flat_map(|&v| [v, 0.5, -0.25]).collect();
        for little in [true, false] {
            let scale = if little { "-1.0" } else { "1.0" };
            let bytes = file("PF", 2, 2, scale, &values, little);
            assert!(is_pfm(&bytes));
            let (w, h, t) = decode(&bytes, 1 << 20).unwrap();
            assert_eq!((w, h), (2, 2));
            assert_eq!(t.iter().map(|c| c.x).collect::<Vec<_>>(), vec![3.0, 4.0, 1.0, 2.0]);
            assert_eq!((t[0].y, t[0].z), (0.5, -0.25));
        }
        let grey = file("Pf", 3, 1, "-1", &[0.5, f32::NAN, 1e6], true);
        let (_, _, t) = decode(&grey, 1 << 20).unwrap();
        assert_eq!(t, vec![Vec3::splat(0.5), Vec3::ZERO, Vec3::splat(1e6)]);
    }

    /// Cut-short data, bad header words and oversized images are refused with a reason.
    #[test]
    fn bad_files_are_refused_with_a_reason() {
        let short = file("PF", 2, 2, "-1", &[1.0; 11], true);
        assert!(decode(&short, 1 << 20).unwrap_err().contains("cut short"));
        assert!(decode(b"PF\n0 2\n-1\n", 1 << 20).unwrap_err().contains("width"));
        assert!(decode(b"PF\n2 x\n-1\n", 1 << 20).unwrap_err().contains("height"));
        assert!(decode(b"PF\n2 2\n0\n", 1 << 20).unwrap_err().contains("scale"));
        assert!(decode(b"PF\n2 2", 1 << 20).unwrap_err().contains("cut short"));
        assert!(decode(b"P6\n2 2\n255\n", 1 << 20).unwrap_err().contains("not a PFM"));
        let big = file("Pf", 1000, 1000, "-1", &[], true);
        assert!(decode(&big, 1000).unwrap_err().contains("too large"));
        assert!(!is_pfm(b"PFX") && !is_pfm(b"P"));
    }
}
