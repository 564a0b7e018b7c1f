//! Reading textures and writing images. Every output is written to a temporary file beside the
//! target and renamed over it, so a reader never sees a half-written image.

use crate::error::{Error, Result};
use crate::math::Vec3;
use crate::texture::{texel_luminance, Encoding, Image, ImageSource, Sampler, Texture};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;

mod pfm;

/// Largest texture accepted, in pixels (8192 × 4096): a small compressed file can declare a huge
/// image, and each pixel costs 24 bytes once converted.
const MAX_TEXTURE_PIXELS: u64 = 1 << 25;

/// Loads a texture as the course's `.ray` maps are read: values as stored, clamped, bilinear.
/// PNG, JPEG, BMP, PPM/PGM/PBM or TGA (and EXR, HDR), recognised by content whatever the
/// extension says (TGA, which has no signature, by its extension); 8 or 16 bits per channel,
/// alpha ignored.
pub fn load_texture(path: &Path) -> Result<Texture> {
    let image = load_image(&ImageSource::File(path.to_path_buf()), Encoding::Linear)?;
    Ok(Texture::sampled(Arc::new(image), Sampler::default()))
}

/// Loads an environment map (a file, bytes or pixels given as numbers) as [`load_texture`] does.
pub fn load_environment(source: &ImageSource) -> Result<Texture> {
    let image = load_image(source, Encoding::Linear)?;
    Ok(Texture::sampled(Arc::new(image), Sampler::default()))
}

/// Decodes an image from a file or from bytes held in a scene file into linear values:
/// integer images through `encoding`, float images (EXR, HDR) as stored.
pub fn load_image(source: &ImageSource, encoding: Encoding) -> Result<Image> {
    let image_error = |message: String| Error::Image {
        path: match source {
            ImageSource::File(path) => path.clone(),
            ImageSource::Memory { name, .. } | ImageSource::Pixels { name, .. } => PathBuf::from(name),
        },
        message,
    };
    if let ImageSource::Pixels {
        width,
        height,
        channels,
        values,
        integer,
        ..
    } = source
    {
        let texels = pixels(*width, *height, *channels, values, *integer, encoding).map_err(image_error)?;
        return Image::new(*width, *height, texels).ok_or_else(|| image_error("the image is empty".into()));
    }
    // PFM, which the image crate does not read: floats, linear as they are.
    let pfm = match source {
        ImageSource::File(path) => {
            let mut magic = [0u8; 3];
            let head = std::fs::File::open(path).and_then(|mut f| std::io::Read::read_exact(&mut f, &mut magic));
            if head.is_ok() && pfm::is_pfm(&magic) {
                Some(std::fs::read(path).map_err(|e| image_error(e.to_string()))?)
            } else {
                None
            }
        }
        ImageSource::Memory { bytes, .. } => pfm::is_pfm(bytes).then(|| bytes.to_vec()),
        ImageSource::Pixels { .. } => None,
    };
    let (w, h, texels) = match pfm {
        Some(bytes) => {
            let (w, h, texels) = pfm::decode(&bytes, MAX_TEXTURE_PIXELS).map_err(image_error)?;
            let texels = match encoding {
                // No alpha channel: wholly covered, or masked by luminance.
                Encoding::Coverage => vec![Vec3::ONE; texels.len()],
                Encoding::Mask => texels.iter().map(|&t| Vec3::splat(texel_luminance(t))).collect(),
                _ => texels,
            };
            (w, h, texels)
        }
        None => match decode_with_image_crate(source, encoding, &image_error)? {
            Decoded::Linear(w, h, texels) => (w, h, texels),
            Decoded::Image(image) => return Ok(image),
        },
    };
    let texels = match encoding {
        Encoding::Bump(strength) => crate::texture::bump::normals_from_bump(w, h, &texels, strength),
        _ => texels,
    };
    Image::new(w, h, texels).ok_or_else(|| image_error("the image is empty".into()))
}

/// Linear texels of pixels given as numbers: integer values (over their largest) through
/// `encoding`, float values as they are; coverage from the alpha channel (2 or 4 channels),
/// else 1; a mask's from alpha, else luminance.
fn pixels(
    width: usize,
    height: usize,
    channels: usize,
    values: &[f32],
    integer: bool,
    encoding: Encoding,
) -> std::result::Result<Vec<Vec3>, String> {
    if !(1..=4).contains(&channels) {
        return Err(format!("an image has 1 to 4 channels, not {channels}"));
    }
    if values.len() != width * height * channels {
        return Err(format!(
            "{} values for {width}×{height} pixels of {channels} channels",
            values.len()
        ));
    }
    if (width * height) as u64 > MAX_TEXTURE_PIXELS {
        return Err(format!(
            "the image is {width}×{height}, too large: at most {MAX_TEXTURE_PIXELS} pixels are accepted"
        ));
    }
    let alpha = |p: &[f32]| match channels {
        2 => Some(p[1]),
        4 => Some(p[3]),
        _ => None,
    };
    let colour = |p: &[f32]| {
        let c = if channels >= 3 {
            Vec3::new(p[0], p[1], p[2])
        } else {
            Vec3::splat(p[0])
        };
        if integer {
            Vec3::new(
                encoding.to_linear(c.x),
                encoding.to_linear(c.y),
                encoding.to_linear(c.z),
            )
        } else {
            c
        }
    };
    Ok(values
        .chunks_exact(channels)
        .map(|p| match encoding {
            Encoding::Coverage => Vec3::splat(alpha(p).unwrap_or(1.0)),
            Encoding::Mask => Vec3::splat(alpha(p).unwrap_or_else(|| texel_luminance(colour(p)))),
            _ => colour(p),
        })
        .collect())
}

/// What the image crate's formats decode to.
enum Decoded {
    /// Width, height and linear texels (rows from the top).
    Linear(usize, usize, Vec<Vec3>),
    /// An image whose bytes are kept.
    Image(Image),
}

/// Decodes the formats the image crate reads.
fn decode_with_image_crate(
    source: &ImageSource,
    encoding: Encoding,
    image_error: &dyn Fn(String) -> Error,
) -> Result<Decoded> {
    let decoded = match source {
        ImageSource::File(path) => {
            let reader = || -> Result<image::ImageReader<std::io::BufReader<std::fs::File>>> {
                image::ImageReader::open(path)
                    .and_then(|r| r.with_guessed_format())
                    .map_err(|e| image_error(e.to_string()))
            };
            check_size(reader()?.into_dimensions().map_err(|e| image_error(e.to_string()))?).map_err(image_error)?;
            reader()?.decode()
        }
        ImageSource::Memory { bytes, .. } => {
            let reader = || {
                image::ImageReader::new(std::io::Cursor::new(&bytes[..]))
                    .with_guessed_format()
                    .map_err(|e| image_error(e.to_string()))
            };
            check_size(reader()?.into_dimensions().map_err(|e| image_error(e.to_string()))?).map_err(image_error)?;
            reader()?.decode()
        }
        // Read by `pixels`, never here.
        ImageSource::Pixels { .. } => return Err(image_error("not an encoded image".into())),
    };
    let img = decoded.map_err(|e| image_error(e.to_string()))?;
    let (w, h) = (img.width() as usize, img.height() as usize);
    let texels: Vec<Vec3> = match img.color() {
        _ if encoding == Encoding::Coverage => img.to_rgba32f().pixels().map(|p| Vec3::splat(p[3])).collect(),
        c if encoding == Encoding::Mask && c.has_alpha() => {
            img.to_rgba32f().pixels().map(|p| Vec3::splat(p[3])).collect()
        }
        _ if encoding == Encoding::Mask => img
            .to_rgb32f()
            .pixels()
            .map(|p| Vec3::splat(texel_luminance(Vec3::new(p[0], p[1], p[2]))))
            .collect(),
        image::ColorType::Rgb32F | image::ColorType::Rgba32F => {
            img.to_rgb32f().pixels().map(|p| Vec3::new(p[0], p[1], p[2])).collect()
        }
        // 8-bit images (most textures) keep their bytes, read through a table of their linear
        // values: no power per texel, and a quarter of the memory.
        image::ColorType::L8 | image::ColorType::La8 | image::ColorType::Rgb8 | image::ColorType::Rgba8 => {
            let linear = std::array::from_fn(|v| encoding.to_linear(v as f32 / 255.0));
            let rgb = img.to_rgb8().pixels().map(|p| p.0).collect::<Vec<_>>();
            if !matches!(encoding, Encoding::Bump(_)) {
                let image = Image::from_bytes(w, h, rgb, linear);
                return image
                    .map(Decoded::Image)
                    .ok_or_else(|| image_error("the image is empty".into()));
            }
            rgb.iter()
                .map(|&[r, g, b]| Vec3::new(linear[usize::from(r)], linear[usize::from(g)], linear[usize::from(b)]))
                .collect()
        }
        _ => img
            .to_rgb32f()
            .pixels()
            .map(|p| {
                Vec3::new(
                    encoding.to_linear(p[0]),
                    encoding.to_linear(p[1]),
                    encoding.to_linear(p[2]),
                )
            })
            .collect(),
    };
    Ok(Decoded::Linear(w, h, texels))
}

/// Refuses an image whose header declares more than [`MAX_TEXTURE_PIXELS`], before decoding.
fn check_size((w, h): (u32, u32)) -> std::result::Result<(), String> {
    if u64::from(w) * u64::from(h) > MAX_TEXTURE_PIXELS {
        return Err(format!(
            "the image is {w}×{h}, too large: at most {MAX_TEXTURE_PIXELS} pixels are accepted"
        ));
    }
    Ok(())
}

/// The formats caustica writes, chosen by the output file's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit PNG.
    Png,
    /// Linear 32-bit float OpenEXR.
    Exr,
}

impl ImageFormat {
    /// The format for `path`'s extension, or an error naming the accepted ones.
    pub fn from_path(path: &Path) -> Result<ImageFormat> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase())
        {
            Some(e) if e == "png" => Ok(ImageFormat::Png),
            Some(e) if e == "exr" => Ok(ImageFormat::Exr),
            _ => Err(Error::InvalidSettings(format!(
                "cannot tell the image format of `{}`: use a .png or .exr extension",
                path.display()
            ))),
        }
    }
}

/// Writes 8-bit RGB rows (top to bottom) as PNG, atomically.
pub fn write_png(path: &Path, width: usize, height: usize, rgb8: &[u8]) -> Result<()> {
    write_atomically(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            rgb8,
            width as u32,
            height as u32,
            image::ExtendedColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())
    })
}

/// Writes linear float RGB rows (top to bottom) as OpenEXR, atomically.
pub fn write_exr(path: &Path, width: usize, height: usize, pixels: &[Vec3]) -> Result<()> {
    let data: Vec<f32> = pixels.iter().flat_map(|p| p.to_array()).collect();
    let buffer = image::Rgb32FImage::from_raw(width as u32, height as u32, data).ok_or_else(|| Error::Image {
        path: path.to_path_buf(),
        message: "pixel count does not match the image size".into(),
    })?;
    write_atomically(path, |tmp| {
        image::DynamicImage::ImageRgb32F(buffer)
            .save_with_format(tmp, image::ImageFormat::OpenExr)
            .map_err(|e| e.to_string())
    })
}

/// Reads an OpenEXR file as linear RGB rows (top to bottom).
pub fn read_exr(path: &Path) -> Result<(usize, usize, Vec<Vec3>)> {
    let img = image::open(path).map_err(|e| Error::Image {
        path: path.to_path_buf(),
        message: e.to_string(),
    })?;
    let rgb = img.to_rgb32f();
    let pixels = rgb.pixels().map(|p| Vec3::new(p[0], p[1], p[2])).collect();
    Ok((rgb.width() as usize, rgb.height() as usize, pixels))
}

/// Checks, before any work, that a file can be written at `path` as [`write_atomically`] will:
/// its folder exists and takes a new file (one is created there and removed), and `path` is
/// not a folder.
pub fn check_writable(path: &Path) -> Result<()> {
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let refuse = |why: String| {
        Err(Error::InvalidSettings(format!(
            "cannot write `{}`: {why}",
            path.display()
        )))
    };
    if !folder.is_dir() {
        return refuse(format!("the folder `{}` does not exist", folder.display()));
    }
    if path.is_dir() {
        return refuse("it is a folder".into());
    }
    let probe = temporary_path(path);
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => Ok(()),
        Err(e) => refuse(format!(
            "the folder `{}` does not take new files ({e})",
            folder.display()
        )),
    }
}

/// Runs `write` on a temporary path in the target's directory, then renames it over `path`.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> std::result::Result<(), String>) -> Result<()> {
    let tmp = temporary_path(path);
    if let Err(message) = write(&tmp) {
        let _ = std::fs::remove_file(&tmp);
        return Err(Error::Image {
            path: path.to_path_buf(),
            message,
        });
    }
    std::fs::rename(&tmp, path).map_err(|source| {
        let _ = std::fs::remove_file(&tmp);
        Error::Io {
            path: path.to_path_buf(),
            source,
        }
    })
}

fn temporary_path(path: &Path) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Keep the real extension last: the encoders pick the format from it.
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().into_owned())
        .unwrap_or_default();
    // Numbered per call: two writers of one process (a preview thread, a front end's own threads)
    // never share a temporary file.
    static NEXT: AtomicU64 = AtomicU64::new(0);
    let n = NEXT.fetch_add(1, Ordering::Relaxed);
    path.with_file_name(format!(".{name}.{}-{n}.tmp.{ext}", std::process::id()))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each texture format the course corpora use reads back the texels written (JPEG within its
    /// loss), also under an extension that names another format (but TGA).
    #[test]
    fn every_texture_format_reads_back() {
        let dir = std::env::temp_dir().join(format!("caustica-tex-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Two flat halves (red, blue) that JPEG keeps nearly exact away from the edge.
        let (w, h) = (32u32, 16u32);
        let image = image::RgbImage::from_fn(w, h, |x, _| {
            if x < w / 2 {
                image::Rgb([200, 40, 20])
            } else {
                image::Rgb([10, 60, 230])
            }
        });
        let formats = [
            ("png", image::ImageFormat::Png, 0.0),
            ("jpg", image::ImageFormat::Jpeg, 6.0 / 255.0),
            ("bmp", image::ImageFormat::Bmp, 0.0),
            ("ppm", image::ImageFormat::Pnm, 0.0),
            ("tga", image::ImageFormat::Tga, 0.0),
        ];
        for (ext, format, tolerance) in formats {
            // TGA has no signature: only its extension tells it.
            let misnamed = (ext != "tga").then(|| format!("{ext}-named.bmp"));
            for name in std::iter::once(format!("t.{ext}")).chain(misnamed) {
                let path = dir.join(&name);
                image.save_with_format(&path, format).unwrap();
                let tex = load_texture(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
                assert_eq!((tex.width(), tex.height()), (w as usize, h as usize), "{name}");
                for (x, want) in [(4, [200, 40, 20]), (27, [10, 60, 230])] {
                    let got = tex.lookup(crate::math::Vec2::new((x as f32 + 0.5) / w as f32, 0.5));
                    let want = Vec3::from_array(want.map(|c: u8| c as f32 / 255.0));
                    assert!(
                        (got - want).abs().max_element() <= tolerance + 1e-6,
                        "{name}: {got} vs {want}"
                    );
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An 8-bit image keeps its bytes, and reads back, filtered or not, exactly as the floats
    /// its encoding makes of them.
    #[test]
    fn an_eight_bit_image_reads_as_its_linear_floats() {
        use crate::texture::Wrap;
        let dir = std::env::temp_dir().join(format!("caustica-bytes-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let (w, h) = (37u32, 23u32);
        let mut rng = crate::sampling::Rng::new(7, 0);
        let image = image::RgbImage::from_fn(w, h, |_, _| {
            image::Rgb([0; 3].map(|_: u8| (rng.next_u32() >> 24) as u8))
        });
        let path = dir.join("bytes.png");
        image.save(&path).unwrap();
        for encoding in [Encoding::Srgb, Encoding::Linear, Encoding::Gamma(2.2)] {
            let floats = image
                .pixels()
                .map(|p| Vec3::from_array(p.0.map(|c| encoding.to_linear(f32::from(c) / 255.0))))
                .collect();
            let want = Arc::new(Image::new(w as usize, h as usize, floats).unwrap());
            let got = Arc::new(load_image(&ImageSource::File(path.clone()), encoding).unwrap());
            for (wrap, nearest) in [(Wrap::Repeat, false), (Wrap::Mirror, true), (Wrap::Black, false)] {
                let sampler = Sampler {
                    wrap: [wrap, Wrap::Clamp],
                    nearest,
                    ..Sampler::default()
                };
                let (want, got) = (
                    Texture::sampled(want.clone(), sampler),
                    Texture::sampled(got.clone(), sampler),
                );
                for _ in 0..2000 {
                    let uv = crate::math::Vec2::new(rng.uniform() * 3.0 - 1.0, rng.uniform() * 1.2 - 0.1);
                    assert_eq!(got.lookup(uv), want.lookup(uv), "{encoding:?} {wrap:?} at {uv}");
                }
                for (x, y) in [(0, 0), (36, 22), (17, 5)] {
                    assert_eq!(got.texel(x, y), want.texel(x, y), "{encoding:?} texel ({x}, {y})");
                }
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn png_and_exr_round_trip_and_leave_no_temporary_file() {
        let dir = std::env::temp_dir().join(format!("caustica-io-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let png = dir.join("a.png");
        write_png(&png, 2, 1, &[255, 0, 0, 0, 128, 255]).unwrap();
        let tex = load_texture(&png).unwrap();
        assert_eq!((tex.width(), tex.height()), (2, 1));
        let exr = dir.join("a.exr");
        let pixels = [Vec3::new(0.25, 2.5, 100.0), Vec3::new(0.0, 1e-3, 1.0)];
        write_exr(&exr, 2, 1, &pixels).unwrap();
        let (w, h, back) = read_exr(&exr).unwrap();
        assert_eq!((w, h), (2, 1));
        assert_eq!(back, pixels.to_vec());
        let leftovers = std::fs::read_dir(&dir)
            .unwrap()
            .filter(|e| e.as_ref().unwrap().file_name().to_string_lossy().contains(".tmp"))
            .count();
        assert_eq!(leftovers, 0);
        assert!(ImageFormat::from_path(Path::new("x.jpg")).is_err());
        assert!(load_texture(&dir.join("missing.png")).is_err());
        assert!(check_writable(&dir.join("b.png")).is_ok());
        assert!(check_writable(&dir.join("no-such-folder/b.png")).is_err());
        assert!(check_writable(&dir).is_err(), "a folder is not a file");
        assert!(!dir.join("b.png").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
