//! The options of `render` (and of the other commands that read a scene or trace photons).

use clap::Args;
use std::path::PathBuf;

/// Options shared by every command that reads a scene.
#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// Read the scene as this format instead of the one its extension names (.ray, .pbrt,
    /// .gltf/.glb, .obj; other extensions are read as .ray).
    #[arg(long, value_parser = ["ray", "pbrt", "gltf", "obj"])]
    pub format: Option<String>,
    /// Reproduce the course skeleton's cone quirks (radius/slope clamps, doubled normal z).
    #[arg(long)]
    pub cone_quirks: bool,
    /// Read the file as this dialect instead of detecting it (hkust: the dictionary reader with
    /// the HKUST COMP 4411 skeleton's defaults, e.g. point lights that do not fall off).
    #[arg(long, value_parser = ["tokenizer", "dictionary", "hkust"])]
    pub dialect: Option<String>,
    /// OBJ scenes: the camera's eye, X,Y,Z (default: framing the mesh from +z, a little above).
    #[arg(long, value_name = "X,Y,Z", allow_negative_numbers = true)]
    pub look_from: Option<String>,
    /// OBJ scenes: the point the camera looks at, X,Y,Z (default: the mesh's centre).
    #[arg(long, value_name = "X,Y,Z", allow_negative_numbers = true)]
    pub look_at: Option<String>,
    /// OBJ scenes: the camera's up direction.
    #[arg(long, value_name = "X,Y,Z", default_value = "0,1,0", allow_negative_numbers = true)]
    pub up: String,
    /// OBJ scenes: the camera's vertical field of view in degrees.
    #[arg(long, default_value_t = 40.0)]
    pub fov: f32,
    /// OBJ scenes: a point light X,Y,Z,R,G,B (repeatable; default: one over the camera's
    /// shoulder giving unit irradiance at the mesh's centre, none when the mesh emits light).
    #[arg(long, value_name = "X,Y,Z,R,G,B", allow_negative_numbers = true)]
    pub point_light: Vec<String>,
    /// OBJ scenes: a directional light DX,DY,DZ,R,G,B, the direction its light travels (repeatable).
    #[arg(long, value_name = "DX,DY,DZ,R,G,B", allow_negative_numbers = true)]
    pub directional_light: Vec<String>,
}

/// Photon-map options.
#[derive(Args, Debug, Clone)]
pub struct PhotonOptions {
    /// Caustic photons to store (0 disables caustics); photons per pass of ppm and gi, light
    /// paths per pass of lt and vcm [default: 200000, or what a pbrt-v4 scene's sppm integrator
    /// asks; vcm: a pilot balances them against its camera paths]
    #[arg(long)]
    pub photons: Option<usize>,
    /// Stop emitting after this many photons (default: 200 per photon to store).
    #[arg(long)]
    pub max_emitted: Option<u64>,
    /// Photons to store per light, comma separated, instead of sharing by power.
    #[arg(long, value_delimiter = ',')]
    pub photons_per_light: Option<Vec<usize>>,
    /// Emit photons in all directions instead of aiming at mirrors and glass (course model;
    /// vcm: none of its light subpaths, nor their bounces, aimed).
    #[arg(long)]
    pub no_aim: bool,
    /// Largest photon map in MB (photons are 24 bytes, the kd-tree under 1 byte each); larger
    /// photon counts are refused before any work.
    #[arg(long, default_value_t = 4096)]
    pub max_memory: u64,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    /// The scene: .ray, .pbrt, .gltf/.glb or .obj (default: the built-in ring scene).
    pub scene: Option<PathBuf>,
    /// Output image; .png (8-bit) or .exr (linear float) [default: caustica.png (a pbrt-v4
    /// scene's Film filename), or none when only a --partial file is asked for].
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Image width in pixels [default: 512, or a pbrt-v4 scene's Film resolution].
    #[arg(long)]
    pub width: Option<usize>,
    /// Image height in pixels (default: width / the camera's aspect ratio; another aspect crops
    /// or extends the picture by the format's rule, never stretches it).
    #[arg(long)]
    pub height: Option<usize>,
    /// N×N stratified, jittered samples per pixel.
    #[arg(long, default_value_t = 1)]
    pub aa: u32,
    /// Bounces after the first surface the eye sees: light reaches the eye after scattering at
    /// no more than N + 1 surfaces (whitted: N reflection/refraction rays) [default: 5 for
    /// whitted, 64 for path, ppm, gi, lt; a pbrt-v4 scene's maxdepth − 1].
    #[arg(long)]
    pub depth: Option<u32>,
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
    /// Course model's caustic estimate: `kernels`, each photon spread over a kernel as wide as
    /// its distance to its k-th neighbour (adapts to the photon density), or `nearest`, the k
    /// nearest photons within the largest radius (Jensen's).
    #[arg(long, value_parser = ["kernels", "nearest"], default_value = "kernels")]
    pub estimate: String,
    /// Compute the caustic estimate for every sample instead of sharing a pixel's first one.
    #[arg(long)]
    pub no_estimate_reuse: bool,
    #[command(flatten)]
    pub progressive: ProgressiveOptions,
    #[command(flatten)]
    pub preview: PreviewOptions,
    #[command(flatten)]
    pub scene_args: SceneArgs,
}

/// Watching a render as it runs.
#[derive(Args, Debug, Clone)]
pub struct PreviewOptions {
    /// Show the image in a running tev viewer at [HOST:]PORT (host 127.0.0.1 by default; tev
    /// listens on 14158) as it renders: the Whitted tiles as they finish, the mean after each pass.
    #[arg(long, value_name = "[HOST:]PORT")]
    pub display: Option<String>,
    /// Rewrite the output image with the running image as it renders (atomically: a viewer
    /// that reloads it never sees half a file).
    #[arg(long)]
    pub preview: bool,
    /// Seconds between updates [default: 0.5 for --display, 2 for --preview, whose image
    /// encoding costs more].
    #[arg(long)]
    pub preview_every: Option<f64>,
}

/// The physical model and its integrators.
#[derive(Args, Debug, Clone)]
pub struct ProgressiveOptions {
    /// Shading model: `course` (the .ray look, Whitted) or `physical` (radiometric units,
    /// inverse-square lights, Fresnel glass, emissive objects as area lights) [default: course
    /// for .ray and .obj, physical for .pbrt and glTF].
    #[arg(long, value_parser = ["course", "physical"])]
    pub model: Option<String>,
    /// Integrator: whitted (course model), or path, ppm, gi, lt, vcm (physical model: what a
    /// pbrt-v4 scene names; vcm for a pbrt or glTF file that names none, as it shows the
    /// caustics of point, spot and sun lights; ppm for a .ray or .obj file with --model
    /// physical). lt is light tracing: mirrors, glass and lights seen by the camera are black.
    /// vcm is vertex connection and merging: all of them, weighted against each other.
    #[arg(long, value_parser = ["whitted", "path", "ppm", "gi", "lt", "vcm"])]
    pub integrator: Option<String>,
    /// Passes to render: N (passes 0..N) or A..B (passes A to B−1 of a run split across
    /// machines) [default: 64 unless --time is given, or a pbrt-v4 scene's pixelsamples].
    #[arg(long)]
    pub passes: Option<String>,
    /// Render passes until this many seconds have passed (at least one pass).
    #[arg(long)]
    pub time: Option<f64>,
    /// Also write the sums of the passes to this file, for `caustica merge`.
    #[arg(long)]
    pub partial: Option<PathBuf>,
    /// Seconds between rewrites of the image while passes run.
    #[arg(long, default_value_t = 10.0)]
    pub save_every: f64,
    /// Exposure in stops for PNG output: values are multiplied by 2^E before the tone map.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub exposure: f32,
    /// PNG tone map: `clamp` (the course's: clamp to 1, no gamma), `reinhard` (x/(1+x), then
    /// sRGB) or `linear` (clamp to 1, then sRGB) [default: clamp for the course model, reinhard
    /// for the physical one].
    #[arg(long, value_parser = ["clamp", "reinhard", "linear"])]
    pub tone_map: Option<String>,
    /// ppm, gi: first gather radius in pixels at the gather point (the footprint the blur starts
    /// from); vcm: first merging radius in pixels [default: 2 for ppm and gi; 3 for vcm where the
    /// eye sees a caustic's focus directly or `--photons` is given, else 2].
    #[arg(long)]
    pub footprint: Option<f32>,
    /// Black wherever the camera looks into a mirror or through glass, as in a particle tracer's
    /// image (for comparing with one).
    #[arg(long)]
    pub no_camera_specular: bool,
    /// Physical model: carry light at sampled wavelengths (hero-wavelength sampling) instead of
    /// RGB [default: when the scene has a dispersive glass, `abbe`].
    #[arg(long, overrides_with = "no_spectral")]
    pub spectral: bool,
    /// Physical model: carry light in RGB even with dispersive glass (which then does not disperse).
    #[arg(long)]
    pub no_spectral: bool,
    /// ppm: Knaus–Zwicker α in (0, 1); the radius² shrinks by (i + α)/(i + 1) each pass.
    #[arg(long, default_value_t = 2.0 / 3.0)]
    pub alpha: f32,
    /// vcm: also connect every camera vertex to every vertex of one light subpath
    /// (bidirectional path tracing's inner connections); off by default: on the Cornell box
    /// race they cost more than they gain.
    #[arg(long)]
    pub vertex_connections: bool,
    /// vcm: no beam queries in media (camera rays gathering the light vertices along their
    /// way); light in fog then comes from light tracing and next-event estimation alone.
    #[arg(long)]
    pub no_beams: bool,
}
