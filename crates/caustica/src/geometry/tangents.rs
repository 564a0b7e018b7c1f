//! Tangent frames for normal maps: per-vertex tangents generated from a mesh's texture
//! coordinates where the file gives none, and the shading normal a normal-map texel bends.

use crate::math::{Vec2, Vec3, Vec4};

/// Per-vertex tangents of a mesh: the direction of increasing u in each triangle (∂p/∂u),
/// averaged over the triangles at a vertex weighted by area and made perpendicular to the
/// vertex normal, with w the sign that makes `normal × tangent · w` point along increasing v.
/// Vertices of no usable triangle get some perpendicular and w = 1.
pub fn generate(points: &[Vec3], indices: &[[u32; 3]], uvs: &[Vec2], normals: Option<&[Vec3]>) -> Vec<Vec4> {
    let mut along_u = vec![Vec3::ZERO; points.len()];
    let mut along_v = vec![Vec3::ZERO; points.len()];
    let mut face_normals = vec![Vec3::ZERO; points.len()];
    for tri in indices {
        let [a, b, c] = tri.map(|i| i as usize);
        let (e1, e2) = (points[b] - points[a], points[c] - points[a]);
        let (d1, d2) = (uvs[b] - uvs[a], uvs[c] - uvs[a]);
        let det = d1.x * d2.y - d2.x * d1.y;
        let cross = e1.cross(e2);
        let area = cross.length();
        if det.abs() < 1e-20 || area <= 0.0 || area.is_nan() {
            continue;
        }
        let du = ((e1 * d2.y - e2 * d1.y) / det).normalize_or_zero() * area;
        let dv = ((e2 * d1.x - e1 * d2.x) / det).normalize_or_zero() * area;
        for v in [a, b, c] {
            along_u[v] += du;
            along_v[v] += dv;
            face_normals[v] += cross;
        }
    }
    (0..points.len())
        .map(|v| {
            let n = normals.map_or(face_normals[v], |ns| ns[v]).normalize_or_zero();
            let mut t = (along_u[v] - n * n.dot(along_u[v])).normalize_or_zero();
            if t == Vec3::ZERO {
                t = n.any_orthonormal_vector();
            }
            let w = if n.cross(t).dot(along_v[v]) < 0.0 { -1.0 } else { 1.0 };
            t.extend(w)
        })
        .collect()
}

/// The shading normal a tangent-space normal-map `texel` gives at a point of interpolated
/// normal `n`, geometric normal `ng` and tangent `tangent` (bitangent `n × tangent · sign`):
/// the texel's [0, 1] mapped to [−1, 1], x and y times `scale`. A bent normal on the other
/// side of the surface than `n` would leak light through it, so `n` is kept there.
pub fn bend(n: Vec3, ng: Vec3, tangent: Vec3, sign: f32, texel: Vec3, scale: f32) -> Vec3 {
    let t = (tangent - n * n.dot(tangent)).normalize_or_zero();
    if t == Vec3::ZERO {
        return n;
    }
    let b = n.cross(t) * sign;
    let m = texel * 2.0 - Vec3::ONE;
    let bent = (t * (m.x * scale) + b * (m.y * scale) + n * m.z).normalize_or_zero();
    if bent.dot(ng) * n.dot(ng) <= 0.0 || !bent.is_finite() {
        n
    } else {
        bent
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quad in z = 0 whose u runs along +x and v along +y: tangent +x, bitangent +y; with u
    /// mirrored the tangent turns to −x and the sign keeps the bitangent +y.
    #[test]
    fn tangents_follow_u_and_the_sign_follows_v() {
        let points = [Vec3::ZERO, Vec3::X, Vec3::new(1.0, 1.0, 0.0), Vec3::Y];
        let indices = [[0, 1, 2], [0, 2, 3]];
        let uvs = [Vec2::ZERO, Vec2::X, Vec2::ONE, Vec2::Y];
        for t in generate(&points, &indices, &uvs, None) {
            assert!((t - Vec4::new(1.0, 0.0, 0.0, 1.0)).length() < 1e-6, "{t}");
        }
        let mirrored = uvs.map(|uv| Vec2::new(1.0 - uv.x, uv.y));
        for t in generate(&points, &indices, &mirrored, None) {
            assert!((t.truncate() + Vec3::X).length() < 1e-6, "{t}");
            assert!((Vec3::Z.cross(t.truncate()) * t.w - Vec3::Y).length() < 1e-6);
        }
    }

    /// A texel of (0.5, 0.5, 1) is the unbent normal; (1, 0.5, 0.75) at scale 1 leans towards
    /// the tangent; a bend into the surface's plane or through it keeps the normal.
    #[test]
    fn texels_bend_the_normal_in_the_tangent_frame() {
        let (n, t) = (Vec3::Z, Vec3::X);
        assert!((bend(n, n, t, 1.0, Vec3::new(0.5, 0.5, 1.0), 1.0) - n).length() < 1e-6);
        let lean = Vec3::new(2.0, 0.0, 1.0).normalize();
        assert!((bend(n, n, t, 1.0, Vec3::new(1.0, 0.5, 0.75), 1.0) - lean).length() < 1e-6);
        let down = Vec3::new(0.0, -2.0, 1.0).normalize();
        assert!((bend(n, n, t, -1.0, Vec3::new(0.5, 1.0, 0.75), 1.0) - down).length() < 1e-6);
        assert_eq!(bend(n, n, t, 1.0, Vec3::new(1.0, 0.5, 0.5), 1.0), n);
        let half = bend(n, n, t, 1.0, Vec3::new(1.0, 0.5, 1.0), 0.5);
        assert!((half - Vec3::new(0.5, 0.0, 1.0).normalize()).length() < 1e-6, "{half}");
        assert_eq!(bend(n, n, t, 1.0, Vec3::new(0.5, 0.5, 0.0), 1.0), n);
    }
}
