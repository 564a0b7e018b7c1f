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
use caustica::format::{obj, Format};
use caustica::integrator::RenderConfig;
use caustica::loader::{load_timed, LoadSettings, Loaded};
use caustica::math::Vec3;
use caustica::photon::{NoCaustics, PhotonSettings, PhotonStats};
use caustica::{Error, Result};
use std::path::Path;

/// Load settings from the command line.
pub fn load_settings(args: &SceneArgs) -> Result<LoadSettings> {
    let mut settings = LoadSettings::new(args.cone_quirks, args.dialect.as_deref())?;
    settings.read.format = args.format.as_deref().map(Format::from_name).transpose()?;
    settings.read.obj = obj_options(args)?;
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
    load_timed(path, &settings, bars)
}

/// Photon settings from the command line, checked.
pub fn photon_settings(options: &PhotonOptions, seed: u64) -> Result<PhotonSettings> {
    let config = RenderConfig {
        photons: options.photons.unwrap_or(RenderConfig::default().photons),
        max_emitted: options.max_emitted,
        photons_per_light: options.photons_per_light.clone(),
        no_aim: options.no_aim,
        seed,
        max_memory: options.max_memory,
        ..RenderConfig::default()
    };
    config.integrator()?;
    Ok(config.photon_settings())
}

/// How many emitted photons stored something, e.g. "62.1% landed, 1.20 stores each".
pub fn landed_text(s: &PhotonStats) -> String {
    let each = s.stores_per_landing();
    if each > 1.005 {
        format!("{:.1}% landed, {each:.2} stores each", 100.0 * s.useful_fraction())
    } else {
        format!("{:.1}% landed", 100.0 * s.useful_fraction())
    }
}

/// The photon pass in words: what it emitted and stored, and why there are no caustics when
/// there are none.
pub fn photon_lines(s: &PhotonStats, seconds: f64) -> Vec<String> {
    if let Some(reason) = s.none {
        let traced = match reason {
            NoCaustics::NoneLanded { .. } => "stopped early",
            _ => "none traced",
        };
        return vec![format!("photons: {traced}: {reason}: no caustics")];
    }
    let mut lines = vec![format!(
        "photons: {} emitted, {} stored ({}) in {seconds:.2} s{}",
        s.emitted,
        s.stored,
        landed_text(s),
        if s.cap_reached {
            " — emission cap reached before the budget was stored"
        } else {
            ""
        }
    )];
    if s.stored == 0 {
        lines.push("photons: none stored: no caustics".into());
    }
    lines
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
