//! pbrt-v4, glTF and OBJ scenes through the real binary: bad files of each format are refused
//! with exit code 2, a message naming the file (an included one, an MTL library, a PLY mesh)
//! with its line and column, and no image; good ones render with the settings they carry.

use assert_cmd::Command;
use std::path::{Path, PathBuf};
use std::time::Duration;

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-cli-formats-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Runs `caustica ARGS` in `dir`; returns (exit code, stderr with line breaks joined, stdout).
fn run(dir: &Path, args: &[&str]) -> (Option<i32>, String, String) {
    let output = Command::cargo_bin("caustica")
        .unwrap()
        .current_dir(dir)
        .args(args)
        .timeout(Duration::from_secs(120))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&output.stderr).replace('\n', " ");
    (
        output.status.code(),
        stderr,
        String::from_utf8_lossy(&output.stdout).into_owned(),
    )
}

const PBRT_STAGE: &str = "LookAt 0 1 4  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";

#[test]
fn bad_files_of_every_format_are_refused_where_they_are_wrong() {
    let dir = temp_dir("bad");
    std::fs::write(
        dir.join("geometry.pbrt"),
        "Shape \"sphere\"\nShape \"sphere\" \"float radius\" [x]\n",
    )
    .unwrap();
    std::fs::write(dir.join("bad.mtl"), "Kd 1 1 1\n").unwrap();
    std::fs::write(dir.join("bad.ply"), "ply\nformat ascii 2.0 extra\nend_header\n").unwrap();
    let cases: &[(&str, &str, &str, &str)] = &[
        // (file, content, message, location)
        (
            "unclosed.pbrt",
            "WorldBegin\nShape \"sphere\" \"float radius\" [1\n",
            "not closed",
            "unclosed.pbrt:2:31:",
        ),
        (
            "include.pbrt",
            "WorldBegin\nInclude \"geometry.pbrt\"\n",
            "expected a number",
            "geometry.pbrt:2:32:",
        ),
        (
            "missing.pbrt",
            "WorldBegin\nInclude \"nowhere.pbrt\"\n",
            "cannot read",
            "missing.pbrt:2:9:",
        ),
        (
            "ply.pbrt",
            "WorldBegin\nShape \"plymesh\" \"string filename\" \"bad.ply\"\n",
            "PLY header",
            "bad.ply:2:1:",
        ),
        (
            "noworld.pbrt",
            "Camera \"perspective\"\n",
            "WorldBegin",
            "noworld.pbrt:2:1:",
        ),
        (
            "face.obj",
            "v 0 0 0\nv 1 0 0\nf 1 2 x\n",
            "vertex index",
            "face.obj:3:7:",
        ),
        (
            "mtl.obj",
            "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n",
            "before any `newmtl`",
            "bad.mtl:1:1:",
        ),
        (
            "json.gltf",
            "{\"asset\": {\"version\": \"2.0\"},\n \"nodes\": [}\n",
            "invalid glTF JSON",
            "json.gltf:2:",
        ),
        (
            "index.gltf",
            "{\"asset\":{\"version\":\"2.0\"},\"scenes\":[{\"nodes\":[0]}],\n\"nodes\":[{\"mesh\":3}]}\n",
            "nodes[0].mesh",
            "index.gltf:2:",
        ),
        (
            "garbage.glb",
            "glTF\x02\x00\x00\x00garbage",
            "not a valid GLB",
            "garbage.glb",
        ),
    ];
    let mut failures = Vec::new();
    for (file, content, message, location) in cases {
        std::fs::write(dir.join(file), content).unwrap();
        let out = format!("{file}.png");
        let (code, stderr, _) = run(&dir, &["render", file, "-o", &out, "--width", "16", "--quiet"]);
        let mut problems = Vec::new();
        if code != Some(2) {
            problems.push(format!("exit {code:?}"));
        }
        if !stderr.contains(message) {
            problems.push(format!("no `{message}`"));
        }
        if !stderr.contains(location) {
            problems.push(format!("no `{location}`"));
        }
        if stderr.contains("panicked") {
            problems.push("panicked".into());
        }
        if dir.join(&out).exists() {
            problems.push("an image was written".into());
        }
        if !problems.is_empty() {
            failures.push(format!("{file}: {} — {stderr}", problems.join(", ")));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn a_pbrt_scene_brings_its_film_sampler_and_integrator() {
    let dir = temp_dir("pbrt");
    let scene = format!(
        "Film \"rgb\" \"integer xresolution\" 24 \"integer yresolution\" 12 \"string filename\" \"named.png\"\n\
         Sampler \"halton\" \"integer pixelsamples\" 3\nIntegrator \"sppm\" \"integer photonsperiteration\" 2000\n\
         {PBRT_STAGE}LightSource \"point\" \"point3 from\" [0 3 2] \"rgb I\" [5 5 5]\nShape \"sphere\"\nFrobnicate 1 2\n"
    );
    std::fs::write(dir.join("s.pbrt"), &scene).unwrap();
    let (code, stderr, stdout) = run(&dir, &["render", "s.pbrt", "--json"]);
    assert_eq!(code, Some(0), "{stderr}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(json["width"], 24);
    assert_eq!(json["height"], 12);
    assert_eq!(json["integrator"], "ppm");
    assert_eq!(json["passes"], 3);
    assert_eq!(json["photons_per_pass"], 2000);
    assert!(dir.join("named.png").exists(), "the Film's file name");
    // The command line wins; the warning names the place.
    let (code, stderr, stdout) = run(
        &dir,
        &[
            "render",
            "s.pbrt",
            "--json",
            "--width",
            "10",
            "--integrator",
            "path",
            "--passes",
            "1",
            "-o",
            "o.png",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(
        (json["width"].as_u64(), json["integrator"].as_str()),
        (Some(10), Some("path"))
    );
    let (_, stderr, _) = run(&dir, &["render", "s.pbrt", "--passes", "1", "-o", "o.png"]);
    assert!(
        stderr.contains("warning: s.pbrt:9:1: ") && stderr.contains("Frobnicate"),
        "{stderr}"
    );
    assert!(dir.join("o.png").exists(), "the render goes on");
    // The course model takes the file's image size but not its samples (it has no passes).
    let (code, stderr, stdout) = run(
        &dir,
        &["render", "s.pbrt", "--json", "--model", "course", "-o", "c.png"],
    );
    assert_eq!(code, Some(0), "{stderr}");
    let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
    assert_eq!(
        (json["width"].as_u64(), json["integrator"].as_str()),
        (Some(24), Some("whitted"))
    );
    // --format reads any extension.
    std::fs::write(dir.join("s.txt"), &scene).unwrap();
    let (code, stderr, _) = run(&dir, &["info", "s.txt", "--format", "pbrt"]);
    assert_eq!(code, Some(0), "{stderr}");
}

#[test]
fn an_obj_scene_takes_its_camera_and_lights_from_options() {
    let dir = temp_dir("obj");
    std::fs::write(dir.join("tri.obj"), "v -1 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n").unwrap();
    let (code, stderr, _) = run(
        &dir,
        &[
            "render",
            "tri.obj",
            "-o",
            "a.png",
            "--width",
            "16",
            "--photons",
            "0",
            "--look-from",
            "0,0.5,3",
            "--look-at",
            "0,0.5,0",
            "--fov",
            "30",
            "--point-light",
            "0,1,2,4,4,4",
            "--directional-light",
            "0,0,-1,1,1,1",
        ],
    );
    assert_eq!(code, Some(0), "{stderr}");
    assert!(dir.join("a.png").exists());
    // Without options it frames itself and lights itself.
    let (code, stderr, _) = run(
        &dir,
        &["render", "tri.obj", "-o", "b.png", "--width", "16", "--photons", "0"],
    );
    assert_eq!(code, Some(0), "{stderr}");
    // Other formats have their own camera and lights.
    std::fs::write(dir.join("s.pbrt"), format!("{PBRT_STAGE}Shape \"sphere\"\n")).unwrap();
    let (code, stderr, _) = run(&dir, &["render", "s.pbrt", "--point-light", "0,1,2,4,4,4"]);
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("set up OBJ"), "{stderr}");
    let (code, stderr, _) = run(&dir, &["render", "tri.obj", "--point-light", "0,1,2"]);
    assert_eq!(code, Some(2));
    assert!(stderr.contains("expected 6"), "{stderr}");
}

/// A file in physical units that names no integrator renders with vcm, which shows the caustic
/// of a point light through glass, and says so; one that names `path` keeps it, with a note that
/// its glass's caustic needs another; an integrator given on the command line says nothing.
#[test]
fn a_file_without_an_integrator_renders_its_caustics_and_says_why() {
    let dir = temp_dir("default-integrator");
    let glass = format!(
        "Film \"rgb\" \"integer xresolution\" 16 \"integer yresolution\" 16\n{PBRT_STAGE}\
         LightSource \"point\" \"point3 from\" [0 3 0] \"rgb I\" [5 5 5]\n\
         Material \"dielectric\" \"float eta\" 1.5\nShape \"sphere\" \"float radius\" 0.5\n\
         Material \"diffuse\"\nShape \"bilinearmesh\" \"point3 P\" [-3 -1 -3  3 -1 -3  -3 -1 3  3 -1 3]\n"
    );
    std::fs::write(dir.join("none.pbrt"), &glass).unwrap();
    std::fs::write(dir.join("path.pbrt"), format!("Integrator \"path\"\n{glass}")).unwrap();
    let render = |file: &str, extra: &[&str]| {
        let mut args = vec![
            "render",
            file,
            "--json",
            "--passes",
            "1",
            "--photons",
            "2000",
            "-o",
            "o.png",
        ];
        args.extend_from_slice(extra);
        let (code, stderr, stdout) = run(&dir, &args);
        assert_eq!(code, Some(0), "{stderr}");
        let json: serde_json::Value = serde_json::from_str(stdout.trim()).unwrap();
        let why = json["integrator_why"].as_str().unwrap_or_default().to_string();
        // Without --json the same note is printed.
        let plain: Vec<&str> = args.iter().copied().filter(|a| *a != "--json").collect();
        let (_, stderr, _) = run(&dir, &plain);
        assert_eq!(stderr.contains(&format!("note: {why}")), !why.is_empty(), "{stderr}");
        (json["integrator"].as_str().unwrap().to_string(), why)
    };
    let (integrator, why) = render("none.pbrt", &[]);
    assert_eq!(integrator, "vcm");
    assert!(why.starts_with("integrator vcm: the file names none"), "{why}");
    let (integrator, why) = render("path.pbrt", &[]);
    assert_eq!(integrator, "path");
    assert!(
        why.starts_with("integrator path: the file names it; a path tracer cannot show the caustics"),
        "{why}"
    );
    let (integrator, why) = render("none.pbrt", &["--integrator", "ppm"]);
    assert_eq!((integrator.as_str(), why.as_str()), ("ppm", ""));
}
