//! Image textures: bilinear lookup with (0, 0) at the bottom-left corner (§6.3).

use crate::math::{Vec2, Vec3};

/// An RGB image in [0, 1] per channel, rows stored top to bottom as in the file.
#[derive(Clone, Debug)]
pub struct Texture {
    width: usize,
    height: usize,
    texels: Vec<Vec3>,
}

impl Texture {
    /// A texture from rows stored top to bottom; `None` if the size does not match.
    pub fn new(width: usize, height: usize, texels: Vec<Vec3>) -> Option<Texture> {
        (width > 0 && height > 0 && texels.len() == width * height).then_some(Texture { width, height, texels })
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.height
    }

    /// The texel in column `x`, row `y` (rows from the top).
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Vec3 {
        self.texels[y * self.width + x]
    }

    /// Bilinearly filtered colour at `uv`, u to the right and v upwards, clamped at the edges.
    pub fn lookup(&self, uv: Vec2) -> Vec3 {
        let x = (uv.x.clamp(0.0, 1.0) * self.width as f32 - 0.5).clamp(0.0, (self.width - 1) as f32);
        let y_up = (uv.y.clamp(0.0, 1.0) * self.height as f32 - 0.5).clamp(0.0, (self.height - 1) as f32);
        let y = (self.height - 1) as f32 - y_up;
        let (x0, y0) = (x.floor() as usize, y.floor() as usize);
        let (x1, y1) = ((x0 + 1).min(self.width - 1), (y0 + 1).min(self.height - 1));
        let (fx, fy) = (x - x0 as f32, y - y0 as f32);
        let at = |xx: usize, yy: usize| self.texels[yy * self.width + xx];
        let top = at(x0, y0).lerp(at(x1, y0), fx);
        let bottom = at(x0, y1).lerp(at(x1, y1), fx);
        top.lerp(bottom, fy)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn origin_is_bottom_left_and_filter_is_bilinear() {
        // Row 0 (top) is red, row 1 (bottom) is blue.
        let red = Vec3::X;
        let blue = Vec3::Z;
        let t = Texture::new(2, 2, vec![red, red, blue, blue]).unwrap();
        assert_eq!(t.lookup(Vec2::new(0.0, 0.0)), blue);
        assert_eq!(t.lookup(Vec2::new(1.0, 1.0)), red);
        let mid = t.lookup(Vec2::new(0.5, 0.5));
        assert!((mid - Vec3::new(0.5, 0.0, 0.5)).length() < 1e-6);
        assert_eq!(t.lookup(Vec2::new(-3.0, 7.0)), red, "clamped outside [0, 1]");
        assert!(Texture::new(2, 2, vec![red]).is_none());
    }
}
