//! vcm's settings and the tunables measured for them (each constant names its benchmark).

use super::*;

/// Settings of vertex connection and merging.
#[derive(Clone, Debug, PartialEq)]
pub struct VcmSettings {
    /// Light subpaths per pass (`None`: as many as a pilot finds best against the camera paths
    /// ([`balance`]), and half as many in the first two passes).
    pub light_paths_per_pass: Option<u64>,
    /// Knaus & Zwicker's α in (0, 1): how fast the merging radius shrinks.
    pub alpha: f32,
    /// The first pass's merging radius: a number of pixels as wide as they are at the distance
    /// from the eye to the scene's centre, or a world radius.
    pub initial_radius: InitialRadius,
    /// Bounces: light reaches the eye from at most this many surfaces plus one.
    pub max_depth: u32,
    /// Connect every smooth camera vertex to every vertex of one light subpath (bidirectional
    /// path tracing's inner connections). Off, the strategies are the camera path's own (hitting
    /// emitters, next-event estimation), light tracing and merging, and camera paths cost far
    /// less; on the Cornell box race that wins (docs/benchmarks/2026-12-02.md, "The caustics
    /// race: vcm against Mitsuba 3").
    pub connections: bool,
    /// Aim [`AIM_SHARE`] of the light subpaths, and [`BOUNCE_AIM_SHARE`] of their bounces off
    /// Lambertian surfaces, at the mirrors and glass (`--no-aim`: none).
    pub aim: bool,
    /// Carry light at sampled wavelengths instead of RGB (`None`: when the scene has a
    /// dispersive glass).
    pub spectral: Option<bool>,
    /// Camera samples a pass in the pixels that see a caustic's focus (1: one, as elsewhere).
    pub focus_samples: usize,
    /// The first merging radius in pixels where the balance pilot chose the count (the eye sees
    /// no caustic's focus directly); `None` keeps `initial_radius` there too. `--radius` and
    /// `--footprint` set `None`.
    pub balanced_footprint: Option<f32>,
    /// Merge in homogeneous media: camera rays gather the light vertices along their way
    /// ([`beams`]; `--no-beams`: light tracing and next-event estimation only).
    pub beams: bool,
}

impl Default for VcmSettings {
    fn default() -> Self {
        VcmSettings {
            light_paths_per_pass: None,
            alpha: 2.0 / 3.0,
            initial_radius: InitialRadius::Pixels(MERGING_FOOTPRINT),
            max_depth: 64,
            connections: false,
            aim: true,
            spectral: None,
            focus_samples: FOCUS_CAMERA_SAMPLES,
            balanced_footprint: Some(BALANCED_FOOTPRINT),
            beams: true,
        }
    }
}

/// The first pass's merging radius in pixels. Measured on the Cornell box race at equal
/// passes (eight seeds, docs/benchmarks/2026-12-02.md, "The caustics race: vcm with more camera
/// samples at the focus, and cheaper passes"): 3 pixels against 2 cut the caustic region's error by
/// 44% at one pass and 14–39% at 3 and 9, level at 20, the focus level, for 2–15% more time
/// a pass (more light vertices to merge); 1 pixel doubled it. (`ppm`'s gathers keep 2:
/// `--footprint` gives both.)
pub const MERGING_FOOTPRINT: f32 = 3.0;

/// The first merging radius in pixels of a scene the balance pilot balanced. Against a
/// reference of `scenes/pool.ray` (a caustic net seen through water), 3 pixels' blur was most of
/// vcm's error at 20 s; 2 pixels cut it 1.5× (docs/benchmarks/2026-12-03.md, "The pool against a
/// reference").
pub const BALANCED_FOOTPRINT: f32 = 2.0;

/// The share of light subpaths aimed at the bounding spheres of mirrors and glass: caustic
/// paths become several times more frequent while the rest keep most of their subpaths.
/// Measured on the race (0.5–4 s, four seeds): 0.15 cut the focus error by 20–60% for
/// 1.1–1.6× the caustic region's error; 0.3 and 0.5 took too many subpaths from the indirect
/// light merged around the caustic (region error 1.4–2.2×) (docs/benchmarks/2026-12-02.md,
/// "The caustics race, aimed vcm").
pub const AIM_SHARE: f32 = 0.15;

/// The share of a directional light's or sun's subpaths (and the sky's) aimed at the mirrors
/// and glass: their beam covers the whole scene, where a glass may take a hundredth of it.
pub const FAR_AIM_SHARE: f32 = 0.5;

/// The share of the light subpaths' bounces off Lambertian surfaces aimed at the mirrors and
/// glass. Light that a lamp-lit ceiling or wall sends through a glass is a second caustic over
/// the first; unaimed, few subpaths carry it, and it was most of the area light's focus noise.
/// A bounce towards a mirror or glass carries little power then (its density is the aimed
/// mixture's) and skips the roulette, so such subpaths become many times more frequent.
/// 0.05 of every bounce cut the race's focus error by 29–36% for 7–8% more time; more, or only
/// the first bounce, was no better (measured: docs/benchmarks/2026-12-03.md, "Aimed
/// bounces").
pub const BOUNCE_AIM_SHARE: f32 = 0.05;

/// Light subpaths per pixel and pass where the eye sees a caustic's focus (elsewhere the
/// balance pilot chooses, [`balance`]), and the weights of the pilot's estimates. Measured on
/// the Cornell box race (docs/benchmarks/2026-12-02.md, "The caustics race: vcm with 16 light
/// subpaths per pixel"), at equal time: 16 cut the focus's error by a fifth and
/// the caustic region's by a sixth against 8; 24 was no better. The first passes trace half
/// (`Vcm::pass_light_paths`).
pub const LIGHT_PATHS_PER_PIXEL: u64 = 16;
/// The default's cap, so that a large image's pass stays within memory (about 100 bytes per
/// stored light vertex, one or two per path).
pub const MAX_DEFAULT_LIGHT_PATHS: u64 = 4_000_000;

/// Light subpaths per batch: the unit of parallel work and of the fixed order of addition.
pub(super) const BATCH: u64 = 1024;
/// Seed offset of the light subpaths (apart from the photon mappers' streams).
pub(super) const LIGHT_SEED: u64 = PHOTON_SEED ^ 0x0076_636d;
/// Next-event samples of each emissive object at the camera path's first vertex. One: four
/// halved the area light's image error at one pass but slowed every pass more than the
/// caustic gained (measured on the race's scenes).
pub(super) const FIRST_VERTEX_LIGHT_SAMPLES: u32 = 1;
/// Camera samples a pass in a pixel that sees a focused cell by default. Their first vertices
/// merge the light around the focus from the same light subpaths, and which of the few bright
/// subpaths a single sample's disc catches is a large part of the focus's noise. At one pass, 8
/// cut the focus's error by 13–28% and the caustic region's by 20–23% against 1; 16 was no
/// better (measured: docs/benchmarks/2026-12-02.md, "The caustics race: vcm with more camera
/// samples at the focus, and cheaper passes"). The focus's pixels are a few hundred of the
/// image's, so the pass takes no measurably longer.
pub const FOCUS_CAMERA_SAMPLES: usize = 8;
/// Camera bounces before Russian roulette may end a camera path.
pub(super) const ROULETTE_DEPTH: u32 = 3;
