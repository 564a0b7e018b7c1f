//! Every physical integrator on every closed-form scene, in one table (pbrt-v4's analytic
//! tests are the model): a white sphere in a constant sky (the furnace), a point light over a
//! Lambertian floor, and the same floor beside a mirror wall, lit also by the light's mirror
//! image (a caustic). `path` has no way to the light through the mirror (a point light seen in
//! a mirror is a delta lobe on a delta light), so it sits that one out.

use crate::common::{rel, render_integrator, scene};
use caustica::film::Film;
use caustica::math::Vec3;
use caustica::scene::Scene;
use std::f32::consts::PI;

const SIZE: usize = 32;

fn render(scene: &Scene, integrator: &str, passes: u64, photons: usize) -> Film {
    render_integrator(scene, integrator, SIZE, passes, photons, 5)
}

/// A white Lambertian sphere in a constant sky of radiance L reflects exactly L.
const FURNACE: &str = "SBT-raytracer 1.0
camera { position = (0, 0, 4); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 60; }
environment_light { color = (0.5, 0.4, 0.3); }
sphere { material = { diffuse = (1, 1, 1); } }";

/// The sphere's central 7² pixels against L: the worst channel's relative error.
fn furnace_error(_: &Scene, film: &Film) -> f32 {
    let got = film.region_mean((12, 19), (12, 19));
    let want = Vec3::new(0.5, 0.4, 0.3);
    (0..3).map(|c| rel(got[c], want[c])).fold(0.0, f32::max)
}

/// A point light of intensity 2 over a floor of albedo 0.6 (y = 0), seen from above.
const PLANE: &str = "SBT-raytracer 1.0
camera { position = (0, 3, 0.001); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 30; }
point_light { position = (0.3, 1, 0.2); color = (2, 2, 2); constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
rotate(1, 0, 0, -1.5707963, scale(40, square { material = { diffuse = (0.6, 0.6, 0.6); } }))";

/// The same floor and light beside a mirror wall in the plane x = −0.4 (y 0 to 4, z −4 to 4),
/// facing +x: the floor also receives the light of its image at x = −1.1.
const MIRROR: &str = "SBT-raytracer 1.0
camera { position = (0, 3, 0.001); viewdir = (0, -1, 0); updir = (0, 0, -1); fov = 30; }
point_light { position = (0.3, 1, 0.2); color = (2, 2, 2); constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
rotate(1, 0, 0, -1.5707963, scale(40, square { material = { diffuse = (0.6, 0.6, 0.6); } }))
translate(-0.4, 2, 0, rotate(0, 1, 0, 1.5707963, scale(8, 4, 1, square { material = { reflective = (1, 1, 1); } })))";

const LIGHT: Vec3 = Vec3::new(0.3, 1.0, 0.2);
const IMAGE: Vec3 = Vec3::new(-1.1, 1.0, 0.2);

/// Radiance of the floor point `q` towards the eye from a light of intensity 2 at `at`.
fn lit_by(q: Vec3, at: Vec3) -> f32 {
    let d = at - q;
    0.6 / PI * 2.0 * (d.y / d.length()) / d.length_squared()
}

/// The worst relative error of the 8×8 block means against the closed form at pixel centres,
/// over blocks wholly on the floor in front of the mirror (x > −0.35) when `mirror`.
fn floor_error(s: &Scene, film: &Film, mirror: bool) -> f32 {
    let camera = s.camera();
    let mut worst = 0.0f32;
    for by in 0..SIZE / 8 {
        for bx in 0..SIZE / 8 {
            let (mut got, mut want, mut on_floor) = (0.0, 0.0, true);
            for y in by * 8..by * 8 + 8 {
                for x in bx * 8..bx * 8 + 8 {
                    let p = film.pixel(x, y);
                    got += (p.x + p.y + p.z) / 3.0;
                    let u = ((x as f32 + 0.5) / SIZE as f32, 1.0 - (y as f32 + 0.5) / SIZE as f32);
                    let ray = camera.generate_ray(u.0, u.1);
                    let q = ray.at(-ray.origin.y / ray.dir.y);
                    want += lit_by(q, LIGHT);
                    if mirror {
                        on_floor &= q.x > -0.35;
                        // The image's light arrives where its path crosses the wall's square.
                        let t = (-0.4 - IMAGE.x) / (q.x - IMAGE.x);
                        let at = IMAGE + (q - IMAGE) * t;
                        if (0.0..=4.0).contains(&at.y) && at.z.abs() <= 4.0 {
                            want += lit_by(q, IMAGE);
                        }
                    }
                }
            }
            if on_floor {
                worst = worst.max(rel(got, want));
            }
        }
    }
    worst
}

#[test]
fn every_physical_integrator_on_every_closed_form_scene() {
    let (furnace, plane, mirror) = (scene(FURNACE), scene(PLANE), scene(MIRROR));
    // (integrator, passes, photons or light paths a pass, tolerance on the furnace, the floor,
    // the mirror's floor; None: not rendered). The bounds are about twice the errors measured
    // at these seeds and budgets; light tracing's are wider, as its noise is.
    type Case = (&'static str, u64, usize, f32, f32, Option<f32>);
    let cases: [Case; 5] = [
        ("path", 32, 0, 0.01, 0.01, None),
        ("ppm", 32, 20_000, 0.01, 0.01, Some(0.02)),
        ("gi", 24, 20_000, 0.01, 0.01, Some(0.02)),
        ("lt", 64, 50_000, 0.01, 0.03, Some(0.03)),
        ("vcm", 48, 20_000, 0.01, 0.01, Some(0.02)),
    ];
    let mut failures = Vec::new();
    for (integrator, passes, photons, furnace_tol, plane_tol, mirror_tol) in cases {
        let mut check = |what: &str, err: f32, tol: f32| {
            eprintln!(
                "{integrator:>4} {what:<8} {:6.2}% (bound {:.0}%)",
                100.0 * err,
                100.0 * tol
            );
            if err.is_nan() || err >= tol {
                failures.push(format!(
                    "{integrator} on the {what}: {:.2}% > {:.0}%",
                    100.0 * err,
                    100.0 * tol
                ));
            }
        };
        check(
            "furnace",
            furnace_error(&furnace, &render(&furnace, integrator, passes, photons)),
            furnace_tol,
        );
        check(
            "floor",
            floor_error(&plane, &render(&plane, integrator, passes, photons), false),
            plane_tol,
        );
        if let Some(tol) = mirror_tol {
            let film = render(&mirror, integrator, passes, photons);
            check("mirror", floor_error(&mirror, &film, true), tol);
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
