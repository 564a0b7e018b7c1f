//! `caustica render` under the physical model: the path, ppm and gi integrators, in passes.

use super::{check_image_size, load_scene, photon_settings, thread_pool};
use crate::cli::{ProgressiveOptions, RenderArgs};
use crate::progress::Bars;
use caustica::film::ToneMap;
use caustica::image_io::ImageFormat;
use caustica::integrator::gi::{Gi, GiSettings};
use caustica::integrator::image_size;
use caustica::integrator::path::{PathSettings, PathTracer};
use caustica::integrator::ppm::{InitialRadius, Ppm, PpmSettings};
use caustica::integrator::progressive::{Accumulator, Progressive};
use caustica::light::Light;
use caustica::progress::{Control, Progress};
use caustica::{Error, Result};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

/// The physical model's integrators.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Integrator {
    /// Unidirectional path tracing (the reference).
    Path,
    /// Progressive photon mapping.
    Ppm,
    /// Jensen's photon mapping with final gathering.
    Gi,
}

impl Integrator {
    fn name(self) -> &'static str {
        match self {
            Integrator::Path => "path",
            Integrator::Ppm => "ppm",
            Integrator::Gi => "gi",
        }
    }
}

/// Passes run when neither --passes nor --time is given.
const DEFAULT_PASSES: u64 = 64;

/// The physical integrator the options ask for; `None` for the course model's Whitted renderer.
pub fn integrator_for(options: &ProgressiveOptions) -> Result<Option<Integrator>> {
    let chosen = match options.integrator.as_deref() {
        Some("path") => Some(Integrator::Path),
        Some("ppm") => Some(Integrator::Ppm),
        Some("gi") => Some(Integrator::Gi),
        _ => None,
    };
    match (options.model.as_deref(), options.integrator.as_deref(), chosen) {
        (Some("course"), Some(name), Some(_)) => Err(Error::InvalidSettings(format!(
            "--integrator {name} renders the physical model; drop --model course (or use --integrator whitted)"
        ))),
        (Some("physical"), Some("whitted"), _) => Err(Error::InvalidSettings(
            "the whitted integrator renders the course model; with --model physical use path, ppm or gi".into(),
        )),
        (Some("physical"), None, _) => Ok(Some(Integrator::Ppm)),
        (_, _, chosen) => Ok(chosen),
    }
}

/// `N` (passes 0..N) or `A..B`; with neither, 64 passes, or as many as --time allows.
fn pass_range(spec: Option<&str>, time: Option<f64>) -> Result<(u64, Option<u64>)> {
    let bad = |s: &str| {
        Error::InvalidSettings(format!(
            "--passes {s}: expected a count N (passes 0..N) or a range A..B with A < B"
        ))
    };
    let Some(spec) = spec else {
        return Ok((0, if time.is_some() { None } else { Some(DEFAULT_PASSES) }));
    };
    let (first, end) = match spec.split_once("..") {
        Some((a, b)) => (
            a.trim().parse::<u64>().map_err(|_| bad(spec))?,
            b.trim().parse::<u64>().map_err(|_| bad(spec))?,
        ),
        None => (0, spec.trim().parse::<u64>().map_err(|_| bad(spec))?),
    };
    // Pass indices feed 32 bits of the random streams' index.
    if first >= end || end > u32::MAX as u64 {
        return Err(bad(spec));
    }
    Ok((first, Some(end)))
}

fn check(args: &RenderArgs) -> Result<()> {
    let p = &args.progressive;
    let invalid = |m: &str| Err(Error::InvalidSettings(m.into()));
    if !p.exposure.is_finite() || p.exposure.abs() > 64.0 {
        return invalid("--exposure must be a number of stops between -64 and 64");
    }
    if !(p.footprint > 0.0 && p.footprint <= 10_000.0) {
        return invalid("--footprint must be a positive number of pixels (at most 10000)");
    }
    if !(p.alpha > 0.0 && p.alpha < 1.0) {
        return invalid("--alpha must lie strictly between 0 and 1");
    }
    if !(p.save_every > 0.0 && p.save_every.is_finite()) {
        return invalid("--save-every must be a positive number of seconds");
    }
    if p.time.is_some_and(|t| !(t > 0.0 && t.is_finite())) {
        return invalid("--time must be a positive number of seconds");
    }
    if args.depth.is_some_and(|d| d == 0 || d > 1024) {
        return invalid("--depth must be between 1 and 1024 for the physical integrators");
    }
    if args.radius.is_some_and(|r| !(r > 0.0 && r.is_finite())) {
        return invalid("--radius must be a positive number");
    }
    if args.k == 0 || args.k > 10_000 {
        return invalid("--k must be between 1 and 10000");
    }
    Ok(())
}

/// FNV-1a: a fingerprint of the scene's bytes that is the same on every machine.
fn content_hash(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

/// Runs a physical render; returns the exit code.
pub fn run(args: RenderArgs, integrator: Integrator, cancel: &'static AtomicBool) -> Result<u8> {
    let start = Instant::now();
    check(&args)?;
    let options = &args.progressive;
    let (first_pass, end_pass) = pass_range(options.passes.as_deref(), options.time)?;
    let output: Option<PathBuf> = match (&args.output, &options.partial) {
        (Some(o), _) => Some(o.clone()),
        (None, Some(_)) => None,
        (None, None) => Some("caustica.png".into()),
    };
    if let Some(o) = &output {
        ImageFormat::from_path(o)?;
    }
    let photons_per_pass = if integrator == Integrator::Path {
        0
    } else {
        if args.photon.photons == 0 {
            return Err(Error::InvalidSettings(format!(
                "--integrator {} needs photons: --photons must be at least 1 (photons per pass)",
                integrator.name()
            )));
        }
        photon_settings(&args.photon, args.seed)?.target_stored as u64
    };
    let pool = thread_pool(args.threads)?;
    let quiet = args.quiet || args.json;
    let bars = Bars::new(quiet);
    let control = Control {
        progress: &bars,
        cancel,
    };

    let loaded = load_scene(args.scene.as_deref(), &args.scene_args, &bars)?;
    let (scene, parse_seconds, build_seconds) = (loaded.scene, loaded.parse_seconds, loaded.build_seconds);
    if !quiet {
        for warning in scene.warnings() {
            eprintln!("warning: {warning}");
        }
        for note in physical_notes(&scene) {
            eprintln!("note: {note}");
        }
        let ignored = ignored_options(&args);
        if !ignored.is_empty() {
            eprintln!(
                "note: {} only apply to the course model's Whitted renderer; ignored here",
                ignored.join(", ")
            );
        }
    }
    let (width, height) = image_size(scene.camera(), args.width, args.height);
    check_image_size(width, height)?;
    let depth = args.depth.unwrap_or(64);
    let scene_id = match &args.scene {
        Some(path) => {
            let bytes = std::fs::read(path).map_err(|source| Error::Io {
                path: path.clone(),
                source,
            })?;
            format!("{:016x}", content_hash(&bytes))
        }
        None => "built-in-ring".into(),
    };
    let fingerprint = format!(
        "scene {scene_id} integrator {} size {width}x{height} seed {} photons {photons_per_pass} k {} alpha {} footprint {} radius {:?} depth {depth} camera-specular {} cone-quirks {} dialect {:?}",
        integrator.name(),
        args.seed,
        args.k,
        options.alpha,
        options.footprint,
        args.radius,
        !options.no_camera_specular,
        args.scene_args.cone_quirks,
        args.scene_args.dialect,
    );

    let renderer: Box<dyn Progressive> = match integrator {
        Integrator::Path => Box::new(PathTracer::new(
            &scene,
            PathSettings {
                max_depth: depth,
                specular_camera_paths: !options.no_camera_specular,
                ..PathSettings::default()
            },
            width,
            height,
            args.seed,
        )),
        Integrator::Ppm => Box::new(Ppm::new(
            &scene,
            PpmSettings {
                photons_per_pass,
                alpha: options.alpha,
                initial_radius: match args.radius {
                    Some(r) => InitialRadius::World(r),
                    None => InitialRadius::Pixels(options.footprint),
                },
                max_depth: depth,
                specular_camera_paths: !options.no_camera_specular,
            },
            width,
            height,
            args.seed,
        )),
        Integrator::Gi => Box::new(Gi::new(
            &scene,
            GiSettings {
                photons_per_pass,
                k_global: args.k,
                caustic_radius: match args.radius {
                    Some(r) => InitialRadius::World(r),
                    None => InitialRadius::Pixels(options.footprint),
                },
                alpha: options.alpha,
                max_depth: depth,
                specular_camera_paths: !options.no_camera_specular,
            },
            width,
            height,
            args.seed,
        )),
    };

    let tone_map = ToneMap::Reinhard {
        exposure: options.exposure,
    };
    let save = |acc: &Accumulator| -> Result<()> {
        if let Some(o) = &output {
            acc.film().save(o, tone_map)?;
        }
        if let Some(p) = &options.partial {
            acc.save(p)?;
        }
        Ok(())
    };

    let t_render = Instant::now();
    let mut acc = Accumulator::new(width, height, fingerprint);
    // The bar counts passes, or tenths of a second under --time.
    let (bar_total, by_time) = match (end_pass, options.time) {
        (Some(end), None) => (end - first_pass, false),
        (_, Some(t)) => ((t * 10.0).ceil() as u64, true),
        (None, None) => (DEFAULT_PASSES, false),
    };
    bars.start("passes", bar_total);
    let mut reported = 0u64;
    let mut last_save = Instant::now();
    let mut pass = first_pass;
    loop {
        if end_pass.is_some_and(|end| pass >= end) || control.cancelled() {
            break;
        }
        if let Some(limit) = options.time {
            if acc.pass_count() > 0 && t_render.elapsed().as_secs_f64() >= limit {
                break;
            }
        }
        let Some(pixels) = pool.install(|| renderer.render_pass(pass, control)) else {
            break;
        };
        acc.add(pass, &pixels);
        pass += 1;
        let done = if by_time {
            ((t_render.elapsed().as_secs_f64() * 10.0) as u64).min(bar_total)
        } else {
            acc.pass_count()
        };
        bars.advance(done.saturating_sub(reported));
        reported = reported.max(done);
        if last_save.elapsed().as_secs_f64() >= options.save_every {
            save(&acc)?;
            last_save = Instant::now();
        }
    }
    bars.finish();
    let render_seconds = t_render.elapsed().as_secs_f64();
    let complete = !control.cancelled();
    if acc.pass_count() == 0 {
        eprintln!("interrupted before the first pass finished: nothing was saved");
        return Ok(crate::EXIT_INTERRUPTED);
    }
    save(&acc)?;

    let total = start.elapsed().as_secs_f64();
    let passes: Vec<String> = acc.passes.iter().map(|(a, b)| format!("{a}..{b}")).collect();
    let shown = |p: &Option<PathBuf>| {
        p.as_ref()
            .map_or("null".to_string(), |p| crate::json::string(&p.display().to_string()))
    };
    if args.json {
        println!(
            "{{\"output\":{},\"partial\":{},\"integrator\":\"{}\",\"model\":\"physical\",\"width\":{width},\"height\":{height},\"passes\":{},\"pass_ranges\":\"{}\",\"photons_per_pass\":{photons_per_pass},\"complete\":{complete},\"seconds\":{{\"parse\":{parse_seconds:.4},\"build\":{build_seconds:.4},\"render\":{render_seconds:.4},\"total\":{total:.4}}},\"peak_memory_bytes\":{}}}",
            shown(&output),
            shown(&options.partial),
            integrator.name(),
            acc.pass_count(),
            passes.join(","),
            super::peak_memory_bytes().map_or("null".to_string(), |b| b.to_string()),
        );
    } else if !args.quiet {
        let written: Vec<String> = [&output, &options.partial]
            .into_iter()
            .flatten()
            .map(|p| p.display().to_string())
            .collect();
        eprintln!(
            "{} {width}×{height}, {} {} passes ({}){} — parse {parse_seconds:.2} s, build {build_seconds:.2} s, render {render_seconds:.2} s, total {total:.2} s{}",
            written.join(" and "),
            acc.pass_count(),
            integrator.name(),
            passes.join(","),
            if photons_per_pass > 0 {
                format!(", {photons_per_pass} photons a pass")
            } else {
                String::new()
            },
            if complete { "" } else { " (interrupted: the passes done are saved)" }
        );
    }
    Ok(if complete { 0 } else { crate::EXIT_INTERRUPTED })
}

/// Options of the Whitted renderer that a physical render was given but does not use.
fn ignored_options(args: &RenderArgs) -> Vec<&'static str> {
    let mut ignored = Vec::new();
    if args.aa != 1 {
        ignored.push("--aa (each pass takes one jittered sample per pixel)");
    }
    if args.photon.photons_per_light.is_some() {
        ignored.push("--photons-per-light");
    }
    if args.photon.no_aim {
        ignored.push("--no-aim");
    }
    if args.photon.max_emitted.is_some() {
        ignored.push("--max-emitted");
    }
    if args.no_estimate_reuse {
        ignored.push("--no-estimate-reuse");
    }
    ignored
}

/// What the physical model reads differently from the course's shading.
fn physical_notes(scene: &caustica::scene::Scene) -> Vec<String> {
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

/// Writes a merged accumulation (used by `caustica merge`).
pub fn save_merged(acc: &Accumulator, output: &Path, partial: Option<&Path>, exposure: f32) -> Result<()> {
    acc.film().save(output, ToneMap::Reinhard { exposure })?;
    if let Some(p) = partial {
        acc.save(p)?;
    }
    Ok(())
}
