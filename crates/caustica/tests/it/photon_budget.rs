//! The course model's photon pass: how the budget is shared between lights, that it is stored
//! exactly, and that a scene where no caustic can form stops at once and says why.

use crate::common;

use caustica::math::luminance;
use caustica::photon::budget::trace_photons;
use caustica::photon::{EstimateSettings, Estimator, NoCaustics, PhotonMap, PhotonSettings};

fn trace(text: &str, stored: usize) -> PhotonMap {
    let scene = common::scene(text);
    let settings = PhotonSettings {
        target_stored: stored,
        seed: 3,
        ..PhotonSettings::default()
    };
    // Only the photons matter here: the map for the cheaper k-nearest estimate.
    let estimate = EstimateSettings {
        estimator: Estimator::Nearest,
        ..EstimateSettings::default()
    };
    PhotonMap::trace(&scene, &settings, &estimate, common::control())
}

/// A sun and a lamp with the course's gentle falloff both light a mirror over a floor. The
/// lamp's photons are stored with d²·f(d) ≈ 60 times their power (f falls much slower than
/// 1/d²); shared by emitted power the lamp would get a sliver of the budget and its photons
/// would carry a hundred times more each. Shared by the power they deliver, photons of both
/// lights carry about the same (within the pilot's measuring error).
#[test]
fn lights_share_the_budget_so_photons_carry_equal_power() {
    let scene = common::scene(
        "SBT-raytracer 1.0
         directional_light { direction = (-0.5, 0, -1); color = (1, 1, 1); }
         point_light { position = (3, 0, 8); color = (1, 1, 1);
           constant_attenuation_coeff = 0.25; linear_attenuation_coeff = 0.003372407;
           quadratic_attenuation_coeff = 0.000045492; }
         translate(0, 0, 2, rotate(0, 1, 0, 1.5707963, scale(4, 8, 1, square { material = { reflective = (1, 1, 1); } })))
         scale(40, square { material = { diffuse = (1, 1, 1); } })",
    );
    let settings = PhotonSettings {
        target_stored: 40_000,
        seed: 3,
        ..PhotonSettings::default()
    };
    // Before the map is built the photons come light by light, in the order of the stats.
    let (photons, s) = trace_photons(&scene, &settings, common::control());
    assert_eq!(s.stored, 40_000, "{s:?}");
    assert_eq!(s.per_light.iter().map(|l| l.1).sum::<u64>(), 40_000);
    let sun = s.per_light[0].1 as usize;
    let mean_power =
        |ps: &[caustica::photon::Photon]| ps.iter().map(|p| luminance(p.power()) as f64).sum::<f64>() / ps.len() as f64;
    let mean = [mean_power(&photons[..sun]), mean_power(&photons[sun..])];
    assert!(s.per_light.iter().all(|l| l.1 > 1000), "{:?}", s.per_light);
    let ratio = mean[0] / mean[1];
    assert!((0.7..1.4).contains(&ratio), "mean photon power per light {mean:?}");
}

/// The budget asked for is the number stored, also when a path stores several photons and with
/// several lights (it was one path's photons over, and each light's share rounded); "useful"
/// counts emitted photons that stored something, never more than all of them.
#[test]
fn the_budget_is_stored_exactly() {
    let text = "SBT-raytracer 1.0
        point_light { position = (0, 0, 6); color = (1, 1, 1); }
        point_light { position = (1, 2, 6); color = (0.3, 0.6, 1); }
        translate(0, 0, 2, sphere { material = { diffuse = (0.3, 0.3, 0.3); reflective = (0.6, 0.6, 0.6);
                                                 transmissive = (0.3, 0.3, 0.3); index = 1.3; } })
        translate(1.5, 0, 1, scale(0.7, box { material = { diffuse = (0.5, 0.5, 0.5); reflective = (0.5, 0.5, 0.5); } }))
        scale(30, square { material = { diffuse = (1, 1, 1); } })";
    for budget in [1, 255, 256, 257, 10_000, 10_001] {
        let map = trace(text, budget);
        let s = &map.stats;
        assert_eq!((map.len(), s.stored as usize), (budget, budget));
        assert!(s.landed <= s.emitted && s.landed <= s.stored && s.landed > 0, "{s:?}");
        assert!(s.useful_fraction() <= 1.0);
        if budget >= 10_000 {
            assert!(s.stored > s.landed, "paths do store several photons here: {s:?}");
        }
    }
}

#[test]
fn scenes_without_caustics_stop_at_once_and_say_why() {
    let cases = [
        (
            "scale(2, box { material = { reflective = (0.8, 0.8, 0.8); } })",
            NoCaustics::NoReceiver,
        ),
        ("scale(20, square { material = { diffuse = (1, 1, 1); } })", NoCaustics::NoSpecular),
        // A convex mirror cannot light itself, and nothing else is there.
        (
            "sphere { material = { diffuse = (0.5, 0.5, 0.5); reflective = (0.8, 0.8, 0.8); } }",
            NoCaustics::NoneLanded { emitted: 65_536 },
        ),
        // Glass over nothing.
        (
            "scale(1, 1, 0.3, sphere { material = { diffuse = (0.1, 0.1, 0.1); transmissive = (0.9, 0.9, 0.9); index = 1.5; } })",
            NoCaustics::NoneLanded { emitted: 65_536 },
        ),
    ];
    for (objects, reason) in cases {
        let map = trace(
            &format!(
                "SBT-raytracer 1.0\ndirectional_light {{ direction = (0, 0.3, -1); color = (1, 1, 1); }}\n{objects}"
            ),
            200_000,
        );
        assert_eq!(map.stats.none, Some(reason), "{objects}");
        assert_eq!(map.len(), 0);
        let emitted = match reason {
            NoCaustics::NoneLanded { emitted } => emitted,
            _ => 0,
        };
        assert_eq!(map.stats.emitted, emitted, "{objects}: stopped after the pilot");
    }
    let lit = trace(
        "SBT-raytracer 1.0\npoint_light { position = (0, 0, 1); color = (1, 1, 1); }",
        1000,
    );
    assert_eq!(lit.stats.none, Some(NoCaustics::NoSpecular));
    let dark = trace(
        "SBT-raytracer 1.0
         point_light { position = (0, 0, 4); color = (0, 0, 0); }
         sphere { material = { reflective = (1, 1, 1); } }
         scale(20, square { material = { diffuse = (1, 1, 1); } })",
        1000,
    );
    assert_eq!(dark.stats.none, Some(NoCaustics::NoLight));
}
