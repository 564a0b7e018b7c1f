//! `caustica bench`: whole renders of the project's scenes, timed per phase, as a table.

use crate::cli::BenchArgs;
use caustica::{Error, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

struct Case {
    name: &'static str,
    scene: PathBuf,
    args: Vec<String>,
}

/// Runs the command; returns the exit code.
pub fn run(args: BenchArgs) -> Result<u8> {
    let exe =
        std::env::current_exe().map_err(|e| Error::InvalidSettings(format!("cannot find the caustica binary: {e}")))?;
    let mut cases = vec![
        case(&args, "ring.ray", "ring (default scene)", "512", "3", "100000"),
        case(&args, "ring_double.ray", "ring, two lights", "512", "1", "200000"),
        case(&args, "lens.ray", "lens", "512", "1", "200000"),
        case(&args, "blue_cube.ray", "blue mirror cube", "512", "1", "200000"),
        case(
            &args,
            "magnifier_sun.ray",
            "magnifier under the sun",
            "512",
            "1",
            "200000",
        ),
        case(&args, "pool.ray", "pool (4.6k-triangle water)", "512", "1", "200000"),
        case(&args, "ring_glossy.ray", "ring on a glossy floor", "512", "1", "200000"),
    ];
    let corpus_dir;
    if let Some(corpus) = &args.corpus {
        corpus_dir = original_ring(corpus)?;
        cases.insert(
            0,
            Case {
                name: "original ring (corpus), worst case",
                scene: corpus_dir.join("ring.ray"),
                args: vec!["--width", "512", "--aa", "3", "--photons", "100000"]
                    .into_iter()
                    .map(String::from)
                    .collect(),
            },
        );
    }
    if args.quick {
        for case in &mut cases {
            for pair in case.args.chunks_mut(2) {
                match pair[0].as_str() {
                    "--width" => pair[1] = "64".into(),
                    "--photons" => pair[1] = "5000".into(),
                    _ => {}
                }
            }
        }
    }
    crate::stdout::print("| scene | settings | photons (s) | render (s) | total (s) | stored | peak memory (MB) |\n|---|---|---:|---:|---:|---:|---:|\n")?;
    for case in &cases {
        let mut best: Option<Summary> = None;
        for _ in 0..args.repeat.max(1) {
            let summary = run_case(&exe, case, args.threads)?;
            if best.as_ref().is_none_or(|b| summary.total < b.total) {
                best = Some(summary);
            }
        }
        let Some(s) = best else { continue };
        crate::stdout::println(&format!(
            "| {} | {} | {:.3} | {:.3} | {:.3} | {} | {:.0} |",
            case.name,
            case.args.join(" "),
            s.photons,
            s.render,
            s.total,
            s.stored,
            s.peak_memory as f64 / 1e6
        ))?;
    }
    Ok(0)
}

fn case(args: &BenchArgs, file: &str, name: &'static str, width: &str, aa: &str, photons: &str) -> Case {
    Case {
        name,
        scene: args.scenes.join(file),
        args: vec!["--width", width, "--aa", aa, "--photons", photons]
            .into_iter()
            .map(String::from)
            .collect(),
    }
}

/// The original project's ring scene beside its texture under the name the scene uses.
fn original_ring(corpus: &Path) -> Result<PathBuf> {
    let dir = std::env::temp_dir().join(format!("caustica-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|source| Error::Io {
        path: dir.clone(),
        source,
    })?;
    for (from, to) in [
        ("OccamsRazer__cs384g__ring.ray", "ring.ray"),
        ("OccamsRazer__cs384g__wood.png", "wood.png"),
    ] {
        let src = corpus.join(from);
        std::fs::copy(&src, dir.join(to)).map_err(|source| Error::Io { path: src, source })?;
    }
    Ok(dir)
}

struct Summary {
    photons: f64,
    render: f64,
    total: f64,
    stored: u64,
    peak_memory: u64,
}

fn run_case(exe: &Path, case: &Case, threads: Option<usize>) -> Result<Summary> {
    let out = std::env::temp_dir().join(format!("caustica-bench-{}.png", std::process::id()));
    let mut cmd = Command::new(exe);
    cmd.arg("render")
        .arg(&case.scene)
        .arg("-o")
        .arg(&out)
        .arg("--json")
        .args(&case.args);
    if let Some(t) = threads {
        cmd.arg("--threads").arg(t.to_string());
    }
    let output = cmd
        .output()
        .map_err(|e| Error::InvalidSettings(format!("cannot run caustica: {e}")))?;
    let _ = std::fs::remove_file(&out);
    if !output.status.success() {
        return Err(Error::InvalidSettings(format!(
            "rendering {} failed: {}",
            case.scene.display(),
            String::from_utf8_lossy(&output.stderr)
        )));
    }
    let json: serde_json::Value = serde_json::from_slice(&output.stdout)
        .map_err(|e| Error::InvalidSettings(format!("caustica render --json printed no JSON: {e}")))?;
    let seconds = |key: &str| json["seconds"][key].as_f64().unwrap_or(f64::NAN);
    Ok(Summary {
        photons: seconds("photons"),
        render: seconds("render"),
        total: seconds("total"),
        stored: json["photons_stored"].as_u64().unwrap_or(0),
        peak_memory: json["peak_memory_bytes"].as_u64().unwrap_or(0),
    })
}
