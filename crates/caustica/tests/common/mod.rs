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
        acc.add(pass, &pixels);
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
