//! Tests of the whole reader through [`parse`](super::parse).

use super::ast::*;
use super::{parse, ParseOptions};
use crate::camera::Camera;
use crate::error::line_col;
use crate::ParseError;
use glam::{Mat4, Vec2, Vec3};
use std::path::{Path, PathBuf};

const HEADER: &str = "SBT-raytracer 1.0\n";

fn read(body: &str) -> RayScene {
    let text = format!("{HEADER}{body}");
    match parse(&text, Path::new("scenes"), &ParseOptions::default()) {
        Ok(scene) => scene,
        Err(e) => panic!("parse failed: {} at {:?} (help {:?})", e.message, e.span, e.help),
    }
}

/// [`read`] in a folder of its own holding (empty) files named `images`, so maps of them exist.
pub(super) fn read_with_images(body: &str, images: &[&str]) -> (RayScene, PathBuf) {
    let dir = std::env::temp_dir().join(format!(
        "caustica-ray-images-{}-{}",
        std::process::id(),
        images.join("-")
    ));
    std::fs::create_dir_all(&dir).unwrap();
    for image in images {
        std::fs::write(dir.join(image), b"").unwrap();
    }
    let text = format!("{HEADER}{body}");
    let scene = parse(&text, &dir, &ParseOptions::default()).unwrap_or_else(|e| panic!("parse failed: {}", e.message));
    (scene, dir)
}

fn read_as(body: &str, dialect: Dialect) -> Result<RayScene, ParseError> {
    let text = format!("{HEADER}{body}");
    let options = ParseOptions { dialect: Some(dialect) };
    parse(&text, Path::new("scenes"), &options)
}

/// The error for `body`, and the text the error's span covers.
fn fail(body: &str) -> (ParseError, String) {
    let text = format!("{HEADER}{body}");
    match parse(&text, Path::new("scenes"), &ParseOptions::default()) {
        Ok(_) => panic!("expected an error for {body:?}"),
        Err(e) => {
            let covered = text.get(e.span.clone()).unwrap_or("<bad span>").to_string();
            (e, covered)
        }
    }
}

fn close(a: Vec3, b: Vec3) -> bool {
    (a - b).length() < 1e-5
}

fn point(object: &ObjectDesc, p: Vec3) -> Vec3 {
    object.world_from_object.transform_point3(p)
}

// ---------------------------------------------------------------- header

#[test]
fn header_versions() {
    assert!(read("").objects.is_empty());
    for ok in ["SBT-raytracer 1.1", "SBT-raytracer 0.5", "// c\nSBT-raytracer 1.0"] {
        assert!(parse(ok, Path::new(""), &ParseOptions::default()).is_ok(), "{ok}");
    }
    let err = parse("SBT-raytracer 1.2", Path::new(""), &ParseOptions::default()).expect_err("version too high");
    assert_eq!(err.span, 14..17);
    let err = parse("camera {}", Path::new(""), &ParseOptions::default()).expect_err("no header");
    assert_eq!(err.span, 0..6);
    assert!(err.message.contains("SBT-raytracer"));
    // Dialect O wants exactly 1.0.
    assert!(parse(
        "SBT-raytracer 1.1",
        Path::new(""),
        &ParseOptions {
            dialect: Some(Dialect::Dictionary)
        }
    )
    .is_err());
}

#[test]
fn byte_order_mark_is_skipped() {
    let text = "\u{feff}SBT-raytracer 1.0\nsphere {}";
    let scene = parse(text, Path::new(""), &ParseOptions::default()).expect("BOM accepted");
    assert_eq!(scene.objects.len(), 1);
}

// ---------------------------------------------------------------- statements and defaults

#[test]
fn camera_fields() {
    let scene = read(
        "camera { position = (1,2,3); viewdir = (0,0,-2) updir = (0,1,0); fov = 45; \
         aspectratio = 1.5; quaternian = (0, 0, 0, 1); }",
    );
    let camera = scene.camera.expect("camera");
    assert_eq!(camera.position, Vec3::new(1.0, 2.0, 3.0));
    assert_eq!(camera.viewdir, Some(Vec3::new(0.0, 0.0, -2.0)));
    assert_eq!(camera.updir, Some(Vec3::Y));
    assert_eq!(camera.fov_degrees, Some(45.0));
    assert_eq!(camera.aspect_ratio, Some(1.5));
    assert_eq!(camera.quaternion, Some([0.0, 0.0, 0.0, 1.0]));
    assert_eq!(camera.basis, CameraBasis::AsGiven);
    assert_eq!(camera.look_at, None);

    let camera = read("camera {}").camera.expect("camera");
    assert_eq!(camera.position, Vec3::ZERO);
    assert_eq!((camera.fov_degrees, camera.aspect_ratio), (None, None));

    let (err, _) = fail("camera { viewdir = (0,0,-1); }");
    assert!(err.message.contains("`viewdir` and `updir`"), "{}", err.message);
}

#[test]
fn lights_and_their_defaults() {
    let scene = read(
        "point_light { position = (1,2,3); colour = (1,1,1) }\n\
         point_light { color = (2,0,0); position = (0,0,0); constant_attenuation_coeff = 0.25;\
           linear_attenuation_coeff = 0.5; quadratic_attenuation_coeff = 0.125; }\n\
         directional_light { direction = (0,0,-1); color = (0.5,0.5,0.5); }\n\
         ambient_light { color = (0.1,0.1,0.1); }\nambient_light { colour = (0.2,0.3,0.4) }",
    );
    assert_eq!(scene.lights.len(), 3);
    match &scene.lights[0] {
        LightDesc::Point {
            position,
            color,
            attenuation,
            ..
        } => {
            assert_eq!(*position, Vec3::new(1.0, 2.0, 3.0));
            assert_eq!(*color, Vec3::ONE);
            assert_eq!(*attenuation, [0.0, 0.0, 1.0]);
        }
        other => panic!("{other:?}"),
    }
    match &scene.lights[1] {
        LightDesc::Point { attenuation, .. } => assert_eq!(*attenuation, [0.25, 0.5, 0.125]),
        other => panic!("{other:?}"),
    }
    match &scene.lights[2] {
        LightDesc::Directional { direction, color, .. } => {
            assert_eq!(*direction, Vec3::NEG_Z);
            assert_eq!(*color, Vec3::splat(0.5));
        }
        other => panic!("{other:?}"),
    }
    assert!(close(scene.ambient, Vec3::new(0.3, 0.4, 0.5)));
}

#[test]
fn light_errors() {
    let (err, covered) = fail("point_light { position = (1,2,3); position = (1,2,3); color = (1,1,1); }");
    assert!(err.message.contains("second `position`"));
    assert_eq!(covered, "position");
    assert_eq!(err.span.start, HEADER.len() + 34);
    let (err, _) = fail("point_light { position = (1,2,3); }");
    assert!(err.message.contains("needs a `color`"));
    let (err, _) = fail("directional_light { color = (1,1,1); }");
    assert!(err.message.contains("needs a `direction`"));
    let (err, _) = fail("directional_light { direction = (1,1,1); colour = (1,1,1); color = (1,1,1) }");
    assert!(err.message.contains("second `color`"));
    let (err, _) = fail("ambient_light { color = (1,1,1); color = (1,1,1); }");
    assert!(err.message.contains("exactly one"));
}

#[test]
fn primitives_and_their_defaults() {
    let scene = read(
        "sphere {} box { name = thing; } square { name = \"x\" } cylinder {}\n\
         cone {} cone { height = 2; bottom_radius = -3; top_radius = 0.5; capped = false; }\n\
         cylinder { capped = false; }",
    );
    let shapes: Vec<_> = scene.objects.iter().map(|o| &o.shape).collect();
    assert!(matches!(shapes[0], ShapeDesc::Sphere));
    assert!(matches!(shapes[1], ShapeDesc::Box));
    assert!(matches!(shapes[2], ShapeDesc::Square));
    assert!(matches!(shapes[3], ShapeDesc::Cylinder { capped: true }));
    match shapes[4] {
        ShapeDesc::Cone {
            height,
            bottom_radius,
            top_radius,
            capped,
        } => assert_eq!((*height, *bottom_radius, *top_radius, *capped), (1.0, 1.0, 0.0, true)),
        other => panic!("{other:?}"),
    }
    match shapes[5] {
        ShapeDesc::Cone {
            height,
            bottom_radius,
            top_radius,
            capped,
        } => assert_eq!((*height, *bottom_radius, *top_radius, *capped), (2.0, 3.0, 0.5, false)),
        other => panic!("{other:?}"),
    }
    assert!(matches!(shapes[6], ShapeDesc::Cylinder { capped: false }));
    for object in &scene.objects {
        assert_eq!(object.material, MaterialDesc::default());
        assert_eq!(object.world_from_object, Mat4::IDENTITY);
    }
    assert_eq!(scene.objects[1].span, HEADER.len() + 10..HEADER.len() + 13);
    // `capped` is for cones and cylinders only.
    let (err, covered) = fail("sphere { capped = true; }");
    assert_eq!(covered, "capped");
    assert!(err.message.contains("`sphere` field"), "{}", err.message);
}

#[test]
fn trimesh_lists_and_inheritance() {
    let scene = read(
        "material = { diffuse = (0.5, 0.5, 0.5); }\n\
         polymesh {\n\
           faces = ((0,1,2,3));\n\
           points = ((0,0,0),(1,0,0),(1,1,0),(0,1,0));\n\
           material = { specular = (1,1,1); }\n\
           materials = ({ diffuse = (1,0,0); }, { emissive = (0,1,0); }, {}, {});\n\
           normals = ((0,0,1),(0,0,1),(0,0,1),(0,0,1));\n\
           texture_uv = ((0,0),(1,0),(1,1),(0,1));\n\
         }\n\
         trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)); gennormals; }",
    );
    assert_eq!(scene.objects.len(), 2);
    let ShapeDesc::Trimesh(mesh) = &scene.objects[0].shape else {
        panic!("not a mesh")
    };
    assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(mesh.uvs.as_ref().expect("uvs")[2], Vec2::ONE);
    assert_eq!(mesh.normals.as_ref().expect("normals").len(), 4);
    let base = &scene.objects[0].material;
    assert_eq!(base.diffuse, Param::grey(0.5));
    assert_eq!(base.specular, Param::grey(1.0));
    let per_vertex = mesh.materials.as_ref().expect("materials");
    // Entries start from the mesh's material at that point: default diffuse + mesh specular.
    assert_eq!(per_vertex[0].diffuse, Param::Constant(Vec3::X));
    assert_eq!(per_vertex[0].specular, Param::grey(1.0));
    assert_eq!(per_vertex[1].diffuse, Param::grey(0.5));
    assert_eq!(per_vertex[1].emissive, Param::Constant(Vec3::Y));
    let ShapeDesc::Trimesh(mesh) = &scene.objects[1].shape else {
        panic!("not a mesh")
    };
    assert!(close(mesh.normals.as_ref().expect("generated")[0], Vec3::Z));
}

#[test]
fn trimesh_errors() {
    let (err, covered) = fail("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2),(0,1,7)); }");
    assert_eq!(err.message, "face 1 uses vertex 7 but the mesh has 3 points");
    assert_eq!(covered, "(0,1,7)");
    let (err, _) = fail("trimesh { points = ((0,0,0),(1,0,0)); faces = ((0,1)); }");
    assert!(err.message.contains("at least 3"));
    let (err, covered) = fail("trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); normals = ((0,0,1)); }");
    assert!(err.message.contains("3 points but 1 normals"));
    assert_eq!(covered, "((0,0,1))");
    // The `;` after a list is required, and `gennormals` needs its `;` too.
    let (err, covered) = fail("trimesh { points = ((0,0,0)) faces = ((0,0,0)); }");
    assert_eq!(covered, "faces");
    assert!(err.message.starts_with("expected `;` after the `points` list"));
    assert!(fail("trimesh { gennormals }")
        .0
        .message
        .contains("`;` after `gennormals`"));
}

#[test]
fn degenerate_mesh_is_dropped_with_warnings() {
    let scene = read("trimesh { points = ((0,0,0),(1,0,0),(2,0,0)); faces = ((0,1,2)); } sphere {}");
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.warnings.len(), 2);
}

// ---------------------------------------------------------------- materials

#[test]
fn materials_inherit_from_the_current_default() {
    let (scene, dir) = read_with_images(
        "sphere {}\n\
         material = { diffuse = (1, 0, 0); shininess = 25.6; };\n\
         sphere {}\n\
         sphere { material = { specular = (0, 1, 0); index = 1.5; transmissive = map(\"glass.png\"); } }\n\
         material = { reflective = (0.5, 0.5, 0.5) }\n\
         box {}",
        &["glass.png"],
    );
    let m: Vec<&MaterialDesc> = scene.objects.iter().map(|o| &o.material).collect();
    assert_eq!(*m[0], MaterialDesc::default());
    assert_eq!(m[1].diffuse, Param::Constant(Vec3::X));
    assert_eq!(m[1].shininess, Param::grey(25.6));
    assert_eq!(m[2].diffuse, Param::Constant(Vec3::X));
    assert_eq!(m[2].specular, Param::Constant(Vec3::Y));
    assert_eq!(m[2].index, Param::grey(1.5));
    match &m[2].transmissive {
        Param::Texture(map) => {
            let course = crate::description::ImageMap::course(dir.join("glass.png"), map.span.clone());
            assert_eq!(**map, course, "read as stored, clamped, bilinear");
            assert_eq!(map.span.end - map.span.start, "map(\"glass.png\")".len());
        }
        other => panic!("{other:?}"),
    }
    // The object's own material does not change the default; the second top-level one builds on the first.
    assert_eq!(m[3].diffuse, Param::Constant(Vec3::X));
    assert_eq!(m[3].specular, Param::grey(0.0));
    assert_eq!(m[3].reflective, Param::grey(0.5));
    assert_eq!(m[3].index, Param::grey(1.0));
}

/// A map of an image that is not there reads mid grey, with a warning at the map, in both
/// dialects; the render goes on.
#[test]
fn a_missing_image_reads_mid_grey_with_a_located_warning() {
    let (scene, dir) = read_with_images(
        "sphere { material = { diffuse = map(\"here.png\"); specular = map(\"gone.png\"); } }",
        &["here.png"],
    );
    let m = &scene.objects[0].material;
    assert!(
        matches!(&m.diffuse, Param::Texture(map) if map.source == crate::description::ImageSource::File(dir.join("here.png")))
    );
    assert_eq!(m.specular, Param::grey(0.5));
    assert_eq!(scene.warnings.len(), 1, "{:?}", scene.warnings);
    let (message, span) = &scene.warnings[0];
    assert!(
        message.contains("gone.png` is missing: the texture reads mid grey"),
        "{message}"
    );
    let text =
        format!("{HEADER}sphere {{ material = {{ diffuse = map(\"here.png\"); specular = map(\"gone.png\"); }} }}");
    assert_eq!(&text[span.clone()], "map(\"gone.png\")");
    for dialect in [Dialect::Tokenizer, Dialect::Dictionary] {
        let scene = read_as("sphere { material = { diffuse = map(\"gone.png\"); } }", dialect).unwrap();
        assert_eq!(scene.objects[0].material.diffuse, Param::grey(0.5), "{dialect:?}");
        assert!(
            scene.warnings.iter().any(|(w, _)| w.contains("is missing")),
            "{dialect:?}"
        );
    }
}

#[test]
fn named_materials_register_and_copy() {
    let scene = read(
        "material = { name glass; transmissive = (1,1,1); index = 1.5; }\n\
         material = { diffuse = (0,0,1); name = \"blue paint\" }\n\
         sphere { material = glass; }\n\
         box { material = \"blue paint\"; }\n\
         material = glass;\n\
         square {}\n\
         trimesh { points = ((0,0,0),(1,0,0),(0,1,0)); faces = ((0,1,2)); materials = (glass, \"blue paint\", {}); }",
    );
    let glass = &scene.objects[0].material;
    assert_eq!(glass.name.as_deref(), Some("glass"));
    assert_eq!(glass.transmissive, Param::grey(1.0));
    // `glass` was registered before `blue paint` set the default's diffuse.
    assert_eq!(glass.diffuse, Param::grey(0.0));
    let blue = &scene.objects[1].material;
    assert_eq!(blue.name.as_deref(), Some("blue paint"));
    assert_eq!(blue.diffuse, Param::Constant(Vec3::Z));
    assert_eq!(blue.transmissive, Param::grey(1.0));
    assert_eq!(&scene.objects[2].material, glass);
    let ShapeDesc::Trimesh(mesh) = &scene.objects[3].shape else {
        panic!("mesh")
    };
    let per_vertex = mesh.materials.as_ref().expect("materials");
    assert_eq!(&per_vertex[0], glass);
    assert_eq!(&per_vertex[1], blue);
}

#[test]
fn named_material_errors() {
    let (err, covered) = fail("material = { name glass; }\nsphere { material = glas; }");
    assert_eq!(err.message, "unknown material `glas`");
    assert_eq!(err.help.as_deref(), Some("did you mean `glass`?"));
    assert_eq!(covered, "glas");
    let (err, covered) = fail("material = { name glass; }\nbox { material = { name glass; } }");
    assert!(err.message.contains("defined twice"));
    assert_eq!(covered, "glass");
    assert_eq!(err.span.start, HEADER.len() + 51);
    // `name ID` needs its `;`; a keyword needs quotes.
    assert!(fail("material = { name glass }").0.message.contains("`;`"));
    let (err, _) = fail("material = { name box; }");
    assert!(err.help.expect("help").contains("quotes"));
}

#[test]
fn material_inside_a_group_sets_the_default_from_there_on() {
    let scene = read(
        "{ sphere {} material = { diffuse = (1,1,1); } box { } }\n\
         square {}",
    );
    assert_eq!(scene.objects[0].material.diffuse, Param::grey(0.0));
    assert_eq!(scene.objects[1].material.diffuse, Param::grey(1.0));
    assert_eq!(scene.objects[2].material.diffuse, Param::grey(1.0));
}

// ---------------------------------------------------------------- transforms and groups

#[test]
fn transforms_compose_outermost_first() {
    let scene = read(
        "translate(1, 0, 0, rotate(0, 0, 1, 1.5707963, scale(2, sphere {})));\n\
         scale(2, -1, 0.5, box {})\n\
         scale(3, { square {} })\n\
         transform((1,0,0,5),(0,2,0,6),(0,0,1,7),(0,0,0,1), cylinder {})",
    );
    let o = &scene.objects;
    assert!(close(point(&o[0], Vec3::X), Vec3::new(1.0, 2.0, 0.0)));
    assert!(close(point(&o[1], Vec3::ONE), Vec3::new(2.0, -1.0, 0.5)));
    assert!(close(point(&o[2], Vec3::ONE), Vec3::splat(3.0)));
    assert!(close(point(&o[3], Vec3::ONE), Vec3::new(6.0, 8.0, 8.0)));
}

#[test]
fn groups_share_their_transform() {
    let scene = read(
        "translate(0, 0, 5, { sphere {} { translate(1, 0, 0, box {}); } cone {} });\n\
         { } ;; { { } }",
    );
    assert_eq!(scene.objects.len(), 3);
    assert!(close(point(&scene.objects[0], Vec3::ZERO), Vec3::new(0.0, 0.0, 5.0)));
    assert!(close(point(&scene.objects[1], Vec3::ZERO), Vec3::new(1.0, 0.0, 5.0)));
    assert!(close(point(&scene.objects[2], Vec3::ZERO), Vec3::new(0.0, 0.0, 5.0)));
    // A stray `;` is not allowed inside a group, and groups must close.
    let (err, covered) = fail("{ sphere {}; }");
    assert_eq!(covered, ";");
    assert!(err.help.is_some());
    let (err, _) = fail("translate(0,0,0, { sphere {}");
    assert!(err.message.contains("`}` to close the group"));
    let (err, _) = fail("translate(0,0,0, sphere {} box {})");
    assert!(err.message.starts_with("expected `)` to close `translate`"));
}

#[test]
fn transform_errors_are_located() {
    let (err, covered) = fail("rotate(0, 0, 0, 1, sphere {})");
    assert!(err.message.contains("zero length"));
    assert_eq!(covered, "rotate(0, 0, 0, 1,");
    let (err, covered) = fail("scale(1, 0, 1, sphere {})");
    assert!(err.message.contains("singular"));
    assert!(covered.starts_with("scale("));
    let (err, _) = fail("transform((1,0,0,0),(1,0,0,0),(0,0,1,0),(0,0,0,1), sphere {})");
    assert!(err.message.contains("singular"));
    let (err, covered) = fail("translate(1e999, 0, 0, sphere {})");
    assert!(err.message.contains("out of range"));
    assert_eq!(covered, "1e999");
}

#[test]
fn deep_nesting_does_not_overflow_a_small_stack() {
    const DEPTH: usize = 10_000;
    let run = || {
        let translates = format!(
            "{HEADER}{}sphere {{}}{}",
            "translate(0,0,0, ".repeat(DEPTH),
            ")".repeat(DEPTH)
        );
        let groups = format!("{HEADER}{}sphere {{}}{}", "{ ".repeat(DEPTH), "} ".repeat(DEPTH));
        let mixed = format!("{HEADER}{}box {{}}{}", "scale(1, { ".repeat(DEPTH), "}) ".repeat(DEPTH));
        let dictionary = format!(
            "{HEADER}{}sphere {{ material = {{}}; }}{}",
            "translate(0,0,0, ".repeat(DEPTH),
            ")".repeat(DEPTH)
        );
        let mut counts = Vec::new();
        for (text, dialect) in [
            (&translates, None),
            (&groups, None),
            (&mixed, None),
            (&dictionary, Some(Dialect::Dictionary)),
        ] {
            let options = ParseOptions { dialect };
            let scene = parse(text, Path::new(""), &options).map_err(|e| e.message)?;
            counts.push(scene.objects.len());
        }
        // Unclosed deep nesting fails cleanly too.
        let truncated = &translates[..translates.len() - 10];
        assert!(parse(truncated, Path::new(""), &ParseOptions::default()).is_err());
        Ok::<_, String>(counts)
    };
    let counts = std::thread::Builder::new()
        .stack_size(2 << 20)
        .spawn(run)
        .expect("thread starts")
        .join()
        .expect("no stack overflow");
    assert_eq!(counts, Ok(vec![1, 1, 1, 1]));
}

// ---------------------------------------------------------------- errors and suggestions

#[test]
fn error_names_expected_and_found_with_location() {
    let body = "sphere {\n  material = {\n    diffuse (1, 0, 0);\n  }\n}";
    let text = format!("{HEADER}{body}");
    let err = parse(&text, Path::new(""), &ParseOptions::default()).expect_err("missing =");
    assert_eq!(err.message, "expected `=` after `diffuse`, found `(`");
    assert_eq!(&text[err.span.clone()], "(");
    assert_eq!(line_col(&text, err.span.start), (4, 13));
}

#[test]
fn misspelled_keywords_get_suggestions() {
    let (err, covered) = fail("sphere { material = { difuse = (1,0,0); } }");
    assert_eq!(covered, "difuse");
    assert_eq!(err.help.as_deref(), Some("did you mean `diffuse`?"));
    assert!(err.message.contains("found `difuse`"));
    let (err, _) = fail("spehre {}");
    assert_eq!(err.help.as_deref(), Some("did you mean `sphere`?"));
    let (err, _) = fail("point_light { position = (0,0,0); colr = (1,1,1); }");
    assert_eq!(err.help.as_deref(), Some("did you mean `color`?"));
    let (err, _) = fail("sphere { fieldofview = 3; }");
    assert_eq!(err.help, None);
}

#[test]
fn student_extensions_are_read_or_skipped_with_a_located_warning() {
    let warned = |scene: &RayScene, text: &str, starts: &str| {
        let full = format!("{HEADER}{text}");
        assert!(
            scene
                .warnings
                .iter()
                .any(|(_, span)| full[span.clone()].starts_with(starts)),
            "no warning at `{starts}` in {:?}",
            scene.warnings
        );
    };
    // A quadric is read as a mesh of its surface.
    let scene = read("translate(0,0,0, quadric {})");
    assert!(matches!(scene.objects[0].shape, ShapeDesc::Trimesh(_)));
    // A bump map is skipped; the sphere and the rest of its material stay.
    let body = "sphere { material = { diffuse = (1,1,1); bump_mapping = bump(\"x.png\"); specular = (1,0,0); } }";
    let scene = read(body);
    assert_eq!(scene.objects.len(), 1);
    assert_eq!(scene.objects[0].material.specular, Param::Constant(Vec3::X));
    warned(&scene, body, "bump_mapping = bump(\"x.png\");");
    // `objfile` names the mesh's file, as caustica's `file` does.
    let scene = read("polymesh { objfile = \"x.obj\"; }");
    assert_eq!(scene.mesh_files[0].path, Path::new("scenes/x.obj"));
    // Objects of other forks are skipped, extensions or not, wherever an object may stand.
    for body in [
        "particles { material = { diffuse = (1,1,1); }; } sphere {}",
        "meteorite { size = 2; speed = (1, 0, 0); } sphere {}",
        "translate(1, 0, 0, meteorite(1, 2)); sphere {}",
        "{ fluid { } } sphere {}",
    ] {
        let scene = read(body);
        assert_eq!(scene.objects.len(), 1, "{body}");
        let word = body.trim_start_matches(['{', ' ']).split([' ', '(']).next().unwrap();
        let word = if word == "translate" { "meteorite" } else { word };
        warned(&scene, body, word);
        let message = &scene.warnings[0].0;
        assert!(message.starts_with(&format!("skipped `{word}")), "{message}");
    }
    // A required field is still required.
    let (err, covered) = fail("warn_light { position = (0,0,0); color = (1,1,1); }");
    assert_eq!(err.message, "`warn_light` needs a `direction`");
    assert!(covered.starts_with("warn_light {"));
}

/// What is not skipped: misspellings of known objects, and blocks that do not close.
#[test]
fn unknown_objects_that_cannot_be_skipped() {
    let (err, covered) = fail("sphre { }");
    assert_eq!(covered, "sphre");
    assert_eq!(err.help.as_deref(), Some("did you mean `sphere`?"));
    let (err, covered) = fail("meteorite { size = (1, 2 }");
    assert_eq!(err.message, "`}` does not close the `(` opened here");
    assert_eq!(covered, "(1, 2 }");
    let (err, covered) = fail("meteorite { size = 2;\nsphere {}");
    assert_eq!(err.message, "`{` is never closed");
    assert_eq!(covered, "{");
    // A word that is no object, at the top level, is a syntax error as before.
    let (err, _) = fail("meteorite = 2;");
    assert!(err.message.starts_with("expected a camera, light"), "{}", err.message);
}

#[test]
fn lexical_errors_surface_through_parse() {
    let (err, covered) = fail("translate(+1, 0, 0, sphere {})");
    assert_eq!(covered, "+");
    let (err2, _) = fail("sphere {} /* open");
    assert!(err2.message.contains("unterminated"));
    assert!(err.help.is_some());
    // `1E5` is `1` followed by the word `E5` in dialect T.
    let err = read_as("translate(1E5, 0, 0, sphere {})", Dialect::Tokenizer).expect_err("split");
    assert_eq!(err.span, HEADER.len() + 11..HEADER.len() + 13);
    assert!(err.message.contains("expected `,`"));
}

#[test]
fn never_panics_on_prefixes_and_noise() {
    let full = format!(
        "{HEADER}camera {{ position = (0,0,4); viewdir = (0,0,-1); updir = (0,1,0); }}\n\
         material = {{ name m; diffuse = map(\"a.png\"); }}\n\
         translate(0,0,0, {{ scale(2, -1, 1, trimesh {{ points = ((0,0,0),(1,0,0),(0,1,0)); \
         faces = ((0,1,2)); materials = (m, {{}}); }}) }});\n\
         point_light {{ position = (1,1,1); colour = (1,1,1) }}"
    );
    for end in (0..=full.len()).filter(|&i| full.is_char_boundary(i)) {
        for dialect in [None, Some(Dialect::Dictionary), Some(Dialect::Tokenizer)] {
            let _ = parse(&full[..end], Path::new(""), &ParseOptions { dialect });
        }
    }
    for noise in [
        "\0\u{1}",
        "SBT-raytracer",
        "SBT-raytracer 1.0 ((((",
        "SBT-raytracer 1.0 }}}",
        "ü",
    ] {
        assert!(parse(noise, Path::new(""), &ParseOptions::default()).is_err());
    }
}

#[test]
fn missing_semicolons_between_entries_are_fine() {
    let scene = read("sphere { material = { diffuse = (1,1,1) specular = (1,1,1) } name = a }");
    assert_eq!(scene.objects[0].material.specular, Param::grey(1.0));
}

// ---------------------------------------------------------------- UW additions

#[test]
fn uw_look_at_sets_an_orthonormal_basis() {
    let camera = read("camera { position = (0,0,5); look_at = (0,0,0); updir = (0,1,0); }")
        .camera
        .expect("camera");
    assert_eq!(camera.look_at, Some(Vec3::ZERO));
    assert_eq!(camera.basis, CameraBasis::Orthonormal);
    assert_eq!(camera.updir, Some(Vec3::Y));
    let (err, _) = fail("camera { look_at = (0,0,0); viewdir = (0,0,-1); updir = (0,1,0); }");
    assert!(err.message.contains("`look_at`"));
}

// ---------------------------------------------------------------- dialect O

const DIALECT_O: &str = "camera { position = (0, 0, 5); viewdir = (0, 0, -2); updir = (0, 3, 0); \
    quaternion = (0, 0, 0, 1); focaldistance = 3; }\n\
    material { name = \"shiny\"; diffuse = (1, 0, 0); specular = (0.5, 0.5, 0.5); shininess = 0.5; }\n\
    point_light { position = (1E1, 0, 0); colour = (1, 1, 1); }\n\
    translate(1, 2, 3, sphere { material = shiny; })\n\
    scale(2, box { material = { diffuse = \"brick.bmp\"; reflective = (0, 0, 1); }; })\n\
    polymesh { points = ((0, 0, 0), (1, 0, 0), (0, 1, 0)); faces = ((0, 1, 2)); gennormals = true; \
    materials = (shiny, { ambient = (1, 1, 1); }, \"shiny\"); }\n";

#[test]
fn dialect_o_reads_its_own_rules() {
    // Detected dialect-O files are read with the HKUST skeleton's defaults.
    let (scene, dir) = read_with_images(DIALECT_O, &["brick.bmp"]);
    assert_eq!(scene.dialect, Dialect::Hkust);
    let camera = scene.camera.as_ref().expect("camera");
    assert_eq!(camera.basis, CameraBasis::Normalized);
    assert_eq!(camera.quaternion, Some([0.0, 0.0, 0.0, 1.0]));
    // `focaldistance` is ignored with a warning naming it.
    assert_eq!(scene.warnings.len(), 1);
    assert!(scene.warnings[0].0.contains("focaldistance"));
    match &scene.lights[0] {
        LightDesc::Point {
            position, attenuation, ..
        } => {
            assert_eq!(*position, Vec3::new(10.0, 0.0, 0.0));
            assert_eq!(*attenuation, [1.0, 0.0, 0.0], "HKUST: no coefficients, no falloff");
        }
        other => panic!("{other:?}"),
    }
    let shiny = &scene.objects[0].material;
    assert_eq!(shiny.name.as_deref(), Some("shiny"));
    assert_eq!(shiny.shininess, Param::grey(64.0));
    assert_eq!(shiny.reflective, Param::grey(0.5));
    assert!(close(point(&scene.objects[0], Vec3::ZERO), Vec3::new(1.0, 2.0, 3.0)));
    let inline = &scene.objects[1].material;
    assert_eq!(inline.reflective, Param::Constant(Vec3::Z));
    assert_eq!(inline.specular, Param::grey(0.0));
    assert!(
        matches!(&inline.diffuse, Param::Texture(map) if map.source == crate::description::ImageSource::File(dir.join("brick.bmp")))
    );
    let ShapeDesc::Trimesh(mesh) = &scene.objects[2].shape else {
        panic!("mesh")
    };
    assert!(mesh.normals.is_some());
    let per_vertex = mesh.materials.as_ref().expect("materials");
    assert_eq!(&per_vertex[0], shiny);
    // Inline entries start from zero, not from the mesh's material.
    assert_eq!(per_vertex[1].ambient, Param::grey(1.0));
    assert_eq!(per_vertex[1].diffuse, Param::grey(0.0));
    assert_eq!(scene.objects[2].material, MaterialDesc::default());
}

#[test]
fn dialect_o_errors() {
    let err = read_as("sphere { }", Dialect::Dictionary).expect_err("needs material");
    assert!(err.message.contains("needs a `material`"));
    let err = read_as("sphere { material = nothing; }", Dialect::Dictionary).expect_err("unknown");
    assert_eq!(err.message, "unknown material `nothing`");
    let err = read_as("material { diffuse = (1,1,1); }", Dialect::Dictionary).expect_err("no name");
    assert!(err.message.contains("needs a `name`"));
    let err = read_as("spher { material = {}; }", Dialect::Dictionary).expect_err("typo");
    assert_eq!(err.help.as_deref(), Some("did you mean `sphere`?"));
    // Other forks' objects are skipped with a warning; their quadrics are read.
    let scene = read_as(
        "fluid { material = {}; } sphere { material = {}; }",
        Dialect::Dictionary,
    )
    .expect("skipped");
    assert_eq!(scene.objects.len(), 1);
    assert!(
        scene.warnings[0].0.starts_with("skipped `fluid { … }`"),
        "{:?}",
        scene.warnings
    );
    let scene = read_as("quadric { material = {}; }", Dialect::Dictionary).expect("a quadric");
    assert!(matches!(scene.objects[0].shape, ShapeDesc::Trimesh(_)));
    let err = read_as("translate(1, 2, sphere { material = {}; })", Dialect::Dictionary).expect_err("arity");
    assert!(err.message.contains("`translate` with (x, y, z, object)"));
    let err = read_as(
        "sphere { material = { diffuse = (1,1,1) specular = (1,1,1) }; }",
        Dialect::Dictionary,
    )
    .expect_err("missing ;");
    assert!(err.message.contains("after the value of `diffuse`"));
    let err = read_as("camera { updir = (0,1,0); }", Dialect::Dictionary).expect_err("pair");
    assert!(err.message.contains("together"));
}

#[test]
fn dialect_t_rejects_dialect_o_syntax_when_forced() {
    assert!(read_as(DIALECT_O, Dialect::Tokenizer).is_err());
    assert!(read_as("sphere { material = { diffuse = (.5, 1, 1); }; }", Dialect::Tokenizer).is_ok());
    assert!(read_as("{ sphere { material = {}; } }", Dialect::Dictionary).is_err());
}

// ---------------------------------------------------------------- detection

#[test]
fn detection_prefers_t_unless_o_is_marked() {
    // Valid in both: read as T (shininess untouched, reflective stays zero).
    let both = "sphere { material = { specular = (1,1,1); shininess = 0.5; }; }";
    assert!(read_as(both, Dialect::Dictionary).is_ok());
    let scene = read(both);
    assert_eq!(scene.dialect, Dialect::Tokenizer);
    assert_eq!(scene.objects[0].material.shininess, Param::grey(0.5));
    assert_eq!(scene.objects[0].material.reflective, Param::grey(0.0));
    // An O marker flips the preference even though T would also accept the file.
    let marked = format!("{both}\ncamera {{ fov = 1E1; }}");
    assert_eq!(
        read_as(&marked, Dialect::Tokenizer)
            .map(|_| ())
            .map_err(|e| e.span.start > 0),
        Err(true)
    );
    let scene = read(&marked);
    assert_eq!(scene.dialect, Dialect::Hkust);
    assert_eq!(scene.objects[0].material.shininess, Param::grey(64.0));
    // T-only syntax.
    assert_eq!(read("{ sphere {} }").dialect, Dialect::Tokenizer);
    assert_eq!(
        read("material = { diffuse = (.5,.5,.5); } sphere {}").dialect,
        Dialect::Tokenizer
    );
}

#[test]
fn detection_reports_the_relevant_error() {
    // A dialect-T file with a typo is not rescued by dialect O ignoring the unknown key.
    let (err, covered) = fail("sphere { material = { difuse = (1,1,1); }; }");
    assert_eq!(covered, "difuse");
    assert_eq!(err.help.as_deref(), Some("did you mean `diffuse`?"));
    // A marked dialect-O file reports dialect O's error.
    let (err, _) = fail("material { name = \"a\"; }\nsphere { material = b; }");
    assert_eq!(err.message, "unknown material `b`");
    // Extensions are named whichever reader got further.
    let (err, _) = fail("area_light { colour = (1,1,1) position = (0,0,0); }\nsphere {}");
    assert!(err.message.starts_with("`area_light`"));
}

#[test]
fn markers_are_counted() {
    use super::detect::{markers, Markers};
    assert_eq!(
        markers("SBT-raytracer 1.0 material { name = a; } camera { quaternion = (0,0,0,1); }"),
        Markers {
            dictionary: 2,
            tokenizer: 0
        }
    );
    assert_eq!(
        markers("SBT-raytracer 1.0 { } material = { diffuse = (.5,1,1); } trimesh { gennormals; }"),
        Markers {
            dictionary: 0,
            tokenizer: 4
        }
    );
}

// ---------------------------------------------------------------- the camera block lowered to a pinhole

fn camera_block() -> RayCamera {
    RayCamera {
        position: Vec3::new(0.0, 0.0, 5.0),
        viewdir: Some(-Vec3::Z),
        updir: Some(Vec3::Y),
        look_at: None,
        quaternion: None,
        fov_degrees: Some(90.0),
        aspect_ratio: Some(2.0),
        basis: CameraBasis::AsGiven,
        span: 0..0,
    }
}

#[test]
fn fov_and_aspect_set_the_image_plane() {
    let cam = Camera::from_desc(&camera_block().lower());
    // fov 90°: h = 2, so the top edge is at 45°.
    let top = cam.generate_ray(0.5, 1.0).dir;
    assert!((top.y.atan2(-top.z).to_degrees() - 45.0).abs() < 1e-3);
    let right = cam.generate_ray(1.0, 0.5).dir;
    assert!((right.x / -right.z - 2.0).abs() < 1e-5, "half-width = aspect · h / 2");
    assert_eq!(cam.height_for_width(512), 256);
    let (sx, sy) = cam.project(Vec3::new(1.0, -0.5, 0.0)).unwrap();
    let back = cam.generate_ray(sx, sy).dir;
    assert!((back - Vec3::new(1.0, -0.5, -5.0).normalize()).length() < 1e-5);
}

#[test]
fn unnormalised_viewdir_narrows_the_view_as_in_the_course() {
    let mut d = camera_block();
    d.viewdir = Some(-Vec3::Z * 2.0);
    let cam = Camera::from_desc(&d.lower());
    let top = cam.generate_ray(0.5, 1.0).dir;
    // look has length 2, v still spans h = 2: the top edge is at atan(1/2).
    assert!((top.y.atan2(-top.z) - 0.5f32.atan()).abs() < 1e-5);
    d.basis = CameraBasis::Orthonormal;
    let ortho = Camera::from_desc(&d.lower());
    let top = ortho.generate_ray(0.5, 1.0).dir;
    assert!((top.y.atan2(-top.z).to_degrees() - 45.0).abs() < 1e-3);
}

#[test]
fn default_view_and_look_at() {
    let mut d = camera_block();
    d.viewdir = None;
    d.updir = None;
    d.fov_degrees = None;
    d.position = Vec3::ZERO;
    let cam = Camera::from_desc(&d.lower());
    assert_eq!(cam.generate_ray(0.5, 0.5).dir, -Vec3::Z);
    d.look_at = Some(Vec3::new(3.0, 0.0, 0.0));
    let cam = Camera::from_desc(&d.lower());
    assert!((cam.generate_ray(0.5, 0.5).dir - Vec3::X).length() < 1e-6);
}

// ---------------------------------------------------------------- media

/// A material's `scattering`, `absorption` and `phase` make a medium inside its object, with
/// whatever surrounds it outside; `boundary` leaves only the boundary; absorption alone stays a
/// coloured glass; a top-level `medium` fills the scene and holds the camera.
#[test]
fn media_are_read_into_materials_and_the_scene() {
    let scene = read(
        "medium { scattering = (0.1, 0.2, 0.3); absorption = (0.01, 0.01, 0.01); phase = 0.4; }
         sphere { material = { scattering = (2, 2, 2); phase = -0.3; boundary = true; } }
         box { material = { transmissive = (1, 1, 1); index = 1.33; absorption = (0.5, 0.1, 0); scattering = (0.3, 0.3, 0.3); } }
         square { material = { transmissive = (1, 1, 1); absorption = (1, 0, 0); } }",
    );
    assert_eq!(scene.media.len(), 3);
    assert_eq!(scene.ambient_medium, Some(0));
    let fog = &scene.media[0];
    assert_eq!(
        (fog.sigma_s, fog.sigma_a, fog.g),
        (Vec3::new(0.1, 0.2, 0.3), Vec3::splat(0.01), 0.4)
    );
    let [ball, water, glass] = [0, 1, 2].map(|i| &scene.objects[i].material);
    assert!(ball.boundary && ball.absorption.is_none());
    assert_eq!(scene.media[1].g, -0.3);
    let inside = |m: &MaterialDesc| m.interface.map(|i| (i.inside, i.outside));
    use crate::description::MediumSide;
    assert_eq!(
        inside(ball),
        Some((MediumSide::Medium(Some(1)), MediumSide::Surrounding))
    );
    assert_eq!(
        inside(water),
        Some((MediumSide::Medium(Some(2)), MediumSide::Surrounding))
    );
    assert_eq!(scene.media[2].sigma_a, Vec3::new(0.5, 0.1, 0.0));
    assert!(!water.boundary && water.absorption.is_none());
    assert_eq!((glass.interface, glass.absorption), (None, Some(Vec3::X)));
}

#[test]
fn media_errors() {
    for (body, covered, says) in [
        ("sphere { material = { phase = 1.5; } }", "1.5", "strictly between"),
        (
            "sphere { material = { scattering = (1, -1, 0); } }",
            "(1, -1, 0)",
            "zero or more",
        ),
        ("sphere { material = { boundary = yes; } }", "yes", "`true` or `false`"),
        (
            "medium { scattering = (1, 1, 1); } medium { absorption = (1, 1, 1); }",
            "medium { absorption = (1, 1, 1); }",
            "second `medium`",
        ),
        ("medium { colour = (1, 1, 1); }", "colour", "medium field"),
    ] {
        let (error, text) = fail(body);
        assert_eq!(text, covered, "{body}");
        assert!(error.message.contains(says), "{body}: {}", error.message);
    }
}
