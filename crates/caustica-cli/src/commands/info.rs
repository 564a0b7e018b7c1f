//! `caustica info`: what was parsed, from the library's scene summary.

use super::load_scene;
use crate::cli::InfoArgs;
use crate::progress::Bars;
use caustica::scene::summary::{LightSummary, LoadSeconds, SceneReport, SceneSummary};
use caustica::{Error, Result};

/// Runs the command; returns the exit code.
pub fn run(args: InfoArgs) -> Result<u8> {
    let loaded = load_scene(Some(&args.scene), &args.scene_args, &Bars::new(false))?;
    let summary = loaded.scene.summary();
    if args.json {
        let info = SceneReport {
            scene: args.scene.display().to_string(),
            summary: &summary,
            seconds: LoadSeconds {
                parse: loaded.parse_seconds,
                build: loaded.build_seconds,
            },
        };
        let text = serde_json::to_string(&info).map_err(|e| Error::InvalidSettings(e.to_string()))?;
        crate::stdout::println(&text)?;
        return Ok(0);
    }
    crate::stdout::print(&text(&args.scene.display().to_string(), &summary))?;
    Ok(0)
}

/// The summary as aligned text.
fn text(scene: &str, s: &SceneSummary) -> String {
    let mut out = String::new();
    let mut line = |l: String| {
        out.push_str(&l);
        out.push('\n');
    };
    let c = &s.camera;
    line(format!("scene      {scene}"));
    line(format!(
        "camera     eye {:?}  look {:?}  aspect {}",
        c.eye, c.look, c.aspect_ratio
    ));
    line(format!("           u {:?}  v {:?}", c.u, c.v));
    line(format!("lights     {}", s.lights.len()));
    for light in &s.lights {
        line(match light {
            LightSummary::Point {
                position,
                color,
                attenuation,
            } => format!("  point        at {position:?}  colour {color:?}  attenuation {attenuation:?}"),
            LightSummary::Directional { direction, color } => {
                format!("  directional  towards {direction:?}  colour {color:?}")
            }
            LightSummary::Spot {
                position,
                direction,
                color,
                attenuation,
                inner_angle,
                outer_angle,
                exponent,
            } => format!(
                "  spot         at {position:?}  towards {direction:?}  colour {color:?}  cone {inner_angle}°–{outer_angle}°  exponent {exponent}  attenuation {attenuation:?}"
            ),
            LightSummary::Sun {
                direction,
                color,
                angle,
            } => format!("  sun          towards {direction:?}  colour {color:?}  angle {angle}°"),
            LightSummary::Environment { color, mapped } => format!(
                "  environment  colour {color:?}{}",
                if *mapped { " × map" } else { "" }
            ),
            LightSummary::Soft {
                shape,
                center,
                area,
                color,
                attenuation,
            } => format!(
                "  area         {shape} at {center:?}  area {area:.4}  colour {color:?}  attenuation {attenuation:?}"
            ),
        });
    }
    if !s.area_lights.is_empty() {
        line(format!(
            "area lights {} (emissive objects; lights in the physical model)",
            s.area_lights.len()
        ));
        for light in &s.area_lights {
            line(format!(
                "  object {}  area {:.4}  radiance {:?}{}",
                light.object,
                light.area,
                light.radiance,
                if light.uniform { "" } else { " (textured: mean guess)" }
            ));
        }
    }
    line(format!("ambient    {:?}", s.ambient));
    line(format!(
        "objects    {} shapes, {} meshes ({} triangles)",
        s.shapes, s.meshes, s.triangles
    ));
    for object in &s.objects {
        let kind = match (object.triangles, object.details.is_empty()) {
            (Some(n), _) => format!("mesh of {n} triangles"),
            (None, true) => object.kind.clone(),
            (None, false) => format!("{} ({})", object.kind, object.details),
        };
        line(format!(
            "  {kind:<44}  material {:>3}  bounds {:?} .. {:?}",
            object.material, object.bounds.min, object.bounds.max
        ));
    }
    line(format!("bounds     {:?} .. {:?}", s.bounds.min, s.bounds.max));
    line(format!("materials  {}   textures {}", s.materials.len(), s.textures));
    if !s.media.is_empty() {
        line(format!("media      {}", s.media.len()));
        for (i, m) in s.media.iter().enumerate() {
            let grid = m
                .grid
                .map_or(String::new(), |[x, y, z]| format!("  density grid {x}×{y}×{z}"));
            line(format!(
                "  {i:>3}  absorption {:?}  scattering {:?}  g {}{grid}",
                m.absorption, m.scattering, m.g
            ));
        }
    }
    for (i, m) in s.materials.iter().enumerate() {
        line(format!(
            "  {i:>3}  kd {}  ks {}  kr {}  kt {}  ke {}  ka {}  ns {}  index {}",
            m.diffuse, m.specular, m.reflective, m.transmissive, m.emissive, m.ambient, m.shininess, m.index
        ));
    }
    for warning in &s.warnings {
        line(format!("warning    {warning}"));
    }
    out
}
