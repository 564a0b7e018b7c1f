//! Why a course-model render would come out black: a grid of camera rays is traced as the
//! Whitted renderer traces them (without caustics); when none of them brings back light that an
//! 8-bit image can show, the probe says why, so a black picture never goes unexplained.
//!
//! The same probe tells when the render is black or *nearly* black because point and spot lights
//! fall off with distance ([`dimmed_by_falloff`]), which decides whether a file that both course
//! readers accept is read the HKUST way (loader.rs).

use super::whitted::{self, WhittedSettings};
use crate::light::{distance_attenuation, Light};
use crate::math::Vec3;
use crate::scene::Scene;

/// Probe rays across and up the image.
const GRID: usize = 48;

/// The smallest colour an 8-bit image shows as more than black.
const VISIBLE: f32 = 1.0 / 255.0;

/// A render whose brightest probe stays below this is nearly black: 5 % of white is 13 of 255
/// in the course's 8-bit image, which a screen shows at about 0.4 % of its white. Scenes lit as
/// their authors meant are far brighter: their lit surfaces reach tens of percent.
pub const NEARLY_BLACK: f32 = 0.05;

/// Point and spot lights whose distance falloff keeps less than this of their colour on
/// everything the camera sees are what darkens a render (the course's 1/d² beyond 4.5 units).
const FALLOFF_DARK: f32 = 0.05;

/// Why a course render is black.
#[derive(Clone, Debug, PartialEq)]
pub struct Darkness {
    /// The reason, in words.
    pub message: String,
    /// Whether the point and spot lights' distance falloff is what darkens it.
    pub falloff: bool,
}

/// The reason the scene renders black under the course model, or `None` when some probe sees
/// light (or the scene has no light at all, which the scene's own warnings already say).
pub fn diagnose(scene: &Scene) -> Option<String> {
    darkness(scene).map(|d| d.message)
}

/// [`diagnose`], telling the falloff apart from the other causes.
pub fn darkness(scene: &Scene) -> Option<Darkness> {
    let (message, falloff) = probe(scene)?;
    Some(Darkness { message, falloff })
}

/// Whether the course render is black or nearly black (no probe reaches [`NEARLY_BLACK`])
/// because its point and spot lights fall off with distance: on everything the camera sees
/// they keep less than 5 % of their colour, and even unshadowed the direct light stays below
/// [`NEARLY_BLACK`] (so shadows, a missing colour or lights facing away are not the cause).
pub fn dimmed_by_falloff(scene: &Scene) -> bool {
    let survey = survey(scene, NEARLY_BLACK);
    if survey.brightest >= NEARLY_BLACK || survey.hits.is_empty() {
        return false;
    }
    let lights: Vec<&Light> = scene.lights().course_lights().collect();
    let direct = direct_light(scene, &survey.hits, &lights);
    direct.receives
        && direct.unshadowed < NEARLY_BLACK
        && direct.best_falloff > 0.0
        && direct.best_falloff < FALLOFF_DARK
}

/// Whether no probe ray brings back [`NEARLY_BLACK`] or more.
pub fn nearly_black(scene: &Scene) -> bool {
    survey(scene, NEARLY_BLACK).brightest < NEARLY_BLACK
}

/// What the probe rays see.
struct Survey {
    /// The largest colour channel any probe brought back (up to the first at `enough`).
    brightest: f32,
    /// Each surface a probe hit and the probe's direction (all of them unless it stopped early).
    hits: Vec<(crate::scene::SurfaceHit, Vec3)>,
}

/// Traces the probe grid, stopping at the first ray that brings back `enough`.
fn survey(scene: &Scene, enough: f32) -> Survey {
    let settings = WhittedSettings::default();
    let camera = scene.camera();
    let no_caustics =
        |_: &crate::scene::SurfaceHit, _: &crate::material::SurfaceParams, _: Vec3, _: Vec3, _: u32, _: f32| Vec3::ZERO;
    let mut survey = Survey {
        brightest: 0.0,
        hits: Vec::new(),
    };
    for j in 0..GRID {
        for i in 0..GRID {
            let ray = camera.generate_ray((i as f32 + 0.5) / GRID as f32, (j as f32 + 0.5) / GRID as f32);
            let seen = whitted::radiance(scene, &settings, &ray, &no_caustics).max_element();
            survey.brightest = survey.brightest.max(seen);
            if survey.brightest >= enough {
                return survey;
            }
            if let Some(isect) = scene.intersect(&ray, f32::INFINITY) {
                survey.hits.push((scene.surface(&ray, &isect), ray.dir));
            }
        }
    }
    survey
}

/// The direct light on what the probes hit, before shadows.
struct Direct {
    /// The brightest unshadowed direct light anywhere the camera looks.
    unshadowed: f32,
    /// Whether some light is in front of some surface seen.
    facing: bool,
    /// Whether some surface seen has a diffuse or specular colour.
    receives: bool,
    /// The largest distance falloff of a point or spot light on a surface seen.
    best_falloff: f32,
}

fn direct_light(scene: &Scene, hits: &[(crate::scene::SurfaceHit, Vec3)], lights: &[&Light]) -> Direct {
    let mut direct = Direct {
        unshadowed: 0.0,
        facing: false,
        receives: false,
        best_falloff: 0.0,
    };
    for (hit, dir) in hits {
        // The normal on the side the camera sees, as the shading takes it.
        let n = if dir.dot(hit.shading_normal) > 0.0 {
            -hit.shading_normal
        } else {
            hit.shading_normal
        };
        let p = scene.phong(hit);
        let reflectance = p.diffuse.max(p.specular).max_element();
        direct.receives |= reflectance > 0.0;
        for light in lights {
            let Some(ls) = light.sample_li(hit.point) else { continue };
            let cos = n.dot(ls.wi).max(0.0);
            direct.facing |= cos > 0.0;
            if let Light::Point { attenuation, .. } | Light::Spot { attenuation, .. } = light {
                direct.best_falloff = direct.best_falloff.max(distance_attenuation(*attenuation, ls.distance));
            }
            direct.unshadowed = direct.unshadowed.max(ls.intensity.max_element() * reflectance * cos);
        }
    }
    direct
}

fn probe(scene: &Scene) -> Option<(String, bool)> {
    let survey = survey(scene, VISIBLE);
    if survey.brightest >= VISIBLE {
        return None;
    }
    let hits = survey.hits;
    let lights: Vec<&Light> = scene.lights().course_lights().collect();
    if lights.is_empty() && scene.ambient() == Vec3::ZERO {
        return None;
    }
    let black = "the image comes out black";
    if hits.is_empty() {
        return Some((
            format!("{black}: the camera sees no object (every ray from it misses the scene)"),
            false,
        ));
    }
    let Direct {
        unshadowed,
        facing,
        receives,
        best_falloff,
    } = direct_light(scene, &hits, &lights);
    if !receives {
        return Some((
            format!(
            "{black}: what the camera sees has no diffuse or specular colour (kd = ks = 0), so no light shows on it"
        ),
            false,
        ));
    }
    if lights.is_empty() {
        return Some((
            format!("{black}: the scene has only ambient light, and what the camera sees has no ambient colour"),
            false,
        ));
    }
    if unshadowed < VISIBLE {
        let falls_off = lights.iter().any(|l| {
            matches!(l, Light::Point { attenuation, .. } | Light::Spot { attenuation, .. } if *attenuation == [0.0, 0.0, 1.0])
        });
        if best_falloff > 0.0 && best_falloff < FALLOFF_DARK {
            let mut why = format!(
                "{black}: the point lights' distance falloff 1/(a + b·d + c·d²) leaves at most {best_falloff:.2e} of their colour on what the camera sees"
            );
            if falls_off {
                why.push_str(
                    "; files written for the HKUST COMP 4411 ray tracer expect lights without coefficients not to fall off: read them with --dialect hkust",
                );
            }
            return Some((why, true));
        }
        if !facing {
            return Some((
                format!("{black}: every light is behind the surfaces the camera sees"),
                false,
            ));
        }
        return Some((
            format!(
                "{black}: the lights are too dim for what the camera sees (at most {unshadowed:.2e} before shadows)"
            ),
            false,
        ));
    }
    Some((
        format!("{black}: everything the camera sees is in shadow (opaque objects stand between it and every light)"),
        false,
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::build::test_scene;

    const FLOOR: &str = "translate(0, 0, -2, scale(20, square { material = { diffuse = (0.8, 0.8, 0.8); } }))";

    #[test]
    fn a_lit_scene_is_not_reported() {
        let scene = test_scene(&format!(
            "directional_light {{ direction = (0, 0, -1); color = (1,1,1); }} {FLOOR}"
        ));
        assert_eq!(diagnose(&scene), None);
    }

    /// 1/d² at 60 units is 2.8e-4 of a light of colour 1: below an 8-bit step, and the reason
    /// names the falloff and the HKUST reading.
    #[test]
    fn far_point_lights_are_named() {
        let scene = test_scene(&format!(
            "point_light {{ position = (0, 0, 58); color = (1,1,1); }} {FLOOR}"
        ));
        let why = diagnose(&scene).expect("black");
        assert!(why.contains("falloff") && why.contains("--dialect hkust"), "{why}");
        let f = 1.0 / (60.0f32 * 60.0);
        assert!(why.contains(&format!("{f:.2e}")), "{why}");
    }

    /// A light 5 units above the floor keeps 1/25 of its colour there (a falloff below 5 %):
    /// colour 1 leaves the brightest probe at 0.8/25 = 3.2 % of white, colour 2 at 6.4 %, on
    /// either side of the nearly-black threshold of 5 %.
    #[test]
    fn nearly_black_from_falloff_is_told_apart_on_each_side_of_the_threshold() {
        let lit = |color: f32| {
            test_scene(&format!(
                "point_light {{ position = (0, 0, 3); color = ({color}, {color}, {color}); }} {FLOOR}"
            ))
        };
        let dim = lit(1.0);
        assert!(dimmed_by_falloff(&dim) && nearly_black(&dim));
        // Not black to an 8-bit image: the probe that explains black renders says nothing.
        assert_eq!(diagnose(&dim), None);
        let brighter = lit(2.0);
        assert!(!dimmed_by_falloff(&brighter) && !nearly_black(&brighter));
        // Nearly black, but from a dim light close by (it keeps 1/4 of its colour), not falloff.
        let faint = test_scene(&format!(
            "point_light {{ position = (0, 0, 0); color = (0.05, 0.05, 0.05); }} {FLOOR}"
        ));
        assert!(nearly_black(&faint) && !dimmed_by_falloff(&faint));
        // A black render from falloff is one too.
        let far = test_scene(&format!(
            "point_light {{ position = (0, 0, 58); color = (1,1,1); }} {FLOOR}"
        ));
        assert!(dimmed_by_falloff(&far));
    }

    #[test]
    fn shadows_lights_behind_and_empty_views_are_named() {
        let shadowed = test_scene(&format!(
            "directional_light {{ direction = (0, 0, -1); color = (1,1,1); }} {FLOOR}
             translate(0, 0, 3, scale(100, 100, 0.1, box {{ material = {{ diffuse = (1,1,1); }} }}))"
        ));
        // The camera at z = 5 looks at the box's top face, which the light does reach.
        assert_eq!(diagnose(&shadowed), None);
        let under = test_scene(&format!(
            "directional_light {{ direction = (0, 0, -1); color = (1,1,1); }} {FLOOR}
             translate(0, 0, 8, scale(100, 100, 0.1, box {{ material = {{ diffuse = (1,1,1); }} }}))"
        ));
        assert!(diagnose(&under).expect("black").contains("in shadow"));
        let behind = test_scene(&format!(
            "directional_light {{ direction = (0, 0, 1); color = (1,1,1); }} {FLOOR}"
        ));
        assert!(diagnose(&behind).expect("black").contains("behind"));
        let empty = test_scene("directional_light { direction = (0, 0, -1); color = (1,1,1); }");
        assert!(diagnose(&empty).expect("black").contains("sees no object"));
        let mirror = test_scene(
            "directional_light { direction = (0, 0, -1); color = (1,1,1); }
             translate(0, 0, -2, scale(20, square { material = { reflective = (1,1,1); } }))",
        );
        assert!(diagnose(&mirror).expect("black").contains("kd = ks = 0"));
    }
}
