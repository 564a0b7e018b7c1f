//! The corpus check (docs/robustness.md): every scene of ../shared/scenes/sbt-corpus rendered at
//! 64 px as `caustica render --width 64` would (course model, default photons), counted as
//! rendered, refused (by cause) or black. A black render must be one the scene's own course ray
//! tracer makes too; those are listed below with the reason.
//!
//! It renders ~190 scenes (about a minute on two cores with `--release`), so it runs on request:
//! `cargo test --release -p caustica --test it corpus_render -- --ignored --nocapture`.

use caustica::error::Error;
use caustica::integrator::{RenderConfig, RenderSession};
use caustica::loader::{build_detected, LoadSettings};
use caustica::progress::{Control, NoProgress};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/sbt-corpus")
}

/// Scenes whose course renders are black in the course ray tracer as well: (file, why).
const BLACK_BY_DESIGN: &[(&str, &str)] = &[
    ("danvim__COMP4411-Trace__blank.ray", "an empty scene"),
    (
        "danvim__COMP4411-Trace__particles.ray",
        "its only object is a particle system, skipped with a warning",
    ),
    (
        "snowboat__RayTracingS17__emptyScene-testHeightField.ray",
        "no object, only a Warn light",
    ),
    ("michaelasper__ray-tracer__scene_blank.ray", "an empty scene"),
    (
        "OccamsRazer__cs384g__cylinder.ray",
        "the camera sits on a face of the wood slab, inside it: no light gets into the closed box",
    ),
    (
        "StormyEmery__Computer-Graphics_RayTracer__box.ray",
        "one mirror cube (kd = ks = 0) in the dark",
    ),
    (
        "StormyEmery__Computer-Graphics_RayTracer__cube.ray",
        "one mirror cube (kd = ks = 0) in the dark",
    ),
    (
        "StormyEmery__Computer-Graphics_RayTracer__InfiniteEscher.ray",
        "only mirrors, nothing diffuse",
    ),
    (
        "StormyEmery__Computer-Graphics_RayTracer__sphere_reflect.ray",
        "one mirror sphere, nothing diffuse",
    ),
    (
        "StormyEmery__Computer-Graphics_RayTracer__sphere_refract2.ray",
        "only glass, nothing diffuse",
    ),
    (
        "michaelasper__ray-tracer__scene_mirror.ray",
        "one mirror sphere, nothing diffuse",
    ),
    (
        "michaelasper__ray-tracer__sphere_reflect.ray",
        "one mirror sphere, nothing diffuse",
    ),
    (
        "snowboat__RayTracingS17__test_accelerate_shadow_atten.ray",
        "a black box (kd = 0), as its name says",
    ),
    (
        "tunneln__ray-tracer__artifact.ray",
        "a UT file whose only light is 75 units away: 1/d² = 1.8e-4",
    ),
];

/// An 8-bit image shows nothing brighter than this as more than black.
const BLACK: f32 = 0.5 / 255.0;

#[test]
#[ignore = "renders the whole course corpus at 64 px (about a minute with --release): run with --ignored"]
fn corpus_renders_at_64_px() {
    let dir = corpus_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("the corpus check needs {}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "ray"))
        .collect();
    files.sort();
    let never = AtomicBool::new(false);
    let control = Control {
        progress: &NoProgress,
        cancel: &never,
    };
    let (mut rendered, mut black, mut refused) = (0usize, Vec::new(), BTreeMap::<String, Vec<String>>::new());
    for path in &files {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let settings = LoadSettings::default();
        let loaded = caustica::format::read_file(path, &settings.read, &NoProgress)
            .and_then(|source| build_detected(source, &settings, &NoProgress));
        let scene = match loaded {
            Ok((_, scene)) => scene,
            Err(error) => {
                refused.entry(cause(&error)).or_default().push(name);
                continue;
            }
        };
        let config = RenderConfig {
            width: 64,
            ..RenderConfig::default()
        };
        let mut session = RenderSession::new(&scene, config.render_options(name.clone()).unwrap()).unwrap();
        session.run(&config.plan().unwrap(), control, |_| Ok(())).unwrap();
        let film = session.image();
        let (w, h) = session.size();
        let brightest = (0..h)
            .flat_map(|y| (0..w).map(move |x| (x, y)))
            .map(|(x, y)| film.pixel(x, y).max_element())
            .fold(0.0f32, f32::max);
        if brightest < BLACK {
            black.push(name);
        } else {
            rendered += 1;
        }
    }
    let refused_total: usize = refused.values().map(Vec::len).sum();
    println!(
        "{} scenes: rendered {rendered}, refused {refused_total}, black {}",
        files.len(),
        black.len()
    );
    println!("refused, by cause:");
    let mut causes: Vec<_> = refused.iter().collect();
    causes.sort_by_key(|(cause, names)| (std::cmp::Reverse(names.len()), (*cause).clone()));
    for (cause, names) in causes {
        println!("  {:3}  {cause}", names.len());
    }
    println!("black:");
    let mut unexpected = Vec::new();
    for name in &black {
        match BLACK_BY_DESIGN.iter().find(|(n, _)| n == name) {
            Some((_, why)) => println!("  {name}: {why}"),
            None => {
                println!("  {name}: NOT EXPECTED");
                unexpected.push(name.clone());
            }
        }
    }
    assert!(
        unexpected.is_empty(),
        "black renders the course ray tracer would not make: {unexpected:?}"
    );
}

/// A refusal's cause, grouped: a texture missing from the corpus snapshot, a named student
/// extension, or the message itself.
fn cause(error: &Error) -> String {
    let message = match error {
        Error::Scene { error, .. } => error.message.clone(),
        other => other.to_string(),
    };
    if message.contains("student extension") {
        let word = message.split('`').nth(1).unwrap_or("?");
        format!("unsupported extension `{word}`")
    } else if message.contains("cannot read the texture") || message.contains("cannot read the skybox image") {
        "an image file missing from the corpus snapshot".into()
    } else {
        message
    }
}

/// Real course scenes that use each extension, or that the HKUST defaults light, are not black
/// in the course model (the probe of `integrator::darkness`, which traces the course model's
/// camera rays): before these were read they were refused or black.
#[test]
#[cfg_attr(not(caustica_corpus), ignore = "../shared/scenes/sbt-corpus is absent")]
fn extension_scenes_are_lit() {
    let cases = [
        (
            "snowboat__RayTracingS17__turtle.ray",
            "HKUST point lights without falloff",
        ),
        (
            "snowboat__RayTracingS17__easy2.ray",
            "HKUST point lights without falloff",
        ),
        (
            "danvim__COMP4411-Trace__recurse_depth_spot.ray",
            "spot_light size/blend",
        ),
        ("snowboat__RayTracingS17__box_test_spotlight.ray", "spot_light angle"),
        ("chipbuster__p2-raytracer__cbox.ray", "area_light light_radius"),
        ("michaelasper__ray-tracer__soft1.ray", "area_light bottom_radius"),
        ("michaelasper__ray-tracer__torus2.ray", "torus"),
        ("michaelasper__ray-tracer__torii.ray", "torus"),
        ("danvim__COMP4411-Trace__metaballs.ray", "metaballs"),
    ];
    let mut problems = Vec::new();
    for (file, what) in cases {
        let settings = LoadSettings::default();
        let loaded = caustica::format::read_file(&corpus_dir().join(file), &settings.read, &NoProgress)
            .and_then(|source| build_detected(source, &settings, &NoProgress));
        match loaded {
            Ok((_, scene)) => {
                if let Some(why) = caustica::integrator::darkness::diagnose(&scene) {
                    problems.push(format!("{file} ({what}): {why}"));
                }
            }
            Err(e) => problems.push(format!("{file} ({what}): {e}")),
        }
    }
    assert!(problems.is_empty(), "{problems:#?}");
}
