//! From a parsed description to a renderable [`Scene`]: textures loaded once per path, shapes
//! placed, meshes moved to world space, and the BVH built.

use super::{Mesh, Scene, SceneParts, TriangleRef};
use crate::camera::Camera;
use crate::description::{
    ImageMap, LightDesc, MaterialDesc, ObjectDesc, Param, SceneDescription, ShapeDesc, SoftShapeDesc, TrimeshDesc,
};
use crate::error::Span;
use crate::error::{Error, ParseError};
use crate::geometry::cone::Cone;
use crate::geometry::triangle::Triangle;
use crate::geometry::{Shape, ShapeKind, ShapeSettings};
use crate::image_io;
use crate::light::{Environment, Light, SoftLight};
use crate::material::{Channel, Material};
use crate::math::{Aabb, Mat3, Vec3};
use crate::medium::{DensityGrid, Medium, Side, VACUUM};
use crate::progress::{NoProgress, Progress};
use crate::texture::{Image, Texture};
use rayon::prelude::*;
use std::collections::HashMap;

/// Options for building a scene.
#[derive(Clone, Debug, Default)]
pub struct BuildSettings {
    /// How shapes are built.
    pub shapes: ShapeSettings,
}

/// Builds a scene from its description.
pub fn build(desc: &SceneDescription, settings: &BuildSettings) -> Result<Scene, ParseError> {
    build_reporting(desc, settings, &NoProgress)
}

/// [`build`], reporting a "build" phase: each object placed (a mesh counts its triangles), then
/// each primitive put in the BVH — the slow part for large meshes.
pub fn build_reporting(
    desc: &SceneDescription,
    settings: &BuildSettings,
    progress: &dyn Progress,
) -> Result<Scene, ParseError> {
    let work: u64 = desc.objects.iter().map(weight).sum();
    progress.start("build", 2 * work);
    let scene = build_objects(desc, settings, progress);
    progress.finish();
    scene
}

fn build_objects(
    desc: &SceneDescription,
    settings: &BuildSettings,
    progress: &dyn Progress,
) -> Result<Scene, ParseError> {
    let mut builder = Builder::default();
    let camera = desc.camera.as_ref().map(Camera::from_desc).unwrap_or_default();
    let mut warnings: Vec<String> = desc.warnings.iter().map(|(w, _)| w.clone()).collect();
    let mut lights = Vec::new();
    // Each described light's number among the built ones (`None`: left out).
    let mut light_numbers = Vec::with_capacity(desc.lights.len());
    for light in &desc.lights {
        let built = convert_light(light, &mut warnings)?;
        light_numbers.push(built.is_some().then_some(lights.len()));
        lights.extend(built);
    }
    let light_media = desc
        .light_media
        .iter()
        .filter_map(|&(i, m)| Some((light_numbers.get(i).copied().flatten()?, m.map_or(VACUUM, |m| m as u32))))
        .collect();
    if desc.camera.is_none() {
        warnings.push("the scene has no camera: using the default one at the origin looking down −z".into());
    }
    if desc.lights.is_empty()
        && desc.ambient == Vec3::ZERO
        && !desc.objects.iter().any(|o| material_is_emissive(&o.material))
    {
        warnings.push("the scene has no lights: the image will be black".into());
    }
    builder.decode_images(desc);
    let mut placed = 0;
    for object in &desc.objects {
        builder.add_object(object, &settings.shapes, &mut warnings)?;
        placed += weight(object);
        progress.advance(weight(object));
    }
    // Dropped triangles never reach the BVH: count them now so the phase ends at its total.
    progress.advance(placed.saturating_sub((builder.shapes.len() + builder.triangles.len()) as u64));
    Ok(Scene::assemble(
        SceneParts {
            camera,
            lights,
            ambient: desc.ambient,
            materials: builder.materials,
            textures: builder.textures,
            shapes: builder.shapes,
            shape_materials: builder.shape_materials,
            meshes: builder.meshes,
            triangles: builder.triangles,
            triangle_refs: builder.triangle_refs,
            warnings,
            hints: crate::description::RenderHints {
                scattering_media: desc.media.iter().any(|m| m.sigma_s.max_element() > 0.0),
                ..desc.hints.clone()
            },
            media: desc.media.iter().map(convert_medium).collect::<Result<_, _>>()?,
            ambient_medium: desc.ambient_medium.map_or(VACUUM, |m| m as u32),
            camera_medium: desc.camera_medium.map(|m| m as u32),
            light_media,
        },
        progress,
    ))
}

/// A side of a medium boundary, as the scene numbers media.
fn medium_side(side: crate::description::MediumSide) -> Side {
    match side {
        crate::description::MediumSide::Medium(m) => Side::Medium(m.map_or(VACUUM, |m| m as u32)),
        crate::description::MediumSide::Surrounding => Side::Surrounding,
    }
}

/// A medium ready to render; a grid whose size and samples disagree is an error at its span.
fn convert_medium(desc: &crate::description::MediumDesc) -> Result<Medium, ParseError> {
    let mut medium = Medium::homogeneous(desc.sigma_a, desc.sigma_s, desc.g);
    if let Some(grid) = &desc.grid {
        let [x, y, z] = grid.dims;
        if x.checked_mul(y).and_then(|n| n.checked_mul(z)) != Some(grid.values.len()) || grid.values.is_empty() {
            return Err(ParseError::new(
                format!(
                    "a density grid of {x}×{y}×{z} samples needs {} values, not {}",
                    x.saturating_mul(y).saturating_mul(z),
                    grid.values.len()
                ),
                desc.span.clone(),
            ));
        }
        let to_grid = glam::Affine3A::from_mat4(grid.grid_from_world);
        medium.grid = Some(DensityGrid::new(grid.dims, grid.values.clone(), to_grid));
    }
    Ok(medium)
}

/// Units of build work for an object: its triangles, or 1 for a shape.
fn weight(object: &ObjectDesc) -> u64 {
    match &object.shape {
        ShapeDesc::Trimesh(mesh) => mesh.triangles.len() as u64,
        _ => 1,
    }
}

fn material_is_emissive(m: &MaterialDesc) -> bool {
    !matches!(m.emissive, Param::Constant(c) if c == Vec3::ZERO)
}

fn convert_light(light: &LightDesc, warnings: &mut Vec<String>) -> Result<Option<Light>, ParseError> {
    let mut unit = |v: &Vec3, what: &str| {
        let d = v.normalize_or_zero();
        if d == Vec3::ZERO || !d.is_finite() {
            warnings.push(format!("a {what} with a zero direction gives no light: left out"));
        }
        (d != Vec3::ZERO && d.is_finite()).then_some(d)
    };
    Ok(match light {
        LightDesc::Point {
            position,
            color,
            attenuation,
            ..
        } => Some(Light::Point {
            position: *position,
            color: *color,
            attenuation: *attenuation,
        }),
        LightDesc::Directional { direction, color, .. } => {
            unit(direction, "directional light").map(|direction| Light::Directional {
                direction,
                color: *color,
            })
        }
        LightDesc::Spot {
            position,
            direction,
            color,
            attenuation,
            inner_degrees,
            outer_degrees,
            exponent,
            ..
        } => unit(direction, "spot light").map(|direction| {
            let outer = outer_degrees.clamp(0.0, 180.0);
            let inner = inner_degrees.clamp(0.0, outer);
            Light::Spot {
                position: *position,
                direction,
                color: *color,
                attenuation: *attenuation,
                cos_inner: inner.to_radians().cos(),
                cos_outer: outer.to_radians().cos(),
                exponent: exponent.max(0.0),
            }
        }),
        LightDesc::Sun {
            direction,
            color,
            angle_degrees,
            ..
        } => unit(direction, "sun").map(|direction| Light::sun(direction, *color, *angle_degrees)),
        LightDesc::Environment {
            color,
            map,
            rotation,
            equal_area,
            span,
        } => {
            let texture = match map {
                None => None,
                Some(source) => Some(image_io::load_environment(source).map_err(|e| {
                    let reason = match e {
                        Error::Image { message, .. } => message,
                        other => other.to_string(),
                    };
                    ParseError::new(
                        format!("cannot read the environment map `{}`: {reason}", source.name()),
                        span.clone(),
                    )
                    .with_help("environment maps are EXR, Radiance HDR or PFM images in latitude–longitude layout, resolved against the scene file's folder")
                })?),
            };
            if *equal_area {
                // pbrt-v4's equal-area square, resampled to the latitude–longitude layout.
                let texture = texture.map(|t| crate::light::environment::equal_area_to_lat_long(&t));
                let rotation = *rotation * crate::light::environment::equal_area_from_lat_long();
                Some(Light::Environment(Environment::new(*color, texture, rotation)))
            } else {
                Some(Light::Environment(Environment::new(*color, texture, *rotation)))
            }
        }
        LightDesc::Soft {
            shape,
            color,
            attenuation,
            span,
        } => match *shape {
            // A ball of radius 0 is a point light.
            SoftShapeDesc::Sphere { center, radius } if radius <= 0.0 => Some(Light::Point {
                position: center,
                color: *color,
                attenuation: *attenuation,
            }),
            SoftShapeDesc::Sphere { center, radius } => Some(Light::Soft(SoftLight {
                shape: crate::light::soft::SoftShape::Sphere { center, radius },
                color: *color,
                attenuation: *attenuation,
            })),
            SoftShapeDesc::Parallelogram { corner, u, v } => Some(Light::Soft(
                SoftLight::parallelogram(corner, u, v, *color, *attenuation)
                    .ok_or_else(|| ParseError::new("the area light's edges `u` and `v` span no area", span.clone()))?,
            )),
            SoftShapeDesc::Ellipse { corner, u, v } => Some(Light::Soft(
                SoftLight::ellipse(corner, u, v, *color, *attenuation)
                    .ok_or_else(|| ParseError::new("the area light's edges `u` and `v` span no area", span.clone()))?,
            )),
        },
        LightDesc::Skybox {
            faces,
            layout,
            color,
            span,
        } => {
            let mut images = Vec::with_capacity(6);
            for path in faces {
                images.push(image_io::load_texture(path).map_err(|e| {
                    let reason = match e {
                        Error::Image { message, .. } => message,
                        other => other.to_string(),
                    };
                    ParseError::new(
                        format!("cannot read the skybox image `{}`: {reason}", path.display()),
                        span.clone(),
                    )
                    .with_help("skybox images are resolved against the scene file's folder")
                })?);
            }
            let faces: [crate::texture::Texture; 6] = images.try_into().expect("six faces");
            let map = crate::light::cube_map::to_lat_long(&faces, *layout);
            Some(Light::Environment(Environment::new(*color, Some(map), Mat3::IDENTITY)))
        }
    })
}

#[derive(Default)]
struct Builder {
    materials: Vec<Material>,
    material_ids: HashMap<MaterialKey, u32>,
    textures: Vec<Texture>,
    texture_ids: HashMap<String, u32>,
    images: HashMap<String, std::sync::Arc<crate::texture::Image>>,
    shapes: Vec<Shape>,
    shape_materials: Vec<u32>,
    meshes: Vec<Mesh>,
    triangles: Vec<Triangle>,
    triangle_refs: Vec<TriangleRef>,
}

/// Materials are deduplicated by their exact bits.
#[derive(Clone, PartialEq, Eq, Hash)]
struct MaterialKey(Vec<u32>);

/// The decoded-image cache's key: one image per source and encoding.
fn image_key(map: &ImageMap) -> String {
    format!("{}\u{0}{:?}", map.source.name(), map.encoding)
}

impl Builder {
    /// Decodes every image the scene's materials read, in parallel (real files name dozens of
    /// large images), into the cache the materials are then built from. An image that fails
    /// is left for the build to report at its material's place.
    fn decode_images(&mut self, desc: &SceneDescription) {
        let mut wanted: Vec<(String, ImageMap)> = Vec::new();
        let mut seen = std::collections::HashSet::new();
        for object in &desc.objects {
            let vertex_materials = match &object.shape {
                ShapeDesc::Trimesh(mesh) => mesh.materials.as_deref().unwrap_or(&[]),
                _ => &[],
            };
            for material in std::iter::once(&object.material).chain(vertex_materials) {
                for map in material.image_maps() {
                    let key = image_key(&map);
                    if seen.insert(key.clone()) {
                        wanted.push((key, map));
                    }
                }
            }
        }
        if wanted.len() < 2 {
            return;
        }
        let decoded: Vec<(String, Option<Image>)> = wanted
            .into_par_iter()
            .map(|(key, map)| (key, image_io::load_image(&map.source, map.encoding).ok()))
            .collect();
        for (key, image) in decoded {
            if let Some(image) = image {
                self.images.insert(key, std::sync::Arc::new(image));
            }
        }
    }

    fn add_object(
        &mut self,
        object: &ObjectDesc,
        settings: &ShapeSettings,
        warnings: &mut Vec<String>,
    ) -> Result<(), ParseError> {
        if let ShapeDesc::Csg(csg) = &object.shape {
            let root = self.csg_node(csg, object, settings)?;
            let leaves = crate::geometry::csg::Csg::new(root)
                .ok_or_else(|| ParseError::new("CSG operands must be closed solids", object.span.clone()))?;
            let first = leaves.materials()[0];
            if leaves
                .materials()
                .iter()
                .any(|&id| self.materials[id as usize].is_emissive())
            {
                warnings.push(
                    "an emissive CSG solid glows but lights nothing in the physical model (only spheres, boxes, squares, discs, cylinders, cones and meshes are sampled as area lights)".into(),
                );
            }
            let kind = ShapeKind::Csg(std::sync::Arc::new(leaves));
            let shape = Shape::new(kind, glam::Mat4::IDENTITY).ok_or_else(|| singular(&object.span))?;
            self.shapes.push(shape);
            // Its own material id is the first leaf's (what a whole-object query reads).
            self.shape_materials.push(first);
            return Ok(());
        }
        let material = self.material(&object.material)?;
        let m = object.world_from_object;
        let kind = match &object.shape {
            ShapeDesc::Trimesh(mesh) => return self.add_mesh(object, mesh, material, warnings),
            _ => shape_kind(object, settings)?,
        };
        if !matches!(
            kind,
            ShapeKind::Sphere | ShapeKind::Box | ShapeKind::Square | ShapeKind::Cone(_) | ShapeKind::Disk { .. }
        ) && material_is_emissive(&object.material)
        {
            warnings.push(format!(
                "an emissive {} glows but lights nothing in the physical model (only spheres, boxes, squares, discs, cylinders, cones and meshes are sampled as area lights)",
                crate::scene::summary::shape_name(&kind)
            ));
        }
        let shape = Shape::new(kind, m).ok_or_else(|| singular(&object.span))?;
        self.shapes.push(shape);
        self.shape_materials.push(material);
        Ok(())
    }

    /// The CSG tree of `desc` (operands folded from the left), each leaf placed and given its
    /// material.
    fn csg_node(
        &mut self,
        desc: &crate::description::CsgDesc,
        object: &ObjectDesc,
        settings: &ShapeSettings,
    ) -> Result<crate::geometry::csg::CsgNode, ParseError> {
        use crate::geometry::csg::{is_closed, CsgNode, CsgOp};
        let op = match desc.op {
            crate::description::CsgOpDesc::Union => CsgOp::Union,
            crate::description::CsgOpDesc::Intersection => CsgOp::Intersection,
            crate::description::CsgOpDesc::Difference => CsgOp::Difference,
        };
        let mut nodes = Vec::with_capacity(desc.operands.len());
        for operand in &desc.operands {
            let node = match &operand.shape {
                ShapeDesc::Csg(inner) => self.csg_node(inner, operand, settings)?,
                ShapeDesc::Trimesh(_) => {
                    return Err(ParseError::new(
                        "CSG operands must be closed shapes (sphere, box, capped cylinder or cone, torus, metaballs): a mesh is not supported",
                        operand.span.clone(),
                    ))
                }
                _ => {
                    let kind = shape_kind(operand, settings)?;
                    if !is_closed(&kind) {
                        return Err(ParseError::new(
                            format!(
                                "CSG operands must be closed solids, and an open {} is not",
                                crate::scene::summary::shape_name(&kind)
                            ),
                            operand.span.clone(),
                        )
                        .with_help("use a box for a slab, and capped cylinders and cones"));
                    }
                    let material = self.material(&operand.material)?;
                    let mut shape = Shape::new(kind, operand.world_from_object).ok_or_else(|| singular(&operand.span))?;
                    shape.needs_uv = self.materials[material as usize].is_textured();
                    CsgNode::Leaf { shape: Box::new(shape), material }
                }
            };
            nodes.push(node);
        }
        let mut nodes = nodes.into_iter();
        let first = nodes
            .next()
            .ok_or_else(|| ParseError::new("a CSG operation needs operands", object.span.clone()))?;
        Ok(nodes.fold(first, |a, b| CsgNode::Op {
            op,
            a: Box::new(a),
            b: Box::new(b),
        }))
    }

    fn add_mesh(
        &mut self,
        object: &ObjectDesc,
        desc: &TrimeshDesc,
        material: u32,
        warnings: &mut Vec<String>,
    ) -> Result<(), ParseError> {
        let m = object.world_from_object;
        if crate::math::is_degenerate_transform(&m) {
            return Err(singular(&object.span));
        }
        let normal_to_world = Mat3::from_mat4(m.inverse()).transpose();
        let points: Vec<Vec3> = desc.points.iter().map(|p| m.transform_point3(*p)).collect();
        let normals = desc
            .normals
            .as_ref()
            .map(|ns| ns.iter().map(|n| (normal_to_world * *n).normalize_or_zero()).collect());
        let vertex_materials = match &desc.materials {
            Some(ms) => Some(
                ms.iter()
                    .map(|md| self.material(md))
                    .collect::<Result<Vec<u32>, ParseError>>()?,
            ),
            None => None,
        };
        let mesh_index = self.meshes.len() as u32;
        let mut indices = Vec::with_capacity(desc.triangles.len());
        let mut bounds = Aabb::EMPTY;
        let mut dropped = 0usize;
        for tri in &desc.triangles {
            let [a, b, c] = tri.map(|i| points[i as usize]);
            let t = Triangle::new(a, b, c);
            if t.geometric_normal() == Vec3::ZERO || !t.bounds().min.is_finite() || !t.bounds().max.is_finite() {
                dropped += 1;
                continue;
            }
            bounds = bounds.union(t.bounds());
            self.triangle_refs.push(TriangleRef {
                mesh: mesh_index,
                index: indices.len() as u32,
            });
            self.triangles.push(t);
            indices.push(*tri);
        }
        if dropped > 0 {
            warnings.push(format!(
                "dropped {dropped} degenerate triangle(s) of a mesh after its transform"
            ));
        }
        let tangents = match (&self.materials[material as usize].normal_map, &desc.uvs) {
            (Some(_), Some(uvs)) => Some(match &desc.tangents {
                Some(ts) => ts
                    .iter()
                    .map(|t| (m.transform_vector3(t.truncate()).normalize_or_zero()).extend(t.w.signum()))
                    .collect(),
                None => crate::geometry::tangents::generate(&points, &indices, uvs, normals.as_deref()),
            }),
            _ => None,
        };
        self.meshes.push(Mesh {
            indices,
            normals,
            tangents,
            uvs: desc.uvs.clone(),
            vertex_materials,
            material,
            bounds,
        });
        Ok(())
    }

    fn material(&mut self, desc: &MaterialDesc) -> Result<u32, ParseError> {
        let material = Material {
            emissive: self.channel(&desc.emissive)?,
            ambient: self.channel(&desc.ambient)?,
            specular: self.channel(&desc.specular)?,
            reflective: self.channel(&desc.reflective)?,
            diffuse: self.channel(&desc.diffuse)?,
            transmissive: self.channel(&desc.transmissive)?,
            shininess: self.channel(&desc.shininess)?,
            index: self.channel(&desc.index)?,
            abbe: desc.abbe,
            physical: match &desc.physical {
                Some(p) => Some(p.try_map(|param| self.channel(param))?),
                None => None,
            },
            alpha: match &desc.alpha {
                Some(a) => Some(crate::description::Alpha {
                    coverage: self.channel(&a.coverage)?,
                    cutoff: a.cutoff,
                }),
                None => None,
            },
            metallic_roughness: match &desc.metallic_roughness {
                Some(mr) => Some(mr.try_map(|param| self.channel(param))?),
                None => None,
            },
            normal_map: match &desc.normal_map {
                Some(n) => match self.channel(&Param::Texture(Box::new(n.map.clone())))? {
                    Channel::Texture(id) => Some((id, n.scale)),
                    Channel::Constant(_) => None,
                },
                None => None,
            },
            emitting_faces: desc.emitting_faces,
            absorption: desc.absorption.filter(|a| a.cmpgt(Vec3::ZERO).any()),
            interface: desc.interface.map(|i| crate::medium::Interface {
                inside: medium_side(i.inside),
                outside: medium_side(i.outside),
            }),
            boundary: desc.boundary,
            mix: match &desc.mix {
                Some(m) => Some(crate::material::Mix {
                    materials: [self.material(&m.materials[0])?, self.material(&m.materials[1])?],
                    amount: self.channel(&m.amount)?,
                }),
                None => None,
            },
            clearcoat: desc.clearcoat.filter(|c| c.weight > 0.0),
            clearcoat_maps: match &desc.clearcoat_maps {
                Some(maps) => Some(maps.try_map(|param| self.channel(param))?),
                None => None,
            },
            roughness_map: match &desc.roughness_map {
                Some(r) => Some(crate::description::RoughnessMap {
                    texture: self.channel(&r.texture)?,
                    remap: r.remap,
                }),
                None => None,
            },
        };
        let key = MaterialKey(
            [
                material.emissive,
                material.ambient,
                material.specular,
                material.reflective,
                material.diffuse,
                material.transmissive,
                material.shininess,
                material.index,
            ]
            .iter()
            .flat_map(|c| match c {
                Channel::Constant(v) => [0, v.x.to_bits(), v.y.to_bits(), v.z.to_bits()],
                Channel::Texture(i) => [1, *i, 0, 0],
            })
            .chain([material.abbe.map_or(0, f32::to_bits)])
            .chain(
                format!(
                    "{:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?} {:?}",
                    material.physical,
                    material.normal_map,
                    material.metallic_roughness,
                    material.alpha,
                    material.emitting_faces,
                    material.absorption,
                    material.mix,
                    material.clearcoat,
                    material.clearcoat_maps,
                    material.roughness_map,
                    material.interface,
                    material.boundary
                )
                .bytes()
                .map(u32::from),
            )
            .collect(),
        );
        if let Some(&id) = self.material_ids.get(&key) {
            return Ok(id);
        }
        let id = self.materials.len() as u32;
        self.materials.push(material);
        self.material_ids.insert(key, id);
        Ok(id)
    }

    fn channel(&mut self, param: &Param) -> Result<Channel, ParseError> {
        match param {
            Param::Constant(c) => Ok(Channel::Constant(*c)),
            Param::Checkerboard { even, odd, scale } => {
                let id = self.textures.len() as u32;
                self.textures.push(checkerboard(*even, *odd, *scale));
                Ok(Channel::Texture(id))
            }
            Param::Texture(map) => {
                let source = map.source.name();
                // One texture per image and sampler, one decoded image per file and encoding.
                let key = format!("{source}\u{0}{:?}\u{0}{:?}", map.encoding, map.sampler);
                if let Some(&id) = self.texture_ids.get(&key) {
                    return Ok(Channel::Texture(id));
                }
                let image_key = image_key(map);
                let image = match self.images.get(&image_key) {
                    Some(image) => image.clone(),
                    None => {
                        let image = image_io::load_image(&map.source, map.encoding).map_err(|e| {
                            let reason = match e {
                                Error::Image { message, .. } => message,
                                other => other.to_string(),
                            };
                            ParseError::new(format!("cannot read the texture `{source}`: {reason}"), map.span.clone())
                                .with_help("texture paths are resolved against the scene file's folder; PNG, JPEG, BMP, PPM, TGA, EXR, HDR and PFM are read")
                        })?;
                        let image = std::sync::Arc::new(image);
                        self.images.insert(image_key, image.clone());
                        image
                    }
                };
                let id = self.textures.len() as u32;
                self.textures.push(Texture::sampled(image, map.sampler));
                self.texture_ids.insert(key, id);
                Ok(Channel::Texture(id))
            }
        }
    }
}

/// The analytic shape of an object that is neither a mesh nor a CSG solid.
fn shape_kind(object: &ObjectDesc, settings: &ShapeSettings) -> Result<ShapeKind, ParseError> {
    Ok(match &object.shape {
        ShapeDesc::Sphere => ShapeKind::Sphere,
        ShapeDesc::Box => ShapeKind::Box,
        ShapeDesc::Square => ShapeKind::Square,
        ShapeDesc::Cylinder { capped } => ShapeKind::cylinder(*capped),
        ShapeDesc::Disk { inner } => ShapeKind::Disk {
            inner: inner.clamp(0.0, 0.999),
        },
        ShapeDesc::Cone {
            height,
            bottom_radius,
            top_radius,
            capped,
        } => {
            if !(*height > 0.0 && height.is_finite()) {
                return Err(ParseError::new(
                    format!("a cone needs a positive height, not {height}"),
                    object.span.clone(),
                ));
            }
            ShapeKind::Cone(Cone::new(
                *height,
                *bottom_radius,
                *top_radius,
                *capped,
                settings.cone_quirks,
            ))
        }
        ShapeDesc::Torus {
            major_radius,
            minor_radius,
        } => {
            if !(*major_radius > 0.0 && *minor_radius > 0.0 && major_radius.is_finite() && minor_radius.is_finite()) {
                return Err(ParseError::new(
                    format!("a torus needs positive radii, not {major_radius} and {minor_radius}"),
                    object.span.clone(),
                ));
            }
            ShapeKind::Torus(crate::geometry::torus::Torus {
                major: *major_radius,
                minor: *minor_radius,
            })
        }
        ShapeDesc::Metaballs(desc) => {
            use crate::geometry::metaballs::{Ball, BlobModel, Metaballs};
            let balls = desc
                .balls
                .iter()
                .map(|&(center, radius)| Ball { center, radius })
                .collect();
            let model = match desc.model {
                crate::description::BlobModelDesc::Field { threshold } => BlobModel::Field { threshold },
                crate::description::BlobModelDesc::SmoothUnion { blend } => BlobModel::SmoothUnion { k: blend },
            };
            let metaballs = Metaballs::new(balls, model)
                .ok_or_else(|| ParseError::new("metaballs need balls of positive radius", object.span.clone()))?;
            ShapeKind::Metaballs(std::sync::Arc::new(metaballs))
        }
        ShapeDesc::Trimesh(_) | ShapeDesc::Csg(_) => unreachable!("meshes and CSG solids are built apart"),
    })
}

/// A checkerboard as an image over [0, 1]² (texture lookups clamp there): eight texels a
/// cell, at most 4096 a side, the cell at the origin `even`.
fn checkerboard(even: Vec3, odd: Vec3, scale: glam::Vec2) -> Texture {
    let cells = |s: f32| (s.abs().ceil() as usize).clamp(1, 512);
    let (cu, cv) = (cells(scale.x), cells(scale.y));
    let (w, h) = (cu * 8, cv * 8);
    let texels = (0..h)
        .flat_map(|row| (0..w).map(move |col| (col, row)))
        .map(|(col, row)| {
            // Rows are stored from the top; v grows upwards.
            let u = (col as f32 + 0.5) / w as f32 * scale.x;
            let v = (1.0 - (row as f32 + 0.5) / h as f32) * scale.y;
            if (u.floor() as i64 + v.floor() as i64).rem_euclid(2) == 0 {
                even
            } else {
                odd
            }
        })
        .collect();
    Texture::new(w, h, texels).expect("sizes match")
}

fn singular(span: &Span) -> ParseError {
    ParseError::new(
        "this object's transform is singular (a zero scale or a degenerate matrix)",
        span.clone(),
    )
}

/// A scene of `objects` seen by a camera at (0, 0, 5) looking down −z, for unit tests.
#[cfg(test)]
pub(crate) fn test_scene(objects: &str) -> Scene {
    let text =
        format!("SBT-raytracer 1.0\ncamera {{ position = (0,0,5); viewdir = (0,0,-1); updir = (0,1,0); }}\n{objects}");
    crate::loader::from_text(&text, std::path::Path::new("."), &Default::default()).unwrap()
}

/// A spot light through a glass ball onto a floor, its caustic in view of a camera above, and
/// `objects` beside them, for unit tests of the caustics integrators.
#[cfg(test)]
pub(crate) fn spot_through_glass(objects: &str) -> Scene {
    let text = format!(
        "SBT-raytracer 1.0
camera {{ position = (-2.5, 2.5, 0); viewdir = (1, -1.1, 0); updir = (0, 1, 0); fov = 40; }}
spot_light {{ position = (1.2, 2, 0); direction = (-1.2, -1.5, 0); color = (3, 3, 3); size = 50; blend = 0.3;
  constant_attenuation_coeff = 0; linear_attenuation_coeff = 0; quadratic_attenuation_coeff = 1; }}
translate(0, 0.5, 0, scale(0.5, sphere {{ material = {{ transmissive = (1, 1, 1); index = 1.5; }} }}))
rotate(1, 0, 0, -1.5707963, scale(40, square {{ material = {{ diffuse = (0.6, 0.6, 0.6); }} }}))
{objects}"
    );
    crate::loader::from_text(&text, std::path::Path::new("."), &Default::default()).unwrap()
}

/// A `polymesh` of a bumpy sheet over [−2, 2]², `n`×`n` quads of two triangles each.
#[cfg(test)]
pub(crate) fn bumpy_sheet(n: usize) -> String {
    let mut points = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let (x, y) = (4.0 * i as f32 / n as f32 - 2.0, 4.0 * j as f32 / n as f32 - 2.0);
            points.push(format!("({x},{y},{})", 0.3 * (2.0 * x).sin() * (3.0 * y).cos()));
        }
    }
    let mut faces = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * (n + 1) + i;
            let (b, c, d) = (a + 1, a + n + 2, a + n + 1);
            faces.push(format!("({a},{b},{c}),({a},{c},{d})"));
        }
    }
    format!(
        "polymesh {{ points = ({}); faces = ({}); material = {{ diffuse = (0.5,0.5,0.5); }} }}",
        points.join(","),
        faces.join(",")
    )
}
