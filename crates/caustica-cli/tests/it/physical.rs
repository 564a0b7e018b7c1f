//! The real binary under the physical model: split runs merged, progressive output, refusals.

use assert_cmd::Command;
use caustica::integrator::partial::Accumulator;
use std::path::{Path, PathBuf};

fn caustica() -> Command {
    Command::cargo_bin("caustica").expect("the binary is built")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-physical-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn scene() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/glass_sphere.ray")
}

const TINY: [&str; 6] = ["--model", "physical", "--width", "32", "--photons", "2000"];

const SMALL: [&str; 6] = ["--width", "48", "--photons", "5000", "--quiet", "--model"];

fn render(dir: &Path, extra: &[&str]) {
    caustica()
        .current_dir(dir)
        .arg("render")
        .arg(scene())
        .args(SMALL)
        .arg("physical")
        .args(extra)
        .assert()
        .success();
}

fn exr(path: &Path) -> Vec<f32> {
    let (_, _, pixels) = caustica::image_io::read_exr(path).unwrap();
    pixels.iter().flat_map(|p| p.to_array()).collect()
}

/// Two halves of a run, merged, give the image of one run over all its passes (the sums are
/// added in another order, so equality is to rounding).
#[test]
fn merged_halves_equal_one_full_run() {
    for integrator in ["ppm", "gi", "path", "lt", "vcm"] {
        let dir = temp_dir(&format!("merge-{integrator}"));
        render(
            &dir,
            &["--integrator", integrator, "--passes", "0..3", "--partial", "a.part"],
        );
        render(
            &dir,
            &["--integrator", integrator, "--passes", "3..6", "--partial", "b.part"],
        );
        render(&dir, &["--integrator", integrator, "--passes", "6", "-o", "full.exr"]);
        assert!(
            !dir.join("caustica.png").exists(),
            "a partial run writes no image unless asked"
        );
        caustica()
            .current_dir(&dir)
            .args(["merge", "b.part", "a.part", "-o", "merged.exr", "--quiet"])
            .assert()
            .success();
        let (full, merged) = (exr(&dir.join("full.exr")), exr(&dir.join("merged.exr")));
        assert_eq!(full.len(), merged.len());
        let worst = full
            .iter()
            .zip(&merged)
            .map(|(a, b)| (a - b).abs() / a.abs().max(1e-3))
            .fold(0.0f32, f32::max);
        assert!(
            worst < 1e-5,
            "{integrator}: merged differs from the full run by {worst}"
        );
        assert!(full.iter().any(|&v| v > 0.0), "{integrator}: the image is not black");
        let part = Accumulator::load(&dir.join("a.part")).unwrap();
        assert_eq!(part.passes, vec![(0, 3)]);
    }
}

#[test]
fn merge_refuses_shared_passes_and_other_runs() {
    let dir = temp_dir("merge-refusals");
    render(&dir, &["--passes", "0..2", "--partial", "a.part"]);
    render(&dir, &["--passes", "1..3", "--partial", "b.part"]);
    render(&dir, &["--passes", "2..4", "--partial", "c.part", "--seed", "9"]);
    let shared = caustica()
        .current_dir(&dir)
        .args(["merge", "a.part", "b.part", "-o", "m.exr"])
        .assert()
        .code(2);
    let stderr = String::from_utf8(shared.get_output().stderr.clone()).unwrap();
    assert!(stderr.contains("count them twice"), "{stderr}");
    let other = caustica()
        .current_dir(&dir)
        .args(["merge", "a.part", "c.part", "-o", "m.exr"])
        .assert()
        .code(2);
    let stderr = String::from_utf8(other.get_output().stderr.clone()).unwrap();
    assert!(stderr.contains("different runs"), "{stderr}");
    assert!(!dir.join("m.exr").exists(), "no output from a refused merge");
    std::fs::write(dir.join("junk.part"), b"not a part").unwrap();
    caustica()
        .current_dir(&dir)
        .args(["merge", "junk.part", "-o", "m.exr"])
        .assert()
        .code(2);
}

#[test]
fn physical_options_are_checked() {
    let dir = temp_dir("options");
    for bad in [
        vec!["--model", "course", "--integrator", "ppm"],
        vec!["--model", "physical", "--integrator", "whitted"],
        vec!["--model", "physical", "--passes", "5..2"],
        vec!["--model", "physical", "--passes", "x"],
        vec!["--model", "physical", "--alpha", "1.5"],
        vec!["--model", "physical", "--footprint", "0"],
        vec!["--model", "physical", "--time", "-1"],
        vec!["--model", "physical", "--photons", "0"],
        vec!["--passes", "4"],
    ] {
        caustica()
            .current_dir(&dir)
            .arg("render")
            .arg(scene())
            .args(["--width", "8"])
            .args(&bad)
            .assert()
            .code(2);
    }
}

#[test]
fn time_budget_renders_at_least_one_pass_and_reports_json() {
    let dir = temp_dir("time");
    let out = caustica()
        .current_dir(&dir)
        .arg("render")
        .arg(scene())
        .args(TINY)
        .args(["--time", "0.3", "--json"])
        .assert()
        .success();
    let summary: serde_json::Value = serde_json::from_slice(&out.get_output().stdout).unwrap();
    assert_eq!(summary["integrator"], "ppm", "{summary}");
    assert!(summary["passes"].as_u64().unwrap() >= 1, "{summary}");
    assert!(summary["seconds"]["build"].as_f64().is_some(), "{summary}");
    assert!(dir.join("caustica.png").exists());
}

#[test]
fn ctrl_c_keeps_the_passes_done() {
    let dir = temp_dir("interrupt");
    let exe = assert_cmd::cargo::cargo_bin("caustica");
    let mut child = std::process::Command::new(exe)
        .current_dir(&dir)
        .arg("render")
        .arg(scene())
        .args(TINY)
        .args([
            "--passes",
            "1000000",
            "--partial",
            "run.part",
            "-o",
            "run.exr",
            "--quiet",
        ])
        .spawn()
        .unwrap();
    std::thread::sleep(std::time::Duration::from_millis(2000));
    let status = std::process::Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    assert_eq!(child.wait().unwrap().code(), Some(130));
    let part = Accumulator::load(&dir.join("run.part")).unwrap();
    assert_eq!(part.passes.len(), 1);
    assert_eq!(part.passes[0].0, 0);
    assert!(part.pass_count() >= 1);
    assert_eq!(exr(&dir.join("run.exr")).len(), 32 * 24 * 3);
}
