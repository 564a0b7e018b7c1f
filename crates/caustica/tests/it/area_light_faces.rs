//! pbrt's one-sided area lights in every physical integrator: a black disk of radiance 1 and radius ½
//! one unit over a Lambertian floor, seen from above. Facing down, it lights the floor by the
//! closed form of a disk's view factor, and the camera sees its dark back; turned round, the
//! floor stays black and the camera sees its lit face.

use crate::common::{rel, render_integrator};
use caustica::film::Film;
use caustica::loader::{load, LoadSettings};
use caustica::scene::Scene;
use std::path::PathBuf;

const SIZE: usize = 32;
const ALBEDO: f32 = 0.5;
const HEIGHT: f32 = 1.0;
const RADIUS: f32 = 0.5;

/// The scene with the disk's front facing down (`ReverseOrientation` turns its +z normal round)
/// or up.
fn disk_scene(down: bool) -> Scene {
    let dir = std::env::temp_dir().join(format!("caustica-faces-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let text = format!(
        r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 60
Film "rgb" "integer xresolution" {SIZE} "integer yresolution" {SIZE}
WorldBegin
Material "diffuse" "rgb reflectance" [{ALBEDO} {ALBEDO} {ALBEDO}]
Shape "trianglemesh" "point3 P" [-50 -50 0 50 -50 0 50 50 0 -50 50 0] "integer indices" [0 1 2 0 2 3]
AttributeBegin
  AreaLightSource "diffuse" "rgb L" [1 1 1]
  Material "diffuse" "rgb reflectance" [0 0 0]
  Translate 0 0 {HEIGHT}
  {}
  Shape "disk" "float radius" {RADIUS}
AttributeEnd
"#,
        if down { "ReverseOrientation" } else { "" }
    );
    let path: PathBuf = dir.join(format!("disk-{down}.pbrt"));
    std::fs::write(&path, text).unwrap();
    load(&path, &LoadSettings::default()).unwrap_or_else(|e| panic!("{e}"))
}

fn render(scene: &Scene, integrator: &str, passes: u64, photons: usize) -> Film {
    render_integrator(scene, integrator, SIZE, passes, photons, 7)
}

/// Radiance of a floor point at distance `r` from the axis under the disk facing down: ρ·L·F,
/// with F the view factor from a parallel element to a coaxial disk,
/// ½(1 − (h² + r² − a²) / √((h² + r² + a²)² − 4r²a²)).
fn floor_radiance(r: f32) -> f32 {
    let (h2, a2, r2) = (HEIGHT * HEIGHT, RADIUS * RADIUS, r * r);
    let f = 0.5 * (1.0 - (h2 + r2 - a2) / ((h2 + r2 + a2).powi(2) - 4.0 * r2 * a2).sqrt());
    ALBEDO * f
}

/// The film's mean and the closed form's over each 8×8 block of the outer ring (floor seen
/// past the disk, which hides the floor within 0.75 of the axis).
fn floor_blocks(scene: &Scene, film: &Film) -> Vec<(f32, f32)> {
    let camera = scene.camera();
    let mut blocks = Vec::new();
    for by in 0..SIZE / 8 {
        for bx in 0..SIZE / 8 {
            if (1..3).contains(&bx) && (1..3).contains(&by) {
                continue;
            }
            let (mut got, mut want) = (0.0, 0.0);
            for y in by * 8..by * 8 + 8 {
                for x in bx * 8..bx * 8 + 8 {
                    let p = film.pixel(x, y);
                    got += (p.x + p.y + p.z) / 3.0 / 64.0;
                    // The pixel's area, at 4×4 points.
                    for (sx, sy) in (0..16).map(|i| (i % 4, i / 4)) {
                        let u = (
                            (x as f32 + (sx as f32 + 0.5) / 4.0) / SIZE as f32,
                            1.0 - (y as f32 + (sy as f32 + 0.5) / 4.0) / SIZE as f32,
                        );
                        let ray = camera.generate_ray(u.0, u.1);
                        let q = ray.at(-ray.origin.z / ray.dir.z);
                        assert!(q.truncate().length() > 0.8, "block ({bx}, {by}) sees under the disk");
                        want += floor_radiance(q.truncate().length()) / (64.0 * 16.0);
                    }
                }
            }
            blocks.push((got, want));
        }
    }
    blocks
}

/// The mean of the central 4×4 pixels: the disk seen from above.
fn disk_seen(film: &Film) -> f32 {
    let p = film.region_mean((14, 18), (14, 18));
    (p.x + p.y + p.z) / 3.0
}

#[test]
fn one_sided_lights_emit_from_their_front_in_every_integrator() {
    let (down, up) = (disk_scene(true), disk_scene(false));
    assert!(down.warnings().is_empty(), "{:?}", down.warnings());
    // (integrator, passes, photons or light paths a pass, bound on the floor's worst block).
    // The bounds are about twice the errors measured at these seeds and budgets (lt's: 1.0%
    // since 2026-12-07's change of the warps' angles).
    let cases: [(&str, u64, usize, f32); 5] = [
        ("path", 128, 0, 0.03),
        ("ppm", 64, 20_000, 0.04),
        ("gi", 64, 20_000, 0.04),
        ("lt", 64, 50_000, 0.02),
        ("vcm", 96, 20_000, 0.03),
    ];
    let mut failures = Vec::new();
    for (integrator, passes, photons, tol) in cases {
        let film = render(&down, integrator, passes, photons);
        let worst = floor_blocks(&down, &film)
            .iter()
            .map(|&(got, want)| rel(got, want))
            .fold(0.0, f32::max);
        let back = disk_seen(&film);
        eprintln!(
            "{integrator:>4} facing down: floor {:5.2}% (bound {:.0}%), back {back:.2e}",
            100.0 * worst,
            100.0 * tol
        );
        if worst.is_nan() || worst >= tol {
            failures.push(format!(
                "{integrator}: the floor under the light is off by {:.2}%",
                100.0 * worst
            ));
        }
        if back > 1e-4 {
            failures.push(format!("{integrator}: the light's back is seen lit ({back})"));
        }
        let film = render(&up, integrator, passes, photons);
        let floor = floor_blocks(&up, &film).iter().map(|&(got, _)| got).fold(0.0, f32::max);
        let front = disk_seen(&film);
        eprintln!("{integrator:>4} facing up: floor {floor:.2e}, front {front:.4}");
        if floor > 1e-6 {
            failures.push(format!("{integrator}: the floor behind the light is lit ({floor})"));
        }
        if rel(front, 1.0) > 0.01 {
            failures.push(format!("{integrator}: the light's front is seen as {front}, not 1"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}
