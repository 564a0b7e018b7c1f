//! Light tracing (`lt`) against a closed form, against the independent reference (skipped when
//! `../shared/reference/` is absent), and its contracts: the same image on any thread count,
//! and split runs that merge into one.

use crate::common::{assert_deterministic_and_merges, load_reference, rel, render_passes, report, scene, Region};
use caustica::film::Film;
use caustica::integrator::lt::{LightTracer, LtSettings};
use caustica::math::Vec3;
use std::f32::consts::PI;

/// A point light of intensity I at height 1 over a Lambertian floor of albedo ρ, seen from
/// straight above: each floor point sends L = ρ/π · I cos θ / d² towards the eye.
const PLANE: &str = "SBT-raytracer 1.0
camera { position = (0, 3, 0.001); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 30; }
point_light { position = (0.3, 1, 0.2); color = (2, 2, 2); constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
rotate(1, 0, 0, -1.5707963, scale(40, square { material = { diffuse = (0.6, 0.6, 0.6); } }))";

const LIGHT: Vec3 = Vec3::new(0.3, 1.0, 0.2);

/// The closed form at the centre of every pixel of a `size`² film.
fn plane_expected(s: &caustica::scene::Scene, size: usize) -> Vec<f32> {
    let camera = s.camera();
    let mut out = Vec::with_capacity(size * size);
    for y in 0..size {
        for x in 0..size {
            let ray = camera.generate_ray((x as f32 + 0.5) / size as f32, 1.0 - (y as f32 + 0.5) / size as f32);
            let p = ray.at(-ray.origin.y / ray.dir.y);
            let d = LIGHT - p;
            let cos = d.y / d.length();
            out.push(0.6 / PI * 2.0 * cos / d.length_squared());
        }
    }
    out
}

/// Means of 8×8 blocks of a 32² image, rendered and expected; the worst relative error.
fn plane_error(film: &Film, expected: &[f32]) -> f32 {
    let mut worst = 0.0f32;
    for by in 0..4 {
        for bx in 0..4 {
            let (mut got, mut want) = (0.0, 0.0);
            for y in by * 8..by * 8 + 8 {
                for x in bx * 8..bx * 8 + 8 {
                    let p = film.pixel(x, y);
                    got += (p.x + p.y + p.z) / 3.0;
                    want += expected[y * 32 + x];
                }
            }
            worst = worst.max(rel(got, want));
            eprint!(" {:+.2}%", 100.0 * (got / want - 1.0));
        }
        eprintln!();
    }
    worst
}

/// The floor under a point light, in RGB and at sampled wavelengths: every 8×8 block of a 32²
/// image within 2% of the closed form (its photons alone carry about 0.5% noise per block).
#[test]
fn light_tracing_matches_a_point_light_over_a_diffuse_plane() {
    let s = scene(PLANE);
    let expected = plane_expected(&s, 32);
    for spectral in [false, true] {
        let settings = LtSettings {
            photons_per_pass: 100_000,
            spectral: Some(spectral),
            ..LtSettings::default()
        };
        let lt = LightTracer::new(&s, settings, 32, 32, 5);
        let film = render_passes(&lt, 32, 32, 0, 96).film();
        let err = plane_error(&film, &expected);
        eprintln!("spectral {spectral}: worst block error {:.2}%", 100.0 * err);
        assert!(err < 0.02, "spectral {spectral}: {:.2}%", 100.0 * err);
        if spectral {
            // A grey floor under a white light stays grey.
            let m = film.region_mean((0, 31), (0, 31));
            assert!(rel(m.x, m.y) < 0.03 && rel(m.z, m.y) < 0.03, "{m:?}");
        }
    }
}

/// One pass is the same, bit for bit, on one thread and on two; split passes merge into the
/// sums of one run.
#[test]
fn light_tracing_is_deterministic_and_merges() {
    let s = scene(PLANE);
    let settings = LtSettings {
        photons_per_pass: 30_000,
        ..LtSettings::default()
    };
    assert_deterministic_and_merges(&LightTracer::new(&s, settings, 32, 32, 7), 32, 32);
}

/// The reference README's regions (rows, columns inclusive), plus the floor's shadow beside the
/// mirror sphere, as in physical.rs.
const REGIONS: [Region; 7] = [
    ("glass caustic", (135, 139), (41, 45)),
    ("lit floor", (150, 158), (60, 90)),
    ("shadow", (150, 156), (112, 132)),
    ("back wall", (40, 70), (60, 100)),
    ("left wall", (60, 100), (5, 20)),
    ("right wall", (60, 100), (140, 155)),
    ("ceiling", (2, 12), (60, 100)),
];

/// The reference's particle tracer stops at 10 path segments; photons of at most 8 bounces meet
/// at most 9 surfaces before the eye: `--depth` 8 (physical.rs, REFERENCE_DEPTH).
const REFERENCE_PHOTON_DEPTH: u32 = 8;

/// On the point-light Cornell box light tracing reaches the focus of the glass sphere's caustic
/// that photon mapping blurs: the caustic, the lit floor, the shadow, the walls and the ceiling
/// each within 2% of the independent reference (lt has no bias; the bound is its noise at this
/// photon count, about 0.5% on the caustic and 1% on the shadow).
#[test]
#[cfg_attr(not(caustica_reference), ignore = "../shared/reference is absent")]
fn lt_converges_to_the_cornell_point_light_reference() {
    let (text, reference) = load_reference("cornell_caustics_point");
    let (w, h) = (reference.width, reference.height);
    let s = scene(&text);
    let settings = LtSettings {
        photons_per_pass: 1_000_000,
        max_depth: REFERENCE_PHOTON_DEPTH,
        ..LtSettings::default()
    };
    let lt = LightTracer::new(&s, settings, w, h, 21);
    let film = render_passes(&lt, w, h, 0, PASSES).film();
    let (worst, text) = report(&film, &reference, &REGIONS);
    eprintln!("lt, point light, {PASSES} passes:\n{text}");
    assert!(worst < 0.02, "{text}");
}

const PASSES: u64 = 16;
