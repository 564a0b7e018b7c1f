//! `caustica render`: the options become a render session of the library, which this command
//! runs with progress bars, saving the image (and the partial sums) as it goes.

mod options;
mod summary;

use super::load_scene;
use super::shown;
use crate::cli::RenderArgs;
use crate::progress::Bars;
use caustica::description::RenderHints;
use caustica::film::ToneMap;
use caustica::format::Format;
use caustica::image_io::{check_writable, ImageFormat};
use caustica::integrator::config::integrator_note;
use caustica::integrator::config::thread_pool;
use caustica::integrator::RenderSession;
use caustica::preview::{tev, Preview, PreviewSettings};
use caustica::progress::Control;
use caustica::{Error, Result};
pub use options::config;
use options::{check_preview, given};
use serde_json::json;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};
use summary::{physical_notes, preview_json, summary_line};

/// Runs the command; returns the exit code.
pub fn run(args: RenderArgs, cancel: &'static AtomicBool) -> Result<u8> {
    let start = Instant::now();
    // Options are checked before the scene is read (physical formats assumed physical, and a
    // `.ray` file given passes too, which a medium in it makes physical), then again with the
    // scene's own settings.
    let format = super::load_settings(&args.scene_args)?;
    let passes_given = {
        let p = &args.progressive;
        p.passes.is_some() || p.time.is_some() || p.partial.is_some()
    };
    let physical_format = args.scene.as_deref().is_some_and(|p| match format.read.format_of(p) {
        Format::Pbrt | Format::Gltf => true,
        Format::Ray => passes_given,
        _ => false,
    });
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

    let report = session.report(
        &summary,
        (loaded.parse_seconds, loaded.build_seconds),
        start.elapsed().as_secs_f64(),
    );
    let complete = report.complete;
    if args.json {
        // A report of plain fields always serialises to an object.
        let mut value = serde_json::to_value(&report).unwrap_or_default();
        if let Some(fields) = value.as_object_mut() {
            fields.insert("output".into(), json!(shown(&output)));
            if progressive {
                fields.insert("partial".into(), json!(shown(&options.partial)));
                fields.insert("integrator_why".into(), json!(integrator_why));
            }
            fields.insert("peak_memory_bytes".into(), json!(super::peak_memory_bytes()));
            fields.insert("preview".into(), preview_json(&preview_report));
        }
        crate::stdout::println(&value.to_string())?;
    } else if !args.quiet {
        eprintln!("{}", summary_line(&report, &output, &options.partial));
    }
    Ok(if complete { 0 } else { crate::EXIT_INTERRUPTED })
}
