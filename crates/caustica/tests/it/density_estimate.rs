//! The course model's default caustic estimate on photon maps whose irradiance is known exactly:
//! sparse photons must give a smooth low glow (no disc around each photon), a dense cluster its
//! own irradiance with a sharp edge.

use crate::common;

use caustica::math::Vec3;
use caustica::photon::{EstimateSettings, Estimator, Photon, PhotonMap, PhotonStats};
use caustica::sampling::Rng;
use std::f32::consts::PI;

/// A white floor (kd = 1) at z = 0. The course's diffuse term has no 1/π (docs/radiometry.md),
/// so the reflected radiance of a receiver is kd·E and the estimate must equal E.
const FLOOR: &str = "SBT-raytracer 1.0
directional_light { direction = (0, 0, -1); color = (1, 1, 1); }
scale(200, square { material = { diffuse = (1, 1, 1); } })
";

/// Every photon carries the same power (what the budget aims for), as on a real wall.
const POWER: f32 = 0.01;
/// 3,600 photons spread uniformly over a 60 × 60 square: irradiance 3,600·Φ / 3,600.
const SPARSE_HALF: f32 = 30.0;
const SPARSE: usize = 3_600;
const E_SPARSE: f32 = SPARSE as f32 * POWER / (4.0 * SPARSE_HALF * SPARSE_HALF);
/// 100,000 more in a disc of radius 0.5 around `CLUSTER`: a caustic 127,000 times brighter.
const DENSE: usize = 100_000;
const DISC: f32 = 0.5;
const CLUSTER: Vec3 = Vec3::new(10.0, 10.0, 0.0);
const E_DENSE: f32 = DENSE as f32 * POWER / (PI * DISC * DISC);

fn photon(position: Vec3) -> Photon {
    Photon::new(
        position,
        Vec3::splat(POWER),
        -Vec3::Z,
        Vec3::Z,
        caustica::photon::REFLECTED,
    )
}

/// Uniformly random (not stratified) positions: the clumping of a real photon pass.
fn photons() -> Vec<Photon> {
    let mut rng = Rng::new(11, 0);
    let mut out = Vec::with_capacity(SPARSE + DENSE);
    for _ in 0..SPARSE {
        let u = rng.uniform2();
        out.push(photon(Vec3::new(
            (2.0 * u.x - 1.0) * SPARSE_HALF,
            (2.0 * u.y - 1.0) * SPARSE_HALF,
            0.0,
        )));
    }
    for _ in 0..DENSE {
        let u = rng.uniform2();
        let (r, phi) = (DISC * u.x.sqrt(), 2.0 * PI * u.y);
        out.push(photon(CLUSTER + Vec3::new(r * phi.cos(), r * phi.sin(), 0.0)));
    }
    out
}

fn map(estimate: &EstimateSettings) -> PhotonMap {
    PhotonMap::from_photons(photons(), PhotonStats::default(), estimate)
}

/// Estimates over a grid in the sparse region, at least 5 units from the cluster and 8 from the
/// square's border (the widest kernel there is about 3).
fn sparse_grid(scene: &caustica::scene::Scene, map: &PhotonMap, estimate: &EstimateSettings) -> Vec<f32> {
    let mut values = Vec::new();
    for i in 0..45 {
        for j in 0..45 {
            let p = Vec3::new(-22.0 + i as f32, -22.0 + j as f32, 0.0);
            if (p - CLUSTER).length() < 5.0 {
                continue;
            }
            values.push(map.flux_density(scene, p, Vec3::Z, estimate).x);
        }
    }
    values
}

fn mean_cv_max(values: &[f32]) -> (f32, f32, f32) {
    let n = values.len() as f32;
    let mean = values.iter().sum::<f32>() / n;
    let var = values.iter().map(|v| (v - mean) * (v - mean)).sum::<f32>() / n;
    let max = values.iter().copied().fold(0.0, f32::max);
    (mean, var.sqrt() / mean, max / mean)
}

/// Sparse photons next to a dense caustic give their own uniform irradiance, smoothly: the mean
/// within 5% of E, pixel-to-pixel spread (cv) under 0.2, no point above 1.6 × the mean. About
/// k = 100 kernels overlap at a point, so the noise is of order 1/√100 = 10% (the cone filter
/// raises it a little). The k-nearest estimate with its automatic radius, which follows the
/// dense cluster, fails exactly this: every sparse photon becomes a disc.
#[test]
fn sparse_photons_give_a_smooth_glow_of_their_irradiance() {
    let scene = common::scene(FLOOR);
    let kernels = EstimateSettings::default();
    assert_eq!(kernels.estimator, Estimator::Kernels);
    let values = sparse_grid(&scene, &map(&kernels), &kernels);
    let (mean, cv, peak) = mean_cv_max(&values);
    eprintln!("kernels: mean {} E, cv {cv}, max/mean {peak}", mean / E_SPARSE);
    assert!(
        common::rel(mean, E_SPARSE) < 0.05,
        "mean {mean} over {} points, want {E_SPARSE}",
        values.len()
    );
    assert!(cv < 0.2, "spread {cv}");
    assert!(peak < 1.6, "brightest point {peak} × the mean");

    let nearest = EstimateSettings {
        estimator: Estimator::Nearest,
        ..EstimateSettings::default()
    };
    let (mean, cv, peak) = mean_cv_max(&sparse_grid(&scene, &map(&nearest), &nearest));
    eprintln!("k nearest: mean {} E, cv {cv}, max/mean {peak}", mean / E_SPARSE);
    assert!(
        cv > 1.0 && peak > 5.0,
        "the k-nearest estimate was expected to show dots here: mean {mean}, cv {cv}, max/mean {peak}"
    );
}

/// The dense cluster keeps its irradiance and a sharp edge. Its photons' kernels are about as
/// wide as the distance to the 100th neighbour, r_k = √(k / (π n)) = 0.016 for the areal density
/// n = 127,000 photons per unit², so the estimate must fall from 90% to 10% of E within 2·r_k
/// of the edge and be under 1% of E at 2·r_k outside it (the disc is 0.5 in radius).
#[test]
fn a_dense_caustic_keeps_its_level_and_a_sharp_edge() {
    let scene = common::scene(FLOOR);
    let estimate = EstimateSettings::default();
    let map = map(&estimate);
    let at = |r: f32| {
        // Averaged round the circle: the edge, not one spot's noise.
        let n = 32;
        (0..n)
            .map(|i| {
                let phi = 2.0 * PI * i as f32 / n as f32;
                map.flux_density(
                    &scene,
                    CLUSTER + r * Vec3::new(phi.cos(), phi.sin(), 0.0),
                    Vec3::Z,
                    &estimate,
                )
                .x
            })
            .sum::<f32>()
            / n as f32
    };
    // Inside: the mean over 400 random points of the inner disc (one point's own noise is
    // about 1/√k).
    let mut rng = Rng::new(5, 1);
    let inside = (0..400)
        .map(|_| {
            let u = rng.uniform2();
            let (r, phi) = (0.7 * DISC * u.x.sqrt(), 2.0 * PI * u.y);
            let p = CLUSTER + Vec3::new(r * phi.cos(), r * phi.sin(), 0.0);
            map.flux_density(&scene, p, Vec3::Z, &estimate).x
        })
        .sum::<f32>()
        / 400.0;
    assert!(common::rel(inside, E_DENSE) < 0.03, "inside {inside}, want {E_DENSE}");
    let r_k = (100.0 / (PI * DENSE as f32 / (PI * DISC * DISC))).sqrt();
    // The 90% and 10% crossings of the radial profile.
    let profile: Vec<(f32, f32)> = (0..=80)
        .map(|i| {
            let r = DISC - 4.0 * r_k + i as f32 * 0.1 * r_k;
            (r, at(r) / E_DENSE)
        })
        .collect();
    let crossing = |level: f32| profile.iter().find(|&&(_, v)| v < level).map(|&(r, _)| r).unwrap();
    let (r90, r10) = (crossing(0.9), crossing(0.1));
    eprintln!(
        "edge: 90% at {r90}, 10% at {r10}, r_k {r_k}, inside {}",
        inside / E_DENSE
    );
    assert!(
        r10 - r90 < 2.0 * r_k,
        "edge 90%→10% over {} (r_k = {r_k}): {profile:?}",
        r10 - r90
    );
    assert!(
        r90 > DISC - 2.0 * r_k && r10 < DISC + 2.0 * r_k,
        "edge at {r90}..{r10}, not at {DISC}"
    );
    let outside = at(DISC + 2.0 * r_k) / E_DENSE;
    assert!(outside < 0.01, "{outside} of the caustic's irradiance just outside it");
}

/// Pixels more than 0.2 brighter than the median of their 5 × 5 neighbourhood (luminance of the
/// course's clamped PNG values): isolated bright dots.
fn dots(film: &caustica::film::Film) -> usize {
    let (w, h) = (film.width, film.height);
    let lum: Vec<f32> = film
        .pixels
        .iter()
        .map(|p| p.clamp(Vec3::ZERO, Vec3::ONE).element_sum() / 3.0)
        .collect();
    let mut count = 0;
    for y in 2..h - 2 {
        for x in 2..w - 2 {
            let mut window: Vec<f32> = (0..25).map(|i| lum[(y + i / 5 - 2) * w + x + i % 5 - 2]).collect();
            window.sort_by(f32::total_cmp);
            count += usize::from(lum[y * w + x] > window[12] + 0.2);
        }
    }
    count
}

/// A corpus scene whose two spheres and mirror wall hold most photons while the walls get few:
/// it was covered in bright dots (1,505 at 100 px, 12% of the image shared by the lights' emitted
/// power and gathered by the k nearest photons). With the default photon pass and estimate it
/// may have at most 0.5% of the image in dots more than the same render without caustics (whose
/// dots are the scene's own: highlights, silhouettes).
#[test]
#[cfg_attr(not(caustica_corpus), ignore = "../shared/scenes/sbt-corpus is absent")]
fn reflection2_has_no_polka_dots() {
    use caustica::integrator::whitted::{render, WhittedSettings};
    use caustica::integrator::{image_size, ImageSettings};
    use caustica::loader::{load, LoadSettings};
    use caustica::photon::PhotonSettings;
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/scenes/sbt-corpus/michaelasper__ray-tracer__reflection2.ray");
    let scene = load(&path, &LoadSettings::default()).expect("the corpus scene loads");
    let (width, height) = image_size(scene.camera(), 100, None);
    let image = ImageSettings {
        width,
        height,
        aa: 1,
        seed: 0,
    };
    let estimate = EstimateSettings::default();
    let map = PhotonMap::trace(&scene, &PhotonSettings::default(), &estimate, common::control());
    let settings = WhittedSettings::default();
    let with = render(&scene, Some((&map, &estimate)), &settings, &image, common::control()).0;
    let without = render(&scene, None, &settings, &image, common::control()).0;
    let (with, without) = (dots(&with), dots(&without));
    eprintln!("dots: {with} with caustics, {without} without");
    assert!(
        with <= without + width * height / 200,
        "{with} dots with caustics, {without} without"
    );
}

/// The kernel estimate keeps, per thread, the tree's leaves near its last points; a second map
/// estimated at the same points on the same thread must give its own values, exactly those a
/// fresh thread gives, and so must nearby points sharing a list.
#[test]
fn nearby_estimates_share_leaves_only_within_their_own_map() {
    let scene = common::scene(FLOOR);
    let estimate = EstimateSettings::default();
    let a = map(&estimate);
    // Another tree: fewer photons, moved.
    let shifted: Vec<Photon> = photons()
        .into_iter()
        .enumerate()
        .filter(|(i, _)| i % 3 != 0)
        .map(|(_, p)| photon(p.position + Vec3::new(0.003, -0.002, 0.0)))
        .collect();
    let b = PhotonMap::from_photons(shifted, PhotonStats::default(), &estimate);
    // Points across the cluster's edge, a pixel (0.004 here) or less apart.
    let points: Vec<Vec3> = (0..400)
        .map(|i| CLUSTER + Vec3::new(0.46 + 0.0011 * i as f32, 0.0007 * (i % 7) as f32, 0.0))
        .collect();
    let at = |map: &PhotonMap, p: Vec3| -> [f32; 4] {
        let ray = caustica::math::Ray::new(p + Vec3::Z * 1e-3, -Vec3::Z);
        let isect = scene.intersect(&ray, 2e-3).expect("the floor");
        let hit = scene.surface(&ray, &isect);
        let (e, r) = map.irradiance(&scene, &hit, Vec3::Z, &estimate, 0.004);
        [e.x, e.y, e.z, r]
    };
    let values = |map: &PhotonMap| -> Vec<[f32; 4]> { points.iter().map(|&p| at(map, p)).collect() };
    let fresh = |map: &PhotonMap| std::thread::scope(|s| s.spawn(|| values(map)).join().unwrap());
    // Both maps at each point in turn, on this thread.
    let (a_here, b_here): (Vec<_>, Vec<_>) = points.iter().map(|&p| (at(&a, p), at(&b, p))).unzip();
    assert_eq!(a_here, fresh(&a));
    assert_eq!(b_here, fresh(&b));
    assert_ne!(a_here, b_here, "the two maps differ here");
}
