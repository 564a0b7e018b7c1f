//! One module per subcommand, plus what they share.

pub mod bench;
pub mod compare;
pub mod info;
pub mod merge;
pub mod photons;
pub mod progressive;
pub mod render;

use crate::cli::{PhotonOptions, SceneArgs};
use crate::progress::Bars;
use caustica::format::ray_file::ast::Dialect;
use caustica::format::ray_file::ParseOptions;
use caustica::format::{self, ReadOptions};
use caustica::loader::{build_source, LoadSettings};
use caustica::photon::PhotonSettings;
use caustica::presets;
use caustica::scene::Scene;
use caustica::{Error, Result};
use std::path::Path;
use std::time::Instant;

/// Largest image side accepted: beyond it the film alone would not fit in memory.
const MAX_SIDE: usize = 32_768;
/// Largest pixel count (1 GiB of float RGB film).
const MAX_PIXELS: usize = 1 << 26;
/// Largest photon count accepted (24 bytes each: 2.4 GB).
const MAX_PHOTONS: usize = 100_000_000;

/// Load settings from the command line.
pub fn load_settings(args: &SceneArgs) -> LoadSettings {
    let mut settings = LoadSettings::default();
    settings.build.shapes.cone_quirks = args.cone_quirks;
    settings.read = ReadOptions {
        ray: ParseOptions {
            dialect: match args.dialect.as_deref() {
                Some("tokenizer") => Some(Dialect::Tokenizer),
                Some("dictionary") => Some(Dialect::Dictionary),
                _ => None,
            },
        },
    };
    settings
}

/// A built scene and the seconds its two phases took.
pub struct Loaded {
    /// The scene.
    pub scene: Scene,
    /// Reading and parsing the file.
    pub parse_seconds: f64,
    /// Building shapes, meshes, textures and the BVH.
    pub build_seconds: f64,
}

/// Reads and parses the scene file, or the built-in ring scene when no path is given, then
/// builds it: two phases, each with its bar.
pub fn load_scene(path: Option<&Path>, args: &SceneArgs, bars: &Bars) -> Result<Loaded> {
    let settings = load_settings(args);
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
    let scene = build_source(source?, &settings.build, bars)?;
    Ok(Loaded {
        scene,
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

/// Refuses image sizes that cannot be rendered, before any memory is committed.
pub fn check_image_size(width: usize, height: usize) -> Result<()> {
    if width == 0 || height == 0 {
        return Err(Error::InvalidSettings(
            "the image needs a width and height of at least 1 pixel".into(),
        ));
    }
    if width > MAX_SIDE || height > MAX_SIDE || width.saturating_mul(height) > MAX_PIXELS {
        return Err(Error::InvalidSettings(format!(
            "{width}×{height} is too large: at most {MAX_SIDE} pixels a side and {MAX_PIXELS} pixels in all"
        )));
    }
    Ok(())
}

/// Photon settings from the command line, checked.
pub fn photon_settings(options: &PhotonOptions, seed: u64) -> Result<PhotonSettings> {
    let total = match &options.photons_per_light {
        Some(counts) => counts.iter().fold(0usize, |a, b| a.saturating_add(*b)),
        None => options.photons,
    };
    // 24 bytes a photon plus the tree's node per 8–16 photons; stored counts overshoot by a few.
    let needed_mb = (total as u64).saturating_mul(25) / 1_000_000;
    if needed_mb > options.max_memory {
        return Err(Error::InvalidSettings(format!(
            "{total} photons need about {needed_mb} MB, more than --max-memory {} MB: store fewer photons or raise the cap",
            options.max_memory
        )));
    }
    if total > MAX_PHOTONS {
        return Err(Error::InvalidSettings(format!(
            "{total} photons would need {} MB; at most {MAX_PHOTONS} photons are accepted",
            total.saturating_mul(24) / 1_000_000
        )));
    }
    Ok(PhotonSettings {
        target_stored: total,
        max_emitted: options.max_emitted.unwrap_or(0),
        aim: !options.no_aim,
        seed,
        per_light: options.photons_per_light.clone(),
        ..PhotonSettings::default()
    })
}

/// Peak resident memory of this process in bytes (Linux), if known.
pub fn peak_memory_bytes() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
