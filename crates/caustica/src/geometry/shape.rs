//! An analytic shape placed in the world by a transform.

use super::{box_shape, cone::Cone, csg::Csg, disk, metaballs::Metaballs, sphere, square, torus::Torus, LocalHit};
use crate::math::{Aabb, Mat3, Mat4, Ray, Vec2, Vec3};

/// The closed set of analytic shapes.
#[derive(Clone, Debug, PartialEq)]
pub enum ShapeKind {
    /// Unit sphere.
    Sphere,
    /// The `.ray` box: the cube [-0.5, 0.5]³.
    Box,
    /// Square [-0.5, 0.5]² at z = 0.
    Square,
    /// Cone or cylinder about +z.
    Cone(Cone),
    /// Torus about +z.
    Torus(Torus),
    /// Metaballs (shared: a shape is cloned cheaply).
    Metaballs(std::sync::Arc<Metaballs>),
    /// A CSG solid whose leaves carry their own transforms (the shape's own is the identity).
    Csg(std::sync::Arc<Csg>),
    /// The unit disc at z = 0 with a hole of radius `inner`.
    Disk {
        /// Radius of the hole (below 1).
        inner: f32,
    },
}

/// Options for how shapes are built from a scene file.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShapeSettings {
    /// Reproduce the course skeleton's cone quirks (radius and slope clamps, doubled normal z).
    pub cone_quirks: bool,
}

/// A shape with its transforms.
#[derive(Clone, Debug)]
pub struct Shape {
    /// Which shape.
    pub kind: ShapeKind,
    /// Object space to world space.
    pub world_from_object: Mat4,
    /// World space to object space.
    pub object_from_world: Mat4,
    /// Inverse transpose of the upper 3×3, for normals.
    pub normal_to_world: Mat3,
    /// World-space bounds.
    pub bounds: Aabb,
    /// An upper bound on how much `object_from_world` stretches any length, for
    /// [`Shape::may_come_within`].
    pub object_stretch: f32,
    /// Whether hits report texture coordinates: scenes clear it for untextured materials, which
    /// spares spheres and cones their inverse trigonometric calls on every hit.
    pub needs_uv: bool,
    /// The rows of `object_from_world`'s upper 3×3 and the object's origin in the world: a
    /// square is tested in world space with them (a third of the work of moving the ray).
    object_rows: [Vec3; 3],
    origin: Vec3,
    /// A sphere whose transform keeps it round (rotation, uniform scale, translation): its
    /// world centre and radius. It is tested in world space, without moving the ray.
    round_sphere: Option<(Vec3, f32)>,
    /// [`Shape::world_normal`] of `+Z` and `-Z`, a square's two normals, worked out once: the
    /// square root and division were most of a box's `Scene::surface`.
    z_normals: [Vec3; 2],
}

/// A shape as a packet test sees it ([`crate::accel::shape_packets`]): the world-space
/// constants of its own test.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PacketForm {
    /// A square.
    Square {
        /// The rows of `object_from_world`'s upper 3×3.
        rows: [Vec3; 3],
        /// The square's centre in the world.
        origin: Vec3,
    },
    /// A sphere kept round by its transform.
    Sphere {
        /// World centre.
        center: Vec3,
        /// World radius.
        radius: f32,
    },
}

/// A hit on a shape, in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    /// Ray parameter.
    pub t: f32,
    /// The hit point on the surface, in object space ([`Shape::world_point`] places it).
    pub local_point: Vec3,
    /// Unit world normal, oriented as the shape defines it (§7).
    pub normal: Vec3,
    /// Texture coordinates; zero unless the shape [`needs_uv`](Shape::needs_uv).
    pub uv: Vec2,
    /// Which leaf of a CSG solid was hit (0 for other shapes).
    pub part: u32,
}

impl Shape {
    /// Places `kind` by `world_from_object`; `None` if the matrix cannot be inverted.
    pub fn new(kind: ShapeKind, world_from_object: Mat4) -> Option<Shape> {
        if crate::math::is_degenerate_transform(&world_from_object) {
            return None;
        }
        let object_from_world = world_from_object.inverse();
        let normal_to_world = Mat3::from_mat4(object_from_world).transpose();
        let bounds = kind.object_bounds().transformed(&world_from_object);
        let linear = Mat3::from_mat4(object_from_world).transpose();
        let round_sphere = match kind {
            ShapeKind::Sphere => uniform_scale(Mat3::from_mat4(world_from_object))
                .map(|scale| (world_from_object.w_axis.truncate(), scale)),
            _ => None,
        };
        Some(Shape {
            kind,
            world_from_object,
            object_from_world,
            normal_to_world,
            bounds,
            object_stretch: max_stretch(Mat3::from_mat4(object_from_world)),
            needs_uv: true,
            object_rows: [linear.x_axis, linear.y_axis, linear.z_axis],
            origin: world_from_object.w_axis.truncate(),
            round_sphere,
            z_normals: [Vec3::Z, -Vec3::Z].map(|n| transform_normal(&normal_to_world, n)),
        })
    }

    /// A world-space sphere (centre, radius) holding the whole shape: the object-space one,
    /// carried over. Tighter than a sphere around the world bounds of a rotated shape.
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let (center, radius) = match &self.kind {
            ShapeKind::Sphere => (Vec3::ZERO, 1.0),
            ShapeKind::Box => (Vec3::ZERO, 0.75f32.sqrt()),
            ShapeKind::Square => (Vec3::ZERO, 0.5f32.sqrt()),
            ShapeKind::Disk { .. } => (Vec3::ZERO, 1.0),
            ShapeKind::Cone(cone) => {
                let h = 0.5 * cone.height;
                let r = cone.bottom_radius.max(cone.top_radius);
                (Vec3::new(0.0, 0.0, h), (r * r + h * h).sqrt())
            }
            ShapeKind::Torus(torus) => (Vec3::ZERO, torus.major + torus.minor),
            ShapeKind::Metaballs(m) => (m.bounds().center(), 0.5 * m.bounds().extent().length()),
            ShapeKind::Csg(c) => (c.bounds().center(), 0.5 * c.bounds().extent().length()),
        };
        let stretch = max_stretch(Mat3::from_mat4(self.world_from_object));
        (self.world_from_object.transform_point3(center), radius * stretch)
    }

    /// Whether the surface may come within world distance `r` of `point`; false only when it
    /// certainly does not (an object-space distance bound divided by the largest stretch).
    #[inline]
    pub fn may_come_within(&self, point: Vec3, r: f32) -> bool {
        if let ShapeKind::Csg(csg) = &self.kind {
            return csg.may_come_within(point, r);
        }
        let p = self.object_from_world.transform_point3(point);
        let d = match &self.kind {
            ShapeKind::Sphere => (p.length() - 1.0).abs(),
            ShapeKind::Box => {
                let q = p.abs() - Vec3::splat(0.5);
                if q.max_element() > 0.0 {
                    q.max(Vec3::ZERO).length()
                } else {
                    -q.max_element()
                }
            }
            ShapeKind::Square => Vec3::new((p.x.abs() - 0.5).max(0.0), (p.y.abs() - 0.5).max(0.0), p.z).length(),
            ShapeKind::Cone(cone) => cone.distance_lower_bound(p),
            ShapeKind::Torus(torus) => torus.distance(p),
            ShapeKind::Metaballs(m) => m.distance_lower_bound(p),
            ShapeKind::Csg(_) => 0.0,
            ShapeKind::Disk { inner } => disk::distance(p, *inner),
        };
        // Rounding in the transform: a relative margin on the object-space distance.
        d * (1.0 - 1e-4) - 1e-6 * (1.0 + p.abs().max_element()) <= r * self.object_stretch
    }

    /// Whether the straight segment between world points `a` and `b` certainly misses the
    /// surface: both ends lie inside the solid's convex interior (sphere, box, cone), which the
    /// surface never enters. False when unsure, and for shapes without one.
    #[inline]
    pub fn interior_holds(&self, a: Vec3, b: Vec3) -> bool {
        self.interior_holds_point(a) && self.interior_holds_point(b)
    }

    /// Whether `p` lies inside the shape's convex interior, well clear of its surface.
    #[inline]
    pub fn interior_holds_point(&self, p: Vec3) -> bool {
        // Well inside: a relative margin far above the transform's rounding.
        const INSIDE: f32 = 1.0 - 1e-4;
        let q = self.object_from_world.transform_point3(p);
        match &self.kind {
            ShapeKind::Sphere => q.length_squared() < INSIDE * INSIDE,
            ShapeKind::Box => q.abs().max_element() < 0.5 * INSIDE,
            ShapeKind::Cone(cone) => cone.interior_holds(q, INSIDE),
            _ => false,
        }
    }

    /// Nearest hit in `(0, t_max)` along the world ray.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let mut hit = self.intersect_object_normal(ray, t_max)?;
        hit.normal = self.world_normal(hit.normal);
        (hit.normal != Vec3::ZERO).then_some(hit)
    }

    /// As [`Shape::intersect`], but the normal stays in object space until
    /// [`Shape::world_normal`] turns it: a closest-hit search meets many shapes and needs the
    /// normal of one.
    #[inline]
    pub fn intersect_object_normal(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        if let ShapeKind::Csg(csg) = &self.kind {
            let c = csg.intersect(ray, t_max)?;
            return Some(ShapeHit {
                t: c.t,
                // The leaves put their own hits on their surfaces; this one goes back to world as is.
                local_point: self.object_from_world.transform_point3(ray.origin + ray.dir * c.t),
                normal: c.normal,
                uv: c.uv,
                part: c.part,
            });
        }
        if matches!(self.kind, ShapeKind::Square) {
            return self.intersect_square(ray, t_max);
        }
        if let Some((center, radius)) = self.round_sphere {
            return self.intersect_round_sphere(ray, t_max, center, radius);
        }
        let local = Ray::new(
            self.object_from_world.transform_point3(ray.origin),
            self.object_from_world.transform_vector3(ray.dir),
        );
        let hit: LocalHit = match &self.kind {
            ShapeKind::Sphere => sphere::intersect(&local, t_max, self.needs_uv),
            ShapeKind::Box => box_shape::intersect(&local, t_max),
            ShapeKind::Cone(cone) => cone.intersect(&local, t_max, self.needs_uv),
            ShapeKind::Torus(torus) => torus.intersect(&local, t_max, self.needs_uv),
            ShapeKind::Metaballs(m) => m.intersect(&local, t_max),
            // Both met above.
            ShapeKind::Csg(_) | ShapeKind::Square => return None,
            ShapeKind::Disk { inner } => disk::intersect(&local, t_max, *inner),
        }?;
        if hit.normal == Vec3::ZERO {
            return None;
        }
        Some(ShapeHit {
            t: hit.t,
            local_point: hit.point,
            normal: hit.normal,
            uv: if self.needs_uv { hit.uv } else { Vec2::ZERO },
            part: 0,
        })
    }

    /// The form in which packets test this shape, if it is a square or a round sphere.
    pub fn packet_form(&self) -> Option<PacketForm> {
        match (&self.kind, self.round_sphere) {
            (ShapeKind::Square, _) => Some(PacketForm::Square {
                rows: self.object_rows,
                origin: self.origin,
            }),
            (ShapeKind::Sphere, Some((center, radius))) => Some(PacketForm::Sphere { center, radius }),
            _ => None,
        }
    }

    /// [`square::intersect`] on the ray as the object sees it, from only the rows of the
    /// transform it needs: the plane's first, then the two in-plane ones for a hit in range.
    #[inline]
    fn intersect_square(&self, ray: &Ray, t_max: f32) -> Option<ShapeHit> {
        let row_z = self.object_rows[2];
        let dir_z = row_z.dot(ray.dir);
        if dir_z == 0.0 {
            return None;
        }
        // Most squares a ray meets lie behind it or beyond its nearest hit: those are turned
        // away before the division, whose latency dominated this test.
        let distance_z = row_z.dot(self.origin - ray.origin);
        if (distance_z > 0.0) != (dir_z > 0.0) || distance_z.abs() >= t_max * dir_z.abs() {
            return None;
        }
        let t = distance_z / dir_z;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        let hit = self.square_hit_at(ray, t, dir_z);
        let (x, y) = (hit.local_point.x, hit.local_point.y);
        (!(x.abs() > 0.5 || y.abs() > 0.5)).then_some(hit)
    }

    /// The record of the square's plane met at `t` along `ray` (`dir_z`: the ray's direction
    /// along the plane's normal), in range or not.
    #[inline]
    fn square_hit_at(&self, ray: &Ray, t: f32, dir_z: f32) -> ShapeHit {
        let [row_x, row_y, _] = self.object_rows;
        let offset = ray.origin + ray.dir * t - self.origin;
        let (x, y) = (row_x.dot(offset), row_y.dot(offset));
        ShapeHit {
            t,
            local_point: Vec3::new(x, y, 0.0),
            // Facing the incoming ray (§7).
            normal: if dir_z > 0.0 { -Vec3::Z } else { Vec3::Z },
            uv: if self.needs_uv {
                Vec2::new(x + 0.5, y + 0.5)
            } else {
                Vec2::ZERO
            },
            part: 0,
        }
    }

    /// The record of the hit at `t` along `ray` of a square or round sphere whose own test (or a
    /// packet's, the same arithmetic) found it there: that test's record, without finding `t`
    /// again. `None` for other shapes, or where that test would have found nothing.
    #[inline]
    pub fn packet_hit_at(&self, ray: &Ray, t: f32) -> Option<ShapeHit> {
        if matches!(self.kind, ShapeKind::Square) {
            return Some(self.square_hit_at(ray, t, self.object_rows[2].dot(ray.dir)));
        }
        let (center, _) = self.round_sphere?;
        self.round_sphere_hit_at(ray.origin - center, ray.dir, t)
    }

    /// [`sphere::intersect`] done in world space on a sphere of world `center` and `radius`: a
    /// miss costs two dot products and no square root, and only a hit is moved into object
    /// space (by the rows of the transform, as a square's).
    #[inline]
    fn intersect_round_sphere(&self, ray: &Ray, t_max: f32, center: Vec3, radius: f32) -> Option<ShapeHit> {
        let (oc, d) = (ray.origin - center, ray.dir);
        let (a, half_b) = (d.dot(d), oc.dot(d));
        // The discriminant about the ray's point nearest the centre, as in the object-space test.
        let l = oc - d * (half_b / a);
        let (l2, r2) = (l.length_squared(), radius * radius);
        if l2 > r2 {
            return None;
        }
        let l_len = l2.sqrt();
        let disc = a * ((radius - l_len) * (radius + l_len));
        let (t0, t1) = super::quadratic_roots(a, half_b, oc.dot(oc) - r2, disc)?;
        let t = if t0 > 0.0 { t0 } else { t1 };
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        self.round_sphere_hit_at(oc, d, t)
    }

    /// The record of a round sphere's hit at `t` along a ray `d` from `oc` off its centre.
    #[inline]
    fn round_sphere_hit_at(&self, oc: Vec3, d: Vec3, t: f32) -> Option<ShapeHit> {
        let offset = oc + d * t;
        let [row_x, row_y, row_z] = self.object_rows;
        let p = Vec3::new(row_x.dot(offset), row_y.dot(offset), row_z.dot(offset));
        let point = p / p.length();
        if !point.is_finite() {
            return None;
        }
        Some(ShapeHit {
            t,
            local_point: point,
            normal: point,
            uv: if self.needs_uv { sphere::uv(point) } else { Vec2::ZERO },
            part: 0,
        })
    }

    /// The unit world normal of a normal [`Shape::intersect_object_normal`] found (zero for a
    /// degenerate transform).
    #[inline]
    pub fn world_normal(&self, normal: Vec3) -> Vec3 {
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        match self.kind {
            // A solid's hits carry the world normal of the leaf they lie on.
            ShapeKind::Csg(_) => normal,
            // The same bits as worked out here (a normal of `-0.0` components is not `+Z`'s).
            ShapeKind::Square if bits(normal) == bits(Vec3::Z) => self.z_normals[0],
            ShapeKind::Square if bits(normal) == bits(-Vec3::Z) => self.z_normals[1],
            _ => transform_normal(&self.normal_to_world, normal),
        }
    }
}

impl Shape {
    /// The world position of a surface point given in object space, and a bound on the rounding
    /// error of each of its coordinates (γ₅ (|M|·|p| + |T|), as in pbrt: the transform's three
    /// products and sums, and the point's own rounding). A shape far from the origin, or large,
    /// has a point error larger than its coordinates alone suggest.
    #[inline]
    pub fn world_point(&self, local: Vec3) -> (Vec3, Vec3) {
        let m = &self.world_from_object;
        let point = m.transform_point3(local);
        let a = local.abs();
        let magnitude = m.x_axis.truncate().abs() * a.x
            + m.y_axis.truncate().abs() * a.y
            + m.z_axis.truncate().abs() * a.z
            + m.w_axis.truncate().abs();
        (point, magnitude * GAMMA_5)
    }
}

/// A normal carried to the world by `normal_to_world`, unit length (zero for a degenerate map).
#[inline]
fn transform_normal(normal_to_world: &Mat3, normal: Vec3) -> Vec3 {
    (*normal_to_world * normal).normalize_or_zero()
}

/// γ₅ = 5u / (1 − 5u) for the unit roundoff u of f32: the relative error bound of five rounded
/// operations.
const GAMMA_5: f32 = 5.0 * (f32::EPSILON * 0.5) / (1.0 - 5.0 * (f32::EPSILON * 0.5));

/// An upper bound on the largest singular value of `m`: the square root of a Gershgorin bound on
/// the largest eigenvalue of `mᵀm` (exact for rotations and axis scales), with a little margin.
/// The scale of a linear map that only rotates (or mirrors) and scales uniformly; `None` for
/// any other (within rounding: 1e-6 of the squared scale).
fn uniform_scale(m: Mat3) -> Option<f32> {
    let g = m.transpose() * m;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let off = (g - Mat3::from_diagonal(Vec3::splat(s2))).to_cols_array();
    (s2 > 0.0 && s2.is_finite() && off.iter().all(|e| e.abs() <= 1e-6 * s2)).then(|| s2.sqrt())
}

fn max_stretch(m: Mat3) -> f32 {
    let g = m.transpose() * m;
    let rows = [g.row(0), g.row(1), g.row(2)];
    let bound = rows.iter().map(|r| r.abs().element_sum()).fold(0.0, f32::max);
    let s = bound.sqrt() * (1.0 + 1e-4);
    if s.is_finite() {
        s
    } else {
        f32::INFINITY
    }
}

impl ShapeKind {
    /// A cylinder of the file (radius 1, height 1).
    pub fn cylinder(capped: bool) -> ShapeKind {
        ShapeKind::Cone(Cone::cylinder(capped))
    }

    /// Object-space bounds.
    pub fn object_bounds(&self) -> Aabb {
        match self {
            ShapeKind::Sphere => sphere::bounds(),
            ShapeKind::Box => box_shape::bounds(),
            ShapeKind::Square => square::bounds(),
            ShapeKind::Cone(cone) => cone.bounds(),
            ShapeKind::Torus(torus) => torus.bounds(),
            ShapeKind::Metaballs(m) => m.bounds(),
            ShapeKind::Csg(c) => c.bounds(),
            ShapeKind::Disk { .. } => disk::bounds(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    fn close(a: f32, b: f32) -> bool {
        (a - b).abs() < 1e-4
    }

    #[test]
    fn sphere_hits_from_outside_and_inside() {
        let s = Shape::new(ShapeKind::Sphere, Mat4::from_translation(Vec3::new(0.0, 0.0, -5.0))).unwrap();
        let hit = s.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z), f32::INFINITY).unwrap();
        assert!(close(hit.t, 4.0));
        assert!((hit.normal - Vec3::Z).length() < 1e-5);
        let inside = s
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, -5.0), Vec3::X), f32::INFINITY)
            .unwrap();
        assert!(close(inside.t, 1.0));
        assert!((inside.normal - Vec3::X).length() < 1e-5, "outward from inside too");
        assert!(s.intersect(&Ray::new(Vec3::ZERO, Vec3::Y), f32::INFINITY).is_none());
        assert!(
            s.intersect(&Ray::new(Vec3::ZERO, -Vec3::Z), 3.9).is_none(),
            "t_max respected"
        );
    }

    #[test]
    fn scaled_sphere_keeps_world_parameter_and_normal() {
        // An ellipsoid with semi-axes (2, 1, 1): hit at x = 2 from the right, normal +x.
        let s = Shape::new(ShapeKind::Sphere, Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0))).unwrap();
        let hit = s
            .intersect(&Ray::new(Vec3::new(10.0, 0.0, 0.0), -Vec3::X * 2.0), f32::INFINITY)
            .unwrap();
        assert!(close(hit.t, 4.0), "t is in units of the world direction: {}", hit.t);
        assert!((hit.normal - Vec3::X).length() < 1e-5);
        // On the ellipsoid at 45° the normal follows the inverse transpose, not the point.
        let p = Vec3::new(2.0 * 0.5f32.sqrt(), 0.5f32.sqrt(), 0.0);
        let hit = s.intersect(&Ray::new(p * 2.0, -p), f32::INFINITY).unwrap();
        let expected = Vec3::new(p.x / 4.0, p.y, 0.0).normalize();
        assert!((hit.normal - expected).length() < 1e-4);
    }

    #[test]
    fn box_faces_normals_and_uv() {
        let b = Shape::new(ShapeKind::Box, Mat4::IDENTITY).unwrap();
        let hit = b
            .intersect(&Ray::new(Vec3::new(0.2, 0.1, 3.0), -Vec3::Z), f32::INFINITY)
            .unwrap();
        assert!(close(hit.t, 2.5));
        assert_eq!(hit.normal, Vec3::Z);
        assert!(close(hit.uv.x, 0.7) && close(hit.uv.y, 0.6));
        let back = b
            .intersect(&Ray::new(Vec3::new(0.2, 0.1, -3.0), Vec3::Z), f32::INFINITY)
            .unwrap();
        assert_eq!(back.normal, -Vec3::Z);
        assert!(close(back.uv.x, 0.3), "−k face mirrors u");
        let inside = b.intersect(&Ray::new(Vec3::ZERO, Vec3::X), f32::INFINITY).unwrap();
        assert!(close(inside.t, 0.5));
        assert_eq!(inside.normal, Vec3::X, "outward, not flipped, from inside");
    }

    #[test]
    fn square_is_two_sided_and_faces_the_ray() {
        let s = Shape::new(ShapeKind::Square, Mat4::IDENTITY).unwrap();
        let down = s
            .intersect(&Ray::new(Vec3::new(0.1, -0.2, 1.0), -Vec3::Z), f32::INFINITY)
            .unwrap();
        assert_eq!(down.normal, Vec3::Z);
        assert!(close(down.uv.x, 0.6) && close(down.uv.y, 0.3));
        let up = s
            .intersect(&Ray::new(Vec3::new(0.1, -0.2, -1.0), Vec3::Z), f32::INFINITY)
            .unwrap();
        assert_eq!(up.normal, -Vec3::Z);
        assert!(s
            .intersect(&Ray::new(Vec3::new(0.6, 0.0, 1.0), -Vec3::Z), f32::INFINITY)
            .is_none());
    }

    /// A square's two normals, worked out once, are the bits the transform gives them; any other
    /// normal (a `-0.0` component included) is carried over as before.
    #[test]
    fn square_normals_are_the_transformed_normals() {
        let m = Mat4::from_scale_rotation_translation(
            Vec3::new(2.0, 0.5, 3.0),
            glam::Quat::from_euler(glam::EulerRot::XYZ, 0.3, -1.1, 2.0),
            Vec3::new(1.0, -2.0, 0.5),
        ) * Mat4::from_cols_array(&[
            1.0, 0.2, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.4, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ]);
        let s = Shape::new(ShapeKind::Square, m).unwrap();
        let direct = |n: Vec3| (s.normal_to_world * n).normalize_or_zero();
        let bits = |v: Vec3| v.to_array().map(f32::to_bits);
        for n in [
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(-0.0, 0.0, 1.0),
            Vec3::new(0.0, 0.6, 0.8),
            Vec3::X,
        ] {
            assert_eq!(bits(s.world_normal(n)), bits(direct(n)), "{n:?}");
        }
        let ray = Ray::new(m.transform_point3(Vec3::Z), m.transform_vector3(-Vec3::Z));
        let down = s.intersect_object_normal(&ray, f32::INFINITY).unwrap();
        assert_eq!(bits(down.normal), bits(Vec3::Z));
        assert_eq!(
            bits(s.intersect(&ray, f32::INFINITY).unwrap().normal),
            bits(direct(Vec3::Z))
        );
    }

    /// The world-space square test against the object-space one on the ray moved into object
    /// space, under sheared and scaled transforms, both against the hit worked out in f64: the
    /// same hits (but within rounding of an edge), and points as accurate.
    #[test]
    fn square_in_world_space_agrees_with_object_space() {
        let mut rng = crate::sampling::Rng::new(3, 0);
        let mut u = || rng.uniform() * 2.0 - 1.0;
        let (mut hits, mut edge) = (0, 0);
        let (mut world_error, mut object_error) = (0.0f64, 0.0f64);
        for _ in 0..200 {
            let m = Mat4::from_cols(
                Vec4::new(1.5 + u(), u(), u(), 0.0),
                Vec4::new(u(), 2.0 + u(), u(), 0.0),
                Vec4::new(u(), u(), 0.5 + u(), 0.0),
                Vec4::new(3.0 * u(), 3.0 * u(), 3.0 * u(), 1.0),
            );
            let s = Shape::new(ShapeKind::Square, m).unwrap();
            let inverse = m.as_dmat4().inverse();
            for _ in 0..50 {
                let origin = Vec3::new(4.0 * u(), 4.0 * u(), 4.0 * u());
                let target = m.transform_point3(Vec3::new(0.7 * u(), 0.7 * u(), 0.0));
                let ray = Ray::new(origin, (target - origin).normalize());
                // The exact hit, from the f32 ray in f64.
                let (local, o, d) = in_object_space(&s, &inverse, &ray);
                let exact = o + d * (-o.z / d.z);
                let world = s.intersect_square(&ray, f32::INFINITY);
                let object = square::intersect(&local, f32::INFINITY);
                match (world, object) {
                    (Some(w), Some(o)) => {
                        hits += 1;
                        world_error += (w.local_point.as_dvec3() - exact).length();
                        object_error += (o.point.as_dvec3() - exact).length();
                        assert_eq!(w.normal, o.normal);
                    }
                    (None, None) => {}
                    (w, o) => {
                        // Only at an edge may rounding decide differently.
                        let off_edge = (exact.x.abs() - 0.5).abs().min((exact.y.abs() - 0.5).abs());
                        assert!(off_edge < 1e-4, "{w:?} vs {o:?} (exact {exact:?})");
                        edge += 1;
                    }
                }
            }
        }
        assert!(hits > 4000 && edge < 10, "{hits} hits, {edge} at an edge");
        check_mean_errors(hits, world_error, object_error, 1e-5, &format!("{edge} at an edge"));
    }

    /// `ray` moved into `s`'s object space as the object-space tests see it (f32), and its
    /// origin and direction moved there in f64 by `inverse`, the exact inverse transform.
    fn in_object_space(s: &Shape, inverse: &glam::DMat4, ray: &Ray) -> (Ray, glam::DVec3, glam::DVec3) {
        let local = Ray::new(
            s.object_from_world.transform_point3(ray.origin),
            s.object_from_world.transform_vector3(ray.dir),
        );
        let o = inverse.transform_point3(ray.origin.as_dvec3());
        (local, o, inverse.transform_vector3(ray.dir.as_dvec3()))
    }

    /// The mean distance to the exact point over `hits` (from the summed errors) of a
    /// world-space test is below `bound` and at most twice the object-space test's.
    fn check_mean_errors(hits: usize, world_error: f64, object_error: f64, bound: f64, misses: &str) {
        let (world_error, object_error) = (world_error / hits as f64, object_error / hits as f64);
        eprintln!("{hits} hits, {misses}; mean error {world_error:e} (world), {object_error:e} (object)");
        assert!(
            world_error < bound && world_error < 2.0 * object_error,
            "{world_error:e} against {object_error:e}"
        );
    }

    /// A sphere that stays round is tested in world space: against the object-space test on the
    /// ray moved into object space, and both against the hit worked out in f64, under rotations,
    /// mirrors, uniform scales and translations, for rays from outside and from inside. A
    /// stretched sphere keeps the object-space test.
    #[test]
    fn round_sphere_in_world_space_agrees_with_object_space() {
        let mut rng = crate::sampling::Rng::new(5, 0);
        let mut u = || rng.uniform() * 2.0 - 1.0;
        let (mut hits, mut rim) = (0, 0);
        let (mut world_error, mut object_error) = (0.0f64, 0.0f64);
        for i in 0..200 {
            let rotation = glam::Quat::from_axis_angle(Vec3::new(u(), u(), u() + 0.01).normalize(), 3.0 * u());
            let mirror = if i % 3 == 0 {
                Vec3::new(-1.0, 1.0, 1.0)
            } else {
                Vec3::ONE
            };
            let scale = 0.05 + 2.0 * (u() + 1.0);
            let m = Mat4::from_translation(Vec3::new(5.0 * u(), 5.0 * u(), 5.0 * u()))
                * Mat4::from_quat(rotation)
                * Mat4::from_scale(mirror * scale);
            let s = Shape::new(ShapeKind::Sphere, m).unwrap();
            assert!(s.round_sphere.is_some(), "{m:?} keeps a sphere round");
            let inverse = m.as_dmat4().inverse();
            for j in 0..50 {
                let target = m.transform_point3(Vec3::new(u(), u(), u()) * 0.9);
                let origin = if j % 4 == 0 {
                    // Inside: glass seen from within.
                    m.transform_point3(Vec3::new(u(), u(), u()) * 0.5)
                } else {
                    target + Vec3::new(u(), u(), u()).normalize() * scale * (2.0 + 8.0 * u().abs())
                };
                let ray = Ray::new(origin, (target - origin).normalize());
                let (local, o, d) = in_object_space(&s, &inverse, &ray);
                let (a, half_b, c) = (d.dot(d), o.dot(d), o.dot(o) - 1.0);
                let disc = half_b * half_b - a * c;
                let world = s.intersect_object_normal(&ray, f32::INFINITY);
                let object = sphere::intersect(&local, f32::INFINITY, false);
                match (world, object) {
                    (Some(w), Some(o_hit)) => {
                        hits += 1;
                        let root = disc.max(0.0).sqrt();
                        let (t0, t1) = ((-half_b - root) / a, (-half_b + root) / a);
                        let t = if t0 > 0.0 { t0 } else { t1 };
                        let exact = (o + d * t).normalize();
                        assert!((w.t as f64 - t).abs() <= 1e-4 * (1.0 + t), "t {} against {t}", w.t);
                        assert_eq!(w.normal, w.local_point);
                        world_error += (w.local_point.as_dvec3() - exact).length();
                        object_error += (o_hit.point.as_dvec3() - exact).length();
                    }
                    (None, None) => {}
                    (w, o_hit) => {
                        // Only a ray grazing the rim may be decided differently by rounding.
                        assert!(disc.abs() < 1e-4 * a, "{w:?} vs {o_hit:?} (disc {disc:e})");
                        rim += 1;
                    }
                }
            }
        }
        assert!(hits > 8000 && rim < 10, "{hits} hits, {rim} at the rim");
        check_mean_errors(hits, world_error, object_error, 1e-6, &format!("{rim} at the rim"));
        let stretched = Shape::new(ShapeKind::Sphere, Mat4::from_scale(Vec3::new(1.0, 1.0, 1.001))).unwrap();
        assert!(stretched.round_sphere.is_none());
    }

    #[test]
    fn cylinder_side_and_caps() {
        let c = Shape::new(ShapeKind::cylinder(true), Mat4::IDENTITY).unwrap();
        let side = c
            .intersect(&Ray::new(Vec3::new(5.0, 0.0, 0.5), -Vec3::X), f32::INFINITY)
            .unwrap();
        assert!(close(side.t, 4.0));
        assert!((side.normal - Vec3::X).length() < 1e-5);
        let top = c
            .intersect(&Ray::new(Vec3::new(0.3, 0.0, 5.0), -Vec3::Z), f32::INFINITY)
            .unwrap();
        assert!(close(top.t, 4.0));
        assert_eq!(top.normal, Vec3::Z);
        let open = Shape::new(ShapeKind::cylinder(false), Mat4::IDENTITY).unwrap();
        let through = open.intersect(&Ray::new(Vec3::new(0.3, 0.0, 5.0), -Vec3::Z), f32::INFINITY);
        assert!(through.is_none(), "an open tube lets an axial ray through");
        let from_inside = open
            .intersect(&Ray::new(Vec3::new(0.0, 0.0, 0.5), Vec3::X), f32::INFINITY)
            .unwrap();
        assert!(
            (from_inside.normal + Vec3::X).length() < 1e-5,
            "faces the ray inside an open tube"
        );
    }

    #[test]
    fn cone_slant_normal_and_quirks() {
        // Bottom radius 1, apex at z = 1: the side at 45°.
        let cone = Cone::new(1.0, 1.0, 0.0, true, false);
        let s = Shape::new(ShapeKind::Cone(cone), Mat4::IDENTITY).unwrap();
        let hit = s
            .intersect(&Ray::new(Vec3::new(5.0, 0.0, 0.5), -Vec3::X), f32::INFINITY)
            .unwrap();
        assert!(close(hit.t, 4.5));
        let expected = Vec3::new(1.0, 0.0, 1.0).normalize();
        assert!((hit.normal - expected).length() < 1e-4, "{:?}", hit.normal);
        let quirky = Cone::new(2.0, 3.0, 3.0, false, true);
        assert!(
            close(quirky.top_radius, 3.002),
            "slope clamp flares equal radii by 0.001·h"
        );
        let sharp = Cone::new(1.0, 1.0, 0.0, true, true);
        assert!(close(sharp.top_radius, 1e-4));
        let q = Shape::new(ShapeKind::Cone(sharp), Mat4::IDENTITY).unwrap();
        let qh = q
            .intersect(&Ray::new(Vec3::new(5.0, 0.0, 0.5), -Vec3::X), f32::INFINITY)
            .unwrap();
        assert!(
            qh.normal.z > expected.z + 0.1,
            "the doubled z tilts the normal: {:?}",
            qh.normal
        );
    }

    /// Rays cast from a point hit the surface within `r` only if `may_come_within` says so;
    /// and it never answers false for a shape that passes within `r` (checked by casting).
    #[test]
    fn proximity_bound_is_conservative() {
        let kinds = [
            ShapeKind::Sphere,
            ShapeKind::Box,
            ShapeKind::Square,
            ShapeKind::cylinder(false),
            ShapeKind::cylinder(true),
            ShapeKind::Cone(Cone::new(2.0, 3.0, 1.0, true, false)),
            ShapeKind::Cone(Cone::new(2.0, 3.0, 3.0, false, true)),
            ShapeKind::Torus(Torus { major: 1.0, minor: 0.3 }),
            ShapeKind::Disk { inner: 0.4 },
        ];
        let transforms = [
            Mat4::IDENTITY,
            Mat4::from_scale(Vec3::new(20.0, 20.0, 0.5)),
            Mat4::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.785)
                * Mat4::from_scale(Vec3::new(3.0, 0.2, 1.5)),
            Mat4::from_cols_array(&[
                1.0, 0.3, 0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.2, 0.0, 0.7, 0.0, 1.0, -2.0, 0.5, 1.0,
            ]),
        ];
        let mut rng = crate::sampling::Rng::new(7, 0);
        let mut pruned = 0;
        for kind in kinds {
            for m in transforms {
                let s = Shape::new(kind.clone(), m).unwrap();
                let (lo, hi) = (s.bounds.min, s.bounds.max);
                let ext = (hi - lo).max_element();
                for _ in 0..200 {
                    let u = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                    let point = lo - Vec3::splat(0.2 * ext) + (hi - lo + Vec3::splat(0.4 * ext)) * u;
                    let r = ext * 0.15 * rng.uniform();
                    if s.may_come_within(point, r) {
                        continue;
                    }
                    pruned += 1;
                    for _ in 0..400 {
                        let d = crate::sampling::sample_uniform_sphere(rng.uniform2());
                        let hit = s.intersect(&Ray::new(point, d), r);
                        assert!(hit.is_none(), "{kind:?} within {r} of {point:?}");
                    }
                }
            }
        }
        assert!(pruned > 500, "the bound prunes: {pruned}");
    }

    /// A segment `interior_holds` says misses the surface does miss it (cast along it, both
    /// ways); segments that cross the surface are never held; and the test does hold most
    /// segments between points deep inside.
    #[test]
    fn held_segments_miss_the_surface() {
        let kinds = [
            ShapeKind::Sphere,
            ShapeKind::Box,
            ShapeKind::cylinder(false),
            ShapeKind::cylinder(true),
            ShapeKind::Cone(Cone::new(2.0, 3.0, 1.0, true, false)),
            ShapeKind::Cone(Cone::new(2.0, 3.0, 3.0, false, true)),
            ShapeKind::Cone(Cone::new(2.0, 0.5, 2.0, false, false)),
        ];
        let transforms = [
            Mat4::IDENTITY,
            Mat4::from_scale(Vec3::new(20.0, 20.0, 0.5)),
            Mat4::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.785)
                * Mat4::from_translation(Vec3::new(0.5, -1.0, 2.0))
                * Mat4::from_scale(Vec3::new(3.0, 0.2, 1.5)),
        ];
        let mut rng = crate::sampling::Rng::new(11, 0);
        for kind in kinds {
            for m in transforms {
                let s = Shape::new(kind.clone(), m).unwrap();
                let (lo, hi) = (s.bounds.min, s.bounds.max);
                let (mut held, mut deep) = (0, 0);
                for _ in 0..4000 {
                    let at = |u: Vec3| lo + (hi - lo) * u;
                    let a = at(Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()));
                    let b = at(Vec3::new(rng.uniform(), rng.uniform(), rng.uniform()));
                    let len = a.distance(b);
                    let crosses = s.intersect(&Ray::new(a, (b - a) / len), len).is_some()
                        || s.intersect(&Ray::new(b, (a - b) / len), len).is_some();
                    let holds = s.interior_holds(a, b);
                    assert!(!(holds && crosses), "{kind:?} {m:?}: held {a} → {b} crosses");
                    held += holds as u32;
                    // Both ends well inside (their object-space points scaled toward the axis).
                    let shrink = |p: Vec3| {
                        let q = s.object_from_world.transform_point3(p);
                        let centre = match &kind {
                            ShapeKind::Cone(c) => Vec3::new(0.0, 0.0, q.z.clamp(0.1 * c.height, 0.9 * c.height)),
                            _ => Vec3::ZERO,
                        };
                        s.world_from_object.transform_point3(centre + (q - centre) * 0.05)
                    };
                    if s.interior_holds(shrink(a), shrink(b)) {
                        deep += 1;
                    }
                }
                assert!(held > 0, "{kind:?} {m:?}: some random segments lie inside");
                assert!(deep > 3000, "{kind:?} {m:?}: {deep} of 4000 deep segments held");
            }
        }
    }

    /// Surface points found by casting rays lie inside the bounding sphere.
    #[test]
    fn bounding_sphere_holds_the_shape() {
        let kinds = [
            ShapeKind::Sphere,
            ShapeKind::Box,
            ShapeKind::Square,
            ShapeKind::cylinder(true),
            ShapeKind::Cone(Cone::new(2.0, 3.0, 1.0, true, false)),
            ShapeKind::Cone(Cone::new(2.0, 3.0, 3.0, false, true)),
            ShapeKind::Torus(Torus { major: 1.0, minor: 0.3 }),
            ShapeKind::Disk { inner: 0.0 },
        ];
        let transforms = [
            Mat4::from_scale(Vec3::new(20.0, 20.0, 0.5)),
            Mat4::from_axis_angle(Vec3::new(1.0, 1.0, 0.0).normalize(), 0.785)
                * Mat4::from_translation(Vec3::new(0.5, -1.0, 2.0))
                * Mat4::from_scale(Vec3::new(3.0, 0.2, 1.5)),
            Mat4::from_cols_array(&[
                1.0, 0.3, 0.0, 0.0, 0.0, 1.0, 0.5, 0.0, 0.2, 0.0, 0.7, 0.0, 1.0, -2.0, 0.5, 1.0,
            ]),
        ];
        let mut rng = crate::sampling::Rng::new(3, 0);
        for kind in kinds {
            for m in transforms {
                let s = Shape::new(kind.clone(), m).unwrap();
                let (center, radius) = s.bounding_sphere();
                let mut hits = 0;
                // Rays start in or near the world bounds, where the object-space solve is precise.
                for _ in 0..2000 {
                    let u = Vec3::new(rng.uniform(), rng.uniform(), rng.uniform());
                    let from = s.bounds.min - Vec3::ONE + (s.bounds.extent() + Vec3::splat(2.0)) * u;
                    let ray = Ray::new(from, crate::sampling::sample_uniform_sphere(rng.uniform2()));
                    if let Some(hit) = s.intersect(&ray, f32::INFINITY) {
                        hits += 1;
                        let d = ray.at(hit.t).distance(center);
                        assert!(d <= radius * (1.0 + 1e-4), "{kind:?}: hit at {d} > {radius}");
                    }
                }
                assert!(hits > 20, "{kind:?}: {hits} hits");
            }
        }
    }

    #[test]
    fn singular_transform_is_rejected() {
        assert!(Shape::new(ShapeKind::Sphere, Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))).is_none());
    }
}
