//! The Whitted integrator against the §9 formula evaluated by hand, pixel by pixel.

use crate::common;

use caustica::integrator::whitted::{render, WhittedSettings};
use caustica::integrator::ImageSettings;
use caustica::math::Vec3;

const SCENE: &str = "SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
ambient_light { color = (0.5, 0.5, 0.5); }
point_light { position = (1, 2, 3); color = (0.9, 0.8, 0.7);
  constant_attenuation_coeff = 0.25; linear_attenuation_coeff = 0.1; quadratic_attenuation_coeff = 0.01; }
directional_light { direction = (0, -1, -1); color = (0.3, 0.3, 0.3); }
scale(10, square { material = { diffuse = (0.6, 0.4, 0.2); specular = (0.5, 0.5, 0.5); shininess = 10;
  ambient = (0.1, 0.2, 0.3); emissive = (0.01, 0.02, 0.03); } })
translate(0.5, 1, 1.5, scale(0.3, sphere { material = { transmissive = (0.5, 0.6, 0.7); } }))
";

const SPHERE_CENTER: Vec3 = Vec3::new(0.5, 1.0, 1.5);
const SPHERE_RADIUS: f32 = 0.3;

/// How many times the segment p → p + wi·dist crosses the glass sphere (0 or 2 here).
fn sphere_crossings(p: Vec3, wi: Vec3, dist: f32) -> i32 {
    let oc = p - SPHERE_CENTER;
    let b = oc.dot(wi);
    let c = oc.dot(oc) - SPHERE_RADIUS * SPHERE_RADIUS;
    let disc = b * b - c;
    if disc <= 0.0 {
        return 0;
    }
    let (t0, t1) = (-b - disc.sqrt(), -b + disc.sqrt());
    [t0, t1].iter().filter(|t| **t > 0.0 && **t < dist).count() as i32
}

fn expected(p: Vec3, v: Vec3) -> Vec3 {
    let n = Vec3::Z;
    let (kd, ks, ns) = (Vec3::new(0.6, 0.4, 0.2), Vec3::splat(0.5), 10.0f32);
    let kt = Vec3::new(0.5, 0.6, 0.7);
    let mut c = Vec3::new(0.01, 0.02, 0.03) + Vec3::new(0.1, 0.2, 0.3) * 0.5;
    let lights = [
        (Vec3::new(1.0, 2.0, 3.0) - p, Vec3::new(0.9, 0.8, 0.7), true),
        (Vec3::new(0.0, 1.0, 1.0), Vec3::splat(0.3), false),
    ];
    for (to_light, color, is_point) in lights {
        let d = to_light.length();
        let l = to_light / d;
        let f = if is_point {
            (1.0 / (0.25 + 0.1 * d + 0.01 * d * d)).min(1.0)
        } else {
            1.0
        };
        let shadow = kt.powf(sphere_crossings(p, l, if is_point { d } else { f32::INFINITY }) as f32);
        let r = 2.0 * n.dot(l) * n - l;
        c += f * shadow * color * (kd * n.dot(l).max(0.0) + ks * v.dot(r).max(0.0).powf(ns));
    }
    c
}

#[test]
fn pixels_match_the_phong_formula_with_filtered_shadows() {
    let scene = common::scene(SCENE);
    let (w, h) = (48, 48);
    let image = ImageSettings {
        width: w,
        height: h,
        aa: 1,
        seed: 0,
    };
    let settings = WhittedSettings {
        max_depth: 0,
        ..WhittedSettings::default()
    };
    let (film, complete) = render(&scene, None, &settings, &image, common::control());
    assert!(complete);
    let mut checked = 0;
    let mut shadowed = 0;
    for y in 0..h {
        for x in 0..w {
            let sx = (x as f32 + 0.5) / w as f32;
            let sy = 1.0 - (y as f32 + 0.5) / h as f32;
            let ray = scene.camera().generate_ray(sx, sy);
            // Skip pixels that see the glass sphere itself.
            let oc = ray.origin - SPHERE_CENTER;
            let b = oc.dot(ray.dir);
            if b * b - (oc.dot(oc) - SPHERE_RADIUS * SPHERE_RADIUS) > -1e-3 {
                continue;
            }
            let t = -ray.origin.z / ray.dir.z;
            let p = ray.origin + ray.dir * t;
            let want = expected(p, -ray.dir);
            let got = film.pixel(x, y);
            assert!(
                (got - want).abs().max_element() < 2e-4,
                "pixel ({x}, {y}): got {got:?}, want {want:?}"
            );
            checked += 1;
            if sphere_crossings(
                p,
                (Vec3::new(1.0, 2.0, 3.0) - p).normalize(),
                (Vec3::new(1.0, 2.0, 3.0) - p).length(),
            ) > 0
            {
                shadowed += 1;
            }
        }
    }
    assert!(checked > 1500, "most pixels see the floor: {checked}");
    assert!(
        shadowed > 10,
        "some pixels lie in the glass sphere's filtered shadow: {shadowed}"
    );
}

#[test]
fn mirror_reflects_with_its_colour_and_depth_limits_recursion() {
    // A mirror square facing the camera reflects a emissive sphere behind the camera.
    let text = "SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 30; }
scale(10, square { material = { reflective = (0.5, 0.25, 1.0); } })
translate(0, 0, 20, scale(8, sphere { material = { emissive = (0.8, 0.8, 0.8); } }))
";
    let scene = common::scene(text);
    let image = ImageSettings {
        width: 8,
        height: 8,
        aa: 1,
        seed: 0,
    };
    let deep = WhittedSettings {
        max_depth: 2,
        ..WhittedSettings::default()
    };
    let (film, _) = render(&scene, None, &deep, &image, common::control());
    let centre = film.pixel(4, 4);
    assert!(
        (centre - Vec3::new(0.4, 0.2, 0.8)).abs().max_element() < 1e-5,
        "{centre:?}"
    );
    let flat = WhittedSettings {
        max_depth: 0,
        ..WhittedSettings::default()
    };
    let (film, _) = render(&scene, None, &flat, &image, common::control());
    assert_eq!(film.pixel(4, 4), Vec3::ZERO, "depth 0: no reflection");
}

#[test]
fn refraction_through_a_slab_keeps_direction_and_filters() {
    // Looking straight through a glass slab at an emissive wall: two interfaces, kt² filtering.
    let text = "SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 10; }
translate(0, 0, 1, scale(4, 4, 0.5, box { material = { transmissive = (0.5, 0.8, 1.0); index = 1.5; } }))
translate(0, 0, -3, scale(20, square { material = { emissive = (1, 1, 1); } }))
";
    let scene = common::scene(text);
    let image = ImageSettings {
        width: 4,
        height: 4,
        aa: 1,
        seed: 0,
    };
    let (film, _) = render(&scene, None, &WhittedSettings::default(), &image, common::control());
    let c = film.pixel(2, 2);
    assert!((c - Vec3::new(0.25, 0.64, 1.0)).abs().max_element() < 1e-5, "{c:?}");
}
