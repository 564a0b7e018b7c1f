//! `caustica render`: the options become a render session of the library, which this command
//! runs with progress bars, saving the image (and the partial sums) as it goes.

use super::load_scene;
use super::shown;
use crate::cli::RenderArgs;
use crate::progress::Bars;
use caustica::description::RenderHints;
use caustica::film::ToneMap;
use caustica::format::Format;
use caustica::image_io::{check_writable, ImageFormat};
use caustica::integrator::config::thread_pool;
use caustica::integrator::config::{integrator_note, GivenOptions, Model};
use caustica::integrator::{Integrator, RenderConfig, RenderSession};
use caustica::light::Light;
use caustica::photon::Estimator;
use caustica::preview::{tev, Preview, PreviewReport, PreviewSettings};
use caustica::progress::Control;
use caustica::scene::Scene;
use caustica::{Error, Result};
use serde_json::json;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

/// The library's render options: the command line's over the scene's own settings (`hints`).
pub fn config(args: &RenderArgs, hints: &RenderHints) -> Result<RenderConfig> {
    let p = &args.progressive;
    let defaults = RenderConfig::default();
    let given = given(args);
    let asked = RenderConfig {
        model: p.model.as_deref().map(str::parse::<Model>).transpose()?,
        integrator: p.integrator.as_deref().map(str::parse).transpose()?,
        width: args.width.unwrap_or(defaults.width),
        height: args.height,
        aa: args.aa,
        depth: args.depth,
        seed: args.seed,
        photons: args.photon.photons.unwrap_or(defaults.photons),
        light_paths: args.photon.photons.map(|p| p as u64),
        max_emitted: args.photon.max_emitted,
        photons_per_light: args.photon.photons_per_light.clone(),
        no_aim: args.photon.no_aim,
        k: args.k,
        radius: args.radius,
        cone_filter: args.cone_filter,
        estimator: match args.estimate.as_str() {
            "nearest" => Estimator::Nearest,
            _ => Estimator::Kernels,
        },
        no_estimate_reuse: args.no_estimate_reuse,
        passes: p.passes.clone(),
        time: p.time,
        footprint: p.footprint,
        alpha: p.alpha,
        no_camera_specular: p.no_camera_specular,
        vertex_connections: p.vertex_connections,
        spectral: match (p.spectral, p.no_spectral) {
            (true, _) => Some(true),
            (_, true) => Some(false),
            _ => None,
        },
        max_memory: args.photon.max_memory,
        partial: p.partial.clone(),
    };
    Ok(asked.over_scene(&given, hints))
}

/// Which of the options a scene file also sets the command line gave.
fn given(args: &RenderArgs) -> GivenOptions {
    let p = &args.progressive;
    GivenOptions {
        model_or_integrator: p.model.is_some() || p.integrator.is_some(),
        width: args.width.is_some(),
        height: args.height.is_some(),
        depth: args.depth.is_some(),
        photons: args.photon.photons.is_some(),
        radius: args.radius.is_some(),
        passes: p.passes.is_some(),
        time: p.time.is_some(),
    }
}

/// Runs the command; returns the exit code.
pub fn run(args: RenderArgs, cancel: &'static AtomicBool) -> Result<u8> {
    let start = Instant::now();
    // Options are checked before the scene is read (physical formats assumed physical), then
    // again with the scene's own settings.
    let format = super::load_settings(&args.scene_args)?;
    let physical_format = args
        .scene
        .as_deref()
        .is_some_and(|p| matches!(format.read.format_of(p), Format::Pbrt | Format::Gltf));
    let early = RenderHints {
        physical: physical_format,
        ..RenderHints::default()
    };
    let checked = config(&args, &early)?;
    let options = &args.progressive;
    // The integrator's own checks (photon memory, passes only where they mean something).
    checked.integrator()?;
    checked.plan()?;
    if !options.exposure.is_finite() || options.exposure.abs() > 64.0 {
        return Err(Error::InvalidSettings(
            "--exposure must be a number of stops between -64 and 64".into(),
        ));
    }
    if !(options.save_every > 0.0 && options.save_every.is_finite()) {
        return Err(Error::InvalidSettings(
            "--save-every must be a positive number of seconds".into(),
        ));
    }
    if let Some(o) = &args.output {
        ImageFormat::from_path(o)?;
    }
    // A folder that is missing or read-only fails now, not after the render.
    for path in args.output.iter().chain(&options.partial) {
        check_writable(path)?;
    }
    let display = args.preview.display.as_deref().map(tev::parse_address).transpose()?;
    let pool = thread_pool(args.threads)?;
    let quiet = args.quiet || args.json;
    let bars = Bars::new(quiet);

    let loaded = load_scene(args.scene.as_deref(), &args.scene_args, &bars)?;
    let scene = &loaded.scene;
    let config = config(&args, scene.hints())?;
    let integrator = config.integrator()?;
    let progressive = integrator.is_progressive();
    let plan = config.plan()?;
    // An image, unless only a partial file is asked for; a pbrt-v4 scene may name its own.
    let output: Option<PathBuf> = match (&args.output, &options.partial, &scene.hints().output) {
        (Some(o), _, _) => Some(o.clone()),
        (None, Some(_), _) => None,
        (None, None, Some(named)) if ImageFormat::from_path(named).is_ok() => Some(named.clone()),
        (None, None, _) => Some("caustica.png".into()),
    };
    // The default or the scene's own name, checked before any photon is traced.
    if let Some(o) = output.as_ref().filter(|_| args.output.is_none()) {
        check_writable(o)?;
    }
    check_preview(&args, &output)?;
    // Why this integrator, when the user did not choose it.
    let integrator_why = integrator_note(&given(&args), scene.hints(), scene).filter(|_| progressive);
    if !quiet {
        for warning in scene.warnings() {
            eprintln!("warning: {warning}");
        }
        if !progressive {
            if let Some(why) = caustica::integrator::darkness::diagnose(scene) {
                eprintln!("warning: {why}");
            }
        }
        if progressive {
            if let Some(note) = &integrator_why {
                eprintln!("note: {note}");
            }
            for note in physical_notes(scene) {
                eprintln!("note: {note}");
            }
            let ignored = config.ignored_by_physical();
            if !ignored.is_empty() {
                eprintln!(
                    "note: {} only apply to the course model's Whitted renderer; ignored here",
                    ignored.join(", ")
                );
            }
            let ignored = config.ignored_by_lt();
            if !ignored.is_empty() {
                eprintln!(
                    "note: {} set a gather radius; lt gathers nothing and ignores them",
                    ignored.join(", ")
                );
            }
        }
    }
    let mut session = RenderSession::new(scene, config.render_options(loaded.scene_id.clone())?)?;
    let (width, height) = session.size();
    // An image of another aspect than the camera's is cropped or extended, and said so.
    let camera_fit = scene.camera().fit_note(width, height);
    if let Some(note) = camera_fit.as_ref().filter(|_| !quiet) {
        eprintln!("note: {note}");
    }
    let exposure = options.exposure;
    let tone_map = match options.tone_map.as_deref() {
        Some("reinhard") => ToneMap::Reinhard { exposure },
        Some("linear") => ToneMap::Linear { exposure },
        Some(_) => ToneMap::Clamp { exposure },
        None if progressive => ToneMap::Reinhard { exposure },
        None => ToneMap::Clamp { exposure },
    };
    let preview = if display.is_some() || args.preview.preview {
        let name = [&output, &options.partial]
            .into_iter()
            .flatten()
            .next()
            .and_then(|p| p.file_name())
            .map_or_else(|| "caustica".to_string(), |n| n.to_string_lossy().into_owned());
        let settings = PreviewSettings {
            display,
            file: output.clone().filter(|_| args.preview.preview).map(|o| (o, tone_map)),
            name,
            display_every: Duration::from_secs_f64(args.preview.preview_every.unwrap_or(0.5)),
            file_every: Duration::from_secs_f64(args.preview.preview_every.unwrap_or(2.0)),
        };
        let warn = move |message: String| {
            if !quiet {
                eprintln!("warning: preview: {message}");
            }
        };
        Some(Preview::start(width, height, settings, warn)?)
    } else {
        None
    };
    let preview_progress = preview.as_ref().map(|p| p.progress(&bars));
    let control = Control {
        progress: match &preview_progress {
            Some(p) => p,
            None => &bars,
        },
        cancel,
    };
    let save = |session: &RenderSession| -> Result<()> {
        if let Some(o) = &output {
            session.image().save(o, tone_map)?;
        }
        if let Some(p) = &options.partial {
            session.accumulator().save(p)?;
        }
        Ok(())
    };

    let mut last_save = Instant::now();
    let summary = pool.install(|| {
        session.run(&plan, control, |session| {
            if let Some(preview) = &preview {
                preview.offer(|| session.image());
            }
            // Progressive renders are rewritten as they converge; the final save is below.
            if progressive && last_save.elapsed().as_secs_f64() >= options.save_every {
                save(session)?;
                last_save = Instant::now();
            }
            Ok(())
        })
    })?;
    // The viewer gets the final image; the preview's last file write is over before the save.
    let preview_report = preview.map(|p| p.finish(&session.image()));
    let photon_stats = session.caustic_map().map(|m| m.stats.clone());
    if !quiet {
        if let Some(s) = &photon_stats {
            for line in super::photon_lines(s, summary.photon_seconds) {
                eprintln!("{line}");
            }
        }
    }
    let passes_done = session.pass_count();
    if passes_done == 0 {
        eprintln!("interrupted before the first pass finished: nothing was saved");
        return Ok(crate::EXIT_INTERRUPTED);
    }
    save(&session)?;

    let total = start.elapsed().as_secs_f64();
    let complete = summary.complete;
    let (parse_seconds, build_seconds) = (loaded.parse_seconds, loaded.build_seconds);
    let ranges: Vec<String> = if progressive {
        session
            .accumulator()
            .passes
            .iter()
            .map(|(a, b)| format!("{a}..{b}"))
            .collect()
    } else {
        vec!["0..1".into()]
    };
    let photons_per_pass = match session.integrator() {
        Integrator::Ppm(s) => s.photons_per_pass,
        Integrator::Gi(s) => s.photons_per_pass,
        Integrator::Lt(s) => s.photons_per_pass,
        Integrator::Vcm(s) => s
            .light_paths_per_pass
            .or_else(|| session.chosen_paths_per_pass())
            .unwrap_or_else(|| caustica::integrator::vcm::default_light_paths(width, height)),
        _ => 0,
    };
    let full_passes = session.accumulator().weight;
    if args.json {
        let summary = if progressive {
            json!({
                "output": shown(&output),
                "partial": shown(&options.partial),
                "integrator": session.integrator().name(),
                "integrator_why": integrator_why,
                "model": "physical",
                "width": width,
                "camera_fit": camera_fit,
                "height": height,
                "passes": passes_done,
                "pass_ranges": ranges.join(","),
                "photons_per_pass": photons_per_pass,
                // Passes resized to a time limit count by their share of a full pass.
                "full_passes": full_passes,
                "photons": (full_passes * photons_per_pass as f64).round() as u64,
                "complete": complete,
                "seconds": {
                    "parse": parse_seconds,
                    "build": build_seconds,
                    "render": summary.render_seconds,
                    "total": total,
                },
                "peak_memory_bytes": super::peak_memory_bytes(),
                "preview": preview_json(&preview_report),
            })
        } else {
            let aa = config.aa;
            json!({
                "output": shown(&output),
                "integrator": "whitted",
                "model": "course",
                "width": width,
                "camera_fit": camera_fit,
                "height": height,
                "samples_per_pixel": aa * aa,
                "photons_stored": photon_stats.as_ref().map_or(0, |s| s.stored),
                "photons_emitted": photon_stats.as_ref().map_or(0, |s| s.emitted),
                "photons_landed": photon_stats.as_ref().map_or(0, |s| s.landed),
                "photons_useful_fraction": photon_stats.as_ref().map_or(0.0, |s| s.useful_fraction()),
                "photons_cap_reached": photon_stats.as_ref().is_some_and(|s| s.cap_reached),
                "photons_none_reason": photon_stats.as_ref().and_then(|s| s.none).map(|r| r.name()),
                "complete": complete,
                "seconds": {
                    "parse": parse_seconds,
                    "build": build_seconds,
                    "photons": summary.photon_seconds,
                    "render": summary.render_seconds,
                    "total": total,
                },
                "peak_memory_bytes": super::peak_memory_bytes(),
                "preview": preview_json(&preview_report),
            })
        };
        crate::stdout::println(&summary.to_string())?;
    } else if !args.quiet {
        if progressive {
            let written: Vec<String> = [&output, &options.partial]
                .into_iter()
                .flatten()
                .map(|p| p.display().to_string())
                .collect();
            eprintln!(
                "{} {width}×{height}, {passes_done} {} passes ({}){} — parse {parse_seconds:.2} s, build {build_seconds:.2} s, render {:.2} s, total {total:.2} s{}",
                written.join(" and "),
                session.integrator().name(),
                ranges.join(","),
                if photons_per_pass > 0 {
                    format!(", {photons_per_pass} photons a pass")
                } else {
                    String::new()
                },
                summary.render_seconds,
                if complete { "" } else { " (interrupted: the passes done are saved)" }
            );
        } else {
            let stored = photon_stats.as_ref().map_or(0, |s| s.stored);
            eprintln!(
                "{} {width}×{height} at {} spp, {stored} photons stored — parse {parse_seconds:.2} s, build {build_seconds:.2} s, photons {:.2} s, render {:.2} s, total {total:.2} s{}",
                output.as_ref().map_or(String::new(), |o| o.display().to_string()),
                config.aa * config.aa,
                summary.photon_seconds,
                summary.render_seconds,
                if complete { "" } else { " (interrupted: partial image)" }
            );
        }
    }
    Ok(if complete { 0 } else { crate::EXIT_INTERRUPTED })
}

/// Refuses preview options that cannot work, before any work.
fn check_preview(args: &RenderArgs, output: &Option<PathBuf>) -> Result<()> {
    if args.preview.preview_every.is_some_and(|s| !(s > 0.0 && s <= 3600.0)) {
        return Err(Error::InvalidSettings(
            "--preview-every must be a positive number of seconds (at most 3600)".into(),
        ));
    }
    if args.preview.preview && output.is_none() {
        return Err(Error::InvalidSettings(
            "--preview rewrites the output image: give one with -o".into(),
        ));
    }
    Ok(())
}

/// The preview's work in the JSON summary (`null` without one).
fn preview_json(report: &Option<PreviewReport>) -> serde_json::Value {
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
fn physical_notes(scene: &Scene) -> Vec<String> {
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
