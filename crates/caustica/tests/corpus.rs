//! Every scene of the shared corpus either parses or fails with the error this table expects.

use caustica::error::line_col;
use caustica::scene::ray_file::{self, ast::Dialect, ParseOptions};
use std::path::{Path, PathBuf};

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/scenes/sbt-corpus")
}

/// Files that must fail: (file name, expected message substring, why).
const EXPECTED_FAILURES: &[(&str, &str, &str)] = &[];

#[test]
fn corpus_parses_or_fails_as_expected() {
    let dir = corpus_dir();
    let Ok(entries) = std::fs::read_dir(&dir) else {
        println!("skipping: corpus directory {} is absent", dir.display());
        return;
    };
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
                if scene.dialect == Dialect::Dictionary {
                    dialect_o += 1;
                }
                println!("OK   {name} {:?} objects={} warnings={}", scene.dialect, scene.objects.len(), scene.warnings.len());
            }
            (Ok(_), Some((_, message, _))) => {
                problems.push(format!("{name}: parsed, but was expected to fail with `{message}`"))
            }
            (Err(error), Some((_, message, _))) if error.message.contains(message) => failed += 1,
            (Err(error), _) => {
                let (line, col) = line_col(&text, error.span.start);
                problems.push(format!("{name}:{line}:{col}: unexpected error: {} (help: {:?})", error.message, error.help));
            }
        }
    }
    println!("{parsed} parsed ({dialect_o} as dialect O), {failed} failed as expected, of {}", names.len());
    for p in &problems {
        println!("{p}");
    }
    assert!(problems.is_empty(), "{} corpus files did not behave as expected", problems.len());
}
