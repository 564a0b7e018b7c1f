//! Spot lights, suns and the environment against closed forms, in every physical integrator.

use crate::common::{rel, render_with, scene};
use caustica::description::LightDesc;
use caustica::film::Film;
use caustica::format::ray_file::{self, ParseOptions};
use caustica::integrator::RenderConfig;
use caustica::light::{spot_solid_angle, Light};
use caustica::math::Vec3;
use caustica::sampling::Rng;
use caustica::scene::{build, BuildSettings, Scene};
use caustica::spectrum::Wavelengths;
use std::f32::consts::PI;
use std::path::Path;

/// Renders `scene` with the physical model's `integrator` at `width`² for `passes` passes.
fn render(scene: &Scene, integrator: &str, width: usize, passes: u64, photons: usize) -> Film {
    let config = RenderConfig {
        integrator: Some(integrator.parse().unwrap()),
        width,
        height: Some(width),
        passes: Some(passes.to_string()),
        photons,
        seed: 3,
        ..RenderConfig::default()
    };
    render_with(scene, &config)
}

fn region(film: &Film, rows: (usize, usize), cols: (usize, usize)) -> Vec3 {
    film.region_mean(rows, cols)
}

/// A white Lambertian sphere (albedo 1) inside a constant sky of radiance L reflects exactly L
/// towards every direction: each point sees the sky over its whole hemisphere.
#[test]
fn environment_furnace_in_every_integrator() {
    let text = "SBT-raytracer 1.0
camera { position = (0, 0, 4); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
environment_light { color = (0.5, 0.4, 0.3); }
sphere { material = { diffuse = (1, 1, 1); } }";
    let s = scene(text);
    let expected = Vec3::new(0.5, 0.4, 0.3);
    for (integrator, passes) in [("path", 48), ("ppm", 48), ("gi", 48)] {
        let film = render(&s, integrator, 32, passes, 20_000);
        // The sphere (14.5° across its radius, seen from 4 units) covers 7 pixels around the
        // centre of the 60° view.
        let got = region(&film, (12, 19), (12, 19));
        for c in 0..3 {
            assert!(rel(got[c], expected[c]) < 0.01, "{integrator}: {got:?} vs {expected:?}");
        }
        // Around the sphere the camera sees the sky itself.
        let sky = region(&film, (0, 1), (0, 31));
        assert!((sky - expected).abs().max_element() < 1e-4, "{integrator}: sky {sky:?}");
    }
}

/// A sun of irradiance E straight above a white floor (albedo ρ) lights it to ρE/π, whatever
/// its angular size, in every integrator; the course model reads it as a directional light.
#[test]
fn sun_lights_a_floor_to_its_irradiance() {
    let text = "SBT-raytracer 1.0
camera { position = (0, 3, 0.001); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 30; }
sun_light { direction = (0, -1, 0); color = (2, 2, 2); angle = 5; }
translate(0, 0, 0, rotate(1, 0, 0, -1.5707963, scale(40, square { material = { diffuse = (0.6, 0.6, 0.6); } })))";
    let s = scene(text);
    let expected = 0.6 * 2.0 / PI;
    for (integrator, passes) in [("path", 16), ("ppm", 8), ("gi", 8)] {
        let film = render(&s, integrator, 16, passes, 10_000);
        let got = region(&film, (0, 15), (0, 15));
        assert!(rel(got.x, expected) < 0.01, "{integrator}: {got:?} vs {expected}");
    }
    match s.lights().get(0) {
        Some(Light::Sun { cos_max, .. }) => assert!((cos_max.acos().to_degrees() - 2.5).abs() < 1e-3),
        other => panic!("a sun: {other:?}"),
    }
}

/// A scene with a spot light added to its description (the `.ray` syntax comes with the
/// course's spellings).
fn spot_scene(inner: f32, outer: f32) -> Scene {
    let text = "SBT-raytracer 1.0
camera { position = (0, 6, 0.001); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 60; }
rotate(1, 0, 0, -1.5707963, scale(40, square { material = { diffuse = (0.5, 0.5, 0.5); } }))";
    let mut desc = ray_file::parse(text, Path::new("."), &ParseOptions::default())
        .unwrap()
        .into_description(&mut caustica::format::SourceFiles::default(), Path::new("."))
        .unwrap();
    desc.lights.push(LightDesc::Spot {
        position: Vec3::new(0.0, 2.0, 0.0),
        direction: Vec3::new(0.0, -1.0, 0.0),
        color: Vec3::splat(3.0),
        attenuation: [0.0, 0.0, 1.0],
        inner_degrees: inner,
        outer_degrees: outer,
        exponent: 0.0,
        span: 0..0,
    });
    build(&desc, &BuildSettings::default()).unwrap()
}

/// Under a spot 2 units above a floor, the floor inside the inner cone gets I/d² (radiance
/// ρI/(πd²) straight below), nothing outside the outer cone; the photons it emits carry its
/// power I·∫profile dω.
#[test]
fn spot_light_lights_its_cone() {
    let s = spot_scene(20.0, 30.0);
    let below = 0.5 * 3.0 / (PI * 4.0);
    for (integrator, passes) in [("path", 8), ("ppm", 8)] {
        let film = render(&s, integrator, 48, passes, 50_000);
        // The view spans ±3.46 at the floor: pixel 24 is below the light, the inner cone's edge
        // (2·tan 20° = 0.73) is 5 pixels out, the outer one (1.15) 8.
        let centre = region(&film, (22, 25), (22, 25));
        assert!(rel(centre.x, below) < 0.03, "{integrator}: {centre:?} vs {below}");
        let outside = region(&film, (0, 8), (0, 47));
        assert!(outside.max_element() < 1e-3 * below, "{integrator}: {outside:?}");
    }
    // Emitted power: Σ flux / N = I·∫profile dω (measured on photons the light set emits).
    let mut rng = Rng::new(9, 0);
    let n = 200_000;
    let mut sum = 0.0f64;
    for _ in 0..n {
        if let Some(p) = s.lights().emit(&s, &Wavelengths::Rgb, &mut rng) {
            sum += p.throughput.x as f64;
        }
    }
    let cos = |deg: f32| deg.to_radians().cos();
    let exact = 3.0 * spot_solid_angle(cos(20.0), cos(30.0), 0.0) as f64;
    assert!(
        (sum / n as f64 / exact - 1.0).abs() < 0.01,
        "{} vs {exact}",
        sum / n as f64
    );
    // The smooth step's solid angle lies between the two cones'.
    let (inner, outer) = (2.0 * PI * (1.0 - cos(20.0)), 2.0 * PI * (1.0 - cos(30.0)));
    let step = spot_solid_angle(cos(20.0), cos(30.0), 0.0);
    assert!(step > inner && step < outer && rel(step, 0.5 * (inner + outer)) < 0.01);
}

/// A sun of small angular size casts the caustic of a glass ball that a directional light of
/// the same irradiance casts (its photons aimed at the ball in view, the directional light's
/// spread over the scene); a wide sun (8°) blurs the focus.
#[test]
fn a_sun_caustic_tends_to_the_directional_light_limit() {
    let caustic = |light: &str| {
        let s = scene(&format!(
            "SBT-raytracer 1.0
camera {{ position = (0, 6, 0.001); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 30; }}
{light}
translate(0, 1.5, 0, sphere {{ material = {{ transmissive = (1, 1, 1); index = 1.5; }} }})
rotate(1, 0, 0, -1.5707963, scale(20, square {{ material = {{ diffuse = (0.8, 0.8, 0.8); }} }}))"
        ));
        let image = render(&s, "ppm", 64, 16, 100_000);
        // The ball (radius 1, n 1.5) focuses 1.5 below its centre: on the floor. The camera
        // looks straight down through it: the whole view, and the focus at its centre.
        (region(&image, (0, 63), (0, 63)), region(&image, (31, 32), (31, 32)))
    };
    let (directional, directional_focus) = caustic("directional_light { direction = (0, -1, 0); color = (1, 1, 1); }");
    let (sun, _) = caustic("sun_light { direction = (0, -1, 0); color = (1, 1, 1); angle = 0.53; }");
    let (_, wide_focus) = caustic("sun_light { direction = (0, -1, 0); color = (1, 1, 1); angle = 8; }");
    assert!(
        (sun - directional).abs().max_element() < 0.01 * directional.max_element(),
        "sun {sun} vs directional {directional}"
    );
    assert!(
        wide_focus.x < 0.9 * directional_focus.x,
        "{wide_focus} {directional_focus}"
    );
}
