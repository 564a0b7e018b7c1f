//! Which face of a pbrt shape is its front, the face a one-sided area light emits from.
//!
//! pbrt names the front by the surface normal: a mesh's given normals (turned round by
//! `ReverseOrientation`), or else the cross product of its edges in world space, and a shape's
//! ∂p/∂u × ∂p/∂v; without given normals the normal is turned round when `ReverseOrientation` or a
//! transform that swaps handedness applies (one of them, not both). caustica names faces by a
//! triangle's winding in world space and a shape's outward normal, so the reader turns triangles
//! and normals round where pbrt's front differs, and says which face of a shape emits.

use crate::description::{EmittingFaces, ShapeDesc, TrimeshDesc};
use glam::{Mat3, Mat4};

/// Puts pbrt's orientation into a shape under `world_from_object`: a mesh's normals turned round
/// under `reverse`, and, for a one-sided light, its triangles wound so that their world normal
/// points out of pbrt's front. Returns the face a one-sided light of this shape emits from.
pub(super) fn orient(shape: &mut ShapeDesc, world_from_object: &Mat4, reverse: bool, one_sided: bool) -> EmittingFaces {
    let swaps = Mat3::from_mat4(*world_from_object).determinant() < 0.0;
    match shape {
        ShapeDesc::Trimesh(mesh) => {
            if reverse {
                if let Some(normals) = &mut mesh.normals {
                    normals.iter_mut().for_each(|n| *n = -*n);
                }
            }
            if one_sided {
                wind_to_front(mesh, world_from_object, reverse ^ swaps);
            }
            EmittingFaces::Front
        }
        _ if reverse ^ swaps => EmittingFaces::Back,
        _ => EmittingFaces::Front,
    }
}

/// Winds each triangle so that its world normal `(b − a) × (c − a)` points out of the front: the
/// side of its vertices' normals where the mesh has them, else the winding's own side, turned
/// round when `turn`.
fn wind_to_front(mesh: &mut TrimeshDesc, world_from_object: &Mat4, turn: bool) {
    let normal_to_world = Mat3::from_mat4(*world_from_object).inverse().transpose();
    let points: Vec<_> = mesh
        .points
        .iter()
        .map(|&p| world_from_object.transform_point3(p))
        .collect();
    for triangle in &mut mesh.triangles {
        let [a, b, c] = triangle.map(|i| points[i as usize]);
        let winding = (b - a).cross(c - a);
        let front = match &mesh.normals {
            Some(normals) => normal_to_world * triangle.iter().map(|&i| normals[i as usize]).sum::<glam::Vec3>(),
            None if turn => -winding,
            None => winding,
        };
        if winding.dot(front) < 0.0 {
            triangle.swap(1, 2);
        }
    }
}
