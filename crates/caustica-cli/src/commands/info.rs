//! `caustica info`: what was parsed.

use super::load_scene;
use crate::cli::InfoArgs;
use caustica::light::Light;
use caustica::material::Channel;
use caustica::scene::ObjectRef;
use caustica::Result;
use std::fmt::Write as _;

/// Runs the command; returns the exit code.
pub fn run(args: InfoArgs) -> Result<u8> {
    let scene = load_scene(Some(&args.scene), &args.scene_args)?;
    let bounds = scene.bounds();
    let cam = &scene.camera;
    if args.json {
        let mut s = String::new();
        let _ = write!(
            s,
            "{{\"camera\":{{\"eye\":{:?},\"look\":{:?},\"u\":{:?},\"v\":{:?},\"aspect_ratio\":{}}},",
            cam.eye.to_array(),
            cam.look.to_array(),
            cam.u.to_array(),
            cam.v.to_array(),
            cam.aspect_ratio
        );
        let lights: Vec<String> = scene.lights.iter().map(light_json).collect();
        let _ = write!(
            s,
            "\"lights\":[{}],\"ambient\":{:?},\"shapes\":{},\"meshes\":{},\"triangles\":{},\"materials\":{},\"textures\":{},\"bounds\":{{\"min\":{:?},\"max\":{:?}}},\"warnings\":{:?}}}",
            lights.join(","),
            scene.ambient.to_array(),
            scene.shapes.len(),
            scene.meshes.len(),
            scene.triangles.len(),
            scene.materials.len(),
            scene.textures.len(),
            bounds.min.to_array(),
            bounds.max.to_array(),
            scene.warnings
        );
        println!("{s}");
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
    println!("lights     {}", scene.lights.len());
    for light in &scene.lights {
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
        }
    }
    println!("ambient    {:?}", scene.ambient.to_array());
    println!(
        "objects    {} shapes, {} meshes ({} triangles)",
        scene.shapes.len(),
        scene.meshes.len(),
        scene.triangles.len()
    );
    for (object, b) in scene.objects() {
        let kind = match object {
            ObjectRef::Shape(i) => format!("{:?}", scene.shapes[i as usize].kind),
            ObjectRef::Mesh(i) => format!("mesh of {} triangles", scene.meshes[i as usize].indices.len()),
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
        scene.materials.len(),
        scene.textures.len()
    );
    for (i, m) in scene.materials.iter().enumerate() {
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
    for warning in &scene.warnings {
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

fn light_json(light: &Light) -> String {
    match light {
        Light::Point {
            position,
            color,
            attenuation,
        } => format!(
            "{{\"type\":\"point\",\"position\":{:?},\"color\":{:?},\"attenuation\":{:?}}}",
            position.to_array(),
            color.to_array(),
            attenuation
        ),
        Light::Directional { direction, color } => format!(
            "{{\"type\":\"directional\",\"direction\":{:?},\"color\":{:?}}}",
            direction.to_array(),
            color.to_array()
        ),
    }
}
