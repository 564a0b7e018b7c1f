//! The real `caustica` binary: outputs, exit codes, diagnostics.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn caustica() -> Command {
    Command::cargo_bin("caustica").expect("the binary is built")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-cli-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scenes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes")
}

fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    (w, h)
}

#[test]
fn render_without_a_scene_writes_the_default_ring() {
    let dir = temp_dir("default");
    caustica()
        .current_dir(&dir)
        .args(["render", "--width", "64", "--photons", "20000", "--quiet"])
        .assert()
        .success();
    assert_eq!(png_size(&dir.join("caustica.png")), (64, 64));
}

#[test]
fn render_writes_exr_and_json_summary() {
    let dir = temp_dir("exr");
    let out = dir.join("lens.exr");
    let assert = caustica()
        .args(["render"])
        .arg(scenes().join("lens.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "40", "--photons", "5000", "--json"])
        .assert()
        .success();
    let stdout = String::from_utf8(assert.get_output().stdout.clone()).unwrap();
    assert!(
        stdout.contains("\"photons_stored\":5") && stdout.contains("\"complete\":true"),
        "{stdout}"
    );
    let bytes = std::fs::read(&out).unwrap();
    assert_eq!(&bytes[..4], &[0x76, 0x2f, 0x31, 0x01], "OpenEXR magic number");
}

#[test]
fn a_malformed_scene_names_file_line_and_column_and_exits_2() {
    let dir = temp_dir("bad");
    let scene = dir.join("bad.ray");
    std::fs::write(
        &scene,
        "SBT-raytracer 1.0\ncamera {\n  position = (0, 0, 1);\n  difuse = (1, 1, 1);\n}\n",
    )
    .unwrap();
    let assert = caustica()
        .arg("render")
        .arg(&scene)
        .arg("-o")
        .arg(dir.join("out.png"))
        .assert()
        .code(2);
    let stderr = String::from_utf8(assert.get_output().stderr.clone()).unwrap();
    assert!(stderr.contains("bad.ray:4:3"), "{stderr}");
    assert!(!dir.join("out.png").exists(), "no output for a bad scene");
}

#[test]
fn bad_options_are_refused_with_exit_2_before_any_work() {
    let dir = temp_dir("options");
    for args in [
        vec!["render", "--width", "100000", "--height", "100000"],
        vec!["render", "--aa", "0"],
        vec!["render", "--photons", "999999999999"],
        vec!["render", "-o", "picture.jpg"],
        vec!["render", "--threads", "0"],
        vec!["render", "--no-such-flag"],
        vec!["render", "--estimate", "widest"],
        vec!["render", "--tone-map", "gamma"],
        vec!["render", "--exposure", "nan"],
    ] {
        let assert = caustica().current_dir(&dir).args(&args).assert().code(2);
        let stderr = String::from_utf8(assert.get_output().stderr.clone()).unwrap();
        assert!(!stderr.is_empty(), "{args:?} says why");
    }
    assert!(!dir.join("caustica.png").exists());
}

#[test]
fn a_missing_scene_file_is_bad_input() {
    caustica().args(["info", "/no/such/scene.ray"]).assert().code(2);
}

#[test]
fn every_subcommand_has_help_with_examples() {
    for sub in ["render", "info", "photons"] {
        let assert = caustica().args([sub, "--help"]).assert().success();
        let stdout = String::from_utf8(assert.get_output().stdout.clone()).unwrap();
        assert!(stdout.contains("Examples:"), "{sub}: {stdout}");
    }
}

#[test]
fn info_reports_camera_lights_and_objects() {
    let assert = caustica()
        .arg("info")
        .arg(scenes().join("ring_double.ray"))
        .arg("--json")
        .assert()
        .success();
    let stdout = String::from_utf8(assert.get_output().stdout.clone()).unwrap();
    assert!(stdout.contains("\"lights\":[{\"type\":\"point\""), "{stdout}");
    assert!(stdout.contains("\"shapes\":2"), "{stdout}");
}

#[test]
fn photons_draws_a_map_and_writes_ply() {
    let dir = temp_dir("photons");
    caustica()
        .arg("photons")
        .arg(scenes().join("ring.ray"))
        .arg("-o")
        .arg(dir.join("map.png"))
        .arg("--ply")
        .arg(dir.join("map.ply"))
        .args(["--photons", "3000", "--width", "48", "--quiet"])
        .assert()
        .success();
    assert_eq!(png_size(&dir.join("map.png")), (48, 48));
    let ply = std::fs::read(dir.join("map.ply")).unwrap();
    let header = String::from_utf8_lossy(&ply[..200]);
    assert!(
        header.starts_with("ply\n") && header.contains("element vertex 3"),
        "{header}"
    );
}

#[test]
fn the_image_does_not_depend_on_the_thread_count() {
    let dir = temp_dir("threads");
    for threads in ["1", "2"] {
        caustica()
            .arg("render")
            .arg(scenes().join("ring.ray"))
            .arg("-o")
            .arg(dir.join(format!("t{threads}.png")))
            .args([
                "--width",
                "48",
                "--aa",
                "2",
                "--photons",
                "10000",
                "--threads",
                threads,
                "--quiet",
            ])
            .assert()
            .success();
    }
    let one = std::fs::read(dir.join("t1.png")).unwrap();
    let two = std::fs::read(dir.join("t2.png")).unwrap();
    assert!(one == two, "1 and 2 threads differ");
}

#[test]
fn ctrl_c_saves_the_partial_image_and_exits_130() {
    let dir = temp_dir("interrupt");
    let out = dir.join("partial.png");
    let exe = assert_cmd::cargo::cargo_bin("caustica");
    // A render long enough to be interrupted: large, many samples.
    let mut child = std::process::Command::new(exe)
        .arg("render")
        .arg(scenes().join("ring.ray"))
        .arg("-o")
        .arg(&out)
        .args(["--width", "1500", "--aa", "6", "--photons", "20000", "--quiet"])
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(1500));
    let status = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    let code = child.wait().unwrap().code();
    assert_eq!(code, Some(130), "exit code after Ctrl-C");
    assert_eq!(png_size(&out), (1500, 1500), "the partial image is complete as a file");
}

#[test]
fn max_memory_caps_the_photon_map() {
    let dir = temp_dir("max-memory");
    let assert = caustica()
        .current_dir(&dir)
        .args(["render", "--photons", "50000000", "--max-memory", "100"])
        .assert()
        .code(2);
    let stderr = String::from_utf8(assert.get_output().stderr.clone()).unwrap();
    assert!(stderr.contains("--max-memory 100 MB"), "{stderr}");
    caustica()
        .current_dir(&dir)
        .args([
            "render",
            "--photons",
            "2000",
            "--max-memory",
            "1",
            "--width",
            "16",
            "--quiet",
        ])
        .assert()
        .success();
}

/// `caustica info big.ray | head -1`: the reader closes the pipe long before the output ends
/// (far more than a pipe's buffer of it), and caustica stops quietly with success.
#[test]
fn a_reader_that_stops_early_ends_info_quietly() {
    use std::io::{BufRead, Read};
    use std::process::Stdio;
    let dir = temp_dir("pipe");
    let scene = dir.join("many.ray");
    let mut text =
        String::from("SBT-raytracer 1.0\ncamera { position = (0, 0, 40); viewdir = (0, 0, -1); updir = (0, 1, 0); }\n");
    for i in 0..3000 {
        text += &format!(
            "translate({}, {}, 0, sphere {{ material = {{ diffuse = (1, 1, 1); }} }})\n",
            i % 60,
            i / 60
        );
    }
    std::fs::write(&scene, text).unwrap();
    let exe = assert_cmd::cargo::cargo_bin("caustica");
    for json in [false, true] {
        let mut child = std::process::Command::new(&exe)
            .arg("info")
            .arg(&scene)
            .args(json.then_some("--json"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        let mut first = String::new();
        std::io::BufReader::new(child.stdout.take().unwrap())
            .take(100)
            .read_line(&mut first)
            .unwrap();
        assert!(!first.is_empty());
        // Dropping the reader closed the pipe.
        let output = child.wait_with_output().unwrap();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert_eq!(output.status.code(), Some(0), "json {json}: {stderr}");
        assert!(stderr.is_empty(), "json {json}: {stderr}");
    }
}

/// An output into a folder that does not exist is refused before the scene is even read (the
/// scene here is malformed, and that is not what is reported), for every command that writes.
#[test]
fn outputs_are_checked_before_any_work() {
    let dir = temp_dir("outputs");
    let bad_scene = dir.join("bad.ray");
    std::fs::write(&bad_scene, "SBT-raytracer 1.0\ncamera { difuse = 1; }\n").unwrap();
    let missing = dir.join("no-such-folder");
    let part = dir.join("a.part");
    let cases: Vec<Vec<std::ffi::OsString>> = vec![
        vec![
            "render".into(),
            bad_scene.clone().into(),
            "-o".into(),
            missing.join("x.png").into(),
        ],
        vec![
            "render".into(),
            bad_scene.clone().into(),
            "--model".into(),
            "physical".into(),
            "--partial".into(),
            missing.join("x.part").into(),
        ],
        vec![
            "photons".into(),
            bad_scene.clone().into(),
            "-o".into(),
            missing.join("x.png").into(),
        ],
        vec![
            "photons".into(),
            bad_scene.clone().into(),
            "-o".into(),
            dir.join("x.png").into(),
            "--ply".into(),
            missing.join("x.ply").into(),
        ],
        vec![
            "merge".into(),
            part.clone().into(),
            "-o".into(),
            missing.join("x.exr").into(),
        ],
        vec![
            "render".into(),
            bad_scene.clone().into(),
            "-o".into(),
            dir.clone().join("sub.png/").into(),
        ],
    ];
    std::fs::create_dir_all(dir.join("sub.png")).unwrap();
    for args in cases {
        let assert = caustica().args(&args).assert().code(2);
        let output = assert.get_output();
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(stderr.contains("cannot write"), "{args:?}: {stderr}");
        assert!(!stderr.contains("bad.ray:"), "{args:?} read the scene first: {stderr}");
        assert!(output.stdout.is_empty());
    }
    assert!(!missing.exists());
    assert!(!dir.join("x.png").exists());
}
