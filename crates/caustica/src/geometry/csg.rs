//! Constructive solid geometry: union, intersection and difference of closed shapes, each with
//! its own transform and material.
//!
//! A ray is followed through every operand: each leaf lists all its crossings along the ray
//! (to infinity, so the parity of its crossings tells whether the ray starts inside it), and an
//! operation walks the merged crossings of its two operands in order, keeping both operands'
//! inside/outside state; wherever the combined state changes the ray crosses the result's
//! surface. There the normal is the operand's outward normal, turned around for the part
//! subtracted in a difference (its inside becomes the result's outside), and the material is
//! the leaf's own. The camera, the shadow rays and the photons all ask this same question, so
//! they all see the same surface.

use super::shape::{Shape, ShapeKind};
use crate::math::{Aabb, Ray, Vec2, Vec3};

/// The three operations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOp {
    /// Inside either.
    Union,
    /// Inside both.
    Intersection,
    /// Inside the first and not the second.
    Difference,
}

impl CsgOp {
    fn combine(self, a: bool, b: bool) -> bool {
        match self {
            CsgOp::Union => a || b,
            CsgOp::Intersection => a && b,
            CsgOp::Difference => a && !b,
        }
    }
}

/// A node of the tree.
// Leaves keep their shape inline (no pointer to follow per leaf test); trees are small.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Debug)]
pub enum CsgNode {
    /// A closed shape with its material id; leaves are numbered in order (the hit's `part`).
    Leaf {
        /// The shape, placed in the world (boxed: a shape is much larger than an operation).
        shape: Box<Shape>,
        /// Its material id.
        material: u32,
    },
    /// An operation on two operands.
    Op {
        /// Which.
        op: CsgOp,
        /// First operand.
        a: Box<CsgNode>,
        /// Second operand.
        b: Box<CsgNode>,
    },
}

/// A crossing of a node's surface along a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Crossing {
    /// Ray parameter.
    pub t: f32,
    /// Unit outward normal of the node's solid there.
    pub normal: Vec3,
    /// Texture coordinates of the leaf.
    pub uv: Vec2,
    /// The leaf crossed.
    pub part: u32,
}

/// A CSG solid in world space.
#[derive(Clone, Debug)]
pub struct Csg {
    root: CsgNode,
    materials: Vec<u32>,
    bounds: Aabb,
}

/// Two solids are the same only if they are one (shapes compare kinds; trees are not compared).
impl PartialEq for Csg {
    fn eq(&self, other: &Csg) -> bool {
        std::ptr::eq(self, other)
    }
}

/// Crossings of one closed leaf looked for along a ray.
const MAX_LEAF_CROSSINGS: usize = 16;

/// Whether a shape bounds a volume (CSG needs closed solids).
pub fn is_closed(kind: &ShapeKind) -> bool {
    match kind {
        ShapeKind::Sphere | ShapeKind::Box | ShapeKind::Torus(_) | ShapeKind::Metaballs(_) | ShapeKind::Csg(_) => true,
        ShapeKind::Cone(cone) => cone.capped,
        ShapeKind::Square | ShapeKind::Disk { .. } => false,
    }
}

impl Csg {
    /// The solid of `root`; `None` if a leaf is not closed.
    pub fn new(root: CsgNode) -> Option<Csg> {
        let mut materials = Vec::new();
        if !collect(&root, &mut materials) {
            return None;
        }
        let bounds = node_bounds(&root);
        Some(Csg {
            root,
            materials,
            bounds,
        })
    }

    /// World bounds.
    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The material id of each leaf (`part`).
    pub fn materials(&self) -> &[u32] {
        &self.materials
    }

    /// Whether the surface may come within world distance `r` of `point`: it lies on the
    /// leaves' surfaces, so only if one of them may.
    pub fn may_come_within(&self, point: Vec3, r: f32) -> bool {
        let mut any = false;
        visit_leaves(&self.root, &mut |shape: &Shape| any |= shape.may_come_within(point, r));
        any
    }

    /// The nearest crossing of the solid's surface in `(0, t_max)` along the world ray.
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Crossing> {
        self.bounds.intersect(ray.origin, ray.dir.recip(), 0.0, t_max)?;
        let mut next_part = 0;
        let (_, crossings) = node_crossings(&self.root, ray, &mut next_part);
        crossings.into_iter().find(|c| c.t > 0.0 && c.t < t_max)
    }
}

/// Leaf materials in order; false if a leaf is not closed.
fn collect(node: &CsgNode, materials: &mut Vec<u32>) -> bool {
    match node {
        CsgNode::Leaf { shape, material } => {
            materials.push(*material);
            is_closed(&shape.kind)
        }
        CsgNode::Op { a, b, .. } => collect(a, materials) && collect(b, materials),
    }
}

fn visit_leaves(node: &CsgNode, f: &mut impl FnMut(&Shape)) {
    match node {
        CsgNode::Leaf { shape, .. } => f(shape),
        CsgNode::Op { a, b, .. } => {
            visit_leaves(a, f);
            visit_leaves(b, f);
        }
    }
}

fn node_bounds(node: &CsgNode) -> Aabb {
    match node {
        CsgNode::Leaf { shape, .. } => shape.bounds,
        CsgNode::Op { op, a, b } => {
            let (ba, bb) = (node_bounds(a), node_bounds(b));
            match op {
                CsgOp::Union => ba.union(bb),
                CsgOp::Intersection => Aabb {
                    min: ba.min.max(bb.min),
                    max: ba.max.min(bb.max),
                },
                CsgOp::Difference => ba,
            }
        }
    }
}

/// Whether the ray starts inside the node, and its crossings of the node's surface in
/// (0, ∞), ascending; `next_part` numbers the leaves met.
fn node_crossings(node: &CsgNode, ray: &Ray, next_part: &mut u32) -> (bool, Vec<Crossing>) {
    match node {
        CsgNode::Leaf { shape, .. } => {
            let part = *next_part;
            *next_part += 1;
            let crossings = leaf_crossings(shape, ray, part);
            // A closed surface's first crossing leaves the solid if the ray starts inside it.
            let inside = crossings.first().is_some_and(|c| c.normal.dot(ray.dir) > 0.0);
            (inside, crossings)
        }
        CsgNode::Op { op, a, b } => {
            let (mut in_a, ca) = node_crossings(a, ray, next_part);
            let (mut in_b, cb) = node_crossings(b, ray, next_part);
            let start = op.combine(in_a, in_b);
            let mut inside = start;
            let mut out = Vec::new();
            let (mut i, mut j) = (0, 0);
            while i < ca.len() || j < cb.len() {
                let from_a = j >= cb.len() || (i < ca.len() && ca[i].t <= cb[j].t);
                let mut c = if from_a {
                    in_a = !in_a;
                    i += 1;
                    ca[i - 1]
                } else {
                    in_b = !in_b;
                    j += 1;
                    cb[j - 1]
                };
                let now = op.combine(in_a, in_b);
                if now != inside {
                    if !from_a && *op == CsgOp::Difference {
                        c.normal = -c.normal;
                    }
                    out.push(c);
                    inside = now;
                }
            }
            (start, out)
        }
    }
}

/// Every crossing of a closed leaf along the ray, found by restarting past each hit.
fn leaf_crossings(shape: &Shape, ray: &Ray, part: u32) -> Vec<Crossing> {
    let mut out = Vec::new();
    let mut t0 = 0.0f32;
    while out.len() < MAX_LEAF_CROSSINGS {
        let origin = ray.at(t0);
        let Some(hit) = shape.intersect(&Ray::new(origin, ray.dir), f32::INFINITY) else {
            break;
        };
        let t = t0 + hit.t;
        out.push(Crossing {
            t,
            normal: hit.normal,
            uv: hit.uv,
            part: hit.part + part,
        });
        // Restart just past the hit, by a step relative to its magnitude (as for shadows).
        let point = ray.at(t);
        t0 = t + 1e-4 * (1.0 + point.abs().max_element()) / ray.dir.length().max(1e-30);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Mat4;

    fn ball(x: f32, r: f32, material: u32) -> CsgNode {
        let m = Mat4::from_translation(Vec3::new(x, 0.0, 0.0)) * Mat4::from_scale(Vec3::splat(r));
        CsgNode::Leaf {
            shape: Box::new(Shape::new(ShapeKind::Sphere, m).unwrap()),
            material,
        }
    }

    fn op(op: CsgOp, a: CsgNode, b: CsgNode) -> Csg {
        Csg::new(CsgNode::Op {
            op,
            a: Box::new(a),
            b: Box::new(b),
        })
        .unwrap()
    }

    /// Along the x axis through two unit balls centred at ±0.5: their surfaces at ±1.5 and ±0.5.
    #[test]
    fn the_three_operations_along_a_line() {
        let ray = Ray::new(Vec3::new(-5.0, 0.0, 0.0), Vec3::X);
        let all = |csg: &Csg| {
            let mut part = 0;
            node_crossings(&csg.root, &ray, &mut part)
                .1
                .iter()
                .map(|c| (c.t - 5.0, c.normal.x, c.part))
                .collect::<Vec<_>>()
        };
        let close = |got: Vec<(f32, f32, u32)>, want: &[(f32, f32, u32)]| {
            assert_eq!(got.len(), want.len(), "{got:?}");
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g.0 - w.0).abs() < 1e-4 && (g.1 - w.1).abs() < 1e-4 && g.2 == w.2,
                    "{got:?} vs {want:?}"
                );
            }
        };
        close(
            all(&op(CsgOp::Union, ball(-0.5, 1.0, 7), ball(0.5, 1.0, 8))),
            &[(-1.5, -1.0, 0), (1.5, 1.0, 1)],
        );
        close(
            all(&op(CsgOp::Intersection, ball(-0.5, 1.0, 7), ball(0.5, 1.0, 8))),
            &[(-0.5, -1.0, 1), (0.5, 1.0, 0)],
        );
        // A − B: enter A at −1.5, leave through B's surface at −0.5 with B's normal turned.
        close(
            all(&op(CsgOp::Difference, ball(-0.5, 1.0, 7), ball(0.5, 1.0, 8))),
            &[(-1.5, -1.0, 0), (-0.5, 1.0, 1)],
        );
        let lens = op(CsgOp::Intersection, ball(-0.5, 1.0, 7), ball(0.5, 1.0, 8));
        assert_eq!(lens.materials(), &[7, 8]);
        let hit = lens.intersect(&ray, f32::INFINITY).unwrap();
        assert_eq!(hit.part, 1);
        assert!((hit.t - 4.5).abs() < 1e-4);
        // From inside the lens the first crossing is its far side.
        let inner = lens.intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY).unwrap();
        assert!((inner.t - 0.5).abs() < 1e-4 && inner.part == 0 && inner.normal.x > 0.99);
    }

    /// A box with a ball cut out of its middle, seen along random rays: every crossing is on
    /// the box and outside the ball, or on the ball and inside the box; crossings alternate
    /// entering and leaving, and the normal always points out of the solid.
    #[test]
    fn crossings_bound_the_solid_and_alternate() {
        let cube = CsgNode::Leaf {
            shape: Box::new(Shape::new(ShapeKind::Box, Mat4::from_scale(Vec3::splat(2.0))).unwrap()),
            material: 0,
        };
        let solid = op(CsgOp::Difference, cube, ball(0.0, 1.2, 1));
        let inside = |p: Vec3| p.abs().max_element() < 1.0 && p.length() > 1.2;
        let mut rng = crate::sampling::Rng::new(3, 0);
        let mut count = 0;
        for _ in 0..3000 {
            let o = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE) * 4.0;
            let target = (Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0 - Vec3::ONE) * 1.5;
            let ray = Ray::new(o, (target - o).normalize());
            let mut part = 0;
            let (start, crossings) = node_crossings(&solid.root, &ray, &mut part);
            assert_eq!(start, inside(o));
            let mut state = start;
            for c in &crossings {
                let p = ray.at(c.t);
                let before = inside(ray.at(c.t - 1e-3));
                let after = inside(ray.at(c.t + 1e-3));
                assert!(before != after || p.abs().max_element() > 0.999, "{p}");
                assert_eq!(
                    c.normal.dot(ray.dir) > 0.0,
                    state,
                    "leaving points along the ray at {p}"
                );
                state = !state;
                count += 1;
            }
            assert!(!state, "every ray from outside ends outside");
        }
        assert!(count > 2000);
    }
}
