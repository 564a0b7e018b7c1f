//! Photon benchmarks: paths traced per second through real scenes, and building the photon map
//! (kd-tree plus automatic radius) over many stored photons, with the memory it takes.
//!
//! ```text
//! cargo bench -p caustica --bench photons                      # trace, and a 1M-photon build
//! PHOTON_BENCH_10M=1 cargo bench -p caustica --bench photons   # adds the 10M-photon build
//! ```
//!
//! Throughput lines count emitted photon paths (`trace`) or stored photons (`build`). Tracing
//! runs on a 1-thread pool (per core) and a 2-thread pool; building on the global pool.

use std::hint::black_box;
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use caustica::loader::{load, LoadSettings};
use caustica::math::Vec3;
use caustica::photon::{EstimateSettings, Estimator, Photon, PhotonMap, PhotonSettings, PhotonStats};
use caustica::progress::{Control, NoProgress};
use caustica::sampling::Rng;
use caustica::scene::Scene;
use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};

const STORED: usize = 100_000;

fn scene(name: &str) -> Scene {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes").join(name);
    load(&path, &LoadSettings::default()).expect("bench scene loads")
}

fn trace(c: &mut Criterion) {
    let cancel = AtomicBool::new(false);
    let control = Control {
        progress: &NoProgress,
        cancel: &cancel,
    };
    let settings = PhotonSettings {
        target_stored: STORED,
        ..PhotonSettings::default()
    };
    let mut group = c.benchmark_group("photons/trace");
    group.sample_size(10).measurement_time(Duration::from_secs(4));
    for name in ["ring.ray", "pool.ray"] {
        let scene = scene(name);
        let emitted = PhotonMap::trace(&scene, &settings, &EstimateSettings::default(), control)
            .stats
            .emitted;
        group.throughput(Throughput::Elements(emitted));
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            group.bench_function(BenchmarkId::new(name, format!("{threads}-thread")), |b| {
                b.iter(|| {
                    pool.install(|| {
                        black_box(PhotonMap::trace(&scene, &settings, &EstimateSettings::default(), control).len())
                    })
                })
            });
        }
    }
    group.finish();
}

/// Photons on a floor: a uniform background, a nephroid band with its cusps and a bright ring, as
/// a ring's caustic stores them.
fn caustic_photons(n: usize) -> Vec<Photon> {
    let mut rng = Rng::new(11, n as u64);
    (0..n)
        .map(|_| {
            let c = rng.uniform();
            let t = rng.uniform() * std::f32::consts::TAU;
            let (x, z) = if c < 0.4 {
                (rng.uniform() * 2.0 - 1.0, rng.uniform() * 2.0 - 1.0)
            } else if c < 0.8 {
                let s = 0.2 * (1.0 - 0.5 * rng.uniform().powi(3));
                (
                    s * (3.0 * t.cos() - (3.0 * t).cos()),
                    s * (3.0 * t.sin() - (3.0 * t).sin()),
                )
            } else {
                let r = 0.85 + 0.004 * (rng.uniform() - 0.5);
                (r * t.cos(), r * t.sin())
            };
            let dir = Vec3::new(rng.uniform() - 0.5, -1.0, rng.uniform() - 0.5).normalize();
            Photon::new(Vec3::new(x, 0.0, z), Vec3::splat(1e-6), dir, Vec3::Y, 1)
        })
        .collect()
}

/// Peak resident memory of this process so far (Linux), in bytes.
fn peak_rss() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

fn build(c: &mut Criterion) {
    let mut sizes = vec![1_000_000];
    if std::env::var_os("PHOTON_BENCH_10M").is_some() {
        sizes.push(10_000_000);
    }
    let mut group = c.benchmark_group("photons/build");
    group.sample_size(10).measurement_time(Duration::from_secs(8));
    for n in sizes {
        let photons = caustic_photons(n);
        // The k-nearest build (tree and automatic radius) as measured before, then the kernel
        // estimate's (the tree and every photon's kernel).
        let nearest = EstimateSettings {
            estimator: Estimator::Nearest,
            ..EstimateSettings::default()
        };
        let kernels = EstimateSettings::default();
        let map = PhotonMap::from_photons(photons.clone(), PhotonStats::default(), &kernels);
        eprintln!(
            "photons/build/{n}: map {:.1} MB ({:.2} bytes per photon), process peak {:.0} MB",
            map.heap_bytes() as f64 / 1e6,
            map.heap_bytes() as f64 / n as f64,
            peak_rss().unwrap_or(0) as f64 / 1e6
        );
        drop(map);
        group.throughput(Throughput::Elements(n as u64));
        group.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter_batched(
                || photons.clone(),
                |p| black_box(PhotonMap::from_photons(p, PhotonStats::default(), &nearest).auto_radius()),
                BatchSize::LargeInput,
            )
        });
        group.bench_function(BenchmarkId::new("kernels", n), |b| {
            b.iter_batched(
                || photons.clone(),
                |p| black_box(PhotonMap::from_photons(p, PhotonStats::default(), &kernels).heap_bytes()),
                BatchSize::LargeInput,
            )
        });
    }
    group.finish();
}

criterion_group!(benches, trace, build);
criterion_main!(benches);
