//! `render`'s options: the command line's over the scene's own settings, and the checks made
//! before any work.

use crate::cli::RenderArgs;
use caustica::description::RenderHints;
use caustica::integrator::config::{GivenOptions, Model};
use caustica::integrator::RenderConfig;
use caustica::photon::Estimator;
use caustica::{Error, Result};
use std::path::PathBuf;

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
        no_beams: p.no_beams,
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
pub(super) fn given(args: &RenderArgs) -> GivenOptions {
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

/// Refuses preview options that cannot work, before any work.
pub(super) fn check_preview(args: &RenderArgs, output: &Option<PathBuf>) -> Result<()> {
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
