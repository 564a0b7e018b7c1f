//! Helpers shared by the integration tests.
#![allow(dead_code)]

use caustica::loader::{from_text, LoadSettings};
use caustica::progress::{Control, NoProgress};
use caustica::scene::Scene;
use std::path::Path;
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
