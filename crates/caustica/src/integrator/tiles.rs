//! The image loop: the image cut into 16×16 tiles rendered in parallel. Each pixel draws from
//! its own random stream (seed, pixel index), so the picture does not depend on the thread
//! count.

use crate::camera::Camera;
use crate::film::Film;
use crate::math::Vec3;
use crate::progress::{Control, PixelBlock};
use crate::sampling::Rng;
use rayon::prelude::*;

/// Image size and sampling.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageSettings {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// N for N×N stratified, jittered samples per pixel (1 samples the pixel centre).
    pub aa: u32,
    /// Seed of all random streams.
    pub seed: u64,
}

const TILE: usize = 16;

/// Renders every pixel with `sample(screen point, rng, pixel state)`, averaging N×N stratified
/// samples; the state starts as `S::default()` for each pixel and is shared by its samples.
/// Returns the film and whether it is complete (false when cancelled).
pub fn render_tiles<S, F>(settings: &ImageSettings, control: Control, phase: &str, sample: F) -> (Film, bool)
where
    S: Default,
    F: Fn(f32, f32, &mut Rng, &mut S) -> Vec3 + Sync,
{
    let (w, h) = (settings.width, settings.height);
    control.progress.start(phase, (w * h) as u64);
    let aa = settings.aa.max(1);
    let inv_samples = 1.0 / (aa * aa) as f32;
    let (pixels, complete) = shade_tiles(w, h, control, true, |x, y| {
        let mut rng = Rng::new(settings.seed, (y * w + x) as u64);
        let mut state = S::default();
        let mut sum = Vec3::ZERO;
        for sy in 0..aa {
            for sx in 0..aa {
                let (jx, jy) = if aa == 1 {
                    (0.5, 0.5)
                } else {
                    (rng.uniform(), rng.uniform())
                };
                let px = x as f32 + (sx as f32 + jx) / aa as f32;
                let py = y as f32 + (sy as f32 + jy) / aa as f32;
                // Screen y runs upwards; film rows run downwards.
                sum += sample(px / w as f32, 1.0 - py / h as f32, &mut rng, &mut state);
            }
        }
        sum * inv_samples
    });
    control.progress.finish();
    let mut film = Film::new(w, h);
    film.pixels = pixels;
    (film, complete)
}

/// Computes `pixel(x, y)` for every pixel, 16×16 tiles in parallel, into rows from the top;
/// tiles not begun before cancellation stay black. With `report`, each finished tile is shown to
/// the progress (for a live preview) and advances it by its pixel count. Returns the pixels and whether every tile was done.
pub(crate) fn shade_tiles<F>(width: usize, height: usize, control: Control, report: bool, pixel: F) -> (Vec<Vec3>, bool)
where
    F: Fn(usize, usize) -> Vec3 + Sync,
{
    shade_tile_blocks(width, height, control, report, |(x0, y0), (x1, y1)| {
        let mut out = Vec::with_capacity((x1 - x0) * (y1 - y0));
        for y in y0..y1 {
            for x in x0..x1 {
                out.push(pixel(x, y));
            }
        }
        out
    })
}

/// [`shade_tiles`] a tile at a time: `tile((x0, y0), (x1, y1))` returns the pixels of the
/// rectangle from `(x0, y0)` to `(x1, y1)` (exclusive), row by row.
pub(crate) fn shade_tile_blocks<F>(
    width: usize,
    height: usize,
    control: Control,
    report: bool,
    tile_pixels: F,
) -> (Vec<Vec3>, bool)
where
    F: Fn((usize, usize), (usize, usize)) -> Vec<Vec3> + Sync,
{
    let tiles_x = width.div_ceil(TILE);
    let tiles_y = height.div_ceil(TILE);
    let tiles: Vec<Option<Vec<Vec3>>> = (0..tiles_x * tiles_y)
        .into_par_iter()
        .map(|tile| {
            if control.cancelled() {
                return None;
            }
            let (x0, y0) = ((tile % tiles_x) * TILE, (tile / tiles_x) * TILE);
            let (x1, y1) = ((x0 + TILE).min(width), (y0 + TILE).min(height));
            let out = tile_pixels((x0, y0), (x1, y1));
            if report {
                control.progress.pixels(&PixelBlock {
                    x: x0,
                    y: y0,
                    width: x1 - x0,
                    height: y1 - y0,
                    pixels: &out,
                });
                control.progress.advance(out.len() as u64);
            }
            Some(out)
        })
        .collect();
    let mut pixels = vec![Vec3::ZERO; width * height];
    let mut complete = true;
    for (tile, values) in tiles.into_iter().enumerate() {
        let Some(values) = values else {
            complete = false;
            continue;
        };
        let (x0, y0) = ((tile % tiles_x) * TILE, (tile / tiles_x) * TILE);
        let tw = (x0 + TILE).min(width) - x0;
        for (i, v) in values.into_iter().enumerate() {
            pixels[(y0 + i / tw) * width + x0 + i % tw] = v;
        }
    }
    (pixels, complete)
}

/// The image size for a camera: `width` as given, height from the aspect ratio unless given.
pub fn image_size(camera: &Camera, width: usize, height: Option<usize>) -> (usize, usize) {
    (width, height.unwrap_or_else(|| camera.height_for_width(width)))
}

/// One jittered sample per pixel of pass `pass`: `sample(sx, sy, rng)` with screen coordinates
/// in [0, 1]² (y up). Tiles run in parallel; the result does not depend on the thread count.
pub fn sample_pass<F>(
    width: usize,
    height: usize,
    seed: u64,
    pass: u64,
    control: Control,
    sample: F,
) -> Option<Vec<Vec3>>
where
    F: Fn(f32, f32, &mut Rng) -> Vec3 + Sync,
{
    sample_pass_tiles(width, height, seed, pass, control, |points| {
        points
            .into_iter()
            .map(|mut p| sample(p.screen.0, p.screen.1, &mut p.rng))
            .collect()
    })
}

/// A pixel's sample in a pass: where it looks and the random stream it draws from.
pub struct PixelSample {
    /// Its jittered point on the screen, in [0, 1]² (y up).
    pub screen: (f32, f32),
    /// Its random stream, the jitter drawn.
    pub rng: Rng,
}

/// [`sample_pass`] a tile at a time: `samples(points)` gets the sample of each pixel of a tile,
/// row by row, and returns their values in the same order (to trace the tile's paths
/// together). The same random streams, so the same image.
pub fn sample_pass_tiles<F>(
    width: usize,
    height: usize,
    seed: u64,
    pass: u64,
    control: Control,
    samples: F,
) -> Option<Vec<Vec3>>
where
    F: Fn(Vec<PixelSample>) -> Vec<Vec3> + Sync,
{
    // Multiplied by, not divided: two divisions a pixel were 1% of a glass ball's render.
    let (inv_width, inv_height) = (1.0 / width as f32, 1.0 / height as f32);
    let (pixels, complete) = shade_tile_blocks(width, height, control, false, |(x0, y0), (x1, y1)| {
        let mut points = Vec::with_capacity((x1 - x0) * (y1 - y0));
        for y in y0..y1 {
            for x in x0..x1 {
                let mut rng = Rng::new(seed, (pass << 32) ^ (y * width + x) as u64);
                let (jx, jy) = (rng.uniform(), rng.uniform());
                let sx = (x as f32 + jx) * inv_width;
                let sy = 1.0 - (y as f32 + jy) * inv_height;
                points.push(PixelSample { screen: (sx, sy), rng });
            }
        }
        let mut values = samples(points);
        for v in &mut values {
            if !v.is_finite() {
                *v = Vec3::ZERO;
            }
        }
        values
    });
    complete.then_some(pixels)
}
