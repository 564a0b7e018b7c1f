//! The course forks' extensions rendered by the course model, against closed forms: a soft
//! shadow's penumbra, a spot light's cone in the forks' spellings, HKUST point lights that do not
//! fall off, skybox faces as the background, and CSG, torus and metaball silhouettes.

use crate::common::scene;
use caustica::integrator::whitted::{self, WhittedSettings};
use caustica::loader::{from_text, LoadSettings};
use caustica::math::{Ray, Vec3};
use caustica::sampling::Rng;
use caustica::scene::Scene;
use std::path::Path;

/// The course model's value along `ray` (no caustics).
fn shade(scene: &Scene, ray: &Ray) -> Vec3 {
    let none = |_: &_, _: &_, _: Vec3, _: Vec3, _: u32, _: f32| Vec3::ZERO;
    whitted::radiance(scene, &WhittedSettings::default(), ray, &none)
}

/// The value seen straight down onto the floor z = 0 at (x, y).
fn floor_at(scene: &Scene, x: f32, y: f32) -> Vec3 {
    shade(scene, &Ray::new(Vec3::new(x, y, 0.5), -Vec3::Z))
}

const HEADER: &str = "SBT-raytracer 1.0
camera { position = (0, 0, 10); viewdir = (0, 0, -1); updir = (0, 1, 0); }
";
const FLOOR: &str = "scale(200, square { material = { diffuse = (1, 1, 1); } })";

/// A square light of side a at height H facing down, and an opaque slab at height h covering
/// x < 0. From the floor point (x, 0) the light point (s, ·) is hidden when the ray crosses the
/// slab's plane at x < 0, i.e. when s < x(1 − H/h): the visible fraction is
/// clamp((a/2 − x(1 − H/h))/a, 0, 1), a linear ramp across the penumbra. The shadow rays take 25
/// stratified points, so each estimate is a multiple of 1/5 across the edge; their mean over
/// 4000 random x in the penumbra must match the ramp's mean to 0.01 (the standard error is
/// about 0.002).
#[test]
fn soft_shadow_penumbra_follows_the_visible_fraction() {
    let (a, big_h, h) = (2.0f32, 8.0f32, 4.0f32);
    let light = format!(
        "area_light {{ position = ({}, {}, {big_h}); u = (0, {a}, 0); v = ({a}, 0, 0); color = (1, 1, 1);
           constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }}\n",
        -a / 2.0,
        -a / 2.0,
    );
    let slab =
        format!("translate(-50, 0, {h}, scale(100, 100, 0.01, box {{ material = {{ diffuse = (0, 0, 0); }} }}))");
    let lit = scene(&format!("{HEADER}{light}{FLOOR}"));
    let shadowed = scene(&format!("{HEADER}{light}{FLOOR}\n{slab}"));
    // The penumbra spans x(1 − H/h) from −a/2 to a/2: x from a/2 to −a/2 (H/h = 2).
    let visible = |x: f32| ((a / 2.0 - x * (1.0 - big_h / h)) / a).clamp(0.0, 1.0);
    let (x0, x1) = (-1.5f32, 1.5f32);
    let mut rng = Rng::new(5, 0);
    let (mut measured, mut expected) = (0.0f64, 0.0f64);
    let n = 4000;
    for _ in 0..n {
        let x = x0 + (x1 - x0) * rng.uniform();
        let y = 0.2 * (rng.uniform() - 0.5);
        let full = floor_at(&lit, x, y).x;
        assert!(full > 0.01, "the light reaches ({x}, {y})");
        measured += f64::from(floor_at(&shadowed, x, y).x / full);
        expected += f64::from(visible(x));
    }
    let (measured, expected) = (measured / n as f64, expected / n as f64);
    assert!(
        (measured - expected).abs() < 0.01,
        "mean visible fraction {measured} vs {expected}"
    );
    // Outside the penumbra: fully lit and fully dark.
    assert!((floor_at(&shadowed, 1.2, 0.0).x / floor_at(&lit, 1.2, 0.0).x - 1.0).abs() < 1e-5);
    assert_eq!(floor_at(&shadowed, -1.2, 0.0), Vec3::ZERO);
}

/// The HKUST 2019 spelling `size` (full angle, degrees) and `blend`: full light within
/// size·(1 − blend)/2 of the axis, none beyond size/2. A spot 10 above the floor aimed down with
/// size 60 and blend 0.5: full to 15° (r = 10 tan 15° = 2.68), dark past 30° (r = 5.77); in
/// full light it equals a point light at the same place.
#[test]
fn spot_light_cone_in_the_hkust_spelling() {
    let spot = scene(&format!(
        "{HEADER}spot_light {{ position = (0, 0, 10); direction = (0, 0, -1); color = (1, 1, 1); size = 60; blend = 0.5;
           constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }}\n{FLOOR}"
    ));
    let point = scene(&format!(
        "{HEADER}point_light {{ position = (0, 0, 10); color = (1, 1, 1);
           constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }}\n{FLOOR}"
    ));
    for r in [0.0f32, 1.0, 2.6] {
        let (s, p) = (floor_at(&spot, r, 0.0), floor_at(&point, r, 0.0));
        assert!((s - p).length() < 1e-5 && p.x > 0.5, "r = {r}: {s} vs {p}");
    }
    for r in [5.8f32, 8.0, 20.0] {
        assert_eq!(floor_at(&spot, r, 0.0), Vec3::ZERO, "r = {r}");
    }
    // The blend falls monotonically between.
    let mid: Vec<f32> = [3.0f32, 4.0, 5.0].iter().map(|&r| floor_at(&spot, r, 0.0).x).collect();
    assert!(mid[0] > mid[1] && mid[1] > mid[2] && mid[2] > 0.0, "{mid:?}");
}

/// The HKUST 2017 spelling: `angle` (half-angle, radians) with a hard edge, aimed by
/// `central_direction`; 0.3 rad from 10 above lights the floor out to r = 10 tan 0.3 = 3.09.
#[test]
fn spot_light_hard_edge_in_the_hkust_2017_spelling() {
    let spot = scene(&format!(
        "{HEADER}spot_light {{ position = (0, 0, 10); central_direction = (0, 0, -1); colour = (1, 1, 1); angle = 0.3; }}\n{FLOOR}"
    ));
    assert!(floor_at(&spot, 3.0, 0.0).x > 0.0);
    assert_eq!(floor_at(&spot, 3.2, 0.0), Vec3::ZERO);
}

/// A point light 20 above the floor, without coefficients, in a file with dialect-O markers
/// (a named material): the HKUST skeleton does not attenuate, so straight below it the floor
/// shows kd·I = 0.5; read by the plain dictionary reader (the UT default 1/d²) it shows 0.5/400.
#[test]
fn hkust_point_lights_without_coefficients_do_not_fall_off() {
    let text = "SBT-raytracer 1.0
camera { position = (0, 0, 10); viewdir = (0, 0, -1); updir = (0, 1, 0); }
point_light { position = (0, 0, 20); colour = (0.5, 0.5, 0.5); }
material { name = \"floor\"; diffuse = (1, 1, 1); }
scale(200, square { material = \"floor\"; })
";
    let hkust = scene(text);
    assert!((floor_at(&hkust, 0.0, 0.0).x - 0.5).abs() < 1e-5);
    let mut ut = LoadSettings::default();
    ut.read.ray.dialect = Some(caustica::format::ray_file::ast::Dialect::Dictionary);
    let ut = from_text(text, Path::new("."), &ut).unwrap();
    assert!((floor_at(&ut, 0.0, 0.0).x - 0.5 / 400.0).abs() < 1e-6);
}

/// CR-only line endings (old Mac files) read like LF ones: a `//` comment ends at the CR.
#[test]
fn cr_only_files_render_like_lf_files() {
    let lf = format!("{HEADER}// a comment\ndirectional_light {{ direction = (0, 0, -1); color = (1, 1, 1); }}\n// another\n{FLOOR}\n");
    let cr = lf.replace('\n', "\r");
    let (a, b) = (scene(&lf), scene(&cr));
    assert_eq!(floor_at(&a, 0.3, 0.1), floor_at(&b, 0.3, 0.1));
    assert!(floor_at(&b, 0.3, 0.1).x > 0.9);
}

/// Seen along the x axis under a light along the view: a torus (radii 1 and 0.25) about z shows
/// its tube between |y| = 0.75 and 1.25 at z = 0; a CSG difference of two balls (unit ball minus
/// a ball of radius 0.5 at (0, 0, 1)) shows the dimple: straight down the axis the hit is at
/// z = 0.5, on the cut ball's surface; and one HKUST metaball with radius 1 and the field level
/// 0.25 is a sphere of radius x where 1 − x³(6x² − 15x + 10) = 0.25.
#[test]
fn torus_csg_and_metaball_silhouettes() {
    let lights = "directional_light { direction = (0, 0, -1); color = (1, 1, 1); }\n";
    let m = "material = { diffuse = (1, 1, 1); }";
    let torus = scene(&format!("{HEADER}{lights}torus {{ a = 1; b = 0.25; {m} }}"));
    let down = |s: &Scene, x: f32, y: f32| s.intersect(&Ray::new(Vec3::new(x, y, 5.0), -Vec3::Z), f32::INFINITY);
    for (y, hit) in [
        (0.0, false),
        (0.74, false),
        (0.76, true),
        (1.0, true),
        (1.24, true),
        (1.26, false),
    ] {
        assert_eq!(down(&torus, 0.0, y).is_some(), hit, "torus at y = {y}");
    }
    // Top of the tube at (0, 1): t = 5 − 0.25, lit fully (normal +z).
    let top = down(&torus, 0.0, 1.0).unwrap();
    assert!((top.t - 4.75).abs() < 1e-4, "{}", top.t);
    assert!((shade(&torus, &Ray::new(Vec3::new(0.0, 1.0, 5.0), -Vec3::Z)).x - 1.0).abs() < 1e-4);

    let dimple = scene(&format!(
        "{HEADER}{lights}difference(sphere {{ {m} }}, translate(0, 0, 1, scale(0.5, sphere {{ {m} }})))"
    ));
    let centre = down(&dimple, 0.0, 0.0).unwrap();
    assert!((centre.t - 4.5).abs() < 1e-4, "{}", centre.t);
    // Off the dimple (r > 0.5·√(1 − (…))): the unit ball's own top, z = √(1 − r²).
    let r = 0.8f32;
    let rim = down(&dimple, r, 0.0).unwrap();
    assert!((rim.t - (5.0 - (1.0 - r * r).sqrt())).abs() < 1e-4, "{}", rim.t);
    // The dimple's floor faces up and is lit: its normal is the cut ball's turned inwards.
    assert!(shade(&dimple, &Ray::new(Vec3::new(0.0, 0.0, 5.0), -Vec3::Z)).x > 0.99);

    let x = {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..80 {
            let mid = 0.5 * (lo + hi);
            if 1.0 - mid.powi(3) * (mid * (6.0 * mid - 15.0) + 10.0) > 0.25 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo as f32
    };
    let blob = scene(&format!(
        "{HEADER}{lights}metaballs {{ balls = ((0, 0, 0, 1), (100, 0, 0, 1)); threshold = 0.25; {m} }}"
    ));
    let hit = down(&blob, 0.0, 0.0).unwrap();
    assert!((hit.t - (5.0 - x)).abs() < 1e-4, "{} vs {}", hit.t, 5.0 - x);
}
