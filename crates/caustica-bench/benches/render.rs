//! Whole renders of the scenes in `scenes/`: photons traced, map built and image rendered, as
//! `caustica render` does, at small settings so the suite stays short.
//!
//! ```text
//! cargo bench -p caustica --bench render
//! ```
//!
//! Settings: 128 pixels wide (height from the camera), 1 sample per pixel (`ring-aa3`: 3×3),
//! 20,000 stored photons, k = 100, seed 0, all threads. The full-size table comes from
//! `caustica bench` (BENCHMARKS.md, "Whole renders").

use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use caustica::integrator::whitted::{self, WhittedSettings};
use caustica::integrator::{image_size, ImageSettings};
use caustica::loader::{load, LoadSettings};
use caustica::photon::{EstimateSettings, PhotonMap, PhotonSettings};
use caustica::progress::{Control, NoProgress};
use caustica::scene::Scene;
use criterion::{criterion_group, criterion_main, Criterion};

const WIDTH: usize = 128;
const STORED: usize = 20_000;

fn render_once(scene: &Scene, aa: u32, control: Control) -> f32 {
    let estimate = EstimateSettings::default();
    let photons = PhotonSettings {
        target_stored: STORED,
        ..PhotonSettings::default()
    };
    let map = PhotonMap::trace(scene, &photons, &estimate, control);
    let (width, height) = image_size(scene.camera(), WIDTH, None);
    let image = ImageSettings {
        width,
        height,
        aa,
        seed: 0,
    };
    let caustics = (!map.is_empty()).then_some((&map, &estimate));
    let (film, _) = whitted::render(scene, caustics, &WhittedSettings::default(), &image, control);
    film.pixels[film.pixels.len() / 2].x
}

fn renders(c: &mut Criterion) {
    let cancel = AtomicBool::new(false);
    let control = Control {
        progress: &NoProgress,
        cancel: &cancel,
    };
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("scenes/ exists")
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.ends_with(".ray"))
        .collect();
    names.sort();
    let mut group = c.benchmark_group("render");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for name in &names {
        let scene = load(&dir.join(name), &LoadSettings::default()).expect("scene loads");
        let label = name.trim_end_matches(".ray");
        group.bench_function(label, |b| b.iter(|| black_box(render_once(&scene, 1, control))));
        if label == "ring" {
            group.bench_function("ring-aa3", |b| b.iter(|| black_box(render_once(&scene, 3, control))));
        }
    }
    group.finish();
}

criterion_group!(benches, renders);
criterion_main!(benches);
