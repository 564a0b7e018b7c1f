//! No shadow acne: a surface point never shadows itself, whatever the shape's scale (ratios up
//! to 1:100), rotation and distance from the origin (up to 10³).
//!
//! Every shape here is convex, so a ray leaving a point of its surface to the outside can never
//! meet it again: any hit on the way out is the surface shadowing itself.

use crate::common;

use caustica::integrator::whitted::{radiance, WhittedSettings};
use caustica::material::SurfaceParams;
use caustica::math::{Ray, Vec3};
use caustica::scene::{Scene, SurfaceHit};

/// The shapes, with `MATERIAL` where their material goes.
const SHAPES: [&str; 4] = [
    "sphere { MATERIAL }",
    "box { MATERIAL }",
    "cylinder { capped = true; MATERIAL }",
    "cone { height = 1; bottom_radius = 1; top_radius = 0.3; capped = true; MATERIAL }",
];

const SCALES: [(f32, f32, f32); 9] = [
    (1.0, 1.0, 1.0),
    (0.2, 0.2, 2.0),
    (0.2, 0.2, 20.0),
    (1.0, 1.0, 10.0),
    (0.01, 0.01, 1.0),
    (1.0, 1.0, 100.0),
    (0.01, 1.0, 1.0),
    (10.0, 0.1, 10.0),
    (100.0, 100.0, 1.0),
];

const TRANSLATIONS: [(f32, f32, f32); 6] = [
    (0.0, 0.0, 0.0),
    (-2.0, -1.0, -1.0),
    (30.0, -20.0, 10.0),
    (1000.0, -1000.0, 500.0),
    (-1000.0, 0.0, 0.0),
    (0.0, 0.0, -1000.0),
];

/// A scene holding one shape under `translate(rotate(scale(…)))`, lit by a directional light.
fn scene(shape: &str, s: (f32, f32, f32), t: (f32, f32, f32), rotated: bool) -> Scene {
    let rotation = if rotated { "1, 2, 3, 0.7" } else { "0, 0, 1, 0" };
    let object = shape.replace("MATERIAL", "material = { diffuse = (0.8, 0.4, 0); }");
    common::scene(&format!(
        "SBT-raytracer 1.0
         directional_light {{ direction = (-1, -1, -0.2); color = (1, 1, 1); }}
         translate({}, {}, {}, rotate({rotation}, scale({}, {}, {}, {object})))",
        t.0, t.1, t.2, s.0, s.1, s.2
    ))
}

/// Deterministic points on the unit sphere (a Fibonacci lattice).
fn directions(n: usize) -> impl Iterator<Item = Vec3> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..n).map(move |i| {
        let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
        let r = (1.0 - z * z).sqrt();
        let phi = golden * i as f32;
        Vec3::new(r * phi.cos(), r * phi.sin(), z)
    })
}

#[test]
fn no_surface_point_shadows_itself() {
    let (mut lit, mut self_hits, mut cases) = (0usize, Vec::new(), 0);
    for shape in SHAPES {
        for s in SCALES {
            for t in TRANSLATIONS {
                for rotated in [false, true] {
                    let scene = scene(shape, s, t, rotated);
                    let bounds = scene.bounds();
                    let (center, extent) = (bounds.center(), bounds.extent().max_element());
                    cases += 1;
                    // Eyes at 3 and 30 times the shape's size, looking at points around it.
                    for (k, eye_dir) in directions(24).enumerate() {
                        let eye = center + eye_dir * extent * if k % 2 == 0 { 3.0 } else { 30.0 };
                        for aim in directions(8) {
                            let target = center + aim * bounds.extent() * 0.3;
                            let ray = Ray::new(eye, (target - eye).normalize());
                            let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
                                continue;
                            };
                            let hit = scene.surface(&ray, &isect);
                            let outward = if hit.geometric_normal.dot(ray.dir) < 0.0 {
                                hit.geometric_normal
                            } else {
                                continue; // a ray from outside meets a convex shape from outside
                            };
                            for wi in directions(16) {
                                if wi.dot(outward) < 0.02 {
                                    continue;
                                }
                                lit += 1;
                                let from = hit.ray_origin(wi);
                                if scene.any_hit(&Ray::new(from, wi), f32::INFINITY, |_| true) {
                                    self_hits.push(format!(
                                        "{shape} scale {s:?} at {t:?} rotated {rotated}: {hit:?} towards {wi}"
                                    ));
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    assert!(cases == 432 && lit > 400_000, "{cases} cases, {lit} shadow rays");
    assert!(
        self_hits.is_empty(),
        "{} of {lit} shadow rays hit their own surface, e.g.\n{}",
        self_hits.len(),
        self_hits[..self_hits.len().min(5)].join("\n")
    );
}

/// The stock course placement (`scale(.2,.2,20)` moved away from the origin) under one
/// directional light, seen by a camera: every pixel on the lit side is exactly kd·E·(N·L).
#[test]
fn a_scaled_and_moved_ellipsoid_is_lit_without_specks() {
    let scene = common::scene(
        "SBT-raytracer 1.0
         camera { position = (5, 0, 0); viewdir = (-1, 0, 0); updir = (0, 0, 1); }
         directional_light { direction = (-1, -1, -0.2); color = (1, 1, 1); }
         translate(-2, -1, -10, scale(0.2, 0.2, 20, sphere { material = { diffuse = (0.8, 0.4, 0); } }))",
    );
    let settings = WhittedSettings::default();
    let none = |_: &SurfaceHit, _: &SurfaceParams, _: Vec3, _: Vec3, _: u32, _: f32| Vec3::ZERO;
    let light = Vec3::new(1.0, 1.0, 0.2).normalize();
    let (n, mut lit, mut wrong) = (240, 0, Vec::new());
    for y in 0..n {
        for x in 0..n {
            let ray = scene
                .camera()
                .generate_ray((x as f32 + 0.5) / n as f32, (y as f32 + 0.5) / n as f32);
            let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let cos = scene.surface(&ray, &isect).geometric_normal.dot(light);
            if cos < 0.01 {
                continue;
            }
            lit += 1;
            let got = radiance(&scene, &settings, &ray, &none).x;
            if (got - 0.8 * cos).abs() > 1e-4 {
                wrong.push((x, y, got, 0.8 * cos));
            }
        }
    }
    assert!(lit > 1000, "{lit} lit pixels");
    assert!(
        wrong.is_empty(),
        "{} of {lit} lit pixels are off, e.g. {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(5)]
    );
}

/// A huge sphere used as the ground (radius 10⁴, centre 10⁴ below, or a flat one 10³ wide): near the origin its points
/// are small numbers but carry the rounding of the huge transform, which a point's own
/// magnitude does not show. Shadow rays up from it must still leave it.
#[test]
fn a_huge_sphere_as_ground_does_not_shadow_itself() {
    // (depth of the centre, scale): a ball, and a flat ellipsoid 100 times wider than deep.
    for (depth, scale) in [(1e4f32, "10000"), (10.0, "1000, 1000, 10")] {
        let scene = common::scene(&format!(
            "SBT-raytracer 1.0
             translate(0, 0, -{depth}, scale({scale}, sphere {{ material = {{ diffuse = (1, 1, 1); }} }}))"
        ));
        let (mut rays, mut self_hits) = (0, 0);
        for (i, aim) in directions(400).enumerate() {
            let eye = Vec3::new(0.3, -0.2, 1.0 + (i % 7) as f32);
            let target = Vec3::new(aim.x, aim.y, 0.0) * 5.0;
            let ray = Ray::new(eye, (target - eye).normalize());
            let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
                continue;
            };
            let hit = scene.surface(&ray, &isect);
            for wi in directions(32).filter(|w| w.dot(hit.geometric_normal) > 0.02) {
                rays += 1;
                let from = hit.ray_origin(wi);
                self_hits += usize::from(scene.any_hit(&Ray::new(from, wi), f32::INFINITY, |_| true));
            }
        }
        assert!(rays > 4000, "{rays}");
        assert_eq!(
            self_hits, 0,
            "scale {scale}: {self_hits} of {rays} shadow rays hit the ground"
        );
    }
}
