//! Frosted glass against an independent renderer: a ball of rough glass (GGX α 0.3, η 1.5) over
//! a grey floor under a point light, the scene of `scripts/scenes/rough_glass.py`, rendered by
//! every physical integrator at 80×60 and compared in four regions with Mitsuba 3.9.1's `path`
//! integrator and its `roughdielectric` (`scripts/race/rough_glass.py --spp 8192`, 320×240, box
//! filter; the regions are whole 4×4 blocks of its pixels, so the means compare at either size).
//! The lit floor also has a closed form: ρ/π · I cos θ / d², 0.05527 over the region, which the
//! ball's scattered light raises by 0.5%.

use crate::common::{control, rel};
use caustica::film::Film;
use caustica::integrator::config::IntegratorKind;
use caustica::integrator::{RenderConfig, RenderSession};
use caustica::loader::{load, LoadSettings};

/// The scene as the script writes it for α 0.3.
const SCENE: &str = r#"LookAt 0.0 4.0 7.0   0.0 0.5 1.0   0 1 0
Camera "perspective" "float fov" [40.0]
Film "rgb" "integer xresolution" [320] "integer yresolution" [240]
WorldBegin
LightSource "point" "point3 from" [0.0 5.0 -2.0] "rgb I" [30.0 30.0 30.0]
AttributeBegin
  Material "diffuse" "rgb reflectance" [0.5 0.5 0.5]
  Shape "bilinearmesh" "point3 P" [-8.0 0 -8.0  8.0 0 -8.0  -8.0 0 8.0  8.0 0 8.0]
AttributeEnd
AttributeBegin
  Material "dielectric" "float eta" [1.5] "float roughness" [0.3] "bool remaproughness" false
  Translate 0.0 1.5 0.0
  Shape "sphere" "float radius" [1.0]
AttributeEnd
"#;

/// Rows and columns (end exclusive) of the regions at 80×60, each with its mirror image in x
/// where it is off the axis.
type Boxes = &'static [((usize, usize), (usize, usize))];

/// Name, boxes, and Mitsuba's mean (of R, G and B).
const REGIONS: [(&str, Boxes, f32); 4] = [
    ("lit floor", &[((51, 59), (3, 13)), ((51, 59), (67, 77))], 0.05578),
    ("caustic", &[((31, 36), (37, 43))], 0.59784),
    ("ball", &[((9, 19), (35, 45))], 0.09837),
    ("shadow", &[((38, 42), (25, 30)), ((38, 42), (50, 55))], 0.00584),
];

/// Each integrator's budget (passes, photons or light paths a pass) and its tolerances in the
/// four regions at that budget. The shadow gets only light the ball scatters, and little of
/// it: its mean is noisy everywhere. ppm and vcm estimate density with kernels that, at this
/// image's large pixels, are wide: the caustic's peak is blurred down by 3%, and ppm, which
/// gathers on the ball's rough surface itself, sees the ball through a kernel that blurs it too.
const BUDGETS: [(IntegratorKind, u64, usize, [f32; 4]); 4] = [
    (IntegratorKind::Path, 1024, 0, [0.02, 0.03, 0.03, 0.15]),
    (IntegratorKind::Lt, 64, 40_000, [0.03, 0.03, 0.05, 0.15]),
    (IntegratorKind::Vcm, 128, 10_000, [0.02, 0.05, 0.03, 0.15]),
    (IntegratorKind::Ppm, 128, 20_000, [0.02, 0.05, 0.10, 0.15]),
];

fn region_mean(film: &Film, boxes: Boxes) -> f32 {
    let (mut sum, mut n) = (0.0f32, 0);
    for &((r0, r1), (c0, c1)) in boxes {
        let m = film.region_mean((r0, r1 - 1), (c0, c1 - 1));
        let count = (r1 - r0) * (c1 - c0);
        sum += (m.x + m.y + m.z) / 3.0 * count as f32;
        n += count;
    }
    sum / n as f32
}

#[test]
fn rough_glass_matches_mitsuba_in_every_integrator() {
    let dir = std::env::temp_dir().join(format!("caustica-rough-glass-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("rough_glass.pbrt");
    std::fs::write(&path, SCENE).unwrap();
    let scene = load(&path, &LoadSettings::default()).unwrap();
    let mut failures = Vec::new();
    for (kind, passes, photons, tolerances) in BUDGETS {
        let config = RenderConfig {
            integrator: Some(kind),
            width: 80,
            height: Some(60),
            depth: Some(10),
            passes: Some(passes.to_string()),
            photons,
            light_paths: Some(photons as u64),
            seed: 5,
            ..RenderConfig::default()
        };
        let mut session = RenderSession::new(&scene, config.render_options("rough glass").unwrap()).unwrap();
        session.run(&config.plan().unwrap(), control(), |_| Ok(())).unwrap();
        let film = session.image();
        for ((name, boxes, mitsuba), tolerance) in REGIONS.into_iter().zip(tolerances) {
            let got = region_mean(&film, boxes);
            let error = 100.0 * (got / mitsuba - 1.0);
            eprintln!(
                "{} {name}: {got:.5} against Mitsuba's {mitsuba:.5} ({error:+.1}%)",
                kind.name()
            );
            if rel(got, mitsuba) > tolerance {
                failures.push(format!(
                    "{} {name}: {got} vs {mitsuba}, beyond {tolerance}",
                    kind.name()
                ));
            }
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    assert!(failures.is_empty(), "{failures:#?}");
}
