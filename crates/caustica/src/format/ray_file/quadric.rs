//! Quadric surfaces of the course forks, read as triangle meshes:
//!
//! - `quadric { points = ((A, B), (C, D), (E, F), (G, H), (I, J)); }` (UT 2019,
//!   michaelasper/ray-tracer): Ax² + By² + Cz² + Dxy + Exz + Fyz + Gx + Hy + Iz + J = 0, the ten
//!   coefficients written as five pairs; without `points`, that fork's −x² + y² + z² = 1;
//! - `hyperboloid` (x² + y² − z² = 1), `hyperbolic_paraboloid` (z = x² − y²) and `paraboloid`
//!   (z = x² + y²), HKUST 2017 (snowboat/RayTracingS17).
//!
//! The forks intersect the unbounded surface but give it the bounding box [-1, 1]³; the part
//! inside that cube is what is kept. caustica has no quadric primitive, so the surface is cut
//! into tetrahedra on a grid (marching tetrahedra): every vertex lies exactly on the surface
//! (the quadric is solved along each grid edge) and its normal is the surface's gradient, so
//! shading is smooth and only silhouettes show the grid.

use super::ast::TrimeshDesc;
use glam::DVec3;
use std::collections::HashMap;

/// Coefficients A..J of Ax² + By² + Cz² + Dxy + Exz + Fyz + Gx + Hy + Iz + J.
pub(crate) type Coefficients = [f64; 10];

/// x² + y² − z² − 1.
pub(crate) const HYPERBOLOID: Coefficients = [1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];
/// x² − y² − z.
pub(crate) const HYPERBOLIC_PARABOLOID: Coefficients = [1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0];
/// x² + y² − z.
pub(crate) const PARABOLOID: Coefficients = [1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0];
/// The UT 2019 fork's `quadric` without coefficients: −x² + y² + z² − 1.
pub(crate) const QUADRIC_DEFAULT: Coefficients = [-1.0, 1.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0];

/// Grid cells along each axis of the cube: about 10⁴ triangles for a surface crossing it.
const CELLS: usize = 48;

/// The built-in surface a keyword names, if it names one.
pub(crate) fn named(keyword: &str) -> Option<Coefficients> {
    match keyword {
        "hyperboloid" => Some(HYPERBOLOID),
        "hyperbolic_paraboloid" => Some(HYPERBOLIC_PARABOLOID),
        "paraboloid" => Some(PARABOLOID),
        "quadric" => Some(QUADRIC_DEFAULT),
        _ => None,
    }
}

fn value(q: &Coefficients, p: DVec3) -> f64 {
    q[0] * p.x * p.x
        + q[1] * p.y * p.y
        + q[2] * p.z * p.z
        + q[3] * p.x * p.y
        + q[4] * p.x * p.z
        + q[5] * p.y * p.z
        + q[6] * p.x
        + q[7] * p.y
        + q[8] * p.z
        + q[9]
}

/// The second-order part alone (the t² coefficient along a segment of direction `d`).
fn quadratic_part(q: &Coefficients, d: DVec3) -> f64 {
    q[0] * d.x * d.x + q[1] * d.y * d.y + q[2] * d.z * d.z + q[3] * d.x * d.y + q[4] * d.x * d.z + q[5] * d.y * d.z
}

fn gradient(q: &Coefficients, p: DVec3) -> DVec3 {
    DVec3::new(
        2.0 * q[0] * p.x + q[3] * p.y + q[4] * p.z + q[6],
        2.0 * q[1] * p.y + q[3] * p.x + q[5] * p.z + q[7],
        2.0 * q[2] * p.z + q[4] * p.x + q[5] * p.y + q[8],
    )
}

/// Where the surface crosses the segment from `a` (value `fa`) to `b` (value `fb`), whose
/// values have opposite signs, as a fraction of the way: the root of the quadratic along it
/// that lies on the segment.
fn crossing(q: &Coefficients, a: DVec3, b: DVec3, fa: f64, fb: f64) -> f64 {
    let d = b - a;
    let (qa, qb, qc) = (quadratic_part(q, d), gradient(q, a).dot(d), fa);
    let linear = fa / (fa - fb);
    let t = if qa.abs() <= 1e-12 * (qb.abs() + qc.abs()).max(1e-300) {
        -qc / qb
    } else {
        let disc = (qb * qb - 4.0 * qa * qc).max(0.0).sqrt();
        // The numerically stable pair of roots; the one on the segment nearest the linear guess.
        let s = -0.5 * (qb + qb.signum() * disc);
        let roots = [s / qa, if s != 0.0 { qc / s } else { f64::NAN }];
        roots
            .into_iter()
            .filter(|t| (-1e-9..=1.0 + 1e-9).contains(t))
            .min_by(|x, y| (x - linear).abs().total_cmp(&(y - linear).abs()))
            .unwrap_or(linear)
    };
    if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        linear
    }
}

/// Crossings this close to a grid point (as a fraction of the edge) are moved onto it, so
/// the triangles around a grid point on the surface share one vertex instead of slivers.
const SNAP: f64 = 1e-4;

/// The part of the quadric inside [-1, 1]³ as a mesh, or `None` when none of it is there.
pub(crate) fn tessellate(q: &Coefficients) -> Option<TrimeshDesc> {
    let n = CELLS;
    let side = n + 1;
    let at = |i: usize, j: usize, k: usize| DVec3::new(i as f64, j as f64, k as f64) * (2.0 / n as f64) - 1.0;
    let index = |i: usize, j: usize, k: usize| (k * side + j) * side + i;
    let mut values = vec![0.0f64; side * side * side];
    for k in 0..side {
        for j in 0..side {
            for i in 0..side {
                values[index(i, j, k)] = value(q, at(i, j, k));
            }
        }
    }
    let mut mesh = Builder {
        q,
        points: Vec::new(),
        gradients: Vec::new(),
        by_edge: HashMap::new(),
        triangles: Vec::new(),
        min_area2: (1e-8 * (2.0 / n as f64).powi(2)).powi(2),
    };
    // Six tetrahedra around the cube's diagonal from corner 0 to corner 7 (bit 1: +x, 2: +y,
    // 4: +z); neighbouring cubes split their shared faces alike, so the surface has no cracks.
    const TETS: [[usize; 4]; 6] = [
        [0, 1, 3, 7],
        [0, 3, 2, 7],
        [0, 2, 6, 7],
        [0, 6, 4, 7],
        [0, 4, 5, 7],
        [0, 5, 1, 7],
    ];
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let corner = |c: usize| (i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1));
                let ids: [usize; 8] = std::array::from_fn(|c| {
                    let (x, y, z) = corner(c);
                    index(x, y, z)
                });
                let signs: Vec<bool> = ids.iter().map(|&id| values[id] < 0.0).collect();
                if signs.iter().all(|&s| s) || signs.iter().all(|&s| !s) {
                    continue;
                }
                for tet in TETS {
                    let v: [(usize, DVec3, f64); 4] = std::array::from_fn(|c| {
                        let (x, y, z) = corner(tet[c]);
                        (ids[tet[c]], at(x, y, z), values[ids[tet[c]]])
                    });
                    mesh.tetrahedron(v);
                }
            }
        }
    }
    mesh.finish()
}

struct Builder<'q> {
    q: &'q Coefficients,
    points: Vec<DVec3>,
    gradients: Vec<DVec3>,
    /// The vertex made on each grid edge (or at a grid point: `(point, usize::MAX)`), so
    /// neighbouring triangles share it.
    by_edge: HashMap<(usize, usize), u32>,
    /// Triangles smaller than this (twice the area, squared) are left out.
    min_area2: f64,
    triangles: Vec<[u32; 3]>,
}

impl Builder<'_> {
    fn vertex(&mut self, a: (usize, DVec3, f64), b: (usize, DVec3, f64)) -> u32 {
        let edge = (a.0.min(b.0), a.0.max(b.0));
        if let Some(&v) = self.by_edge.get(&edge) {
            return v;
        }
        // Always solve from the lower grid index, so both tetrahedra get the same point.
        let (a, b) = if a.0 <= b.0 { (a, b) } else { (b, a) };
        let t = crossing(self.q, a.1, b.1, a.2, b.2);
        let (key, p) = if t < SNAP {
            ((a.0, usize::MAX), a.1)
        } else if t > 1.0 - SNAP {
            ((b.0, usize::MAX), b.1)
        } else {
            (edge, a.1 + (b.1 - a.1) * t)
        };
        if let Some(&v) = self.by_edge.get(&key) {
            self.by_edge.insert(edge, v);
            return v;
        }
        self.points.push(p);
        self.gradients.push(gradient(self.q, p));
        let v = (self.points.len() - 1) as u32;
        self.by_edge.insert(key, v);
        self.by_edge.insert(edge, v);
        v
    }

    fn tetrahedron(&mut self, v: [(usize, DVec3, f64); 4]) {
        let inside: Vec<usize> = (0..4).filter(|&c| v[c].2 < 0.0).collect();
        let outside: Vec<usize> = (0..4).filter(|&c| v[c].2 >= 0.0).collect();
        match (inside.as_slice(), outside.as_slice()) {
            ([a], [b, c, d]) | ([b, c, d], [a]) => {
                let t = [
                    self.vertex(v[*a], v[*b]),
                    self.vertex(v[*a], v[*c]),
                    self.vertex(v[*a], v[*d]),
                ];
                self.triangle(t);
            }
            ([a, b], [c, d]) => {
                let (ac, ad) = (self.vertex(v[*a], v[*c]), self.vertex(v[*a], v[*d]));
                let (bd, bc) = (self.vertex(v[*b], v[*d]), self.vertex(v[*b], v[*c]));
                self.triangle([ac, ad, bd]);
                self.triangle([ac, bd, bc]);
            }
            _ => {}
        }
    }

    /// Adds a triangle facing the way the gradient points (out of the region where f < 0);
    /// triangles of no area (at grid points on the surface) are left out.
    fn triangle(&mut self, mut t: [u32; 3]) {
        let [p0, p1, p2] = t.map(|i| self.points[i as usize]);
        let n = (p1 - p0).cross(p2 - p0);
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || n.length_squared() <= self.min_area2 {
            return;
        }
        let g: DVec3 = t.iter().map(|&i| self.gradients[i as usize]).sum();
        if n.dot(g) < 0.0 {
            t.swap(1, 2);
        }
        self.triangles.push(t);
    }

    fn finish(self) -> Option<TrimeshDesc> {
        if self.triangles.is_empty() {
            return None;
        }
        // Where the gradient vanishes (a cone's apex) the faces around the vertex give its normal.
        let mut fallback = vec![DVec3::ZERO; self.points.len()];
        for t in &self.triangles {
            let [p0, p1, p2] = t.map(|i| self.points[i as usize]);
            let n = (p1 - p0).cross(p2 - p0);
            for &i in t {
                fallback[i as usize] += n;
            }
        }
        let normals = self
            .gradients
            .iter()
            .zip(&fallback)
            .map(|(g, f)| {
                let n = if g.length_squared() > 1e-18 { *g } else { *f };
                n.try_normalize().unwrap_or(DVec3::Z).as_vec3()
            })
            .collect();
        Some(TrimeshDesc {
            points: self.points.iter().map(|p| p.as_vec3()).collect(),
            triangles: self.triangles,
            normals: Some(normals),
            materials: None,
            uvs: None,
            tangents: None,
        })
    }
}

/// The coefficients of a `quadric`'s `points` list: five pairs, read in order as A..J.
pub(crate) fn from_pairs(pairs: &[[f32; 2]]) -> Option<Coefficients> {
    (pairs.len() == 5).then(|| std::array::from_fn(|i| pairs[i / 2][i % 2] as f64))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn check_on_surface(q: &Coefficients, mesh: &TrimeshDesc) {
        for (p, n) in mesh.points.iter().zip(mesh.normals.as_ref().unwrap()) {
            let p = p.as_dvec3();
            assert!(value(q, p).abs() < 1e-4, "{p} is off the surface: {}", value(q, p));
            assert!(p.abs().max_element() <= 1.0 + 1e-6, "{p} is outside the cube");
            assert!((n.length() - 1.0).abs() < 1e-4);
        }
    }

    /// A sphere of radius 0.9 written as a quadric: its mesh lies on it, closes up (every edge
    /// shared by two triangles) and faces outwards.
    #[test]
    fn a_sphere_quadric_is_a_closed_outward_mesh_on_the_sphere() {
        let q = from_pairs(&[[1.0, 1.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, -0.81]]).unwrap();
        let mesh = tessellate(&q).expect("a surface");
        check_on_surface(&q, &mesh);
        let mut edges: HashMap<(u32, u32), i32> = HashMap::new();
        for t in &mesh.triangles {
            for e in 0..3 {
                let (a, b) = (t[e], t[(e + 1) % 3]);
                *edges.entry((a.min(b), a.max(b))).or_default() += 1;
            }
            let [p0, p1, p2] = t.map(|i| mesh.points[i as usize]);
            let face = (p1 - p0).cross(p2 - p0);
            assert!(face.dot(p0 + p1 + p2) > 0.0, "a triangle faces inwards");
        }
        assert!(edges.values().all(|&c| c == 2), "the mesh has a crack");
        // Its area is close to 4π·0.81.
        let area: f32 = mesh
            .triangles
            .iter()
            .map(|t| {
                let [p0, p1, p2] = t.map(|i| mesh.points[i as usize]);
                0.5 * (p1 - p0).cross(p2 - p0).length()
            })
            .sum();
        let exact = 4.0 * std::f32::consts::PI * 0.81;
        assert!((area - exact).abs() < 0.01 * exact, "area {area}, not {exact}");
    }

    #[test]
    fn the_named_surfaces_are_cut_to_the_cube() {
        for name in ["hyperboloid", "hyperbolic_paraboloid", "paraboloid", "quadric"] {
            let q = named(name).unwrap();
            let mesh = tessellate(&q).unwrap_or_else(|| panic!("{name} is empty"));
            check_on_surface(&q, &mesh);
            assert!(mesh.triangles.len() > 1000, "{name}: {}", mesh.triangles.len());
        }
        // The saddle spans the whole cube in x and y.
        let mesh = tessellate(&HYPERBOLIC_PARABOLOID).unwrap();
        let max = mesh.points.iter().fold(Vec3::splat(-2.0), |m, p| m.max(*p));
        assert!(max.x > 0.99 && max.y > 0.99, "{max}");
    }

    #[test]
    fn a_quadric_outside_the_cube_has_no_mesh() {
        // x² + y² + z² = 16: a sphere of radius 4 around the cube.
        let q = from_pairs(&[[1.0, 1.0], [1.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, -16.0]]).unwrap();
        assert!(tessellate(&q).is_none());
        assert!(from_pairs(&[[1.0, 1.0]]).is_none());
    }
}
