//! The course forks' files: old-Mac line ends, the HKUST skeleton's defaults, and the extensions
//! students wrote (spot, area and Warn lights, skyboxes, quadrics, CSG, skipped objects), read by
//! both readers.

use super::ast::*;
use super::{parse, ParseOptions};
use crate::description::{SkyboxLayout, SoftShapeDesc};
use crate::error::line_col;
use crate::format::SourceFiles;
use crate::ParseError;
use glam::Vec3;
use std::path::Path;

const HEADER: &str = "SBT-raytracer 1.0\n";

fn read_as(body: &str, dialect: Option<Dialect>) -> Result<RayScene, ParseError> {
    let text = format!("{HEADER}{body}");
    parse(&text, Path::new("scenes"), &ParseOptions { dialect })
}

fn read(body: &str) -> RayScene {
    read_as(body, None).unwrap_or_else(|e| panic!("{}: {:?} {:?}", e.message, e.span, e.help))
}

/// The error and the text its span covers.
fn fail(body: &str, dialect: Option<Dialect>) -> (ParseError, String) {
    let text = format!("{HEADER}{body}");
    let e = parse(&text, Path::new("scenes"), &ParseOptions { dialect }).expect_err("an error");
    let covered = text.get(e.span.clone()).unwrap_or("<bad span>").to_string();
    (e, covered)
}

// ---------------------------------------------------------------- old Mac line ends

const COMMENTED: &str = "// box_cyl_opaque_shadow.ray\n// Test opaque shadows\ncamera {\n\tposition = (15, 0, 5);\n\t\
    viewdir = (-1, 0, -.3);\n\tupdir = (0, 0, 1);\n}\npoint_light { position = (3, 0, 6); color = (1, 1, 1); }\n\
    // the box\ntranslate(0, 0, -2, box { material = { diffuse = (0.5, 0, 0); } })\n";

/// A file whose lines end with a lone CR reads exactly like its LF version (an old Mac file's
/// first comment used to swallow it), and errors in it are located by CR-ended lines.
#[test]
fn cr_only_files_read_like_their_lf_versions() {
    let lf = read(COMMENTED);
    let cr = read(&COMMENTED.replace('\n', "\r"));
    assert_eq!(
        format!(
            "{:?}",
            lf.into_description(&mut SourceFiles::default(), Path::new("")).unwrap()
        ),
        format!(
            "{:?}",
            cr.into_description(&mut SourceFiles::default(), Path::new("")).unwrap()
        )
    );
    let broken = format!("{HEADER}{}", COMMENTED.replace("(3, 0, 6)", "(3, 0 6)")).replace('\n', "\r");
    let err = parse(&broken, Path::new(""), &ParseOptions::default()).expect_err("a missing comma");
    assert_eq!(line_col(&broken, err.span.start).0, 9, "{}", err.message);
}

// ---------------------------------------------------------------- the HKUST skeleton

fn point_attenuation(scene: &RayScene, i: usize) -> [f32; 3] {
    match &scene.lights[i] {
        LightDesc::Point { attenuation, .. } => *attenuation,
        other => panic!("{other:?}"),
    }
}

/// HKUST point lights without coefficients do not fall off (f = min(1, 1/1) = 1); coefficients
/// count when one of them is positive (the 2017 fork's rule); dialect-O markers choose these
/// defaults, `--dialect dictionary` keeps the UT falloff.
#[test]
fn hkust_point_lights_do_not_fall_off_unless_told() {
    let body = "material { name = m; diffuse = (1,1,1); }\n\
        point_light { position = (0,0,9); colour = (1,1,1); }\n\
        point_light { position = (0,0,9); colour = (1,1,1); quadratic_attenuation_coeff = 0.5; }\n\
        point_light { position = (0,0,9); colour = (1,1,1); constant_attenuation_coeff = 0; }\n\
        sphere { material = m; }";
    let scene = read(body);
    assert_eq!(scene.dialect, Dialect::Hkust);
    assert_eq!(point_attenuation(&scene, 0), [1.0, 0.0, 0.0]);
    assert_eq!(point_attenuation(&scene, 1), [0.0, 0.0, 0.5]);
    assert_eq!(point_attenuation(&scene, 2), [1.0, 0.0, 0.0]);
    let forced = read_as(body, Some(Dialect::Dictionary)).unwrap();
    assert_eq!(forced.dialect, Dialect::Dictionary);
    assert_eq!(point_attenuation(&forced, 0), [0.0, 0.0, 1.0]);
    assert_eq!(point_attenuation(&forced, 1), [0.0, 0.0, 0.5]);
    // Without markers the file is read as dialect T, unless HKUST is asked for.
    let plain = "point_light { position = (0,0,9); colour = (1,1,1); }";
    assert_eq!(point_attenuation(&read(plain), 0), [0.0, 0.0, 1.0]);
    let hkust = read_as(plain, Some(Dialect::Hkust)).unwrap();
    assert_eq!(hkust.dialect, Dialect::Hkust);
    assert_eq!(point_attenuation(&hkust, 0), [1.0, 0.0, 0.0]);
}

/// `texture = "earth.bmp"` in an HKUST material is its diffuse map; only `Hkust` reads it.
#[test]
fn hkust_texture_is_the_diffuse_map() {
    let body = "sphere { material = { diffuse = (1,1,1); texture = \"earth.bmp\"; }; }";
    let (scene, dir) = super::tests::read_with_images(body, &["earth.bmp"]);
    assert_eq!(scene.dialect, Dialect::Hkust, "`texture = \"…\"` marks an HKUST file");
    match &scene.objects[0].material.diffuse {
        Param::Texture(map) => assert_eq!(map.source, crate::description::ImageSource::File(dir.join("earth.bmp"))),
        other => panic!("{other:?}"),
    }
    // Without the image: mid grey, warned.
    let missing = read(body);
    assert_eq!(missing.objects[0].material.diffuse, Param::grey(0.5));
    assert!(missing
        .warnings
        .iter()
        .any(|(w, _)| w.contains("earth.bmp` is missing")));
    let plain = read_as(body, Some(Dialect::Dictionary)).unwrap();
    assert_eq!(plain.objects[0].material.diffuse, Param::grey(1.0));
    assert!(plain.warnings[0].0.contains("`texture`"));
}

// ---------------------------------------------------------------- spot lights

fn spot(scene: &RayScene) -> (Vec3, Vec3, [f32; 3], f32, f32, f32) {
    match &scene.lights[0] {
        LightDesc::Spot {
            position,
            direction,
            attenuation,
            inner_degrees,
            outer_degrees,
            exponent,
            ..
        } => (
            *position,
            *direction,
            *attenuation,
            *inner_degrees,
            *outer_degrees,
            *exponent,
        ),
        other => panic!("{other:?}"),
    }
}

/// Each fork's spelling lands on the same cone: full intensity to the inner half-angle, dark
/// past the outer one.
#[test]
fn spot_light_spellings_of_each_fork() {
    // HKUST 2019: size 70° across, blend 0.4 → dark past 35°, full within 70·0.6/2 = 21°.
    let s = spot(&read(
        "spot_light { position=(2,3,4); direction=(-2,-3,-4); size=70; blend=0.4; color=(1,1,1); }",
    ));
    assert_eq!((s.0, s.1), (Vec3::new(2.0, 3.0, 4.0), Vec3::new(-2.0, -3.0, -4.0)));
    assert!((s.3 - 21.0).abs() < 1e-4 && s.4 == 35.0, "{s:?}");
    // HKUST 2017: a hard edge at `angle` radians around `central_direction`.
    let s = spot(&read(
        "spot_light { position = (3,0,6); color = (1,1,1); angle = 0.5; central_direction = (-3,0,-6);\
         constant_attenuation_coeff= 0.25; linear_attenuation_coeff = 0.003372407; quadratic_attenuation_coeff = 0.000045492; }",
    ));
    assert!((s.3 - 0.5f32.to_degrees()).abs() < 1e-4 && s.3 == s.4);
    assert_eq!(s.2, [0.25, 0.003372407, 0.000045492]);
    // The team fork: aimed at a target, dark past cone_angle, fading over penumbra.
    let scene = read(
        "spot_light { cutoff_distance = 500; penumbra = 10; cone_angle = 30; position = (0, 3, 6);\
         target = (0, 0, 0); color = (1, 0, 0); }",
    );
    let s = spot(&scene);
    assert_eq!(s.1, Vec3::new(0.0, -3.0, -6.0));
    assert_eq!((s.3, s.4), (20.0, 30.0));
    assert!(scene.warnings[0].0.contains("cutoff_distance"));
    // inner/outer in degrees, with caustica's exponent.
    let s = spot(&read(
        "spot_light { position = (5,0,0); color = (1,1,1); direction = (-1,0,0); outer = 30; inner = 15; exponent = 2; }",
    ));
    assert_eq!((s.3, s.4, s.5), (15.0, 30.0, 2.0));
    // Dialect T: the UT falloff; the HKUST reading of a marked file: none.
    assert_eq!(s.2, [0.0, 0.0, 1.0]);
    let hkust = read("material { name = m; } spot_light { position=(0,0,1); direction=(0,0,-1); size=40; blend=0.1; color=(1,1,1); }");
    assert_eq!(hkust.dialect, Dialect::Hkust);
    assert_eq!(spot(&hkust).2, [1.0, 0.0, 0.0]);
}

#[test]
fn spot_light_errors_are_located() {
    let (err, covered) = fail(
        "spot_light { position = (0,0,1); direction = (0,0,-1); size = 40; angle = 0.3; color = (1,1,1); }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("one spelling"), "{}", err.message);
    assert_eq!(covered, "angle = 0.3");
    let (err, covered) = fail(
        "spot_light { position = (0,0,1); direction = (0,0,-1); target = (0,0,0); color = (1,1,1); }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("aim once"), "{}", err.message);
    assert_eq!(covered, "target = (0,0,0)");
    let (err, _) = fail(
        "spot_light { position = (0,0,1); color = (1,1,1); }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("needs a `direction`"));
    let (err, covered) = fail(
        "spot_light { position = (0,0,1); direction = (0,0,-1); angle = 7; color = (1,1,1); }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("radians"));
    assert_eq!(covered, "angle = 7");
    let (err, covered) = fail(
        "spot_light { position = (0,0,1); direction = (0,0,-1); color = (1,1,1); blnd = 0.2; }",
        Some(Dialect::Tokenizer),
    );
    assert_eq!(covered, "blnd");
    assert_eq!(err.help.as_deref(), Some("did you mean `blend`?"));
}

// ---------------------------------------------------------------- area lights

#[test]
fn area_light_spellings() {
    let ball = |scene: &RayScene| match &scene.lights[0] {
        LightDesc::Soft { shape, attenuation, .. } => (*shape, *attenuation),
        other => panic!("{other:?}"),
    };
    // UT 2018: light_radius; UT 2019: bottom_radius (and a missing `;` after the colour).
    let (shape, abc) = ball(&read(
        "area_light { position = (0.0,3.0,2.0); colour = (1.0,1.0,1.0); light_radius = 1.0;\
         constant_attenuation_coeff= 0.25; linear_attenuation_coeff = 0.003372407; quadratic_attenuation_coeff = 0.000045492; }",
    ));
    assert_eq!(
        shape,
        SoftShapeDesc::Sphere {
            center: Vec3::new(0.0, 3.0, 2.0),
            radius: 1.0
        }
    );
    assert_eq!(abc, [0.25, 0.003372407, 0.000045492]);
    let (shape, abc) = ball(&read(
        "area_light { bottom_radius = 0.5; position = (-1,4,-0.4); colour = (1.0,1.0,0.7) }",
    ));
    assert!(matches!(shape, SoftShapeDesc::Sphere { radius, .. } if radius == 0.5));
    assert_eq!(abc, [0.0, 0.0, 1.0]);
    // The team fork: a parallelogram from a corner, falling off as 1/(d² + 0.01).
    let (shape, abc) = ball(&read(
        "material { name = m; } area_light { position = (0, 0, -4); u = (-1, 0, 0); v = (0, 1, 0); color = (1.0, 1.0, 1.0); }",
    ));
    assert_eq!(
        shape,
        SoftShapeDesc::Parallelogram {
            corner: Vec3::new(0.0, 0.0, -4.0),
            u: -Vec3::X,
            v: Vec3::Y
        }
    );
    assert_eq!(abc, [0.01, 0.0, 1.0]);
    let (err, covered) = fail(
        "area_light { position = (0,0,0); color = (1,1,1); light_radius = 1; u = (1,0,0); v = (0,1,0); }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("one size"), "{}", err.message);
    assert_eq!(covered, "light_radius = 1");
    let (err, _) = fail(
        "area_light { position = (0,0,0); color = (1,1,1); u = (1,0,0); v = (2,0,0); }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("no area"));
}

// ---------------------------------------------------------------- skyboxes

#[test]
fn skybox_faces_and_their_files() {
    let scene = read(
        "skybox { back = \"b.bmp\"; front = \"f.bmp\"; left = \"l.bmp\"; right = \"r.bmp\";\
         top = \"t.bmp\"; bottom = \"d.bmp\"; }",
    );
    match &scene.lights[0] {
        LightDesc::Skybox {
            faces, layout, color, ..
        } => {
            let names: Vec<String> = faces.iter().map(|f| f.display().to_string()).collect();
            assert_eq!(
                names,
                ["r.bmp", "l.bmp", "t.bmp", "d.bmp", "b.bmp", "f.bmp"].map(|n| format!("scenes/{n}"))
            );
            assert_eq!(*layout, SkyboxLayout::Inside);
            assert_eq!(*color, Vec3::ONE);
        }
        other => panic!("{other:?}"),
    }
    let (err, _) = fail("skybox { front = \"f.bmp\"; }", Some(Dialect::Tokenizer));
    assert!(err.message.contains("`right (posx)`"), "{}", err.message);
    let (err, covered) = fail(
        "skybox { posx = \"a.png\"; right = \"b.png\"; }",
        Some(Dialect::Tokenizer),
    );
    assert!(err.message.contains("same face"));
    assert_eq!(covered, "\"b.png\"");
}

/// The team fork named its images from its project's root, with Windows separators: the
/// shortest tail of the path that exists beside the scene is taken, with a warning.
#[test]
fn skybox_paths_written_from_a_project_root_are_found() {
    let dir = std::env::temp_dir().join(format!("caustica-skybox-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("skybox")).unwrap();
    for face in ["back", "front", "left", "right", "top", "bottom"] {
        std::fs::write(dir.join("skybox").join(format!("{face}.bmp")), b"x").unwrap();
    }
    let faces: String = ["back", "front", "left", "right", "top", "bottom"]
        .iter()
        .map(|f| format!("{f} = \".\\simpleSamples\\bonus\\skybox\\{f}.bmp\";"))
        .collect();
    let text = format!("{HEADER}material {{ name = m; }} skybox {{ {faces} }}");
    let scene = parse(&text, &dir, &ParseOptions::default());
    std::fs::remove_dir_all(&dir).unwrap();
    let scene = scene.unwrap();
    match &scene.lights[0] {
        LightDesc::Skybox { faces, .. } => assert_eq!(faces[5], dir.join("skybox/front.bmp")),
        other => panic!("{other:?}"),
    }
    assert_eq!(scene.warnings.len(), 6);
    assert!(
        scene.warnings[0].0.contains("using `skybox/back.bmp`"),
        "{}",
        scene.warnings[0].0
    );
}

// ---------------------------------------------------------------- torus

#[test]
fn torus_radii_in_each_fork() {
    let radii = |scene: &RayScene| match scene.objects[0].shape {
        ShapeDesc::Torus {
            major_radius,
            minor_radius,
        } => (major_radius, minor_radius),
        ref other => panic!("{other:?}"),
    };
    // UT 2019: no fields, radii 1 and 0.3.
    assert_eq!(
        radii(&read(
            "scale(1.0, rotate(-.75,-.5,-.5,-.75, torus { material = { diffuse = (1,1,1); }; }))"
        )),
        (1.0, 0.3)
    );
    // HKUST 2019: `a` and `b`, defaults 1 and 0.2 in its dictionary reader.
    let hkust = "translate(6, 0, 1, scale(2, 2, 2, torus { a = 1.5; material = { diffuse = (1,1,1); } }))";
    assert_eq!(radii(&read_as(hkust, Some(Dialect::Hkust)).unwrap()), (1.5, 0.2));
    assert_eq!(
        radii(&read("torus { major_radius = 2; minor_radius = 0.5; }")),
        (2.0, 0.5)
    );
    let (err, covered) = fail("torus { b = -1; }", Some(Dialect::Tokenizer));
    assert!(err.message.contains("positive"));
    assert_eq!(covered, "-1");
}

// ---------------------------------------------------------------- metaballs

#[test]
fn metaballs_in_each_fork() {
    let blobs = |scene: &RayScene| match &scene.objects[0].shape {
        ShapeDesc::Metaballs(m) => (**m).clone(),
        other => panic!("{other:?}"),
    };
    use crate::description::BlobModelDesc;
    // HKUST 2019: the fork's three fixed balls at level 0.25.
    let m = blobs(&read("metaballs { material = { diffuse=( 1,0.3,0.3); }; }"));
    assert_eq!(
        m.balls,
        vec![
            (Vec3::ZERO, 1.0),
            (Vec3::new(1.0, 0.5, 0.0), 1.0),
            (Vec3::new(0.0, 0.9, 0.0), 1.0)
        ]
    );
    assert_eq!(m.model, BlobModelDesc::Field { threshold: 0.25 });
    // The team fork: spheres of radius `size`, smooth-unioned over 0.7.
    let m = blobs(&read(
        "material { name = m; } metaball { material = { diffuse = (0.5, 1.0, 1.0); }; size = 3.0; ball = ((0,0,0),(1,-1,1),(-1,-1,1)); }",
    ));
    assert_eq!(m.balls.len(), 3);
    assert_eq!(m.balls[1], (Vec3::new(1.0, -1.0, 1.0), 3.0));
    assert_eq!(m.model, BlobModelDesc::SmoothUnion { blend: 0.7 });
    // caustica's spellings: per-ball radii and a threshold.
    let m = blobs(&read(
        "metaballs { balls = ((0,0,0,2), (1,0,0)); radius = 0.5; threshold = 0.4; }",
    ));
    assert_eq!(m.balls, vec![(Vec3::ZERO, 2.0), (Vec3::X, 0.5)]);
    // A `metaball` without balls has nothing to draw: skipped, with a warning at it.
    for dialect in [Dialect::Tokenizer, Dialect::Hkust] {
        let scene = read_as(
            "metaball { material = {}; size = 1; } sphere { material = {}; }",
            Some(dialect),
        )
        .unwrap();
        assert_eq!(scene.objects.len(), 1);
        assert!(matches!(scene.objects[0].shape, ShapeDesc::Sphere));
        let (message, span) = &scene.warnings[0];
        assert!(message.starts_with("skipped `metaball"), "{message}");
        assert_eq!(span.start, HEADER.len());
    }
    let (err, covered) = fail("metaballs { balls = ((0,0)); }", Some(Dialect::Tokenizer));
    assert!(err.message.contains("not 2 numbers"));
    assert_eq!(covered, "(0,0)");
}

// ---------------------------------------------------------------- CSG

fn csg(scene: &RayScene, i: usize) -> &crate::description::CsgDesc {
    match &scene.objects[i].shape {
        ShapeDesc::Csg(c) => c,
        other => panic!("{other:?}"),
    }
}

/// Dialect T: operations as transformable elements with two or more operands, each carrying
/// its own transform and material; a group operand is the union of its objects.
#[test]
fn csg_operations_in_dialect_t() {
    use crate::description::CsgOpDesc;
    let scene = read(
        "translate(1, 0, 0, difference(box { material = { diffuse = (1,0,0); }; },\
           scale(0.6, sphere { material = { diffuse = (0,1,0); }; }), { sphere {} translate(0, 2, 0, sphere {}) }));\
         intersection(sphere {}, translate(0, 0, 1, sphere {}))",
    );
    assert_eq!(scene.objects.len(), 2);
    let d = csg(&scene, 0);
    assert_eq!(d.op, CsgOpDesc::Difference);
    assert_eq!(d.operands.len(), 3);
    assert!(matches!(d.operands[0].shape, ShapeDesc::Box));
    assert_eq!(d.operands[1].material.diffuse, Param::Constant(Vec3::Y));
    // The outer translate reaches the operands; the group is a union of two spheres.
    let centre = d.operands[1].world_from_object.transform_point3(Vec3::ZERO);
    assert!((centre - Vec3::X).length() < 1e-6);
    match &d.operands[2].shape {
        ShapeDesc::Csg(u) => assert_eq!((u.op, u.operands.len()), (CsgOpDesc::Union, 2)),
        other => panic!("{other:?}"),
    }
    assert_eq!(csg(&scene, 1).op, CsgOpDesc::Intersection);
    let (err, _) = fail("union(sphere {})", Some(Dialect::Tokenizer));
    assert!(err.message.contains("two or more operands"));
    let (err, covered) = fail("csg { }", Some(Dialect::Tokenizer));
    assert!(err.message.contains("`union(a, b)`"));
    assert_eq!(covered, "csg");
}

/// Dialect O: the HKUST 2019 fork's `subtraction(a, b)` inside transforms, and the team fork's
/// `csg` block with named operands and nested operations.
#[test]
fn csg_operations_in_dialect_o() {
    use crate::description::CsgOpDesc;
    let scene = read(
        "material { name = glass; transmissive = (0.8, 0.8, 0.8); }\n\
         translate(6, -2, 1, scale(2, 2, 2, subtraction(translate(0, -0.5, 0, sphere { material = glass; }),\
           translate(0, 0.5, 0, sphere { material = { diffuse = (1, 0.6, 0.8); }; }))))\n\
         csg { primitives = (\"box1\", \"sphere1\", \"s2\");\n\
           box1 = rotate(1, 1, 1, 1, box { material = glass; });\n\
           sphere1 = scale(0.67, sphere { material = glass; });\n\
           s2 = sphere { material = glass; };\n\
           operation = (\"box1\", \"sub\", (\"sphere1\", \"or\", \"s2\")); }",
    );
    assert_eq!(scene.dialect, Dialect::Hkust);
    let d = csg(&scene, 0);
    assert_eq!(d.op, CsgOpDesc::Difference);
    let centre = d.operands[1].world_from_object.transform_point3(Vec3::ZERO);
    assert!((centre - Vec3::new(6.0, -1.0, 1.0)).length() < 1e-6, "{centre}");
    let block = csg(&scene, 1);
    assert_eq!(block.op, CsgOpDesc::Difference);
    assert!(matches!(block.operands[0].shape, ShapeDesc::Box));
    match &block.operands[1].shape {
        ShapeDesc::Csg(u) => assert_eq!(u.op, CsgOpDesc::Union),
        other => panic!("{other:?}"),
    }
    let (err, covered) = fail(
        "material { name = m; } csg { a = sphere { material = m; }; operation = (\"a\", \"xor\", \"a\"); }",
        None,
    );
    assert!(err.message.contains("`xor`"));
    assert_eq!(covered, "\"xor\"");
}

/// Without `operation` a `csg` block's operands are still drawn: as their union, with a warning
/// at the block.
#[test]
fn csg_block_without_operation_is_the_union_of_its_operands() {
    use crate::description::CsgOpDesc;
    let body = "material { name = m; }\n\
                csg { primitives = (\"a\", \"b\"); a = sphere { material = m; }; b = translate(1, 0, 0, box { material = m; }); }";
    let scene = read(body);
    assert_eq!(scene.objects.len(), 1);
    let u = csg(&scene, 0);
    assert_eq!(u.op, CsgOpDesc::Union);
    assert!(matches!(u.operands[0].shape, ShapeDesc::Sphere));
    assert!(matches!(u.operands[1].shape, ShapeDesc::Box));
    let (message, span) = &scene.warnings[0];
    assert!(message.contains("has no `operation`"), "{message}");
    let text = format!("{HEADER}{body}");
    assert!(text[span.clone()].starts_with("csg {"));
    // The block alone marks the team fork's dialect O; one operand is drawn as it is.
    let scene = read("csg { primitives = (\"a\"); a = scale(2, sphere { material = { diffuse = (1, 1, 1); }; }); }");
    assert_eq!(scene.dialect, Dialect::Hkust);
    assert!(matches!(scene.objects[0].shape, ShapeDesc::Sphere));
    assert!(scene.warnings[0].0.contains("its 1 operand(s)"));
}

// ---------------------------------------------------------------- Warn lights

/// The three forks' Warn lights are spot lights: cos^p over the half-space they face (or a hard
/// beam of radius `size` at unit distance); flaps and beam shapes are warned about, in place.
#[test]
fn warn_lights_of_each_fork() {
    // HKUST 2017 (a dialect-O marker: no falloff without coefficients).
    let body = "warn_model_light { position = (0, 0, 8); color = (1, 1, 1); central_direction = (0, 0, -1);\n\
                specular_exponent = 16.0; xflapmin = -2; xflapmax = 2; zflapmax = 2; }";
    let scene = read(body);
    assert_eq!(scene.dialect, Dialect::Hkust);
    let s = spot(&scene);
    assert_eq!(
        (s.0, s.1, s.2),
        (Vec3::new(0.0, 0.0, 8.0), Vec3::NEG_Z, [1.0, 0.0, 0.0])
    );
    assert_eq!((s.3, s.4, s.5), (90.0, 90.0, 16.0));
    let (message, span) = &scene.warnings[0];
    assert!(
        message.contains("flaps (xflapmin = -2, xflapmax = 2, zflapmax = 2)"),
        "{message}"
    );
    let text = format!("{HEADER}{body}");
    assert_eq!(line_col(&text, span.start), (3, 27));
    assert!(text[span.clone()].starts_with("xflapmin = -2") && text[span.clone()].ends_with("zflapmax = 2"));
    // The team fork: `normal` and `p`.
    let scene = read(
        "warn_light { cutoff_distance = 100; p = 100; xmin = -1; xmax = 1; position = (0, 2, 6); normal = (0, -1, -1); color = (1, 1, 1); }",
    );
    let s = spot(&scene);
    assert_eq!((s.1, s.5), (Vec3::new(0.0, -1.0, -1.0), 100.0));
    assert_eq!(scene.warnings.len(), 2, "{:?}", scene.warnings);
    // HKUST 2019: a beam of radius 0.5 at unit distance, its shape drawn round.
    let scene = read_as(
        "warn_light { position = (1, 2, 1); direction = (-1, -2, -1); colour = (0.8, 0.8, 0.8); type = 3; size = 0.5; }",
        Some(Dialect::Tokenizer),
    )
    .unwrap();
    let s = spot(&scene);
    assert!(
        (s.3 - 0.5f32.atan().to_degrees()).abs() < 1e-4 && s.3 == s.4 && s.5 == 0.0,
        "{s:?}"
    );
    assert_eq!(s.2, [0.0, 0.0, 1.0]);
    assert!(scene.warnings[0].0.contains("`type = 3`"));
    // Errors stay located.
    let (err, covered) = fail(
        "warn_light { position = (0,0,1); normal = (0,0,-1); direction = (0,0,-1); color = (1,1,1); }",
        None,
    );
    assert!(err.message.contains("aim once"), "{}", err.message);
    assert!(covered.starts_with("normal"), "{covered}");
    let (err, _) = fail(
        "warn_light { position = (0,0,1); normal = (0,0,-1); color = (1,1,1); p = -1; }",
        None,
    );
    assert!(err.message.contains("0 or more"));
}

// ---------------------------------------------------------------- quadrics

fn mesh(scene: &RayScene, i: usize) -> &TrimeshDesc {
    match &scene.objects[i].shape {
        ShapeDesc::Trimesh(m) => m,
        other => panic!("{other:?}"),
    }
}

/// The UT 2019 `quadric`: five pairs are the coefficients A..J; here the sphere
/// x² + y² + z² − 0.25 = 0 under a transform, read as a mesh on that sphere.
#[test]
fn quadric_coefficients_are_read_as_pairs() {
    let scene = read(
        "material = { diffuse = (0.4, 0.8, 0.2); }\n\
         translate(0, 0, 3, quadric { points = ((1, 1), (1, 0), (0, 0), (0, 0), (0, -0.25)); })",
    );
    let object = &scene.objects[0];
    assert_eq!(object.material.diffuse, Param::Constant(Vec3::new(0.4, 0.8, 0.2)));
    for p in &mesh(&scene, 0).points {
        assert!((p.length() - 0.5).abs() < 1e-3, "{p}");
        let world = object.world_from_object.transform_point3(*p);
        assert!((world - Vec3::new(0.0, 0.0, 3.0)).length() < 0.51);
    }
    let (err, covered) = fail("quadric { points = ((1, 1), (1, 0)); }", None);
    assert!(err.message.contains("five pairs"), "{}", err.message);
    assert_eq!(covered, "((1, 1), (1, 0))");
}

/// `hyperboloid`, `hyperbolic_paraboloid` and `paraboloid` in either reader: the surface's
/// equation holds at every vertex.
#[test]
fn named_quadrics_in_both_dialects() {
    type Surface = fn(Vec3) -> f32;
    let surfaces: [(&str, Surface); 3] = [
        ("hyperboloid", |p| p.x * p.x + p.y * p.y - p.z * p.z - 1.0),
        ("hyperbolic_paraboloid", |p| p.x * p.x - p.y * p.y - p.z),
        ("paraboloid", |p| p.x * p.x + p.y * p.y - p.z),
    ];
    for dialect in [Dialect::Tokenizer, Dialect::Hkust] {
        for (word, f) in surfaces {
            let scene = read_as(
                &format!("scale(4, 4, 2, {word} {{ material = {{ diffuse = (1,1,1); }}; }})"),
                Some(dialect),
            )
            .unwrap_or_else(|e| panic!("{word}: {}", e.message));
            let m = mesh(&scene, 0);
            assert!(m.points.iter().all(|&p| f(p).abs() < 1e-3), "{word} in {dialect:?}");
            assert_eq!(
                scene.objects[0].world_from_object.transform_point3(Vec3::ONE),
                Vec3::new(4.0, 4.0, 2.0)
            );
        }
    }
}

/// The HKUST 2019 fork's procedural marble in a material: its `color` stands in, with a warning.
#[test]
fn marble_textures_fall_back_to_their_colour() {
    let body = "material { name = m; }\n\
                sphere { material = { diffuse = marble { color = (0.6, 0.0, 1.0); contrast = 0.8; }; specular = (0.5, 0.5, 0.5); }; }";
    let scene = read(body);
    let material = &scene.objects[0].material;
    assert_eq!(material.diffuse, Param::Constant(Vec3::new(0.6, 0.0, 1.0)));
    // `reflective` still follows `specular` when not given.
    assert_eq!(material.reflective, Param::grey(0.5));
    let (message, span) = &scene.warnings[0];
    assert!(message.contains("`marble`"), "{message}");
    let text = format!("{HEADER}{body}");
    assert!(text[span.clone()].starts_with("marble {"));
}
