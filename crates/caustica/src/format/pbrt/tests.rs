use super::*;
use crate::description::{Coating, EmittingFaces};
use crate::error::Error;
use crate::progress::NoProgress;

fn read_text(text: &str) -> Result<SceneSource> {
    read(Path::new("t.pbrt"), text.to_string(), Path::new("."), &NoProgress)
}

fn scene(body: &str) -> SceneDescription {
    let text = format!("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\nWorldBegin\n{body}\n");
    read_text(&text).unwrap_or_else(|e| panic!("{e}")).description
}

fn error(text: &str) -> (String, usize, usize) {
    match read_text(text) {
        Err(Error::Scene { path, text, error }) => {
            let (line, col) = crate::error::line_col(&text, error.span.start);
            assert_eq!(path, Path::new("t.pbrt"));
            (error.message, line, col)
        }
        other => panic!(
            "expected an error, got {:?}",
            other.map(|s| s.description.objects.len())
        ),
    }
}

/// pbrt's camera looks down +z of its space with x to the right of the image: from +z towards
/// the origin with y up, the world's +x is on the image's left (not mirrored as a right-handed
/// reading of the same numbers would put it).
#[test]
fn the_camera_is_not_mirrored() {
    let desc = scene("");
    let camera = crate::camera::Camera::from_desc(desc.camera.as_ref().unwrap());
    let (sx, sy) = camera.project(Vec3::new(1.0, 0.5, 0.0)).unwrap();
    assert!(sx < 0.5, "pbrt puts +x on the left here: {sx}");
    assert!(sy > 0.5, "and +y up: {sy}");
    // fov spans the shorter axis: 1280×720 by default, so 45° vertically.
    let (_, top) = camera
        .project(Vec3::new(0.0, 5.0 * (22.5f32).to_radians().tan(), 0.0))
        .unwrap();
    assert!((top - 1.0).abs() < 1e-3, "{top}");
    assert_eq!(desc.hints.width, Some(1280));
    assert_eq!(desc.hints.height, Some(720));
    // A mirroring scale before the camera flips the image back, as in pbrt.
    let text = "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";
    let mirrored = read_text(text).unwrap().description;
    let camera = crate::camera::Camera::from_desc(mirrored.camera.as_ref().unwrap());
    assert!(camera.project(Vec3::new(1.0, 0.0, 0.0)).unwrap().0 > 0.5);
}

/// pbrt's thin lens: `lensradius` and `focaldistance`; in focus, a point on the focus plane
/// lands on one pixel from every lens point, a nearer one on several.
#[test]
fn the_camera_reads_a_thin_lens() {
    let text = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float lensradius\" 0.2 \"float focaldistance\" 5\nWorldBegin\n";
    let desc = read_text(text).unwrap().description;
    let lens = desc.camera.as_ref().unwrap().lens.unwrap();
    assert_eq!((lens.radius, lens.focus), (0.2, 5.0));
    let camera = crate::camera::Camera::from_desc(desc.camera.as_ref().unwrap());
    // Rays through one screen point from different lens points (drawn from nearby screen
    // points' bits) meet at the focus plane, 5 along the view.
    let hits: Vec<Vec3> = [0.3001f32, 0.30011, 0.30012]
        .iter()
        .map(|&sx| {
            let ray = camera.generate_ray(sx, 0.6);
            ray.origin + ray.dir * ((0.0 - ray.origin.z) / ray.dir.z)
        })
        .collect();
    let origins: Vec<Vec3> = [0.3001f32, 0.30011, 0.30012]
        .iter()
        .map(|&sx| camera.generate_ray(sx, 0.6).origin)
        .collect();
    assert!(
        (origins[0] - origins[1]).length() > 1e-3,
        "different lens points: {origins:?}"
    );
    assert!(
        (hits[0] - hits[1]).length() < 1e-3 && (hits[0] - hits[2]).length() < 1e-3,
        "{hits:?}"
    );
    // Without the parameters, a pinhole.
    let pinhole = read_text("LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n").unwrap();
    assert!(pinhole.description.camera.unwrap().lens.is_none());
}

#[test]
fn transforms_compose_as_pbrt_does() {
    let desc = scene(
        "AttributeBegin\nTranslate 1 2 3\nRotate 90 0 0 1\nScale 2 2 2\nShape \"sphere\" \"float radius\" 0.5\nAttributeEnd\n\
         AttributeBegin\nTransform [1 0 0 0  0 1 0 0  0 0 1 0  4 5 6 1]\nConcatTransform [2 0 0 0 0 2 0 0 0 0 2 0 0 0 0 1]\nShape \"sphere\"\nAttributeEnd\n\
         Shape \"sphere\"",
    );
    let m = desc.objects[0].world_from_object;
    // Scale 2 × radius 0.5, then a quarter turn about z (x → y), then the translation.
    let p = m.transform_point3(Vec3::X);
    assert!((p - Vec3::new(1.0, 3.0, 3.0)).length() < 1e-5, "{p:?}");
    let q = desc.objects[1].world_from_object.transform_point3(Vec3::X);
    assert!((q - Vec3::new(6.0, 5.0, 6.0)).length() < 1e-5, "{q:?}");
    assert_eq!(
        desc.objects[2].world_from_object,
        Mat4::IDENTITY,
        "AttributeEnd restores"
    );
}

#[test]
fn film_sampler_and_integrator_become_hints() {
    let text =
        "Film \"rgb\" \"integer xresolution\" [200] \"integer yresolution\" 100 \"string filename\" \"out.exr\"\n\
                Sampler \"halton\" \"integer pixelsamples\" 32\n\
                Integrator \"sppm\" \"integer maxdepth\" 7 \"integer photonsperiteration\" 5000\n\
                Camera \"perspective\"\nWorldBegin\n";
    let hints = read_text(text).unwrap().description.hints;
    assert_eq!((hints.width, hints.height), (Some(200), Some(100)));
    assert_eq!(hints.output, Some(PathBuf::from("out.exr")));
    assert_eq!(hints.samples, Some(32));
    assert_eq!(hints.integrator, Some(IntegratorHint::Ppm));
    assert_eq!(hints.max_depth, Some(7));
    assert_eq!(hints.photons_per_pass, Some(5000));
    assert!(hints.physical);
    for (name, hint, warns) in [
        ("bdpt", IntegratorHint::Bidirectional, true),
        ("mlt", IntegratorHint::Bidirectional, true),
        ("lightpath", IntegratorHint::LightTracer, false),
        ("volpath", IntegratorHint::Path, false),
        ("ambientocclusion", IntegratorHint::Path, true),
    ] {
        let desc = read_text(&format!("Integrator \"{name}\"\nWorldBegin\n"))
            .unwrap()
            .description;
        assert_eq!(desc.hints.integrator, Some(hint), "{name}");
        assert_eq!(!desc.warnings.is_empty(), warns, "{name}: {:?}", desc.warnings);
    }
}

#[test]
fn materials_map_to_both_models() {
    let desc = scene(
        "Material \"dielectric\" \"spectrum eta\" \"glass-F11\"\nShape \"sphere\"\n\
         Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" \"float roughness\" 0.01\nShape \"sphere\"\n\
         Material \"conductor\"\nShape \"sphere\"\n\
         Material \"coateddiffuse\" \"rgb reflectance\" [0.5 0.1 0.1] \"float roughness\" 0\nShape \"sphere\"\n\
         Material \"diffusetransmission\"\nShape \"sphere\"\n\
         MakeNamedMaterial \"red\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.8 0 0]\nNamedMaterial \"red\"\nShape \"sphere\"",
    );
    let m: Vec<&MaterialDesc> = desc.objects.iter().map(|o| &o.material).collect();
    assert_eq!(m[0].index, Param::grey(1.78472));
    assert_eq!(m[0].abbe, Some(25.68));
    assert_eq!(m[0].transmissive, Param::grey(1.0));
    let Some(PhysicalMaterial::Conductor { roughness, eta, .. }) = &m[1].physical else {
        panic!()
    };
    assert!((roughness - 0.1).abs() < 1e-6, "remapped: √0.01");
    assert_eq!(*eta, spectra::metal("metal-Au").unwrap().0);
    assert!(
        matches!(m[1].specular, Param::Constant(c) if c.x > 0.9),
        "{:?}",
        m[1].specular
    );
    let Some(PhysicalMaterial::Conductor { roughness, .. }) = &m[2].physical else {
        panic!()
    };
    assert_eq!(*roughness, 0.0);
    assert!(
        matches!(m[2].reflective, Param::Constant(c) if c.x > 0.9 && c.z < 0.6),
        "copper by default"
    );
    assert!(matches!(m[3].physical, Some(PhysicalMaterial::CoatedDiffuse { eta, .. }) if eta == 1.5));
    assert_eq!(m[3].diffuse, Param::Constant(Vec3::new(0.5, 0.1, 0.1)));
    assert!(matches!(
        m[4].physical,
        Some(PhysicalMaterial::DiffuseTransmission { .. })
    ));
    assert_eq!(m[5].diffuse, Param::Constant(Vec3::new(0.8, 0.0, 0.0)));
}

/// pbrt-v3's materials and area light, as pbrt-v3 defines their parameters: each read onto
/// caustica's nearest material, with its own defaults (metal's roughness 0.01, plastic's Kd 0.25,
/// mirror's Kr 0.9), `color` spellings and `index` for glass; approximations say so.
#[test]
fn pbrt_v3_materials_are_read() {
    let dir = std::env::temp_dir().join(format!("caustica-v3-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("spds")).unwrap();
    std::fs::write(
        dir.join("spds/Odd.eta.spd"),
        "# wavelength value\n400 1.0\n500 2.0\n600 3.0\n700 4.0\n",
    )
    .unwrap();
    let text = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 45\nWorldBegin\n\
         Material \"matte\" \"color Kd\" [0.2 0.3 0.4]\nShape \"sphere\"\n\
         Material \"plastic\" \"color Kd\" [0.5 0.5 0.5] \"float roughness\" 0.04\nShape \"sphere\"\n\
         Material \"glass\" \"float index\" 1.33\nShape \"sphere\"\n\
         Material \"metal\" \"spectrum eta\" \"spds/Odd.eta.spd\" \"spectrum k\" \"spds/Au.k.spd\"\nShape \"sphere\"\n\
         Material \"mirror\"\nShape \"sphere\"\n\
         Material \"substrate\" \"color Kd\" [0.6 0.1 0.1] \"color Ks\" [0.04 0.04 0.04]\nShape \"sphere\"\n\
         Material \"uber\" \"color Kd\" [0.3 0.3 0.3] \"color opacity\" [0.5 0.5 0.5]\nShape \"sphere\"\n\
         Material \"translucent\" \"color Kd\" [0.8 0.8 0.8]\nShape \"sphere\"\n\
         AttributeBegin\nAreaLightSource \"area\" \"color L\" [3 3 3] \"integer nsamples\" 4\nShape \"sphere\"\nAttributeEnd\n";
    std::fs::write(dir.join("v3.pbrt"), text).unwrap();
    let source = read(&dir.join("v3.pbrt"), text.to_string(), &dir, &NoProgress).unwrap();
    let desc = &source.description;
    let m: Vec<&MaterialDesc> = desc.objects.iter().map(|o| &o.material).collect();
    assert_eq!(m[0].diffuse, Param::Constant(Vec3::new(0.2, 0.3, 0.4)));
    assert!(m[0].physical.is_none());
    match &m[1].physical {
        Some(PhysicalMaterial::CoatedDiffuse {
            eta,
            roughness,
            reflectance,
            layering,
            ..
        }) => {
            assert_eq!(
                (*eta, *reflectance == Param::grey(0.5), *layering),
                (1.5, true, Coating::Fresnel)
            );
            assert!((roughness - 0.2).abs() < 1e-6, "remapped √0.04: {roughness}");
        }
        other => panic!("plastic: {other:?}"),
    }
    assert_eq!(
        (m[2].index.clone(), m[2].transmissive.clone()),
        (Param::grey(1.33), Param::grey(1.0))
    );
    match &m[3].physical {
        Some(PhysicalMaterial::Conductor { eta, k, roughness, .. }) => {
            // The file's table at 650, 550 and 450 nm; gold's k by name, the file being absent.
            assert!((*eta - Vec3::new(3.5, 2.5, 1.5)).length() < 1e-5, "{eta}");
            assert_eq!(*k, spectra::metal("metal-Au").unwrap().1);
            assert!(
                (roughness - 0.1).abs() < 1e-6,
                "metal's default 0.01, remapped: {roughness}"
            );
        }
        other => panic!("metal: {other:?}"),
    }
    assert!(
        matches!(&m[4].physical, Some(PhysicalMaterial::Conductor { reflectance: Some(r), roughness, .. })
        if *r == Param::grey(0.9) && *roughness == 0.0)
    );
    match &m[5].physical {
        Some(PhysicalMaterial::CoatedDiffuse { eta, .. }) => {
            assert!((eta - 1.5).abs() < 0.01, "Ks 0.04 is index 1.5: {eta}")
        }
        other => panic!("substrate: {other:?}"),
    }
    assert_eq!(m[6].alpha.as_ref().map(|a| a.coverage.clone()), Some(Param::grey(0.5)));
    assert!(
        matches!(&m[7].physical, Some(PhysicalMaterial::DiffuseTransmission { reflectance, transmittance })
        if *reflectance == Param::grey(0.4) && *transmittance == Param::grey(0.4))
    );
    assert_eq!(m[8].emissive, Param::grey(3.0));
    let warnings: Vec<&str> = desc.warnings.iter().map(|(w, _)| w.as_str()).collect();
    for said in [
        "plastic is read as",
        "Au.k.spd` is missing: pbrt-v4's metal-Au-k",
        "uber is read as",
        "translucent's glossy part",
    ] {
        assert!(warnings.iter().any(|w| w.contains(said)), "{said}: {warnings:?}");
    }
    assert!(
        !warnings
            .iter()
            .any(|w| w.contains("not supported") || w.contains("not read")),
        "{warnings:?}"
    );
}

#[test]
fn lights_shapes_and_instances() {
    let desc = scene(
        "LightSource \"point\" \"point3 from\" [0 4 0] \"rgb I\" [2 2 2] \"float scale\" 3\n\
         LightSource \"distant\" \"point3 from\" [0 1 0] \"point3 to\" [0 0 0] \"blackbody L\" 5500\n\
         AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [4 4 4] \"bool twosided\" true\nShape \"disk\" \"float radius\" 2 \"float innerradius\" 1\nAttributeEnd\n\
         Shape \"cylinder\" \"float zmin\" -1 \"float zmax\" 3\n\
         ObjectBegin \"tri\"\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0]\nObjectEnd\n\
         Translate 10 0 0\nObjectInstance \"tri\"\nTranslate 10 0 0\nObjectInstance \"tri\"",
    );
    let LightDesc::Point { position, color, .. } = &desc.lights[0] else {
        panic!()
    };
    assert_eq!((*position, *color), (Vec3::new(0.0, 4.0, 0.0), Vec3::splat(6.0)));
    let LightDesc::Directional { direction, color, .. } = &desc.lights[1] else {
        panic!()
    };
    assert_eq!(*direction, -Vec3::Y);
    assert!((0.2126 * color.x + 0.7152 * color.y + 0.0722 * color.z - 1.0).abs() < 1e-3);
    assert!(matches!(desc.objects[0].shape, ShapeDesc::Disk { inner } if inner == 0.5));
    assert_eq!(desc.objects[0].material.emissive, Param::grey(4.0));
    let cylinder = desc.objects[1].world_from_object;
    assert!((cylinder.transform_point3(Vec3::Z) - Vec3::new(0.0, 0.0, 3.0)).length() < 1e-6);
    assert_eq!(desc.objects.len(), 4, "two instances of the triangle");
    assert!((desc.objects[3].world_from_object.transform_point3(Vec3::ZERO).x - 20.0).abs() < 1e-6);
}

#[test]
fn unsupported_directives_warn_with_their_place_and_reading_goes_on() {
    let text = "WorldBegin\nFrobnicate \"x\" [1 2] 3\nShape \"curve\" \"point3 P\" [0 0 0]\nShape \"sphere\" \"float bogus\" 1\n";
    let source = read_text(text).unwrap();
    let w = &source.description.warnings;
    let at = |needle: &str| {
        let (_, span) = w
            .iter()
            .find(|(m, _)| m.contains(needle))
            .unwrap_or_else(|| panic!("{needle}: {w:?}"));
        crate::error::line_col(text, span.start)
    };
    assert_eq!(at("Frobnicate"), (2, 1));
    assert_eq!(at("curve"), (3, 7));
    assert_eq!(at("bogus"), (4, 16));
    assert_eq!(source.description.objects.len(), 1);
}

#[test]
fn malformed_files_get_located_errors() {
    assert_eq!(error("WorldBegin\nShape \"sphere\" \"float radius\" [1\n").1, 2);
    let (m, line, col) = error("WorldBegin\nTranslate 1 x 2\n");
    assert!(m.contains("number"), "{m}");
    assert_eq!((line, col), (2, 13));
    assert!(error("LookAt 0 0 0 0 0 1 0 1 0\n").0.contains("WorldBegin"));
    assert!(
        error("WorldBegin\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 5]\n")
            .0
            .contains("out of range")
    );
    assert!(error("WorldBegin\nNamedMaterial \"nope\"\n").0.contains("nope"));
    assert!(error("WorldBegin\nShape \"sphere\" \"floot radius\" 1\n")
        .0
        .contains("floot"));
    assert!(error("WorldBegin\nLookAt 0 0 0  0 0 0  0 1 0\n").0.contains("LookAt"));
    assert!(error("WorldBegin\nShape \"sphere\" \"float radius\" \"one\"\n")
        .0
        .contains("cannot take"));
    assert!(
        error("WorldBegin\nMaterial \"dielectric\" \"spectrum eta\" \"glass-XYZ\"\n")
            .0
            .contains("glass-XYZ")
    );
}

#[test]
fn included_files_name_themselves_in_errors() {
    let dir = std::env::temp_dir().join(format!("caustica-pbrt-include-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("geometry.pbrt"),
        "Shape \"sphere\"\nShape \"sphere\" \"float radius\" [2 oops]\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("ok.pbrt"),
        "Material \"diffuse\" \"rgb reflectance\" [0.1 0.2 0.3]\nShape \"sphere\"\n",
    )
    .unwrap();
    let main = "WorldBegin\nImport \"ok.pbrt\"\nShape \"sphere\"\nInclude \"geometry.pbrt\"\n";
    let result = read(&dir.join("main.pbrt"), main.to_string(), &dir, &NoProgress);
    let Err(Error::Scene { path, text, error }) = result else {
        panic!("expected an error")
    };
    assert_eq!(path, dir.join("geometry.pbrt"));
    assert_eq!(crate::error::line_col(&text, error.span.start), (2, 34));
    // Import keeps its material to itself.
    let main = "WorldBegin\nImport \"ok.pbrt\"\nShape \"sphere\"\n";
    let desc = read(&dir.join("main.pbrt"), main.to_string(), &dir, &NoProgress)
        .unwrap()
        .description;
    assert_eq!(
        desc.objects[0].material.diffuse,
        Param::Constant(Vec3::new(0.1, 0.2, 0.3))
    );
    assert_eq!(desc.objects[1].material.diffuse, Param::grey(0.5));
    // A missing file is an error at the directive that names it.
    let Err(Error::Scene { path, error, .. }) = read(
        &dir.join("main.pbrt"),
        "WorldBegin\nInclude \"gone.pbrt\"\n".into(),
        &dir,
        &NoProgress,
    ) else {
        panic!()
    };
    assert_eq!(path, dir.join("main.pbrt"));
    assert_eq!(error.span.start, 19);
    std::fs::remove_dir_all(&dir).ok();
}

/// One-sided area lights emit from pbrt's front: a mesh's given normals (turned by
/// `ReverseOrientation`), else its world winding turned by `ReverseOrientation` or a mirroring
/// transform (one of them, not both); a shape's outward normal under the same rule.
#[test]
fn one_sided_lights_face_pbrt_front() {
    // A triangle wound towards +z; `normals` appends its normals, `before` goes before it.
    let light = |before: &str, normals: &str, twosided: bool| {
        let body = format!(
            "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"bool twosided\" {twosided}\n{before}\n\
             Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2] {normals}\nAttributeEnd"
        );
        let desc = scene(&body);
        let object = &desc.objects[0];
        let ShapeDesc::Trimesh(mesh) = &object.shape else {
            panic!()
        };
        let [a, b, c] = mesh.triangles[0].map(|i| object.world_from_object.transform_point3(mesh.points[i as usize]));
        ((b - a).cross(c - a).normalize(), object.material.emitting_faces)
    };
    let down = "\"normal N\" [0 0 -1 0 0 -1 0 0 -1]";
    let cases: [(&str, &str, Vec3); 6] = [
        ("", "", Vec3::Z),
        ("ReverseOrientation", "", -Vec3::Z),
        ("Scale 1 -1 1", "", Vec3::Z),
        ("ReverseOrientation Scale 1 -1 1", "", -Vec3::Z),
        ("", down, -Vec3::Z),
        ("ReverseOrientation", down, Vec3::Z),
    ];
    for (before, normals, front) in cases {
        let (winding, faces) = light(before, normals, false);
        assert_eq!(faces, EmittingFaces::Front, "{before} {normals}");
        assert!(
            (winding - front).length() < 1e-6,
            "{before} {normals}: wound to {winding}"
        );
    }
    let (winding, faces) = light("ReverseOrientation", "", true);
    assert_eq!(
        (winding, faces),
        (Vec3::Z, EmittingFaces::Both),
        "two-sided: left as wound"
    );
    let sphere = |before: &str| {
        scene(&format!(
            "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [1 1 1]\n{before}\nShape \"sphere\"\nAttributeEnd"
        ))
        .objects[0]
            .material
            .emitting_faces
    };
    assert_eq!(sphere(""), EmittingFaces::Front);
    assert_eq!(sphere("ReverseOrientation"), EmittingFaces::Back);
    assert_eq!(sphere("Scale -1 1 1"), EmittingFaces::Back);
    assert_eq!(
        scene("Shape \"sphere\"").objects[0].material.emitting_faces,
        EmittingFaces::Both,
        "no light"
    );
}

/// Rough glass: pbrt-v4's `dielectric` and pbrt-v3's `glass` with roughness become GGX glass
/// (α remapped as √roughness unless `remaproughness` is false), keeping their course reading
/// and dispersion; smooth glass and thin glass stay as they were.
#[test]
fn rough_dielectrics_become_ggx_glass() {
    let desc = scene(
        "Material \"dielectric\" \"float eta\" 1.4 \"float roughness\" 0.09\nShape \"sphere\"\n\
         Material \"dielectric\" \"spectrum eta\" \"glass-BK7\" \"float roughness\" 0.2 \"bool remaproughness\" false\nShape \"sphere\"\n\
         Material \"glass\" \"float index\" 1.6 \"float uroughness\" 0.04 \"float vroughness\" 0.04\nShape \"sphere\"\n\
         Material \"dielectric\" \"float eta\" 1.5\nShape \"sphere\"\n\
         Material \"thindielectric\" \"float eta\" 1.5\nShape \"sphere\"",
    );
    let m: Vec<&MaterialDesc> = desc.objects.iter().map(|o| &o.material).collect();
    let rough = |i: usize| match &m[i].physical {
        Some(PhysicalMaterial::RoughDielectric {
            eta, roughness, abbe, ..
        }) => (*eta, *roughness, *abbe),
        other => panic!("{i}: {other:?}"),
    };
    let (eta, alpha, abbe) = rough(0);
    assert!(eta == 1.4 && (alpha - 0.3).abs() < 1e-6 && abbe.is_none());
    let (eta, alpha, abbe) = rough(1);
    assert!((eta - 1.5168).abs() < 1e-4 && alpha == 0.2 && abbe == Some(64.17));
    let (eta, alpha, _) = rough(2);
    assert!(eta == 1.6 && (alpha - 0.2).abs() < 1e-6);
    for material in &m[..3] {
        assert_eq!(
            material.transmissive,
            Param::grey(1.0),
            "the course reading stays glass"
        );
    }
    assert_eq!(m[3].physical, None);
    assert!(matches!(m[4].physical, Some(PhysicalMaterial::ThinDielectric { .. })));
}

/// pbrt's `mix` keeps both materials and the second's share (nested mixes too); the course
/// fields hold the larger part; a part that is not defined is an error at the list.
#[test]
fn mix_keeps_both_parts_and_the_amount() {
    let desc = scene(
        "MakeNamedMaterial \"white\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.8 0.8 0.8]\n\
         MakeNamedMaterial \"glass\" \"string type\" \"dielectric\"\n\
         MakeNamedMaterial \"half\" \"string type\" \"mix\" \"string materials\" [\"white\" \"glass\"] \"float amount\" 0.3\n\
         MakeNamedMaterial \"nested\" \"string type\" \"mix\" \"string materials\" [\"half\" \"white\"] \"float amount\" 0.9\n\
         NamedMaterial \"half\"\nShape \"sphere\"\nNamedMaterial \"nested\"\nShape \"sphere\"",
    );
    let m: Vec<&MaterialDesc> = desc.objects.iter().map(|o| &o.material).collect();
    let mix = m[0].mix.as_ref().expect("a mix");
    assert_eq!(mix.amount, Param::grey(0.3));
    assert_eq!(mix.materials[0].diffuse, Param::grey(0.8));
    assert_eq!(mix.materials[1].transmissive, Param::grey(1.0));
    assert_eq!(m[0].diffuse, Param::grey(0.8), "the course reading: the larger part");
    let nested = m[1].mix.as_ref().expect("a mix");
    assert!(nested.materials[0].mix.is_some(), "a mix inside a mix");
    assert_eq!(nested.amount, Param::grey(0.9));
    assert!(
        desc.warnings.iter().all(|(w, _)| !w.contains("mix")),
        "{:?}",
        desc.warnings
    );
    let (message, line, _) = error(
        "WorldBegin\nMakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"white\" \"nothing\"]\n",
    );
    assert!(message.contains("no material named \"white\""), "{message}");
    assert_eq!(line, 2);
}

/// pbrt-v4's `coatedconductor`: the conductor (its index relative to the coat's, as pbrt-v4
/// divides it) under a clear coat of `interface.eta` and `interface.roughness`.
#[test]
fn coated_conductors_are_a_conductor_under_a_clear_coat() {
    let desc = scene(
        "Material \"coatedconductor\" \"float interface.roughness\" 0.04 \"float interface.eta\" 1.6 \
         \"rgb conductor.eta\" [0.2 0.9 1.1] \"rgb conductor.k\" [3.9 2.4 2.1] \"float conductor.roughness\" 0.01\n\
         Shape \"sphere\"\n\
         Material \"coatedconductor\" \"rgb reflectance\" [0.9 0.5 0.2] \"float albedo\" 0.3\nShape \"sphere\"",
    );
    let m: Vec<&MaterialDesc> = desc.objects.iter().map(|o| &o.material).collect();
    let coat = m[0].clearcoat.expect("a coat");
    assert_eq!((coat.weight, coat.eta), (1.0, 1.6));
    assert!((coat.alpha - 0.2).abs() < 1e-6, "remapped √0.04: {}", coat.alpha);
    let Some(PhysicalMaterial::Conductor { eta, k, roughness, .. }) = &m[0].physical else {
        panic!("{:?}", m[0].physical)
    };
    assert!((*eta - Vec3::new(0.2, 0.9, 1.1) / 1.6).abs().max_element() < 1e-6);
    assert!((*k - Vec3::new(3.9, 2.4, 2.1) / 1.6).abs().max_element() < 1e-6);
    assert!((roughness - 0.1).abs() < 1e-6);
    assert!(matches!(
        &m[1].physical,
        Some(PhysicalMaterial::Conductor { reflectance: Some(Param::Constant(r)), .. }) if *r == Vec3::new(0.9, 0.5, 0.2)
    ));
    assert_eq!(m[1].clearcoat.map(|c| c.eta), Some(1.5));
    assert!(
        desc.warnings.iter().any(|(w, _)| w.contains("`albedo`")),
        "{:?}",
        desc.warnings
    );
}
