//! The library's layers point one way (docs/architecture.md): every `crate::` path in a module's
//! source must name its own module or one of a layer below.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// Layers from the bottom; a module may use its own layer's modules and those below, except the
/// pairs in [`SIBLINGS`].
const LAYERS: &[(&str, &[&str])] = &[
    (
        "base",
        &[
            "math", "sampling", "spectrum", "error", "progress", "texture", "image_io", "film", "presets", "preview",
        ],
    ),
    ("description", &["description"]),
    (
        "readers and scene",
        &["format", "geometry", "accel", "camera", "material", "light", "scene"],
    ),
    ("transport", &["bsdf", "photon"]),
    ("integrators", &["integrator"]),
    // Loading may probe a scene with the course renderer: a file that reads two ways is read
    // the second way when the first would render black (`integrator::darkness`).
    ("loading", &["loader"]),
];

/// Modules of one layer that must not use each other: the file formats know nothing of the
/// renderable scene, and the scene nothing of file syntax.
const SIBLINGS: &[(&str, &[&str])] = &[
    ("format", &["geometry", "accel", "camera", "material", "light", "scene"]),
    ("geometry", &["format"]),
    ("accel", &["format"]),
    ("camera", &["format"]),
    ("material", &["format"]),
    ("light", &["format"]),
    ("scene", &["format"]),
];

fn layer_of(module: &str) -> Option<usize> {
    LAYERS.iter().position(|(_, modules)| modules.contains(&module))
}

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).expect("the source folder reads") {
        let path = entry.expect("a directory entry").path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") && !path.ends_with("tests.rs") {
            // `tests.rs` files are test modules, like the `#[cfg(test)]` parts skipped below.
            out.push(path);
        }
    }
}

/// The names after each `crate::` in `text`, skipping comments and test modules.
fn crate_paths(text: &str) -> BTreeSet<String> {
    let code = text.split("#[cfg(test)]").next().unwrap_or(text);
    let mut found = BTreeSet::new();
    for line in code.lines() {
        let line = line.trim_start();
        if line.starts_with("//") {
            continue;
        }
        for (i, _) in line.match_indices("crate::") {
            let rest = &line[i + "crate::".len()..];
            let name: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
            if !name.is_empty() {
                found.insert(name);
            }
        }
        // `use crate::{a, b::c}` groups.
        if let Some(group) = line.strip_prefix("use crate::{") {
            for item in group.split(',') {
                let name: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                if !name.is_empty() {
                    found.insert(name);
                }
            }
        }
    }
    found
}

#[test]
fn no_module_uses_a_layer_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    assert!(files.len() > 40, "found {} source files", files.len());
    let mut problems = Vec::new();
    for file in &files {
        let relative = file.strip_prefix(&src).expect("under src");
        let first = relative.components().next().expect("a path");
        let module = first.as_os_str().to_string_lossy().trim_end_matches(".rs").to_string();
        if module == "lib" {
            continue;
        }
        let Some(own) = layer_of(&module) else {
            problems.push(format!("{}: module `{module}` is in no layer", relative.display()));
            continue;
        };
        let text = std::fs::read_to_string(file).expect("the source reads");
        for used in crate_paths(&text) {
            if used == module || matches!(used.as_str(), "Error" | "ParseError" | "Result") {
                continue;
            }
            let Some(layer) = layer_of(&used) else {
                problems.push(format!("{}: `crate::{used}` is in no layer", relative.display()));
                continue;
            };
            let forbidden_sibling = SIBLINGS
                .iter()
                .any(|(m, others)| *m == module && others.contains(&used.as_str()));
            if layer > own || forbidden_sibling {
                problems.push(format!(
                    "{}: `{module}` ({}) uses `{used}` ({})",
                    relative.display(),
                    LAYERS[own].0,
                    LAYERS[layer].0
                ));
            }
        }
    }
    assert!(problems.is_empty(), "layers crossed:\n{}", problems.join("\n"));
}

#[test]
fn the_check_finds_crate_paths() {
    let text = "use crate::math::Vec3;\nuse crate::{light::Light, scene};\n// crate::integrator in a comment\nlet x = crate::photon::trace();\n#[cfg(test)]\nuse crate::loader;";
    let found: Vec<String> = crate_paths(text).into_iter().collect();
    assert_eq!(found, ["light", "math", "photon", "scene"]);
}
