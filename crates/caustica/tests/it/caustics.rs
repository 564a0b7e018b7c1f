//! Caustic photon maps against analytic answers.

use crate::common;

use caustica::integrator::whitted::transmittance;
use caustica::light::distance_attenuation;
use caustica::math::Vec3;
use caustica::photon::{EstimateSettings, Estimator, PhotonMap, PhotonSettings};

/// A photon map for Jensen's k-nearest estimate (the checks of photon transport use it: its
/// box over thousands of photons averages smooth fields).
fn trace(scene: &caustica::scene::Scene, settings: PhotonSettings, k: usize) -> PhotonMap {
    let estimate = EstimateSettings {
        estimator: Estimator::Nearest,
        k,
        ..EstimateSettings::default()
    };
    PhotonMap::trace(scene, &settings, &estimate, common::control())
}

/// A photon map for the default (kernel) estimate with `estimate`.
fn trace_for(scene: &caustica::scene::Scene, settings: PhotonSettings, estimate: &EstimateSettings) -> PhotonMap {
    PhotonMap::trace(scene, &settings, estimate, common::control())
}

/// For smooth fields: 10,000 photons per estimate (noise ≈ 1/√k = 1%) and a box filter.
fn smooth() -> EstimateSettings {
    EstimateSettings {
        estimator: Estimator::Nearest,
        k: 10_000,
        max_radius: Some(1e3),
        cone_filter: None,
        ..EstimateSettings::default()
    }
}

fn photons(n: usize) -> PhotonSettings {
    PhotonSettings {
        target_stored: n,
        seed: 7,
        ..PhotonSettings::default()
    }
}

/// A vertical mirror wall at x = 0 and a point light at (2, 0, 3) above a diffuse floor: on the
/// floor the reflected light is that of the light's mirror image at (−2, 0, 3).
const MIRROR: &str = "SBT-raytracer 1.0
point_light { position = (2, 0, 3); color = (1, 1, 1);
  constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
translate(0, 0, 2, rotate(0, 1, 0, 1.5707963, scale(4, 8, 1, square { material = { reflective = (1, 1, 1); } })))
scale(20, square { material = { diffuse = (1, 1, 1); } })
";

#[test]
fn flat_mirror_caustic_is_the_mirror_image_of_the_light() {
    let scene = common::scene(MIRROR);
    let map = trace(&scene, photons(1_000_000), 200);
    let settings = smooth();
    let image = Vec3::new(-2.0, 0.0, 3.0);
    for p in [
        Vec3::new(1.0, 0.0, 0.0),
        Vec3::new(2.0, 0.5, 0.0),
        Vec3::new(3.0, -1.0, 0.0),
        Vec3::new(1.5, 1.5, 0.0),
    ] {
        let to = image - p;
        let d = to.length();
        let want = (to.z / d) / (d * d);
        let got = map.flux_density(&scene, p, Vec3::Z, &settings).x;
        assert!(
            common::rel(got, want) < 0.05,
            "at {p:?}: photons {got}, mirror image {want}"
        );
    }
    // Behind the mirror (x < 0) the floor receives no reflected light.
    let near = EstimateSettings {
        estimator: Estimator::Nearest,
        max_radius: Some(0.5),
        ..EstimateSettings::default()
    };
    let behind = map.flux_density(&scene, Vec3::new(-1.5, 0.0, 0.0), Vec3::Z, &near).x;
    assert!(behind < 1e-4, "{behind}");
}

/// A glass slab (kt = 0.8, two interfaces) under a directional light of irradiance 1.
const SLAB: &str = "SBT-raytracer 1.0
directional_light { direction = (0, 0, -1); color = (1, 1, 1); }
translate(0, 0, 2, scale(2, 2, 0.5, box { material = { transmissive = (0.8, 0.8, 0.8); index = 1.5; } }))
scale(20, square { material = { diffuse = (1, 1, 1); } })
";

#[test]
fn glass_slab_passes_exactly_the_transmitted_power() {
    let scene = common::scene(SLAB);
    let map = trace(&scene, photons(600_000), 100);
    let settings = smooth();
    for p in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.5, -0.3, 0.0),
        Vec3::new(-0.6, 0.6, 0.0),
    ] {
        let got = map.flux_density(&scene, p, Vec3::Z, &settings).x;
        assert!(common::rel(got, 0.64) < 0.03, "under the slab at {p:?}: {got}");
    }
    // Total stored power equals irradiance × slab area × kt² (the slab is 2 × 2).
    let total: f64 = map.photons().iter().map(|p| p.power().x as f64).sum();
    assert!((total / (4.0 * 0.64) - 1.0).abs() < 0.02, "transmitted power {total}");
    // Shadow rays agree: the direct light under the slab is filtered by kt at both faces.
    let t = transmittance(&scene, Vec3::ZERO, Vec3::Z, Vec3::Z, f32::INFINITY);
    assert!((t.x - 0.64).abs() < 1e-5, "{t:?}");
}

#[test]
fn stored_flux_never_exceeds_emitted_flux() {
    // Glass and mirror over diffuse receivers, inverse-square light: each photon's power only falls.
    let text = "SBT-raytracer 1.0
point_light { position = (0, 0, 4); color = (1, 1, 1);
  constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
translate(0, 0, 1.5, sphere { material = { transmissive = (0.9, 0.9, 0.9); reflective = (0.1, 0.1, 0.1); index = 1.5; } })
translate(2.5, 0, 1, sphere { material = { reflective = (0.8, 0.6, 0.4); } })
scale(30, square { material = { diffuse = (0.7, 0.7, 0.7); } })
";
    let scene = common::scene(text);
    let settings = PhotonSettings {
        aim: false,
        ..photons(50_000)
    };
    let map = trace(&scene, settings, 50);
    let stored: Vec3 = map.photons().iter().map(|p| p.power()).sum();
    // Emitted flux in the course convention: 4π × intensity (photon powers sum to it).
    let emitted = 4.0 * std::f32::consts::PI;
    assert!(map.len() > 10_000);
    assert!(
        stored.max_element() <= emitted * 1.001,
        "stored {stored:?} > emitted {emitted}"
    );
    assert!(
        stored.max_element() > 0.01 * emitted,
        "the caustics carry real power: {stored:?}"
    );
    assert!(stored.z < stored.x, "photons take the mirror's colour");
}

fn direct_light_at(scene: &caustica::scene::Scene, p: Vec3) -> f32 {
    scene
        .lights()
        .iter()
        .map(|l| {
            let s = l.sample_li(p).unwrap();
            let shadow = transmittance(scene, p, Vec3::Z, s.wi, s.distance);
            (s.intensity * shadow * s.wi.dot(Vec3::Z).max(0.0)).x
        })
        .sum()
}

#[test]
fn first_hit_photons_reproduce_direct_light_from_point_and_directional_lights() {
    let text = "SBT-raytracer 1.0
point_light { position = (1, -1, 4); color = (1, 1, 1);
  constant_attenuation_coeff = 0.25; linear_attenuation_coeff = 0.003372407; quadratic_attenuation_coeff = 0.000045492; }
directional_light { direction = (-1, 0.5, -2); color = (0.4, 0.4, 0.4); }
scale(12, square { material = { diffuse = (1, 1, 1); } })
";
    let scene = common::scene(text);
    let settings = PhotonSettings {
        first_hit: true,
        aim: false,
        ..photons(2_000_000)
    };
    let map = trace(&scene, settings, 300);
    let estimate = smooth();
    for p in [
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(2.0, -1.0, 0.0),
        Vec3::new(-2.5, 2.0, 0.0),
        Vec3::new(1.0, 3.0, 0.0),
    ] {
        let want = direct_light_at(&scene, p);
        let got = map.flux_density(&scene, p, Vec3::Z, &estimate).x;
        assert!(
            common::rel(got, want) < 0.04,
            "at {p:?}: photons {got}, shadow rays {want}"
        );
    }
    // The course's falloff is carried by the photons: check it is far from inverse-square here.
    let d = (Vec3::new(1.0, -1.0, 4.0)).length();
    assert!(distance_attenuation([0.25, 0.003372407, 0.000045492], d) > 2.0 / (d * d));
}

#[test]
fn no_light_bleeds_through_a_thin_wall() {
    // A mirror throws light onto the floor on the +x side of a thin wall at x = 0; the floor just
    // behind the wall (−x side) is in shadow and must stay dark.
    let text = "SBT-raytracer 1.0
point_light { position = (1.5, 0, 4); color = (1, 1, 1);
  constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }
translate(3, 0, 2.5, rotate(0, 1, 0, 1.5707963, scale(3, 6, 1, square { material = { reflective = (1, 1, 1); } })))
translate(0, 0, 1, scale(0.02, 6, 2, box { material = { diffuse = (1, 1, 1); } }))
scale(20, square { material = { diffuse = (1, 1, 1); } })
";
    let scene = common::scene(text);
    // Both estimates: k nearest photons, and photons spread over their own kernels (those
    // beside the wall reach across it).
    for estimator in [Estimator::Nearest, Estimator::Kernels] {
        let estimate = EstimateSettings {
            estimator,
            k: 100,
            max_radius: Some(0.5),
            ..EstimateSettings::default()
        };
        let map = trace_for(&scene, photons(100_000), &estimate);
        let lit = map.flux_density(&scene, Vec3::new(0.1, 0.0, 0.0), Vec3::Z, &estimate).x;
        let behind = map
            .flux_density(&scene, Vec3::new(-0.1, 0.0, 0.0), Vec3::Z, &estimate)
            .x;
        // The mirror image of the light is at (4.5, 0, 4): irradiance 0.019 at (0.1, 0, 0), of
        // which a gather disc cut in half by the wall sees at least a good part.
        assert!(
            lit > 0.006,
            "{estimator:?}: the lit side receives the mirror's light: {lit}"
        );
        assert!(
            behind < 0.01 * lit,
            "{estimator:?}: light bled through the wall: {behind} vs {lit}"
        );
    }
}

#[test]
fn aimed_and_uniform_emission_give_the_same_caustic() {
    let scene = common::scene(SLAB);
    let aimed = trace(&scene, photons(400_000), 100);
    let uniform = trace(
        &scene,
        PhotonSettings {
            aim: false,
            ..photons(400_000)
        },
        100,
    );
    assert!(
        aimed.stats.useful_fraction() > 2.0 * uniform.stats.useful_fraction(),
        "aiming wastes fewer photons"
    );
    let settings = smooth();
    for p in [Vec3::new(0.2, 0.1, 0.0), Vec3::new(-0.5, 0.5, 0.0)] {
        let a = aimed.flux_density(&scene, p, Vec3::Z, &settings).x;
        let u = uniform.flux_density(&scene, p, Vec3::Z, &settings).x;
        assert!(common::rel(a, u) < 0.04, "aimed {a} vs uniform {u}");
    }
}

#[test]
fn photon_map_is_identical_with_one_and_two_threads() {
    let scene = common::scene(MIRROR);
    let run = |threads| {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        pool.install(|| trace(&scene, photons(30_000), 50))
    };
    let (one, two) = (run(1), run(2));
    assert_eq!(one.stats.emitted, two.stats.emitted);
    assert_eq!(one.photons(), two.photons());
}

#[test]
fn a_blue_mirror_throws_a_blue_caustic() {
    let text = "SBT-raytracer 1.0
point_light { position = (0, 0, 6); color = (1, 1, 1); }
translate(0, 0, 2, scale(1.5, box { material = { reflective = (0.1, 0.2, 0.9); } }))
translate(0, 0, 8, scale(30, square { material = { diffuse = (1, 1, 1); } }))
scale(30, square { material = { diffuse = (1, 1, 1); } })
";
    let scene = common::scene(text);
    let map = trace(&scene, photons(20_000), 50);
    assert!(map.len() >= 20_000);
    for p in map.photons() {
        let c = p.power();
        assert!(c.z > 4.0 * c.x && c.z > 2.0 * c.y, "{c:?}");
    }
}

#[test]
fn emission_cap_stops_a_pass_that_stores_too_rarely() {
    // A mirror sends the sun sideways; only a small card catches the reflection (about one photon
    // in 300), far too rarely to store the budget within the cap.
    let text = "SBT-raytracer 1.0
directional_light { direction = (0, 0, -1); color = (1, 1, 1); }
translate(0, 0, 2, rotate(0, 1, 0, 0.7853982, scale(4, square { material = { reflective = (1, 1, 1); } })))
translate(5, 0, 2, rotate(0, 1, 0, -1.5707963, scale(0.3, square { material = { diffuse = (1, 1, 1); } })))
";
    let scene = common::scene(text);
    let settings = PhotonSettings {
        max_emitted: 400_000,
        ..photons(10_000)
    };
    let map = trace(&scene, settings, 10);
    assert!(map.stats.cap_reached);
    assert!(map.stats.none.is_none());
    assert!(
        map.stats.emitted <= 400_000 && map.stats.emitted > 390_000,
        "{:?}",
        map.stats
    );
    assert!(map.len() > 100 && map.len() < 10_000, "{}", map.len());
}

#[test]
fn sharing_a_pixels_caustic_estimate_changes_the_image_only_slightly() {
    use caustica::integrator::whitted::{render, WhittedSettings};
    use caustica::integrator::ImageSettings;
    let text = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../scenes/ring.ray")).unwrap();
    let scene = common::scene(&text);
    let estimate = EstimateSettings::default();
    let map = trace_for(&scene, photons(100_000), &estimate);
    let image = ImageSettings {
        width: 96,
        height: 96,
        aa: 3,
        seed: 1,
    };
    let run = |reuse| {
        let settings = WhittedSettings {
            reuse_caustic_estimates: reuse,
            ..WhittedSettings::default()
        };
        render(&scene, Some((&map, &estimate)), &settings, &image, common::control()).0
    };
    let (shared, fresh) = (run(true), run(false));
    let mean = |f: &caustica::film::Film| f.pixels.iter().map(|p| p.element_sum()).sum::<f32>() / f.pixels.len() as f32;
    let diff: f32 = shared
        .pixels
        .iter()
        .zip(&fresh.pixels)
        .map(|(a, b)| (*a - *b).abs().element_sum())
        .sum::<f32>()
        / shared.pixels.len() as f32;
    assert!(
        common::rel(mean(&shared), mean(&fresh)) < 0.005,
        "{} vs {}",
        mean(&shared),
        mean(&fresh)
    );
    assert!(diff < 0.01 * mean(&fresh), "mean absolute difference {diff}");
    assert!(shared != fresh, "the reuse took effect");
}

/// A glass slab with a faint diffuse colour (kd 0.1, kr = kt = 0.7) seen from above under a
/// light from above. The course's value is the diffuse term of the light on each side it is
/// seen from: the top, kd·E = 0.1, plus through the top (weighted kt) the inside of the bottom
/// face, lit through the top: kd·kt·E = 0.07. Caustics must add nothing to it: 0.1 + 0.7 · 0.07
/// = 0.149. (Photons stored inside the glass made it 0.25.)
#[test]
fn faint_diffuse_glass_shows_only_its_diffuse_term() {
    use caustica::integrator::whitted::{render, WhittedSettings};
    use caustica::integrator::ImageSettings;
    let scene = common::scene(
        "SBT-raytracer 1.0
         camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 20; }
         directional_light { direction = (0, 0, -1); color = (1, 1, 1); }
         scale(10, 10, 0.5, box { material = { diffuse = (0.1, 0.1, 0.1); transmissive = (0.7, 0.7, 0.7);
                                               reflective = (0.7, 0.7, 0.7); index = 1.5; } })",
    );
    let estimate = EstimateSettings::default();
    let map = trace_for(&scene, photons(50_000), &estimate);
    let image = ImageSettings {
        width: 16,
        height: 16,
        aa: 1,
        seed: 0,
    };
    let film = render(
        &scene,
        Some((&map, &estimate)),
        &WhittedSettings::default(),
        &image,
        common::control(),
    )
    .0;
    for p in &film.pixels {
        assert!((p.x - 0.149).abs() < 1e-4, "{p:?}");
    }
    // Photons that went through the glass found nothing diffuse outside it to land on.
    assert_eq!(map.len(), 0, "photons stored inside the glass");
    assert!(map.stats.emitted > 0);
}

/// A thin glass ellipsoid (kr = kt = 0.7) traps photons by total internal reflection. Inside,
/// photons choose as camera rays do (refraction only), so their power cannot grow there: at
/// most it gains kt / P(refract) = 0.7 / 0.5 on entering. No stored photon may carry more than
/// 1.4 × what a photon leaves the light with (E·π·R² over the photons emitted, for the disc of
/// radius R they are aimed through), up to the 8-bit mantissa of its stored power. (It was
/// 47,000 times that, 1.4³².)
#[test]
fn photons_gain_no_power_inside_glass() {
    let scene = common::scene(
        "SBT-raytracer 1.0
         directional_light { direction = (0.3, 0.2, -1); color = (1, 1, 1); }
         translate(0, 0, 2, scale(2, 2, 0.3, sphere { material = { diffuse = (0.02, 0.02, 0.02);
             transmissive = (0.7, 0.7, 0.7); reflective = (0.7, 0.7, 0.7); index = 1.5; } }))
         scale(30, square { material = { diffuse = (1, 1, 1); } })",
    );
    let map = trace(&scene, photons(50_000), 100);
    let targets = caustica::light::aim::caustic_targets(&scene);
    assert_eq!(targets.len(), 1);
    let emitted_power = std::f32::consts::PI * targets[0].radius.powi(2) / map.stats.emitted as f32;
    let largest = map
        .photons()
        .iter()
        .map(|p| p.power().max_element())
        .fold(0.0, f32::max);
    assert!(map.len() >= 50_000);
    assert!(
        largest <= 1.4 * emitted_power * (1.0 + 1.0 / 128.0),
        "a photon carries {} times the emitted power",
        largest / emitted_power
    );
    assert!(
        largest >= 1.3 * emitted_power,
        "photons through the glass do carry 1.4×"
    );
    for p in map.photons() {
        assert!(p.position.z.abs() < 1e-3, "stored off the floor: {:?}", p.position);
    }
}
