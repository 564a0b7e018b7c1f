//! Tells the tests which parts of `../shared` (the course corpus, the reference renders and the
//! scenes from the field, beside the repository) are present, so tests that need them are
//! reported as ignored instead of passing without checking anything.

use std::path::Path;

fn main() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared");
    println!("cargo::rustc-check-cfg=cfg(caustica_corpus)");
    println!("cargo::rustc-check-cfg=cfg(caustica_reference)");
    println!("cargo::rustc-check-cfg=cfg(caustica_field)");
    if shared.join("scenes/sbt-corpus").is_dir() {
        println!("cargo::rustc-cfg=caustica_corpus");
    }
    if shared.join("reference/cornell_caustics_area.ray").is_file() {
        println!("cargo::rustc-cfg=caustica_reference");
    }
    if shared.join("field/pbrt/cornell-box/pbrt/TungstenRender.exr").is_file() {
        println!("cargo::rustc-cfg=caustica_field");
    }
    // Watching an absent path would rerun this script, and rebuild the crate, on every build;
    // so it reruns only when changed itself (touch it after adding or removing ../shared).
    println!("cargo::rerun-if-changed=build.rs");
}
