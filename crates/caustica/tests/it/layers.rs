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
            "math",
            "sampling",
            "spectrum",
            "error",
            "diagnostic",
            "progress",
            "texture",
            "image_io",
            "film",
            "presets",
            "preview",
        ],
    ),
    ("description", &["description"]),
    (
        "readers and scene",
        &[
            "format", "geometry", "accel", "camera", "material", "medium", "light", "scene",
        ],
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
    (
        "format",
        &["geometry", "accel", "camera", "material", "medium", "light", "scene"],
    ),
    ("medium", &["format"]),
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
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The files of the modules `text` (the source of `file`) declares under `#[cfg(test)]`, such
/// as `#[cfg(test)] mod tests;`: test code, like the `#[cfg(test)]` items skipped in each file.
fn test_module_files(file: &Path, text: &str) -> Vec<PathBuf> {
    let stem = file.file_stem().expect("a file name");
    let parent = file.parent().expect("in a folder");
    let dir = if stem == "mod" || stem == "lib" {
        parent.to_path_buf()
    } else {
        parent.join(stem)
    };
    let mut files = Vec::new();
    let mut lines = text.lines().map(str::trim);
    while let Some(line) = lines.next() {
        if line == "#[cfg(test)]" {
            let item = lines.next().unwrap_or("");
            let name = item.strip_prefix("pub(crate) ").unwrap_or(item);
            if let Some(name) = name.strip_prefix("mod ").and_then(|n| n.strip_suffix(';')) {
                files.push(dir.join(format!("{name}.rs")));
            }
        }
    }
    files
}

/// The names after each `crate::` in `text`, skipping comments and the items marked
/// `#[cfg(test)]` (test modules and test helpers), however far down the file they are: a
/// `#[cfg(test)]` item ends at its `;` or at the brace that closes it.
fn crate_paths(text: &str) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        let line = line.trim_start();
        if line.starts_with("//") {
            continue;
        }
        if line.starts_with("#[cfg(test)]") {
            skip_item(&mut lines);
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

/// Passes over the item after a `#[cfg(test)]` (and any further attributes on it): up to the
/// line where its brackets balance again and it has ended (`}`, or `;` or `,` for an item
/// without a body). Brackets in strings, characters and comments do not count.
fn skip_item<'a>(lines: &mut impl Iterator<Item = &'a str>) {
    let mut code = Code::default();
    for line in lines {
        let trimmed = line.trim();
        if !code.opened && code.depth == 0 && (trimmed.starts_with("#[") || trimmed.starts_with("//")) {
            continue;
        }
        code.feed(line);
        if code.depth <= 0 && code.state == State::Code && (code.opened || trimmed.ends_with([';', ','])) {
            return;
        }
    }
}

#[derive(Default, PartialEq)]
enum State {
    #[default]
    Code,
    Str,
    /// A raw string closed by `"` and this many `#`.
    Raw(usize),
    /// Nested block comments.
    Comment(usize),
}

/// Bracket depth of Rust source fed a line at a time, outside strings, characters and comments.
#[derive(Default)]
struct Code {
    state: State,
    depth: i64,
    /// A `{` has been seen.
    opened: bool,
}

impl Code {
    fn feed(&mut self, line: &str) {
        let c: Vec<char> = line.chars().collect();
        let at = |i: usize| c.get(i).copied().unwrap_or('\0');
        let mut i = 0;
        while i < c.len() {
            match self.state {
                State::Str => {
                    match c[i] {
                        '\\' => i += 1,
                        '"' => self.state = State::Code,
                        _ => {}
                    }
                    i += 1;
                }
                State::Raw(hashes) => {
                    if c[i] == '"' && (1..=hashes).all(|k| at(i + k) == '#') {
                        self.state = State::Code;
                        i += hashes;
                    }
                    i += 1;
                }
                State::Comment(n) => {
                    if c[i] == '*' && at(i + 1) == '/' {
                        self.state = if n == 1 { State::Code } else { State::Comment(n - 1) };
                        i += 1;
                    } else if c[i] == '/' && at(i + 1) == '*' {
                        self.state = State::Comment(n + 1);
                        i += 1;
                    }
                    i += 1;
                }
                State::Code => {
                    match c[i] {
                        '/' if at(i + 1) == '/' => return,
                        '/' if at(i + 1) == '*' => {
                            self.state = State::Comment(1);
                            i += 1;
                        }
                        '"' => self.state = State::Str,
                        'r' if (i == 0 || !(at(i - 1).is_alphanumeric() || at(i - 1) == '_') || at(i - 1) == 'b')
                            && matches!(at(i + 1), '"' | '#') =>
                        {
                            let hashes = c[i + 1..].iter().take_while(|&&h| h == '#').count();
                            if at(i + 1 + hashes) == '"' {
                                self.state = State::Raw(hashes);
                                i += 1 + hashes;
                            }
                        }
                        // A character ('x' or '\n'), not a lifetime.
                        '\'' if at(i + 1) == '\\' => {
                            i += 3;
                            while i < c.len() && c[i] != '\'' {
                                i += 1;
                            }
                        }
                        '\'' if at(i + 2) == '\'' => i += 2,
                        '{' | '(' | '[' => {
                            self.depth += 1;
                            self.opened |= c[i] == '{';
                        }
                        '}' | ')' | ']' => self.depth -= 1,
                        _ => {}
                    }
                    i += 1;
                }
            }
        }
    }
}

#[test]
fn no_module_uses_a_layer_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&src, &mut files);
    let mut test_files = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("the source reads");
        test_files.extend(test_module_files(file, &text));
    }
    assert!(test_files.len() >= 4, "found {} test module files", test_files.len());
    files.retain(|f| !test_files.contains(f));
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

/// Only the `#[cfg(test)]` items are skipped, not the rest of the file after the first one.
#[test]
fn the_check_reads_past_test_items() {
    let text = r#"#[cfg(test)]
mod tests;
use crate::math::Vec3;

impl Bvh {
    #[cfg(test)]
    #[allow(dead_code)]
    fn child_box(
        &self,
        slot: usize,
    ) -> (Vec3, Vec3) {
        let brace = '{';
        let text = "} ) ]";
        crate::loader::load(r"}")
    }

    fn hit(&self) {
        crate::scene::hit()
    }
}

#[cfg(test)]
struct Probe {
    #[cfg(test)]
    field: crate::loader::Loaded,
    lines: [u8; 2],
}
use crate::light::Light;

#[cfg(test)]
mod more_tests {
    use crate::integrator::Ppm;
    /* } */
}
let y = crate::photon::trace();
"#;
    let found: Vec<String> = crate_paths(text).into_iter().collect();
    assert_eq!(found, ["light", "math", "photon", "scene"]);
    let files = test_module_files(
        Path::new("src/format/ray_file.rs"),
        "#[cfg(test)]\nmod fork_tests;\nmod lexer;",
    );
    assert_eq!(files, [Path::new("src/format/ray_file/fork_tests.rs")]);
}
