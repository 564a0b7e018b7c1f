//! Emissive shapes and meshes as area lights (physical mode): points on them are sampled for
//! direct light and photon emission, and the density of any point can be evaluated for multiple
//! importance sampling.
//!
//! A shape is sampled uniformly by area in its own object space and carried to the world by its
//! transform. The world-space area density then follows from the transform alone: a linear map
//! M scales an area element with unit normal n_w by |det M| / |Mᵀ n_w|, so
//! p(x) = |Mᵀ n_w| / (A_object · |det M|) for every shape kind, under any scale or shear.
//! A mesh picks a triangle by area, then a uniform point in it. Light leaves with radiance ke by
//! the faces the material names: both, like the `emissive` term of the course shading, or one
//! (pbrt's one-sided area lights).

use super::emission::{area_radiance, emitting_side, Emission, EmissionPoint, EmitArgs, Emitters};
use super::{visible_emission, DirectQuery, DirectSample, Light};
use crate::description::EmittingFaces;
use crate::geometry::cone::Cone;
use crate::geometry::ShapeKind;
use crate::math::{offset_origin, Frame, Ray};
use crate::math::{Mat3, Vec2, Vec3};
use crate::sampling::{sample_cosine_hemisphere, Rng};
use crate::sampling::{sample_uniform_cone_local, sample_uniform_disc, sample_uniform_sphere, uniform_cone_pdf};
use crate::scene::{ObjectRef, Scene};
use std::f32::consts::PI;

/// A sampled point on an area light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AreaSample {
    /// World position.
    pub point: Vec3,
    /// Unit world geometric normal (outward, as the shape defines it).
    pub normal: Vec3,
    /// Density with respect to world area.
    pub pdf_area: f32,
    /// The primitive the point lies on.
    pub prim: u32,
}

#[derive(Clone, Debug)]
enum Sampler {
    Shape {
        prim: u32,
        object_area: f32,
        det: f32,
        linear: Mat3,
    },
    Mesh {
        /// Global triangle indices and the running sum of their areas.
        triangles: Vec<u32>,
        cdf: Vec<f32>,
        area: f32,
    },
}

/// One emissive object.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The object that emits.
    pub object: ObjectRef,
    /// Emitted radiance where the material is constant; otherwise the material's mean guess,
    /// used only to share samples between lights.
    pub radiance: Vec3,
    /// Whether `radiance` is exact everywhere on the object (no texture, no per-vertex material).
    pub uniform: bool,
    /// World area (estimated by sampling for sheared shapes).
    pub area: f32,
    sampler: Sampler,
    /// Centre and radius of a sphere under a similarity transform: seen from outside it is
    /// sampled by the cone of directions it subtends (no sample wasted on its far side).
    sphere: Option<(Vec3, f32)>,
    /// The faces light leaves by: the material's, or only the outer one of a closed convex
    /// lamp that absorbs all light and holds nothing (what it emits inwards dies on its own
    /// inside).
    pub faces: EmittingFaces,
}

/// A point on a light sampled for a shading point, with the density in solid angle there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectionSample {
    /// The point on the light.
    pub point: AreaSample,
    /// Solid-angle density as seen from the shading point.
    pub pdf_solid: f32,
    /// The point is the light's nearest along its direction from the shading point (a sphere
    /// drawn by its cone): no part of the light itself lies in between.
    pub nearest: bool,
    /// The unit direction from the shading point to the point and its distance, where the
    /// drawing found them (a sphere's cone: its direction and the hit's `t`).
    pub toward: Option<(Vec3, f32)>,
}

impl AreaLight {
    /// The area lights of a scene: every object whose material can emit.
    pub fn collect(scene: &Scene) -> Vec<AreaLight> {
        let mut lights = Vec::new();
        for (i, shape) in scene.shapes().iter().enumerate() {
            let material = &scene.materials()[scene.shape_material(i) as usize];
            if !material.is_emissive() {
                continue;
            }
            let linear = Mat3::from_mat4(shape.world_from_object);
            let det = linear.determinant().abs();
            let object_area = object_area(&shape.kind);
            if !(det > 0.0 && object_area > 0.0) {
                continue;
            }
            let (radiance, uniform) = match material.emissive {
                crate::material::Channel::Constant(c) => (c, true),
                crate::material::Channel::Texture(_) => (Vec3::splat(0.5), false),
            };
            let sampler = Sampler::Shape {
                prim: scene.shape_prim(i),
                object_area,
                det,
                linear,
            };
            let area = world_area(&shape.kind, &sampler);
            let sphere = match shape.kind {
                ShapeKind::Sphere => {
                    similarity_scale(&linear).map(|scale| (shape.world_from_object.transform_point3(Vec3::ZERO), scale))
                }
                _ => None,
            };
            let closed = match shape.kind {
                ShapeKind::Sphere | ShapeKind::Box => true,
                ShapeKind::Cone(cone) => cone.capped,
                ShapeKind::Square | ShapeKind::Disk { .. } => false,
                ShapeKind::Torus(_) | ShapeKind::Metaballs(_) | ShapeKind::Csg(_) => true,
            };
            let absorbs = [
                material.diffuse,
                material.specular,
                material.reflective,
                material.transmissive,
            ]
            .iter()
            .all(|c| !c.may_be_nonzero());
            let outward_only = material.emitting_faces == EmittingFaces::Both
                && closed
                && absorbs
                && scene
                    .occluders_near(
                        shape.bounds.center(),
                        0.5 * shape.bounds.extent().max_element(),
                        i as u32,
                    )
                    .is_empty();
            lights.push(AreaLight {
                object: ObjectRef::Shape(i as u32),
                radiance,
                uniform,
                area,
                sampler,
                sphere,
                faces: if outward_only {
                    EmittingFaces::Front
                } else {
                    material.emitting_faces
                },
            });
        }
        // Triangles by mesh, gathered in one pass over the scene's triangles.
        let mut by_mesh: Vec<Vec<u32>> = Vec::new();
        for (m, mesh) in scene.meshes().iter().enumerate() {
            let emissive_base = scene.materials()[mesh.material as usize].is_emissive();
            let per_vertex = mesh
                .vertex_materials
                .as_ref()
                .is_some_and(|ids| ids.iter().any(|&id| scene.materials()[id as usize].is_emissive()));
            if !emissive_base && !per_vertex {
                continue;
            }
            if by_mesh.is_empty() {
                by_mesh = vec![Vec::new(); scene.meshes().len()];
                for t in 0..scene.triangles().len() {
                    by_mesh[scene.triangle_ref(t).mesh as usize].push(t as u32);
                }
            }
            let mut triangles = Vec::new();
            let mut cdf = Vec::new();
            let mut area = 0.0f32;
            for &t in &by_mesh[m] {
                let t = t as usize;
                let [a, b, c] = scene.triangles()[t].vertices();
                let tri_area = 0.5 * (b - a).cross(c - a).length();
                if tri_area > 0.0 && tri_area.is_finite() {
                    area += tri_area;
                    triangles.push(t as u32);
                    cdf.push(area);
                }
            }
            if triangles.is_empty() {
                continue;
            }
            let (radiance, uniform) = match (
                &mesh.vertex_materials,
                scene.materials()[mesh.material as usize].emissive,
            ) {
                (None, crate::material::Channel::Constant(c)) => (c, true),
                _ => (Vec3::splat(0.5), false),
            };
            lights.push(AreaLight {
                object: ObjectRef::Mesh(m as u32),
                radiance,
                uniform,
                area,
                sampler: Sampler::Mesh { triangles, cdf, area },
                sphere: None,
                faces: scene.materials()[mesh.material as usize].emitting_faces,
            });
        }
        lights
    }

    /// Emitted power (luminance) guess, π·A·L from each face that emits usefully, used to
    /// share samples.
    pub fn power(&self) -> f32 {
        self.faces.count() * PI * self.area * crate::math::luminance(self.radiance).max(0.0)
    }

    /// Centre and radius of a sphere lamp under a similarity transform (sampled uniformly by
    /// area, so its area density is 1/(4πr²) everywhere).
    pub fn sphere(&self) -> Option<(Vec3, f32)> {
        self.sphere
    }

    /// A point on the light; `u_pick` chooses the triangle of a mesh.
    pub fn sample(&self, scene: &Scene, u_pick: f32, u: Vec2) -> Option<AreaSample> {
        match &self.sampler {
            Sampler::Shape { prim, linear, .. } => {
                if let Some((center, radius)) = self.sphere {
                    // A sphere under a similarity is sampled uniformly by area as it stands:
                    // no transform, normalisation or density to work out per sample.
                    let normal = sample_uniform_sphere(u);
                    return Some(AreaSample {
                        point: center + normal * radius,
                        normal,
                        pdf_area: sphere_area_pdf(radius),
                        prim: *prim,
                    });
                }
                let shape = &scene.shapes()[*prim as usize];
                let (p, n) = sample_object(&shape.kind, u_pick, u)?;
                let point = shape.world_from_object.transform_point3(p);
                let normal = (shape.normal_to_world * n).normalize_or_zero();
                if normal == Vec3::ZERO {
                    return None;
                }
                let pdf_area = self.shape_pdf(linear, normal);
                Some(AreaSample {
                    point,
                    normal,
                    pdf_area,
                    prim: *prim,
                })
            }
            Sampler::Mesh { triangles, cdf, area } => {
                let target = u_pick * area;
                let i = cdf.partition_point(|&c| c <= target).min(triangles.len() - 1);
                let t = triangles[i] as usize;
                let [a, b, c] = scene.triangles()[t].vertices();
                let su = u.x.sqrt();
                let (b1, b2) = (1.0 - su, u.y * su);
                let point = a * (1.0 - b1 - b2) + b * b1 + c * b2;
                let normal = (b - a).cross(c - a).normalize_or_zero();
                (normal != Vec3::ZERO).then(|| AreaSample {
                    point,
                    normal,
                    pdf_area: 1.0 / area,
                    prim: scene.triangle_prim(t),
                })
            }
        }
    }

    /// A point on the light for lighting `from`: by solid angle for a sphere seen from outside,
    /// by area otherwise (its density converted to solid angle).
    pub fn sample_towards(&self, scene: &Scene, from: Vec3, u_pick: f32, u: Vec2) -> Option<DirectionSample> {
        if let Some((center, radius)) = self.sphere {
            let to = center - from;
            let d2 = to.length_squared();
            if let Some(cos_max) = cone_cosine_at(d2, radius) {
                let d = d2.sqrt();
                let local = sample_uniform_cone_local(u, cos_max);
                let dir = Frame::from_normal(to * d.recip()).to_world(local);
                // The nearest hit from the cone's angle θ, not by testing the ray, so that it
                // does not wait for `dir`: the ray passes closest to the centre d·cosθ along it,
                // (r² − d²·sin²θ)^½ after the sphere's near side (clamped: a direction at the
                // cone's rim can graze past it by rounding).
                let sin2 = (1.0 - local.z * local.z).max(0.0);
                let t = d * local.z - (radius * radius - d2 * sin2).max(0.0).sqrt();
                if t.is_nan() || t <= 0.0 {
                    return None;
                }
                let point = from + dir * t;
                let Sampler::Shape { prim, .. } = &self.sampler else {
                    return None;
                };
                return Some(DirectionSample {
                    point: AreaSample {
                        point,
                        // On the sphere to rounding: dividing by the radius saves normalising's
                        // square root, on next-event estimation's chain of dependent operations.
                        normal: (point - center) * radius.recip(),
                        // As `sample` draws it: uniform by area.
                        pdf_area: sphere_area_pdf(radius),
                        prim: *prim,
                    },
                    pdf_solid: uniform_cone_pdf(cos_max),
                    nearest: true,
                    toward: Some((dir, t)),
                });
            }
        }
        let sample = self.sample(scene, u_pick, u)?;
        let pdf_solid = solid_angle_pdf(from, sample.point, sample.normal, sample.pdf_area)?;
        Some(DirectionSample {
            point: sample,
            pdf_solid,
            nearest: false,
            toward: None,
        })
    }

    /// Solid-angle density of [`AreaLight::sample_towards`] from `from` at the light's point
    /// `point` with unit normal `normal`; 0 where it cannot be drawn.
    pub fn pdf_towards(&self, from: Vec3, point: Vec3, normal: Vec3) -> f32 {
        if let Some((center, radius)) = self.sphere {
            if let Some(cos_max) = cone_cosine(from, center, radius) {
                return uniform_cone_pdf(cos_max);
            }
        }
        solid_angle_pdf(from, point, normal, self.pdf_area(normal)).unwrap_or(0.0)
    }

    /// Area density of [`AreaLight::sample`] at a point of this light with unit world normal
    /// `normal`.
    pub fn pdf_area(&self, normal: Vec3) -> f32 {
        // A sphere lamp's, the same everywhere: no transformed normal's length to work out.
        if let Some((_, radius)) = self.sphere {
            return sphere_area_pdf(radius);
        }
        match &self.sampler {
            Sampler::Shape { linear, .. } => self.shape_pdf(linear, normal),
            Sampler::Mesh { area, .. } => 1.0 / area,
        }
    }

    fn shape_pdf(&self, linear: &Mat3, normal: Vec3) -> f32 {
        let Sampler::Shape { object_area, det, .. } = &self.sampler else {
            return 0.0;
        };
        (linear.transpose() * normal).length() / (object_area * det)
    }
}

/// The area density of a sphere of `radius` sampled uniformly by area.
#[inline]
fn sphere_area_pdf(radius: f32) -> f32 {
    1.0 / (4.0 * PI * radius * radius)
}

/// The cosine of the half-angle a sphere subtends from `from`; `None` inside or on it.
fn cone_cosine(from: Vec3, center: Vec3, radius: f32) -> Option<f32> {
    cone_cosine_at((center - from).length_squared(), radius)
}

/// [`cone_cosine`] from `d2`, the squared distance to the centre.
fn cone_cosine_at(d2: f32, radius: f32) -> Option<f32> {
    let sin2 = radius * radius / d2;
    // Too close to the surface for a cone to be accurate: sample by area instead.
    if sin2.is_nan() || sin2 >= 0.99 {
        return None;
    }
    Some((1.0 - sin2).sqrt())
}

/// An area density at `point` (normal `normal`) seen from `from`, in solid angle.
fn solid_angle_pdf(from: Vec3, point: Vec3, normal: Vec3, pdf_area: f32) -> Option<f32> {
    let to = point - from;
    let d2 = to.length_squared();
    let cos = normal.dot(to).abs() / d2.sqrt();
    (cos > 1e-7 && d2 > 0.0).then(|| pdf_area * d2 / cos)
}

/// The scale of a linear map that is a rotation times a uniform scale, if it is one.
fn similarity_scale(m: &Mat3) -> Option<f32> {
    let g = m.transpose() * *m;
    let s2 = (g.x_axis.x + g.y_axis.y + g.z_axis.z) / 3.0;
    let off = g - Mat3::from_diagonal(Vec3::splat(s2));
    let err = off
        .x_axis
        .abs()
        .max_element()
        .max(off.y_axis.abs().max_element())
        .max(off.z_axis.abs().max_element());
    (s2 > 0.0 && err <= 1e-5 * s2).then(|| s2.sqrt())
}

/// Object-space surface area of a shape kind.
fn object_area(kind: &ShapeKind) -> f32 {
    match kind {
        ShapeKind::Sphere => 4.0 * PI,
        ShapeKind::Box => 6.0,
        ShapeKind::Square => 1.0,
        ShapeKind::Disk { inner } => PI * (1.0 - inner * inner),
        ShapeKind::Cone(cone) => {
            let (side, bottom, top) = cone_areas(cone);
            side + bottom + top
        }
        // Not sampled: an emissive torus glows without lighting (the builder warns).
        ShapeKind::Torus(_) | ShapeKind::Metaballs(_) | ShapeKind::Csg(_) => 0.0,
    }
}

fn cone_areas(cone: &Cone) -> (f32, f32, f32) {
    let (r0, r1, h) = (cone.bottom_radius, cone.top_radius, cone.height);
    let side = PI * (r0 + r1) * (h * h + (r1 - r0) * (r1 - r0)).sqrt();
    if cone.capped {
        (side, PI * r0 * r0, PI * r1 * r1)
    } else {
        (side, 0.0, 0.0)
    }
}

/// World area: exact for similarity transforms, a fixed-sample estimate otherwise.
fn world_area(kind: &ShapeKind, sampler: &Sampler) -> f32 {
    let Sampler::Shape {
        object_area,
        det,
        linear,
        ..
    } = sampler
    else {
        return 0.0;
    };
    let mut sum = 0.0f64;
    let count = 4096;
    let mut rng = crate::sampling::Rng::new(0x00a2_ea11, 0);
    let normal_to_world = linear.inverse().transpose();
    for _ in 0..count {
        let Some((_, n)) = sample_object(kind, rng.uniform(), rng.uniform2()) else {
            continue;
        };
        let nw = (normal_to_world * n).normalize_or_zero();
        // Jacobian |det M| / |Mᵀ n_w| of the area element.
        let stretch = det / (linear.transpose() * nw).length().max(1e-30);
        sum += stretch as f64;
    }
    (*object_area as f64 * sum / count as f64) as f32
}

/// A point uniform by area on the object-space surface, with its outward unit normal.
fn sample_object(kind: &ShapeKind, u_pick: f32, u: Vec2) -> Option<(Vec3, Vec3)> {
    match kind {
        ShapeKind::Sphere => {
            let p = sample_uniform_sphere(u);
            Some((p, p))
        }
        ShapeKind::Box => {
            let face = ((u_pick * 6.0) as usize).min(5);
            let axis = face % 3;
            let sign = if face < 3 { 1.0 } else { -1.0 };
            let mut p = Vec3::ZERO;
            let mut n = Vec3::ZERO;
            p[axis] = 0.5 * sign;
            n[axis] = sign;
            p[(axis + 1) % 3] = u.x - 0.5;
            p[(axis + 2) % 3] = u.y - 0.5;
            Some((p, n))
        }
        ShapeKind::Square => Some((Vec3::new(u.x - 0.5, u.y - 0.5, 0.0), Vec3::Z)),
        ShapeKind::Torus(_) | ShapeKind::Metaballs(_) | ShapeKind::Csg(_) => None,
        ShapeKind::Disk { inner } => {
            // Radius with density ∝ r between the hole and the rim.
            let r = (inner * inner + u.x * (1.0 - inner * inner)).sqrt();
            let (s, c) = (2.0 * PI * u.y).sin_cos();
            Some((Vec3::new(r * c, r * s, 0.0), Vec3::Z))
        }
        ShapeKind::Cone(cone) => {
            let (side, bottom, top) = cone_areas(cone);
            let total = side + bottom + top;
            if total <= 0.0 {
                return None;
            }
            let x = u_pick * total;
            if x < side {
                let (r0, r1, h) = (cone.bottom_radius, cone.top_radius, cone.height);
                // Height fraction t with density ∝ r(t) = r0 + (r1 − r0) t.
                let t = if (r1 - r0).abs() < 1e-6 * (r0 + r1) {
                    u.x
                } else {
                    let a = 0.5 * (r1 - r0);
                    let c = -u.x * 0.5 * (r0 + r1);
                    (-r0 + (r0 * r0 - 4.0 * a * c).max(0.0).sqrt()) / (2.0 * a)
                };
                let radius = r0 + (r1 - r0) * t;
                let phi = 2.0 * PI * u.y;
                let (s, c) = phi.sin_cos();
                let p = Vec3::new(radius * c, radius * s, t * h);
                let n = Vec3::new(c * h, s * h, r0 - r1).normalize_or_zero();
                Some((p, n))
            } else {
                let d = sample_uniform_disc(u);
                if x < side + bottom {
                    let r = cone.bottom_radius;
                    Some((Vec3::new(d.x * r, d.y * r, 0.0), -Vec3::Z))
                } else {
                    let r = cone.top_radius;
                    Some((Vec3::new(d.x * r, d.y * r, cone.height), Vec3::Z))
                }
            }
        }
    }
}

impl AreaLight {
    /// Next-event estimation's sample: a point on the light for lighting the query's point,
    /// visibility included.
    pub(super) fn sample_direct(&self, q: &DirectQuery, (u_pick, u): (f32, Vec2)) -> Option<DirectSample> {
        let (scene, hit, p_pick, light) = (q.scene, q.hit, q.choice, self);
        let p = hit.point;
        let drawn = light.sample_towards(scene, p, u_pick, u)?;
        let sample = drawn.point;
        let (wi, d) = drawn.toward.unwrap_or_else(|| {
            let to = sample.point - p;
            let d = to.length();
            (to / d, d)
        });
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        if !(q.takes)(wi) {
            return None;
        }
        let le = visible_emission(q, light, &drawn, wi, d)?;
        let pdf = p_pick * drawn.pdf_solid;
        Some(DirectSample {
            wi,
            distance: d,
            contribution: le / pdf,
            pdf,
            direct_pdf: pdf,
            delta: false,
            point: sample.point,
            normal: sample.normal,
            cos_light: sample.normal.dot(wi).abs(),
        })
    }
}

impl Emitters {
    /// A start from an emissive object: a point by area, a face, a cosine-weighted direction (or, aimed,
    /// one towards a target from the half of a sphere lamp facing it).
    pub(super) fn emit_area(&self, light: &Light, args: EmitArgs, rng: &mut Rng) -> Option<Emission> {
        let scene = args.scene;
        let (number, pick, u, u_dir, wl) = args.parts();
        match light {
            Light::Area(light) => {
                let mut sample = light.sample(scene, rng.uniform(), u)?;
                let (dir, normal) = match self.aimed_lobe(rng) {
                    Some((aim, u_pick, u_aim)) => {
                        let dir = match (self.lamp(number), light.sphere()) {
                            (Some(lamp), Some((center, radius))) => {
                                let (normal, dir) = lamp.sample(sample.normal, u_pick, u_aim)?;
                                sample.normal = normal;
                                sample.point = center + normal * radius;
                                dir
                            }
                            _ => aim.sample(sample.point, u_pick, u_aim)?,
                        };
                        // Leaves by the face it points out of, if that face emits.
                        let side = if dir.dot(sample.normal) >= 0.0 { 1.0 } else { -1.0 };
                        if light.faces.sign().is_some_and(|s| s != side) {
                            return None;
                        }
                        (dir, sample.normal * side)
                    }
                    None => {
                        // A face at random, or the one that emits, then a cosine-weighted
                        // direction.
                        let (side, u2) = emitting_side(light, u_dir);
                        let normal = sample.normal * side;
                        (
                            Frame::from_normal(normal).to_world(sample_cosine_hemisphere(u2)),
                            normal,
                        )
                    }
                };
                let le = area_radiance(light, scene, &sample, wl);
                let cos = dir.dot(normal);
                let plain = cos / (PI * light.faces.count());
                let pdf = pick * self.start_pdf((number, light), sample.point, sample.normal, dir, plain);
                let point_pdf = pick * self.point_pdf((number, light), &sample);
                (cos > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(offset_origin(sample.point, sample.normal, dir), dir),
                    throughput: le * (cos / pdf),
                    emission_pdf: pdf,
                    cos,
                    delta: false,
                    light: number,
                    normal,
                    far: false,
                    origin: (point_pdf > 0.0).then(|| EmissionPoint {
                        point: sample.point,
                        normal: sample.normal,
                        faces: light.faces,
                        radiance: le / point_pdf,
                    }),
                })
            }
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::build::test_scene as scene;

    fn disk_scene() -> crate::scene::Scene {
        use crate::description::*;
        let desc = SceneDescription {
            objects: vec![ObjectDesc {
                shape: ShapeDesc::Disk { inner: 0.5 },
                world_from_object: glam::Mat4::from_scale(Vec3::new(2.0, 3.0, 1.0)),
                material: MaterialDesc {
                    emissive: Param::grey(1.0),
                    ..MaterialDesc::default()
                },
                span: 0..0,
            }],
            ..SceneDescription::default()
        };
        crate::scene::build(&desc, &Default::default()).unwrap()
    }

    /// Σ 1/pdf over samples estimates the area; it must match the closed form for each kind
    /// under a non-uniform scale (where a similarity-only formula would be wrong).
    #[test]
    fn area_density_integrates_to_the_world_area() {
        let cases = [
            ("scale(2, sphere { material = { emissive = (1,1,1); } })", 16.0 * PI),
            ("scale(2, 3, 1, box { material = { emissive = (1,1,1); } })", 2.0 * (6.0 + 2.0 + 3.0)),
            ("scale(2, 3, 1, square { material = { emissive = (1,1,1); } })", 6.0),
            ("disk", 6.0 * PI * (1.0 - 0.25)),
            (
                "scale(2, cylinder { capped = true; material = { emissive = (1,1,1); } })",
                // radius 2, height 2: side 2π·2·2, caps 2·π·4
                8.0 * PI + 8.0 * PI,
            ),
            (
                "cone { height = 2; bottom_radius = 1; top_radius = 0.5; capped = true; material = { emissive = (1,1,1); } }",
                PI * 1.5 * (4.0f32 + 0.25).sqrt() + PI + PI * 0.25,
            ),
        ];
        for (object, exact) in cases {
            let s = if object == "disk" {
                // Radius 1 with a hole of 0.5, stretched to 2 × 3.
                disk_scene()
            } else {
                scene(object)
            };
            let lights = AreaLight::collect(&s);
            assert_eq!(lights.len(), 1, "{object}");
            let light = &lights[0];
            let mut rng = crate::sampling::Rng::new(4, 0);
            let n = 100_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let sample = light.sample(&s, rng.uniform(), rng.uniform2()).unwrap();
                assert!((light.pdf_area(sample.normal) - sample.pdf_area).abs() <= 1e-5 * sample.pdf_area);
                sum += 1.0 / sample.pdf_area as f64;
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.01,
                "{object}: {estimate} vs {exact}"
            );
            assert!((light.area / exact - 1.0).abs() < 0.02, "{object}: area {}", light.area);
        }
    }

    /// An ellipsoid's area has no closed form; the sampled density must agree with a fine
    /// numerical integral of the surface (1° × 1° patches).
    #[test]
    fn sheared_sphere_density_agrees_with_numerical_area() {
        let s = scene("scale(1, 2, 0.5, sphere { material = { emissive = (1,1,1); } })");
        let light = &AreaLight::collect(&s)[0];
        let (a, b, c) = (1.0f64, 2.0f64, 0.5f64);
        let mut area = 0.0f64;
        let steps = 720;
        for i in 0..steps {
            let theta = (i as f64 + 0.5) * std::f64::consts::PI / steps as f64;
            for j in 0..2 * steps {
                let phi = (j as f64 + 0.5) * std::f64::consts::PI / steps as f64;
                let (st, ct, sp, cp) = (theta.sin(), theta.cos(), phi.sin(), phi.cos());
                // |∂x/∂θ × ∂x/∂φ| for x = (a sinθ cosφ, b sinθ sinφ, c cosθ)
                let dt = [a * ct * cp, b * ct * sp, -c * st];
                let dp = [-a * st * sp, b * st * cp, 0.0];
                let cross = [
                    dt[1] * dp[2] - dt[2] * dp[1],
                    dt[2] * dp[0] - dt[0] * dp[2],
                    dt[0] * dp[1] - dt[1] * dp[0],
                ];
                let len = (cross[0] * cross[0] + cross[1] * cross[1] + cross[2] * cross[2]).sqrt();
                area += len * (std::f64::consts::PI / steps as f64).powi(2);
            }
        }
        let mut rng = crate::sampling::Rng::new(5, 0);
        let n = 200_000;
        let sum: f64 = (0..n)
            .map(|_| 1.0 / light.sample(&s, rng.uniform(), rng.uniform2()).unwrap().pdf_area as f64)
            .sum();
        assert!(
            (sum / n as f64 / area - 1.0).abs() < 0.01,
            "{} vs {area}",
            sum / n as f64
        );
    }

    /// Σ over samples of (1/pdf) · [hit the sphere] estimates the solid angle the sphere
    /// subtends, 2π(1 − cos θ), whether drawn by cone or (up close, or ellipsoid) by area.
    #[test]
    fn sphere_lights_sample_their_solid_angle() {
        for (object, from) in [
            (
                "translate(0, 0, -3, scale(0.5, sphere { material = { emissive = (1,1,1); } }))",
                Vec3::ZERO,
            ),
            (
                "translate(0, 0, -3, scale(0.5, sphere { material = { emissive = (1,1,1); } }))",
                Vec3::new(0.0, 0.0, -2.48),
            ),
            (
                "translate(0, 0, -3, scale(0.5, 0.5, 0.6, sphere { material = { emissive = (1,1,1); } }))",
                Vec3::ZERO,
            ),
        ] {
            let s = scene(object);
            let light = &AreaLight::collect(&s)[0];
            let mut rng = crate::sampling::Rng::new(7, 0);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let Some(d) = light.sample_towards(&s, from, rng.uniform(), rng.uniform2()) else {
                    continue;
                };
                // Only points visible from `from` count: the first hit along the direction.
                let dir = (d.point.point - from).normalize();
                let Some(hit) = s.intersect(&crate::math::Ray::new(from, dir), f32::INFINITY) else {
                    continue; // a tangent direction, lost to rounding
                };
                if (hit.t - (d.point.point - from).length()).abs() < 1e-3 {
                    let pdf = light.pdf_towards(from, d.point.point, d.point.normal);
                    assert!((pdf - d.pdf_solid).abs() <= 1e-3 * pdf);
                    sum += 1.0 / d.pdf_solid as f64;
                }
            }
            let estimate = sum / n as f64;
            // Exact solid angle of the sphere (the ellipsoid's is checked against a fine
            // direction grid below).
            let exact = if object.contains("0.6") {
                let mut count = 0u64;
                let steps = 2000;
                for i in 0..steps {
                    for j in 0..steps {
                        let u = Vec2::new((i as f32 + 0.5) / steps as f32, (j as f32 + 0.5) / steps as f32);
                        let dir = sample_uniform_sphere(u);
                        if s.intersect(&crate::math::Ray::new(from, dir), f32::INFINITY).is_some() {
                            count += 1;
                        }
                    }
                }
                4.0 * std::f64::consts::PI * count as f64 / (steps * steps) as f64
            } else {
                let d = (Vec3::new(0.0, 0.0, -3.0) - from).length() as f64;
                2.0 * std::f64::consts::PI * (1.0 - (1.0 - 0.25 / (d * d)).sqrt())
            };
            assert!(
                (estimate / exact - 1.0).abs() < 0.01,
                "{object} from {from}: {estimate} vs {exact}"
            );
        }
    }

    #[test]
    fn mesh_lights_sample_by_area() {
        let s = scene(
            "trimesh { points = ((0,0,0),(2,0,0),(0,2,0),(0,0,1)); faces = ((0,1,2),(0,1,3)); material = { emissive = (2,2,2); } }",
        );
        let light = &AreaLight::collect(&s)[0];
        assert!((light.area - 3.0).abs() < 1e-5);
        assert!(light.uniform);
        let mut rng = crate::sampling::Rng::new(6, 0);
        let n = 30_000;
        let on_first = (0..n)
            .filter(|_| light.sample(&s, rng.uniform(), rng.uniform2()).unwrap().point.z.abs() < 1e-6)
            .count();
        // Triangle areas 2 and 1.
        assert!((on_first as f64 / n as f64 - 2.0 / 3.0).abs() < 0.01);
    }
}
