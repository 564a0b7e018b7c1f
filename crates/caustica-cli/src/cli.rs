//! Command-line interface definitions.

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// caustica — a photon-mapping renderer for caustics, reading SBT-raytracer `.ray` scenes.
#[derive(Parser, Debug)]
#[command(name = "caustica", version, about, long_about = None, after_help = "Exit codes: 0 success, 1 internal error, 2 bad input or usage, 130 interrupted.")]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a scene to a PNG or EXR image.
    #[command(after_help = "Examples:
  caustica render                                   # the built-in ring scene to caustica.png
  caustica render scenes/lens.ray -o lens.png --aa 3
  caustica render scenes/ring.ray --photons 500000 --k 200 -o ring.exr
  caustica render scene.ray --photons 0             # plain Whitted, no caustics")]
    Render(RenderArgs),
    /// Show what was parsed: camera, lights, objects, bounds, materials.
    #[command(after_help = "Examples:
  caustica info scenes/ring.ray
  caustica info scene.ray --json")]
    Info(InfoArgs),
    /// Draw the stored caustic photons as points through the camera.
    #[command(after_help = "Reflected photons are drawn yellow, refracted ones blue, both green.

Examples:
  caustica photons scenes/ring.ray -o ring-photons.png
  caustica photons scenes/lens.ray -o lens-map.png --ply lens.ply --photons 50000
  caustica photons scenes/ring.ray --json            # a one-line summary on stdout")]
    Photons(PhotonArgs),
    /// Time whole renders of the project's scenes and print a table (for BENCHMARKS.md).
    #[command(
        after_help = "Each render runs in a child `caustica render --json` process, so peak memory is per render.

Examples:
  caustica bench                          # the full table, run from the repository root
  caustica bench --quick                  # small images, for a smoke test
  caustica bench --corpus ../shared/scenes/sbt-corpus   # adds the original project's ring scene"
    )]
    Bench(BenchArgs),
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Folder holding caustica's scenes.
    #[arg(long, default_value = "scenes")]
    pub scenes: PathBuf,
    /// Folder of the course corpus; adds the original project's ring scene at its worst-case settings.
    #[arg(long)]
    pub corpus: Option<PathBuf>,
    /// Small images and photon counts: checks the harness, not the speed.
    #[arg(long)]
    pub quick: bool,
    /// Worker threads for each render (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Repetitions of each render; the table shows the fastest.
    #[arg(long, default_value_t = 1)]
    pub repeat: usize,
}

/// Options shared by every command that reads a scene.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Reproduce the course skeleton's cone quirks (radius/slope clamps, doubled normal z).
    #[arg(long)]
    pub cone_quirks: bool,
    /// Read the file as this dialect instead of detecting it.
    #[arg(long, value_parser = ["tokenizer", "dictionary"])]
    pub dialect: Option<String>,
}

/// Photon-map options.
#[derive(Args, Debug, Clone)]
pub struct PhotonOptions {
    /// Caustic photons to store (0 disables caustics).
    #[arg(long, default_value_t = 200_000)]
    pub photons: usize,
    /// Stop emitting after this many photons (default: 200 per photon to store).
    #[arg(long)]
    pub max_emitted: Option<u64>,
    /// Photons to store per light, comma separated, instead of sharing by power.
    #[arg(long, value_delimiter = ',')]
    pub photons_per_light: Option<Vec<usize>>,
    /// Emit photons in all directions instead of aiming at mirrors and glass.
    #[arg(long)]
    pub no_aim: bool,
    /// Largest photon map in MB (photons are 24 bytes, the kd-tree under 1 byte each); larger
    /// photon counts are refused before any work.
    #[arg(long, default_value_t = 4096)]
    pub max_memory: u64,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The .ray scene (default: the built-in ring scene).
    pub scene: Option<PathBuf>,
    /// Output image; .png (8-bit) or .exr (linear float).
    #[arg(short, long, default_value = "caustica.png")]
    pub output: PathBuf,
    /// Image width in pixels.
    #[arg(long, default_value_t = 512)]
    pub width: usize,
    /// Image height in pixels (default: width / the camera's aspect ratio).
    #[arg(long)]
    pub height: Option<usize>,
    /// N×N stratified, jittered samples per pixel.
    #[arg(long, default_value_t = 1)]
    pub aa: u32,
    /// Maximum reflection/refraction depth.
    #[arg(long, default_value_t = 5)]
    pub depth: u32,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of all random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub photon: PhotonOptions,
    /// Photons per radiance estimate (k nearest).
    #[arg(long, default_value_t = 100)]
    pub k: usize,
    /// Largest gather radius in scene units (default: chosen from the photon density).
    #[arg(long)]
    pub radius: Option<f32>,
    /// Cone filter constant (≥ 1); 0 turns the filter off.
    #[arg(long, default_value_t = 1.1)]
    pub cone_filter: f32,
    /// Compute the caustic estimate for every sample instead of sharing a pixel's first one.
    #[arg(long)]
    pub no_estimate_reuse: bool,
    #[command(flatten)]
    pub scene_args: SceneArgs,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The .ray scene.
    pub scene: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub scene_args: SceneArgs,
}

#[derive(Args, Debug)]
pub struct PhotonArgs {
    /// The .ray scene.
    pub scene: PathBuf,
    /// Output picture (.png).
    #[arg(short, long, default_value = "photons.png")]
    pub output: PathBuf,
    /// Also write the photons as a PLY point cloud.
    #[arg(long)]
    pub ply: Option<PathBuf>,
    /// Image width in pixels.
    #[arg(long, default_value_t = 512)]
    pub width: usize,
    /// Image height in pixels (default: width / the camera's aspect ratio).
    #[arg(long)]
    pub height: Option<usize>,
    /// Worker threads (default: all cores).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of all random numbers.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
    /// Print a machine-readable summary on stdout.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub photon: PhotonOptions,
    #[command(flatten)]
    pub scene_args: SceneArgs,
}
