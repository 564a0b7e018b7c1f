//! What `render` says when it ends: the summary line, the preview's part of `--json`, and the
//! notes on a physical render's scene.

use caustica::integrator::{RunDetail, RunReport};
use caustica::light::Light;
use caustica::preview::PreviewReport;
use caustica::scene::Scene;
use serde_json::json;
use std::path::PathBuf;

/// The one line a run ends with: what was written, the image, the passes or photons, the time.
pub(super) fn summary_line(report: &RunReport, output: &Option<PathBuf>, partial: &Option<PathBuf>) -> String {
    let (width, height) = (report.width, report.height);
    let s = &report.seconds;
    let times = format!("parse {:.2} s, build {:.2} s", s.parse, s.build);
    match &report.detail {
        RunDetail::Passes {
            passes,
            pass_ranges,
            photons_per_pass,
            ..
        } => {
            let written: Vec<String> = [output, partial]
                .into_iter()
                .flatten()
                .map(|p| p.display().to_string())
                .collect();
            format!(
                "{} {width}×{height}, {passes} {} passes ({pass_ranges}){} — {times}, render {:.2} s, total {:.2} s{}",
                written.join(" and "),
                report.integrator,
                if *photons_per_pass > 0 {
                    format!(", {photons_per_pass} photons a pass")
                } else {
                    String::new()
                },
                s.render,
                s.total,
                if report.complete { "" } else { " (interrupted: the passes done are saved)" }
            )
        }
        RunDetail::Course {
            samples_per_pixel,
            photons_stored,
            ..
        } => format!(
            "{} {width}×{height} at {samples_per_pixel} spp, {photons_stored} photons stored — {times}, photons {:.2} s, render {:.2} s, total {:.2} s{}",
            output.as_ref().map_or(String::new(), |o| o.display().to_string()),
            s.photons.unwrap_or(0.0),
            s.render,
            s.total,
            if report.complete { "" } else { " (interrupted: partial image)" }
        ),
    }
}

/// The preview's work in the JSON summary (`null` without one).
pub(super) fn preview_json(report: &Option<PreviewReport>) -> serde_json::Value {
    match report {
        Some(r) => json!({
            "updates": r.updates,
            "busy_seconds": r.busy_seconds,
            "bytes_sent": r.bytes_sent,
        }),
        None => serde_json::Value::Null,
    }
}

/// What the physical model reads differently from the course's shading.
pub(super) fn physical_notes(scene: &Scene) -> Vec<String> {
    let mut notes = Vec::new();
    let attenuated = scene
        .lights()
        .iter()
        .filter(|l| matches!(l, Light::Point { attenuation, .. } if *attenuation != [0.0, 0.0, 1.0]))
        .count();
    if attenuated > 0 {
        notes.push(format!(
            "the physical model ignores the attenuation coefficients of {attenuated} point light(s): light falls off with the inverse square"
        ));
    }
    if scene.ambient() != caustica::math::Vec3::ZERO {
        notes.push("the physical model ignores ambient light: indirect light is computed".into());
    }
    notes
}
