//! Scenes from the field against another renderer: Bitterli's Cornell box in pbrt-v4, read as
//! the file says (a one-sided lamp, a path tracer) but with paths as deep as Tungsten's, agrees
//! with Tungsten's reference region by region. Without `../shared/field` the test is reported as
//! ignored (build.rs).

use crate::common::{rel, render_with};
use caustica::film::Film;
use caustica::integrator::{GivenOptions, RenderConfig};
use caustica::loader::{load, LoadSettings};
use caustica::math::Vec3;
use std::path::Path;

/// The image's size, and how many of the reference's pixels each of its pixels covers a side.
const SIZE: usize = 64;
const BLOCK: usize = 16;

fn field_dir() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/field/pbrt")
}

/// The mean of the reference's pixels under each of the image's.
fn downsampled(reference: &Film) -> Film {
    let mut pixels = vec![Vec3::ZERO; SIZE * SIZE];
    for (i, p) in pixels.iter_mut().enumerate() {
        let (x, y) = (i % SIZE, i / SIZE);
        *p = reference.region_mean((y * BLOCK, y * BLOCK + BLOCK - 1), (x * BLOCK, x * BLOCK + BLOCK - 1));
    }
    Film {
        width: SIZE,
        height: SIZE,
        pixels,
    }
}

#[test]
#[cfg_attr(not(caustica_field), ignore = "../shared/field is absent")]
fn the_cornell_box_matches_tungsten() {
    let dir = field_dir().join("cornell-box/pbrt");
    let scene = load(&dir.join("scene-v4.pbrt"), &LoadSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    let (w, h, pixels) = caustica::image_io::read_exr(&dir.join("TungstenRender.exr")).unwrap();
    assert_eq!((w, h), (SIZE * BLOCK, SIZE * BLOCK));
    let reference = downsampled(&Film {
        width: w,
        height: h,
        pixels,
    });
    // The file's `maxdepth` 4 leaves out 5% of the light Tungsten's deep paths carry.
    let given = GivenOptions {
        width: true,
        height: true,
        depth: true,
        passes: true,
        ..GivenOptions::default()
    };
    let config = RenderConfig {
        width: SIZE,
        height: Some(SIZE),
        depth: Some(64),
        passes: Some("256".into()),
        seed: 3,
        ..RenderConfig::default()
    }
    .over_scene(&given, scene.hints());
    let film = render_with(&scene, &config);
    // (name, rows, columns) in the image's pixels; the bound, 3%, is twice the largest error
    // measured at this seed and budget (the ceiling's; a 1024² render for 45 s agrees within
    // 0.1%). Both faces of the lamp emitting put the ceiling 28% over, `maxdepth` 4 5% under.
    type Region = (&'static str, (usize, usize), (usize, usize));
    let regions: [Region; 6] = [
        ("left wall", (19, 43), (0, 6)),
        ("right wall", (19, 43), (57, 63)),
        ("back wall", (10, 24), (35, 53)),
        ("floor", (60, 62), (8, 28)),
        ("ceiling", (0, 2), (10, 54)),
        ("whole image", (0, 63), (0, 63)),
    ];
    let mut failures = Vec::new();
    for (name, rows, cols) in regions {
        let (got, want) = (film.region_mean(rows, cols), reference.region_mean(rows, cols));
        let err = (0..3).map(|c| rel(got[c], want[c])).fold(0.0, f32::max);
        eprintln!("{name:<12} {got:?} vs {want:?}: {:.2}%", 100.0 * err);
        if err.is_nan() || err > 0.03 {
            failures.push(format!("{name}: {:.2}%", 100.0 * err));
        }
    }
    assert!(failures.is_empty(), "{failures:?}");
}
