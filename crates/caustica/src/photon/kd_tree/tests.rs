use super::*;

/// splitmix64: small, seedable, good enough for test data.
struct Rng(u64);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform in [0, 1).
    fn f(&mut self) -> f32 {
        (self.next_u64() >> 40) as f32 / (1u64 << 24) as f32
    }
    fn range(&mut self, a: f32, b: f32) -> f32 {
        a + (b - a) * self.f()
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n as u64) as usize
    }
    fn vec(&mut self) -> Vec3 {
        Vec3::new(self.f(), self.f(), self.f())
    }
}

/// A photon-sized item, so tests cover a `KdPoint` that is not `Vec3`.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Item {
    pos: Vec3,
    id: u32,
    _pad: [f32; 2],
}

impl KdPoint for Item {
    fn position(&self) -> Vec3 {
        self.pos
    }
}

fn items_of(points: &[Vec3]) -> Vec<Item> {
    points
        .iter()
        .enumerate()
        .map(|(i, &pos)| Item {
            pos,
            id: i as u32,
            _pad: [0.0; 2],
        })
        .collect()
}

fn uniform(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    (0..n).map(|_| rng.vec()).collect()
}

fn clustered(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    let centers: Vec<Vec3> = (0..5).map(|_| rng.vec()).collect();
    (0..n)
        .map(|_| {
            let c = centers[rng.below(centers.len())];
            let s = if rng.below(2) == 0 { 1e-3 } else { 1e-5 };
            c + (rng.vec() - Vec3::splat(0.5)) * s
        })
        .collect()
}

fn duplicates(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    let distinct: Vec<Vec3> = (0..7).map(|_| rng.vec()).collect();
    (0..n).map(|_| distinct[rng.below(distinct.len())]).collect()
}

fn axis_plane(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    (0..n).map(|_| Vec3::new(rng.f(), 0.25, rng.f())).collect()
}

fn tilted_plane(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    let (u, v) = (Vec3::new(1.0, 0.3, -0.2), Vec3::new(-0.1, 0.7, 0.9));
    (0..n).map(|_| u * rng.f() + v * rng.f()).collect()
}

fn collinear(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    let d = Vec3::new(0.3, -0.5, 0.8);
    (0..n).map(|_| d * rng.range(-1.0, 1.0)).collect()
}

/// Integer grid: many exactly tied distances.
fn grid(rng: &mut Rng, n: usize) -> Vec<Vec3> {
    (0..n)
        .map(|_| Vec3::new(rng.below(6) as f32, rng.below(6) as f32, rng.below(3) as f32))
        .collect()
}

fn identical(_rng: &mut Rng, n: usize) -> Vec<Vec3> {
    vec![Vec3::new(0.5, -2.0, 3.0); n]
}

type Gen = fn(&mut Rng, usize) -> Vec<Vec3>;

const GENERATORS: [(&str, Gen); 8] = [
    ("uniform", uniform),
    ("clustered", clustered),
    ("duplicates", duplicates),
    ("axis_plane", axis_plane),
    ("tilted_plane", tilted_plane),
    ("collinear", collinear),
    ("grid", grid),
    ("identical", identical),
];

const SIZES: [usize; 10] = [0, 1, 2, 11, 12, 13, 25, 100, 1000, 4000];

/// Sorted (dist2, slot) of every item within `r2` by brute force.
fn brute_within<T: KdPoint>(items: &[T], p: Vec3, r2: f32) -> Vec<(f32, u32)> {
    let mut v: Vec<(f32, u32)> = items
        .iter()
        .enumerate()
        .map(|(i, it)| (dist2(it.position().to_array(), p.to_array()), i as u32))
        .filter(|&(d, _)| d <= r2)
        .collect();
    v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    v
}

fn check_knn<T: KdPoint>(
    tree: &KdTree,
    items: &[T],
    p: Vec3,
    k: usize,
    max_d2: f32,
    out: &mut Vec<Neighbor>,
    ctx: &str,
) {
    let r = tree.k_nearest(items, p, k, max_d2, out);
    let brute = brute_within(items, p, max_d2);
    let want: Vec<f32> = brute.iter().take(k).map(|x| x.0).collect();
    // Every result is real, unique and reports its true distance.
    let mut slots: Vec<u32> = out.iter().map(|n| n.slot).collect();
    slots.sort_unstable();
    slots.dedup();
    assert_eq!(slots.len(), out.len(), "{ctx}: duplicate slots");
    for n in out.iter() {
        let d = dist2(items[n.slot as usize].position().to_array(), p.to_array());
        assert_eq!(d, n.dist2, "{ctx}: wrong dist2 for slot {}", n.slot);
    }
    // Same distances as brute force (ties may pick different slots).
    let mut got: Vec<f32> = out.iter().map(|n| n.dist2).collect();
    got.sort_by(f32::total_cmp);
    assert_eq!(got, want, "{ctx}: k={k} r2={max_d2} p={p}");
    // out is a max-heap and the returned radius follows the contract.
    for i in 1..out.len() {
        assert!(out[(i - 1) / 2].dist2 >= out[i].dist2, "{ctx}: not a heap");
    }
    // The unordered query finds the same distances and radius.
    let mut plain = Vec::new();
    let r_plain = tree.k_nearest_unordered(items, p, k, max_d2, &mut plain);
    let mut plain: Vec<f32> = plain.iter().map(|n| n.dist2).collect();
    plain.sort_by(f32::total_cmp);
    assert_eq!(plain, want, "{ctx}: unordered k={k} r2={max_d2} p={p}");
    assert_eq!(r_plain.to_bits(), r.to_bits(), "{ctx}: unordered radius");
    if k > 0 && out.len() == k {
        assert_eq!(r, out[0].dist2, "{ctx}: radius");
        assert_eq!(r, *want.last().unwrap(), "{ctx}: radius");
    } else {
        assert_eq!(r.to_bits(), max_d2.to_bits(), "{ctx}: radius when short");
    }
}

fn check_within<T: KdPoint>(tree: &KdTree, items: &[T], p: Vec3, r2: f32, ctx: &str) {
    let mut got = Vec::new();
    tree.for_each_within(items, p, r2, |s, d| got.push((d, s)));
    for &(d, s) in &got {
        let true_d = dist2(items[s as usize].position().to_array(), p.to_array());
        assert_eq!(d, true_d, "{ctx}: wrong dist2");
    }
    got.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    assert_eq!(got, brute_within(items, p, r2), "{ctx}: r2={r2} p={p}");
}

/// Queries: random points near the data, exact data points, and far away points.
fn queries(rng: &mut Rng, pts: &[Vec3]) -> Vec<Vec3> {
    let mut q: Vec<Vec3> = (0..6).map(|_| rng.vec() * 1.2 - Vec3::splat(0.1)).collect();
    for _ in 0..6 {
        if !pts.is_empty() {
            q.push(pts[rng.below(pts.len())]);
        }
    }
    q.push(Vec3::new(50.0, -40.0, 7.0));
    q
}

#[test]
fn knn_matches_brute_force() {
    let mut rng = Rng(1);
    let mut out = Vec::new();
    for (name, gen) in GENERATORS {
        for n in SIZES {
            let pts = gen(&mut rng, n);
            let mut items = items_of(&pts);
            let tree = KdTree::build(&mut items);
            assert_eq!(tree.len(), n);
            let pts: Vec<Vec3> = items.iter().map(|i| i.pos).collect();
            for p in queries(&mut rng, &pts) {
                for k in [0, 1, 2, 5, 12, 13, 50, 200, n, n + 3] {
                    for max_d2 in [0.0, 1e-8, 1e-4, 0.01, 0.1, 1.0, f32::INFINITY] {
                        let ctx = format!("{name} n={n}");
                        check_knn(&tree, &items, p, k, max_d2, &mut out, &ctx);
                    }
                }
            }
        }
    }
}

#[test]
fn within_matches_brute_force() {
    let mut rng = Rng(2);
    for (name, gen) in GENERATORS {
        for n in SIZES {
            let pts = gen(&mut rng, n);
            let mut items = items_of(&pts);
            let tree = KdTree::build(&mut items);
            let pts: Vec<Vec3> = items.iter().map(|i| i.pos).collect();
            for p in queries(&mut rng, &pts) {
                for r2 in [0.0, 1e-8, 1e-4, 0.003, 0.05, 0.5, 4.0, f32::INFINITY] {
                    check_within(&tree, &items, p, r2, &format!("{name} n={n}"));
                }
            }
        }
    }
}

/// Radii chosen exactly at data distances, so boundary ties are exercised.
#[test]
fn inclusive_radius_at_exact_distances() {
    let mut rng = Rng(3);
    let mut out = Vec::new();
    for (name, gen) in [("grid", grid as Gen), ("uniform", uniform)] {
        let pts = gen(&mut rng, 3000);
        let mut items = pts.clone();
        let tree = KdTree::build(&mut items);
        for _ in 0..40 {
            let p = items[rng.below(items.len())] + Vec3::new(0.5, 0.0, 0.0);
            let r2 = dist2(items[rng.below(items.len())].to_array(), p.to_array());
            check_within(&tree, &items, p, r2, name);
            for k in [1, 7, 64] {
                check_knn(&tree, &items, p, k, r2, &mut out, name);
            }
        }
    }
}

#[test]
fn larger_random_sets() {
    let mut rng = Rng(4);
    let mut out = Vec::new();
    for (name, gen) in [
        ("uniform", uniform as Gen),
        ("tilted_plane", tilted_plane),
        ("clustered", clustered),
    ] {
        let mut items = gen(&mut rng, 100_000);
        let tree = KdTree::build(&mut items);
        for _ in 0..30 {
            let p = items[rng.below(items.len())] + (rng.vec() - Vec3::splat(0.5)) * 0.01;
            for k in [1, 50, 200] {
                check_knn(&tree, &items, p, k, 0.01, &mut out, name);
                check_knn(&tree, &items, p, k, f32::INFINITY, &mut out, name);
            }
            check_within(&tree, &items, p, 1e-4, name);
        }
    }
}

#[test]
fn empty_one_and_identical() {
    let mut out = vec![Neighbor { slot: 9, dist2: 9.0 }];
    let mut empty: Vec<Vec3> = Vec::new();
    let tree = KdTree::build(&mut empty);
    assert!(tree.is_empty());
    assert_eq!(tree.len(), 0);
    assert_eq!(tree.k_nearest(&empty, Vec3::ZERO, 5, 1.0, &mut out), 1.0);
    assert!(out.is_empty());
    tree.for_each_within(&empty, Vec3::ZERO, 1.0, |_, _| panic!("empty tree"));

    let mut one = vec![Vec3::new(1.0, 2.0, 3.0)];
    let tree = KdTree::build(&mut one);
    assert_eq!(tree.len(), 1);
    assert!(!tree.is_empty());
    let r = tree.k_nearest(&one, Vec3::new(1.0, 2.0, 4.0), 1, 10.0, &mut out);
    assert_eq!(out, [Neighbor { slot: 0, dist2: 1.0 }]);
    assert_eq!(r, 1.0);
    let r = tree.k_nearest(&one, Vec3::new(1.0, 2.0, 4.0), 3, 10.0, &mut out);
    assert_eq!((out.len(), r), (1, 10.0));
    let r = tree.k_nearest(&one, Vec3::new(1.0, 2.0, 4.0), 1, 0.5, &mut out);
    assert_eq!((out.len(), r), (0, 0.5));

    let mut same = vec![Vec3::splat(0.25); 100_000];
    let tree = KdTree::build(&mut same);
    let r = tree.k_nearest(&same, Vec3::splat(0.25), 50, 1.0, &mut out);
    assert_eq!((out.len(), r), (50, 0.0));
    let r = tree.k_nearest(&same, Vec3::new(0.25, 0.25, 1.25), 200, 2.0, &mut out);
    assert_eq!((out.len(), r), (200, 1.0));
    let mut count = 0;
    tree.for_each_within(&same, Vec3::splat(0.3), 0.01, |_, _| count += 1);
    assert_eq!(count, 100_000);
}

#[test]
fn k_zero_returns_nothing() {
    let mut rng = Rng(5);
    let mut items = uniform(&mut rng, 500);
    let tree = KdTree::build(&mut items);
    let mut out = Vec::new();
    assert_eq!(tree.k_nearest(&items, Vec3::splat(0.5), 0, 0.3, &mut out), 0.3);
    assert!(out.is_empty());
}

#[test]
fn nan_queries_find_nothing() {
    let mut rng = Rng(6);
    let mut items = uniform(&mut rng, 1000);
    let tree = KdTree::build(&mut items);
    let mut out = Vec::new();
    for p in [
        Vec3::new(f32::NAN, 0.5, 0.5),
        Vec3::new(0.5, 0.5, f32::NAN),
        Vec3::splat(f32::NAN),
    ] {
        tree.k_nearest(&items, p, 10, f32::INFINITY, &mut out);
        assert!(out.is_empty());
        tree.for_each_within(&items, p, f32::INFINITY, |_, _| panic!("NaN query"));
    }
    let r = tree.k_nearest(&items, Vec3::splat(0.5), 10, f32::NAN, &mut out);
    assert!(out.is_empty() && r.is_nan());
    tree.for_each_within(&items, Vec3::splat(0.5), f32::NAN, |_, _| panic!("NaN r2"));
    tree.k_nearest(&items, Vec3::splat(0.5), 10, -1.0, &mut out);
    assert!(out.is_empty());
    // An infinite query point is far from everything but must not panic.
    let inf = Vec3::new(f32::INFINITY, 0.5, 0.5);
    tree.k_nearest(&items, inf, 10, 1.0, &mut out);
    assert!(out.is_empty());
}

/// NaN items are never reported and do not hide the finite ones.
#[test]
fn nan_items_are_ignored() {
    let mut rng = Rng(7);
    let mut pts = uniform(&mut rng, 3000);
    for i in (0..pts.len()).step_by(3) {
        pts[i][i % 3] = f32::NAN;
    }
    let mut items = items_of(&pts);
    let tree = KdTree::build(&mut items);
    let mut out = Vec::new();
    for p in queries(&mut rng, &[]) {
        for k in [1, 10, 100, 5000] {
            check_knn(&tree, &items, p, k, f32::INFINITY, &mut out, "nan items");
            check_knn(&tree, &items, p, k, 0.02, &mut out, "nan items");
        }
        check_within(&tree, &items, p, 0.02, "nan items");
    }
}

#[test]
fn build_is_deterministic_across_thread_counts() {
    let mut rng = Rng(8);
    let pts = clustered(&mut rng, 150_000)
        .into_iter()
        .chain(tilted_plane(&mut rng, 150_000))
        .chain(duplicates(&mut rng, 50_000))
        .collect::<Vec<_>>();
    let build_in = |threads: usize| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        let mut items = items_of(&pts);
        let tree = pool.install(|| KdTree::build(&mut items));
        (tree, items.iter().map(|i| i.id).collect::<Vec<_>>())
    };
    let (t1, o1) = build_in(1);
    let (t2, o2) = build_in(2);
    let (t3, o3) = build_in(3);
    let (t4, o4) = build_in(2);
    assert_eq!(o1, o2);
    assert_eq!(o1, o3);
    assert_eq!(o1, o4);
    assert!(t1 == t2 && t1 == t3 && t1 == t4);
    // The reorder is a permutation.
    let mut ids = o1.clone();
    ids.sort_unstable();
    assert!(ids.iter().enumerate().all(|(i, &id)| i as u32 == id));
}

#[test]
fn tree_overhead_is_small() {
    for n in [1, 12, 13, 1000, 123_457, 1 << 20, 10_000_000] {
        let nodes = (1usize << depth_for(n)) - 1;
        // Per inner node its split and the bounds of its points; per leaf its points' bounds.
        let bytes = nodes * (std::mem::size_of::<Node>() + std::mem::size_of::<PointBounds>())
            + (nodes + 1) * std::mem::size_of::<PointBounds>();
        assert!(bytes <= 7 * n.max(8), "n={n}: {bytes} bytes");
        if n <= 123_457 {
            let mut points: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f32, (i % 7) as f32, 0.0)).collect();
            assert_eq!(KdTree::build(&mut points).heap_bytes(), bytes, "n={n}");
        }
        // Leaves hold at most LEAF_MAX items.
        assert!(n.div_ceil(nodes + 1) <= LEAF_MAX);
    }
}

/// Every (slot, dist2) whose ball strictly holds `p`, or within the floor (inclusive), in slot
/// order.
fn brute_reaching<T: KdPoint>(items: &[T], radius: &[f32], p: Vec3, floor: f32) -> Vec<(u32, f32)> {
    let floor2 = floor * floor;
    (0..items.len())
        .filter_map(|i| {
            let d2 = dist2(items[i].position().to_array(), p.to_array());
            (d2 < radius[i] * radius[i] || d2 <= floor2).then_some((i as u32, d2))
        })
        .collect()
}

#[test]
fn reaching_matches_brute_force_and_near_leaves_serve_nearby_points() {
    let mut rng = Rng(9);
    let mut slots = Vec::new();
    for (name, gen) in GENERATORS {
        for n in [0, 1, 13, 100, 1000, 4000] {
            let pts = gen(&mut rng, n);
            let mut items = items_of(&pts);
            let tree = KdTree::build(&mut items);
            // Radii from tiny to wide, some zero, so balls of every size overlap.
            let radius: Vec<f32> = (0..n)
                .map(|i| if i % 7 == 0 { 0.0 } else { 0.3 * rng.f() * rng.f() })
                .collect();
            let reach = tree.reach(&items, radius.clone());
            let pts: Vec<Vec3> = items.iter().map(|i| i.pos).collect();
            for p in queries(&mut rng, &pts) {
                for floor in [0.0, 1e-3, 0.02] {
                    let ctx = format!("{name} n={n} p={p} floor={floor}");
                    let mut found = Vec::new();
                    tree.for_each_reaching(&reach, &items, p, floor, |slot, d2| found.push((slot, d2)));
                    assert_eq!(found, brute_reaching(&items, &radius, p, floor), "{ctx}");
                    // Slots listed around p serve points within delta and floors up to its own.
                    let delta = 0.01;
                    tree.reaching_near(&reach, &items, p, floor, delta, &mut slots);
                    for _ in 0..8 {
                        let dir = (rng.vec() - Vec3::splat(0.5)).normalize_or_zero();
                        let q = p + dir * (delta * rng.f());
                        let f = floor * rng.f();
                        let mut near = Vec::new();
                        tree.for_each_reaching_among(&reach, &items, &slots, q, f, |slot, d2| near.push((slot, d2)));
                        let mut whole = Vec::new();
                        tree.for_each_reaching(&reach, &items, q, f, |slot, d2| whole.push((slot, d2)));
                        assert_eq!(near, whole, "{ctx} q={q} f={f}");
                    }
                }
            }
        }
    }
}

/// A beam query finds exactly the items a brute-force scan finds square to the segment within
/// the radius, whatever the segment's direction (along an axis too) and length.
#[test]
fn near_segment_matches_brute_force() {
    let mut rng = Rng(5);
    for (name, gen) in GENERATORS {
        for n in SIZES {
            let pts = gen(&mut rng, n);
            let mut items = items_of(&pts);
            let tree = KdTree::build(&mut items);
            for case in 0..12 {
                let origin = rng.vec() * 1.4 - Vec3::splat(0.2);
                let dir = match case % 4 {
                    0 => Vec3::X,
                    1 => -Vec3::Z,
                    _ => (rng.vec() - Vec3::splat(0.5)).normalize(),
                };
                let (t0, t1) = (rng.range(-0.2, 0.3), rng.range(0.3, 1.5));
                let radius = [0.0, 0.01, 0.05, 0.2][case % 4];
                let mut found = Vec::new();
                tree.for_each_near_segment(&items, (origin, dir), (t0, t1), radius, |slot, t, d2| {
                    found.push((slot, t, d2));
                });
                found.sort_by_key(|f| f.0);
                let mut expected = Vec::new();
                for (slot, it) in items.iter().enumerate() {
                    let v = it.pos - origin;
                    let t = v.dot(dir);
                    let d2 = (v.length_squared() - t * t).max(0.0);
                    if t >= t0 && t <= t1 && d2 < radius * radius {
                        expected.push((slot as u32, t, d2));
                    }
                }
                assert_eq!(found, expected, "{name} n={n} case {case}");
            }
        }
    }
}
