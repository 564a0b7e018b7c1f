//! The physical model's integrators against closed forms (the furnace) and against reference
//! images from an independent renderer (Mitsuba 3's particle tracer, in `../shared/reference/`;
//! those tests skip when the folder is absent).

use crate::common::{control, load_reference, rel, render_passes, report, scene, Region};
use caustica::film::Film;
use caustica::integrator::config::{scattering_surfaces, IntegratorKind, Model};
use caustica::integrator::gi::{Gi, GiSettings};
use caustica::integrator::lt::{LightTracer, LtSettings};
use caustica::integrator::path::{PathSettings, PathTracer};
use caustica::integrator::ppm::{Ppm, PpmSettings};
use caustica::integrator::{partial::Accumulator, Progressive, RenderConfig, RenderSession};
use caustica::math::Vec3;

fn mean(film: &Film) -> Vec3 {
    film.region_mean((0, film.height - 1), (0, film.width - 1))
}

/// Inside a closed sphere that emits Le and reflects diffusely with albedo a, the radiance
/// everywhere is Le / (1 − a): Le + a·Le + a²·Le + …
const FURNACE: &str = "SBT-raytracer 1.0
camera { position = (0.1, -0.2, 0.05); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 90; }
scale(2, sphere { material = { emissive = (1, 0.5, 0.25); diffuse = (0.5, 0.5, 0.5); } })
";

fn furnace_expected() -> Vec3 {
    Vec3::new(1.0, 0.5, 0.25) / (1.0 - 0.5)
}

fn assert_close(what: &str, got: Vec3, expected: Vec3, tolerance: f32) {
    for c in 0..3 {
        assert!(
            rel(got[c], expected[c]) < tolerance,
            "{what}: {got:?} vs {expected:?} (tolerance {tolerance})"
        );
    }
}

/// Renders the furnace with `passes` passes of a 24×24 image and checks the mean radiance.
fn furnace(name: &str, renderer: &dyn Progressive, passes: u64, tolerance: f32) {
    let got = mean(&render_passes(renderer, 24, 24, 0, passes).film());
    assert_close(name, got, furnace_expected(), tolerance);
}

#[test]
fn furnace_path() {
    let s = scene(FURNACE);
    furnace(
        "path",
        &PathTracer::new(&s, PathSettings::default(), 24, 24, 1),
        64,
        0.01,
    );
}

#[test]
fn furnace_ppm() {
    let s = scene(FURNACE);
    let settings = PpmSettings {
        photons_per_pass: 20_000,
        ..PpmSettings::default()
    };
    furnace("ppm", &Ppm::new(&s, settings, 24, 24, 2), 16, 0.015);
}

#[test]
fn furnace_gi() {
    let s = scene(FURNACE);
    let settings = GiSettings {
        photons_per_pass: 20_000,
        ..GiSettings::default()
    };
    furnace("gi", &Gi::new(&s, settings, 24, 24, 3), 16, 0.015);
}

/// `--depth` N means one thing in every integrator: light reaches the eye after scattering at
/// no more than N + 1 surfaces. Inside the furnace that is Le·(1 + a + … + a^(N+1)), which
/// `path`, `ppm`, `gi` and `lt` (the emitter itself seen by connecting its point to the eye)
/// must each give at depths 0, 1 and 2, rendered through the options as the command line
/// builds them. Were the path tracer's limit `--depth` surfaces rather than
/// [`scattering_surfaces`] it would be a term short: 1·Le instead of 1.5·Le at depth 0,
/// 1.5·Le instead of 1.75·Le at depth 1.
#[test]
fn depth_counts_the_same_bounces_in_every_integrator() {
    let s = scene(FURNACE);
    let le = Vec3::new(1.0, 0.5, 0.25);
    for depth in [0u32, 1, 2] {
        assert_eq!(scattering_surfaces(depth), depth + 1);
        let terms = (0..=depth + 1).map(|k| 0.5f32.powi(k as i32)).sum::<f32>();
        for (kind, passes, expected) in [
            (IntegratorKind::Path, 48, le * terms),
            (IntegratorKind::Ppm, 8, le * terms),
            (IntegratorKind::Gi, 8, le * terms),
            (IntegratorKind::Lt, 8, le * terms),
        ] {
            let config = RenderConfig {
                model: Some(Model::Physical),
                integrator: Some(kind),
                width: 24,
                height: Some(24),
                depth: Some(depth),
                passes: Some(passes.to_string()),
                photons: 20_000,
                seed: 9,
                ..RenderConfig::default()
            };
            let mut session = RenderSession::new(&s, config.render_options("depth").unwrap()).unwrap();
            session.run(&config.plan().unwrap(), control(), |_| Ok(())).unwrap();
            let got = mean(&session.image());
            eprintln!("{} --depth {depth}: {got:?}, expected {expected:?}", kind.name());
            assert_close(&format!("{} --depth {depth}", kind.name()), got, expected, 0.02);
        }
    }
}

/// A square panel 1 m over a floor, its vertex normals all leaning 30° from the panel's own
/// (geometric) normal, is lit from the side by a spot light whose cone reaches nothing else, so
/// the floor the camera sees gets only what the panel reflects. Camera paths use the shading
/// normal; photons must carry flux by the adjoint BSDF, which with shading normals needs
/// Veach's correction |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|): here the light meets the panel at
/// 63° from its geometric normal but 33° from its shading normal, and without the correction
/// photons brought the floor 53% less light than camera paths find.
const LEANING_NORMALS: &str = "SBT-raytracer 1.0
camera { position = (0, 0.7, 0); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 60; }
spot_light { position = (-1, 0.5, 0); color = (4, 4, 4); direction = (1, 0.5, 0); inner = 18; outer = 20; }
rotate(1, 0, 0, -1.5707963, scale(40, square { material = { diffuse = (0.5, 0.5, 0.5); } }))
polymesh {
  points = ((-0.5, 1, -0.5), (0.5, 1, -0.5), (0.5, 1, 0.5), (-0.5, 1, 0.5));
  faces = ((0, 1, 2, 3));
  normals = ((-0.5, -0.8660254, 0), (-0.5, -0.8660254, 0), (-0.5, -0.8660254, 0), (-0.5, -0.8660254, 0));
  material = { diffuse = (0.8, 0.8, 0.8); };
}
";

/// Under interpolated normals the photon methods (`lt`, `ppm`) agree with the path tracer on
/// the floor lit only by the leaning panel ([`LEANING_NORMALS`]) within 2% (they read 0.1–0.5%
/// apart over seeds; without Veach's correction both read 53% low).
#[test]
fn photons_see_shading_normals_as_camera_paths_do() {
    let s = scene(LEANING_NORMALS);
    let size = 32;
    let path = PathTracer::new(&s, PathSettings::default(), size, size, 3);
    let reference = mean(&render_passes(&path, size, size, 0, 1024).film());
    let (lt, ppm) = lt_and_ppm(&s, size, (100_000, 50_000), (4, 5));
    let lt = mean(&render_passes(&lt, size, size, 0, 16).film());
    let ppm = mean(&render_passes(&ppm, size, size, 0, 16).film());
    eprintln!("floor: path {reference:?}, lt {lt:?}, ppm {ppm:?}");
    assert!(reference.x > 0.0);
    assert_close("lt", lt, reference, 0.02);
    assert_close("ppm", ppm, reference, 0.02);
}

/// A light tracer and a `ppm` renderer of `s` at `size`², with default settings but their
/// photons a pass and seeds.
fn lt_and_ppm<'a>(
    s: &'a caustica::scene::Scene,
    size: usize,
    (lt_photons, ppm_photons): (u64, u64),
    (lt_seed, ppm_seed): (u64, u64),
) -> (LightTracer<'a>, Ppm<'a>) {
    let lt_settings = LtSettings {
        photons_per_pass: lt_photons,
        ..LtSettings::default()
    };
    let ppm_settings = PpmSettings {
        photons_per_pass: ppm_photons,
        ..PpmSettings::default()
    };
    (
        LightTracer::new(s, lt_settings, size, size, lt_seed),
        Ppm::new(s, ppm_settings, size, size, ppm_seed),
    )
}

/// Regions of the reference README (rows, columns inclusive), plus a shadow on the floor
/// beside the mirror sphere.
const WALLS: [Region; 4] = [
    ("back wall", (40, 70), (60, 100)),
    ("left wall", (60, 100), (5, 20)),
    ("right wall", (60, 100), (140, 155)),
    ("ceiling", (2, 12), (60, 100)),
];
const CAUSTIC: Region = ("glass caustic", (135, 139), (41, 45));
const SHADOW: Region = ("shadow", (150, 156), (112, 132));
const FLOOR: Region = ("lit floor", (150, 158), (60, 90));

const SIZE: usize = 160;

/// Path lengths as the reference's: its particle tracer stops at `max_depth` 10, which counts
/// path segments (1 = the light seen directly, 2 = direct light), so light reaching the camera
/// from a diffuse surface has met at most 9 surfaces: `--depth` 8 (a photon stored after 8
/// bounces has met 9 surfaces; the path tracer's own limit, in surfaces, is
/// [`scattering_surfaces`] of it). Unlimited paths read 1–2% above the reference where light
/// arrives mostly indirectly (walls, ceiling, shadows): that is the energy of the longer paths it
/// leaves out.
const REFERENCE_DEPTH: u32 = 8;

fn ppm_settings(photons: u64) -> PpmSettings {
    PpmSettings {
        photons_per_pass: photons,
        // The reference is a particle tracer: it cannot see through glass or in a mirror.
        specular_camera_paths: false,
        max_depth: REFERENCE_DEPTH,
        ..PpmSettings::default()
    }
}

/// Progressive photon mapping converges to the independent reference on the area-light scene:
/// the worst error over the caustic and the lit floor falls as passes grow and ends within 2%;
/// the lit floor, the walls and the ceiling agree within 1%, and the mirror sphere's shadow (lit
/// only indirectly, and by the mirror's caustic) within 3%.
#[test]
#[cfg_attr(not(caustica_reference), ignore = "../shared/reference is absent")]
fn cornell_area_light_ppm_converges_to_the_reference() {
    let (text, reference) = load_reference("cornell_caustics_area");
    let s = scene(&text);
    let ppm = Ppm::new(&s, ppm_settings(200_000), SIZE, SIZE, 11);
    let mut acc = Accumulator::new(SIZE, SIZE, "test");
    let mut errors = Vec::new();
    let mut pass = 0;
    for end in [4, 16, 64] {
        while pass < end {
            acc.add(pass, &ppm.render_pass(pass, control()).unwrap(), 1.0);
            pass += 1;
        }
        let (worst, text) = report(&acc.film(), &reference, &[CAUSTIC, FLOOR]);
        eprintln!("ppm, {end} passes:\n{text}");
        errors.push(worst);
    }
    let (shadow, text) = report(&acc.film(), &reference, &[SHADOW]);
    eprintln!("ppm shadow:\n{text}");
    assert!(shadow < 0.03, "{text}");
    let mut diffuse = WALLS.to_vec();
    diffuse.push(FLOOR);
    let (walls, text) = report(&acc.film(), &reference, &diffuse);
    eprintln!("ppm walls and floor:\n{text}");
    assert!(errors[2] < 0.02, "final error {errors:?}");
    assert!(errors[2] < errors[0], "the error must fall: {errors:?}");
    assert!(walls < 0.01, "walls and floor: {text}");
}

/// The path tracer agrees with the reference on the area-light scene's back wall within 1%, and
/// within 5% on the regions the mirror's caustic lights (its caustic converges too slowly to
/// test here: see BENCHMARKS.md, "The physical model against the reference").
#[test]
#[cfg_attr(not(caustica_reference), ignore = "../shared/reference is absent")]
fn cornell_area_light_path_matches_the_reference() {
    let (text, reference) = load_reference("cornell_caustics_area");
    let s = scene(&text);
    let settings = PathSettings {
        specular_camera_paths: false,
        max_depth: scattering_surfaces(REFERENCE_DEPTH),
        ..PathSettings::default()
    };
    let path = PathTracer::new(&s, settings, SIZE, SIZE, 12);
    let film = render_passes(&path, SIZE, SIZE, 0, 128).film();
    // The back wall is lit by direct and diffuse light; the floor, the side walls and the
    // ceiling also get the mirror's and the glass's caustics, which a path tracer finds only by
    // hitting the small light after a specular bounce: rare, bright samples that need far more
    // passes than a test can run.
    let (worst, text) = report(&film, &reference, &[WALLS[0]]);
    eprintln!("path:\n{text}");
    assert!(worst < 0.01, "{text}");
    let (noisy, text) = report(&film, &reference, &[WALLS[1], WALLS[2], WALLS[3], FLOOR]);
    eprintln!("path, caustic-lit regions:\n{text}");
    assert!(noisy < 0.05, "{text}");
}

/// Jensen's method with final gathering agrees with the reference on the walls and the ceiling
/// (lit partly indirectly) within 2%, and within 3% on the lit floor (under the caustics) and on
/// the floor's shadow beside the mirror sphere, lit only indirectly and the noisiest region of
/// final gathering.
#[test]
#[cfg_attr(not(caustica_reference), ignore = "../shared/reference is absent")]
fn cornell_area_light_gi_matches_the_reference() {
    let (text, reference) = load_reference("cornell_caustics_area");
    let s = scene(&text);
    let settings = GiSettings {
        photons_per_pass: 200_000,
        specular_camera_paths: false,
        max_depth: REFERENCE_DEPTH,
        ..GiSettings::default()
    };
    let gi = Gi::new(&s, settings, SIZE, SIZE, 1);
    let film = render_passes(&gi, SIZE, SIZE, 0, 64).film();
    let (worst, text) = report(&film, &reference, &WALLS);
    eprintln!("gi:\n{text}");
    assert!(worst < 0.02, "{text}");
    // The lit floor holds the spheres' caustics, which gi's shrinking gather radius still blurs
    // at 64 passes: measured 1.95–2.02% dark over photon streams, 0.5% at 256 passes (ppm
    // reads 0.4% at 64).
    let (floor, text) = report(&film, &reference, &[FLOOR, SHADOW]);
    eprintln!("gi:\n{text}");
    assert!(floor < 0.03, "{text}");
}

/// With a point light, ppm shows the glass sphere's caustic at the reference's brightness, the
/// path tracer cannot show it at all, and spherical lights of the same power converge to it
/// as they shrink.
#[test]
#[cfg_attr(not(caustica_reference), ignore = "../shared/reference is absent")]
fn point_light_caustic_is_the_limit_of_shrinking_area_lights() {
    let (text, reference) = load_reference("cornell_caustics_point");
    let s = scene(&text);
    let ppm = Ppm::new(&s, ppm_settings(100_000), SIZE, SIZE, 14);
    let film = render_passes(&ppm, SIZE, SIZE, 0, 48).film();
    let (err, text_report) = report(&film, &reference, &[CAUSTIC, FLOOR, SHADOW]);
    eprintln!("ppm, point light:\n{text_report}");
    assert!(err < 0.03, "{text_report}");
    let caustic = |f: &Film| {
        let m = f.region_mean(CAUSTIC.1, CAUSTIC.2);
        m.x + m.y + m.z
    };
    let point = caustic(&film);
    let floor = film.region_mean(FLOOR.1, FLOOR.2);
    assert!(point > 2.5 * (floor.x + floor.y + floor.z), "a bright caustic");

    let settings = PathSettings {
        specular_camera_paths: false,
        ..PathSettings::default()
    };
    let path = PathTracer::new(&s, settings, SIZE, SIZE, 15);
    // Enough passes that path noise (about ±20% at 8) cannot reach the bound: the region's
    // light without the caustic is about 0.45 of the point light's.
    let without = caustic(&render_passes(&path, SIZE, SIZE, 0, 64).film());
    assert!(
        without < 0.5 * point,
        "path cannot render a point light's caustic: {without} vs {point}"
    );

    // Same power: emitted radiance I / (π r²) for a sphere of radius r.
    let mut errors = Vec::new();
    for radius in [0.16f32, 0.04] {
        let le = 2.0 / (std::f32::consts::PI * radius * radius);
        let light = format!(
            "translate(0, 1.8, 0, scale({radius}, sphere {{ material = {{ emissive = ({le}, {le}, {le}); }} }}))"
        );
        let start = text.find("point_light").unwrap();
        let end = start + text[start..].find('}').unwrap() + 1;
        let area_text = format!("{}{}{}", &text[..start], light, &text[end..]);
        let s = scene(&area_text);
        let ppm = Ppm::new(&s, ppm_settings(100_000), SIZE, SIZE, 16);
        let c = caustic(&render_passes(&ppm, SIZE, SIZE, 0, 48).film());
        eprintln!("radius {radius}: caustic {c:.4} vs point {point:.4}");
        errors.push(rel(c, point));
    }
    assert!(errors[1] < errors[0], "{errors:?}");
    assert!(errors[1] < 0.03, "{errors:?}");
}

/// A floor that is a sharp highlight and nothing else (Phong, exponent 100) mirrors a white
/// wall lit by a small lamp; the camera sees only the floor. Its light is the wall's (reached by
/// photons that bounced off the wall) and the lamp's (direct light). `ppm` used to weigh the
/// photons that land on the floor by the lobe's peak, 51 times a white Lambertian surface's f,
/// and drew the floor as scattered dots; its camera paths now go on through the highlight and
/// gather on the wall.
const HIGHLIGHT_FLOOR: &str = "SBT-raytracer 1.0
camera { position = (0, -2, 1); viewdir = (0, 0.949, -0.316); updir = (0, 0, 1); fov = 30; }
scale(20, square { material = { specular = (0.8, 0.8, 0.8); shininess = 100; } })
translate(0, 3.5, 2, scale(10, 1, 4, box { material = { diffuse = (0.8, 0.8, 0.8); } }))
translate(0.5, 2.2, 0.4, scale(0.1, sphere { material = { emissive = (40, 40, 40); } }))
";

/// Root-mean-square relative difference between two renders, over pixels brighter than a
/// tenth of the first's mean: the noise of one render times √2.
fn relative_spread(a: &Film, b: &Film) -> f32 {
    let lum = |f: &Film, i: usize| f.pixels[i].x + f.pixels[i].y + f.pixels[i].z;
    let n = a.pixels.len();
    let floor = (0..n).map(|i| lum(a, i)).sum::<f32>() / n as f32 * 0.1;
    let (mut sum, mut count) = (0.0f64, 0usize);
    for i in 0..n {
        let (x, y) = (lum(a, i), lum(b, i));
        if x > floor {
            sum += (((x - y) / x) as f64).powi(2);
            count += 1;
        }
    }
    (sum / count.max(1) as f64).sqrt() as f32
}

/// `ppm`'s camera paths go on through a sharp highlight: the floor agrees with the path
/// tracer's within 3% in each block (measured: within 1.9%; counting the lamp's light both by
/// the highlight's BSDF sample and where the path goes on made the lamp's reflection 83% too
/// bright), and two seeds differ by less than half as much as when the highlight gathers
/// photons (measured: a third).
#[test]
fn ppm_goes_on_through_sharp_highlights() {
    let s = scene(HIGHLIGHT_FLOOR);
    let size = 32;
    let path = PathTracer::new(&s, PathSettings::default(), size, size, 3);
    let reference = render_passes(&path, size, size, 0, 2048).film();
    let render = |glossy_camera_paths: bool, seed: u64| {
        let settings = PpmSettings {
            photons_per_pass: 20_000,
            glossy_camera_paths,
            ..PpmSettings::default()
        };
        render_passes(&Ppm::new(&s, settings, size, size, seed), size, size, 0, 16).film()
    };
    let through = [render(true, 1), render(true, 2)];
    let gathered = [render(false, 1), render(false, 2)];
    // The floor below the wall's foot (row 9), in four blocks; the lamp, seen directly above
    // it, is left out: its few edge pixels would weigh more than the floor.
    let blocks = [
        ((10, 20), (0, 15)),
        ((10, 20), (16, 31)),
        ((21, 31), (0, 15)),
        ((21, 31), (16, 31)),
    ];
    for (rows, cols) in blocks {
        let expected = reference.region_mean(rows, cols);
        let got = (through[0].region_mean(rows, cols) + through[1].region_mean(rows, cols)) * 0.5;
        eprintln!("floor rows {rows:?} columns {cols:?}: path {expected:?}, ppm {got:?}");
        assert_close(&format!("floor rows {rows:?} columns {cols:?}"), got, expected, 0.03);
    }
    let (spread_through, spread_gathered) = (
        relative_spread(&through[0], &through[1]),
        relative_spread(&gathered[0], &gathered[1]),
    );
    eprintln!("seed to seed: through the highlight {spread_through}, gathering there {spread_gathered}");
    assert!(spread_through < 0.5 * spread_gathered);
}

/// A glass ball focuses a point lamp onto a floor that is a sharp highlight only (Phong,
/// exponent 50); the camera looks at the floor from the lamp's mirror side, so it sees the
/// caustic in the highlight. Only photons find that light (the lamp is a point seen through
/// glass): the highlight keeps the photons that came by mirrors and glass alone.
const CAUSTIC_IN_A_HIGHLIGHT: &str = "SBT-raytracer 1.0
camera { position = (1.66, 0, 2.5); viewdir = (-0.555, 0, -0.832); updir = (0, 1, 0); fov = 30; }
point_light { position = (-2, 0, 3); color = (8, 8, 8); constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
scale(20, square { material = { specular = (0.8, 0.8, 0.8); shininess = 50; } })
translate(-1, 0, 1.5, scale(0.5, sphere { material = { transmissive = (1, 1, 1); index = 1.5; } }))
";

/// `ppm`, going on through the highlight, still sees the caustic in it: the caustic's
/// reflection agrees with light tracing's within 5% (measured: 0.1%); with no photons gathered
/// at the highlight it read 0.02% of it.
#[test]
fn ppm_keeps_a_caustic_seen_in_a_highlight() {
    let s = scene(CAUSTIC_IN_A_HIGHLIGHT);
    let size = 64;
    let (lt, ppm) = lt_and_ppm(&s, size, (200_000, 200_000), (1, 2));
    let (rows, cols) = ((20, 43), (20, 43));
    let expected = render_passes(&lt, size, size, 0, 64).film().region_mean(rows, cols);
    let got = render_passes(&ppm, size, size, 0, 32).film().region_mean(rows, cols);
    eprintln!("the caustic in the highlight: lt {expected:?}, ppm {got:?}");
    assert!(expected.x > 0.01);
    assert_close("the caustic in the highlight", got, expected, 0.05);
}
