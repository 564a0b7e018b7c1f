//! One module per subcommand, plus what they share.

pub mod bench;
pub mod compare;
pub mod info;
pub mod merge;
pub mod photons;
pub mod render;

use crate::cli::{PhotonOptions, SceneArgs};
use crate::progress::Bars;
use caustica::description::LightDesc;
use caustica::format::ray_file::ast::Dialect;
use caustica::format::ray_file::ParseOptions;
use caustica::format::{self, obj, Format, ReadOptions};
use caustica::integrator::RenderConfig;
use caustica::loader::{build_detected, scene_id, LoadSettings};
use caustica::math::Vec3;
use caustica::photon::PhotonSettings;
use caustica::presets;
use caustica::scene::Scene;
use caustica::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// Load settings from the command line.
pub fn load_settings(args: &SceneArgs) -> Result<LoadSettings> {
    let mut settings = LoadSettings::default();
    settings.build.shapes.cone_quirks = args.cone_quirks;
    settings.read = ReadOptions {
        ray: ParseOptions {
            dialect: match args.dialect.as_deref() {
                Some("tokenizer") => Some(Dialect::Tokenizer),
                Some("dictionary") => Some(Dialect::Dictionary),
                Some("hkust") => Some(Dialect::Hkust),
                _ => None,
            },
        },
        format: args.format.as_deref().map(Format::from_name).transpose()?,
        obj: obj_options(args)?,
    };
    Ok(settings)
}

/// Numbers separated by commas, exactly `n` of them.
fn numbers(flag: &str, text: &str, n: usize) -> Result<Vec<f32>> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|_| Error::InvalidSettings(format!("--{flag} {text}: expected {n} numbers separated by commas")))?;
    if values.len() != n || values.iter().any(|v| !v.is_finite()) {
        return Err(Error::InvalidSettings(format!(
            "--{flag} {text}: expected {n} finite numbers separated by commas"
        )));
    }
    Ok(values)
}

fn vec3(flag: &str, text: &str) -> Result<Vec3> {
    let v = numbers(flag, text, 3)?;
    Ok(Vec3::new(v[0], v[1], v[2]))
}

/// The camera and lights of an OBJ scene from the command line.
fn obj_options(args: &SceneArgs) -> Result<obj::SceneOptions> {
    let mut options = obj::SceneOptions::default();
    if !(args.fov > 0.0 && args.fov < 180.0) {
        return Err(Error::InvalidSettings(
            "--fov must lie between 0 and 180 degrees".into(),
        ));
    }
    let up = vec3("up", &args.up)?;
    if args.look_from.is_some() || args.look_at.is_some() || args.fov != 40.0 || args.up != "0,1,0" {
        let eye = args.look_from.as_deref().map(|t| vec3("look-from", t)).transpose()?;
        let at = args.look_at.as_deref().map(|t| vec3("look-at", t)).transpose()?;
        options.camera = Some(obj::CameraRequest {
            eye,
            target: at,
            up,
            fov_degrees: args.fov,
        });
    }
    for text in &args.point_light {
        let v = numbers("point-light", text, 6)?;
        options.lights.push(LightDesc::Point {
            position: Vec3::new(v[0], v[1], v[2]),
            color: Vec3::new(v[3], v[4], v[5]),
            attenuation: [0.0, 0.0, 1.0],
            span: 0..0,
        });
    }
    for text in &args.directional_light {
        let v = numbers("directional-light", text, 6)?;
        let direction = Vec3::new(v[0], v[1], v[2]);
        if direction == Vec3::ZERO {
            return Err(Error::InvalidSettings(
                "--directional-light needs a non-zero direction".into(),
            ));
        }
        options.lights.push(LightDesc::Directional {
            direction,
            color: Vec3::new(v[3], v[4], v[5]),
            span: 0..0,
        });
    }
    Ok(options)
}

/// A built scene and the seconds its two phases took.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// What identifies it in a render's fingerprint.
    pub scene_id: String,
    /// Reading and parsing the file.
    pub parse_seconds: f64,
    /// Building shapes, meshes, textures and the BVH.
    pub build_seconds: f64,
}

/// Reads and parses the scene file, or the built-in ring scene when no path is given, then
/// builds it: two phases, each with its bar.
pub fn load_scene(path: Option<&Path>, args: &SceneArgs, bars: &Bars) -> Result<Loaded> {
    let settings = load_settings(args)?;
    if let Some(path) = path {
        let obj_flags = args.look_from.is_some()
            || args.look_at.is_some()
            || !args.point_light.is_empty()
            || !args.directional_light.is_empty();
        if obj_flags && settings.read.format_of(path) != Format::Obj {
            return Err(Error::InvalidSettings(
                "--look-from, --look-at, --point-light and --directional-light set up OBJ scenes; this scene has its own camera and lights".into(),
            ));
        }
    }
    let start = Instant::now();
    let source = match path {
        Some(path) => format::read_file(path, &settings.read, bars),
        None => format::read_text(
            Path::new("<built-in ring scene>"),
            presets::RING.to_string(),
            Path::new("."),
            &settings.read,
            bars,
        ),
    };
    let parse_seconds = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let source = source?;
    let scene_id = scene_id(&source, &settings);
    let (_, scene) = build_detected(source, &settings, bars)?;
    Ok(Loaded {
        scene,
        scene_id,
        parse_seconds,
        build_seconds: start.elapsed().as_secs_f64(),
    })
}

/// Makes a thread pool of `threads` workers (all cores by default).
pub fn thread_pool(threads: Option<usize>) -> Result<rayon::ThreadPool> {
    if threads == Some(0) || threads.is_some_and(|t| t > 1024) {
        return Err(Error::InvalidSettings("--threads must be between 1 and 1024".into()));
    }
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::InvalidSettings(format!("cannot start worker threads: {e}")))
}

/// Refuses photon counts whose map would exceed `--max-memory` MB, before any work.
pub fn check_photon_memory(total: usize, max_memory: u64) -> Result<()> {
    // 24 bytes a photon plus the tree's node per 8–16 photons; stored counts overshoot by a few.
    let needed_mb = (total as u64).saturating_mul(25) / 1_000_000;
    if needed_mb > max_memory {
        return Err(Error::InvalidSettings(format!(
            "{total} photons need about {needed_mb} MB, more than --max-memory {max_memory} MB: store fewer photons or raise the cap"
        )));
    }
    Ok(())
}

/// Photon settings from the command line, checked.
pub fn photon_settings(options: &PhotonOptions, seed: u64) -> Result<PhotonSettings> {
    let config = RenderConfig {
        photons: options.photons.unwrap_or(RenderConfig::default().photons),
        max_emitted: options.max_emitted,
        photons_per_light: options.photons_per_light.clone(),
        no_aim: options.no_aim,
        seed,
        ..RenderConfig::default()
    };
    check_photon_memory(config.photon_total(), options.max_memory)?;
    config.integrator()?;
    Ok(config.photon_settings())
}

/// A path as JSON shows it (`null` for none); any path prints, UTF-8 or not.
pub fn shown(path: &Option<std::path::PathBuf>) -> Option<String> {
    path.as_ref().map(|p| p.display().to_string())
}

/// Peak resident memory of this process in bytes (Linux), if known.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
