use std::collections::HashSet;

use super::*;
use crate::accel::lanes::Width;
use crate::geometry::triangle::Triangle;

/// xorshift64*: deterministic and dependency-free.
struct Rng(u64);

impl Rng {
    fn f(&mut self) -> f32 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 40) as f32 / (1u64 << 24) as f32
    }
    fn v(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
    fn dir(&mut self) -> Vec3 {
        // Non-unit lengths, and sometimes exactly axis-aligned or with zero components.
        let mut d = (self.v() - 0.5) * (0.1 + 3.0 * self.f());
        match (self.f() * 8.0) as u32 {
            0 => d.x = 0.0,
            1 => {
                d.y = 0.0;
                d.z = 0.0;
            }
            2 => d.z = -0.0,
            _ => {}
        }
        d
    }
}

/// Random triangles of mixed sizes, with degenerate ones (points, lines, axis-aligned flats,
/// duplicates) mixed in.
fn random_triangles(rng: &mut Rng, n: usize) -> Vec<Triangle> {
    let mut tris = Vec::with_capacity(n);
    while tris.len() < n {
        let p = rng.v() * 10.0;
        let s = if rng.f() < 0.1 { 4.0 } else { 0.6 };
        let t = match tris.len() % 13 {
            0 => Triangle::new(p, p, p),
            1 => Triangle::new(p, p + Vec3::X * s, p + Vec3::X * 2.0 * s),
            2 => Triangle::new(p, p + Vec3::X * s, p + Vec3::Y * s),
            3 if !tris.is_empty() => tris[tris.len() - 1],
            _ => Triangle::new(p, p + (rng.v() - 0.5) * s, p + (rng.v() - 0.5) * s),
        };
        tris.push(t);
    }
    tris
}

fn brute_closest(tris: &[Triangle], ray: &Ray, t_max: f32) -> Option<(f32, u32)> {
    let mut best = None;
    let mut t_max = t_max;
    for (i, tri) in tris.iter().enumerate() {
        if let Some(h) = tri.intersect(ray, t_max) {
            t_max = h.t;
            best = Some((h.t, i as u32));
        }
    }
    best
}

/// Equal, or a near-tie between different primitives (traversal order may pick either).
fn same_hit(tris: &[Triangle], ray: &Ray, a: Option<(f32, u32)>, b: Option<(f32, u32)>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some((ta, pa)), Some((tb, pb))) => {
            pa == pb && ta == tb
                || ((ta - tb).abs() <= 1e-5 * ta.abs().max(1.0)
                    && tris[pa as usize]
                        .intersect(ray, f32::INFINITY)
                        .is_some_and(|h| h.t == ta))
        }
        _ => false,
    }
}

/// Half the rays are aimed at a random point of a random triangle, so hits are common.
fn random_ray(rng: &mut Rng, tris: &[Triangle]) -> Ray {
    let origin = rng.v() * 14.0 - 2.0;
    if rng.f() < 0.5 {
        let tri = tris[(rng.f() * tris.len() as f32) as usize % tris.len()];
        let (u, v) = (rng.f(), rng.f());
        let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
        Ray::new(origin, (tri.point(u, v) - origin) * (0.2 + rng.f()))
    } else {
        Ray::new(origin, rng.dir())
    }
}

fn check_against_brute_force(tris: &[Triangle], rng: &mut Rng, rays: usize, width: Width) {
    let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
    let bvh = Bvh::build(&bounds);
    let tbvh = TriangleBvh::new(tris).with_width(width);
    let mut hits = 0;
    for _ in 0..rays {
        let ray = random_ray(rng, tris);
        let t_max = if rng.f() < 0.3 {
            1.0 + rng.f() * 5.0
        } else {
            f32::INFINITY
        };
        let expect = brute_closest(tris, &ray, t_max);
        let got = bvh.closest_hit(&ray, t_max, |p, t| tris[p as usize].intersect(&ray, t).map(|h| h.t));
        assert!(
            same_hit(tris, &ray, got, expect),
            "closest {ray:?} t_max {t_max}: {got:?} vs {expect:?}"
        );
        let fast = tbvh.closest_hit(&ray, t_max).map(|h| (h.t, h.prim));
        assert!(
            same_hit(tris, &ray, fast, expect),
            "triangle bvh {ray:?}: {fast:?} vs {expect:?}"
        );
        if let Some(h) = tbvh.closest_hit(&ray, t_max) {
            let e = tris[h.prim as usize].intersect(&ray, f32::INFINITY).unwrap();
            assert_eq!((h.u, h.v), (e.u, e.v));
        }
        hits += usize::from(expect.is_some());

        let mut seen = HashSet::new();
        let occluded = bvh.any_hit(&ray, t_max, |p, t| {
            assert!(seen.insert(p), "primitive {p} visited twice");
            assert_eq!(t, t_max);
            tris[p as usize].intersect(&ray, t).is_some()
        });
        assert_eq!(occluded, expect.is_some(), "any_hit {ray:?}");
        assert_eq!(tbvh.any_hit(&ray, t_max), expect.is_some(), "triangle any_hit {ray:?}");
        // Every triangle the segment meets is visited once, with the scalar test's hit.
        let mut visited = Vec::new();
        assert!(!tbvh.each_hit(&ray, t_max, |h| {
            visited.push((h.prim, h.t));
            false
        }));
        visited.sort_by_key(|&(p, _)| p);
        let all: Vec<(u32, f32)> = tris
            .iter()
            .enumerate()
            .filter_map(|(i, t)| t.intersect(&ray, t_max).map(|h| (i as u32, h.t)))
            .collect();
        assert_eq!(visited, all, "each_hit {ray:?}");
    }
    assert!(
        tris.len() < 3 || hits > rays / 10,
        "too few hits ({hits}) for a meaningful test"
    );
}

#[test]
fn closest_and_any_hit_match_brute_force() {
    let mut rng = Rng(0x1234_5678_9abc_def1);
    for n in [1, 2, 3, 5, 9, 40, 300, 3000] {
        let tris = random_triangles(&mut rng, n);
        for width in Width::on_host() {
            check_against_brute_force(&tris, &mut rng, if n < 100 { 500 } else { 3000 }, width);
        }
    }
}

#[test]
fn all_identical_boxes() {
    let mut rng = Rng(7);
    let t = Triangle::new(
        Vec3::new(1.0, 1.0, 1.0),
        Vec3::new(9.0, 2.0, 3.0),
        Vec3::new(4.0, 9.0, 8.0),
    );
    let tris = vec![t; 1000];
    for width in Width::on_host() {
        check_against_brute_force(&tris, &mut rng, 2000, width);
    }
    let bvh = Bvh::build(&vec![t.bounds(); 1000]);
    assert!(bvh.depth() <= 12, "depth {}", bvh.depth());
}

/// 300 parallel triangles at exponentially growing spacing: SAH peels them one at a time, so
/// the tree is as deep as the depth cap allows.
fn exponential_steps() -> Vec<Triangle> {
    (0..300)
        .map(|i| {
            let x = 1.07f32.powi(i) - 1.0;
            Triangle::new(Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0), Vec3::new(x, 0.0, 1.0))
        })
        .collect()
}

/// Exponentially spaced primitives make SAH peel one at a time; the depth cap must keep the
/// traversal stack bounded.
#[test]
fn pathological_depth_is_capped() {
    let mut rng = Rng(99);
    let tris = exponential_steps();
    let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
    let bvh = Bvh::build(&bounds);
    assert!(bvh.depth() < 80, "depth {}", bvh.depth());
    // The eight-wide triangle tree's walk must fit its stack too.
    let tbvh = TriangleBvh::new(&tris);
    assert!(tbvh.bvh.stack_fits(LARGE_STACK), "depth {}", tbvh.depth());
    for _ in 0..2000 {
        let o = Vec3::new(-1.0, rng.f(), rng.f());
        let ray = Ray::new(o, Vec3::new(1.0, (rng.f() - 0.5) * 0.01, (rng.f() - 0.5) * 0.01));
        let expect = brute_closest(&tris, &ray, f32::INFINITY);
        let got = bvh.closest_hit(&ray, f32::INFINITY, |p, t| {
            tris[p as usize].intersect(&ray, t).map(|h| h.t)
        });
        assert!(same_hit(&tris, &ray, got, expect), "{got:?} vs {expect:?}");
        let fast = tbvh.closest_hit(&ray, f32::INFINITY).map(|h| (h.t, h.prim));
        assert!(
            same_hit(&tris, &ray, fast, expect),
            "triangle bvh {fast:?} vs {expect:?}"
        );
    }
}

#[test]
fn empty_and_single() {
    let ray = Ray::new(Vec3::ZERO, Vec3::X);
    let empty = Bvh::build(&[]);
    assert_eq!(empty.node_count(), 0);
    assert!(empty.bounds().is_empty());
    assert_eq!(
        empty.closest_hit(&ray, f32::INFINITY, |_, _| panic!("no primitives")),
        None
    );
    assert!(!empty.any_hit(&ray, f32::INFINITY, |_, _| panic!("no primitives")));
    assert!(TriangleBvh::new(&[]).closest_hit(&ray, 1.0).is_none());

    let b = Aabb::new(Vec3::new(2.0, -1.0, -1.0), Vec3::new(3.0, 1.0, 1.0));
    let one = Bvh::build(&[b]);
    assert_eq!(one.node_count(), 1);
    assert_eq!(one.bounds(), b);
    assert_eq!(
        one.closest_hit(&ray, f32::INFINITY, |p, _| Some(2.5 + p as f32)),
        Some((2.5, 0))
    );
    assert_eq!(one.closest_hit(&ray, 1.5, |_, _| panic!("box is beyond t_max")), None);
    assert!(one.any_hit(&ray, 10.0, |p, _| p == 0));
    let back = Ray::new(Vec3::ZERO, -Vec3::X);
    assert!(!one.any_hit(&back, f32::INFINITY, |_, _| panic!("box is behind the ray")));
}

#[test]
fn non_finite_bounds_are_skipped() {
    let good = Aabb::new(Vec3::splat(-1.0), Vec3::splat(1.0));
    let nan = Aabb {
        min: Vec3::splat(f32::NAN),
        max: Vec3::ONE,
    };
    let inf = Aabb {
        min: Vec3::splat(f32::NEG_INFINITY),
        max: Vec3::splat(f32::INFINITY),
    };
    let bounds = [
        nan,
        good,
        inf,
        Aabb::EMPTY,
        good,
        Aabb {
            min: Vec3::ONE,
            max: -Vec3::ONE,
        },
    ];
    let bvh = Bvh::build(&bounds);
    assert_eq!(bvh.bounds(), good);
    let mut seen = Vec::new();
    let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
    assert!(!bvh.any_hit(&ray, f32::INFINITY, |p, _| {
        seen.push(p);
        false
    }));
    seen.sort();
    assert_eq!(seen, [1, 4]);
    let only_bad = Bvh::build(&[nan, inf, Aabb::EMPTY]);
    assert_eq!(only_bad.node_count(), 0);
    assert!(only_bad.bounds().is_empty());
}

#[test]
fn odd_rays_do_not_panic_or_hang() {
    let mut rng = Rng(3);
    let tris = random_triangles(&mut rng, 500);
    let tbvh = TriangleBvh::new(&tris);
    let nasty = [0.0, -0.0, f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 1e-40, 1e30, 5.0];
    for &o in &nasty {
        for &d in &nasty {
            for ray in [
                Ray::new(Vec3::new(o, 5.0, 5.0), Vec3::new(d, 0.0, 1.0)),
                Ray::new(Vec3::splat(o), Vec3::splat(d)),
            ] {
                for t_max in [f32::INFINITY, f32::NAN, -1.0, 0.0, 10.0] {
                    let _ = tbvh.closest_hit(&ray, t_max);
                    let _ = tbvh.any_hit(&ray, t_max);
                }
            }
        }
    }
    // Zero direction: nothing is hit.
    assert!(tbvh
        .closest_hit(&Ray::new(Vec3::splat(5.0), Vec3::ZERO), f32::INFINITY)
        .is_none());
}

/// A ray grazing the face of a flat (zero-thickness) box must still find the box.
#[test]
fn flat_boxes_are_hit() {
    let tri = Triangle::new(
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(1.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 1.0),
    );
    let bvh = Bvh::build(&[tri.bounds()]);
    let mut rng = Rng(5);
    for _ in 0..1000 {
        let target = tri.point(rng.f() * 0.5, rng.f() * 0.5);
        let o = target + Vec3::new(rng.f() - 0.5, rng.f() - 0.5, 1.0) * (1.0 + 10.0 * rng.f());
        let ray = Ray::new(o, target - o);
        assert!(
            bvh.closest_hit(&ray, f32::INFINITY, |_, t| tri.intersect(&ray, t).map(|h| h.t))
                .is_some(),
            "{ray:?}"
        );
    }
}

#[test]
fn closed_mesh_does_not_leak() {
    let tris = sphere(40, 80);
    let tbvh = TriangleBvh::new(&tris);
    let mut rng = Rng(11);
    for _ in 0..20_000 {
        let ray = Ray::new((rng.v() - 0.5) * 0.5, rng.dir());
        if ray.dir == Vec3::ZERO {
            continue;
        }
        assert!(tbvh.closest_hit(&ray, f32::INFINITY).is_some(), "escaped: {ray:?}");
    }
}

fn sphere(rings: usize, segments: usize) -> Vec<Triangle> {
    let p = |i: usize, j: usize| {
        let (theta, phi) = (
            std::f32::consts::PI * i as f32 / rings as f32,
            std::f32::consts::TAU * (j % segments) as f32 / segments as f32,
        );
        Vec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
    };
    let mut tris = Vec::new();
    for i in 0..rings {
        for j in 0..segments {
            tris.push(Triangle::new(p(i, j), p(i + 1, j), p(i + 1, j + 1)));
            tris.push(Triangle::new(p(i, j), p(i + 1, j + 1), p(i, j + 1)));
        }
    }
    tris
}

#[test]
fn node_layout() {
    // Two cache lines for four children, four for eight.
    assert_eq!(std::mem::size_of::<Node<1>>(), 128);
    assert_eq!(std::mem::size_of::<Node<2>>(), 256);
    assert_eq!(std::mem::align_of::<Node<2>>(), 64);
}

fn snapshot(bvh: &Bvh) -> (Vec<u32>, Vec<u32>, u32) {
    let bits = bvh
        .nodes
        .iter()
        .flat_map(|n| {
            n.bounds
                .iter()
                .flatten()
                .flatten()
                .flat_map(|v| v.to_array())
                .map(f32::to_bits)
                .chain(n.children.into_iter().flatten())
        })
        .collect();
    (bits, bvh.order.clone(), bvh.depth)
}

#[test]
fn build_is_deterministic_across_thread_counts() {
    let mut rng = Rng(42);
    // Large enough for parallel subtrees and parallel binning.
    let bounds: Vec<Aabb> = (0..200_000)
        .map(|_| {
            let p = rng.v() * 100.0;
            Aabb::new(p, p + rng.v())
        })
        .collect();
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| snapshot(&Bvh::build(&bounds)))
    };
    let one = run(1);
    assert_eq!(one, run(3));
    assert_eq!(one, run(2));
    // Every primitive appears exactly once in the leaf order.
    let mut ids: Vec<u32> = one.1.iter().map(|p| p & !END).collect();
    ids.sort_unstable();
    assert!(ids.iter().copied().eq(0..200_000));
}

#[test]
fn bounds_contain_children() {
    let mut rng = Rng(8);
    let tris = random_triangles(&mut rng, 5000);
    let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
    let bvh = Bvh::build(&bounds);
    // Walk the tree: each leaf's primitives lie inside the leaf box.
    let mut stack = vec![0u32];
    let mut leaves = 0;
    while let Some(n) = stack.pop() {
        let node = &bvh.nodes[n as usize];
        for slot in 0..Node::<1>::WIDTH {
            let (lo, hi) = node.child_box(slot);
            if lo.x > hi.x {
                continue;
            }
            let c = node.child(slot);
            if c & LEAF == 0 {
                stack.push(c);
                continue;
            }
            leaves += 1;
            let mut i = (c & !LEAF) as usize;
            loop {
                let b = bounds[(bvh.order[i] & !END) as usize];
                assert!(b.min.cmpge(lo).all() && b.max.cmple(hi).all());
                if bvh.order[i] & END != 0 {
                    break;
                }
                i += 1;
            }
        }
    }
    assert!(leaves > 5000 / build::LeafCost::SINGLE.max_leaf);
}

/// A cube of half-side up to 2 centred in [0, 10]³.
fn random_cube(rng: &mut Rng) -> Aabb {
    let c = rng.v() * 10.0;
    let h = Vec3::splat(rng.f() * 2.0);
    Aabb::new(c - h, c + h)
}

#[test]
fn triangle_overlap_query_finds_every_triangle_touching_the_box() {
    let mut rng = Rng(21);
    let tris = random_triangles(&mut rng, 2000);
    let tbvh = TriangleBvh::new(&tris);
    for _ in 0..200 {
        let query = random_cube(&mut rng);
        let mut found = HashSet::new();
        assert!(!tbvh.any_overlap(&query, |p| {
            assert!(found.insert(p), "visited twice");
            false
        }));
        for (i, t) in tris.iter().enumerate() {
            let [a, b, c] = t.vertices();
            let b_ = t.bounds();
            let hittable = a != b && b != c && c != a;
            if hittable && b_.min.cmple(query.max).all() && b_.max.cmpge(query.min).all() {
                assert!(found.contains(&(i as u32)), "triangle {i} missed");
            }
        }
    }
}

#[test]
fn box_overlap_query_matches_brute_force() {
    let mut rng = Rng(99);
    let tris = random_triangles(&mut rng, 3000);
    let bounds: Vec<Aabb> = tris.iter().map(|t| t.bounds()).collect();
    let bvh = Bvh::build(&bounds);
    for _ in 0..300 {
        let query = random_cube(&mut rng);
        let mut found = HashSet::new();
        let stopped = bvh.any_overlap(&query, |p| {
            assert!(found.insert(p), "visited twice");
            false
        });
        assert!(!stopped);
        let expected: HashSet<u32> = bounds
            .iter()
            .enumerate()
            .filter(|(_, b)| {
                b.min.is_finite()
                    && b.max.is_finite()
                    && b.min.cmple(b.max).all()
                    && b.min.cmple(query.max).all()
                    && b.max.cmpge(query.min).all()
            })
            .map(|(i, _)| i as u32)
            .collect();
        // Leaf boxes may be looser than one primitive's box: everything expected is found.
        assert!(expected.is_subset(&found));
        if let Some(&first) = expected.iter().next() {
            assert!(bvh.any_overlap(&query, |p| p == first));
        }
    }
}

/// Counts the units reported, as a progress bar would.
#[derive(Default)]
struct Count(std::sync::atomic::AtomicU64);

impl crate::progress::Progress for Count {
    fn start(&self, _: &str, _: u64) {}
    fn advance(&self, n: u64) {
        self.0.fetch_add(n, std::sync::atomic::Ordering::Relaxed);
    }
    fn finish(&self) {}
}

#[test]
fn build_reports_every_primitive_once() {
    let mut rng = Rng(11);
    // Large enough for parallel subtrees; the bad boxes are counted too.
    let mut bounds: Vec<Aabb> = random_triangles(&mut rng, 30_000)
        .iter()
        .map(Triangle::bounds)
        .collect();
    bounds.push(Aabb::EMPTY);
    for n in [0, 1, 7, 5000, bounds.len()] {
        let count = Count::default();
        let bvh = Bvh::build_reporting(&bounds[..n], &count);
        assert_eq!(count.0.into_inner(), n as u64, "{n} primitives");
        assert_eq!(snapshot(&bvh), snapshot(&Bvh::build(&bounds[..n])));
    }
}

/// The interleaved streams give each ray exactly its single-ray answers, whatever the tree's
/// stack tier, ray order and number of rays (fewer, as many as, or more than the stream's lanes),
/// loading ahead or not; and so do a few triangles tested a ray a lane (`closest_each`),
/// rays through a floor's shared edge and corners (edge functions of exactly zero) among them.
#[test]
fn stream_matches_single_rays() {
    let mut rng = Rng(0x5eed);
    let floor = vec![
        Triangle::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(4.0, 0.0, 4.0),
            Vec3::new(4.0, 0.0, 0.0),
        ),
        Triangle::new(
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(0.0, 0.0, 4.0),
            Vec3::new(4.0, 0.0, 4.0),
        ),
    ];
    let meshes = [
        Vec::new(),
        random_triangles(&mut rng, 1),
        floor.clone(),
        random_triangles(&mut rng, 5),
        random_triangles(&mut rng, 8),
        random_triangles(&mut rng, 40),
        random_triangles(&mut rng, 3000),
        sphere(40, 80),
        exponential_steps(),
    ];
    let nasty = [0.0, f32::NAN, f32::INFINITY, 1e-40, 5.0];
    for (tris, width, fetch_ahead) in meshes.iter().flat_map(|m| {
        Width::on_host()
            .into_iter()
            .flat_map(move |w| [false, true].map(|f| (m, w, f)))
    }) {
        let tbvh = TriangleBvh::new(tris).with_width(width).fetching_ahead(fetch_ahead);
        let mut rays: Vec<Ray> = (0..2000)
            .map(|i| match (i % 7, tris.is_empty()) {
                (0, _) | (_, true) => Ray::new(rng.v() * 4.0 - 1.0, rng.dir()),
                (1, _) => Ray::new(Vec3::new(-1.0, rng.f(), rng.f()), Vec3::new(1.0, 0.001, 0.002)),
                _ => random_ray(&mut rng, tris),
            })
            .collect();
        rays.extend(
            nasty
                .iter()
                .map(|&x| Ray::new(Vec3::new(x, 0.5, 0.5), Vec3::new(1.0, x, 0.0))),
        );
        // Down onto the floor's diagonal, its corners and its rim, from above and at a slant: for
        // `closest_each` only (a walk's box test may miss the rim of a flat tree that its
        // packets, tested without one, hit).
        let mut each_rays = rays.clone();
        each_rays.extend((0..=8).flat_map(|i| {
            let s = i as f32 * 0.5;
            [
                Ray::new(Vec3::new(s, 2.0, s), Vec3::new(0.0, -1.0, 0.0)),
                Ray::new(Vec3::new(s + 1.0, 2.0, s), Vec3::new(-0.5, -1.0, 0.0)),
                Ray::new(Vec3::new(s, 1.0, 0.0), Vec3::new(0.0, -1.0, 0.0)),
            ]
        }));
        // Directions with two or three largest components alike, where the axis a ray is
        // sheared along is decided by a tie.
        each_rays.extend((0..40).flat_map(|i| {
            let origin = Vec3::new(0.1 * i as f32, 2.0, 0.05 * i as f32 - 0.5);
            [(0.3, -1.0, 1.0), (1.0, -1.0, 1.0), (-1.0, -1.0, 0.3), (0.5, -1.0, -1.0)]
                .map(|(x, y, z)| Ray::new(origin, Vec3::new(x, y, z)))
        }));
        for count in [0, 1, 5, 8, 9, rays.len()] {
            for t_max in [f32::INFINITY, 3.0] {
                let batch = &rays[..count];
                let mut hits = vec![None; count];
                tbvh.closest_hits(batch, t_max, &mut hits);
                let mut occluded = vec![true; count];
                tbvh.any_hits(batch, t_max, &mut occluded);
                for ((ray, hit), blocked) in batch.iter().zip(&hits).zip(&occluded) {
                    assert_eq!(*hit, tbvh.closest_hit(ray, t_max), "{ray:?} t_max {t_max}");
                    assert_eq!(*blocked, tbvh.any_hit(ray, t_max), "{ray:?} t_max {t_max}");
                }
            }
            let batch = &each_rays[..count.min(each_rays.len())];
            let batch = if count == rays.len() { &each_rays[..] } else { batch };
            let mut each = vec![None; batch.len()];
            tbvh.closest_each(batch, &mut each);
            for (ray, hit) in batch.iter().zip(&each) {
                assert_eq!(
                    hit.map(|h| (h.prim, h.t.to_bits(), h.u.to_bits(), h.v.to_bits())),
                    tbvh.closest_hit(ray, f32::INFINITY)
                        .map(|h| (h.prim, h.t.to_bits(), h.u.to_bits(), h.v.to_bits())),
                    "{width:?}, a ray a lane: {ray:?}"
                );
            }
            // Each ray its own segment, empty ones included (shadow rays).
            let own = |i: usize| [f32::INFINITY, 0.0, 0.4, 1.5, 3.0][i % 5] * (1.0 + i as f32 * 1e-3);
            let batch = &rays[..count];
            let mut occluded = vec![true; count];
            tbvh.any_hits_within(batch, own, &mut occluded);
            for (i, (ray, blocked)) in batch.iter().zip(&occluded).enumerate() {
                assert_eq!(*blocked, tbvh.any_hit(ray, own(i)), "{ray:?} t_max {}", own(i));
            }
        }
    }
}

/// Only trees beyond the caches load ahead: a sphere of 12,800 triangles does not, one of
/// 128,000 (about 5.7 MB) does.
#[test]
fn only_large_trees_load_ahead() {
    assert!(!TriangleBvh::new(&sphere(80, 80)).fetches_ahead());
    assert!(TriangleBvh::new(&sphere(400, 160)).fetches_ahead());
}

#[test]
#[should_panic(expected = "one answer slot per ray")]
fn stream_needs_one_slot_per_ray() {
    let tbvh = TriangleBvh::new(&random_triangles(&mut Rng(1), 10));
    tbvh.closest_hits(&[Ray::new(Vec3::ZERO, Vec3::X)], f32::INFINITY, &mut []);
}

/// A query made from a callback of another (which holds the thread's scratch stack) walks with
/// its own stack, and both answer as when made alone.
#[test]
fn queries_nested_in_callbacks() {
    let mut rng = Rng(21);
    let tris = random_triangles(&mut rng, 3000);
    let bounds: Vec<Aabb> = tris.iter().map(Triangle::bounds).collect();
    let bvh = Bvh::build(&bounds);
    let tbvh = TriangleBvh::new(&tris);
    let mut inner_queries = 0;
    for _ in 0..300 {
        let (outer, inner) = (random_ray(&mut rng, &tris), random_ray(&mut rng, &tris));
        let alone = tbvh.closest_hit(&inner, f32::INFINITY);
        let got = bvh.closest_hit(&outer, f32::INFINITY, |p, t| {
            assert_eq!(tbvh.closest_hit(&inner, f32::INFINITY), alone);
            inner_queries += 1;
            tris[p as usize].intersect(&outer, t).map(|h| h.t)
        });
        let expect = brute_closest(&tris, &outer, f32::INFINITY);
        assert!(same_hit(&tris, &outer, got, expect), "{got:?} vs {expect:?}");
    }
    assert!(inner_queries > 300, "{inner_queries} nested queries");
}

/// A tree walked with its boxes tested eight lanes at a time finds the same hits, to the bit, as
/// with four; and visits them in the same order.
#[test]
fn walks_find_the_same_hits_at_every_width() {
    let mut rng = Rng(0x71de);
    let widths = Width::on_host();
    for tris in [random_triangles(&mut rng, 3000), sphere(60, 120), exponential_steps()] {
        let trees: Vec<TriangleBvh> = widths.iter().map(|&w| TriangleBvh::new(&tris).with_width(w)).collect();
        let rays: Vec<Ray> = (0..3000).map(|_| random_ray(&mut rng, &tris)).collect();
        let answers = |tree: &TriangleBvh| {
            let mut streamed = vec![None; rays.len()];
            tree.closest_hits(&rays, f32::INFINITY, &mut streamed);
            let singles: Vec<_> = rays.iter().map(|r| tree.closest_hit(r, 2.0)).collect();
            let order: Vec<Vec<u32>> = rays
                .iter()
                .map(|r| {
                    let mut seen = Vec::new();
                    tree.each_hit(r, f32::INFINITY, |h| {
                        seen.push(h.prim);
                        false
                    });
                    seen
                })
                .collect();
            (streamed, singles, order)
        };
        let first = answers(&trees[0]);
        assert!(first.0.iter().filter(|h| h.is_some()).count() > rays.len() / 10);
        for (tree, width) in trees.iter().zip(&widths).skip(1) {
            assert!(answers(tree) == first, "{width:?} differs from {:?}", widths[0]);
        }
    }
}

/// A floor of two triangles (which the tree does not walk) answers as testing each triangle
/// does for rays from on, above, below and beside it in every direction, zero components
/// included: those that start outside its bounds and move away are passed over, and no other.
#[test]
fn a_floor_passes_over_only_the_rays_that_move_away() {
    let (a, b, c, d) = (
        Vec3::new(-5.0, 0.0, -5.0),
        Vec3::new(5.0, 0.0, -5.0),
        Vec3::new(5.0, 0.0, 5.0),
        Vec3::new(-5.0, 0.0, 5.0),
    );
    let tris = [Triangle::new(a, c, b), Triangle::new(a, d, c)];
    let mut rng = Rng(0x0f10_0a2e_d0c5_3a11);
    for width in Width::on_host() {
        let floor = TriangleBvh::new(&tris).with_width(width);
        assert!(!floor.walks());
        let (mut hits, mut away) = (0, 0);
        for i in 0..20_000 {
            let heights = [0.0, 1e-6, -1e-6, 0.5, -0.5, 3.0];
            let mut origin = (rng.v() - 0.5) * 14.0;
            origin.y = heights[i % heights.len()];
            let ray = Ray::new(origin, rng.dir());
            let t_max = if i % 3 == 0 {
                1.0 + rng.f() * 10.0
            } else {
                f32::INFINITY
            };
            let expect = brute_closest(&tris, &ray, t_max);
            let got = floor.closest_hit(&ray, t_max).map(|h| (h.t, h.prim));
            assert!(same_hit(&tris, &ray, got, expect), "{ray:?}: {got:?} vs {expect:?}");
            assert_eq!(floor.any_hit(&ray, t_max), expect.is_some(), "{ray:?}");
            hits += usize::from(expect.is_some());
            away += usize::from(floor.heads_away(&ray));
        }
        assert!(hits > 3_000 && away > 3_000, "{hits} hits, {away} rays moving away");
    }
}

/// The branch-free sort of a node's children (AVX2) gives the entries the scalar sort of the
/// keys gives, to the bit: the same children in the same order with the same rounded distances,
/// for rays from outside and from inside boxes (whose entry distances tie at zero), with and
/// without a finite `t_max`.
#[cfg(target_arch = "x86_64")]
#[test]
fn sorted_children_match_the_scalar_sort() {
    use crate::accel::lanes::{in_avx2, Avx};
    let Some(avx2) = Avx::detect().and_then(Avx::avx2) else {
        eprintln!("skipped: this CPU has no AVX2");
        return;
    };
    let mut rng = Rng(0x0050_f7ed);
    let mut counts = [0usize; MAX_WIDTH + 1];
    for tris in [random_triangles(&mut rng, 3000), sphere(40, 80)] {
        let tree = TriangleBvh::new(&tris);
        for i in 0..400 {
            let ray = if i % 4 == 0 {
                Ray::new(tris[i % tris.len()].point(0.3, 0.3), rng.dir())
            } else {
                random_ray(&mut rng, &tris)
            };
            let t_max = if i % 3 == 0 { 0.5 + 4.0 * rng.f() } else { f32::INFINITY };
            for node in &tree.bvh.nodes {
                let (fast, scalar) = in_avx2(avx2, || {
                    let (mut fast, mut scalar) = ([(0, 0.0); MAX_WIDTH], [(0, 0.0); MAX_WIDTH]);
                    let (sorting, wide) = (SortingRayPre::new(&ray), WideRayPre::new(&ray));
                    let (n, m) = (
                        sorting.hit_sorted::<true>(node, t_max, &mut fast),
                        wide.hit_sorted::<true>(node, t_max, &mut scalar),
                    );
                    let (mut fast_near, mut scalar_near) = ([(0, 0.0); MAX_WIDTH], [(0, 0.0); MAX_WIDTH]);
                    let (n_near, m_near) = (
                        sorting.hit_sorted::<false>(node, t_max, &mut fast_near),
                        wide.hit_sorted::<false>(node, t_max, &mut scalar_near),
                    );
                    let fast = [&fast[..n], &fast_near[..n_near]].concat();
                    (fast, [&scalar[..m], &scalar_near[..m_near]].concat())
                });
                let bits = |entries: &[(u32, f32)]| entries.iter().map(|&(c, t)| (c, t.to_bits())).collect::<Vec<_>>();
                assert_eq!(bits(&fast), bits(&scalar), "{ray:?} t_max {t_max}");
                counts[fast.len() / 2] += 1;
            }
        }
    }
    assert!(
        counts.iter().all(|&c| c > 0),
        "every number of children met: {counts:?}"
    );
}
