//! What a built scene holds, as plain data for people and programs: `caustica info` prints it
//! as text or JSON, the Python module hands it out as a dict.

use super::{ObjectRef, Scene};
use crate::geometry::ShapeKind;
use crate::light::Light;
use crate::material::Channel;
use crate::math::Aabb;
use serde::Serialize;

/// A summary of a scene.
#[derive(Clone, Debug, Serialize)]
pub struct SceneSummary {
    /// The camera.
    pub camera: CameraSummary,
    /// The file's lights (emissive objects are in `area_lights`).
    pub lights: Vec<LightSummary>,
    /// Emissive objects (lights in the physical model).
    pub area_lights: Vec<AreaLightSummary>,
    /// Ambient light Ia.
    pub ambient: [f32; 3],
    /// Number of analytic shapes.
    pub shapes: usize,
    /// Number of meshes.
    pub meshes: usize,
    /// Number of triangles in all meshes.
    pub triangles: usize,
    /// Every object, shapes first.
    pub objects: Vec<ObjectSummary>,
    /// Materials, by id.
    pub materials: Vec<MaterialSummary>,
    /// Number of textures.
    pub textures: usize,
    /// Participating media (absorbing glass among them), by number.
    pub media: Vec<MediumSummary>,
    /// World bounds (infinite, `null` in JSON, for an empty scene).
    pub bounds: BoundsSummary,
    /// Remarks made while reading and building.
    pub warnings: Vec<String>,
}

/// What `caustica info --json` prints and the Python module's `Scene.info()` returns: the file
/// as named, its summary, and the seconds reading and building it took.
#[derive(Clone, Debug, Serialize)]
pub struct SceneReport<'a> {
    /// The file as the user named it.
    pub scene: String,
    /// The summary, its fields at the top level.
    #[serde(flatten)]
    pub summary: &'a SceneSummary,
    /// Seconds per loading phase.
    pub seconds: LoadSeconds,
}

/// Seconds spent loading a scene.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct LoadSeconds {
    /// Reading and parsing the file.
    pub parse: f64,
    /// Building the scene.
    pub build: f64,
}

/// The pinhole camera.
#[derive(Clone, Debug, Serialize)]
pub struct CameraSummary {
    /// Eye position.
    pub eye: [f32; 3],
    /// From the eye to the image-plane centre.
    pub look: [f32; 3],
    /// Image-plane horizontal span.
    pub u: [f32; 3],
    /// Image-plane vertical span.
    pub v: [f32; 3],
    /// Width / height.
    pub aspect_ratio: f32,
}

/// A point or directional light.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "type", rename_all = "lowercase")]
pub enum LightSummary {
    /// A point light.
    Point {
        /// Position.
        position: [f32; 3],
        /// Colour.
        color: [f32; 3],
        /// The course's (a, b, c) falloff.
        attenuation: [f32; 3],
    },
    /// A directional light.
    Directional {
        /// The unit direction light travels.
        direction: [f32; 3],
        /// Colour.
        color: [f32; 3],
    },
    /// A spot light.
    Spot {
        /// Position.
        position: [f32; 3],
        /// The unit direction it shines.
        direction: [f32; 3],
        /// Colour on its axis.
        color: [f32; 3],
        /// The course's (a, b, c) falloff.
        attenuation: [f32; 3],
        /// Half-angle of full intensity, in degrees.
        inner_angle: f32,
        /// Half-angle beyond which it is dark, in degrees.
        outer_angle: f32,
        /// Exponent of the cosine falloff.
        exponent: f32,
    },
    /// A sun.
    Sun {
        /// The unit direction its light travels.
        direction: [f32; 3],
        /// Irradiance on a surface facing it.
        color: [f32; 3],
        /// Angular diameter in degrees.
        angle: f32,
    },
    /// The sky.
    Environment {
        /// Radiance (times the map).
        color: [f32; 3],
        /// Whether an image map modulates it.
        mapped: bool,
    },
    /// A light with a size (`area_light`).
    Soft {
        /// "ball" or "parallelogram".
        shape: &'static str,
        /// Centre.
        center: [f32; 3],
        /// Emitting area.
        area: f32,
        /// A ball's intensity or a parallelogram's radiance.
        color: [f32; 3],
        /// The course's (a, b, c) falloff.
        attenuation: [f32; 3],
    },
}

/// An emissive object.
#[derive(Clone, Debug, Serialize)]
pub struct AreaLightSummary {
    /// Index into [`SceneSummary::objects`].
    pub object: usize,
    /// World area.
    pub area: f32,
    /// Emitted radiance (a guess at the mean where textured).
    pub radiance: [f32; 3],
    /// Whether the radiance is the same everywhere on it.
    pub uniform: bool,
}

/// One object.
#[derive(Clone, Debug, Serialize)]
pub struct ObjectSummary {
    /// What it is: `sphere`, `box`, `square`, `cylinder`, `cone` or `mesh`.
    pub kind: String,
    /// Its parameters in words (a cone's height and radii, a cylinder's caps).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub details: String,
    /// A mesh's triangle count.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub triangles: Option<usize>,
    /// Material id.
    pub material: u32,
    /// World bounds.
    pub bounds: BoundsSummary,
}

/// A box.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BoundsSummary {
    /// Lower corner.
    pub min: [f32; 3],
    /// Upper corner.
    pub max: [f32; 3],
}

/// A material parameter: a constant colour or a texture.
#[derive(Clone, Debug, Serialize)]
#[serde(untagged)]
pub enum ChannelSummary {
    /// A constant.
    Constant([f32; 3]),
    /// A texture by id.
    Texture {
        /// Texture id.
        texture: u32,
    },
}

/// A participating medium's coefficients per unit of length, its phase function's mean cosine,
/// and a density grid's size.
#[derive(Clone, Debug, Serialize)]
pub struct MediumSummary {
    /// σa.
    pub absorption: [f32; 3],
    /// σs.
    pub scattering: [f32; 3],
    /// Henyey–Greenstein's g.
    pub g: f32,
    /// Samples along x, y, z of its density grid (`None`: homogeneous).
    pub grid: Option<[usize; 3]>,
}

/// A material's eight course parameters.
#[derive(Clone, Debug, Serialize)]
pub struct MaterialSummary {
    /// kd
    pub diffuse: ChannelSummary,
    /// ks
    pub specular: ChannelSummary,
    /// kr
    pub reflective: ChannelSummary,
    /// kt
    pub transmissive: ChannelSummary,
    /// ke
    pub emissive: ChannelSummary,
    /// ka
    pub ambient: ChannelSummary,
    /// Phong exponent.
    pub shininess: ChannelSummary,
    /// Index of refraction.
    pub index: ChannelSummary,
}

impl ChannelSummary {
    fn of(c: &Channel) -> ChannelSummary {
        match c {
            Channel::Constant(v) => ChannelSummary::Constant(v.to_array()),
            Channel::Texture(i) => ChannelSummary::Texture { texture: *i },
        }
    }
}

impl std::fmt::Display for ChannelSummary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ChannelSummary::Constant([r, g, b]) if r == g && g == b => write!(f, "{r}"),
            ChannelSummary::Constant([r, g, b]) => write!(f, "({r}, {g}, {b})"),
            ChannelSummary::Texture { texture } => write!(f, "texture#{texture}"),
        }
    }
}

impl BoundsSummary {
    fn of(b: &Aabb) -> BoundsSummary {
        BoundsSummary {
            min: b.min.to_array(),
            max: b.max.to_array(),
        }
    }
}

/// A shape kind's name in words ("sphere", "torus", …).
pub fn shape_name(kind: &ShapeKind) -> String {
    describe(kind).0
}

/// A shape's kind and its parameters in words.
fn describe(kind: &ShapeKind) -> (String, String) {
    match kind {
        ShapeKind::Sphere => ("sphere".into(), String::new()),
        ShapeKind::Box => ("box".into(), String::new()),
        ShapeKind::Square => ("square".into(), String::new()),
        ShapeKind::Torus(t) => ("torus".into(), format!("radii {} and {}", t.major, t.minor)),
        ShapeKind::Metaballs(m) => ("metaballs".into(), format!("{} balls", m.balls().len())),
        ShapeKind::Csg(c) => ("csg".into(), format!("{} solids", c.materials().len())),
        ShapeKind::Disk { inner } => (
            "disk".into(),
            if *inner > 0.0 {
                format!("hole {inner}")
            } else {
                String::new()
            },
        ),
        ShapeKind::Cone(c) => {
            let caps = if c.capped { "capped" } else { "open" };
            if c.bottom_radius == c.top_radius && c.height == 1.0 && c.bottom_radius == 1.0 {
                ("cylinder".into(), caps.into())
            } else {
                (
                    "cone".into(),
                    format!(
                        "height {}, radius {} to {}, {caps}",
                        c.height, c.bottom_radius, c.top_radius
                    ),
                )
            }
        }
    }
}

impl Scene {
    /// What the scene holds.
    pub fn summary(&self) -> SceneSummary {
        let camera = self.camera();
        let lights = self
            .lights()
            .iter()
            .filter_map(|light| match light {
                Light::Point {
                    position,
                    color,
                    attenuation,
                } => Some(LightSummary::Point {
                    position: position.to_array(),
                    color: color.to_array(),
                    attenuation: *attenuation,
                }),
                Light::Directional { direction, color } => Some(LightSummary::Directional {
                    direction: direction.to_array(),
                    color: color.to_array(),
                }),
                Light::Spot {
                    position,
                    direction,
                    color,
                    attenuation,
                    cos_inner,
                    cos_outer,
                    exponent,
                } => Some(LightSummary::Spot {
                    position: position.to_array(),
                    direction: direction.to_array(),
                    color: color.to_array(),
                    attenuation: *attenuation,
                    inner_angle: cos_inner.clamp(-1.0, 1.0).acos().to_degrees(),
                    outer_angle: cos_outer.clamp(-1.0, 1.0).acos().to_degrees(),
                    exponent: *exponent,
                }),
                Light::Sun {
                    direction,
                    color,
                    cos_max,
                    ..
                } => Some(LightSummary::Sun {
                    direction: direction.to_array(),
                    color: color.to_array(),
                    angle: 2.0 * cos_max.clamp(-1.0, 1.0).acos().to_degrees(),
                }),
                Light::Environment(env) => Some(LightSummary::Environment {
                    color: env.color.to_array(),
                    mapped: env.has_map(),
                }),
                Light::Soft(soft) => Some(LightSummary::Soft {
                    shape: match soft.shape {
                        crate::light::soft::SoftShape::Sphere { .. } => "ball",
                        crate::light::soft::SoftShape::Parallelogram { ellipse: false, .. } => "parallelogram",
                        crate::light::soft::SoftShape::Parallelogram { ellipse: true, .. } => "ellipse",
                    },
                    center: soft.center().to_array(),
                    area: soft.area(),
                    color: soft.color.to_array(),
                    attenuation: soft.attenuation,
                }),
                Light::Area(_) => None,
            })
            .collect();
        let object_index = |object: ObjectRef| match object {
            ObjectRef::Shape(i) => i as usize,
            ObjectRef::Mesh(i) => self.shapes().len() + i as usize,
        };
        let area_lights = self
            .lights()
            .area_lights()
            .map(|light| AreaLightSummary {
                object: object_index(light.object),
                area: light.area,
                radiance: light.radiance.to_array(),
                uniform: light.uniform,
            })
            .collect();
        let objects = self
            .objects()
            .map(|(object, bounds)| {
                let (kind, details, triangles) = match object {
                    ObjectRef::Shape(i) => {
                        let (kind, details) = describe(&self.shapes()[i as usize].kind);
                        (kind, details, None)
                    }
                    ObjectRef::Mesh(i) => (
                        "mesh".to_string(),
                        String::new(),
                        Some(self.meshes()[i as usize].indices.len()),
                    ),
                };
                ObjectSummary {
                    kind,
                    details,
                    triangles,
                    material: self.object_material(object),
                    bounds: BoundsSummary::of(&bounds),
                }
            })
            .collect();
        let materials = self
            .materials()
            .iter()
            .map(|m| MaterialSummary {
                diffuse: ChannelSummary::of(&m.diffuse),
                specular: ChannelSummary::of(&m.specular),
                reflective: ChannelSummary::of(&m.reflective),
                transmissive: ChannelSummary::of(&m.transmissive),
                emissive: ChannelSummary::of(&m.emissive),
                ambient: ChannelSummary::of(&m.ambient),
                shininess: ChannelSummary::of(&m.shininess),
                index: ChannelSummary::of(&m.index),
            })
            .collect();
        SceneSummary {
            camera: CameraSummary {
                eye: camera.eye.to_array(),
                look: camera.look.to_array(),
                u: camera.u.to_array(),
                v: camera.v.to_array(),
                aspect_ratio: camera.aspect_ratio,
            },
            lights,
            area_lights,
            ambient: self.ambient().to_array(),
            shapes: self.shapes().len(),
            meshes: self.meshes().len(),
            triangles: self.triangles().len(),
            objects,
            materials,
            textures: self.textures().len(),
            media: self
                .media()
                .iter()
                .map(|m| MediumSummary {
                    absorption: m.sigma_a.to_array(),
                    scattering: m.sigma_s.to_array(),
                    g: m.phase.g,
                    grid: m.grid.as_ref().map(|g| g.dims()),
                })
                .collect(),
            bounds: BoundsSummary::of(&self.bounds()),
            warnings: self.warnings().to_vec(),
        }
    }
}
