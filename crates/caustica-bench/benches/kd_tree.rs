//! kd-tree benchmarks: caustica's `KdTree` beside kiddo 5 on identical photon-like data.
//!
//! Data lies on surfaces, as photons do:
//! - `caustic`: a floor plane with a uniform background, a nephroid caustic band (with its cusps)
//!   and a thin bright ring;
//! - `scene`: a box (floor, two walls), a tilted plane and a sphere.
//!
//! Queries are single-threaded, at jittered photon positions (where a renderer gathers), in
//! random order; each criterion iteration runs a batch of `QUERIES`, so the throughput line is
//! queries/s. Builds run on the global rayon pool (ours) and single-threaded (ours, kiddo).
//!
//! ```text
//! cargo bench -p caustica --bench kd_tree                  # 100k and 1M
//! KD_BENCH_10M=1 cargo bench -p caustica --bench kd_tree   # adds 10M (several GB, minutes)
//! cargo bench -p caustica --bench kd_tree -- knn50/caustic # filter, as usual
//! ```

use std::hint::black_box;
use std::num::NonZeroUsize;
use std::time::Duration;

use caustica::math::Vec3;
use caustica::photon::kd_tree::{KdPoint, KdTree, Neighbor};
use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion, Throughput};
use kiddo::{ImmutableKdTree, SquaredEuclidean};

type KiddoTree = kiddo::KdTree<f32, 3>;

/// Queries per criterion iteration.
const QUERIES: usize = 10_000;
/// Gather radius for k-NN: large enough to hold 200 photons everywhere in both data sets.
const KNN_MAX_DIST2: f32 = 0.25 * 0.25;

/// A photon as the renderer stores it: 24 bytes. Only the payload's size matters here.
#[derive(Clone, Copy)]
#[allow(dead_code)]
struct Photon {
    pos: Vec3,
    power: [u8; 4],
    dir: [i16; 4],
}

impl KdPoint for Photon {
    #[inline]
    fn position(&self) -> Vec3 {
        self.pos
    }
}

/// splitmix64.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn f(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    /// Roughly normal (sum of uniforms).
    fn gauss(&mut self) -> f32 {
        (self.f() + self.f() + self.f() + self.f() - 2.0) * 1.73
    }
}

/// Floor y = 0, x,z in [-1, 1]: background, nephroid band with cusps, bright ring.
fn caustic(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|_| {
            let c = rng.f();
            let (x, z) = if c < 0.4 {
                (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0))
            } else if c < 0.8 {
                // Nephroid x = 3cos t - cos 3t, z = 3sin t - sin 3t; light piles up on the
                // curve and fades inward.
                let t = rng.range(0.0, std::f32::consts::TAU);
                let s = 0.2 * (1.0 - 0.5 * rng.f().powi(3));
                (
                    s * (3.0 * t.cos() - (3.0 * t).cos()),
                    s * (3.0 * t.sin() - (3.0 * t).sin()),
                )
            } else {
                let t = rng.range(0.0, std::f32::consts::TAU);
                let r = 0.85 + 0.004 * rng.gauss();
                (r * t.cos(), r * t.sin())
            };
            Vec3::new(x, 0.0, z)
        })
        .collect()
}

/// Box floor and two walls, a tilted plane and a sphere.
fn scene(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    let (u, v) = (
        Vec3::new(0.8, 0.3, -0.2).normalize(),
        Vec3::new(-0.1, 0.5, 0.9).normalize(),
    );
    (0..n)
        .map(|_| {
            let (a, b) = (rng.range(-1.0, 1.0), rng.range(-1.0, 1.0));
            match rng.below(5) {
                0 => Vec3::new(a, -1.0, b),
                1 => Vec3::new(a, b, -1.0),
                2 => Vec3::new(-1.0, a, b),
                3 => Vec3::new(0.2, -0.3, 0.1) + u * a * 0.6 + v * b * 0.6,
                _ => {
                    let z = a;
                    let phi = std::f32::consts::PI * b;
                    let r = (1.0 - z * z).sqrt();
                    Vec3::new(0.5, -0.6, 0.4) + Vec3::new(r * phi.cos(), z, r * phi.sin()) * 0.35
                }
            }
        })
        .collect()
}

struct Data {
    name: &'static str,
    n: usize,
    photons: Vec<Photon>,
    /// Same positions, for kiddo.
    points: Vec<[f32; 3]>,
    queries: Vec<Vec3>,
    /// Fixed gather radius: about 50 photons at a typical query.
    within_r2: f32,
}

fn make(name: &'static str, n: usize) -> Data {
    let mut rng = Rng(n as u64 ^ name.len() as u64);
    let pos = if name == "caustic" {
        caustic(&mut rng, n)
    } else {
        scene(&mut rng, n)
    };
    let photons: Vec<Photon> = pos
        .iter()
        .enumerate()
        .map(|(i, &pos)| Photon {
            pos,
            power: [i as u8; 4],
            dir: [0; 4],
        })
        .collect();
    let points = pos.iter().map(|p| p.to_array()).collect();
    let jitter = 0.3 / (n as f32).sqrt();
    let queries: Vec<Vec3> = (0..QUERIES)
        .map(|_| {
            let p = pos[rng.below(n)];
            p + Vec3::new(rng.gauss(), rng.gauss(), rng.gauss()) * jitter
        })
        .collect();
    // Median 50th-neighbour distance over some queries.
    let mut items = photons.clone();
    let tree = KdTree::build(&mut items);
    let mut out = Vec::new();
    let mut r2s: Vec<f32> = queries[..501]
        .iter()
        .map(|&q| tree.k_nearest(&items, q, 50, f32::INFINITY, &mut out))
        .collect();
    r2s.sort_by(f32::total_cmp);
    Data {
        name,
        n,
        photons,
        points,
        queries,
        within_r2: r2s[250],
    }
}

fn label(n: usize) -> String {
    if n >= 1_000_000 {
        format!("{}M", n / 1_000_000)
    } else {
        format!("{}k", n / 1000)
    }
}

fn sizes() -> Vec<usize> {
    let mut s = vec![100_000, 1_000_000];
    if std::env::var_os("KD_BENCH_10M").is_some() {
        s.push(10_000_000);
    }
    s
}

fn tune(g: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>, n: usize) {
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(if n >= 10_000_000 { 20 } else { 3 }));
}

fn kiddo_mutable(points: &[[f32; 3]]) -> KiddoTree {
    let mut t = KiddoTree::with_capacity(points.len());
    for (i, p) in points.iter().enumerate() {
        t.add(p, i as u64);
    }
    t
}

fn bench_build(c: &mut Criterion, d: &Data) {
    let mut g = c.benchmark_group(format!("build/{}", d.name));
    tune(&mut g, d.n);
    g.throughput(Throughput::Elements(d.n as u64));
    let id = |f: &str| BenchmarkId::new(f, label(d.n));
    g.bench_function(id("ours"), |b| {
        b.iter_batched_ref(
            || d.photons.clone(),
            |items| KdTree::build(items),
            BatchSize::LargeInput,
        )
    });
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap();
    g.bench_function(id("ours_1thread"), |b| {
        b.iter_batched_ref(
            || d.photons.clone(),
            |items| one.install(|| KdTree::build(items)),
            BatchSize::LargeInput,
        )
    });
    g.bench_function(id("kiddo_immutable"), |b| {
        b.iter(|| ImmutableKdTree::<f32, 3>::new_from_slice(&d.points))
    });
    // Skipped at 10M: many seconds per build and pathological on flat data (see queries).
    if d.n < 10_000_000 {
        g.bench_function(id("kiddo_mutable"), |b| b.iter(|| kiddo_mutable(&d.points)));
    }
    g.finish();
}

/// Checks that all three trees agree before timing them.
fn cross_check(d: &Data, items: &[Photon], ours: &KdTree, imm: &ImmutableKdTree<f32, 3>) {
    let mut out = Vec::new();
    for &q in &d.queries[..200] {
        for k in [50, 200] {
            let r = ours.k_nearest(items, q, k, KNN_MAX_DIST2, &mut out);
            let theirs = imm.nearest_n_within::<SquaredEuclidean>(
                &q.to_array(),
                KNN_MAX_DIST2,
                NonZeroUsize::new(k).unwrap(),
                false,
            );
            assert_eq!(out.len(), theirs.len());
            let far = theirs.iter().map(|n| n.distance).fold(0.0, f32::max);
            assert!((far - r).abs() <= 1e-6 * r.max(1e-12), "{far} vs {r}");
        }
        let mut count = 0usize;
        ours.for_each_within(items, q, d.within_r2, |_, _| count += 1);
        let theirs = imm.within_unsorted::<SquaredEuclidean>(&q.to_array(), d.within_r2);
        // Boundary rounding may differ by a point at most rarely.
        assert!(count.abs_diff(theirs.len()) <= 1, "{count} vs {}", theirs.len());
    }
}

fn bench_queries(c: &mut Criterion, d: &Data) {
    let mut items = d.photons.clone();
    let ours = KdTree::build(&mut items);
    let imm = ImmutableKdTree::<f32, 3>::new_from_slice(&d.points);
    // kiddo's mutable tree: skipped at 10M (slow to build, very slow on flat data).
    let mutable = (d.n < 10_000_000).then(|| kiddo_mutable(&d.points));
    cross_check(d, &items, &ours, &imm);
    eprintln!(
        "{} {}: tree overhead {:.2} bytes/point (ours), fixed radius {:.5}",
        d.name,
        label(d.n),
        ours.heap_bytes() as f64 / d.n as f64,
        d.within_r2.sqrt()
    );

    for k in [50usize, 200] {
        let mut g = c.benchmark_group(format!("knn{k}/{}", d.name));
        tune(&mut g, d.n);
        g.throughput(Throughput::Elements(d.queries.len() as u64));
        let id = |f: &str| BenchmarkId::new(f, label(d.n));
        let kk = NonZeroUsize::new(k).unwrap();
        g.bench_function(id("ours"), |b| {
            let mut out: Vec<Neighbor> = Vec::with_capacity(k);
            b.iter(|| {
                let mut acc = 0.0;
                for &q in &d.queries {
                    acc += ours.k_nearest(&items, q, k, KNN_MAX_DIST2, &mut out);
                }
                acc
            })
        });
        g.bench_function(id("kiddo_immutable"), |b| {
            b.iter(|| {
                let mut acc = 0usize;
                for q in &d.queries {
                    let r = imm.nearest_n_within::<SquaredEuclidean>(&q.to_array(), KNN_MAX_DIST2, kk, false);
                    acc += r.len();
                }
                acc
            })
        });
        g.bench_function(id("kiddo_immutable_unbounded"), |b| {
            b.iter(|| {
                let mut acc = 0usize;
                for q in &d.queries {
                    acc += imm.nearest_n::<SquaredEuclidean>(&q.to_array(), kk).len();
                }
                acc
            })
        });
        // kiddo's mutable tree is very slow on flat data (see the report); fewer queries.
        let few = &d.queries[..QUERIES / 20];
        g.throughput(Throughput::Elements(few.len() as u64));
        if let Some(mutable) = &mutable {
            g.bench_function(id("kiddo_mutable"), |b| {
                b.iter(|| {
                    let mut acc = 0usize;
                    for q in few {
                        let r = mutable.nearest_n_within::<SquaredEuclidean>(&q.to_array(), KNN_MAX_DIST2, kk, false);
                        acc += r.len();
                    }
                    acc
                })
            });
        }
        g.finish();
    }

    let mut g = c.benchmark_group(format!("within/{}", d.name));
    tune(&mut g, d.n);
    g.throughput(Throughput::Elements(d.queries.len() as u64));
    let id = |f: &str| BenchmarkId::new(f, label(d.n));
    let r2 = d.within_r2;
    g.bench_function(id("ours"), |b| {
        b.iter(|| {
            let mut acc = 0.0f32;
            for &q in &d.queries {
                ours.for_each_within(&items, q, r2, |_, d2| acc += d2);
            }
            acc
        })
    });
    g.bench_function(id("kiddo_immutable"), |b| {
        b.iter(|| {
            let mut acc = 0.0f32;
            for q in &d.queries {
                for n in imm.within_unsorted::<SquaredEuclidean>(&q.to_array(), r2) {
                    acc += n.distance;
                }
            }
            acc
        })
    });
    let few = &d.queries[..QUERIES / 20];
    g.throughput(Throughput::Elements(few.len() as u64));
    if let Some(mutable) = &mutable {
        g.bench_function(id("kiddo_mutable"), |b| {
            b.iter(|| {
                let mut acc = 0.0f32;
                for q in few {
                    for n in mutable.within_unsorted::<SquaredEuclidean>(&q.to_array(), r2) {
                        acc += n.distance;
                    }
                }
                acc
            })
        });
    }
    g.finish();
    black_box((items, ours, imm, mutable));
}

fn benches(c: &mut Criterion) {
    for n in sizes() {
        for name in ["caustic", "scene"] {
            let d = make(name, n);
            bench_build(c, &d);
            bench_queries(c, &d);
        }
    }
}

criterion_group!(kd_tree, benches);
criterion_main!(kd_tree);
