//! `caustica render`: photons (when the scene can make caustics), then the image.

use super::{check_image_size, load_scene, photon_settings, thread_pool};
use crate::cli::RenderArgs;
use crate::progress::Bars;
use caustica::film::ToneMap;
use caustica::image_io::ImageFormat;
use caustica::integrator::whitted::{self, WhittedSettings};
use caustica::integrator::{image_size, ImageSettings};
use caustica::photon::{EstimateSettings, PhotonMap};
use caustica::progress::Control;
use caustica::{Error, Result};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// Runs the command; returns the exit code.
pub fn run(args: RenderArgs, cancel: &'static AtomicBool) -> Result<u8> {
    if let Some(integrator) = super::progressive::integrator_for(&args.progressive)? {
        return super::progressive::run(args, integrator, cancel);
    }
    let start = Instant::now();
    if args.progressive.partial.is_some() || args.progressive.passes.is_some() || args.progressive.time.is_some() {
        return Err(Error::InvalidSettings(
            "--passes, --time and --partial belong to the physical model's integrators (--model physical)".into(),
        ));
    }
    let output = args.output.clone().unwrap_or_else(|| "caustica.png".into());
    let depth = args.depth.unwrap_or(5);
    ImageFormat::from_path(&output)?;
    if args.aa == 0 || args.aa > 64 {
        return Err(Error::InvalidSettings("--aa must be between 1 and 64".into()));
    }
    if depth > 64 {
        return Err(Error::InvalidSettings("--depth must be at most 64".into()));
    }
    if args.radius.is_some_and(|r| !(r > 0.0 && r.is_finite())) {
        return Err(Error::InvalidSettings("--radius must be a positive number".into()));
    }
    if !(args.cone_filter == 0.0 || args.cone_filter >= 1.0) {
        return Err(Error::InvalidSettings(
            "--cone-filter must be 0 (off) or at least 1".into(),
        ));
    }
    if args.k == 0 || args.k > 10_000 {
        return Err(Error::InvalidSettings("--k must be between 1 and 10000".into()));
    }
    let photons = photon_settings(&args.photon, args.seed)?;
    let pool = thread_pool(args.threads)?;
    let bars = Bars::new(args.quiet || args.json);
    let control = Control {
        progress: &bars,
        cancel,
    };

    let loaded = load_scene(args.scene.as_deref(), &args.scene_args, &bars)?;
    let (scene, parse_seconds, build_seconds) = (loaded.scene, loaded.parse_seconds, loaded.build_seconds);
    if !args.quiet {
        for warning in scene.warnings() {
            eprintln!("warning: {warning}");
        }
    }
    let (width, height) = image_size(scene.camera(), args.width, args.height);
    check_image_size(width, height)?;

    let estimate = EstimateSettings {
        k: args.k,
        max_radius: args.radius,
        cone_filter: (args.cone_filter > 0.0).then_some(args.cone_filter),
        ..EstimateSettings::default()
    };
    let t_photons = Instant::now();
    let map = if photons.target_stored > 0 {
        let map = pool.install(|| PhotonMap::trace(&scene, &photons, estimate.k, control));
        if !args.quiet && !args.json {
            let s = &map.stats;
            eprintln!(
                "photons: {} emitted, {} stored ({:.1}% useful) in {:.2} s{}",
                s.emitted,
                s.stored,
                100.0 * s.useful_fraction(),
                t_photons.elapsed().as_secs_f64(),
                if s.cap_reached {
                    " — emission cap reached before the budget was stored"
                } else {
                    ""
                }
            );
            if s.stored == 0 {
                eprintln!("photons: none stored (the scene has no mirror or glass that lights reach): no caustics");
            }
        }
        Some(map)
    } else {
        None
    };
    let photon_seconds = t_photons.elapsed().as_secs_f64();

    let image = ImageSettings {
        width,
        height,
        aa: args.aa,
        seed: args.seed,
    };
    let settings = WhittedSettings {
        max_depth: depth,
        reuse_caustic_estimates: !args.no_estimate_reuse,
        ..WhittedSettings::default()
    };
    let t_render = Instant::now();
    let caustics = map.as_ref().filter(|m| !m.is_empty()).map(|m| (m, &estimate));
    let (film, complete) = pool.install(|| whitted::render(&scene, caustics, &settings, &image, control));
    let render_seconds = t_render.elapsed().as_secs_f64();
    film.save(&output, ToneMap::Clamp)?;

    let total = start.elapsed().as_secs_f64();
    let stored = map.as_ref().map_or(0, |m| m.stats.stored);
    if args.json {
        println!(
            "{{\"output\":{},\"width\":{width},\"height\":{height},\"samples_per_pixel\":{},\"photons_stored\":{stored},\"photons_emitted\":{},\"complete\":{complete},\"seconds\":{{\"parse\":{parse_seconds:.4},\"build\":{build_seconds:.4},\"photons\":{photon_seconds:.4},\"render\":{render_seconds:.4},\"total\":{total:.4}}},\"peak_memory_bytes\":{}}}",
            crate::json::string(&output.display().to_string()),
            args.aa * args.aa,
            map.as_ref().map_or(0, |m| m.stats.emitted),
            super::peak_memory_bytes().map_or("null".to_string(), |b| b.to_string()),
        );
    } else if !args.quiet {
        eprintln!(
            "{} {}×{} at {} spp, {stored} photons stored — parse {parse_seconds:.2} s, build {build_seconds:.2} s, photons {photon_seconds:.2} s, render {render_seconds:.2} s, total {total:.2} s{}",
            output.display(),
            width,
            height,
            args.aa * args.aa,
            if complete { "" } else { " (interrupted: partial image)" }
        );
    }
    Ok(if complete { 0 } else { crate::EXIT_INTERRUPTED })
}
