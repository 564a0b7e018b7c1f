//! The real binary's summaries: the one-line text on stderr, `--json` on stdout, `--quiet`.

use assert_cmd::Command;
use serde_json::Value;
use std::path::{Path, PathBuf};

fn caustica() -> Command {
    Command::cargo_bin("caustica").expect("the binary is built")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-summary-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scene(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name)
}

/// Runs to success; returns stdout and stderr.
fn run(cmd: &mut Command) -> (String, String) {
    let output = cmd.assert().success().get_output().clone();
    (
        String::from_utf8(output.stdout).unwrap(),
        String::from_utf8(output.stderr).unwrap(),
    )
}

/// The single line of stdout as JSON.
fn json(stdout: &str) -> Value {
    assert_eq!(stdout.lines().count(), 1, "one line: {stdout}");
    serde_json::from_str(stdout).unwrap_or_else(|e| panic!("not JSON ({e}): {stdout}"))
}

/// Checks that `seconds` holds each phase as a number of seconds.
fn assert_phases(summary: &Value, phases: &[&str]) {
    for phase in phases {
        let s = summary["seconds"][phase].as_f64();
        assert!(s.is_some_and(|s| s >= 0.0), "seconds.{phase} in {summary}");
    }
}

#[test]
fn render_json_has_every_phase() {
    let dir = temp_dir("render-json");
    let out = dir.join("ring.png");
    let (stdout, stderr) = run(caustica()
        .arg("render")
        .arg(scene("ring.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "32", "--aa", "2", "--photons", "3000", "--json"]));
    let summary = json(&stdout);
    assert_phases(&summary, &["parse", "build", "photons", "render", "total"]);
    assert_eq!(summary["output"].as_str(), Some(out.to_str().unwrap()));
    assert_eq!(summary["width"], 32);
    assert_eq!(summary["samples_per_pixel"], 4);
    assert_eq!(summary["photons_stored"], 3000, "exactly the budget: {summary}");
    let useful = summary["photons_useful_fraction"].as_f64().unwrap();
    assert!(useful > 0.0 && useful <= 1.0, "{summary}");
    assert_eq!(summary["photons_cap_reached"], false);
    assert_eq!(summary["photons_none_reason"], Value::Null);
    assert_eq!(summary["complete"], true);
    assert!(
        stderr.is_empty(),
        "--json keeps stderr for warnings and errors: {stderr}"
    );
    assert!(out.exists());
}

#[test]
fn render_prints_a_one_line_summary_with_every_phase() {
    let dir = temp_dir("render-text");
    let out = dir.join("lens.png");
    let (stdout, stderr) = run(caustica()
        .arg("render")
        .arg(scene("lens.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "24", "--photons", "2000"]));
    assert!(stdout.is_empty(), "{stdout}");
    let last = stderr.lines().last().unwrap_or_default();
    for part in [
        "lens.png",
        "at 1 spp",
        "photons stored",
        "parse ",
        "build ",
        "photons ",
        "render ",
        "total ",
    ] {
        assert!(last.contains(part), "`{part}` in the summary: {stderr}");
    }
}

#[test]
fn quiet_render_prints_nothing() {
    let dir = temp_dir("quiet");
    // A scene with a warning (no lights): --quiet silences it too.
    let dark = dir.join("dark.ray");
    std::fs::write(
        &dark,
        "SBT-raytracer 1.0\nsphere { material = { diffuse = (1, 1, 1); } }\n",
    )
    .unwrap();
    for scene in [scene("ring.ray"), dark] {
        let out = dir.join("out.png");
        let (stdout, stderr) = run(caustica().arg("render").arg(&scene).arg("-o").arg(&out).args([
            "--width",
            "16",
            "--photons",
            "1000",
            "--quiet",
        ]));
        assert!(stdout.is_empty() && stderr.is_empty(), "{scene:?}: {stdout}{stderr}");
        assert!(out.exists());
    }
}

#[test]
fn quiet_still_prints_errors() {
    let dir = temp_dir("quiet-error");
    let assert = caustica()
        .arg("render")
        .arg(dir.join("missing.ray"))
        .arg("-o")
        .arg(dir.join("out.png"))
        .arg("--quiet")
        .assert()
        .code(2);
    assert!(!assert.get_output().stderr.is_empty());
}

#[test]
fn photons_json_and_text_summaries() {
    let dir = temp_dir("photons-json");
    let (out, ply) = (dir.join("map.png"), dir.join("map.ply"));
    let (stdout, stderr) = run(caustica()
        .arg("photons")
        .arg(scene("ring.ray"))
        .arg("-o")
        .arg(&out)
        .arg("--ply")
        .arg(&ply)
        .args(["--width", "32", "--photons", "2000", "--json"]));
    let summary = json(&stdout);
    assert_phases(&summary, &["parse", "build", "photons", "total"]);
    assert_eq!(summary["output"].as_str(), Some(out.to_str().unwrap()));
    assert_eq!(summary["ply"].as_str(), Some(ply.to_str().unwrap()));
    let stored = summary["photons_stored"].as_u64().unwrap();
    assert!(
        stored >= 2000 && summary["photons_emitted"].as_u64().unwrap() >= stored,
        "{summary}"
    );
    assert_eq!(summary["complete"], true);
    assert!(stderr.is_empty(), "{stderr}");

    let (stdout, stderr) = run(caustica()
        .arg("photons")
        .arg(scene("ring.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "32", "--photons", "2000"]));
    assert!(stdout.is_empty(), "{stdout}");
    for part in ["map.png", "photons stored", "parse ", "build ", "photons ", "total "] {
        assert!(stderr.contains(part), "`{part}` in the summary: {stderr}");
    }
    let (stdout, stderr) = run(caustica()
        .arg("photons")
        .arg(scene("ring.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "32", "--photons", "2000", "--quiet"]));
    assert!(stdout.is_empty() && stderr.is_empty(), "{stdout}{stderr}");
}

#[test]
fn info_json_holds_what_the_text_shows() {
    let (stdout, _) = run(caustica().arg("info").arg(scene("pool.ray")).arg("--json"));
    let info = json(&stdout);
    let objects = info["objects"].as_array().unwrap();
    let (shapes, meshes) = (info["shapes"].as_u64().unwrap(), info["meshes"].as_u64().unwrap());
    assert_eq!(objects.len() as u64, shapes + meshes);
    let mesh = objects.iter().find(|o| o["kind"] == "mesh").expect("the water mesh");
    assert_eq!(mesh["triangles"], info["triangles"]);
    assert_eq!(mesh["bounds"]["min"].as_array().map(Vec::len), Some(3));
    let materials = info["materials"].as_array().unwrap();
    assert!(!materials.is_empty());
    for object in objects {
        assert!(object["material"].as_u64().unwrap() < materials.len() as u64);
    }
    assert_eq!(materials[0]["diffuse"].as_array().map(Vec::len), Some(3));
    assert!(info["warnings"].is_array() && info["camera"]["eye"].is_array());
    assert_eq!(info["lights"][0]["type"], "sun");
    assert_eq!(info["lights"][1]["type"], "environment");
    assert_phases(&info, &["parse", "build"]);
    assert!(info["scene"].as_str().unwrap().ends_with("pool.ray"));
}

#[test]
fn info_json_of_an_empty_scene_is_still_json() {
    let dir = temp_dir("info-empty");
    let empty = dir.join("empty.ray");
    // Nothing to bound: the bounds are infinite, which JSON writes as null.
    std::fs::write(&empty, "SBT-raytracer 1.0\n").unwrap();
    let (stdout, _) = run(caustica().arg("info").arg(&empty).arg("--json"));
    let info = json(&stdout);
    assert_eq!(info["bounds"]["min"][0], Value::Null);
    assert_eq!(info["warnings"].as_array().map(Vec::len), Some(2), "{info}");
}

#[test]
fn photons_ctrl_c_draws_the_partial_map_and_exits_130() {
    let dir = temp_dir("photons-interrupt");
    let out = dir.join("partial.png");
    // Far more photons than can be traced before the signal.
    let child = std::process::Command::new(assert_cmd::cargo::cargo_bin("caustica"))
        .arg("photons")
        .arg(scene("ring.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "32", "--photons", "5000000", "--json"])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1000));
    let status = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let output = child.wait_with_output().unwrap();
    assert_eq!(output.status.code(), Some(130), "exit code after Ctrl-C");
    let summary = json(&String::from_utf8(output.stdout).unwrap());
    assert_eq!(summary["complete"], false);
    assert!(summary["photons_stored"].as_u64().unwrap() < 5_000_000);
    assert!(out.exists(), "the photons stored so far are drawn");
}

/// A scene whose photons can make no caustic stops the photon pass at once and says why, in
/// words and in JSON.
#[test]
fn a_scene_without_caustics_says_why() {
    let dir = temp_dir("no-caustics");
    let cases = [
        (
            "mirror.ray",
            "scale(2, box { material = { reflective = (0.8, 0.8, 0.8); } })",
            "no_receiver",
            "nowhere to land",
        ),
        (
            "ball.ray",
            "sphere { material = { diffuse = (0.5, 0.5, 0.5); reflective = (0.8, 0.8, 0.8); } }",
            "none_landed",
            "none of the first 65536 photons",
        ),
    ];
    for (name, objects, reason, words) in cases {
        let file = dir.join(name);
        std::fs::write(
            &file,
            format!(
                "SBT-raytracer 1.0\ncamera {{ position = (0, 0, 6); viewdir = (0, 0, -1); updir = (0, 1, 0); }}\n\
                 directional_light {{ direction = (0, 0.3, -1); color = (1, 1, 1); }}\n{objects}"
            ),
        )
        .unwrap();
        let render = |extra: &str| {
            run(caustica()
                .arg("render")
                .arg(&file)
                .arg("-o")
                .arg(dir.join("out.png"))
                .args(["--width", "16"])
                .arg(extra))
        };
        let summary = json(&render("--json").0);
        assert_eq!(summary["photons_none_reason"], reason, "{summary}");
        assert_eq!(summary["photons_stored"], 0);
        let (_, stderr) = render("--seed=0");
        assert!(stderr.contains(words) && stderr.contains("no caustics"), "{stderr}");
    }
}
