//! Turning the lists of a `trimesh`/`polymesh` block into a checked triangle mesh (both dialects).

use super::ast::{MaterialDesc, Span, TrimeshDesc};
use crate::ParseError;
use glam::{Vec2, Vec3};
use std::ops::Range;

/// The raw lists of a mesh block, as written.
#[derive(Debug, Default)]
pub(crate) struct MeshInput {
    /// `points`.
    pub points: Vec<Vec3>,
    /// All face indices, as written (not yet truncated).
    pub face_indices: Vec<f64>,
    /// Each face: its range in `face_indices` and where it is written.
    pub faces: Vec<(Range<usize>, Span)>,
    /// `normals`, with the span of the list.
    pub normals: Option<(Vec<Vec3>, Span)>,
    /// `materials`, with the span of the list.
    pub materials: Option<(Vec<MaterialDesc>, Span)>,
    /// UW `texture_uv`, with the span of the list.
    pub uvs: Option<(Vec<Vec2>, Span)>,
    /// `gennormals` was given.
    pub gennormals: bool,
}

/// Validates and triangulates a mesh; `Ok(None)` when no triangle is left (with a warning).
pub(crate) fn finish(
    input: MeshInput,
    span: &Span,
    warnings: &mut Vec<(String, Span)>,
) -> Result<Option<TrimeshDesc>, ParseError> {
    let count = input.points.len();
    for (what, len, list_span) in [
        ("normals", input.normals.as_ref().map(|(v, s)| (v.len(), s))),
        ("materials", input.materials.as_ref().map(|(v, s)| (v.len(), s))),
        ("texture_uv", input.uvs.as_ref().map(|(v, s)| (v.len(), s))),
    ]
    .into_iter()
    .filter_map(|(what, found)| found.map(|(len, s)| (what, len, s)))
    {
        if len != count {
            return Err(ParseError::new(
                format!("the mesh has {count} points but {len} {what}; give exactly one per point"),
                list_span.clone(),
            ));
        }
    }

    let mut triangles = Vec::new();
    let mut degenerate = 0usize;
    let mut first_degenerate: Option<Span> = None;
    for (face_number, (range, face_span)) in input.faces.iter().enumerate() {
        let written = &input.face_indices[range.clone()];
        if written.len() < 3 {
            return Err(ParseError::new(
                format!(
                    "face {face_number} has {} indices; a face needs at least 3",
                    written.len()
                ),
                face_span.clone(),
            ));
        }
        let mut indices = Vec::with_capacity(written.len());
        for &value in written {
            // The course readers truncate indices towards zero.
            let index = value.trunc();
            if index < 0.0 || index >= count as f64 {
                return Err(ParseError::new(
                    format!("face {face_number} uses vertex {index} but the mesh has {count} points"),
                    face_span.clone(),
                ));
            }
            indices.push(index as u32);
        }
        for k in 1..indices.len() - 1 {
            let tri = [indices[0], indices[k], indices[k + 1]];
            let [a, b, c] = tri.map(|i| input.points[i as usize]);
            if (b - a).cross(c - a).length_squared() > 0.0 {
                triangles.push(tri);
            } else {
                degenerate += 1;
                first_degenerate.get_or_insert_with(|| face_span.clone());
            }
        }
    }
    if let Some(first) = first_degenerate {
        warnings.push((
            format!("dropped {degenerate} degenerate (zero-area) triangle(s) of this mesh"),
            first,
        ));
    }
    if triangles.is_empty() {
        warnings.push((
            "the mesh has no triangles with non-zero area; it is left out".to_string(),
            span.clone(),
        ));
        return Ok(None);
    }

    let normals = if input.gennormals {
        Some(generate_normals(&input.points, &triangles))
    } else {
        input.normals.map(|(n, _)| n)
    };
    Ok(Some(TrimeshDesc {
        points: input.points,
        triangles,
        normals,
        materials: input.materials.map(|(m, _)| m),
        uvs: input.uvs.map(|(u, _)| u),
        tangents: None,
    }))
}

/// Per-vertex normals: the normalised average of the unit normals of the triangles using the vertex.
///
/// A vertex that no triangle uses gets a zero normal; it is never shaded.
fn generate_normals(points: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; points.len()];
    for tri in triangles {
        let [a, b, c] = tri.map(|i| points[i as usize]);
        let n = (b - a).cross(c - a).normalize_or_zero();
        for &i in tri {
            sums[i as usize] += n;
        }
    }
    sums.into_iter().map(Vec3::normalize_or_zero).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> MeshInput {
        MeshInput {
            points: vec![
                Vec3::new(0.0, 0.0, 0.0),
                Vec3::new(1.0, 0.0, 0.0),
                Vec3::new(1.0, 1.0, 0.0),
                Vec3::new(0.0, 1.0, 0.0),
            ],
            face_indices: vec![0.0, 1.0, 2.9, 3.0],
            faces: vec![(0..4, 10..20)],
            ..MeshInput::default()
        }
    }

    #[test]
    fn polygons_are_fan_triangulated_with_truncated_indices() {
        let mut warnings = Vec::new();
        let mesh = finish(square(), &(0..1), &mut warnings).expect("valid").expect("kept");
        assert_eq!(mesh.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(warnings.is_empty());
    }

    #[test]
    fn out_of_range_index_names_face_and_count() {
        let mut input = square();
        input.face_indices.extend([0.0, 1.0, 40.0]);
        input.faces.push((4..7, 30..40));
        let err = finish(input, &(0..1), &mut Vec::new()).expect_err("bad index");
        assert_eq!(err.message, "face 1 uses vertex 40 but the mesh has 4 points");
        assert_eq!(err.span, 30..40);
        let mut input = square();
        input.face_indices[0] = -1.0;
        assert!(finish(input, &(0..1), &mut Vec::new()).is_err());
    }

    #[test]
    fn short_faces_and_wrong_counts_are_errors() {
        let mut input = square();
        input.faces = vec![(0..2, 5..9)];
        assert_eq!(finish(input, &(0..1), &mut Vec::new()).expect_err("short").span, 5..9);
        let mut input = square();
        input.normals = Some((vec![Vec3::Z; 3], 50..60));
        let err = finish(input, &(0..1), &mut Vec::new()).expect_err("count");
        assert_eq!(err.span, 50..60);
        assert!(err.message.contains("3 normals"));
    }

    #[test]
    fn degenerate_triangles_are_dropped_and_empty_meshes_left_out() {
        let mut input = square();
        input.face_indices.extend([0.0, 0.0, 1.0]);
        input.faces.push((4..7, 30..40));
        let mut warnings = Vec::new();
        let mesh = finish(input, &(0..1), &mut warnings).expect("valid").expect("kept");
        assert_eq!(mesh.triangles.len(), 2);
        assert_eq!(warnings.len(), 1);
        assert_eq!(warnings[0].1, 30..40);

        let mut input = square();
        input.face_indices = vec![0.0, 1.0, 1.0];
        input.faces = vec![(0..3, 0..5)];
        let mut warnings = Vec::new();
        assert!(finish(input, &(7..8), &mut warnings).expect("valid").is_none());
        assert_eq!(warnings.len(), 2);
        assert_eq!(warnings[1].1, 7..8);
    }

    #[test]
    fn generated_normals_average_unit_face_normals() {
        // Two faces meeting at a right angle along the x axis.
        let mut input = MeshInput {
            points: vec![Vec3::ZERO, Vec3::X, Vec3::new(0.0, 5.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
            face_indices: vec![0.0, 1.0, 2.0, 0.0, 3.0, 1.0],
            faces: vec![(0..3, 0..1), (3..6, 1..2)],
            ..MeshInput::default()
        };
        input.gennormals = true;
        let mesh = finish(input, &(0..1), &mut Vec::new()).expect("valid").expect("kept");
        let normals = mesh.normals.expect("generated");
        let expected = Vec3::new(0.0, 1.0, 1.0).normalize();
        assert!((normals[0] - expected).length() < 1e-6, "{}", normals[0]);
        assert!((normals[2] - Vec3::Z).length() < 1e-6);
    }
}
