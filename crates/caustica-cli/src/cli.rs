//! Command-line interface definitions.

mod render_args;

pub use render_args::{PhotonOptions, RenderArgs, SceneArgs};

use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;

/// caustica — a photon-mapping renderer for caustics, reading SBT-raytracer `.ray`, pbrt-v4,
/// glTF 2.0 and Wavefront OBJ scenes.
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
  caustica render scene.ray --photons 0             # plain Whitted, no caustics
  caustica render scene.ray --model physical --passes 256 -o out.exr     # progressive photon mapping
  caustica render scene.ray --integrator path --time 60 -o reference.exr # path-traced reference
  caustica render scene.ray --model physical --display 14158 -o out.exr  # watch it in tev
  caustica render scene.ray --aa 4 --preview -o out.png                  # out.png rewritten as it renders
  caustica render scene.pbrt                         # pbrt-v4: its Film, Sampler and Integrator apply
  caustica render model.glb --integrator ppm -o model.png
  caustica render bunny.obj --point-light 0,4,4,16,16,16 --look-from 0,1,3")]
    Render(Box<RenderArgs>),
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
    /// Merge the partial files of a split progressive run into one image.
    #[command(after_help = "Passes are independent: parts rendered on several machines with
`render --passes A..B --partial part.part` merge into exactly the image of one run over all
passes. Parts of different runs (scene or settings) or sharing a pass are refused.

Examples:
  caustica render scene.ray --model physical --passes 0..32 --partial a.part
  caustica render scene.ray --model physical --passes 32..64 --partial b.part
  caustica merge a.part b.part -o image.exr")]
    Merge(MergeArgs),
    /// Compare an EXR image with a reference EXR: region means and relative errors.
    #[command(
        after_help = "Regions are inclusive row and column ranges counted from the top-left pixel,
ROWS,COLS as R0..R1,C0..C1, optionally named NAME=R0..R1,C0..C1. With no region the whole image is compared.

Examples:
  caustica compare ppm.exr reference.exr
  caustica compare ppm.exr reference.exr --region caustic=135..139,41..45 --region floor=150..158,60..90"
    )]
    Compare(CompareArgs),
}

#[derive(Args, Debug)]
pub struct CompareArgs {
    /// The image to check (.exr).
    pub image: PathBuf,
    /// The reference (.exr), of the same size.
    pub reference: PathBuf,
    /// A region: [NAME=]R0..R1,C0..C1 (inclusive, from the top-left).
    #[arg(long)]
    pub region: Vec<String>,
    /// Print JSON instead of a table.
    #[arg(long)]
    pub json: bool,
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

#[derive(Args, Debug)]
pub struct MergeArgs {
    /// Partial files written by `render --partial`.
    #[arg(required = true)]
    pub parts: Vec<PathBuf>,
    /// The merged image; .png (tone-mapped) or .exr (linear float).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Also write the merged sums as a partial file (to merge further later).
    #[arg(long)]
    pub partial: Option<PathBuf>,
    /// Exposure in stops for PNG output.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// Print nothing but errors.
    #[arg(short, long)]
    pub quiet: bool,
}

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// The scene.
    pub scene: PathBuf,
    /// Print JSON instead of text.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub scene_args: SceneArgs,
}

#[derive(Args, Debug)]
pub struct PhotonArgs {
    /// The scene.
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
    /// Image height in pixels (default: width / the camera's aspect ratio; another aspect crops
    /// or extends the picture by the format's rule, never stretches it).
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
