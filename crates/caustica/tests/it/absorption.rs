//! Beer–Lambert absorption inside glass, on both walks: light crossing a slab of thickness d
//! that absorbs σ per unit of length keeps exp(−σ d) of what clear glass lets through (the
//! Fresnel factors are the same for both and cancel; light reflected twice inside, R² = 0.16% of
//! it, moves the ratio by less than that).

use crate::common::{render_integrator, scene};
use caustica::material::Channel;
use caustica::math::Vec3;
use caustica::scene::Scene;

const THICKNESS: f32 = 0.5;
const SIGMA: Vec3 = Vec3::new(1.0, 0.3, 0.0);

/// `objects` with a 0.8-wide slab of glass at `at`, absorbing `sigma` (or clear).
fn with_slab(objects: &str, at: Vec3, sigma: Option<Vec3>) -> Scene {
    let absorption = sigma.map_or(String::new(), |s| format!("absorption = ({}, {}, {});", s.x, s.y, s.z));
    scene(&format!(
        "SBT-raytracer 1.0
         {objects}
         translate({}, {}, {}, scale(0.8, 0.8, {THICKNESS}, box {{ material = {{ transmissive = (1, 1, 1); index = 1.5; {absorption} }} }}))",
        at.x, at.y, at.z
    ))
}

/// The clear slab's ratio to the absorbing one's, channel by channel, against exp(−σ d).
fn check(name: &str, clear: Vec3, absorbing: Vec3, tolerance: f32) {
    let expected = (-SIGMA * THICKNESS).exp();
    let ratio = absorbing / clear;
    eprintln!("{name}: {ratio} against {expected}");
    assert!(
        clear.min_element() > 0.0,
        "{name}: nothing through the clear slab {clear}"
    );
    assert!(
        (ratio - expected).abs().max_element() <= tolerance * expected.max_element(),
        "{name}: the slab kept {ratio}, want {expected}"
    );
}

/// The camera's side: a lamp seen through the slab, by path, ppm and vcm (their camera walks go
/// through glass to an emitter).
#[test]
fn an_emitter_seen_through_absorbing_glass_keeps_exp_minus_sigma_d() {
    let objects = "camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 8; }
         translate(0, 0, -1, scale(4, 4, 1, square { material = { emissive = (1, 1, 1); diffuse = (0, 0, 0); } }))";
    let at = Vec3::new(0.0, 0.0, 0.5);
    let (clear, absorbing) = (with_slab(objects, at, None), with_slab(objects, at, Some(SIGMA)));
    for integrator in ["path", "ppm", "vcm"] {
        let mean = |scene: &Scene| render_integrator(scene, integrator, 16, 4, 20_000, 3).region_mean((4, 12), (4, 12));
        check(integrator, mean(&clear), mean(&absorbing), 0.01);
    }
}

/// The light's side: a point light's caustic through the slab onto a floor, by lt, ppm and vcm
/// (their photons and light subpaths cross the glass); the camera sees that floor past the slab.
#[test]
fn light_through_absorbing_glass_keeps_exp_minus_sigma_d() {
    // The camera looks at the floor under the slab past its side (its ray there clears the
    // slab's bottom edge by 0.6).
    let objects = "camera { position = (0, -6, 2); viewdir = (0, 8, -2); updir = (0, 0, 1); fov = 20; }
         point_light { position = (0, 2, 3); color = (1, 1, 1); constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
         scale(20, 20, 1, square { material = { diffuse = (0.5, 0.5, 0.5); } })";
    let at = Vec3::new(0.0, 2.0, 0.5);
    let (clear, absorbing) = (with_slab(objects, at, None), with_slab(objects, at, Some(SIGMA)));
    const SIZE: usize = 48;
    let camera = clear.camera().fitted(SIZE, SIZE);
    let (sx, sy) = camera.project(Vec3::new(0.0, 2.0, 0.0)).unwrap();
    let (x, y) = ((sx * SIZE as f32) as usize, ((1.0 - sy) * SIZE as f32) as usize);
    for integrator in ["lt", "ppm", "vcm"] {
        let mean = |scene: &Scene| {
            render_integrator(scene, integrator, SIZE, 4, 200_000, 5).region_mean((y - 1, y + 1), (x - 1, x + 1))
        };
        check(integrator, mean(&clear), mean(&absorbing), 0.03);
    }
}

/// An absorbing glass and a clear one alike in every other value stay two materials (the
/// scene's materials are shared by their values, absorption among them).
#[test]
fn absorbing_and_clear_glass_stay_apart() {
    let clear_ball = "translate(2, 0, 0, sphere { material = { transmissive = (1, 1, 1); index = 1.5; } })";
    let scene = with_slab(clear_ball, Vec3::ZERO, Some(SIGMA));
    let glass: Vec<_> = scene
        .materials()
        .iter()
        .filter(|m| matches!(m.index, Channel::Constant(i) if i.x > 1.0))
        .collect();
    assert_eq!(glass.len(), 2, "two glasses");
    assert_eq!(glass.iter().filter(|m| m.absorption == Some(SIGMA)).count(), 1);
}

/// A point light at the centre of a ball of rough absorbing glass (GGX α 0.3, radius 1): the
/// light reaches the surface after exactly one radius inside, so the glowing ball keeps
/// exp(−σ·1) of the clear ball's light, less a little for what the rough surface reflects back
/// inside and crosses again. Next-event estimation from the surface to the light, and vcm's
/// connections between vertices on the inside, run through the glass and must pay for it as the
/// walks do: path, lt and vcm agree.
#[test]
fn a_lamp_inside_rough_absorbing_glass_keeps_exp_minus_sigma_r() {
    use caustica::description::PhysicalMaterial;
    use caustica::format::{read_text, ReadOptions};
    use caustica::progress::NoProgress;
    use caustica::scene::build::{build, BuildSettings};
    let sigma = Vec3::new(0.5, 0.1, 0.0);
    let ball = |absorbing: bool| {
        let text = format!(
            "SBT-raytracer 1.0
             camera {{ position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 26; }}
             point_light {{ position = (0, 0, 0); color = (1, 1, 1); constant_attenuation_coeff = 1; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 0; }}
             sphere {{ material = {{ transmissive = (1, 1, 1); index = 1.5; {} }} }}",
            if absorbing { "absorption = (0.5, 0.1, 0);" } else { "" }
        );
        let path = std::path::Path::new("ball.ray");
        let mut source = read_text(
            path,
            text,
            std::path::Path::new("."),
            &ReadOptions::default(),
            &NoProgress,
        )
        .unwrap();
        for object in &mut source.description.objects {
            object.material.physical = Some(PhysicalMaterial::RoughDielectric {
                eta: 1.5,
                roughness: 0.3,
                tint: caustica::description::Param::grey(1.0),
                abbe: None,
            });
        }
        build(&source.description, &BuildSettings::default()).unwrap()
    };
    let (clear, absorbing) = (ball(false), ball(true));
    let expected = (-sigma).exp();
    let mut seen = Vec::new();
    for (integrator, passes, photons) in [("path", 64, 0), ("lt", 8, 40_000), ("vcm", 8, 20_000)] {
        let mean = |scene: &Scene| {
            let config = caustica::integrator::RenderConfig {
                integrator: Some(integrator.parse().unwrap()),
                model: Some(caustica::integrator::config::Model::Physical),
                width: 24,
                height: Some(24),
                passes: Some(passes.to_string()),
                photons,
                light_paths: Some(photons as u64),
                seed: 7,
                ..caustica::integrator::RenderConfig::default()
            };
            crate::common::render_with(scene, &config).region_mean((6, 17), (6, 17))
        };
        let (c, a) = (mean(&clear), mean(&absorbing));
        let ratio = a / c;
        eprintln!("{integrator}: clear {c}, absorbing {a}, ratio {ratio} against exp(−σr) {expected}");
        assert!(c.min_element() > 0.0, "{integrator}: the clear ball is dark");
        assert!(
            (ratio - expected).abs().max_element() < 0.05,
            "{integrator}: kept {ratio}, want about {expected}"
        );
        seen.push(a);
    }
    for a in &seen[1..] {
        assert!(((*a - seen[0]) / seen[0]).abs().max_element() < 0.04, "{seen:?}");
    }
}
