//! A catalogue of bad scene input run through the real binary: each case has its exit code, a
//! message substring, the `file:line:col` where there is one, and no output image on failure.

use assert_cmd::Command;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// A camera and a light, so that only the part under test is wrong.
const STAGE: &str = "SBT-raytracer 1.0
camera { position = (0, 0, 4); viewdir = (0, 0, -1); updir = (0, 1, 0); }
point_light { position = (1, 1, 4); color = (1, 1, 1); }
";

#[derive(Clone, Copy, PartialEq)]
enum Run {
    /// `render FILE -o OUT --width 32 --photons 1000 --quiet` plus extra arguments.
    Render,
    /// `render` without `--quiet`, for the cases that must print a warning.
    RenderLoud,
    /// `info FILE`.
    Info,
}

struct Case {
    name: &'static str,
    scene: Vec<u8>,
    run: Run,
    extra: &'static [&'static str],
    code: i32,
    /// Substrings the standard error must hold.
    messages: &'static [&'static str],
    /// `line:col` after the file name, when the error has a location.
    location: Option<&'static str>,
}

fn case(name: &'static str, scene: impl Into<Vec<u8>>, messages: &'static [&'static str]) -> Case {
    Case {
        name,
        scene: scene.into(),
        run: Run::Render,
        extra: &[],
        code: 2,
        messages,
        location: None,
    }
}

impl Case {
    fn at(mut self, location: &'static str) -> Case {
        self.location = Some(location);
        self
    }
    fn run(mut self, run: Run) -> Case {
        self.run = run;
        self
    }
    fn extra(mut self, extra: &'static [&'static str]) -> Case {
        self.extra = extra;
        self
    }
    fn succeeds(mut self) -> Case {
        self.code = 0;
        self
    }
}

fn staged(body: &str) -> String {
    format!("{STAGE}{body}")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-bad-input-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn catalogue() -> Vec<Case> {
    vec![
        // Syntax.
        case(
            "missing_paren",
            staged("translate(1, 2, 3, sphere {}\nsphere {}\n"),
            &["expected `)` to close `translate`"],
        )
        .at("5:1"),
        case("stray_token", staged("sphere {} )\n"), &["expected a camera, light"]).at("4:11"),
        case(
            "unterminated_block_comment",
            staged("/* never closed\nsphere {}\n"),
            &["unterminated block comment"],
        )
        .at("4:1"),
        case("bad_header", "SBT-raytracr 1.0\nsphere {}\n", &["SBT-raytracer 1.0"]).at("1:1"),
        case("version_2", "SBT-raytracer 2.0\nsphere {}\n", &["version 2 is not supported"]).at("1:15"),
        case("empty_file", "", &["SBT-raytracer 1.0"]).at("1:1"),
        case("only_comments", "// nothing here\n", &["SBT-raytracer 1.0"]).at("2:1"),
        case(
            "unterminated_string",
            staged("sphere { material = { diffuse = map(\"a.png); } }\n"),
            &["unterminated string"],
        )
        .at("4:37"),
        // Fields and keywords.
        case(
            "unknown_field",
            staged("sphere { radius = 2; }\n"),
            &["expected a `sphere` field"],
        )
        .at("4:10"),
        case(
            "misspelt_field",
            staged("sphere { material = { difuse = (1, 0, 0); } }\n"),
            &["did you mean `diffuse`"],
        )
        .at("4:23"),
        case("misspelt_keyword", staged("sphre { }\n"), &["did you mean `sphere`"]).at("4:1"),
        case(
            "tuple_arity",
            "SBT-raytracer 1.0\ncamera { position = (1, 2); }\n",
            &["expected `,` between the numbers of a 3-tuple"],
        )
        .at("2:26"),
        // A fork's Warn light is read, and one without its aim is refused at its place.
        case(
            "warn_light_without_direction",
            staged("warn_light { position = (0, 0, 0); color = (1, 1, 1); }\n"),
            &["`warn_light` needs a `direction`"],
        )
        .at("4:1"),
        // An object no fork's skeleton explains is skipped with a located warning.
        case("unknown_object", staged("meteorite { speed = 3; }\nsphere {}\n"), &["skipped `meteorite { … }`"])
            .run(Run::RenderLoud)
            .succeeds()
            .at("4:1"),
        // Meshes.
        case(
            "face_index_out_of_range",
            staged("polymesh { points = ((0,0,0), (1,0,0), (0,1,0)); faces = ((0, 1, 3)); }\n"),
            &["face 0 uses vertex 3 but the mesh has 3 points"],
        )
        .at("4:59"),
        case(
            "negative_face_index",
            staged("polymesh { points = ((0,0,0), (1,0,0), (0,1,0)); faces = ((0, -1, 2)); }\n"),
            &["face 0 uses vertex -1"],
        )
        .at("4:59"),
        case(
            "normals_count",
            staged("polymesh { points = ((0,0,0), (1,0,0), (0,1,0)); faces = ((0, 1, 2));\n  normals = ((0,0,1)); }\n"),
            &["3 points but 1 normals"],
        )
        .at("5:13"),
        case(
            "materials_count",
            staged("polymesh { points = ((0,0,0), (1,0,0), (0,1,0)); faces = ((0, 1, 2));\n  materials = ({}, {}); }\n"),
            &["3 points but 2 materials"],
        )
        .at("5:15"),
        // Textures.
        // A missing image is a located warning, and the render goes on with mid grey.
        case(
            "missing_texture",
            staged("sphere { material = { diffuse = map(\"nope.png\"); } }\n"),
            &["warning: ", ":4:33: the image `", "nope.png` is missing: the texture reads mid grey"],
        )
        .run(Run::RenderLoud)
        .succeeds(),
        case(
            "corrupt_texture",
            staged("sphere { material = { diffuse = map(\"garbage.png\"); } }\n"),
            &["cannot read the texture", "garbage.png"],
        )
        .at("4:33"),
        case(
            "huge_texture",
            staged("sphere { material = { diffuse = map(\"huge.png\"); } }\n"),
            &["cannot read the texture", "is 10000×10000, too large"],
        )
        .at("4:33"),
        // Numbers and transforms.
        case("huge_number", staged("translate(1e999, 0, 0, sphere {})\n"), &["out of range"]).at("4:11"),
        case("not_a_number", staged("translate(nan, 0, 0, sphere {})\n"), &["expected a number"]).at("4:11"),
        case("zero_scale", staged("scale(0, sphere {})\n"), &["singular transform"]).at("4:1"),
        case(
            "singular_matrix",
            staged("transform((1,0,0,0), (0,1,0,0), (0,0,0,0), (0,0,0,1), sphere {})\n"),
            &["singular transform"],
        )
        .at("4:1"),
        case(
            "zero_rotation_axis",
            staged("rotate(0, 0, 0, 1, sphere {})\n"),
            &["rotation axis (0, 0, 0) has zero length"],
        )
        .at("4:1"),
        case(
            "overflowing_nested_scales",
            staged("scale(1e12, scale(1e12, sphere {}))\n"),
            &["overflows or becomes singular"],
        )
        .at("4:13"),
        case("cone_height", staged("cone { height = 0; }\n"), &["positive height"]).at("4:1"),
        // Encoding.
        case("non_utf8", [STAGE.as_bytes(), b"sphere { }\xff\xfe\n"].concat(), &["not valid UTF-8"]).at("4:11"),
        case("nul_byte", staged("sphere { }\0\n"), &["unexpected character"]).at("4:11"),
        // Accepted with a warning.
        case(
            "degenerate_triangles",
            staged("polymesh { points = ((0,0,0), (1,0,0), (2,0,0), (0,1,0)); faces = ((0, 1, 2), (0, 1, 3)); }\n"),
            &["warning: ", ":4:", ": dropped 1 degenerate (zero-area) triangle(s)"],
        )
        .run(Run::RenderLoud)
        .succeeds(),
        case(
            "only_degenerate_triangles",
            staged("polymesh { points = ((0,0,0), (1,0,0), (2,0,0)); faces = ((0, 1, 2)); }\n"),
            &["warning: ", ": the mesh has no triangles with non-zero area"],
        )
        .run(Run::RenderLoud)
        .succeeds(),
        case(
            "no_lights",
            "SBT-raytracer 1.0\ncamera { position = (0, 0, 4); }\nsphere { material = { diffuse = (1, 1, 1); } }\n",
            &["warning: the scene has no lights"],
        )
        .run(Run::RenderLoud)
        .succeeds(),
        case(
            "no_camera",
            "SBT-raytracer 1.0\npoint_light { position = (1, 1, 4); color = (1, 1, 1); }\ntranslate(0, 0, -4, sphere {})\n",
            &["warning: the scene has no camera"],
        )
        .run(Run::RenderLoud)
        .succeeds(),
        case("info_on_a_bad_file", staged("sphere { ] }\n"), &["unexpected character `]`"])
            .run(Run::Info)
            .at("4:10"),
        // Absurd settings: refused before any memory is committed.
        case("absurd_size", STAGE, &["too large"]).extra(&["--width", "1000000", "--height", "1000000"]),
        case("absurd_photons", STAGE, &["10000000000 photons need about"]).extra(&["--photons", "10000000000"]),
        case(
            "absurd_aspect",
            "SBT-raytracer 1.0\ncamera { aspectratio = 0.000001; }\n",
            &["too large"],
        )
        .extra(&["--width", "30000"]),
    ]
}

/// A PNG whose header declares a `w`×`h` 8-bit RGB image and which holds no pixel data.
fn png_header(w: u32, h: u32) -> Vec<u8> {
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut ihdr = w.to_be_bytes().to_vec();
    ihdr.extend(h.to_be_bytes());
    ihdr.extend([8, 2, 0, 0, 0]);
    for (kind, data) in [(&b"IHDR"[..], &ihdr[..]), (b"IDAT", &[]), (b"IEND", &[])] {
        let chunk = [kind, data].concat();
        png.extend((data.len() as u32).to_be_bytes());
        png.extend(&chunk);
        png.extend(crc32(&chunk).to_be_bytes());
    }
    png
}

/// The CRC-32 of PNG chunks (reflected, polynomial 0xEDB88320).
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = (crc >> 1) ^ (0xedb8_8320 & (crc & 1).wrapping_neg());
        }
    }
    !crc
}

/// The report with its whitespace collapsed (margins and line breaks of the excerpt).
fn flatten(stderr: &str) -> String {
    stderr
        .replace('│', " ")
        .split_whitespace()
        .collect::<Vec<_>>()
        .join(" ")
}

fn check(dir: &Path, case: &Case) -> Result<(), String> {
    let file = dir.join(format!("{}.ray", case.name));
    std::fs::write(&file, &case.scene).unwrap();
    let out = dir.join(format!("{}-out.png", case.name));
    let mut cmd = Command::cargo_bin("caustica").expect("the binary is built");
    match case.run {
        Run::Render | Run::RenderLoud => {
            cmd.arg("render").arg(&file).arg("-o").arg(&out);
            let mut args = vec!["--width", "32", "--photons", "1000"];
            for pair in case.extra.chunks(2) {
                // A case's own value replaces the default one.
                if let Some(i) = args.iter().position(|a| *a == pair[0]) {
                    args.remove(i);
                    args.remove(i);
                }
                args.extend_from_slice(pair);
            }
            cmd.args(args);
            if case.run == Run::Render {
                cmd.arg("--quiet");
            }
        }
        Run::Info => {
            cmd.arg("info").arg(&file);
        }
    }
    cmd.timeout(Duration::from_secs(60));
    let start = Instant::now();
    let output = cmd.output().map_err(|e| format!("cannot run: {e}"))?;
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&output.stderr);
    let flat = flatten(&stderr);
    let mut problems = Vec::new();
    if output.status.code() != Some(case.code) {
        problems.push(format!("exit code {:?}, expected {}", output.status.code(), case.code));
    }
    for message in case.messages {
        if !flat.contains(message) {
            problems.push(format!("no `{message}` in the error"));
        }
    }
    if let Some(location) = case.location {
        let wanted = format!("{}.ray:{location}:", case.name);
        if !flat.contains(&wanted) {
            problems.push(format!("no location `{wanted}`"));
        }
    }
    if stderr.contains("panicked") {
        problems.push("it panicked".into());
    }
    if case.code != 0 && out.exists() {
        problems.push("an output image was written".into());
    }
    if case.code == 0 && case.run != Run::Info && !out.exists() {
        problems.push("no output image".into());
    }
    if case.code == 2 && elapsed > Duration::from_secs(10) {
        problems.push(format!("took {elapsed:?} to refuse"));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(format!("{}: {}\n--- stderr:\n{stderr}", case.name, problems.join("; ")))
    }
}

#[test]
fn every_bad_input_is_refused_with_a_located_message() {
    let dir = temp_dir("catalogue");
    std::fs::write(
        dir.join("garbage.png"),
        b"\x89PNG but not really \x00\x01\x02 garbage bytes",
    )
    .unwrap();
    std::fs::write(dir.join("huge.png"), png_header(10_000, 10_000)).unwrap();
    let failures: Vec<String> = catalogue().iter().filter_map(|c| check(&dir, c).err()).collect();
    assert!(
        failures.is_empty(),
        "{} case(s) failed:\n\n{}",
        failures.len(),
        failures.join("\n\n")
    );
}

#[test]
fn a_missing_scene_file_is_bad_input() {
    let dir = temp_dir("missing");
    let out = dir.join("out.png");
    let assert = Command::cargo_bin("caustica")
        .unwrap()
        .arg("render")
        .arg(dir.join("absent.ray"))
        .arg("-o")
        .arg(&out)
        .assert()
        .code(2);
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    assert!(stderr.contains("absent.ray"), "{stderr}");
    assert!(!out.exists());
}

/// An error past column 65,535 of a one-line file (the column a report could once not pad to):
/// every command refuses it with exit 2 and a short located report, as text and as JSON.
#[test]
fn an_error_far_along_one_long_line_gets_a_short_located_report() {
    let dir = temp_dir("long-line");
    let gltf = dir.join("cut.gltf");
    let body = format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"extras\":{{\"note\":\"{}\"}},\"scenes\":[{{\"nodes\":[0",
        "x".repeat(100_000)
    );
    std::fs::write(&gltf, &body).unwrap();
    let ray = dir.join("long.ray");
    std::fs::write(
        &ray,
        format!(
            "{STAGE}polymesh {{ points = ({}(1, 2, oops)); }}\n",
            "(0, 0, 0), ".repeat(9_000)
        ),
    )
    .unwrap();
    let out = dir.join("out.png");
    for (scene, column_past) in [(&gltf, 100_000), (&ray, 99_000)] {
        for command in [&["render"][..], &["info"], &["photons"], &["render", "--json"]] {
            let mut cmd = Command::cargo_bin("caustica").unwrap();
            cmd.args(command).arg(scene);
            if command[0] != "info" {
                cmd.arg("-o").arg(&out);
            }
            let output = cmd.output().unwrap();
            let stderr = String::from_utf8_lossy(&output.stderr);
            let what = format!("{command:?} {}", scene.display());
            assert_eq!(output.status.code(), Some(2), "{what}: {stderr}");
            assert!(!stderr.contains("panicked"), "{what}: {stderr}");
            assert!(stderr.lines().all(|l| l.chars().count() < 300), "{what}: {stderr}");
            let first = stderr.lines().next().unwrap_or_default();
            let column: usize = first
                .split(':')
                .nth(if first.starts_with("error: ") { 3 } else { 2 })
                .and_then(|c| c.parse().ok())
                .unwrap_or_else(|| panic!("{what}: no file:line:col in {first}"));
            assert!(column > column_past, "{what}: column {column}");
            assert!(stderr.contains('^') && stderr.contains('…'), "{what}: {stderr}");
            if command.contains(&"--json") {
                let stdout = String::from_utf8_lossy(&output.stdout);
                let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
                assert_eq!(json["error"]["kind"], "scene", "{stdout}");
                assert_eq!(json["error"]["excerpt"]["column"], column, "{stdout}");
                assert!(json["error"]["excerpt"]["text"].as_str().unwrap().chars().count() < 200);
            }
            assert!(!out.exists(), "{what} wrote an image");
        }
    }
}

/// Each exit code of the contract, from the release binary: 0 done, 2 bad input, 1 a bug (a
/// panic on a worker thread, reported in one line without a backtrace).
#[test]
fn every_exit_code_means_what_the_help_says() {
    let dir = temp_dir("exit-codes");
    let scene = dir.join("ok.ray");
    std::fs::write(&scene, staged("sphere {}\n")).unwrap();
    let out = dir.join("ok.png");
    let run = |extra: &[&str], panic: bool| {
        let mut cmd = Command::cargo_bin("caustica").unwrap();
        cmd.arg("render")
            .arg(&scene)
            .arg("-o")
            .arg(&out)
            .args(["--width", "8", "--quiet"]);
        cmd.args(extra).env_remove("RUST_BACKTRACE");
        if panic {
            cmd.env("CAUSTICA_TEST_PANIC", "1");
        }
        cmd.output().unwrap()
    };
    assert_eq!(run(&[], false).status.code(), Some(0));
    assert!(out.exists());
    std::fs::remove_file(&out).unwrap();
    assert_eq!(run(&["--aa", "0"], false).status.code(), Some(2));
    let bug = run(&[], true);
    let stderr = String::from_utf8_lossy(&bug.stderr);
    assert_eq!(bug.status.code(), Some(1), "{stderr}");
    assert_eq!(stderr.trim().lines().count(), 1, "{stderr}");
    assert!(
        stderr.contains("internal error") && stderr.contains("a bug"),
        "{stderr}"
    );
    assert!(
        !stderr.contains("backtrace") && !stderr.contains("panicked"),
        "{stderr}"
    );
    assert!(!out.exists());
}
