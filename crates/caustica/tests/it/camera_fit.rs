//! An image whose aspect differs from the camera's is cropped or extended by each format's rule,
//! never stretched: a sphere stays round, a square stays square, at the size its field of view
//! gives.

use crate::common::{render_with, scene};
use crate::formats::base64;
use caustica::film::Film;
use caustica::integrator::RenderConfig;
use caustica::loader::{load, LoadSettings};
use caustica::scene::Scene;
use std::path::PathBuf;

fn render(scene: &Scene, integrator: Option<&str>, width: usize, height: usize) -> Film {
    let config = RenderConfig {
        model: integrator.map(|_| caustica::integrator::config::Model::Physical),
        integrator: integrator.map(|i| i.parse().unwrap()),
        width,
        height: Some(height),
        passes: integrator.map(|_| "1".to_string()),
        ..RenderConfig::default()
    };
    render_with(scene, &config)
}

/// The lit object's extent in pixels: (columns, rows) holding any pixel brighter than 0.1.
fn extent(film: &Film) -> (usize, usize) {
    let lit = |x: usize, y: usize| film.pixel(x, y).max_element() > 0.1;
    let cols = (0..film.width).filter(|&x| (0..film.height).any(|y| lit(x, y))).count();
    let rows = (0..film.height).filter(|&y| (0..film.width).any(|x| lit(x, y))).count();
    (cols, rows)
}

/// An object of half-size `half` on the image plane at unit distance spans `half / span` of an
/// axis whose field of view spans `span` at unit distance.
fn pixels(half: f32, span: f32, axis_pixels: usize) -> f32 {
    2.0 * half / span * axis_pixels as f32
}

fn close(got: usize, want: f32, what: &str) {
    assert!(
        (got as f32 - want).abs() <= 2.0,
        "{what}: {got} pixels, {want:.1} expected"
    );
}

fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-camera-fit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A course camera with a 16:9 frame rendered square keeps its vertical field of view: a unit
/// sphere 5 away (silhouette half-size tan(asin(1/5)) at unit distance) is as wide as it is tall.
#[test]
fn a_course_camera_keeps_its_vertical_field_of_view_in_a_square_image() {
    let s = scene(
        "SBT-raytracer 1.0
camera { position = (0, 0, 5); viewdir = (0, 0, -1); updir = (0, 1, 0); fov = 30; aspectratio = 1.7777778; }
directional_light { direction = (0, 0, -1); color = (1, 1, 1); }
sphere { material = { diffuse = (1, 1, 1); } }",
    );
    let note = s
        .camera()
        .fit_note(64, 64)
        .expect("a square image of a 16:9 camera is noted");
    assert!(note.contains("cropped at the sides"), "{note}");
    assert!(
        s.camera().fit_note(64, 36).is_none(),
        "the camera's own aspect needs no note"
    );
    let want = pixels((1.0f32 / 5.0).asin().tan(), 2.0 * 15f32.to_radians().tan(), 64);
    let (w, h) = extent(&render(&s, None, 64, 64));
    close(w, want, "width");
    close(h, want, "height");
    // Wider than the camera: the sides are extended, the sphere the same size.
    let (w, h) = extent(&render(&s, None, 128, 64));
    close(w, want, "width in a 2:1 image");
    close(h, want, "height in a 2:1 image");
}

/// A glTF camera with `aspectRatio` 16:9 rendered square: `yfov` stays vertical, so an emissive
/// 2×2 square 5 away covers 0.4 / (2 tan(yfov/2)) of both axes.
#[test]
fn a_gltf_camera_keeps_yfov_in_a_square_image() {
    let positions: [f32; 12] = [-1.0, -1.0, 0.0, 1.0, -1.0, 0.0, 1.0, 1.0, 0.0, -1.0, 1.0, 0.0];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut buffer: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    buffer.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let gltf = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
"nodes":[{{"mesh":0}},{{"camera":0,"translation":[0,0,5]}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.5,"aspectRatio":1.7777778,"znear":0.1}}}}],
"materials":[{{"emissiveFactor":[1,1,1],"pbrMetallicRoughness":{{"baseColorFactor":[0,0,0,1]}}}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":1,"material":0}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[-1,-1,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":12}}],
"buffers":[{{"byteLength":60,"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        base64(&buffer)
    );
    let s = load(&temp_file("square.gltf", &gltf), &LoadSettings::default()).unwrap();
    let want = pixels(0.2, 2.0 * 0.25f32.tan(), 64);
    let (w, h) = extent(&render(&s, Some("path"), 64, 64));
    close(w, want, "width");
    close(h, want, "height");
}

/// A pbrt camera whose film is 16:9 rendered 9:16: `fov` spans the shorter axis, now the
/// horizontal one, so the square covers 0.4 / (2 tan 15°) of the width and keeps its shape.
#[test]
fn a_pbrt_camera_spans_the_shorter_axis_in_a_portrait_image() {
    let pbrt = r#"LookAt 0 0 5  0 0 0  0 1 0
Camera "perspective" "float fov" 30
Film "rgb" "integer xresolution" 96 "integer yresolution" 54
WorldBegin
AttributeBegin
AreaLightSource "diffuse" "rgb L" [1 1 1] "bool twosided" true
Shape "trianglemesh" "point3 P" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] "integer indices" [0 1 2 0 2 3]
AttributeEnd
"#;
    let s = load(&temp_file("square.pbrt", pbrt), &LoadSettings::default()).unwrap();
    let span = 2.0 * 15f32.to_radians().tan();
    let (w, h) = extent(&render(&s, Some("path"), 96, 54));
    close(w, pixels(0.2, span, 54), "width in the film's own 96×54");
    close(h, pixels(0.2, span, 54), "height in the film's own 96×54");
    let note = s
        .camera()
        .fit_note(54, 96)
        .expect("a portrait image of a landscape film is noted");
    assert!(note.contains("shorter side"), "{note}");
    let (w, h) = extent(&render(&s, Some("path"), 54, 96));
    close(w, pixels(0.2, span, 54), "width in 54×96");
    close(h, pixels(0.2, span, 54), "height in 54×96");
}
