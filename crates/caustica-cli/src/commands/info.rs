//! `caustica info`: what was parsed.

use super::{load_scene, Loaded};
use crate::cli::InfoArgs;
use crate::json;
use crate::progress::Bars;
use caustica::light::Light;
use caustica::material::Channel;
use caustica::scene::ObjectRef;
use caustica::Result;
use std::fmt::Write as _;

/// Runs the command; returns the exit code.
pub fn run(args: InfoArgs) -> Result<u8> {
    let loaded = load_scene(Some(&args.scene), &args.scene_args, &Bars::new(false))?;
    let scene = &loaded.scene;
    let bounds = scene.bounds();
    let cam = scene.camera();
    if args.json {
        println!("{}", info_json(&args, &loaded));
        return Ok(0);
    }
    println!("scene      {}", args.scene.display());
    println!(
        "camera     eye {:?}  look {:?}  aspect {}",
        cam.eye.to_array(),
        cam.look.to_array(),
        cam.aspect_ratio
    );
    println!("           u {:?}  v {:?}", cam.u.to_array(), cam.v.to_array());
    println!("lights     {}", scene.lights().course_lights().count());
    for light in scene.lights().course_lights() {
        match light {
            Light::Point {
                position,
                color,
                attenuation,
            } => {
                println!(
                    "  point        at {:?}  colour {:?}  attenuation {:?}",
                    position.to_array(),
                    color.to_array(),
                    attenuation
                )
            }
            Light::Directional { direction, color } => {
                println!(
                    "  directional  towards {:?}  colour {:?}",
                    direction.to_array(),
                    color.to_array()
                )
            }
            Light::Area(_) => {}
        }
    }
    let area_lights: Vec<_> = scene.lights().area_lights().collect();
    if !area_lights.is_empty() {
        println!(
            "area lights {} (emissive objects; lights in the physical model)",
            area_lights.len()
        );
        for light in area_lights {
            println!(
                "  {:?}  area {:.4}  radiance {:?}{}",
                light.object,
                light.area,
                light.radiance.to_array(),
                if light.uniform { "" } else { " (textured: mean guess)" }
            );
        }
    }
    println!("ambient    {:?}", scene.ambient().to_array());
    println!(
        "objects    {} shapes, {} meshes ({} triangles)",
        scene.shapes().len(),
        scene.meshes().len(),
        scene.triangles().len()
    );
    for (object, b) in scene.objects() {
        let kind = match object {
            ObjectRef::Shape(i) => format!("{:?}", scene.shapes()[i as usize].kind),
            ObjectRef::Mesh(i) => format!("mesh of {} triangles", scene.meshes()[i as usize].indices.len()),
        };
        let kind: String = kind.chars().take(60).collect();
        println!(
            "  {kind:<60}  material {:>3}  bounds {:?} .. {:?}",
            scene.object_material(object),
            b.min.to_array(),
            b.max.to_array()
        );
    }
    println!("bounds     {:?} .. {:?}", bounds.min.to_array(), bounds.max.to_array());
    println!(
        "materials  {}   textures {}",
        scene.materials().len(),
        scene.textures().len()
    );
    for (i, m) in scene.materials().iter().enumerate() {
        println!(
            "  {i:>3}  kd {}  ks {}  kr {}  kt {}  ke {}  ka {}  ns {}  index {}",
            channel(&m.diffuse),
            channel(&m.specular),
            channel(&m.reflective),
            channel(&m.transmissive),
            channel(&m.emissive),
            channel(&m.ambient),
            channel(&m.shininess),
            channel(&m.index)
        );
    }
    for warning in scene.warnings() {
        println!("warning    {warning}");
    }
    Ok(0)
}

fn channel(c: &Channel) -> String {
    match c {
        Channel::Constant(v) if v.x == v.y && v.y == v.z => format!("{}", v.x),
        Channel::Constant(v) => format!("({}, {}, {})", v.x, v.y, v.z),
        Channel::Texture(i) => format!("texture#{i}"),
    }
}

/// Everything the text output shows, as one JSON object.
fn info_json(args: &InfoArgs, loaded: &Loaded) -> String {
    let scene = &loaded.scene;
    let cam = scene.camera();
    let bounds = scene.bounds();
    let mut s = String::new();
    let _ = write!(
        s,
        "{{\"scene\":{},\"camera\":{{\"eye\":{},\"look\":{},\"u\":{},\"v\":{},\"aspect_ratio\":{}}},",
        json::string(&args.scene.display().to_string()),
        json::numbers(&cam.eye.to_array()),
        json::numbers(&cam.look.to_array()),
        json::numbers(&cam.u.to_array()),
        json::numbers(&cam.v.to_array()),
        json::number(f64::from(cam.aspect_ratio))
    );
    let lights: Vec<String> = scene.lights().course_lights().filter_map(light_json).collect();
    let objects: Vec<String> = scene
        .objects()
        .map(|(object, b)| {
            let kind = match object {
                ObjectRef::Shape(i) => format!("{:?}", scene.shapes()[i as usize].kind),
                ObjectRef::Mesh(_) => "mesh".to_string(),
            };
            let triangles = match object {
                ObjectRef::Shape(_) => String::new(),
                ObjectRef::Mesh(i) => format!(",\"triangles\":{}", scene.meshes()[i as usize].indices.len()),
            };
            format!(
                "{{\"kind\":{}{triangles},\"material\":{},\"bounds\":{}}}",
                json::string(&kind),
                scene.object_material(object),
                bounds_json(b.min.to_array(), b.max.to_array())
            )
        })
        .collect();
    let materials: Vec<String> = scene
        .materials()
        .iter()
        .map(|m| {
            format!(
                "{{\"diffuse\":{},\"specular\":{},\"reflective\":{},\"transmissive\":{},\"emissive\":{},\"ambient\":{},\"shininess\":{},\"index\":{}}}",
                channel_json(&m.diffuse),
                channel_json(&m.specular),
                channel_json(&m.reflective),
                channel_json(&m.transmissive),
                channel_json(&m.emissive),
                channel_json(&m.ambient),
                channel_json(&m.shininess),
                channel_json(&m.index)
            )
        })
        .collect();
    let _ = write!(
        s,
        "\"lights\":[{}],\"area_lights\":{},\"ambient\":{},\"shapes\":{},\"meshes\":{},\"triangles\":{},\"objects\":[{}],\"materials\":[{}],\"textures\":{},\"bounds\":{},\"warnings\":{},\"seconds\":{{\"parse\":{:.4},\"build\":{:.4}}}}}",
        lights.join(","),
        scene.lights().area_lights().count(),
        json::numbers(&scene.ambient().to_array()),
        scene.shapes().len(),
        scene.meshes().len(),
        scene.triangles().len(),
        objects.join(","),
        materials.join(","),
        scene.textures().len(),
        bounds_json(bounds.min.to_array(), bounds.max.to_array()),
        json::strings(scene.warnings()),
        loaded.parse_seconds,
        loaded.build_seconds
    );
    s
}

fn bounds_json(min: [f32; 3], max: [f32; 3]) -> String {
    format!("{{\"min\":{},\"max\":{}}}", json::numbers(&min), json::numbers(&max))
}

/// A constant as `[r, g, b]`, a texture as `{"texture": id}`.
fn channel_json(c: &Channel) -> String {
    match c {
        Channel::Constant(v) => json::numbers(&v.to_array()),
        Channel::Texture(i) => format!("{{\"texture\":{i}}}"),
    }
}

fn light_json(light: &Light) -> Option<String> {
    Some(match light {
        Light::Point {
            position,
            color,
            attenuation,
        } => format!(
            "{{\"type\":\"point\",\"position\":{},\"color\":{},\"attenuation\":{}}}",
            json::numbers(&position.to_array()),
            json::numbers(&color.to_array()),
            json::numbers(attenuation)
        ),
        Light::Directional { direction, color } => format!(
            "{{\"type\":\"directional\",\"direction\":{},\"color\":{}}}",
            json::numbers(&direction.to_array()),
            json::numbers(&color.to_array())
        ),
        Light::Area(_) => return None,
    })
}
