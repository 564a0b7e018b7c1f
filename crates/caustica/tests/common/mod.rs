//! Helpers shared by the integration tests.
#![allow(dead_code)]

use caustica::film::Film;
use caustica::integrator::{partial::Accumulator, Progressive};
use caustica::loader::{from_text, LoadSettings};
use caustica::progress::{Control, NoProgress};
use caustica::scene::Scene;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

/// Builds a scene from `.ray` text, panicking with the parse error if it is malformed.
pub fn scene(text: &str) -> Scene {
    from_text(text, Path::new("."), &LoadSettings::default()).unwrap_or_else(|e| panic!("scene does not build: {e:?}"))
}

static NEVER: AtomicBool = AtomicBool::new(false);

/// `scene` rendered to the end with `config`, as the command line renders it.
pub fn render_with(scene: &Scene, config: &caustica::integrator::RenderConfig) -> Film {
    let options = config.render_options("test").unwrap();
    let mut session = caustica::integrator::RenderSession::new(scene, options).unwrap();
    let summary = session.run(&config.plan().unwrap(), control(), |_| Ok(())).unwrap();
    assert!(summary.complete);
    session.image()
}

/// `scene` rendered square at `size` with `integrator`, `passes` passes and `photons` photons
/// (or light paths) a pass, from `seed`.
pub fn render_integrator(scene: &Scene, integrator: &str, size: usize, passes: u64, photons: usize, seed: u64) -> Film {
    let config = caustica::integrator::RenderConfig {
        integrator: Some(integrator.parse().unwrap()),
        width: size,
        height: Some(size),
        passes: Some(passes.to_string()),
        photons,
        light_paths: Some(photons as u64),
        seed,
        ..caustica::integrator::RenderConfig::default()
    };
    render_with(scene, &config)
}

/// A control that reports nowhere and is never cancelled.
pub fn control() -> Control<'static> {
    Control {
        progress: &NoProgress,
        cancel: &NEVER,
    }
}

/// Relative difference of two numbers.
pub fn rel(a: f32, b: f32) -> f32 {
    (a - b).abs() / b.abs().max(1e-12)
}

/// Renders passes `first..end` of `renderer` and returns their sums.
pub fn render_passes(renderer: &dyn Progressive, width: usize, height: usize, first: u64, end: u64) -> Accumulator {
    let mut acc = Accumulator::new(width, height, "test");
    for pass in first..end {
        let pixels = renderer.render_pass(pass, control()).expect("not cancelled");
        acc.add(pass, &pixels, renderer.pass_weight(pass));
    }
    acc
}

/// The independent renderer's references; tests that read them are ignored without them
/// (build.rs).
pub fn reference_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../../shared/reference")
}

/// The reference scene `name` (`.ray` text) and its image.
pub fn load_reference(name: &str) -> (String, Film) {
    let dir = reference_dir();
    let text = std::fs::read_to_string(dir.join(format!("{name}.ray"))).unwrap();
    let (w, h, pixels) = caustica::image_io::read_exr(&dir.join(format!("{name}_ref.exr"))).unwrap();
    (
        text,
        Film {
            width: w,
            height: h,
            pixels,
        },
    )
}

/// One pass of `renderer` is the same, bit for bit, on one thread and on two (and not black);
/// passes split over two runs merge into the sums of one run.
pub fn assert_deterministic_and_merges(renderer: &dyn Progressive, width: usize, height: usize) {
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| renderer.render_pass(3, control()).unwrap())
    };
    let (one, two) = (run(1), run(2));
    assert!(one.iter().any(|p| p.x > 0.0));
    assert_eq!(one, two);
    let whole = render_passes(renderer, width, height, 0, 4);
    let mut first = render_passes(renderer, width, height, 0, 2);
    first.merge(&render_passes(renderer, width, height, 2, 4)).unwrap();
    assert_eq!(first.passes, whole.passes);
    for (a, b) in first.film().pixels.iter().zip(&whole.film().pixels) {
        assert!((*a - *b).abs().max_element() <= 1e-6 * a.abs().max_element().max(1.0));
    }
}

/// A named box of rows and columns (inclusive, from the top-left).
pub type Region = (&'static str, (usize, usize), (usize, usize));

/// Relative error of a region's mean (over its pixels and channels) against the reference.
pub fn region_error(film: &Film, reference: &Film, region: Region) -> f32 {
    let got = film.region_mean(region.1, region.2);
    let want = reference.region_mean(region.1, region.2);
    rel(got.x + got.y + got.z, want.x + want.y + want.z)
}

/// The worst region error, and a line per region for the log.
pub fn report(film: &Film, reference: &Film, regions: &[Region]) -> (f32, String) {
    let mut worst = 0.0f32;
    let mut text = String::new();
    for r in regions {
        let err = region_error(film, reference, *r);
        worst = worst.max(err);
        text += &format!(
            "  {}: {:.4} vs {:.4} ({:.2}%)\n",
            r.0,
            film.region_mean(r.1, r.2),
            reference.region_mean(r.1, r.2),
            100.0 * err
        );
    }
    (worst, text)
}

/// A UV sphere as Blender triangulates one: rings × segments, smooth normals.
pub fn uv_sphere(radius: f32, rings: u32, segments: u32) -> (Vec<glam::Vec3>, Vec<glam::Vec3>, Vec<u16>) {
    let mut points = vec![glam::Vec3::new(0.0, radius, 0.0)];
    for r in 1..rings {
        let theta = std::f32::consts::PI * r as f32 / rings as f32;
        for s in 0..segments {
            let phi = 2.0 * std::f32::consts::PI * s as f32 / segments as f32;
            points.push(radius * glam::Vec3::new(theta.sin() * phi.cos(), theta.cos(), -theta.sin() * phi.sin()));
        }
    }
    points.push(glam::Vec3::new(0.0, -radius, 0.0));
    let bottom = (points.len() - 1) as u16;
    let ring = |r: u32, s: u32| (1 + (r - 1) * segments + s % segments) as u16;
    let mut indices = Vec::new();
    for s in 0..segments {
        indices.extend([0, ring(1, s), ring(1, s + 1)]);
        indices.extend([bottom, ring(rings - 1, s + 1), ring(rings - 1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            let (a, b, c, d) = (ring(r, s), ring(r, s + 1), ring(r + 1, s), ring(r + 1, s + 1));
            indices.extend([a, c, d, a, d, b]);
        }
    }
    let normals = points.iter().map(|p| p.normalize()).collect();
    (points, normals, indices)
}
