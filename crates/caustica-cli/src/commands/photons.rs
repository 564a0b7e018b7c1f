//! `caustica photons`: the stored caustic photons drawn through the camera, and a PLY dump.

use super::shown;
use super::{load_scene, photon_settings};
use crate::cli::PhotonArgs;
use crate::progress::Bars;
use caustica::film::ToneMap;
use caustica::integrator::config::thread_pool;
use caustica::integrator::image_size;
use caustica::integrator::session::check_image_size;
use caustica::photon::picture::{draw_photons, write_ply};
use caustica::photon::{EstimateSettings, Estimator, PhotonMap};
use caustica::progress::Control;
use caustica::Result;
use serde_json::json;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Runs the command; returns the exit code.
pub fn run(args: PhotonArgs, cancel: &'static AtomicBool) -> Result<u8> {
    let start = Instant::now();
    caustica::image_io::ImageFormat::from_path(&args.output)?;
    for path in std::iter::once(&args.output).chain(&args.ply) {
        caustica::image_io::check_writable(path)?;
    }
    let settings = photon_settings(&args.photon, args.seed)?;
    let pool = thread_pool(args.threads)?;
    let bars = Bars::new(args.quiet || args.json);
    let loaded = load_scene(Some(&args.scene), &args.scene_args, &bars)?;
    let scene = loaded.scene;
    if !args.quiet {
        for warning in scene.warnings() {
            eprintln!("warning: {warning}");
        }
    }
    let (width, height) = image_size(scene.camera(), args.width, args.height);
    check_image_size(width, height)?;
    let control = Control {
        progress: &bars,
        cancel,
    };
    let t_photons = Instant::now();
    // Only the photons are drawn: the cheapest map will do.
    let estimate = EstimateSettings {
        estimator: Estimator::Nearest,
        k: 1,
        ..EstimateSettings::default()
    };
    let map = pool.install(|| PhotonMap::trace(&scene, &settings, &estimate, control));
    let photon_seconds = t_photons.elapsed().as_secs_f64();
    // Checked right after tracing: a Ctrl-C while writing does not make the map partial.
    let complete = !cancel.load(Ordering::Relaxed);
    let film = draw_photons(&scene, map.photons(), width, height);
    film.save(&args.output, ToneMap::Clamp { exposure: 0.0 })?;
    if let Some(ply) = &args.ply {
        write_ply(ply, map.photons())?;
    }
    let total = start.elapsed().as_secs_f64();
    let s = &map.stats;
    if args.json {
        let summary = json!({
            "output": args.output.display().to_string(),
            "ply": shown(&args.ply),
            "width": width,
            "height": height,
            "photons_stored": s.stored,
            "photons_emitted": s.emitted,
            "photons_landed": s.landed,
            "useful_fraction": s.useful_fraction(),
            "cap_reached": s.cap_reached,
            "none_reason": s.none.map(|r| r.name()),
            "complete": complete,
            "seconds": {
                "parse": loaded.parse_seconds,
                "build": loaded.build_seconds,
                "photons": photon_seconds,
                "total": total,
            },
            "peak_memory_bytes": super::peak_memory_bytes(),
        });
        crate::stdout::println(&summary.to_string())?;
    } else if !args.quiet {
        if s.none.is_some() {
            eprintln!("{}", super::photon_lines(s, photon_seconds).join("\n"));
        }
        eprintln!(
            "{}{}: {} photons stored of {} emitted ({}){} — parse {:.2} s, build {:.2} s, photons {photon_seconds:.2} s, total {total:.2} s{}",
            args.output.display(),
            args.ply.as_ref().map_or(String::new(), |p| format!(" and {}", p.display())),
            s.stored,
            s.emitted,
            super::landed_text(s),
            if s.cap_reached { ", emission cap reached" } else { "" },
            loaded.parse_seconds,
            loaded.build_seconds,
            if complete { "" } else { " (interrupted: partial map)" }
        );
    }
    Ok(if complete { 0 } else { crate::EXIT_INTERRUPTED })
}
