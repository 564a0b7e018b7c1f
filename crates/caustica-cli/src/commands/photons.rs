//! `caustica photons`: the stored caustic photons drawn through the camera, and a PLY dump.

use super::{check_image_size, load_scene, photon_settings, thread_pool};
use crate::cli::PhotonArgs;
use crate::progress::Bars;
use caustica::film::ToneMap;
use caustica::integrator::{image_size, Control};
use caustica::photon::picture::{draw_photons, write_ply};
use caustica::photon::PhotonMap;
use caustica::Result;
use std::sync::atomic::AtomicBool;

/// Runs the command; returns the exit code.
pub fn run(args: PhotonArgs, cancel: &'static AtomicBool) -> Result<u8> {
    caustica::image_io::ImageFormat::from_path(&args.output)?;
    let settings = photon_settings(&args.photon, args.seed)?;
    let pool = thread_pool(args.threads)?;
    let scene = load_scene(Some(&args.scene), &args.scene_args)?;
    let (width, height) = image_size(&scene.camera, args.width, args.height);
    check_image_size(width, height)?;
    let bars = Bars::new(args.quiet);
    let control = Control {
        progress: &bars,
        cancel,
    };
    let map = pool.install(|| PhotonMap::trace(&scene, &settings, 1, control));
    let film = draw_photons(&scene, map.photons(), width, height);
    film.save(&args.output, ToneMap::Clamp)?;
    if let Some(ply) = &args.ply {
        write_ply(ply, map.photons())?;
    }
    if !args.quiet {
        let s = &map.stats;
        eprintln!(
            "{}: {} photons stored of {} emitted ({:.1}% useful) in {:.2} s{}",
            args.output.display(),
            s.stored,
            s.emitted,
            100.0 * s.useful_fraction(),
            s.seconds,
            if s.cap_reached { " — emission cap reached" } else { "" }
        );
    }
    Ok(0)
}
