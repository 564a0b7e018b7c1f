//! Every scene of the shared corpus either parses or fails with the error this table expects;
//! none is refused for an object or extension caustica does not know (those are skipped).
//! Without `../shared/scenes/sbt-corpus` the tests are reported as ignored (see build.rs).

use caustica::error::line_col;
use caustica::format::ray_file::{self, ast::Dialect, ParseOptions};
use std::path::{Path, PathBuf};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/sbt-corpus")
}

/// Files that must fail: (file name, expected message substring, why). Students' extensions
/// are read or skipped with a warning, so only files that are no scene at all are here.
const EXPECTED_FAILURES: &[(&str, &str, &str)] = &[(
    "aashish-sheshadri__cs384G-ray__stars.ray",
    "expected the header `SBT-raytracer 1.0`",
    "include fragment without a header",
)];

/// Messages of errors that refuse a scene for an object or extension it does not know.
const UNKNOWN_OBJECT_ERRORS: &[&str] = &["student extension", "unknown object", "does not know"];

/// Files that use a fork's extension, and a piece of the warning each must carry for it.
const SKIPPED_WITH_A_WARNING: &[(&str, &str)] = &[
    ("aashish-sheshadri__cs384G-ray__bump.ray", "skipped `bump_mapping`"),
    ("danvim__COMP4411-Trace__particles.ray", "skipped `particles { … }`"),
    ("danvim__COMP4411-Trace__shapeLight.ray", "beam's shape"),
    (
        "danvim__COMP4411-Trace__box_csg_reflect_texture_brick_marble.ray",
        "procedural `marble`",
    ),
    ("snowboat__RayTracingS17__test_warn_model.ray", "flaps"),
];

#[test]
#[cfg_attr(not(caustica_corpus), ignore = "../shared/scenes/sbt-corpus is absent")]
fn corpus_parses_or_fails_as_expected() {
    let dir = corpus_dir();
    let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    let mut names: Vec<String> = entries
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".ray"))
        .collect();
    names.sort();
    let mut problems = Vec::new();
    let (mut parsed, mut failed, mut dialect_o) = (0, 0, 0);
    for name in &names {
        let bytes = std::fs::read(dir.join(name)).expect("readable corpus file");
        let text = String::from_utf8_lossy(&bytes);
        let result = ray_file::parse(&text, &dir, &ParseOptions::default());
        let expected = EXPECTED_FAILURES.iter().find(|(n, _, _)| n == name);
        match (result, expected) {
            (Ok(scene), None) => {
                parsed += 1;
                if let Some((_, warning)) = SKIPPED_WITH_A_WARNING.iter().find(|(n, _)| n == name) {
                    if !scene.warnings.iter().any(|(w, _)| w.contains(warning)) {
                        problems.push(format!("{name}: no warning with `{warning}`: {:?}", scene.warnings));
                    }
                }
                let spans = scene
                    .objects
                    .iter()
                    .map(|o| &o.span)
                    .chain(scene.warnings.iter().map(|(_, s)| s));
                for span in spans {
                    if text.get(span.clone()).is_none() {
                        problems.push(format!("{name}: span {span:?} is outside the text"));
                    }
                }
                if scene.dialect.is_dictionary() {
                    dialect_o += 1;
                }
                println!(
                    "OK   {name} {:?} objects={} warnings={}",
                    scene.dialect,
                    scene.objects.len(),
                    scene.warnings.len()
                );
            }
            (Ok(_), Some((_, message, _))) => {
                problems.push(format!("{name}: parsed, but was expected to fail with `{message}`"))
            }
            (Err(error), Some((_, message, _))) if error.message.contains(message) => failed += 1,
            (Err(error), _) if UNKNOWN_OBJECT_ERRORS.iter().any(|m| error.message.contains(m)) => {
                let (line, col) = line_col(&text, error.span.start);
                problems.push(format!(
                    "{name}:{line}:{col}: refused for an object it does not know instead of skipping it: {}",
                    error.message
                ));
            }
            (Err(error), _) => {
                let (line, col) = line_col(&text, error.span.start);
                problems.push(format!(
                    "{name}:{line}:{col}: unexpected error: {} (help: {:?})",
                    error.message, error.help
                ));
            }
        }
    }
    let listed = EXPECTED_FAILURES
        .iter()
        .map(|(name, _, _)| *name)
        .chain(SKIPPED_WITH_A_WARNING.iter().map(|(name, _)| *name));
    for name in listed {
        if !names.iter().any(|n| n == name) {
            problems.push(format!("{name}: listed above but not in the corpus"));
        }
    }
    println!(
        "{parsed} parsed ({dialect_o} as dialect O), {failed} failed as expected, of {}",
        names.len()
    );
    for p in &problems {
        println!("{p}");
    }
    assert!(
        problems.is_empty(),
        "{} corpus files did not behave as expected",
        problems.len()
    );
}

/// Jared Croy's nephroid scene: an open ring made of an equal-radius, uncapped cone.
#[test]
#[cfg_attr(not(caustica_corpus), ignore = "../shared/scenes/sbt-corpus is absent")]
fn caustics_ring_scene_reads_as_written() {
    let dir = corpus_dir();
    let path = dir.join("OccamsRazer__cs384g__ring.ray");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let scene = ray_file::parse(&text, &dir, &ParseOptions::default()).expect("ring.ray parses");
    assert_eq!(scene.dialect, Dialect::Tokenizer);
    let ring = scene
        .objects
        .iter()
        .find_map(|o| match o.shape {
            ray_file::ast::ShapeDesc::Cone {
                height,
                bottom_radius,
                top_radius,
                capped,
            } => Some((height, bottom_radius, top_radius, capped)),
            _ => None,
        })
        .expect("a cone");
    assert_eq!(ring, (2.0, 3.0, 3.0, false));
    assert_eq!(scene.lights.len(), 1);
}
