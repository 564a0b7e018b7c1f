//! Image textures as each format means them, checked against the formats' own definitions:
//! the sRGB curve for 8-bit colour maps, glTF's sampler and `KHR_texture_transform` formulas,
//! pbrt-v4's `imagemap` parameters, OBJ's `map_Kd`; images in files, data URIs and a GLB's
//! binary chunk rendering the same pixels; a missing image a warning, not a refusal.

use crate::common::render_with;
use crate::formats::base64;
use caustica::integrator::RenderConfig;
use caustica::loader::{load, LoadSettings};
use caustica::material::Channel;
use caustica::math::{Vec2, Vec3};
use caustica::scene::Scene;
use std::path::{Path, PathBuf};

/// The sRGB transfer function of an 8-bit value (IEC 61966-2-1), written out here.
fn srgb(v: u8) -> f32 {
    let c = f64::from(v) / 255.0;
    (if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }) as f32
}

fn folder(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("caustica-textures-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// A PNG of `w`×`h` RGB texels, rows from the top.
fn png(w: u32, h: u32, texels: &[[u8; 3]]) -> Vec<u8> {
    let image = image::RgbImage::from_fn(w, h, |x, y| image::Rgb(texels[(y * w + x) as usize]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    bytes.into_inner()
}

/// The diffuse colour of the scene's only textured material at `uv` (v upwards).
fn diffuse_at(scene: &Scene, uv: Vec2) -> Vec3 {
    let material = scene
        .materials()
        .iter()
        .find(|m| matches!(m.diffuse, Channel::Texture(_)))
        .expect("a textured material");
    material.eval(scene.textures(), uv).diffuse
}

fn near(a: Vec3, b: Vec3, tolerance: f32) -> bool {
    (a - b).abs().max_element() <= tolerance
}

/// A 16² path-traced image of `passes` passes.
fn path_traced(scene: &Scene, passes: u64) -> caustica::film::Film {
    let config = RenderConfig {
        integrator: Some("path".parse().unwrap()),
        width: 16,
        height: Some(16),
        passes: Some(passes.to_string()),
        seed: 3,
        ..RenderConfig::default()
    };
    render_with(scene, &config)
}

/// How a glTF file holds its image.
#[derive(Clone, Copy, PartialEq)]
enum Holder {
    File,
    DataUri,
    Glb,
}

/// A unit quad in z = 0 (u along x, glTF's v down along −y) with one textured material, its
/// image held as `holder` says; `material` and `sampler` are JSON written into the file.
fn quad_gltf(dir: &Path, image: &[u8], holder: Holder, material: &str, sampler: &str) -> PathBuf {
    let positions: [f32; 12] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0];
    let uvs: [f32; 8] = [0.0, 1.0, 1.0, 1.0, 1.0, 0.0, 0.0, 0.0];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut buffer: Vec<u8> = positions.iter().chain(&uvs).flat_map(|v| v.to_le_bytes()).collect();
    buffer.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    let mut views = vec![
        r#"{"buffer":0,"byteOffset":0,"byteLength":48}"#.to_string(),
        r#"{"buffer":0,"byteOffset":48,"byteLength":32}"#.to_string(),
        r#"{"buffer":0,"byteOffset":80,"byteLength":12}"#.to_string(),
    ];
    let image_json = match holder {
        Holder::File => {
            std::fs::write(dir.join("texels.png"), image).unwrap();
            r#"{"uri":"texels.png"}"#.to_string()
        }
        Holder::DataUri => format!(r#"{{"uri":"data:image/png;base64,{}"}}"#, base64(image)),
        Holder::Glb => {
            buffer.resize(buffer.len().next_multiple_of(4), 0);
            views.push(format!(
                r#"{{"buffer":0,"byteOffset":{},"byteLength":{}}}"#,
                buffer.len(),
                image.len()
            ));
            buffer.extend(image);
            r#"{"bufferView":3,"mimeType":"image/png"}"#.to_string()
        }
    };
    buffer.resize(buffer.len().next_multiple_of(4), 0);
    let buffer_json = match holder {
        Holder::Glb => format!(r#"{{"byteLength":{}}}"#, buffer.len()),
        _ => format!(
            r#"{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}"#,
            buffer.len(),
            base64(&buffer)
        ),
    };
    let json = format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0,1]}}],
"nodes":[{{"mesh":0}},{{"camera":0,"translation":[0.5,0.5,2]}}],
"cameras":[{{"type":"perspective","perspective":{{"yfov":0.4,"aspectRatio":1,"znear":0.1}}}}],
"materials":[{material}],
"textures":[{{"source":0,"sampler":0}}],"samplers":[{sampler}],"images":[{image_json}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":1}},"indices":2,"material":0}}]}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
{{"bufferView":1,"componentType":5126,"count":4,"type":"VEC2"}},
{{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}],
"bufferViews":[{}],"buffers":[{buffer_json}]}}"#,
        views.join(",")
    );
    if holder != Holder::Glb {
        let path = dir.join("quad.gltf");
        std::fs::write(&path, json).unwrap();
        return path;
    }
    let mut json = json.into_bytes();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut glb = Vec::new();
    glb.extend(b"glTF");
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + buffer.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(&json);
    glb.extend((buffer.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(&buffer);
    let path = dir.join("quad.glb");
    std::fs::write(&path, glb).unwrap();
    path
}

/// A diffuse material (no metal, no specular layer) whose base colour is texture 0 times
/// `factor`.
fn diffuse_material(factor: &str, texture_info: &str) -> String {
    format!(
        r#"{{"pbrMetallicRoughness":{{"baseColorFactor":{factor},"metallicFactor":0,"baseColorTexture":{texture_info}}},
"extensions":{{"KHR_materials_specular":{{"specularFactor":0}}}}}}"#
    )
}

const LINEAR_REPEAT: &str = r#"{"magFilter":9729,"wrapS":10497,"wrapT":10497}"#;

/// A uniform 8-bit base-colour texture reads the sRGB decoding of its value times the factor;
/// the same file with its image in a file, a data URI and a GLB's binary chunk renders the
/// same pixels, and a diffuse quad under the default sky of radiance 1 shows that albedo.
#[test]
fn a_uniform_colour_texture_is_srgb_decoded_and_times_its_factor_wherever_the_image_is() {
    let dir = folder("uniform");
    let texel = [128u8, 64, 200];
    let image = png(2, 2, &[texel; 4]);
    let material = diffuse_material("[0.5,1,1,1]", r#"{"index":0}"#);
    let want = Vec3::new(0.5 * srgb(128), srgb(64), srgb(200));
    let mut films = Vec::new();
    for holder in [Holder::File, Holder::DataUri, Holder::Glb] {
        let scene = load(
            &quad_gltf(&dir, &image, holder, &material, LINEAR_REPEAT),
            &LoadSettings::default(),
        )
        .unwrap();
        for uv in [Vec2::new(0.3, 0.7), Vec2::new(-2.6, 5.1)] {
            let got = diffuse_at(&scene, uv);
            assert!(near(got, want, 1e-6), "{got} vs {want}");
        }
        films.push(path_traced(&scene, 64));
    }
    assert!(
        films.windows(2).all(|f| f[0].pixels == f[1].pixels),
        "the three holders render alike"
    );
    // The quad fills the view's middle; a Lambertian plane under a uniform sky of radiance 1
    // reflects its albedo.
    let got = films[0].region_mean((6, 10), (6, 10));
    assert!(
        near(got, want, 0.03 * want.max_element()),
        "rendered {got}, albedo {want}"
    );
}

/// glTF's sampler (nearest, REPEAT on s, MIRRORED_REPEAT on t) and `KHR_texture_transform`
/// (offset, rotation, scale) against the spec's formulas, texel by texel, at texture
/// coordinates inside and far outside 0..1.
#[test]
fn gltf_sampler_and_texture_transform_follow_the_spec() {
    let dir = folder("transform");
    let texels: Vec<[u8; 3]> = (0..16u8).map(|i| [i * 16 + 8, 255 - i * 16, 40]).collect();
    let image = png(4, 4, &texels);
    let (offset, rotation, scale) = ([0.25f32, -0.5f32], 0.3f32, [2.0f32, 3.0f32]);
    let info = format!(
        r#"{{"index":0,"extensions":{{"KHR_texture_transform":{{"offset":[{},{}],"rotation":{rotation},"scale":[{},{}]}}}}}}"#,
        offset[0], offset[1], scale[0], scale[1]
    );
    let material = diffuse_material("[1,1,1,1]", &info);
    let sampler = r#"{"magFilter":9728,"minFilter":9728,"wrapS":10497,"wrapT":33648}"#;
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, &material, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    let (sin, cos) = rotation.sin_cos();
    let mut checked = 0;
    for i in 0..23 {
        for j in 0..19 {
            // glTF's texture coordinates, v down.
            let (u, v) = (-1.7 + i as f32 * 0.173, -2.3 + j as f32 * 0.261);
            // The spec: T · R · S with R = [[cos, sin], [−sin, cos]].
            let s = cos * scale[0] * u + sin * scale[1] * v + offset[0];
            let t = -sin * scale[0] * u + cos * scale[1] * v + offset[1];
            let repeat = s - s.floor();
            let m = t.rem_euclid(2.0);
            let mirror = if m <= 1.0 { m } else { 2.0 - m };
            let (x, y) = (repeat * 4.0, mirror * 4.0);
            if [x, y].iter().any(|c| (c - c.round()).abs() < 1e-3) {
                continue; // on a texel edge: either neighbour is right
            }
            let texel = texels[(y.floor() as usize).min(3) * 4 + (x.floor() as usize).min(3)];
            let want = Vec3::new(srgb(texel[0]), srgb(texel[1]), srgb(texel[2]));
            let got = diffuse_at(&scene, Vec2::new(u, 1.0 - v));
            assert!(near(got, want, 1e-6), "at ({u}, {v}): {got} vs texel {texel:?}");
            checked += 1;
        }
    }
    assert!(checked > 300, "{checked} points checked");
}

/// Each glTF wrap mode on its own, bilinear: CLAMP_TO_EDGE reads the edge texel beyond the
/// image, the others tile.
#[test]
fn gltf_clamp_to_edge_holds_the_edge_texel() {
    let dir = folder("clamp");
    let image = png(2, 1, &[[0, 0, 0], [255, 255, 255]]);
    let material = diffuse_material("[1,1,1,1]", r#"{"index":0}"#);
    let sampler = r#"{"magFilter":9729,"wrapS":33071,"wrapT":33071}"#;
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, &material, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    assert_eq!(diffuse_at(&scene, Vec2::new(3.4, 0.5)), Vec3::ONE);
    assert_eq!(diffuse_at(&scene, Vec2::new(-3.4, 0.5)), Vec3::ZERO);
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, &material, LINEAR_REPEAT),
        &LoadSettings::default(),
    )
    .unwrap();
    // Repeating, u = 3 lies on the seam between the white last texel and the black first one.
    assert!(near(diffuse_at(&scene, Vec2::new(3.0, 0.5)), Vec3::splat(0.5), 1e-6));
}

/// A missing image and a KTX2 image are warnings naming them; the factor stands in.
#[test]
fn an_image_that_cannot_be_read_is_a_warning_and_the_factor_stands_in() {
    let dir = folder("missing");
    let image = png(1, 1, &[[10, 20, 30]]);
    let path = quad_gltf(
        &dir,
        &image,
        Holder::File,
        &diffuse_material("[0.2,0.4,0.6,1]", r#"{"index":0}"#),
        LINEAR_REPEAT,
    );
    std::fs::remove_file(dir.join("texels.png")).unwrap();
    let scene = load(&path, &LoadSettings::default()).unwrap();
    assert!(
        scene
            .warnings()
            .iter()
            .any(|w| w.contains("texels.png") && w.contains("missing")),
        "{:?}",
        scene.warnings()
    );
    assert!(scene
        .materials()
        .iter()
        .any(|m| m.diffuse == Channel::Constant(Vec3::new(0.2, 0.4, 0.6))));
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("texels.png", "texels.ktx2");
    std::fs::write(&path, text).unwrap();
    let scene = load(&path, &LoadSettings::default()).unwrap();
    assert!(scene
        .warnings()
        .iter()
        .any(|w| w.contains("KTX2") && w.contains("texels.ktx2")));
}

/// pbrt's roughness from a float image texture, read point by point: a conductor's and a
/// coated diffuse's GGX α is the texel (its square root with `remaproughness`), and a
/// dielectric is rough where the texel says so and smooth where it is 0.
#[test]
fn pbrt_roughness_textures_set_the_lobe_point_by_point() {
    use caustica::description::PhysicalMaterial;
    let dir = folder("pbrt-roughness");
    std::fs::write(dir.join("rough.png"), png(2, 1, &[[0, 0, 0], [128, 128, 128]])).unwrap();
    let roughness_at = |material: &str, u: f32| {
        let text = format!(
            r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
WorldBegin
LightSource "point" "rgb I" [1 1 1] "point3 from" [0 0 2]
Texture "r" "float" "imagemap" "string filename" "rough.png" "string filter" "point" "string encoding" "linear"
Material {material}
Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 1 1 0 0 1 0] "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3]
"#
        );
        std::fs::write(dir.join("scene.pbrt"), text).unwrap();
        let scene = load(&dir.join("scene.pbrt"), &LoadSettings::default()).unwrap();
        assert!(
            scene.warnings().iter().all(|w| !w.contains("rough")),
            "{:?}",
            scene.warnings()
        );
        let m = scene
            .materials()
            .iter()
            .find(|m| m.roughness_map.is_some())
            .expect("a roughness map");
        match m.physical_at(scene.textures(), Vec2::new(u, 0.5)) {
            Some(PhysicalMaterial::Conductor { roughness, .. })
            | Some(PhysicalMaterial::CoatedDiffuse { roughness, .. })
            | Some(PhysicalMaterial::RoughDielectric { roughness, .. }) => Some(roughness),
            None => None,
            other => panic!("{other:?}"),
        }
    };
    let texel = 128.0f32 / 255.0;
    let conductor = r#""conductor" "texture roughness" "r" "bool remaproughness" false"#;
    assert_eq!(roughness_at(conductor, 0.25), Some(0.0));
    assert!((roughness_at(conductor, 0.75).unwrap() - texel).abs() < 1e-6);
    let remapped = r#""coateddiffuse" "texture uroughness" "r" "texture vroughness" "r""#;
    assert!((roughness_at(remapped, 0.75).unwrap() - texel.sqrt()).abs() < 1e-6);
    let glass = r#""dielectric" "texture roughness" "r" "bool remaproughness" false"#;
    assert_eq!(roughness_at(glass, 0.25), None, "smooth: the course fields' dielectric");
    assert!((roughness_at(glass, 0.75).unwrap() - texel).abs() < 1e-6);
}

/// pbrt-v4's `imagemap`: 8-bit images are sRGB unless `encoding` says "linear" or "gamma G";
/// `uscale`/`udelta` map u, `scale` multiplies, `wrap "black"` is black outside, `filter
/// "point"` reads the nearest texel.
#[test]
fn pbrt_imagemap_encodings_mapping_and_wrap() {
    let dir = folder("pbrt");
    std::fs::write(dir.join("ramp.png"), png(2, 1, &[[100, 100, 100], [200, 200, 200]])).unwrap();
    let scene_with = |texture: &str| {
        let text = format!(
            r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
WorldBegin
LightSource "point" "rgb I" [1 1 1] "point3 from" [0 0 2]
Texture "t" "spectrum" "imagemap" "string filename" "ramp.png" "string filter" "point" {texture}
Material "diffuse" "texture reflectance" "t"
Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 1 1 0 0 1 0] "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3]
"#
        );
        std::fs::write(dir.join("scene.pbrt"), text).unwrap();
        load(&dir.join("scene.pbrt"), &LoadSettings::default())
    };
    let scene_with = |texture: &str| scene_with(texture).unwrap();
    let (left, right) = (Vec2::new(0.25, 0.5), Vec2::new(0.75, 0.5));
    let s = scene_with("");
    assert!(near(diffuse_at(&s, left), Vec3::splat(srgb(100)), 1e-6));
    assert!(near(diffuse_at(&s, right), Vec3::splat(srgb(200)), 1e-6));
    let s = scene_with(r#""string encoding" "linear""#);
    assert!(near(diffuse_at(&s, left), Vec3::splat(100.0 / 255.0), 1e-6));
    let s = scene_with(r#""string encoding" "gamma 2.2""#);
    assert!(near(
        diffuse_at(&s, right),
        Vec3::splat((200.0f32 / 255.0).powf(2.2)),
        1e-5
    ));
    // u ↦ 2u + 0.5: u = 0.1 reads 0.7 (the right texel), u = 0.3 reads 1.1, past the edge.
    let s = scene_with(r#""float uscale" 2 "float udelta" 0.5 "string wrap" "black" "float scale" 0.5"#);
    assert!(near(
        diffuse_at(&s, Vec2::new(0.1, 0.5)),
        Vec3::splat(0.5 * srgb(200)),
        1e-6
    ));
    assert_eq!(diffuse_at(&s, Vec2::new(0.3, 0.5)), Vec3::ZERO);
    let s = scene_with(r#""float uscale" 2 "float udelta" 0.5"#);
    assert!(
        near(diffuse_at(&s, Vec2::new(0.3, 0.5)), Vec3::splat(srgb(100)), 1e-6),
        "repeats by default"
    );
}

/// OBJ's `map_Kd` is an sRGB colour map that repeats.
#[test]
fn obj_map_kd_is_srgb_and_repeats() {
    let dir = folder("obj");
    std::fs::write(dir.join("wood.png"), png(1, 1, &[[30, 90, 150]])).unwrap();
    std::fs::write(dir.join("m.mtl"), "newmtl wood\nKd 1 1 1\nmap_Kd wood.png\n").unwrap();
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nusemtl wood\nf 1/1 2/2 3/3\n",
    )
    .unwrap();
    let s = load(&dir.join("m.obj"), &LoadSettings::default()).unwrap();
    let want = Vec3::new(srgb(30), srgb(90), srgb(150));
    assert!(near(diffuse_at(&s, Vec2::new(4.2, -1.3)), want, 1e-6));
}

/// An emissive texture times `emissiveFactor` (and `KHR_materials_emissive_strength`): black
/// texels do not glow.
#[test]
fn an_emissive_texture_glows_only_where_its_texels_do() {
    let dir = folder("emissive");
    let image = png(2, 1, &[[0, 0, 0], [255, 128, 255]]);
    let material = r#"{"pbrMetallicRoughness":{"baseColorFactor":[0,0,0,1],"metallicFactor":0},
"emissiveFactor":[1,0.5,1],"emissiveTexture":{"index":0},
"extensions":{"KHR_materials_emissive_strength":{"emissiveStrength":4}}}"#;
    let sampler = r#"{"magFilter":9728,"wrapS":10497,"wrapT":10497}"#;
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, material, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    let m = scene
        .materials()
        .iter()
        .find(|m| matches!(m.emissive, Channel::Texture(_)))
        .expect("a textured emission");
    assert_eq!(m.eval(scene.textures(), Vec2::new(0.25, 0.5)).emissive, Vec3::ZERO);
    let want = Vec3::new(4.0, 2.0 * srgb(128), 4.0);
    assert!(near(
        m.eval(scene.textures(), Vec2::new(0.75, 0.5)).emissive,
        want,
        1e-5
    ));
}

/// A constant tangent-space normal map tilts a Lambertian quad's normal: under a directional
/// light of irradiance E from angle φ the quad's radiance is albedo/π · E · max(0, n·l), with
/// n the decoded texel (x and y times `scale`), normalised in the frame whose tangent follows u
/// (along +x here) — the spec's exact answer, which a tangent the wrong way round would miss.
#[test]
fn a_constant_normal_map_tilts_the_shading_by_its_decoded_normal() {
    let dir = folder("normal");
    let texel = [209u8, 128, 225];
    let image = png(1, 1, &[texel]);
    let scale = 0.5f32;
    let material = format!(
        r#"{{"pbrMetallicRoughness":{{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0}},
"normalTexture":{{"index":0,"scale":{scale}}},
"extensions":{{"KHR_materials_specular":{{"specularFactor":0}}}}}}"#
    );
    let path = quad_gltf(&dir, &image, Holder::File, &material, LINEAR_REPEAT);
    let (sin, cos) = 0.6f32.sin_cos();
    let (hs, hc) = 0.3f32.sin_cos();
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text
        .replacen(
            r#"{"asset":{"version":"2.0"},"#,
            r#"{"asset":{"version":"2.0"},"extensionsUsed":["KHR_lights_punctual"],"extensions":{"KHR_lights_punctual":{"lights":[{"type":"directional","intensity":1366}]}},"#,
            1,
        )
        .replacen(r#""nodes":[0,1]"#, r#""nodes":[0,1,2]"#, 1)
        .replacen(
            r#""translation":[0.5,0.5,2]}]"#,
            &format!(
                r#""translation":[0.5,0.5,2]}},{{"rotation":[0,{hs},0,{hc}],"extensions":{{"KHR_lights_punctual":{{"light":0}}}}}}]"#
            ),
            1,
        );
    std::fs::write(&path, text).unwrap();
    let scene = load(&path, &LoadSettings::default()).unwrap();
    assert_eq!(scene.lights().len(), 1, "{:?}", scene.warnings());
    let m = Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) / 255.0 * 2.0 - Vec3::ONE;
    let n = Vec3::new(m.x * scale, m.y * scale, m.z).normalize();
    // The light travels along (−sin φ, 0, −cos φ): towards it is (sin φ, 0, cos φ).
    let want = 0.5 / std::f32::consts::PI * 2.0 * n.dot(Vec3::new(sin, 0.0, cos));
    let flat = 0.5 / std::f32::consts::PI * 2.0 * cos;
    let got = path_traced(&scene, 4).region_mean((5, 11), (5, 11));
    assert!((want - flat).abs() > 0.05 * flat, "the map tilts enough to tell");
    assert!(
        near(got, Vec3::splat(want), 0.01 * want),
        "rendered {got}, expected {want} (flat: {flat})"
    );
}

/// The scene's material read with a metallic-roughness texture, after checking that no
/// warning mentions any of `unsaid`.
fn metallic_roughness_material<'s>(scene: &'s Scene, unsaid: &[&str]) -> &'s caustica::material::Material {
    assert!(
        scene.warnings().iter().all(|w| unsaid.iter().all(|u| !w.contains(u))),
        "{:?}",
        scene.warnings()
    );
    scene
        .materials()
        .iter()
        .find(|m| m.metallic_roughness.is_some())
        .unwrap()
}

/// glTF's metallic-roughness texture, linear: blue times `metallicFactor` is metalness, green
/// times `roughnessFactor` roughness (GGX α its square); a metal point reflects the base colour,
/// a dielectric point is the base colour under the coat of the ior.
#[test]
fn a_metallic_roughness_texture_decides_metal_and_roughness_point_by_point() {
    use caustica::description::PhysicalMaterial;
    let dir = folder("metal");
    let image = png(2, 1, &[[0, 64, 255], [0, 200, 0]]);
    let material = r#"{"pbrMetallicRoughness":{"baseColorFactor":[0.9,0.6,0.2,1],"metallicFactor":1,"roughnessFactor":0.8,
"metallicRoughnessTexture":{"index":0}}}"#;
    let sampler = r#"{"magFilter":9728,"wrapS":10497,"wrapT":10497}"#;
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, material, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    let m = metallic_roughness_material(&scene, &["metallic"]);
    let base = Vec3::new(0.9, 0.6, 0.2);
    let alpha = |g: u8| (g as f32 / 255.0 * 0.8).powi(2);
    match m.physical_at(scene.textures(), Vec2::new(0.25, 0.5)) {
        Some(PhysicalMaterial::Conductor {
            reflectance: Some(r),
            roughness,
            ..
        }) => {
            assert_eq!(r, base);
            assert!((roughness - alpha(64)).abs() < 1e-6, "{roughness}");
        }
        other => panic!("a metal point: {other:?}"),
    }
    match m.physical_at(scene.textures(), Vec2::new(0.75, 0.5)) {
        Some(PhysicalMaterial::CoatedDiffuse {
            reflectance,
            eta,
            roughness,
            coat_tint,
            layering,
        }) => {
            assert_eq!(
                (reflectance, eta, layering, coat_tint),
                (base, 1.5, caustica::description::Coating::Fresnel, Vec3::ONE)
            );
            assert!((roughness - alpha(200)).abs() < 1e-6, "{roughness}");
        }
        other => panic!("a dielectric point: {other:?}"),
    }
}

/// On solid glass (transmission with a volume) the metallic-roughness texture decides metal,
/// rough glass or smooth glass point by point, the glass tinted by the base colour; without a
/// texture the roughness factor makes the whole glass rough.
#[test]
fn a_metallic_roughness_texture_on_glass_makes_it_rough_or_metal_point_by_point() {
    use caustica::description::PhysicalMaterial;
    let dir = folder("rough-glass");
    let image = png(3, 1, &[[0, 128, 0], [0, 0, 255], [0, 2, 0]]);
    let glass = r#""extensions":{"KHR_materials_transmission":{"transmissionFactor":1},"KHR_materials_ior":{"ior":1.4},
"KHR_materials_volume":{"thicknessFactor":1}}"#;
    let material = format!(
        r#"{{"pbrMetallicRoughness":{{"baseColorFactor":[0.9,0.6,0.2,1],"metallicFactor":1,"roughnessFactor":1,
"metallicRoughnessTexture":{{"index":0}}}},{glass}}}"#
    );
    let sampler = r#"{"magFilter":9728,"wrapS":10497,"wrapT":10497}"#;
    let path = quad_gltf(&dir, &image, Holder::File, &material, sampler);
    let scene = load(&path, &LoadSettings::default()).unwrap();
    let m = metallic_roughness_material(&scene, &["metallic", "rough"]);
    let base = Vec3::new(0.9, 0.6, 0.2);
    match m.physical_at(scene.textures(), Vec2::new(1.0 / 6.0, 0.5)) {
        Some(PhysicalMaterial::RoughDielectric {
            eta, roughness, tint, ..
        }) => {
            assert_eq!((eta, tint), (1.4, base));
            assert!((roughness - (128.0f32 / 255.0).powi(2)).abs() < 1e-6, "{roughness}");
        }
        other => panic!("a rough glass point: {other:?}"),
    }
    assert!(matches!(
        m.physical_at(scene.textures(), Vec2::new(0.5, 0.5)),
        Some(PhysicalMaterial::Conductor { reflectance: Some(r), .. }) if r == base
    ));
    assert_eq!(
        m.physical_at(scene.textures(), Vec2::new(5.0 / 6.0, 0.5)),
        None,
        "smooth glass: the course dielectric"
    );
    assert_eq!(m.eval(scene.textures(), Vec2::new(5.0 / 6.0, 0.5)).transmissive, base);
    // Without the texture, roughnessFactor 0.5 makes it all rough glass of α 0.25.
    let plain = format!(r#"{{"pbrMetallicRoughness":{{"metallicFactor":0,"roughnessFactor":0.5}},{glass}}}"#);
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, &plain, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    let rough = scene
        .materials()
        .iter()
        .find_map(|m| match m.physical_at(scene.textures(), Vec2::ZERO) {
            Some(PhysicalMaterial::RoughDielectric { roughness, .. }) => Some(roughness),
            _ => None,
        });
    assert_eq!(rough, Some(0.25));
}

/// The cosine-weighted mean of Fresnel's reflectance over the hemisphere for index `eta` (F̄),
/// by quadrature in cos².
fn mean_fresnel(eta: f32) -> f32 {
    let n = 4096;
    (0..n)
        .map(|j| caustica::bsdf::fresnel_dielectric(((j as f32 + 0.5) / n as f32).sqrt(), eta))
        .sum::<f32>()
        / n as f32
}

/// The glTF quad of `material` (with a white texel), read, no warning mentioning `unsaid`.
fn white_quad(test: &str, material: &str, unsaid: &str) -> Scene {
    let dir = folder(test);
    let image = png(1, 1, &[[255, 255, 255]]);
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, material, "{}"),
        &LoadSettings::default(),
    )
    .unwrap();
    assert!(
        scene.warnings().iter().all(|w| !w.contains(unsaid)),
        "{:?}",
        scene.warnings()
    );
    scene
}

/// glTF's `KHR_materials_clearcoat` over a Lambert base (specular 0): under the uniform sky
/// caustica adds to a file without lights, a quad seen face-on has radiance
/// F(0) + (1 − F(0))·ρ·(1 − F̄) with the coat's F of index 1.5 (F(0) = 0.04, F̄ its
/// cosine-weighted mean): the coat's reflection of the sky plus the base seen through it.
#[test]
fn a_gltf_clear_coat_reflects_the_sky_and_shows_the_base_through_it() {
    let scene = white_quad(
        "clearcoat",
        r#"{"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0,"roughnessFactor":1},
"extensions":{"KHR_materials_specular":{"specularFactor":0},"KHR_materials_clearcoat":{"clearcoatFactor":1,"clearcoatRoughnessFactor":0}}}"#,
        "clearcoat",
    );
    let mean_f = mean_fresnel(1.5);
    let want = 0.04 + 0.96 * 0.5 * (1.0 - mean_f);
    for integrator in ["path", "vcm"] {
        // The quad fills the view (within 22° of its normal, where F moves by 0.0002).
        let film = crate::common::render_integrator(&scene, integrator, 16, 32, 10_000, 3);
        let got = film.region_mean((0, 15), (0, 15));
        eprintln!("{integrator}: {got}, want {want}");
        assert!(
            (got - Vec3::splat(want)).abs().max_element() < 0.015 * want,
            "{integrator}: {got} vs {want}"
        );
    }
}

/// A single-sided emissive glTF material emits from its front alone: the counter-clockwise
/// face, or the clockwise one under a node that swaps handedness; a double-sided one emits
/// from both.
#[test]
fn single_sided_gltf_emitters_emit_from_their_front() {
    let dir = folder("one-sided");
    let image = png(1, 1, &[[255, 255, 255]]);
    let emits = |double_sided: bool, mirrored: bool| {
        let material = format!(r#"{{"emissiveFactor":[1,1,1],"doubleSided":{double_sided}}}"#);
        let path = quad_gltf(&dir, &image, Holder::File, &material, "{}");
        if mirrored {
            let json = std::fs::read_to_string(&path).unwrap();
            std::fs::write(
                &path,
                json.replacen(r#"{"mesh":0}"#, r#"{"mesh":0,"scale":[-1,1,1]}"#, 1),
            )
            .unwrap();
        }
        let scene = load(&path, &LoadSettings::default()).unwrap();
        let x = if mirrored { -0.5 } else { 0.5 };
        let ray = caustica::math::Ray::new(Vec3::new(x, 0.5, 1.0), -Vec3::Z);
        let hit = scene.intersect(&ray, f32::INFINITY).expect("the quad");
        let surface = scene.surface(&ray, &hit);
        let rgb = caustica::spectrum::Wavelengths::Rgb;
        let towards = |d: Vec3| scene.emission_towards(&surface, d, &rgb).x;
        (towards(Vec3::Z), towards(-Vec3::Z))
    };
    assert_eq!(emits(true, false), (1.0, 1.0));
    assert_eq!(emits(false, false), (1.0, 0.0), "the front is +z, counter-clockwise");
    assert_eq!(emits(false, true), (1.0, 0.0), "mirrored: +z stays the front");
}

/// glTF's clear coat textures (linear): the coat's weight is `clearcoatFactor` times the red
/// of `clearcoatTexture`, its roughness `clearcoatRoughnessFactor` times the green of
/// `clearcoatRoughnessTexture` (GGX α its square).
#[test]
fn gltf_clear_coat_textures_set_the_coat_point_by_point() {
    let dir = folder("clearcoat-textures");
    let image = png(2, 1, &[[0, 128, 0], [255, 255, 0]]);
    let material = r#"{"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0,"roughnessFactor":1},
"extensions":{"KHR_materials_clearcoat":{"clearcoatFactor":0.8,"clearcoatTexture":{"index":0},
"clearcoatRoughnessFactor":0.5,"clearcoatRoughnessTexture":{"index":0}}}}"#;
    let sampler = r#"{"magFilter":9728,"wrapS":33071,"wrapT":33071}"#;
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, material, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    assert!(
        scene.warnings().iter().all(|w| !w.contains("clearcoat")),
        "{:?}",
        scene.warnings()
    );
    let coat_at = |x: f32| {
        let ray = caustica::math::Ray::new(Vec3::new(x, 0.5, 1.0), -Vec3::Z);
        let hit = scene.intersect(&ray, f32::INFINITY).expect("the quad");
        scene.clearcoat(&scene.surface(&ray, &hit)).expect("a coat")
    };
    let (left, right) = (coat_at(0.25), coat_at(0.75));
    assert_eq!((left.weight, right.weight), (0.0, 0.8));
    let r = 0.5 * 128.0 / 255.0;
    assert!((left.alpha - r * r).abs() < 1e-6, "{}", left.alpha);
    assert!((right.alpha - 0.25).abs() < 1e-6, "{}", right.alpha);
    // A reference that is not a texture is said, and the factor used.
    let bad = material.replace(r#""clearcoatTexture":{"index":0}"#, r#""clearcoatTexture":{"index":7}"#);
    let scene = load(
        &quad_gltf(&dir, &image, Holder::File, &bad, sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    assert!(
        scene
            .warnings()
            .iter()
            .any(|w| w.contains("clearcoatTexture") && w.contains("factor")),
        "{:?}",
        scene.warnings()
    );
}

/// glTF's `KHR_materials_specular` over a Lambert base: the coat reflects the specular weight
/// times its colour times F, and the base loses the largest channel's share each way. Under the
/// uniform sky, a quad seen face-on has radiance c·F(0) + ρ(1 − w·F(0))(1 − w·F̄) per channel,
/// c the weight times the colour and w its largest channel.
#[test]
fn a_gltf_specular_layer_reflects_its_colour_and_weight() {
    let scene = white_quad(
        "specular",
        r#"{"pbrMetallicRoughness":{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0,"roughnessFactor":0},
"extensions":{"KHR_materials_specular":{"specularFactor":0.5,"specularColorFactor":[1,0.5,0.25]}}}"#,
        "specular",
    );
    let mean_f = mean_fresnel(1.5);
    let c = Vec3::new(0.5, 0.25, 0.125);
    let w = 0.5;
    let want = c * 0.04 + Vec3::splat(0.5 * (1.0 - w * 0.04) * (1.0 - w * mean_f));
    for integrator in ["path", "vcm"] {
        let film = crate::common::render_integrator(&scene, integrator, 16, 32, 10_000, 3);
        let got = film.region_mean((0, 15), (0, 15));
        eprintln!("{integrator}: {got}, want {want}");
        assert!(
            ((got - want) / want).abs().max_element() < 0.015,
            "{integrator}: {got} vs {want}"
        );
    }
}

/// `KHR_materials_specular`'s textures: the weight is `specularTexture`'s alpha (linear), the
/// colour `specularColorTexture` (sRGB), each times its factors.
#[test]
fn gltf_specular_textures_set_the_coat_point_by_point() {
    use caustica::description::PhysicalMaterial;
    let dir = folder("specular-textures");
    let rgba = image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba([188, 188, 188, if x == 0 { 51 } else { 255 }]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    rgba.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    let image = bytes.into_inner();
    let sampler = r#"{"magFilter":9728,"wrapS":10497,"wrapT":10497}"#;
    let tint_at = |specular: &str, u: f32| {
        let material = format!(
            r#"{{"pbrMetallicRoughness":{{"baseColorFactor":[0.5,0.5,0.5,1],"metallicFactor":0,"roughnessFactor":0.5}},
"extensions":{{"KHR_materials_specular":{{"specularFactor":0.8,"specularColorFactor":[1,0.5,1],{specular}}}}}}}"#
        );
        let scene = load(
            &quad_gltf(&dir, &image, Holder::File, &material, sampler),
            &LoadSettings::default(),
        )
        .unwrap();
        assert!(
            scene.warnings().iter().all(|w| !w.contains("specular")),
            "{:?}",
            scene.warnings()
        );
        let m = scene.materials().iter().find(|m| m.physical.is_some()).unwrap();
        match m.physical_at(scene.textures(), Vec2::new(u, 0.5)) {
            Some(PhysicalMaterial::CoatedDiffuse { coat_tint, .. }) => coat_tint,
            other => panic!("{other:?}"),
        }
    };
    let factor = Vec3::new(0.8, 0.4, 0.8);
    // The weight: alpha 51/255 = 0.2 on the left, 1 on the right.
    let left = tint_at(r#""specularTexture":{"index":0}"#, 0.25);
    let right = tint_at(r#""specularTexture":{"index":0}"#, 0.75);
    assert!((left - factor * 0.2).abs().max_element() < 1e-4, "{left}");
    assert!((right - factor).abs().max_element() < 1e-4, "{right}");
    // The colour: sRGB 188 is 0.5 linear.
    let colour = tint_at(r#""specularColorTexture":{"index":0}"#, 0.25);
    let srgb = ((188.0f32 / 255.0 + 0.055) / 1.055).powf(2.4);
    assert!((colour - factor * srgb).abs().max_element() < 1e-3, "{colour}");
}

/// glTF's `alphaMode`: MASK cuts holes where the base colour's alpha times its factor is below
/// `alphaCutoff` — for camera rays, shadow rays and every other query alike — and BLEND lets a
/// ray through with the chance 1 − coverage.
#[test]
fn alpha_masks_are_holes_for_every_ray_and_blend_passes_in_proportion() {
    let dir = folder("alpha");
    let rgba = image::RgbaImage::from_fn(2, 1, |x, _| image::Rgba([200, 100, 50, if x == 0 { 60 } else { 255 }]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    rgba.write_to(&mut bytes, image::ImageFormat::Png).unwrap();
    let image = bytes.into_inner();
    let sampler = r#"{"magFilter":9728,"wrapS":33071,"wrapT":33071}"#;
    let material = |mode: &str| {
        format!(
            r#"{{"pbrMetallicRoughness":{{"baseColorFactor":[1,1,1,0.8],"metallicFactor":0,"baseColorTexture":{{"index":0}}}},{mode}}}"#
        )
    };
    // Rays straight down −z through the quad's left (u = 0.25) and right (u = 0.75) halves.
    let down = |x: f32| caustica::math::Ray::new(Vec3::new(x, 0.5, 1.0), -Vec3::Z);
    // Left coverage 0.8 · 60/255 = 0.19 is below the cutoff 0.5; right 0.8 is above.
    let mask = load(
        &quad_gltf(&dir, &image, Holder::File, &material(r#""alphaMode":"MASK""#), sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    assert!(
        mask.intersect(&down(0.25), f32::INFINITY).is_none(),
        "a hole for camera rays"
    );
    assert!(mask.intersect(&down(0.75), f32::INFINITY).is_some());
    let (above, below) = (Vec3::new(0.25, 0.5, 1.0), Vec3::new(0.25, 0.5, -1.0));
    assert!(
        mask.segment_clear(above, Vec3::Z, below, -Vec3::Z),
        "a hole for shadow rays"
    );
    assert!(!mask.segment_clear(above + Vec3::X * 0.5, Vec3::Z, below + Vec3::X * 0.5, -Vec3::Z));
    // A cutoff of 0.1 keeps the left half.
    let low = load(
        &quad_gltf(
            &dir,
            &image,
            Holder::File,
            &material(r#""alphaMode":"MASK","alphaCutoff":0.1"#),
            sampler,
        ),
        &LoadSettings::default(),
    )
    .unwrap();
    assert!(low.intersect(&down(0.25), f32::INFINITY).is_some());
    // BLEND: of many rays through the left half, 1 − 0.19 pass.
    let blend = load(
        &quad_gltf(&dir, &image, Holder::File, &material(r#""alphaMode":"BLEND""#), sampler),
        &LoadSettings::default(),
    )
    .unwrap();
    let n = 20_000;
    let passed = (0..n)
        .filter(|i| {
            let (x, y) = (
                0.02 + 0.46 * (*i % 200) as f32 / 200.0,
                0.02 + 0.96 * (*i / 200) as f32 / 100.0,
            );
            blend
                .intersect(&caustica::math::Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z), f32::INFINITY)
                .is_none()
        })
        .count() as f32
        / n as f32;
    let want = 1.0 - 0.8 * 60.0 / 255.0;
    assert!((passed - want).abs() < 0.02, "{passed} passed, {want} expected");
}

/// An OBJ quad in the z = 0 plane (normal +z), u along +x and v along +y, with `material`
/// written as its MTL; loaded with its warnings.
fn obj_quad(dir: &Path, material: &str) -> Scene {
    std::fs::write(dir.join("m.mtl"), format!("newmtl m\nKd 0.5 0.5 0.5\n{material}\n")).unwrap();
    std::fs::write(
        dir.join("m.obj"),
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\n\
         usemtl m\nf 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/3/1 4/4/1\n",
    )
    .unwrap();
    load(&dir.join("m.obj"), &LoadSettings::default()).unwrap()
}

/// The shading normal where a ray straight down meets the quad at (x, y).
fn shading_normal_at(scene: &Scene, x: f32, y: f32) -> Vec3 {
    let ray = caustica::math::Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
    let hit = scene.intersect(&ray, f32::INFINITY).expect("the quad");
    scene.surface(&ray, &hit).shading_normal
}

/// OBJ bump maps: a grey `bump` image is heights, its slope (central differences, in texels,
/// times `-bm`) tilting the normal against it; `map_Bump` holding a normal map (as Blender
/// writes it) and `norm` read the same tilt, x and y times `-bm`.
#[test]
fn obj_bump_maps_are_heights_or_normal_maps() {
    let dir = folder("obj-bump");
    // Heights 0, 20, 40, … (of 255) rising along u, the same on both rows.
    let ramp: Vec<[u8; 3]> = (0..2).flat_map(|_| (0..8u8).map(|x| [20 * x; 3])).collect();
    std::fs::write(dir.join("ramp.png"), png(8, 2, &ramp)).unwrap();
    let scene = obj_quad(&dir, "bump -bm 2 ramp.png");
    assert!(scene.warnings().is_empty(), "{:?}", scene.warnings());
    // Texel 3's centre: its neighbours differ by 40/255 over two texels.
    let slope = 2.0 * (40.0 / 255.0) / 2.0;
    let want = Vec3::new(-slope, 0.0, 1.0).normalize();
    let got = shading_normal_at(&scene, 3.5 / 8.0, 0.25);
    assert!(near(got, want, 1e-4), "height ramp: {got} against {want}");
    let flat = obj_quad(&dir, "");
    assert!(near(shading_normal_at(&flat, 0.4, 0.3), Vec3::Z, 1e-6));

    let texel = [209u8, 128, 225];
    std::fs::write(dir.join("normal.png"), png(1, 1, &[texel])).unwrap();
    let m = Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) / 255.0 * 2.0 - Vec3::ONE;
    let want = Vec3::new(m.x * 0.5, m.y * 0.5, m.z).normalize();
    for statement in ["map_Bump -bm 0.5 normal.png", "norm -bm 0.5 normal.png"] {
        let got = shading_normal_at(&obj_quad(&dir, statement), 0.3, 0.6);
        assert!(near(got, want, 1e-4), "{statement}: {got} against {want}");
    }
}

/// OBJ `map_d`: the mask (alpha, or luminance where the image has none) times d is the chance a
/// ray meets the surface: black texels are holes for camera and shadow rays.
#[test]
fn obj_map_d_cuts_holes() {
    let dir = folder("obj-mask");
    std::fs::write(dir.join("mask.png"), png(2, 1, &[[0, 0, 0], [255, 255, 255]])).unwrap();
    let scene = obj_quad(&dir, "map_d mask.png");
    let down = |x: f32| caustica::math::Ray::new(Vec3::new(x, 0.5, 1.0), -Vec3::Z);
    assert!(scene.intersect(&down(0.25), f32::INFINITY).is_none(), "a hole");
    assert!(scene.intersect(&down(0.75), f32::INFINITY).is_some());
    assert!(scene.segment_clear(Vec3::new(0.25, 0.5, 1.0), Vec3::Z, Vec3::new(0.25, 0.5, -1.0), -Vec3::Z));
    // d 0 leaves nothing of the surface.
    let gone = obj_quad(&dir, "d 0\nmap_d mask.png");
    assert!(gone.intersect(&down(0.75), f32::INFINITY).is_none());
}

/// OBJ `map_Ke` glows as its sRGB texels times Ke; texture options `-s`, `-o` and `-clamp on`
/// move and hold the image; a file name with spaces, written with backslashes, is found.
#[test]
fn obj_map_ke_and_texture_options() {
    let dir = folder("obj-options");
    std::fs::create_dir_all(dir.join("maps")).unwrap();
    std::fs::write(dir.join("maps/wood grain.png"), png(2, 1, &[[0, 0, 0], [200, 100, 50]])).unwrap();
    let scene = obj_quad(&dir, "Ke 2 2 4\nmap_Ke maps\\wood grain.png");
    // Said, not silent: the Windows path, and that the glow is the only light.
    let warnings = scene.warnings().join("\n");
    assert_eq!(scene.warnings().len(), 2, "{warnings}");
    assert!(warnings.contains("backslashes are read as /"), "{warnings}");
    assert!(
        warnings.contains("only lights") && warnings.contains("--point-light"),
        "{warnings}"
    );
    let material = scene
        .materials()
        .iter()
        .find(|m| matches!(m.emissive, Channel::Texture(_)))
        .expect("a textured emission");
    let glow = |u: f32| material.eval(scene.textures(), Vec2::new(u, 0.5)).emissive;
    assert_eq!(glow(0.25), Vec3::ZERO, "black texels do not glow");
    let want = Vec3::new(2.0 * srgb(200), 2.0 * srgb(100), 4.0 * srgb(50));
    assert!(near(glow(0.75), want, 1e-5), "{}", glow(0.75));

    let b = Vec3::new(srgb(200), srgb(100), srgb(50));
    // u ↦ 2u + 0.5: u = −0.125 reads texel 0's centre, u = 0.125 texel 1's; u = 0.5 reads 1.5,
    // held at the edge texel (repeating would blend the two halves).
    let scene = obj_quad(&dir, "map_Kd -s 2 1 -o 0.5 0 -clamp on maps/wood grain.png");
    assert!(near(diffuse_at(&scene, Vec2::new(-0.125, 0.5)), Vec3::ZERO, 1e-6));
    assert!(near(diffuse_at(&scene, Vec2::new(0.125, 0.5)), b, 1e-6));
    assert!(near(diffuse_at(&scene, Vec2::new(0.5, 0.5)), b, 1e-6));
    let scene = obj_quad(&dir, "map_Kd -s 2 1 -o 0.5 0 maps/wood grain.png");
    assert!(near(diffuse_at(&scene, Vec2::new(0.5, 0.5)), b * 0.5, 1e-6));

    // Unread options are warnings; a missing file is a warning naming what stands in.
    let scene = obj_quad(&dir, "map_Kd -imfchan l -blendu off maps/wood grain.png\nbump gone.png");
    let warnings = scene.warnings().join("\n");
    assert!(
        warnings.contains("`-imfchan` is not read") && warnings.contains("`-blendu` is not read"),
        "{warnings}"
    );
    assert!(
        warnings.contains("gone.png") && warnings.contains("without it"),
        "{warnings}"
    );
    assert!(near(diffuse_at(&scene, Vec2::new(0.25, 0.5)), Vec3::ZERO, 1e-6));
}

/// A pbrt quad in the z = 0 plane (u along +x, v along +y) under `material`, with `shape`'s
/// extra parameters; `textures` are declared before it.
fn pbrt_quad(dir: &Path, textures: &str, material: &str, shape: &str) -> Scene {
    let text = format!(
        r#"LookAt 0 0 3  0 0 0  0 1 0
Camera "perspective" "float fov" 40
WorldBegin
LightSource "point" "rgb I" [1 1 1] "point3 from" [0 0 2]
{textures}
Material {material}
Shape "trianglemesh" "point3 P" [0 0 0 1 0 0 1 1 0 0 1 0] "point2 uv" [0 0 1 0 1 1 0 1] "integer indices" [0 1 2 0 2 3] {shape}
"#
    );
    std::fs::write(dir.join("scene.pbrt"), text).unwrap();
    load(&dir.join("scene.pbrt"), &LoadSettings::default()).unwrap()
}

/// pbrt-v4's `normalmap` (a linear image, texels 2c − 1 in the frame of u and the normal)
/// tilts the shading normal; a missing one is a warning.
#[test]
fn pbrt_normalmap_tilts_the_shading_normal() {
    let dir = folder("pbrt-normal");
    let texel = [160u8, 100, 240];
    std::fs::write(dir.join("n.png"), png(1, 1, &[texel])).unwrap();
    let scene = pbrt_quad(&dir, "", r#""diffuse" "string normalmap" "n.png""#, "");
    let want = (Vec3::new(texel[0] as f32, texel[1] as f32, texel[2] as f32) / 255.0 * 2.0 - Vec3::ONE).normalize();
    let got = shading_normal_at(&scene, 0.3, 0.6);
    assert!(near(got, want, 1e-4), "{got} against {want}");
    let missing = pbrt_quad(&dir, "", r#""diffuse" "string normalmap" "gone.png""#, "");
    assert!(
        missing.warnings().iter().any(|w| w.contains("gone.png")),
        "{:?}",
        missing.warnings()
    );
    assert!(near(shading_normal_at(&missing, 0.3, 0.6), Vec3::Z, 1e-6));
}

/// pbrt-v4's shape `alpha`: a float texture's zeros are holes, ones solid; a constant 0 leaves
/// the shape out, a constant between lets rays through in proportion.
#[test]
fn pbrt_alpha_cuts_holes() {
    let dir = folder("pbrt-alpha");
    std::fs::write(dir.join("mask.png"), png(2, 1, &[[0, 0, 0], [255, 255, 255]])).unwrap();
    let down = |x: f32, y: f32| caustica::math::Ray::new(Vec3::new(x, y, 1.0), -Vec3::Z);
    let texture = r#"Texture "mask" "float" "imagemap" "string filename" "mask.png" "string filter" "point""#;
    let scene = pbrt_quad(&dir, texture, r#""diffuse""#, r#""texture alpha" "mask""#);
    assert!(scene.intersect(&down(0.25, 0.5), f32::INFINITY).is_none(), "a hole");
    assert!(scene.intersect(&down(0.75, 0.5), f32::INFINITY).is_some());
    let gone = pbrt_quad(&dir, "", r#""diffuse""#, r#""float alpha" 0"#);
    assert!(gone.intersect(&down(0.75, 0.5), f32::INFINITY).is_none());
    let whole = pbrt_quad(&dir, "", r#""diffuse""#, r#""float alpha" 1"#);
    assert!(whole.intersect(&down(0.25, 0.5), f32::INFINITY).is_some());
    let half = pbrt_quad(&dir, "", r#""diffuse""#, r#""float alpha" 0.3"#);
    let n = 10_000;
    let passed = (0..n)
        .filter(|i| {
            let (x, y) = (
                0.02 + 0.96 * (i % 100) as f32 / 100.0,
                0.02 + 0.96 * (i / 100) as f32 / 100.0,
            );
            half.intersect(&down(x, y), f32::INFINITY).is_none()
        })
        .count() as f32
        / n as f32;
    assert!((passed - 0.7).abs() < 0.03, "{passed} of rays passed, 0.7 expected");
}

/// PFM images (Bitterli's scenes use them) are read as the floats they hold, linear, rows
/// stored bottom-up: a pbrt `imagemap` of a 2×1 PFM reads each texel at its centre.
#[test]
fn pfm_images_are_read_as_linear_floats() {
    let dir = folder("pfm");
    let mut bytes = b"PF\n2 1\n-1.0\n".to_vec();
    for v in [0.25f32, 0.5, 2.0, 0.125, 0.0, 4.0] {
        bytes.extend(v.to_le_bytes());
    }
    std::fs::write(dir.join("sky.pfm"), &bytes).unwrap();
    let texture = r#"Texture "t" "spectrum" "imagemap" "string filename" "sky.pfm" "string filter" "point""#;
    let scene = pbrt_quad(&dir, texture, r#""diffuse" "texture reflectance" "t""#, "");
    assert_eq!(diffuse_at(&scene, Vec2::new(0.25, 0.5)), Vec3::new(0.25, 0.5, 2.0));
    assert_eq!(diffuse_at(&scene, Vec2::new(0.75, 0.5)), Vec3::new(0.125, 0.0, 4.0));
    // Cut short: a located refusal naming the file, not a panic.
    std::fs::write(dir.join("sky.pfm"), &bytes[..bytes.len() - 3]).unwrap();
    let Err(err) = load(&dir.join("scene.pbrt"), &LoadSettings::default()) else {
        panic!("a cut-short image is refused");
    };
    let err = err.to_string();
    assert!(err.contains("sky.pfm") && err.contains("cut short"), "{err}");
}

/// OBJ and MTL from Windows exporters: `.\` and backslashes between folders, and names in the
/// local code page (not UTF-8), read with a warning each; the material still matches its
/// `usemtl` (both names read alike) and its colour is used.
#[test]
fn obj_from_windows_exporters_reads_with_warnings() {
    let dir = folder("obj-windows");
    std::fs::create_dir_all(dir.join("mats")).unwrap();
    // "Matériau" in Latin-1: é is the single byte 0xE9.
    let mut mtl = b"newmtl Mat\xe9riau\nKd 0.2 0.4 0.6\n".to_vec();
    mtl.extend(b"Ks 0 0 0\n");
    std::fs::write(dir.join("mats/m.mtl"), mtl).unwrap();
    let mut obj = b"mtllib .\\mats\\m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl Mat\xe9riau\nf 1 2 3\n".to_vec();
    obj.extend(b"# end\n");
    std::fs::write(dir.join("m.obj"), obj).unwrap();
    let scene = load(&dir.join("m.obj"), &LoadSettings::default()).unwrap();
    let warnings = scene.warnings().join("\n");
    assert!(
        warnings.matches("not valid UTF-8").count() == 2,
        "the OBJ and the MTL: {warnings}"
    );
    assert!(warnings.contains("backslashes are read as /"), "{warnings}");
    assert!(
        !warnings.contains("missing") && !warnings.contains("no material"),
        "{warnings}"
    );
    let kd = scene
        .materials()
        .iter()
        .map(|m| m.eval(scene.textures(), Vec2::ZERO).diffuse);
    assert!(
        kd.into_iter().any(|d| d == Vec3::new(0.2, 0.4, 0.6)),
        "the MTL colour is used"
    );
}

/// Images are decoded in parallel before the materials are built: a scene of several images
/// reads each as alone, and one that cannot be decoded is still refused at its own place.
#[test]
fn images_decoded_together_read_as_alone_and_fail_at_their_place() {
    let dir = folder("parallel");
    std::fs::write(dir.join("a.png"), png(1, 1, &[[10, 20, 30]])).unwrap();
    std::fs::write(dir.join("b.png"), png(1, 1, &[[200, 100, 50]])).unwrap();
    let textures = r#"Texture "a" "spectrum" "imagemap" "string filename" "a.png"
Texture "b" "spectrum" "imagemap" "string filename" "b.png""#;
    let scene = pbrt_quad(
        &dir,
        textures,
        r#""diffuse" "texture reflectance" "a" "string normalmap" "b.png""#,
        "",
    );
    assert_eq!(scene.textures().len(), 2);
    assert!(near(
        diffuse_at(&scene, Vec2::new(0.5, 0.5)),
        Vec3::new(srgb(10), srgb(20), srgb(30)),
        1e-6
    ));
    let cut = png(1, 1, &[[200, 100, 50]]);
    std::fs::write(dir.join("b.png"), &cut[..cut.len() / 2]).unwrap();
    let text = std::fs::read_to_string(dir.join("scene.pbrt")).unwrap();
    let Err(err) = load(&dir.join("scene.pbrt"), &LoadSettings::default()) else {
        panic!("a broken image is refused");
    };
    let err = err.to_string();
    // The normal map names it last (texture "b" itself is never read).
    let at = text.rfind("\"b.png\"").unwrap();
    let line = text[..at].matches('\n').count() + 1;
    assert!(err.contains("b.png") && err.contains(&format!(":{line}:")), "{err}");
}
