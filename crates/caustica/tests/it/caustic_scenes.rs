//! Scenes from outside the course format render with the caustic they should have: the pbrt-v4
//! glass ball in `scenes/glass_caustic.pbrt`, written from pbrt-v4's documentation, and the same
//! scene as a GLB laid out the way Blender's glTF exporter writes one.
//!
//! Both put a glass ball of radius R = 0.3 on the floor in sunlight 48.2° from the zenith: a ball
//! lens of index 1.5 focuses 1.5 R from its centre, so the sun's image falls on the floor at
//! F = centre + 1.5 R · sun direction. The floor there must be several times brighter than open,
//! sunlit floor.

use crate::common::{control, uv_sphere};
use caustica::film::Film;
use caustica::integrator::config::{IntegratorKind, Model};
use caustica::integrator::{RenderConfig, RenderSession};
use caustica::loader::{load, LoadSettings};
use caustica::scene::Scene;
use glam::{Mat3, Quat, Vec3};
use std::path::{Path, PathBuf};

const SUN: Vec3 = Vec3::new(0.7454, -0.6667, 0.0);
const CENTRE: Vec3 = Vec3::new(0.0, 0.3, 0.0);

fn focus() -> Vec3 {
    CENTRE + 0.45 * SUN.normalize()
}

fn render(scene: &Scene, physical: bool) -> Film {
    let mut config = RenderConfig::for_scene(scene.hints());
    config.width = 96;
    config.height = Some(96);
    if physical {
        config.model = Some(Model::Physical);
        config.integrator = Some(IntegratorKind::Ppm);
        config.passes = Some("12".into());
        config.photons = 100_000;
    } else {
        config.model = Some(Model::Course);
        config.integrator = Some(IntegratorKind::Whitted);
        config.passes = None;
        config.photons = 100_000;
        config.radius = None;
    }
    let mut session = RenderSession::new(scene, config.render_options("caustic").unwrap()).unwrap();
    session.run(&config.plan().unwrap(), control(), |_| Ok(())).unwrap();
    session.image()
}

/// Mean luminance of the 5×5 pixels around where `p` lands.
fn around(scene: &Scene, film: &Film, p: Vec3) -> f32 {
    let (sx, sy) = scene.camera().project(p).expect("in front of the camera");
    let (x, y) = (
        (sx * film.width as f32) as i64,
        ((1.0 - sy) * film.height as f32) as i64,
    );
    let mut sum = 0.0;
    let mut n = 0;
    for dy in -2..=2 {
        for dx in -2..=2 {
            let (px, py) = (x + dx, y + dy);
            if px >= 0 && py >= 0 && (px as usize) < film.width && (py as usize) < film.height {
                let c = film.pixel(px as usize, py as usize);
                sum += 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
                n += 1;
            }
        }
    }
    assert!(n > 0, "{p:?} is outside the image");
    sum / n as f32
}

fn check(scene: &Scene, what: &str) {
    // Open floor, sunlit, away from the ball and its shadow.
    let open = Vec3::new(0.6, 0.0, 0.6);
    for physical in [true, false] {
        let film = render(scene, physical);
        let (caustic, floor) = (around(scene, &film, focus()), around(scene, &film, open));
        let ratio = caustic / floor;
        eprintln!("{what} physical={physical}: caustic {caustic:.3}, open floor {floor:.3}, ratio {ratio:.2}");
        // PNG tone mapping is not applied here: these are linear (course: clamped-free) values.
        assert!(
            ratio > 3.0,
            "{what} (physical {physical}): the caustic is only {ratio:.2}× the open floor"
        );
    }
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

#[test]
fn the_pbrt_glass_ball_focuses_the_sun() {
    let path = root().join("scenes/glass_caustic.pbrt");
    let scene = load(&path, &LoadSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    assert!(scene.warnings().is_empty(), "{:?}", scene.warnings());
    assert_eq!(scene.hints().width, Some(256));
    check(&scene, "glass_caustic.pbrt");
    // Orientation: pbrt's LookAt puts up × (look − eye) on the image's right (its camera space
    // is left-handed), so the red box at (0.2, 0.15, −0.9) falls left of the image's centre
    // from the eye at (1.6, 1.3, 1.4); a right-handed reading would mirror it to the right.
    let box_centre = Vec3::new(0.2, 0.15, -0.9);
    let (sx, sy) = scene.camera().project(box_centre).expect("in front of the camera");
    assert!(sx < 0.5, "the box projects to x = {sx}");
    let film = render(&scene, false);
    // Red pixels within 4 of where a point projects (the box's faces away from the sun are dark).
    let red = |sx: f32| {
        let (cx, cy) = (
            (sx * film.width as f32) as i64,
            ((1.0 - sy) * film.height as f32) as i64,
        );
        (-4..=4)
            .flat_map(|dy| (-4..=4).map(move |dx| (cx + dx, cy + dy)))
            .any(|(x, y)| {
                let p = film.pixel(
                    x.clamp(0, film.width as i64 - 1) as usize,
                    y.clamp(0, film.height as i64 - 1) as usize,
                );
                p.x > 0.05 && p.x > 3.0 * p.y.max(p.z)
            })
    };
    assert!(
        red(sx) && !red(1.0 - sx),
        "the red box is drawn at x = {sx}, not mirrored"
    );
}

/// The scene as Blender 4's exporter writes it to a .glb: Y up, a camera node with a rotation
/// and the render's aspect ratio, the sun as a directional light of 683 lux per W/m², glass as
/// a Principled BSDF with full transmission (KHR_materials_transmission; no volume, no ior at
/// the default 1.5), the floor a rough dielectric, meshes with normals and 16-bit indices in the
/// binary chunk, names everywhere.
fn blender_glb() -> Vec<u8> {
    let mut bin: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push = |bin: &mut Vec<u8>, bytes: &[u8], target: u32| {
        bin.resize(bin.len().next_multiple_of(4), 0);
        let start = bin.len();
        bin.extend_from_slice(bytes);
        views.push(format!(
            "{{\"buffer\":0,\"byteOffset\":{start},\"byteLength\":{},\"target\":{target}}}",
            bytes.len()
        ));
        views.len() - 1
    };
    let mut mesh = |bin: &mut Vec<u8>, points: &[Vec3], normals: &[Vec3], indices: &[u16]| {
        let f = |v: &[Vec3]| {
            v.iter()
                .flat_map(|p| p.to_array())
                .flat_map(f32::to_le_bytes)
                .collect::<Vec<u8>>()
        };
        let (lo, hi) = points
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(a, b), p| {
                (a.min(*p), b.max(*p))
            });
        let pv = push(bin, &f(points), 34962);
        let nv = push(bin, &f(normals), 34962);
        let iv = push(
            bin,
            &indices.iter().flat_map(|i| i.to_le_bytes()).collect::<Vec<u8>>(),
            34963,
        );
        let base = accessors.len();
        accessors.push(format!(
            "{{\"bufferView\":{pv},\"componentType\":5126,\"count\":{},\"max\":[{},{},{}],\"min\":[{},{},{}],\"type\":\"VEC3\"}}",
            points.len(), hi.x, hi.y, hi.z, lo.x, lo.y, lo.z
        ));
        accessors.push(format!(
            "{{\"bufferView\":{nv},\"componentType\":5126,\"count\":{},\"type\":\"VEC3\"}}",
            normals.len()
        ));
        accessors.push(format!(
            "{{\"bufferView\":{iv},\"componentType\":5123,\"count\":{},\"type\":\"SCALAR\"}}",
            indices.len()
        ));
        base
    };
    let plane = [
        Vec3::new(-4.0, 0.0, 4.0),
        Vec3::new(4.0, 0.0, 4.0),
        Vec3::new(-4.0, 0.0, -4.0),
        Vec3::new(4.0, 0.0, -4.0),
    ];
    let floor = mesh(&mut bin, &plane, &[Vec3::Y; 4], &[0, 1, 3, 0, 3, 2]);
    let (sp, sn, si) = uv_sphere(0.3, 32, 64);
    let ball = mesh(&mut bin, &sp, &sn, &si);
    bin.resize(bin.len().next_multiple_of(4), 0);
    // Camera and sun as node rotations taking −z to where they look.
    let look = |dir: Vec3| {
        let dir = dir.normalize();
        let right = dir.cross(Vec3::Y).normalize();
        Quat::from_mat3(&Mat3::from_cols(right, right.cross(dir), -dir))
    };
    let eye = Vec3::new(1.6, 1.3, 1.4);
    let cam = look(Vec3::new(0.25, 0.1, 0.0) - eye);
    let sun = look(SUN);
    let json = format!(
        r#"{{"asset":{{"generator":"Khronos glTF Blender I/O v4.2.69","version":"2.0"}},
"extensionsUsed":["KHR_lights_punctual","KHR_materials_transmission"],
"extensions":{{"KHR_lights_punctual":{{"lights":[{{"color":[1,0.9667,0.9],"intensity":{},"type":"directional","name":"Sun"}}]}}}},
"scene":0,"scenes":[{{"name":"Scene","nodes":[0,1,2,3]}}],
"nodes":[{{"mesh":0,"name":"Plane"}},{{"mesh":1,"name":"Sphere","translation":[0,0.3,0]}},
{{"camera":0,"name":"Camera","rotation":[{},{},{},{}],"translation":[{},{},{}]}},
{{"extensions":{{"KHR_lights_punctual":{{"light":0}}}},"name":"Light","rotation":[{},{},{},{}],"translation":[-2,3,0]}}],
"cameras":[{{"name":"Camera","type":"perspective","perspective":{{"aspectRatio":1.0,"yfov":0.6981317,"zfar":100,"znear":0.1}}}}],
"materials":[{{"doubleSided":true,"name":"Floor","pbrMetallicRoughness":{{"baseColorFactor":[0.8,0.8,0.8,1],"metallicFactor":0,"roughnessFactor":0.5}}}},
{{"doubleSided":true,"name":"Glass","extensions":{{"KHR_materials_transmission":{{"transmissionFactor":1}}}},"pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,1],"metallicFactor":0,"roughnessFactor":0}}}}],
"meshes":[{{"name":"Plane","primitives":[{{"attributes":{{"POSITION":{},"NORMAL":{}}},"indices":{},"material":0}}]}},
{{"name":"Sphere","primitives":[{{"attributes":{{"POSITION":{},"NORMAL":{}}},"indices":{},"material":1}}]}}],
"accessors":[{}],"bufferViews":[{}],"buffers":[{{"byteLength":{}}}]}}"#,
        3.0 * caustica::format::gltf::LUMENS_PER_WATT,
        cam.x,
        cam.y,
        cam.z,
        cam.w,
        eye.x,
        eye.y,
        eye.z,
        sun.x,
        sun.y,
        sun.z,
        sun.w,
        floor,
        floor + 1,
        floor + 2,
        ball,
        ball + 1,
        ball + 2,
        accessors.join(","),
        views.join(","),
        bin.len()
    );
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&bin);
    glb
}

#[test]
fn a_blender_style_glb_glass_ball_focuses_the_sun() {
    let dir = std::env::temp_dir().join(format!("caustica-blender-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("ball.glb");
    std::fs::write(&path, blender_glb()).unwrap();
    let scene = load(&path, &LoadSettings::default()).unwrap_or_else(|e| panic!("{e}"));
    // The closed glass mesh without KHR_materials_volume is read as solid glass, and says so.
    assert!(
        scene.warnings().iter().any(|w| w.contains("solid glass")),
        "{:?}",
        scene.warnings()
    );
    assert!(scene.hints().physical);
    check(&scene, "ball.glb");
}
