//! What a `.ray` file says: its dialect and camera as written, and its lights and objects in the
//! format-neutral description's types, into which [`RayScene::into_description`] lowers it.
//!
//! Transforms are already flattened: every object carries its `world_from_object` matrix (the
//! product of the enclosing transforms, outermost first). Materials are already resolved: the
//! current-default inheritance of dialect T and the named materials of both dialects are applied,
//! so each object holds the finished material it will render with.

use crate::description::{CameraDesc, FovAxis, SceneDescription};
pub use crate::description::{LightDesc, MaterialDesc, ObjectDesc, Param, ShapeDesc, TrimeshDesc};
use crate::error::ParseError;
pub use crate::error::Span;
use crate::format::obj::ObjMesh;
use crate::format::{ply, SourceFiles};
use glam::{Quat, Vec3};
use std::path::Path;

/// Which of the two course readers the file was written for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dialect {
    /// The tokenizer-based reader (UT CS 384G 2012–2019, UW CSE 457 2009+), §1–§9.
    Tokenizer,
    /// The older object/dictionary reader (UW ≤ 2008, UT ≤ 2010, HKUST), §10.
    Dictionary,
    /// The dictionary reader as the HKUST COMP 4411 skeleton and its forks use it: a point light
    /// without attenuation coefficients does not fall off (the skeleton reads only its position
    /// and colour), and `texture = "file"` in a material is its diffuse map. Files with
    /// dialect-O markers are read this way unless a dialect is forced.
    Hkust,
}

impl Dialect {
    /// Whether the file is read by the object/dictionary reader (dialect O).
    pub fn is_dictionary(self) -> bool {
        matches!(self, Dialect::Dictionary | Dialect::Hkust)
    }
}

impl std::str::FromStr for Dialect {
    type Err = crate::error::Error;

    fn from_str(s: &str) -> Result<Dialect, Self::Err> {
        match s {
            "tokenizer" => Ok(Dialect::Tokenizer),
            "dictionary" => Ok(Dialect::Dictionary),
            "hkust" => Ok(Dialect::Hkust),
            other => Err(crate::error::Error::InvalidSettings(format!(
                "unknown dialect `{other}`: expected tokenizer, dictionary or hkust"
            ))),
        }
    }
}

/// Everything a `.ray` file describes.
#[derive(Clone, Debug)]
pub struct RayScene {
    /// The dialect that was detected.
    pub dialect: Dialect,
    /// The camera, if the file has one.
    pub camera: Option<RayCamera>,
    /// Point and directional lights, in file order.
    pub lights: Vec<LightDesc>,
    /// Sum of all `ambient_light` colours (Ia).
    pub ambient: Vec3,
    /// Every primitive, in file order, with its world transform and material.
    pub objects: Vec<ObjectDesc>,
    /// Non-fatal remarks (ignored dictionary keys, etc.), each with a span.
    pub warnings: Vec<(String, Span)>,
    /// Meshes named by `file` (a caustica extension), read when the scene is lowered.
    pub mesh_files: Vec<MeshFile>,
    /// Media inside objects and the scene's own (`medium { … }`), caustica extensions.
    pub media: Vec<crate::description::MediumDesc>,
    /// The medium filling the scene (`medium { … }` at the top level).
    pub ambient_medium: Option<usize>,
}

/// A `polymesh { file = "…"; }`: an OBJ or PLY file in place of the mesh's lists.
#[derive(Clone, Debug)]
pub struct MeshFile {
    /// The placeholder object it replaces.
    pub object: usize,
    /// The file, resolved against the scene's folder.
    pub path: std::path::PathBuf,
    /// Where the file is named.
    pub span: Span,
    /// Whether the block gives its own material (otherwise an OBJ's MTL materials apply).
    pub material_given: bool,
}

/// How the camera basis is formed from `viewdir` and `updir`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CameraBasis {
    /// UT skeleton: vectors used as given (not normalised, not orthogonalised).
    AsGiven,
    /// Dialect O: each vector normalised separately, not orthogonalised.
    Normalized,
    /// UW 2013 and `look_at`: orthonormalised.
    Orthonormal,
}

/// The camera block.
#[derive(Clone, Debug)]
pub struct RayCamera {
    /// Eye position (default origin).
    pub position: Vec3,
    /// View direction; `None` means the default orientation (−z) or the quaternion.
    pub viewdir: Option<Vec3>,
    /// Up direction, given together with `viewdir`.
    pub updir: Option<Vec3>,
    /// `look_at` target point (UW), turned into a view direction by the builder.
    pub look_at: Option<Vec3>,
    /// Quaternion (x, y, z, w) applied to the default frame, if given.
    pub quaternion: Option<[f32; 4]>,
    /// Vertical field of view in degrees; `None` gives the skeleton's normalised height 1.
    pub fov_degrees: Option<f32>,
    /// Width / height; `None` means 1.
    pub aspect_ratio: Option<f32>,
    /// How to form the basis.
    pub basis: CameraBasis,
    /// Where the camera block is.
    pub span: Span,
}

impl RayScene {
    /// The format-neutral description of the file; meshes named by `file` are read now, each
    /// added to `files` (their errors point into them).
    pub fn into_description(self, files: &mut SourceFiles, scene_dir: &Path) -> Result<SceneDescription, ParseError> {
        let mut objects = self.objects;
        let mut warnings = self.warnings;
        // From the last, so the earlier placeholders keep their places.
        for mesh in self.mesh_files.iter().rev() {
            let placeholder = objects[mesh.object].clone();
            let is_ply = mesh.path.extension().is_some_and(|e| e.eq_ignore_ascii_case("ply"));
            let replacement = if is_ply {
                let ply = ply::read(files, &mesh.path, &mesh.span)?;
                warnings.extend(ply.warnings);
                let n = ply.points.len();
                let desc = TrimeshDesc {
                    points: ply.points,
                    triangles: ply.triangles,
                    normals: ply.normals.filter(|v| v.len() == n),
                    materials: None,
                    uvs: ply.uvs.filter(|v| v.len() == n),
                    tangents: None,
                };
                vec![ObjectDesc {
                    shape: ShapeDesc::Trimesh(Box::new(desc)),
                    ..placeholder.clone()
                }]
            } else {
                let (base, text, bad) = files.read_text_lossy(&mesh.path, &mesh.span)?;
                let text = text.to_string();
                if let Some(bad) = bad {
                    warnings.push((crate::format::NOT_UTF8.to_string(), bad));
                }
                let dir = mesh.path.parent().unwrap_or(scene_dir).to_path_buf();
                let obj = ObjMesh::parse(files, base, &text, &dir)?;
                warnings.extend(obj.warnings.iter().cloned());
                let material = mesh.material_given.then_some(&placeholder.material);
                obj.objects(
                    placeholder.world_from_object,
                    material,
                    &placeholder.span,
                    &mut warnings,
                )
            };
            objects.splice(mesh.object..mesh.object + 1, replacement);
        }
        Ok(SceneDescription {
            camera: self.camera.as_ref().map(RayCamera::lower),
            lights: self.lights,
            ambient: self.ambient,
            objects,
            warnings,
            hints: Default::default(),
            media: self.media,
            ambient_medium: self.ambient_medium,
            camera_medium: self.ambient_medium,
            ..Default::default()
        })
    }
}

impl RayCamera {
    /// The pinhole this camera block describes (§4). With `viewdir` V and `updir` U the UT
    /// skeleton uses the vectors as given: look = V, u = (U × −V)·h·aspect, v = U·h with
    /// h = 2·tan(fov/2). Non-unit or non-perpendicular vectors therefore change the field of view
    /// or shear the image, exactly as in the course renderer.
    pub fn lower(&self) -> CameraDesc {
        let aspect = self.aspect_ratio.filter(|a| a.is_finite() && *a > 0.0).unwrap_or(1.0);
        let h = self.fov_degrees.map_or(1.0, |fov| 2.0 * (fov.to_radians() * 0.5).tan());
        let (mut view, mut up) = (-Vec3::Z, Vec3::Y);
        if let Some(q) = self.quaternion {
            let rotation = Quat::from_xyzw(q[0], q[1], q[2], q[3]).normalize();
            view = rotation * view;
            up = rotation * up;
        }
        let mut basis = self.basis;
        if let Some(target) = self.look_at {
            view = target - self.position;
            up = self.updir.unwrap_or(if view.cross(Vec3::Y).length_squared() < 1e-12 {
                Vec3::X
            } else {
                Vec3::Y
            });
            basis = CameraBasis::Orthonormal;
        } else if let (Some(v), Some(u)) = (self.viewdir, self.updir) {
            view = v;
            up = u;
        }
        let (view, up) = match basis {
            CameraBasis::AsGiven => (view, up),
            CameraBasis::Normalized => (view.normalize_or_zero(), up.normalize_or_zero()),
            CameraBasis::Orthonormal => {
                let z = -view.normalize_or_zero();
                let x = up.cross(z).normalize_or_zero();
                (-z, z.cross(x))
            }
        };
        CameraDesc {
            position: self.position,
            view,
            up,
            height: h,
            aspect_ratio: aspect,
            right: None,
            fov_axis: FovAxis::Vertical,
            lens: None,
            span: self.span.clone(),
        }
    }
}
