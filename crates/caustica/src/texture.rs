//! Image textures: an image of linear RGB texels and how a material samples it — a transform
//! of the texture coordinates, the wrap of each axis, the filter and a factor. (0, 0) is the
//! image's bottom-left corner (§6.3); readers whose formats put v downwards flip it.

pub mod bump;

use crate::math::{floor_to_i64, Affine2, Vec2, Vec3};
use std::sync::Arc;

/// Where an image's bytes are.
#[derive(Clone, Debug, PartialEq)]
pub enum ImageSource {
    /// A file, its path resolved against the scene file's folder.
    File(std::path::PathBuf),
    /// Bytes held in the scene file (a GLB's binary chunk, a data URI), named for messages
    /// as `file#images[i]`.
    Memory {
        /// The name messages use.
        name: String,
        /// The encoded image (PNG, JPEG, …).
        bytes: std::sync::Arc<[u8]>,
    },
    /// Pixels given as numbers (an array from Python), rows from the top, `channels` values a
    /// pixel (1 grey, 2 grey and alpha, 3 RGB, 4 RGBA).
    Pixels {
        /// The name messages use.
        name: String,
        /// Pixels per row.
        width: usize,
        /// Rows.
        height: usize,
        /// Values per pixel, 1 to 4.
        channels: usize,
        /// The values: for an integer array, stored over its largest value (so in [0, 1]) and
        /// decoded by the map's encoding; for a float array, linear as they are.
        values: std::sync::Arc<[f32]>,
        /// Whether the values came from integers (decoded by the encoding) or floats (linear).
        integer: bool,
    },
}

impl ImageSource {
    /// The file's path, or the name of bytes in the scene file.
    pub fn name(&self) -> String {
        match self {
            ImageSource::File(path) => path.display().to_string(),
            ImageSource::Memory { name, .. } | ImageSource::Pixels { name, .. } => name.clone(),
        }
    }
}

/// An RGB image of linear values, rows stored top to bottom as in the file.
#[derive(Clone, Debug)]
pub struct Image {
    width: usize,
    height: usize,
    texels: Texels,
}

/// How an image holds its texels.
#[derive(Clone, Debug)]
enum Texels {
    /// Linear values as they are: float images, and maps worked out from the file's values.
    Linear(Vec<Vec3>),
    /// An 8-bit image's bytes and the linear value of each byte: a quarter of the memory
    /// (large textures spend their time waiting for texels), read back as the same floats.
    Bytes {
        /// R, G, B of each texel.
        rgb: Vec<[u8; 3]>,
        /// The linear value of a stored byte.
        linear: Box<[f32; 256]>,
    },
}

impl Texels {
    fn len(&self) -> usize {
        match self {
            Texels::Linear(texels) => texels.len(),
            Texels::Bytes { rgb, .. } => rgb.len(),
        }
    }
}

impl Image {
    /// An image from rows stored top to bottom; `None` if the size does not match.
    pub fn new(width: usize, height: usize, texels: Vec<Vec3>) -> Option<Image> {
        Image::sized(width, height, Texels::Linear(texels))
    }

    /// An image of 8-bit channels (rows top to bottom), byte `b` meaning `linear[b]`; `None` if
    /// the size does not match.
    pub fn from_bytes(width: usize, height: usize, rgb: Vec<[u8; 3]>, linear: [f32; 256]) -> Option<Image> {
        let linear = Box::new(linear);
        Image::sized(width, height, Texels::Bytes { rgb, linear })
    }

    fn sized(width: usize, height: usize, texels: Texels) -> Option<Image> {
        (width > 0 && height > 0 && texels.len() == width * height).then_some(Image { width, height, texels })
    }

    /// The texel at index `i` (row-major from the top).
    #[inline]
    fn texel(&self, i: usize) -> Vec3 {
        match &self.texels {
            Texels::Linear(texels) => texels[i],
            Texels::Bytes { rgb, linear } => bytes_texel(rgb, linear, i),
        }
    }
}

#[inline(always)]
fn bytes_texel(rgb: &[[u8; 3]], linear: &[f32; 256], i: usize) -> Vec3 {
    let [r, g, b] = rgb[i];
    Vec3::new(linear[usize::from(r)], linear[usize::from(g)], linear[usize::from(b)])
}

/// How an integer image's stored values become linear light (float images are linear).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Encoding {
    /// As stored, over the largest value (data maps, and the course's `.ray` maps).
    Linear,
    /// The sRGB curve (colour maps of glTF, pbrt and OBJ).
    Srgb,
    /// A power law: stored value to the power G (pbrt's `"gamma G"`).
    Gamma(f32),
    /// Not the colour but the alpha channel, as coverage in all three channels (1 where the
    /// image has no alpha).
    Coverage,
    /// Coverage from a mask (OBJ's `map_d`): the alpha channel where the image has one, else
    /// its linear luminance.
    Mask,
    /// A bump map read as a tangent-space normal map (OBJ's `bump`/`map_Bump`), its x and y
    /// times the strength: see [`bump::normals_from_bump`].
    Bump(f32),
}

impl Encoding {
    /// The linear value of a stored value in [0, 1].
    #[inline]
    pub fn to_linear(self, stored: f32) -> f32 {
        match self {
            Encoding::Linear | Encoding::Coverage | Encoding::Mask | Encoding::Bump(_) => stored,
            Encoding::Srgb if stored <= 0.04045 => stored / 12.92,
            Encoding::Srgb => ((stored + 0.055) / 1.055).powf(2.4),
            Encoding::Gamma(g) => stored.max(0.0).powf(g),
        }
    }
}

/// What a texture coordinate outside 0..1 reads, per axis.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Wrap {
    /// The edge texel (the course's `.ray` maps).
    #[default]
    Clamp,
    /// The image tiles (glTF's REPEAT, pbrt's and OBJ's default).
    Repeat,
    /// The image tiles, every other copy mirrored (glTF's MIRRORED_REPEAT).
    Mirror,
    /// Black outside (pbrt's `black`).
    Black,
}

impl Wrap {
    /// The texel index `i` reads on an axis of `n` texels; `None`: black.
    #[inline(always)]
    fn index(self, i: i64, n: usize) -> Option<usize> {
        let n = n as i64;
        Some(match self {
            Wrap::Clamp => i.clamp(0, n - 1),
            Wrap::Repeat => i.rem_euclid(n),
            Wrap::Mirror => {
                let k = i.rem_euclid(2 * n);
                if k < n {
                    k
                } else {
                    2 * n - 1 - k
                }
            }
            Wrap::Black if (0..n).contains(&i) => i,
            Wrap::Black => return None,
        } as usize)
    }
}

/// How a texture is read from its image.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampler {
    /// Wrap of u and of v.
    pub wrap: [Wrap; 2],
    /// Nearest texel instead of bilinear filtering.
    pub nearest: bool,
    /// From the hit's texture coordinates to the image's (both with v upwards).
    pub transform: Affine2,
    /// Multiplies every texel (a glTF factor, pbrt's `scale`).
    pub scale: Vec3,
}

impl Default for Sampler {
    /// The course's maps: clamped, bilinear, as stored.
    fn default() -> Self {
        Sampler {
            wrap: [Wrap::Clamp; 2],
            nearest: false,
            transform: Affine2::IDENTITY,
            scale: Vec3::ONE,
        }
    }
}

/// An image as a material samples it.
#[derive(Clone, Debug)]
pub struct Texture {
    image: Arc<Image>,
    sampler: Sampler,
}

impl Texture {
    /// A texture from rows stored top to bottom, sampled as the course's maps are; `None` if
    /// the size does not match.
    pub fn new(width: usize, height: usize, texels: Vec<Vec3>) -> Option<Texture> {
        Image::new(width, height, texels).map(|image| Texture::sampled(Arc::new(image), Sampler::default()))
    }

    /// `image` read through `sampler`.
    pub fn sampled(image: Arc<Image>, sampler: Sampler) -> Texture {
        Texture { image, sampler }
    }

    /// Width in texels.
    pub fn width(&self) -> usize {
        self.image.width
    }

    /// Height in texels.
    pub fn height(&self) -> usize {
        self.image.height
    }

    /// The stored texel in column `x`, row `y` (rows from the top), without the sampler.
    #[inline]
    pub fn texel(&self, x: usize, y: usize) -> Vec3 {
        self.image.texel(y * self.image.width + x)
    }

    /// The colour at `uv`, u to the right and v upwards: transformed, wrapped, filtered and
    /// scaled by the sampler.
    pub fn lookup(&self, uv: Vec2) -> Vec3 {
        // The storage chosen once, not at each of the four texels.
        match &self.image.texels {
            Texels::Linear(texels) => self.filtered(uv, |i| texels[i]),
            Texels::Bytes { rgb, linear } => self.filtered(uv, |i| bytes_texel(rgb, linear, i)),
        }
    }

    /// [`Texture::lookup`] with texels read by `fetch`.
    #[inline(always)]
    fn filtered(&self, uv: Vec2, fetch: impl Fn(usize) -> Vec3) -> Vec3 {
        // The texel at wrapped column `x` and row `y_up` counted upwards from the bottom;
        // black where either wrapped to nothing.
        let at = |x: Option<usize>, y_up: Option<usize>| match (x, y_up) {
            (Some(x), Some(y)) => fetch((self.image.height - 1 - y) * self.image.width + x),
            _ => Vec3::ZERO,
        };
        let s = &self.sampler;
        let uv = s.transform.transform_point2(uv);
        let (w, h) = (self.image.width, self.image.height);
        // Past ±2^40 texels a coordinate is noise: kept finite so the index stays exact.
        let limit = 1.0e12;
        let (x, y) = (
            (uv.x * w as f32).clamp(-limit, limit),
            (uv.y * h as f32).clamp(-limit, limit),
        );
        if !(x.is_finite() && y.is_finite()) {
            return Vec3::ZERO;
        }
        let [wrap_x, wrap_y] = s.wrap;
        let colour = if s.nearest {
            at(wrap_x.index(floor_to_i64(x), w), wrap_y.index(floor_to_i64(y), h))
        } else {
            let (x, y) = (x - 0.5, y - 0.5);
            let (x0, y0) = (floor_to_i64(x), floor_to_i64(y));
            let (fx, fy) = (x - x0 as f32, y - y0 as f32);
            // Each axis wrapped once for the two texels it reads.
            let (xa, xb) = (wrap_x.index(x0, w), wrap_x.index(x0 + 1, w));
            let (ya, yb) = (wrap_y.index(y0, h), wrap_y.index(y0 + 1, h));
            let bottom = at(xa, ya).lerp(at(xb, ya), fx);
            let top = at(xa, yb).lerp(at(xb, yb), fx);
            bottom.lerp(top, fy)
        };
        colour * s.scale
    }
}

/// The luminance of a linear texel (Rec. 709 weights): a grey mask's coverage, a bump map's height.
#[inline]
pub fn texel_luminance(t: Vec3) -> f32 {
    t.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn image(w: usize, h: usize, texels: Vec<Vec3>) -> Arc<Image> {
        Arc::new(Image::new(w, h, texels).unwrap())
    }

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

    /// One row of four texels 0, 1, 2, 3 read at texel centres beyond the image's edges.
    #[test]
    fn each_wrap_reads_the_texel_its_rule_names() {
        let row = image(4, 1, (0..4).map(|i| Vec3::splat(i as f32)).collect());
        let at = |wrap: Wrap, texel: f32| {
            let sampler = Sampler {
                wrap: [wrap, Wrap::Clamp],
                nearest: true,
                ..Sampler::default()
            };
            Texture::sampled(row.clone(), sampler)
                .lookup(Vec2::new((texel + 0.5) / 4.0, 0.5))
                .x
        };
        for (texel, clamp, repeat, mirror, black) in [
            (-1.0, 0.0, 3.0, 0.0, 0.0),
            (-5.0, 0.0, 3.0, 3.0, 0.0),
            (2.0, 2.0, 2.0, 2.0, 2.0),
            (4.0, 3.0, 0.0, 3.0, 0.0),
            (6.0, 3.0, 2.0, 1.0, 0.0),
            (9.0, 3.0, 1.0, 1.0, 0.0),
        ] {
            assert_eq!(at(Wrap::Clamp, texel), clamp, "clamp at {texel}");
            assert_eq!(at(Wrap::Repeat, texel), repeat, "repeat at {texel}");
            assert_eq!(at(Wrap::Mirror, texel), mirror, "mirror at {texel}");
            assert_eq!(at(Wrap::Black, texel), black, "black at {texel}");
        }
    }

    /// Bilinear filtering across a repeating edge blends the last texel with the first.
    #[test]
    fn a_repeating_edge_filters_across_the_seam() {
        let row = image(2, 1, vec![Vec3::ZERO, Vec3::ONE]);
        let sampler = Sampler {
            wrap: [Wrap::Repeat; 2],
            ..Sampler::default()
        };
        let t = Texture::sampled(row, sampler);
        assert!((t.lookup(Vec2::new(0.0, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((t.lookup(Vec2::new(2.0, 0.5)).x - 0.5).abs() < 1e-6);
        assert!((t.lookup(Vec2::new(0.75, 0.5)).x - 1.0).abs() < 1e-6);
    }

    #[test]
    fn the_transform_and_scale_apply_before_and_after_the_lookup() {
        // Left half black, right half white; the transform mirrors u.
        let row = image(2, 1, vec![Vec3::ZERO, Vec3::ONE]);
        let sampler = Sampler {
            nearest: true,
            transform: Affine2::from_cols(Vec2::new(-1.0, 0.0), Vec2::Y, Vec2::new(1.0, 0.0)),
            scale: Vec3::new(0.5, 0.25, 2.0),
            ..Sampler::default()
        };
        let t = Texture::sampled(row, sampler);
        assert_eq!(t.lookup(Vec2::new(0.1, 0.5)), Vec3::new(0.5, 0.25, 2.0));
        assert_eq!(t.lookup(Vec2::new(0.9, 0.5)), Vec3::ZERO);
        assert_eq!(t.lookup(Vec2::new(f32::NAN, 0.5)), Vec3::ZERO);
    }
}
