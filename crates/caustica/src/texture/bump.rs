//! Bump maps as tangent-space normal maps. OBJ's `bump`/`map_Bump` holds either heights (a
//! grey image) or, as Blender's exporter writes it, a tangent-space normal map (mostly blue);
//! both become normal-map texels once, when the image is decoded, so shading reads one kind.

use crate::math::Vec3;

/// Whether texels in [0, 1] look like a tangent-space normal map: nearly all decode to unit
/// vectors, which on average point out of the surface more than they lean. A grey image fails
/// the second (its three components are equal).
pub fn looks_like_normal_map(texels: &[Vec3]) -> bool {
    if texels.is_empty() {
        return false;
    }
    let decoded = texels.iter().map(|&t| t * 2.0 - Vec3::ONE);
    let unit = decoded.clone().filter(|n| (n.length() - 1.0).abs() < 0.1).count();
    let mean = decoded.fold(Vec3::ZERO, |a, n| a + n) / texels.len() as f32;
    unit as f32 >= 0.9 * texels.len() as f32 && mean.z > 0.5 && mean.z - mean.x.abs().max(mean.y.abs()) > 0.1
}

/// Normal-map texels (components in [−1, 1] stored as [0, 1]) from a bump map of `width` ×
/// `height` texels, rows from the top: a normal map has its x and y times `strength`; heights
/// (the luminance) are turned into normals by central differences that wrap at the edges, a
/// height of 1 rising `strength` texels.
pub fn normals_from_bump(width: usize, height: usize, texels: &[Vec3], strength: f32) -> Vec<Vec3> {
    let strength = if strength.is_finite() { strength } else { 1.0 };
    if looks_like_normal_map(texels) {
        return texels
            .iter()
            .map(|&t| {
                let n = t * 2.0 - Vec3::ONE;
                (Vec3::new(n.x * strength, n.y * strength, n.z) + Vec3::ONE) * 0.5
            })
            .collect();
    }
    let h = |x: usize, y: usize| super::texel_luminance(texels[y * width + x]);
    let mut out = Vec::with_capacity(texels.len());
    for y in 0..height {
        let (up, down) = ((y + height - 1) % height, (y + 1) % height);
        for x in 0..width {
            let (left, right) = ((x + width - 1) % width, (x + 1) % width);
            // u to the right, v upwards (rows run downwards).
            let du = (h(right, y) - h(left, y)) * 0.5;
            let dv = (h(x, up) - h(x, down)) * 0.5;
            let n = Vec3::new(-strength * du, -strength * dv, 1.0).normalize();
            out.push((n + Vec3::ONE) * 0.5);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp of heights rising to the right by 0.1 a texel tilts every normal toward −u by
    /// atan(0.1 × strength); rows give no v slope. A grey image is not taken for a normal map.
    #[test]
    fn a_height_ramp_tilts_normals_against_its_slope() {
        let (w, h) = (8, 3);
        // Luminance 0.1·x on every row; the wrap at the edges makes the end columns differ.
        let texels: Vec<Vec3> = (0..h)
            .flat_map(|_| (0..w).map(|x| Vec3::splat(0.1 * x as f32)))
            .collect();
        assert!(!looks_like_normal_map(&texels));
        let out = normals_from_bump(w, h, &texels, 2.0);
        let n = out[w + 3] * 2.0 - Vec3::ONE;
        let want = Vec3::new(-0.2, 0.0, 1.0).normalize();
        assert!((n - want).length() < 1e-5, "{n} against {want}");
    }

    /// Heights rising upwards in the picture (toward v = 1) tilt normals toward −v.
    #[test]
    fn heights_rising_toward_the_top_row_tilt_toward_minus_v() {
        let (w, h) = (3, 5);
        let texels: Vec<Vec3> = (0..h)
            .flat_map(|y| (0..w).map(move |_| Vec3::splat(0.1 * (h - 1 - y) as f32)))
            .collect();
        let n = normals_from_bump(w, h, &texels, 1.0)[2 * w + 1] * 2.0 - Vec3::ONE;
        assert!(n.y < -0.09 && n.x.abs() < 1e-6, "{n}");
    }

    /// A normal map keeps its z and has x and y scaled.
    #[test]
    fn a_normal_map_is_kept_with_its_lean_scaled() {
        let t = (Vec3::new(0.2, -0.1, 0.97) + Vec3::ONE) * 0.5;
        let texels = vec![t; 4];
        assert!(looks_like_normal_map(&texels));
        let n = normals_from_bump(2, 2, &texels, 0.5)[0] * 2.0 - Vec3::ONE;
        assert!((n - Vec3::new(0.1, -0.05, 0.97)).length() < 1e-5, "{n}");
    }
}
