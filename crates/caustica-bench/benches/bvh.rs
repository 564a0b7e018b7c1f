//! BVH build time and single-thread ray throughput on triangle meshes and on analytic shapes,
//! against the `obvhs` crate.
//!
//! `cargo bench --bench bvh` runs criterion (rays/s as throughput).
//! `BVH_BENCH_QUICK=1 cargo bench --bench bvh` skips criterion and prints a table of the best
//! of a few timed batches per case (about a minute in all).

use std::hint::black_box;
use std::time::{Duration, Instant};

use caustica::accel::bvh::{Bvh, TriangleBvh};
use caustica::geometry::cone::Cone;
use caustica::geometry::triangle::{Triangle, TriangleRay};
use caustica::geometry::{Shape, ShapeKind};
use caustica::math::{Aabb, Mat4, Quat, Ray, Vec3};
use criterion::{BenchmarkId, Criterion, Throughput};

/// Rays per timed batch (`BVH_BENCH_RAYS` overrides).
fn ray_count() -> usize {
    std::env::var("BVH_BENCH_RAYS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1 << 18)
}

/// splitmix64: deterministic inputs without another dependency.
struct Rng(u64);

impl Rng {
    fn f(&mut self) -> f32 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        ((z ^ (z >> 31)) >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// A latitude–longitude sphere of `2 · rings · segments` triangles, radially displaced by
/// `bumps` (0 = smooth).
fn sphere(rings: usize, segments: usize, bumps: f32) -> Vec<Triangle> {
    let point = |i: usize, j: usize| {
        let theta = std::f32::consts::PI * i as f32 / rings as f32;
        let phi = std::f32::consts::TAU * (j % segments) as f32 / segments as f32;
        let r = 1.0
            + bumps
                * (0.08 * (9.0 * theta).sin() * (7.0 * phi).cos()
                    + 0.03 * (31.0 * theta + 17.0 * phi).sin()
                    + 0.01 * (97.0 * theta).cos() * (83.0 * phi).sin());
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()) * r
    };
    let mut tris = Vec::with_capacity(2 * rings * segments);
    for i in 0..rings {
        for j in 0..segments {
            tris.push(Triangle::new(point(i, j), point(i + 1, j), point(i + 1, j + 1)));
            tris.push(Triangle::new(point(i, j), point(i + 1, j + 1), point(i, j + 1)));
        }
    }
    tris
}

fn mesh_bounds(tris: &[Triangle]) -> Aabb {
    tris.iter().fold(Aabb::EMPTY, |b, t| b.union(t.bounds()))
}

/// Pinhole camera framing the mesh, rays in scanline order.
fn primary_rays(bounds: Aabb, n: usize) -> Vec<Ray> {
    let side = (n as f32).sqrt() as usize;
    let center = bounds.center();
    let radius = bounds.extent().length() * 0.5;
    let eye = center + Vec3::new(0.4, 0.5, 1.0).normalize() * radius * 2.6;
    let forward = (center - eye).normalize();
    let right = forward.cross(Vec3::Y).normalize();
    let up = right.cross(forward);
    let half = (22.5f32).to_radians().tan();
    let mut rays = Vec::with_capacity(side * side);
    for y in 0..side {
        for x in 0..side {
            let sx = (2.0 * (x as f32 + 0.5) / side as f32 - 1.0) * half;
            let sy = (1.0 - 2.0 * (y as f32 + 0.5) / side as f32) * half;
            rays.push(Ray::new(eye, forward + right * sx + up * sy));
        }
    }
    rays
}

/// Origins uniform in the mesh bounds, directions uniform on the sphere.
fn incoherent_rays(bounds: Aabb, n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let o = bounds.min + bounds.extent() * Vec3::new(rng.f(), rng.f(), rng.f());
            let z = 2.0 * rng.f() - 1.0;
            let phi = std::f32::consts::TAU * rng.f();
            let s = (1.0 - z * z).max(0.0).sqrt();
            Ray::new(o, Vec3::new(s * phi.cos(), s * phi.sin(), z))
        })
        .collect()
}

/// Secondary rays as a path tracer casts them: from a point on a random triangle (uniform by
/// index, then uniform on the triangle), cosine-distributed about the normal, reflected or
/// transmitted with equal odds; the origin sits 1e-4 off the surface on the ray's side.
fn bounce_rays(tris: &[Triangle], n: usize, seed: u64) -> Vec<Ray> {
    let mut rng = Rng(seed);
    (0..n)
        .map(|_| {
            let tri = &tris[((rng.f() * tris.len() as f32) as usize).min(tris.len() - 1)];
            let (mut u, mut v) = (rng.f(), rng.f());
            if u + v > 1.0 {
                (u, v) = (1.0 - u, 1.0 - v);
            }
            let [a, b, c] = tri.vertices();
            let side = if rng.f() < 0.5 { 1.0 } else { -1.0 };
            let normal = (b - a).cross(c - a).normalize() * side;
            let tangent = normal.any_orthonormal_vector();
            let bitangent = normal.cross(tangent);
            let (r, phi) = (rng.f().sqrt(), std::f32::consts::TAU * rng.f());
            let local = Vec3::new(r * phi.cos(), r * phi.sin(), (1.0 - r * r).max(0.0).sqrt());
            let dir = tangent * local.x + bitangent * local.y + normal * local.z;
            Ray::new(a + (b - a) * u + (c - a) * v + normal * 1e-4, dir)
        })
        .collect()
}

/// Everything built for one mesh.
struct Scene {
    name: &'static str,
    tris: Vec<Triangle>,
    bvh: Bvh,
    tri_bvh: TriangleBvh,
    ob: obvhs::cwbvh::CwBvh,
    ob_tris: Vec<obvhs::triangle::Triangle>,
    /// `ob_tris` in the comparison BVH's leaf order (its fast layout).
    ob_tris_ordered: Vec<obvhs::triangle::Triangle>,
}

fn to_ob(t: &Triangle) -> obvhs::triangle::Triangle {
    let [a, b, c] = t.vertices();
    obvhs::triangle::Triangle {
        v0: a.to_array().into(),
        v1: b.to_array().into(),
        v2: c.to_array().into(),
    }
}

fn to_ob_ray(r: &Ray) -> obvhs::ray::Ray {
    obvhs::ray::Ray::new_inf(r.origin.to_array().into(), r.dir.to_array().into())
}

fn build_ob(tris: &[obvhs::triangle::Triangle]) -> obvhs::cwbvh::CwBvh {
    obvhs::cwbvh::builder::build_cwbvh_from_tris(tris, obvhs::BvhBuildParams::medium_build(), &mut Duration::default())
}

impl Scene {
    fn new(name: &'static str, tris: Vec<Triangle>) -> Scene {
        let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
        let bvh = Bvh::build(&bounds);
        let tri_bvh = TriangleBvh::new(&tris);
        let ob_tris: Vec<_> = tris.iter().map(to_ob).collect();
        let ob = build_ob(&ob_tris);
        let ob_tris_ordered = ob.primitive_indices.iter().map(|&i| ob_tris[i as usize]).collect();
        Scene {
            name,
            tris,
            bvh,
            tri_bvh,
            ob,
            ob_tris,
            ob_tris_ordered,
        }
    }
}

/// Analytic shapes as `.ray` scenes place them: spheres, boxes, capped cylinders, cones and
/// squares in equal numbers, each rotated at random, scaled by 0.3–1.3 per axis and scattered
/// through a cube sized for about one shape per 8 unit cubes. Texture coordinates are off (the
/// scene of untextured materials).
struct ShapeScene {
    name: &'static str,
    shapes: Vec<Shape>,
    bvh: Bvh,
    ob: obvhs::cwbvh::CwBvh,
}

impl ShapeScene {
    fn new(name: &'static str, count: usize) -> ShapeScene {
        let mut rng = Rng(0xa11c_e5ed);
        let side = (8.0 * count as f32).cbrt();
        let shapes: Vec<Shape> = (0..count)
            .map(|i| {
                let kind = match i % 5 {
                    0 => ShapeKind::Sphere,
                    1 => ShapeKind::Box,
                    2 => ShapeKind::cylinder(true),
                    3 => ShapeKind::Cone(Cone::new(1.0, 0.5, 0.1, true, false)),
                    _ => ShapeKind::Square,
                };
                let axis = Vec3::new(rng.f() - 0.5, rng.f() - 0.5, rng.f() - 0.5).normalize_or(Vec3::Z);
                let rotation = Quat::from_axis_angle(axis, std::f32::consts::TAU * rng.f());
                let scale = Vec3::new(rng.f(), rng.f(), rng.f()) + Vec3::splat(0.3);
                let at = Vec3::new(rng.f(), rng.f(), rng.f()) * side;
                let mut shape = Shape::new(kind, Mat4::from_scale_rotation_translation(scale, rotation, at))
                    .expect("an invertible transform");
                shape.needs_uv = false;
                shape
            })
            .collect();
        let bounds: Vec<Aabb> = shapes.iter().map(|s| s.bounds).collect();
        let bvh = Bvh::build(&bounds);
        let ob_bounds: Vec<obvhs::aabb::Aabb> = bounds
            .iter()
            .map(|b| obvhs::aabb::Aabb::new(b.min.to_array().into(), b.max.to_array().into()))
            .collect();
        let ob = obvhs::cwbvh::builder::build_cwbvh(
            &ob_bounds,
            obvhs::BvhBuildParams::medium_build(),
            &mut Duration::default(),
        );
        ShapeScene { name, shapes, bvh, ob }
    }

    fn bounds(&self) -> Aabb {
        self.bvh.bounds()
    }
}

/// Hits and the sum of their distances, from each ray's closest-hit distance.
fn sum_closest(rays: &[Ray], mut closest: impl FnMut(&Ray) -> Option<f32>) -> (usize, f64) {
    rays.iter().fold((0, 0.0), |acc, ray| match black_box(closest(ray)) {
        Some(t) => (acc.0 + 1, acc.1 + t as f64),
        None => acc,
    })
}

/// The number of rays `blocked` says are occluded (and no distance sum).
fn count_occluded(rays: &[Ray], mut blocked: impl FnMut(&Ray) -> bool) -> (usize, f64) {
    (rays.iter().filter(|ray| black_box(blocked(ray))).count(), 0.0)
}

/// The closest-hit distance of `ray` in the comparison BVH, whose closure gets its ray and a
/// primitive's leaf position and returns the hit distance (infinity for a miss).
fn obvhs_closest(
    ob: &obvhs::cwbvh::CwBvh,
    ray: &Ray,
    hit_t: impl FnMut(&obvhs::ray::Ray, usize) -> f32,
) -> Option<f32> {
    let mut hit = obvhs::ray::RayHit::none();
    ob.ray_traverse(to_ob_ray(ray), &mut hit, hit_t).then_some(hit.t)
}

/// [`sum_closest`] over the generic BVH, `hit(prim, ray, t_max)` testing one primitive.
fn bvh_closest(bvh: &Bvh, rays: &[Ray], hit: impl Fn(u32, &Ray, f32) -> Option<f32>) -> (usize, f64) {
    sum_closest(rays, |ray| {
        bvh.closest_hit(ray, f32::INFINITY, |p, t| hit(p, ray, t))
            .map(|(t, _)| t)
    })
}

fn shapes_closest(s: &ShapeScene, rays: &[Ray]) -> (usize, f64) {
    bvh_closest(&s.bvh, rays, |p, ray, t| {
        s.shapes[p as usize].intersect(ray, t).map(|h| h.t)
    })
}

fn shapes_any(s: &ShapeScene, rays: &[Ray]) -> (usize, f64) {
    count_occluded(rays, |ray| {
        s.bvh.any_hit(ray, f32::INFINITY, |p, t| {
            s.shapes[p as usize].intersect(ray, t).is_some()
        })
    })
}

/// The comparison BVH with the same shape tests.
fn shapes_obvhs(s: &ShapeScene, rays: &[Ray]) -> (usize, f64) {
    let idx = &s.ob.primitive_indices;
    sum_closest(rays, |ray| {
        obvhs_closest(&s.ob, ray, |r, id| {
            s.shapes[idx[id] as usize]
                .intersect(ray, r.tmax)
                .map_or(f32::INFINITY, |h| h.t)
        })
    })
}

const SHAPE_TRACERS: [(&str, Tracer<ShapeScene>); 3] = [
    ("Bvh", shapes_closest),
    ("Bvh-any", shapes_any),
    ("obvhs", shapes_obvhs),
];

/// The shape scenes whose name matches `filter` (or all).
fn shape_scenes(filter: &str) -> Vec<ShapeScene> {
    [("shapes-100", 100), ("shapes-10k", 10_000)]
        .into_iter()
        .filter(|(name, _)| {
            let wanted = filter.split('/').next().unwrap_or_default();
            name.contains(wanted) || !filter.contains("shapes")
        })
        .map(|(name, count)| ShapeScene::new(name, count))
        .collect()
}

fn shape_ray_sets(s: &ShapeScene) -> [(&'static str, Vec<Ray>); 2] {
    [
        ("primary", primary_rays(s.bounds(), ray_count())),
        ("incoherent", incoherent_rays(s.bounds(), ray_count(), 7)),
    ]
}

/// A traversal variant over scene type `S`: hits and the sum of hit distances (as a cross-check).
type Tracer<S> = fn(&S, &[Ray]) -> (usize, f64);

fn generic(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    bvh_closest(&s.bvh, rays, |p, ray, t| {
        s.tris[p as usize].intersect(ray, t).map(|h| h.t)
    })
}

fn generic_pre(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    sum_closest(rays, |ray| {
        let tr = TriangleRay::new(ray);
        s.bvh
            .closest_hit(ray, f32::INFINITY, |p, t| {
                s.tris[p as usize].intersect_pre(&tr, t).map(|h| h.t)
            })
            .map(|(t, _)| t)
    })
}

fn triangle_bvh(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    sum_closest(rays, |ray| s.tri_bvh.closest_hit(ray, f32::INFINITY).map(|h| h.t))
}

fn triangle_bvh_stream(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    let mut hits = vec![None; rays.len()];
    s.tri_bvh.closest_hits(rays, f32::INFINITY, &mut hits);
    black_box(&hits)
        .iter()
        .flatten()
        .fold((0, 0.0), |acc, h| (acc.0 + 1, acc.1 + h.t as f64))
}

fn triangle_bvh_any_stream(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    let mut occluded = vec![false; rays.len()];
    s.tri_bvh.any_hits(rays, f32::INFINITY, &mut occluded);
    (black_box(&occluded).iter().filter(|&&o| o).count(), 0.0)
}

fn triangle_bvh_any(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    count_occluded(rays, |ray| s.tri_bvh.any_hit(ray, f32::INFINITY))
}

fn shadow(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    count_occluded(rays, |ray| {
        let tr = TriangleRay::new(ray);
        s.bvh.any_hit(ray, f32::INFINITY, |p, t| {
            s.tris[p as usize].intersect_pre(&tr, t).is_some()
        })
    })
}

fn obvhs_indexed(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    let idx = &s.ob.primitive_indices;
    sum_closest(rays, |ray| {
        obvhs_closest(&s.ob, ray, |r, id| s.ob_tris[idx[id] as usize].intersect(r))
    })
}

fn obvhs_ordered(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    sum_closest(rays, |ray| {
        obvhs_closest(&s.ob, ray, |r, id| s.ob_tris_ordered[id].intersect(r))
    })
}

/// The comparison BVH with our (watertight) triangle test, to separate BVH from triangle cost.
fn obvhs_our_triangle(s: &Scene, rays: &[Ray]) -> (usize, f64) {
    let idx = &s.ob.primitive_indices;
    sum_closest(rays, |ray| {
        let tr = TriangleRay::new(ray);
        obvhs_closest(&s.ob, ray, |r, id| {
            s.tris[idx[id] as usize]
                .intersect_pre(&tr, r.tmax)
                .map_or(f32::INFINITY, |h| h.t)
        })
    })
}

const TRACERS: [(&str, Tracer<Scene>); 10] = [
    ("closure", generic),
    ("closure+pre", generic_pre),
    ("TriangleBvh", triangle_bvh),
    ("TriangleBvh-stream", triangle_bvh_stream),
    ("TriangleBvh-any", triangle_bvh_any),
    ("TriangleBvh-any-stream", triangle_bvh_any_stream),
    ("any_hit", shadow),
    ("obvhs", obvhs_indexed),
    ("obvhs-ordered", obvhs_ordered),
    ("obvhs+our-tri", obvhs_our_triangle),
];

/// The meshes whose name matches `filter` (or all).
fn scenes(filter: &str) -> Vec<Scene> {
    let mut out = Vec::new();
    if filter.contains("shapes") {
        return out;
    }
    if filter.is_empty() || filter.contains("1M") || !filter.contains("37k") {
        // 2 · 500 · 1000 = 1,000,000 triangles.
        out.push(Scene::new("bumpy-1M", sphere(500, 1000, 1.0)));
    }
    if filter.is_empty() || filter.contains("37k") || !filter.contains("1M") {
        // 2 · 96 · 192 = 36,864 triangles (the Embree comparison case).
        out.push(Scene::new("sphere-37k", sphere(96, 192, 0.0)));
    }
    out
}

fn ray_sets(s: &Scene) -> [(&'static str, Vec<Ray>); 3] {
    let b = mesh_bounds(&s.tris);
    let sets = [
        ("primary", primary_rays(b, ray_count())),
        ("incoherent", incoherent_rays(b, ray_count(), 7)),
        ("bounce", bounce_rays(&s.tris, ray_count(), 11)),
    ];
    if let Some(dir) = std::env::var_os("BVH_BENCH_DUMP") {
        for (kind, rays) in &sets {
            dump_rays(
                &std::path::Path::new(&dir).join(format!("{}-{kind}.rays", s.name)),
                rays,
            );
        }
    }
    sets
}

/// Writes rays as little-endian f32 (origin xyz, direction xyz), for the Embree harness
/// (`scripts/embree/compare.sh`), so both programs trace exactly the same rays.
fn dump_rays(path: &std::path::Path, rays: &[Ray]) {
    let bytes: Vec<u8> = rays
        .iter()
        .flat_map(|r| [r.origin.to_array(), r.dir.to_array()])
        .flatten()
        .flat_map(f32::to_le_bytes)
        .collect();
    std::fs::write(path, bytes).expect("writing the ray dump");
}

/// CPU time of this thread (Linux schedstat, ns), so numbers survive a machine shared with
/// other jobs; `None` elsewhere.
fn thread_cpu_time() -> Option<Duration> {
    let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    Some(Duration::from_nanos(s.split_whitespace().next()?.parse().ok()?))
}

/// Best wall time and best CPU time of `runs` runs.
fn best_of<T>(runs: usize, mut f: impl FnMut() -> T) -> (Duration, Duration, T) {
    let (mut wall, mut cpu) = (Duration::MAX, Duration::MAX);
    let mut out = None;
    for _ in 0..runs {
        let (start, start_cpu) = (Instant::now(), thread_cpu_time());
        let r = f();
        wall = wall.min(start.elapsed());
        if let (Some(a), Some(b)) = (start_cpu, thread_cpu_time()) {
            cpu = cpu.min(b - a);
        }
        out = Some(r);
    }
    (wall, cpu, out.expect("at least one run"))
}

fn quick() {
    let filter = std::env::var("BVH_BENCH_FILTER").unwrap_or_default();
    let runs = std::env::var("BVH_BENCH_RUNS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(5);
    if filter.is_empty() || filter.contains("build") {
        let tris = sphere(500, 1000, 1.0);
        let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
        let (t, _, bvh) = best_of(3, || Bvh::build(&bounds));
        println!(
            "build 1M: {:>7.1} ms  ({} threads; {} nodes, depth {})",
            t.as_secs_f64() * 1e3,
            rayon::current_num_threads(),
            bvh.node_count(),
            bvh.depth()
        );
        let (t, _, _) = best_of(3, || TriangleBvh::new(&tris));
        println!("build 1M TriangleBvh: {:>7.1} ms", t.as_secs_f64() * 1e3);
        let ob_tris: Vec<_> = tris.iter().map(to_ob).collect();
        let (t, _, _) = best_of(3, || build_ob(&ob_tris));
        println!("build 1M obvhs (medium_build): {:>7.1} ms", t.as_secs_f64() * 1e3);
    }

    println!("\nMrays/s, best of {runs}: by wall time, and by this thread's CPU time (robust to load)");
    println!("| mesh | rays | variant | Mrays/s wall | Mrays/s cpu | hits | mean t |\n|---|---|---|---|---|---|---|");
    for s in scenes(&filter) {
        eprintln!("{}: {} nodes, depth {}", s.name, s.bvh.node_count(), s.bvh.depth());
        print_rates(s.name, &s, &ray_sets(&s), &TRACERS, &filter, runs);
    }
    for s in shape_scenes(&filter) {
        eprintln!("{}: {} nodes, depth {}", s.name, s.bvh.node_count(), s.bvh.depth());
        print_rates(s.name, &s, &shape_ray_sets(&s), &SHAPE_TRACERS, &filter, runs);
    }
}

/// One table row per ray set and variant whose label `scene/rays/variant` matches `filter`.
fn print_rates<S>(
    scene_name: &str,
    scene: &S,
    ray_sets: &[(&str, Vec<Ray>)],
    tracers: &[(&str, Tracer<S>)],
    filter: &str,
    runs: usize,
) {
    for (kind, rays) in ray_sets {
        for (name, f) in tracers {
            let label = format!("{scene_name}/{kind}/{name}");
            if !label.contains(filter) && !filter.is_empty() {
                continue;
            }
            let (wall, cpu, (hits, sum)) = best_of(runs, || f(scene, rays));
            let rate = |d: Duration| rays.len() as f64 / d.as_secs_f64() / 1e6;
            println!(
                "| {scene_name} | {kind} | {name} | {:.2} | {:.2} | {hits} | {:.4} |",
                rate(wall),
                rate(cpu),
                sum / hits.max(1) as f64
            );
        }
    }
}

/// A criterion group per ray set, with every variant.
fn bench_rates<S>(
    c: &mut Criterion,
    scene_name: &str,
    scene: &S,
    ray_sets: &[(&str, Vec<Ray>)],
    tracers: &[(&str, Tracer<S>)],
) {
    for (kind, rays) in ray_sets {
        let mut g = c.benchmark_group(format!("{scene_name}/{kind}"));
        g.throughput(Throughput::Elements(rays.len() as u64));
        for (name, f) in tracers {
            g.bench_with_input(BenchmarkId::from_parameter(name), rays, |b, rays| {
                b.iter(|| f(scene, rays))
            });
        }
        g.finish();
    }
}

fn main() {
    if std::env::var_os("BVH_BENCH_QUICK").is_some() {
        quick();
        return;
    }
    let mut c = Criterion::default()
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4))
        .configure_from_args();

    let tris = sphere(500, 1000, 1.0);
    let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
    let ob_tris: Vec<_> = tris.iter().map(to_ob).collect();
    let mut g = c.benchmark_group("build-1M");
    g.throughput(Throughput::Elements(tris.len() as u64));
    g.bench_function("Bvh::build", |b| b.iter(|| Bvh::build(black_box(&bounds))));
    g.bench_function("obvhs-medium", |b| b.iter(|| build_ob(black_box(&ob_tris))));
    g.finish();
    drop((tris, bounds, ob_tris));

    for s in scenes("") {
        bench_rates(&mut c, s.name, &s, &ray_sets(&s), &TRACERS);
    }
    for s in shape_scenes("") {
        bench_rates(&mut c, s.name, &s, &shape_ray_sets(&s), &SHAPE_TRACERS);
    }
    c.final_summary();
}
