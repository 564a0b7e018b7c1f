//! One module per subcommand, plus what they share.

pub mod bench;
pub mod compare;
pub mod info;
pub mod merge;
pub mod photons;
pub mod render;

use crate::cli::{PhotonOptions, SceneArgs};
use crate::progress::Bars;
use caustica::integrator::RenderConfig;
use caustica::loader::{load_timed, LoadSettings, Loaded};
use caustica::photon::PhotonSettings;
use caustica::Result;
use std::path::Path;

/// Load settings from the command line.
pub fn load_settings(args: &SceneArgs) -> Result<LoadSettings> {
    LoadSettings::new(args.cone_quirks, args.dialect.as_deref())
}

/// Reads and parses the scene file, or the built-in ring scene when no path is given, then
/// builds it: two phases, each with its bar.
pub fn load_scene(path: Option<&Path>, args: &SceneArgs, bars: &Bars) -> Result<Loaded> {
    load_timed(path, &load_settings(args)?, bars)
}

/// Photon settings from the command line, checked.
pub fn photon_settings(options: &PhotonOptions, seed: u64) -> Result<PhotonSettings> {
    let config = RenderConfig {
        photons: options.photons,
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
