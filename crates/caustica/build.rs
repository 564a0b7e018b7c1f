//! Tells the tests which parts of `../shared` (the course corpus, the reference renders and the
//! scenes from the field, beside the repository) are present, so tests that need them are
//! reported as ignored instead of passing without checking anything; and whether Blender is on
//! the PATH, for the tests that read what its exporter writes.

use std::path::Path;

fn main() {
    let shared = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared");
    println!("cargo::rustc-check-cfg=cfg(caustica_corpus)");
    println!("cargo::rustc-check-cfg=cfg(caustica_reference)");
    println!("cargo::rustc-check-cfg=cfg(caustica_field)");
    println!("cargo::rustc-check-cfg=cfg(caustica_blender)");
    if shared.join("scenes/sbt-corpus").is_dir() {
        println!("cargo::rustc-cfg=caustica_corpus");
    }
    if shared.join("reference/cornell_caustics_area.ray").is_file() {
        println!("cargo::rustc-cfg=caustica_reference");
    }
    if shared.join("field/pbrt/cornell-box/pbrt/TungstenRender.exr").is_file() {
        println!("cargo::rustc-cfg=caustica_field");
    }
    let on_path = |name: &str| {
        std::env::var_os("PATH").is_some_and(|path| std::env::split_paths(&path).any(|dir| dir.join(name).is_file()))
    };
    if on_path("blender") {
        println!("cargo::rustc-cfg=caustica_blender");
    }
    // Watching an absent path (or PATH, which pip's build of the Python module changes) would
    // rerun this script, and rebuild the crate, on more builds than need it; so it reruns only
    // when changed itself (touch it after adding or removing ../shared or Blender).
    println!("cargo::rerun-if-changed=build.rs");
}
