//! One scene — a matte floor, a red box and a glass gem under a point light — written in each
//! format caustica reads (.ray, pbrt-v4, glTF, OBJ with the camera and light as options) renders
//! to the same image within noise, in the course model and the physical one.
//!
//! "Within noise": the images of the other formats differ from the .ray one by no more (RMS
//! over the pixels) than the .ray image differs from itself rendered with another seed, and
//! their means agree within 1%.

use crate::common::control;
use caustica::description::LightDesc;
use caustica::film::Film;
use caustica::format::obj::{CameraRequest, SceneOptions};
use caustica::format::ReadOptions;
use caustica::integrator::config::{IntegratorKind, Model};
use caustica::integrator::{RenderConfig, RenderSession};
use caustica::loader::{load, LoadSettings};
use glam::{Mat3, Quat, Vec3};
use std::fmt::Write;
use std::path::{Path, PathBuf};

const EYE: Vec3 = Vec3::new(0.0, 1.2, 3.2);
const TARGET: Vec3 = Vec3::new(0.0, 0.3, 0.0);
const FOV: f32 = 40.0;
const LIGHT: Vec3 = Vec3::new(1.0, 2.2, 1.0);
const INTENSITY: f32 = 6.0;

struct Mesh {
    points: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    /// 0 floor, 1 red, 2 glass.
    material: usize,
}

fn meshes() -> Vec<Mesh> {
    let floor = Mesh {
        points: vec![
            Vec3::new(-3.0, 0.0, -3.0),
            Vec3::new(3.0, 0.0, -3.0),
            Vec3::new(3.0, 0.0, 3.0),
            Vec3::new(-3.0, 0.0, 3.0),
        ],
        triangles: vec![[0, 2, 1], [0, 3, 2]],
        material: 0,
    };
    // A box on the left of the image: the test would see a mirrored image.
    let (c, h) = (Vec3::new(-1.1, 0.25, -0.4), 0.25);
    let corner = |i: u32| {
        c + h * Vec3::new(
            if i & 1 != 0 { 1.0 } else { -1.0 },
            if i & 2 != 0 { 1.0 } else { -1.0 },
            if i & 4 != 0 { 1.0 } else { -1.0 },
        )
    };
    let cube = Mesh {
        points: (0..8).map(corner).collect(),
        triangles: vec![
            [0, 2, 3],
            [0, 3, 1],
            [4, 5, 7],
            [4, 7, 6],
            [0, 1, 5],
            [0, 5, 4],
            [2, 6, 7],
            [2, 7, 3],
            [0, 4, 6],
            [0, 6, 2],
            [1, 3, 7],
            [1, 7, 5],
        ],
        material: 1,
    };
    // A gem: an icosahedron split once and pushed onto a sphere of radius 0.4 at (0, 0.4, 0).
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut points: Vec<Vec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| Vec3::new(x, y, z).normalize())
    .collect();
    let faces: [[u32; 3]; 20] = [
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    let mut triangles = Vec::new();
    let mut middle = std::collections::HashMap::new();
    let mut mid = |a: u32, b: u32, points: &mut Vec<Vec3>| {
        *middle.entry((a.min(b), a.max(b))).or_insert_with(|| {
            points.push((points[a as usize] + points[b as usize]).normalize());
            (points.len() - 1) as u32
        })
    };
    for [a, b, c] in faces {
        let (ab, bc, ca) = (mid(a, b, &mut points), mid(b, c, &mut points), mid(c, a, &mut points));
        triangles.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
    }
    let gem = Mesh {
        points: points.iter().map(|p| *p * 0.4 + Vec3::new(0.0, 0.4, 0.0)).collect(),
        triangles,
        material: 2,
    };
    vec![floor, cube, gem]
}

const COLOURS: [Vec3; 2] = [Vec3::new(0.7, 0.7, 0.7), Vec3::new(0.7, 0.1, 0.1)];

fn v3(v: Vec3) -> String {
    format!("{} {} {}", v.x, v.y, v.z)
}

fn ray_file(meshes: &[Mesh]) -> String {
    let mut s = format!(
        "SBT-raytracer 1.0\ncamera {{ position = ({}); look_at = ({}); updir = (0,1,0); fov = {FOV}; aspectratio = 1; }}\n\
         point_light {{ position = ({}); color = ({INTENSITY}, {INTENSITY}, {INTENSITY}); }}\n",
        v3(EYE).replace(' ', ","),
        v3(TARGET).replace(' ', ","),
        v3(LIGHT).replace(' ', ",")
    );
    for m in meshes {
        let points: Vec<String> = m
            .points
            .iter()
            .map(|p| format!("({})", v3(*p).replace(' ', ",")))
            .collect();
        let faces: Vec<String> = m
            .triangles
            .iter()
            .map(|t| format!("({},{},{})", t[0], t[1], t[2]))
            .collect();
        let material = match m.material {
            2 => "transmissive = (1,1,1); index = 1.5;".to_string(),
            k => format!("diffuse = ({});", v3(COLOURS[k]).replace(' ', ",")),
        };
        writeln!(
            s,
            "polymesh {{ points = ({}); faces = ({}); material = {{ {material} }} }}",
            points.join(","),
            faces.join(",")
        )
        .unwrap();
    }
    s
}

fn pbrt_file(meshes: &[Mesh]) -> String {
    // pbrt's camera is left-handed: the mirroring scale gives the image a right-handed
    // renderer makes of the same numbers (what exporters to pbrt write).
    let mut s = format!(
        "Scale -1 1 1\nLookAt {}  {}  0 1 0\nCamera \"perspective\" \"float fov\" [{FOV}]\n\
         Film \"rgb\" \"integer xresolution\" [48] \"integer yresolution\" [48]\nWorldBegin\n\
         LightSource \"point\" \"point3 from\" [{}] \"rgb I\" [{INTENSITY} {INTENSITY} {INTENSITY}]\n",
        v3(EYE),
        v3(TARGET),
        v3(LIGHT)
    );
    for m in meshes {
        let material = match m.material {
            2 => "Material \"dielectric\" \"float eta\" 1.5".to_string(),
            k => format!("Material \"diffuse\" \"rgb reflectance\" [{}]", v3(COLOURS[k])),
        };
        let points: Vec<String> = m.points.iter().map(|p| v3(*p)).collect();
        let indices: Vec<String> = m
            .triangles
            .iter()
            .map(|t| format!("{} {} {}", t[0], t[1], t[2]))
            .collect();
        writeln!(
            s,
            "AttributeBegin\n{material}\nShape \"trianglemesh\" \"point3 P\" [{}] \"integer indices\" [{}]\nAttributeEnd",
            points.join(" "),
            indices.join(" ")
        )
        .unwrap();
    }
    s
}

pub(crate) fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

fn gltf_file(meshes: &[Mesh]) -> String {
    let mut buffer = Vec::new();
    let (mut views, mut accessors, mut gltf_meshes, mut nodes) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for (i, m) in meshes.iter().enumerate() {
        let start = buffer.len();
        for p in &m.points {
            for c in p.to_array() {
                buffer.extend(c.to_le_bytes());
            }
        }
        let (lo, hi) = m
            .points
            .iter()
            .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(a, b), p| {
                (a.min(*p), b.max(*p))
            });
        views.push(format!(
            "{{\"buffer\":0,\"byteOffset\":{start},\"byteLength\":{}}}",
            buffer.len() - start
        ));
        accessors.push(format!(
            "{{\"bufferView\":{},\"componentType\":5126,\"count\":{},\"type\":\"VEC3\",\"min\":[{}],\"max\":[{}]}}",
            views.len() - 1,
            m.points.len(),
            v3(lo).replace(' ', ","),
            v3(hi).replace(' ', ",")
        ));
        let start = buffer.len();
        for t in &m.triangles {
            for i in t {
                buffer.extend(i.to_le_bytes());
            }
        }
        views.push(format!(
            "{{\"buffer\":0,\"byteOffset\":{start},\"byteLength\":{}}}",
            buffer.len() - start
        ));
        accessors.push(format!(
            "{{\"bufferView\":{},\"componentType\":5125,\"count\":{},\"type\":\"SCALAR\"}}",
            views.len() - 1,
            m.triangles.len() * 3
        ));
        gltf_meshes.push(format!(
            "{{\"primitives\":[{{\"attributes\":{{\"POSITION\":{}}},\"indices\":{},\"material\":{}}}]}}",
            accessors.len() - 2,
            accessors.len() - 1,
            m.material
        ));
        nodes.push(format!("{{\"mesh\":{i}}}"));
    }
    // The camera node: −z towards the target, +y up.
    let dir = (TARGET - EYE).normalize();
    let right = dir.cross(Vec3::Y).normalize();
    let up = right.cross(dir);
    let q = Quat::from_mat3(&Mat3::from_cols(right, up, -dir));
    nodes.push(format!(
        "{{\"camera\":0,\"translation\":[{}],\"rotation\":[{},{},{},{}]}}",
        v3(EYE).replace(' ', ","),
        q.x,
        q.y,
        q.z,
        q.w
    ));
    nodes.push(format!(
        "{{\"translation\":[{}],\"extensions\":{{\"KHR_lights_punctual\":{{\"light\":0}}}}}}",
        v3(LIGHT).replace(' ', ",")
    ));
    let diffuse = |c: Vec3| {
        format!(
            "{{\"pbrMetallicRoughness\":{{\"baseColorFactor\":[{},1],\"metallicFactor\":0,\"roughnessFactor\":1}},\
             \"extensions\":{{\"KHR_materials_specular\":{{\"specularFactor\":0}}}}}}",
            v3(c).replace(' ', ",")
        )
    };
    let glass = "{\"pbrMetallicRoughness\":{\"metallicFactor\":0,\"roughnessFactor\":0},\"extensions\":{\
        \"KHR_materials_transmission\":{\"transmissionFactor\":1},\"KHR_materials_ior\":{\"ior\":1.5},\
        \"KHR_materials_volume\":{\"thicknessFactor\":0.8}}}";
    let node_list: Vec<String> = (0..nodes.len()).map(|i| i.to_string()).collect();
    format!(
        "{{\"asset\":{{\"version\":\"2.0\"}},\"scene\":0,\"scenes\":[{{\"nodes\":[{}]}}],\"nodes\":[{}],\
         \"meshes\":[{}],\"materials\":[{},{},{glass}],\
         \"cameras\":[{{\"type\":\"perspective\",\"perspective\":{{\"yfov\":{},\"aspectRatio\":1,\"znear\":0.01}}}}],\
         \"extensionsUsed\":[\"KHR_lights_punctual\",\"KHR_materials_specular\",\"KHR_materials_transmission\",\"KHR_materials_ior\",\"KHR_materials_volume\"],\
         \"extensions\":{{\"KHR_lights_punctual\":{{\"lights\":[{{\"type\":\"point\",\"intensity\":{}}}]}}}},\
         \"accessors\":[{}],\"bufferViews\":[{}],\
         \"buffers\":[{{\"byteLength\":{},\"uri\":\"data:application/octet-stream;base64,{}\"}}]}}",
        node_list.join(","),
        nodes.join(","),
        gltf_meshes.join(","),
        diffuse(COLOURS[0]),
        diffuse(COLOURS[1]),
        FOV.to_radians(),
        INTENSITY * caustica::format::gltf::LUMENS_PER_WATT,
        accessors.join(","),
        views.join(","),
        buffer.len(),
        base64(&buffer)
    )
}

fn obj_files(meshes: &[Mesh]) -> (String, String) {
    let mut obj = String::from("mtllib scene.mtl\n");
    let mut base = 1;
    for (m, name) in meshes.iter().zip(["floor", "red", "glass"]) {
        writeln!(obj, "o {name}\nusemtl {name}").unwrap();
        for p in &m.points {
            writeln!(obj, "v {}", v3(*p)).unwrap();
        }
        for t in &m.triangles {
            writeln!(obj, "f {} {} {}", t[0] + base, t[1] + base, t[2] + base).unwrap();
        }
        base += m.points.len() as u32;
    }
    let mtl = format!(
        "newmtl floor\nKd {}\nKs 0 0 0\nillum 1\nnewmtl red\nKd {}\nKs 0 0 0\nillum 1\n\
         newmtl glass\nKd 0 0 0\nKs 0 0 0\nNi 1.5\nTf 1 1 1\nillum 7\n",
        v3(COLOURS[0]),
        v3(COLOURS[1])
    );
    (obj, mtl)
}

/// The scene in every format, written once per test run: tests run in parallel and must not
/// read a file another is still writing.
fn write_scenes() -> PathBuf {
    static DIR: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    DIR.get_or_init(write_scene_files).clone()
}

fn write_scene_files() -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-formats-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let m = meshes();
    std::fs::write(dir.join("scene.ray"), ray_file(&m)).unwrap();
    std::fs::write(dir.join("scene.pbrt"), pbrt_file(&m)).unwrap();
    std::fs::write(dir.join("scene.gltf"), gltf_file(&m)).unwrap();
    let (obj, mtl) = obj_files(&m);
    std::fs::write(dir.join("scene.obj"), obj).unwrap();
    std::fs::write(dir.join("scene.mtl"), mtl).unwrap();
    dir
}

fn obj_options() -> SceneOptions {
    SceneOptions {
        camera: Some(CameraRequest {
            eye: Some(EYE),
            target: Some(TARGET),
            up: Vec3::Y,
            fov_degrees: FOV,
        }),
        lights: vec![LightDesc::Point {
            position: LIGHT,
            color: Vec3::splat(INTENSITY),
            attenuation: [0.0, 0.0, 1.0],
            span: 0..0,
        }],
    }
}

fn render(path: &Path, physical: bool, seed: u64) -> Film {
    let settings = LoadSettings {
        read: ReadOptions {
            obj: obj_options(),
            ..ReadOptions::default()
        },
        ..LoadSettings::default()
    };
    let scene = load(path, &settings).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    // The scene's own settings, then the test's (as a front end does).
    let mut config = RenderConfig::for_scene(scene.hints());
    config.width = 48;
    config.height = Some(48);
    config.seed = seed;
    config.photons = 30_000;
    config.depth = None;
    if physical {
        config.model = Some(Model::Physical);
        config.integrator = Some(IntegratorKind::Ppm);
        config.passes = Some("6".into());
    } else {
        config.model = Some(Model::Course);
        config.integrator = Some(IntegratorKind::Whitted);
        config.passes = None;
        config.radius = None;
    }
    let mut session = RenderSession::new(&scene, config.render_options("formats").unwrap()).unwrap();
    session.run(&config.plan().unwrap(), control(), |_| Ok(())).unwrap();
    session.image()
}

fn mean(f: &Film) -> f64 {
    f.pixels.iter().map(|p| (p.x + p.y + p.z) as f64 / 3.0).sum::<f64>() / f.pixels.len() as f64
}

fn rms(a: &Film, b: &Film) -> f64 {
    let sum: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .map(|(p, q)| (*p - *q).length_squared() as f64 / 3.0)
        .sum();
    (sum / a.pixels.len() as f64).sqrt()
}

fn check_model(dir: &Path, physical: bool, formats: &[&str]) {
    let reference = render(&dir.join("scene.ray"), physical, 1);
    let reseeded = render(&dir.join("scene.ray"), physical, 2);
    let noise = rms(&reference, &reseeded);
    let model = if physical { "physical" } else { "course" };
    assert!(mean(&reference) > 0.02, "{model}: the scene is lit");
    for format in formats {
        let image = render(&dir.join(format!("scene.{format}")), physical, 1);
        let (d, m) = (rms(&image, &reference), mean(&image) / mean(&reference) - 1.0);
        eprintln!(
            "{model} {format}: rms {d:.5} vs noise {noise:.5}, mean {:+.3}%",
            100.0 * m
        );
        assert!(
            d <= noise.max(1e-6),
            "{model} {format}: rms difference {d} above the noise {noise}"
        );
        assert!(m.abs() < 0.01, "{model} {format}: mean differs by {:.2}%", 100.0 * m);
    }
}

#[test]
fn one_scene_in_every_format_renders_alike_in_the_course_model() {
    let dir = write_scenes();
    check_model(&dir, false, &["pbrt", "gltf", "obj"]);
}

#[test]
fn one_scene_in_every_format_renders_alike_in_the_physical_model() {
    let dir = write_scenes();
    check_model(&dir, true, &["pbrt", "gltf", "obj"]);
}

/// A mirrored camera would put the red box on the other side: its pixels are where the .ray
/// file's are in every format (checked directly, beside the RMS above).
#[test]
fn no_format_mirrors_the_image() {
    let dir = write_scenes();
    let redness = |f: &Film| {
        let (mut left, mut right) = (0.0f32, 0.0f32);
        for y in 0..f.height {
            for x in 0..f.width {
                let p = f.pixel(x, y);
                let r = (p.x - p.y).max(0.0);
                if x < f.width / 2 {
                    left += r;
                } else {
                    right += r;
                }
            }
        }
        (left, right)
    };
    for format in ["ray", "pbrt", "gltf", "obj"] {
        let (left, right) = redness(&render(&dir.join(format!("scene.{format}")), false, 1));
        assert!(left > 4.0 * right, "{format}: red left {left}, right {right}");
    }
}

/// A glTF whose NORMAL and TEXCOORD_0 hold a NaN and an infinity (as broken exporters write)
/// loads with the normal recomputed from the faces, the coordinate read as (0, 0), a warning
/// counting each; a NaN position leaves out the triangles that use it, with a warning too.
#[test]
fn gltf_not_finite_attributes_are_repaired_not_refused() {
    let dir = std::env::temp_dir().join(format!("caustica-formats-{}-nan", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // A quad and a fifth corner at a NaN; the first normal a NaN, the second uv an infinity.
    let mut positions = [
        0.0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 5.0, 0.0,
    ];
    positions[12] = f32::NAN;
    let mut normals = [0.0f32, 0.0, 1.0].repeat(5);
    normals[0] = f32::NAN;
    let uvs: [f32; 10] = [0.0, 0.0, f32::INFINITY, 0.0, 1.0, 1.0, 0.0, 1.0, 0.0, 0.0];
    let indices: [u16; 9] = [0, 1, 2, 0, 2, 3, 3, 2, 4];
    let mut buffer: Vec<u8> = positions
        .iter()
        .chain(&normals)
        .chain(&uvs)
        .flat_map(|v| v.to_le_bytes())
        .collect();
    buffer.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    buffer.resize(buffer.len().next_multiple_of(4), 0);
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"NORMAL":1,"TEXCOORD_0":2}},"indices":3}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3","min":[0,0,0],"max":[1,5,0]}},
{{"bufferView":1,"componentType":5126,"count":5,"type":"VEC3"}},
{{"bufferView":2,"componentType":5126,"count":5,"type":"VEC2"}},
{{"bufferView":3,"componentType":5123,"count":9,"type":"SCALAR"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":60}},{{"buffer":0,"byteOffset":60,"byteLength":60}},
{{"buffer":0,"byteOffset":120,"byteLength":40}},{{"buffer":0,"byteOffset":160,"byteLength":18}}],
"buffers":[{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}]}}"#,
        buffer.len(),
        base64(&buffer)
    );
    let path = dir.join("nan.gltf");
    std::fs::write(&path, json).unwrap();
    let scene = caustica::loader::load(&path, &caustica::loader::LoadSettings::default()).unwrap();
    let warnings = scene.warnings().join("\n");
    for counted in [
        "1 of 5 vertex positions are not finite",
        "1 of 5 vertex normals are not finite",
        "1 of 5 texture coordinates are not finite",
    ] {
        assert!(warnings.contains(counted), "{counted}: {warnings}");
    }
    assert_eq!(scene.triangles().len(), 2, "the triangle on the NaN corner is left out");
    let ray = caustica::math::Ray::new(Vec3::new(0.1, 0.05, 1.0), -Vec3::Z);
    let hit = scene.intersect(&ray, f32::INFINITY).expect("the quad");
    let normal = scene.surface(&ray, &hit).shading_normal;
    assert!((normal - Vec3::Z).length() < 1e-5, "recomputed normal: {normal}");
}

/// glTF's volume attenuation is read as Beer–Lambert absorption inside the solid glass: light
/// keeps `attenuationColor` after `attenuationDistance`, so σ = −ln(colour) / distance.
#[test]
fn gltf_volume_attenuation_is_absorption_inside_the_glass() {
    let text = gltf_file(&meshes()).replace(
        "\"KHR_materials_volume\":{\"thicknessFactor\":0.8}",
        "\"KHR_materials_volume\":{\"thicknessFactor\":0.8,\"attenuationColor\":[0.5,0.8,1.0],\"attenuationDistance\":2.0}",
    );
    assert!(text.contains("attenuationDistance"));
    let dir = std::env::temp_dir().join(format!("caustica-attenuation-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("amber.gltf");
    std::fs::write(&path, text).unwrap();
    let scene = caustica::loader::load(&path, &caustica::loader::LoadSettings::default()).unwrap();
    assert!(
        !scene.warnings().iter().any(|w| w.contains("attenuation")),
        "{:?}",
        scene.warnings()
    );
    let absorbing: Vec<Vec3> = scene.materials().iter().filter_map(|m| m.absorption).collect();
    assert_eq!(absorbing.len(), 1, "one absorbing glass");
    let expected = Vec3::new(-(0.5f32.ln()), -(0.8f32.ln()), 0.0) / 2.0;
    assert!(
        (absorbing[0] - expected).abs().max_element() < 1e-6,
        "{} against {expected}",
        absorbing[0]
    );
}

/// Every extension a glTF uses that caustica does not render gets a warning naming it, once,
/// located at its place in `extensionsUsed`; those it reads, and metadata, get none.
#[test]
fn gltf_extensions_not_rendered_are_said() {
    let text = gltf_file(&meshes()).replace(
        "\"extensionsUsed\":[",
        "\"extensionsUsed\":[\"KHR_materials_sheen\",\"KHR_materials_iridescence\",\"KHR_materials_clearcoat\",\"KHR_xmp_json_ld\",",
    );
    let dir = std::env::temp_dir().join(format!("caustica-extensions-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("sheen.gltf");
    std::fs::write(&path, text).unwrap();
    let scene = caustica::loader::load(&path, &caustica::loader::LoadSettings::default()).unwrap();
    let warnings = scene.warnings();
    for name in ["KHR_materials_sheen", "KHR_materials_iridescence"] {
        let said: Vec<_> = warnings.iter().filter(|w| w.contains(name)).collect();
        assert_eq!(said.len(), 1, "{name}: {warnings:?}");
        assert!(
            said[0].contains("not rendered") && said[0].contains(":1:"),
            "{}",
            said[0]
        );
    }
    // Metadata changes nothing in the picture: no warning either.
    for read in [
        "KHR_materials_clearcoat",
        "KHR_materials_transmission",
        "KHR_materials_volume",
        "KHR_lights_punctual",
        "KHR_xmp_json_ld",
    ] {
        assert!(
            !warnings.iter().any(|w| w.contains(&format!("{read} is not"))),
            "{warnings:?}"
        );
    }
}

/// pbrt's `mix` blends two materials by `amount` in the mean: a floor that is a white diffuse
/// (0.8) and a black one at amount 0.25 (the second's share), under a uniform sky of radiance
/// 1 with nothing else to shade it, has radiance 0.75 · 0.8 = 0.6, for camera paths and for
/// light paths alike.
#[test]
fn pbrt_mix_blends_its_materials_by_amount() {
    let text = "LookAt 0 1 0  0 0 0  0 0 1\nCamera \"perspective\" \"float fov\" 30\nWorldBegin\n\
        LightSource \"infinite\" \"rgb L\" [1 1 1]\n\
        MakeNamedMaterial \"white\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.8 0.8 0.8]\n\
        MakeNamedMaterial \"black\" \"string type\" \"diffuse\" \"rgb reflectance\" [0 0 0]\n\
        Material \"mix\" \"string materials\" [\"white\" \"black\"] \"float amount\" 0.25\n\
        Shape \"bilinearmesh\" \"point3 P\" [-100 0 -100  100 0 -100  -100 0 100  100 0 100]\n";
    let dir = std::env::temp_dir().join(format!("caustica-mix-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("mix.pbrt");
    std::fs::write(&path, text).unwrap();
    let scene = caustica::loader::load(&path, &caustica::loader::LoadSettings::default()).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        scene.warnings().iter().all(|w| !w.contains("mix")),
        "{:?}",
        scene.warnings()
    );
    for (integrator, passes) in [("path", 32), ("vcm", 8)] {
        let film = crate::common::render_integrator(&scene, integrator, 24, passes, 20_000, 5);
        let mean = film.region_mean((0, 23), (0, 23));
        eprintln!("{integrator}: {mean}");
        assert!(
            (mean - Vec3::splat(0.6)).abs().max_element() < 0.01,
            "{integrator}: {mean}"
        );
    }
}
