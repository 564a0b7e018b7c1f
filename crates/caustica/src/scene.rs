//! The renderable scene: world-space shapes and triangles in their BVHs, materials, textures,
//! lights and the camera. Built from a scene description by [`build`].

pub mod build;
pub mod summary;

pub use build::{build, BuildSettings};

use crate::accel::bvh::{Bvh, TriangleBvh, TriangleBvhHit};
use crate::accel::shape_packets::ShapePackets;
use crate::camera::Camera;
use crate::description::EmittingFaces;
use crate::geometry::shape::ShapeHit;
use crate::geometry::triangle::Triangle;
use crate::geometry::{Shape, ShapeKind};
use crate::light::{Light, LightSet};
use crate::material::{Lobes, Material, MaterialRef, MaterialSpectra, SurfaceParams};
use crate::math::{Aabb, Ray, Vec2, Vec3};
use crate::medium::{Interface, Media, Medium, Side, VACUUM};
use crate::progress::Progress;
use crate::spectrum::{Spectrum, Wavelengths};
use crate::texture::Texture;
use std::sync::OnceLock;

/// A triangle mesh's shading data in world space; its triangles live in [`Scene::triangles`].
#[derive(Clone, Debug)]
pub struct Mesh {
    /// Vertex indices of each triangle.
    pub indices: Vec<[u32; 3]>,
    /// Unit per-vertex normals in world space.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex texture coordinates.
    pub uvs: Option<Vec<Vec2>>,
    /// Per-vertex world-space tangents (w: the bitangent's sign) where a normal map needs them.
    pub tangents: Option<Vec<crate::math::Vec4>>,
    /// Per-vertex material ids.
    pub vertex_materials: Option<Vec<u32>>,
    /// The mesh's material id.
    pub material: u32,
    /// World-space bounds.
    pub bounds: Aabb,
}

impl Mesh {
    /// Texture coordinates at barycentrics (`b1`, `b2`) of triangle `index`: interpolated, or
    /// the barycentrics themselves when the mesh has none.
    #[inline]
    pub fn uv_at(&self, index: u32, b1: f32, b2: f32) -> Vec2 {
        match &self.uvs {
            Some(uvs) => {
                let [i0, i1, i2] = self.indices[index as usize].map(|i| i as usize);
                uvs[i0] * (1.0 - b1 - b2) + uvs[i1] * b1 + uvs[i2] * b2
            }
            None => Vec2::new(b1, b2),
        }
    }
}

/// Which object a triangle belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TriangleRef {
    /// Mesh index.
    pub mesh: u32,
    /// Triangle index within the mesh.
    pub index: u32,
}

/// One renderable object: an analytic shape or a mesh, with its material.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ObjectRef {
    /// Index into [`Scene::shapes`].
    Shape(u32),
    /// Index into [`Scene::meshes`].
    Mesh(u32),
}

/// A short list of primitives near a point; past its capacity it only records that it overflowed.
#[derive(Clone, Debug, Default)]
pub struct Occluders {
    prims: [u32; OCCLUDER_CAPACITY],
    len: usize,
    overflowed: bool,
}

/// Few primitives come near one gather; past this many, testing the whole BVH is as cheap.
const OCCLUDER_CAPACITY: usize = 8;

/// How deep mixes of mixes are followed (pbrt files nest a few).
const MAX_MIX_DEPTH: u32 = 8;

impl Occluders {
    fn push(&mut self, prim: u32) {
        if self.len < OCCLUDER_CAPACITY {
            self.prims[self.len] = prim;
            self.len += 1;
        } else {
            self.overflowed = true;
        }
    }

    /// The primitives found (all of them unless overflowed).
    pub fn prims(&self) -> &[u32] {
        &self.prims[..self.len]
    }

    /// Whether no primitive came near.
    pub fn is_empty(&self) -> bool {
        self.len == 0 && !self.overflowed
    }
}

/// Segments from one gather point to the photons around it ([`Scene::segments_from`]): the
/// point's end is moved off its surface, and the convex interiors that hold it are found, once
/// for all its photons (done per photon, that was 3% of the original's worst case).
pub struct SegmentsFrom<'a> {
    scene: &'a Scene,
    occluders: &'a Occluders,
    from: Vec3,
    /// Bit i: the convex interior of occluder i holds `from`.
    inside: u32,
}

impl SegmentsFrom<'_> {
    /// Whether the segment to the surface point `b` (normal `b_normal`) misses every occluder
    /// (every primitive of the scene when the list overflowed); each end is moved off its
    /// surface as in [`Scene::segment_clear`].
    pub fn clear_to(&self, b: Vec3, b_normal: Vec3) -> bool {
        let scene = self.scene;
        let to = crate::math::offset_along(b, b_normal);
        let prims = self.occluders.prims();
        // A segment inside a shape's interior (photons on a floor inside a ring) needs no test.
        let open = prims.iter().enumerate().fold(0u32, |mask, (i, &prim)| {
            let held = self.inside & (1 << i) != 0 && scene.shapes[prim as usize].interior_holds_point(to);
            mask | (u32::from(!held) << i)
        });
        if open == 0 && !self.occluders.overflowed {
            return true;
        }
        let d = to - self.from;
        let len = d.length();
        if len.is_nan() || len <= 0.0 {
            return true;
        }
        let ray = Ray::new(self.from, d / len);
        if self.occluders.overflowed {
            return !scene.any_hit(&ray, len, |h| !scene.is_boundary(h));
        }
        !prims.iter().enumerate().any(|(i, &prim)| {
            open & (1 << i) != 0
                && scene
                    .intersect_prim(prim, &ray, len)
                    .is_some_and(|h| !scene.is_boundary(&h))
        })
    }
}

/// A segment that next-event estimation needs clear: from a surface point towards a light,
/// passing over primitive `own` (the light's, or `u32::MAX`).
#[derive(Clone, Copy, Debug)]
pub struct ShadowRay {
    /// From just off the surface, towards the light.
    pub ray: Ray,
    /// Where the segment ends.
    pub t_max: f32,
    /// The primitive that never blocks.
    pub own: u32,
}

/// A scene ready to render. Its parts are read through methods: primitives are numbered
/// shapes first, then triangles, and only the scene relies on that numbering.
pub struct Scene {
    camera: Camera,
    lights: LightSet,
    ambient: Vec3,
    materials: Vec<Material>,
    /// Each material's fitted spectra, made the first time spectral transport asks.
    material_spectra: Vec<OnceLock<MaterialSpectra>>,
    /// Whether some material is a mix ([`Scene::choose`]).
    mixes: bool,
    /// Whether some material has a clear coat.
    coats: bool,
    /// Each untextured material's lobes, worked out once (`None`: textured).
    material_lobes: Vec<Option<Lobes>>,
    textures: Vec<Texture>,
    shapes: Vec<Shape>,
    /// Material id of each shape.
    shape_materials: Vec<u32>,
    meshes: Vec<Mesh>,
    /// All triangles of all meshes, in world space.
    triangles: Vec<Triangle>,
    /// The mesh and index of each triangle.
    triangle_refs: Vec<TriangleRef>,
    warnings: Vec<String>,
    /// What the scene file asks for about rendering.
    hints: crate::description::RenderHints,
    /// Hierarchy over the analytic shapes (primitive ids `0..shapes.len()`).
    shape_bvh: Bvh,
    /// The shapes in packets, tested instead of `shape_bvh` where there are few squares and
    /// round spheres and nothing else.
    shape_packets: Option<ShapePackets>,
    /// Hierarchy over the triangles, tested four at a time (primitive id `shapes.len() + i`).
    triangle_bvh: TriangleBvh,
    /// Whether some mesh has cut-outs (a material with coverage): only then are hits tested.
    cutouts: bool,
    /// Participating media (absorbing glass among them); empty: no walk tracks any.
    media: Vec<Medium>,
    /// The medium where no interface says otherwise.
    ambient_medium: u32,
    /// The medium the eye is in.
    camera_medium: u32,
    /// The medium each light starts its light in.
    light_media: Vec<u32>,
    /// Whether some material is only a boundary between media (shadow rays pass it).
    boundaries: bool,
    /// The sphere around the scene: media fill no more than it.
    sphere: (Vec3, f32),
}

/// What a scene is assembled from (the builder's output).
pub(crate) struct SceneParts {
    pub camera: Camera,
    pub lights: Vec<Light>,
    pub ambient: Vec3,
    pub materials: Vec<Material>,
    pub textures: Vec<Texture>,
    pub shapes: Vec<Shape>,
    pub shape_materials: Vec<u32>,
    pub meshes: Vec<Mesh>,
    pub triangles: Vec<Triangle>,
    pub triangle_refs: Vec<TriangleRef>,
    pub warnings: Vec<String>,
    pub hints: crate::description::RenderHints,
    pub media: Vec<Medium>,
    pub ambient_medium: u32,
    pub camera_medium: Option<u32>,
    /// The media of lights the file places in one: (light number, medium).
    pub light_media: Vec<(usize, u32)>,
}

/// Shape `prim`'s hit as an intersection.
#[inline]
fn shape_intersection(prim: u32, hit: ShapeHit) -> Intersection {
    Intersection {
        t: hit.t,
        prim,
        normal_or_bary: hit.normal,
        uv: hit.uv,
        part: hit.part,
        local_point: hit.local_point,
    }
}

/// The minimal record of a closest hit: enough to build a [`SurfaceHit`] when needed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Intersection {
    /// Ray parameter.
    pub t: f32,
    /// Primitive index: shapes first, then triangles.
    pub prim: u32,
    /// Shapes: the normal in object space ([`Shape::world_normal`] turns it, only for the hit
    /// that is shaded); triangles: barycentric (u, v, 0).
    normal_or_bary: Vec3,
    uv: Vec2,
    /// The leaf of a CSG solid hit (0 otherwise).
    part: u32,
    /// Shapes: the point on the surface in object space.
    local_point: Vec3,
}

/// Everything shading needs at a surface point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Ray parameter.
    pub t: f32,
    /// World position.
    pub point: Vec3,
    /// A bound on the rounding error of each coordinate of `point` (zero where the magnitude of
    /// `point` bounds it: triangles).
    pub point_error: Vec3,
    /// Unit geometric normal as the shape defines it (outward for closed shapes, §7).
    pub geometric_normal: Vec3,
    /// Unit shading normal (interpolated for meshes), on the geometric normal's side.
    pub shading_normal: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// The material here (one, or three blended across a mesh triangle).
    pub material: MaterialRef,
    /// The object hit.
    pub object: ObjectRef,
    /// The primitive hit (shapes first, then triangles).
    pub prim: u32,
    /// The media on its two sides as the walk that reached it sees them (vacuum in scenes
    /// without media).
    pub media: Media,
}

impl SurfaceHit {
    /// Where a ray leaving the surface in direction `dir` starts: moved off the surface to the
    /// side `dir` points to, past the rounding error of the point.
    #[inline]
    pub fn ray_origin(&self, dir: Vec3) -> Vec3 {
        crate::math::offset_origin_bounded(self.point, self.geometric_normal, dir, self.point_error)
    }
}

impl SurfaceHit {
    /// A scattering point inside `medium`: no surface, the same medium on both sides (next-event
    /// estimation asks for a hit).
    pub fn in_medium(point: Vec3, medium: u32) -> SurfaceHit {
        SurfaceHit {
            t: 0.0,
            point,
            point_error: Vec3::ZERO,
            geometric_normal: Vec3::ZERO,
            shading_normal: Vec3::ZERO,
            uv: Vec2::ZERO,
            material: MaterialRef::One(0),
            object: ObjectRef::Shape(u32::MAX),
            prim: u32::MAX,
            media: Media::both(medium),
        }
    }

    /// Whether this is a scattering point in a medium rather than a surface.
    #[inline]
    pub fn is_in_medium(&self) -> bool {
        self.prim == u32::MAX
    }
}

impl Scene {
    /// Assembles a scene: builds its hierarchies, then finds its emissive objects.
    pub(crate) fn assemble(parts: SceneParts, progress: &dyn Progress) -> Scene {
        let SceneParts {
            camera,
            lights,
            ambient,
            materials,
            textures,
            mut shapes,
            shape_materials,
            meshes,
            triangles,
            triangle_refs,
            warnings,
            hints,
            media,
            ambient_medium,
            camera_medium,
            light_media,
        } = parts;
        for (shape, &material) in shapes.iter_mut().zip(&shape_materials) {
            shape.needs_uv = materials[material as usize].is_textured();
        }
        let shape_bounds: Vec<Aabb> = shapes.iter().map(|s| s.bounds).collect();
        let shape_bvh = Bvh::build_reporting(&shape_bounds, progress);
        let shape_packets = ShapePackets::new(&shapes);
        let triangle_bvh = TriangleBvh::build_reporting(&triangles, progress);
        let mut scene = Scene {
            camera,
            lights: LightSet::default(),
            ambient,
            material_spectra: materials.iter().map(|_| OnceLock::new()).collect(),
            mixes: materials.iter().any(|m| m.mix.is_some()),
            coats: materials.iter().any(|m| m.clearcoat.is_some()),
            material_lobes: materials
                .iter()
                .map(|m| (!m.is_textured()).then(|| Lobes::new(&m.eval(&[], Vec2::ZERO))))
                .collect(),
            materials,
            textures,
            shapes,
            shape_materials,
            meshes,
            triangles,
            triangle_refs,
            // A warning quoting a huge token is cut to a readable length here, once for every
            // front end.
            warnings: warnings
                .iter()
                .map(|w| crate::diagnostic::shorten(w).into_owned())
                .collect(),
            hints,
            shape_bvh,
            shape_packets,
            triangle_bvh,
            cutouts: false,
            media: Vec::new(),
            ambient_medium: VACUUM,
            camera_medium: VACUUM,
            light_media: Vec::new(),
            boundaries: false,
            sphere: (Vec3::ZERO, 0.0),
        };
        scene.cutouts = scene
            .meshes
            .iter()
            .any(|m| scene.materials[m.material as usize].alpha.is_some());
        scene.lights = LightSet::new(&scene, lights);
        scene.set_media(media, ambient_medium, camera_medium, &light_media);
        scene
    }

    /// A point inside a light, to find the medium it shines into (`None`: a far light).
    fn light_point(&self, light: &Light) -> Option<Vec3> {
        match light {
            Light::Point { position, .. } | Light::Spot { position, .. } => Some(*position),
            Light::Soft(soft) => Some(soft.center()),
            Light::Area(area) => Some(match area.object {
                ObjectRef::Shape(s) => self.shapes[s as usize].bounds.center(),
                ObjectRef::Mesh(m) => self.meshes[m as usize].bounds.center(),
            }),
            Light::Directional { .. } | Light::Sun { .. } | Light::Environment(_) => None,
        }
    }

    /// Puts the media in place: each absorbing glass becomes a medium that only absorbs, inside
    /// its surface, with whatever surrounded the path outside; then the media of the eye and of
    /// each light are found.
    fn set_media(&mut self, mut media: Vec<Medium>, ambient: u32, camera: Option<u32>, lights: &[(usize, u32)]) {
        for material in &mut self.materials {
            if let (Some(sigma), None) = (material.absorption, material.interface) {
                media.push(Medium::homogeneous(sigma, Vec3::ZERO, 0.0));
                material.interface = Some(Interface {
                    inside: Side::Medium(media.len() as u32 - 1),
                    outside: Side::Surrounding,
                });
            }
        }
        self.boundaries = self.materials.iter().any(|m| m.boundary);
        let clear = media.iter().all(Medium::is_clear) && !self.boundaries;
        if clear {
            // Nothing to track: every walk takes the fast way.
            return;
        }
        self.media = media;
        self.ambient_medium = ambient;
        let bounds = self.bounds();
        self.sphere = (bounds.center(), (0.5 * bounds.extent().length()).max(1e-3));
        self.camera_medium = camera.unwrap_or_else(|| self.medium_at(self.camera.eye));
        self.light_media = self
            .lights
            .iter()
            .enumerate()
            .map(|(i, light)| match lights.iter().find(|&&(n, _)| n == i) {
                Some(&(_, medium)) => medium,
                None => self
                    .light_point(light)
                    .map_or(self.ambient_medium, |p| self.medium_at(p)),
            })
            .collect();
    }

    /// The scene with `lights` in place of its own (its emissive objects kept).
    #[cfg(test)]
    pub(crate) fn set_lights(&mut self, lights: Vec<Light>) {
        self.lights = LightSet::new(self, lights);
    }

    /// The camera.
    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Every light: the file's, then the emissive objects.
    pub fn lights(&self) -> &LightSet {
        &self.lights
    }

    /// Ambient light Ia of the course shading.
    pub fn ambient(&self) -> Vec3 {
        self.ambient
    }

    /// Materials, indexed by id.
    pub fn materials(&self) -> &[Material] {
        &self.materials
    }

    /// Textures, indexed by id.
    pub fn textures(&self) -> &[Texture] {
        &self.textures
    }

    /// Analytic shapes.
    pub fn shapes(&self) -> &[Shape] {
        &self.shapes
    }

    /// The material id of shape `i`.
    pub fn shape_material(&self, i: usize) -> u32 {
        self.shape_materials[i]
    }

    /// Meshes.
    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// All triangles of all meshes, in world space.
    pub fn triangles(&self) -> &[Triangle] {
        &self.triangles
    }

    /// The mesh and index of triangle `t`.
    pub fn triangle_ref(&self, t: usize) -> TriangleRef {
        self.triangle_refs[t]
    }

    /// The primitive number of shape `i`.
    pub fn shape_prim(&self, i: usize) -> u32 {
        i as u32
    }

    /// The primitive number of triangle `t`.
    pub fn triangle_prim(&self, t: usize) -> u32 {
        (self.shapes.len() + t) as u32
    }

    /// The render settings the scene file asks for (image size, integrator …), which
    /// [`RenderConfig::for_scene`](crate::integrator::RenderConfig::for_scene) applies.
    pub fn hints(&self) -> &crate::description::RenderHints {
        &self.hints
    }

    /// Remarks made while reading and building (dropped triangles, ignored keys, …).
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// The course's eight material values at a surface point.
    #[inline]
    pub fn phong(&self, hit: &SurfaceHit) -> SurfaceParams {
        match hit.material {
            MaterialRef::One(id) => self.materials[id as usize].eval(&self.textures, hit.uv),
            MaterialRef::Blend { ids, weights } => {
                let p = ids.map(|id| self.materials[id as usize].eval(&self.textures, hit.uv));
                SurfaceParams::blend([&p[0], &p[1], &p[2]], weights)
            }
        }
    }

    /// The lobes of the material at a surface point, if they are the same everywhere on it
    /// (one untextured material).
    #[inline]
    pub fn constant_lobes(&self, hit: &SurfaceHit) -> Option<&Lobes> {
        match hit.material {
            MaterialRef::One(id) => self.material_lobes[id as usize].as_ref(),
            MaterialRef::Blend { .. } => None,
        }
    }

    /// Material `id`'s constant colours as smooth spectra (fitted on first use).
    pub fn material_spectra(&self, id: u32) -> &MaterialSpectra {
        self.material_spectra[id as usize].get_or_init(|| MaterialSpectra::of(&self.materials[id as usize]))
    }

    /// Whether some material is a dispersive glass.
    pub fn has_dispersion(&self) -> bool {
        self.materials.iter().any(|m| m.abbe.is_some())
    }

    /// The Abbe number of a dispersive glass at a surface point.
    #[inline]
    pub fn abbe(&self, hit: &SurfaceHit) -> Option<f32> {
        match hit.material {
            MaterialRef::One(id) => self.materials[id as usize].abbe,
            MaterialRef::Blend { ids, .. } => ids.iter().find_map(|&id| self.materials[id as usize].abbe),
        }
    }

    /// Whether walks track media here (some medium, absorbing glass or boundary): without,
    /// every walk takes the fast way and no hit carries media.
    #[inline]
    pub fn has_media(&self) -> bool {
        !self.media.is_empty()
    }

    /// Whether some medium scatters light (fog, smoke; not a glass that only absorbs).
    pub fn scatters(&self) -> bool {
        self.media.iter().any(|m| !m.only_absorbs() && !m.is_clear())
    }

    /// Every medium (empty in a scene that tracks none).
    pub fn media(&self) -> &[Medium] {
        &self.media
    }

    /// Medium `id` (not [`VACUUM`]).
    #[inline]
    pub fn medium(&self, id: u32) -> &Medium {
        &self.media[id as usize]
    }

    /// The medium where no interface says otherwise.
    pub fn ambient_medium(&self) -> u32 {
        self.ambient_medium
    }

    /// The medium the eye is in.
    pub fn camera_medium(&self) -> u32 {
        self.camera_medium
    }

    /// The medium light `index` starts in.
    pub fn light_medium(&self, index: usize) -> u32 {
        self.light_media.get(index).copied().unwrap_or(VACUUM)
    }

    /// The media the surface at `hit` separates (`None`: paths crossing it keep theirs).
    #[inline]
    pub fn interface(&self, hit: &SurfaceHit) -> Option<Interface> {
        match hit.material {
            MaterialRef::One(id) => self.materials[id as usize].interface,
            MaterialRef::Blend { .. } => None,
        }
    }

    /// Whether the primitive of `isect` is only a boundary between media.
    #[inline]
    pub fn is_boundary(&self, isect: &Intersection) -> bool {
        self.boundaries && self.materials[self.intersection_material(isect) as usize].boundary
    }

    /// The material of an intersection's primitive (a mesh's own, a shape's part's).
    fn intersection_material(&self, isect: &Intersection) -> u32 {
        let n_shapes = self.shapes.len() as u32;
        if isect.prim < n_shapes {
            self.part_material(isect.prim as usize, isect.part)
        } else {
            self.meshes[self.triangle_refs[(isect.prim - n_shapes) as usize].mesh as usize].material
        }
    }

    /// The segment of `ray` (unit direction) between `t0` and `t1` that media fill: no more
    /// than the sphere around the scene.
    #[inline]
    pub fn medium_segment(&self, ray: &Ray, (t0, t1): (f32, f32)) -> (f32, f32) {
        let (center, radius) = self.sphere;
        let oc = ray.origin - center;
        let b = oc.dot(ray.dir);
        let c = oc.length_squared() - radius * radius;
        let disc = b * b - c;
        if disc <= 0.0 {
            return (t0, t0);
        }
        let root = disc.sqrt();
        (t0.max(-b - root), t1.min(-b + root))
    }

    /// The medium at `point`, found by following a ray from it to the first boundary that says
    /// which medium lies on the point's side (the ambient medium where none does).
    pub fn medium_at(&self, point: Vec3) -> u32 {
        let dir = Vec3::new(0.267_261_24, 0.534_522_5, 0.801_783_7);
        let mut ray = Ray::new(point, dir);
        let mut outer = self.ambient_medium;
        for _ in 0..1024 {
            let Some(isect) = self.intersect(&ray, f32::INFINITY) else {
                break;
            };
            let hit = self.surface(&ray, &isect);
            if let Some(interface) = self.interface(&hit) {
                let leaving = dir.dot(hit.geometric_normal) > 0.0;
                match (leaving, interface.inside, interface.outside) {
                    (true, Side::Medium(m), _) | (false, _, Side::Medium(m)) => return m,
                    _ => outer = self.ambient_medium,
                }
            }
            ray = Ray::new(hit.ray_origin(dir), dir);
        }
        outer
    }

    /// What light keeps along the unblocked segment from `hit` towards `wi` (unit) for
    /// `distance` (infinite: out of the scene): the transmittance of each medium it crosses,
    /// boundaries between media passed.
    pub fn transmittance_towards(
        &self,
        hit: &SurfaceHit,
        wi: Vec3,
        distance: f32,
        wl: &Wavelengths,
        rng: &mut crate::sampling::Rng,
    ) -> Spectrum {
        let mut medium = hit.media.towards(hit.geometric_normal, wi);
        let origin = hit.ray_origin(wi);
        let mut left = if distance.is_finite() {
            (distance - (origin - hit.point).length()) * (1.0 - 1e-5)
        } else {
            f32::INFINITY
        };
        let mut ray = Ray::new(origin, wi);
        let mut kept = wl.grey(1.0);
        let mut outer = self.ambient_medium;
        for _ in 0..1024 {
            let next = if self.boundaries {
                self.intersect(&ray, left).filter(|i| self.is_boundary(i))
            } else {
                None
            };
            let end = next.map_or(left, |i| i.t);
            if medium != VACUUM {
                let segment = self.medium_segment(&ray, (0.0, end));
                kept *= self.media[medium as usize].transmittance(&ray, segment, wl, rng);
            }
            let Some(isect) = next else {
                break;
            };
            let boundary = self.surface(&ray, &isect);
            medium = self.medium_beyond(&boundary, wi, medium, &mut outer);
            let origin = boundary.ray_origin(wi);
            left -= (origin - ray.origin).length();
            ray = Ray::new(origin, wi);
        }
        kept
    }

    /// The medium a path in `current` goes into across the surface at `hit` along `dir`;
    /// `outer` remembers what surrounded it where a surface's outside is
    /// [`Side::Surrounding`].
    #[inline]
    pub fn medium_beyond(&self, hit: &SurfaceHit, dir: Vec3, current: u32, outer: &mut u32) -> u32 {
        let Some(interface) = self.interface(hit) else {
            return current;
        };
        if dir.dot(hit.geometric_normal) < 0.0 {
            if interface.outside == Side::Surrounding {
                *outer = current;
            }
            match interface.inside {
                Side::Medium(m) => m,
                Side::Surrounding => current,
            }
        } else {
            match interface.outside {
                Side::Medium(m) => m,
                Side::Surrounding => *outer,
            }
        }
    }

    /// The radiance a surface point emits towards `wo` at the wavelengths `wl`: zero out of a
    /// face that does not emit.
    #[inline]
    pub fn emission_towards(&self, hit: &SurfaceHit, wo: Vec3, wl: &Wavelengths) -> Spectrum {
        let id = match hit.material {
            // Most surfaces a path meets do not glow: no emission to look up.
            MaterialRef::One(id) if !self.materials[id as usize].is_emissive() => return Spectrum::ZERO,
            MaterialRef::One(id) => id,
            MaterialRef::Blend { ids, .. } => ids[0],
        };
        let faces = self.materials[id as usize].emitting_faces;
        if faces != EmittingFaces::Both && !faces.emit_towards(self.front_normal(hit), wo) {
            return Spectrum::ZERO;
        }
        self.emission_spectrum(hit, wl)
    }

    /// The normal that names a hit's front face: the geometric normal, except on a disk or
    /// square, whose hits face the ray and whose front is their object-space +z.
    fn front_normal(&self, hit: &SurfaceHit) -> Vec3 {
        match hit.object {
            ObjectRef::Shape(i) => {
                let shape = &self.shapes[i as usize];
                match shape.kind {
                    ShapeKind::Disk { .. } | ShapeKind::Square => shape.world_normal(Vec3::Z),
                    _ => hit.geometric_normal,
                }
            }
            ObjectRef::Mesh(_) => hit.geometric_normal,
        }
    }

    /// The emitted radiance at a surface point at the wavelengths `wl`, from either face.
    pub fn emission_spectrum(&self, hit: &SurfaceHit, wl: &Wavelengths) -> Spectrum {
        let le = self.emission(hit).max(Vec3::ZERO);
        match (wl.is_spectral(), hit.material) {
            (true, MaterialRef::One(id)) if !self.materials[id as usize].emissive_is_textured() => {
                self.material_spectra(id).emission(le, wl)
            }
            _ => wl.unbounded(le),
        }
    }

    /// The physical reading's values at a surface point, when its material has its own (a
    /// blend of per-vertex materials reads the first vertex's).
    #[inline(always)]
    pub fn physical(&self, hit: &SurfaceHit) -> Option<crate::material::PhysicalMaterial<Vec3>> {
        let id = match hit.material {
            MaterialRef::One(id) => id,
            MaterialRef::Blend { ids, .. } => ids[0],
        };
        self.materials[id as usize].physical_at(&self.textures, hit.uv)
    }

    /// The clear coat over the material at a surface point, if it has one.
    #[inline]
    pub fn clearcoat(&self, hit: &SurfaceHit) -> Option<crate::description::ClearCoat> {
        let material = match hit.material {
            MaterialRef::One(id) => &self.materials[id as usize],
            MaterialRef::Blend { .. } => return None,
        };
        let mut coat = material.clearcoat?;
        if let Some(maps) = &material.clearcoat_maps {
            if let Some(weight) = &maps.weight {
                coat.weight = weight.eval(&self.textures, hit.uv).x.clamp(0.0, 1.0);
            }
            if let Some(roughness) = &maps.roughness {
                let r = roughness.eval(&self.textures, hit.uv).y.clamp(0.0, 1.0);
                coat.alpha = r * r;
            }
        }
        Some(coat)
    }

    /// Whether some material has a clear coat.
    #[inline]
    pub fn has_clearcoats(&self) -> bool {
        self.coats
    }

    /// The emitted radiance (`emissive`) at a surface point.
    #[inline]
    pub fn emission(&self, hit: &SurfaceHit) -> Vec3 {
        match hit.material {
            MaterialRef::One(id) => self.materials[id as usize].emissive.eval(&self.textures, hit.uv),
            MaterialRef::Blend { .. } => self.phong(hit).emissive,
        }
    }

    /// Whether nothing blocks the segment from a surface point towards `wi` for `distance`.
    /// Every surface blocks, glass included (the physical model's light through glass arrives
    /// as caustics).
    pub fn unoccluded(&self, hit: &SurfaceHit, wi: Vec3, distance: f32) -> bool {
        !self.blocks(&self.shadow_ray(hit, wi, distance, u32::MAX))
    }

    /// The segment [`Scene::unoccluded`] tests, passing over primitive `own` (`u32::MAX`: none;
    /// else the light whose point the segment ends on, when nothing of it can lie in between).
    #[inline(always)]
    pub fn shadow_ray(&self, hit: &SurfaceHit, wi: Vec3, distance: f32, own: u32) -> ShadowRay {
        let (point, origin) = (hit.point, hit.ray_origin(wi));
        let t_max = if distance.is_finite() {
            (distance - (origin - point).length()) * (1.0 - 1e-5)
        } else {
            f32::INFINITY
        };
        ShadowRay {
            ray: Ray::new(origin, wi),
            t_max,
            own,
        }
    }

    /// Whether something blocks `shadow`.
    #[inline(always)]
    pub fn blocks(&self, shadow: &ShadowRay) -> bool {
        self.blocked(&shadow.ray, shadow.t_max, shadow.own)
    }

    /// Whether shadow rays can be tested many at once ([`Scene::blocks_each`]) for less than
    /// one by one: the triangles' tree is larger than the caches (within them, a shadow ray
    /// walks what its camera ray just brought in, and the bookkeeping costs what the stream
    /// saves), and no surface is passed over by what it is (a cut-out, a boundary between
    /// media).
    pub fn shadows_stream(&self) -> bool {
        let large = self.triangle_bvh.walks() && self.triangle_bvh.fetches_ahead();
        large && !self.cutouts && !self.boundaries && !self.has_media()
    }

    /// Whether something blocks each of `shadows`, into `blocked` (one per ray): [`Scene::blocks`]
    /// ray by ray, with the same answers; the triangles are tested in an any-hit stream where
    /// [`Scene::shadows_stream`] holds.
    ///
    /// # Panics
    /// If `blocked` and `shadows` differ in length.
    pub fn blocks_each(&self, shadows: &[ShadowRay], blocked: &mut [bool]) {
        assert_eq!(shadows.len(), blocked.len(), "one answer per shadow ray");
        let n_shapes = self.shapes.len() as u32;
        // A segment ending on a triangle has to pass over it: the stream cannot, so it goes alone.
        let alone = |s: &ShadowRay| s.own != u32::MAX && s.own >= n_shapes;
        if !self.shadows_stream() {
            for (s, b) in shadows.iter().zip(blocked.iter_mut()) {
                *b = self.blocks(s);
            }
            return;
        }
        for (s, b) in shadows.iter().zip(blocked.iter_mut()) {
            *b = if alone(s) {
                self.blocks(s)
            } else {
                self.shape_blocks(&s.ray, s.t_max, s.own)
            };
        }
        let rays: Vec<Ray> = shadows.iter().map(|s| s.ray).collect();
        // Settled rays walk nothing: an empty segment meets no box.
        let t_max = |i: usize| {
            if blocked[i] || alone(&shadows[i]) {
                0.0
            } else {
                shadows[i].t_max
            }
        };
        let mut triangles = vec![false; shadows.len()];
        self.triangle_bvh.any_hits_within(&rays, t_max, &mut triangles);
        for (b, t) in blocked.iter_mut().zip(triangles) {
            *b |= t;
        }
    }

    /// Whether a surface other than primitive `own` (`u32::MAX`: none) and other than a
    /// boundary between media meets `ray` in `(0, t_max)`.
    #[inline]
    fn blocked(&self, ray: &Ray, t_max: f32, own: u32) -> bool {
        let n_shapes = self.shapes.len() as u32;
        self.shape_blocks(ray, t_max, own)
            || self.triangle_bvh.each_hit(ray, t_max, |h| {
                n_shapes + h.prim != own
                    && !self.is_hole(ray, &h)
                    && !(self.boundaries && self.is_boundary(&self.triangle_intersection(h)))
            })
    }

    /// [`Scene::blocked`]'s shapes alone.
    #[inline(always)]
    fn shape_blocks(&self, ray: &Ray, t_max: f32, own: u32) -> bool {
        let n_shapes = self.shapes.len() as u32;
        // `own` is passed over before it is intersected: the segment ends on it, so the test
        // would find it on nearly every call only to throw the hit away.
        let blocks = |prim: u32| {
            prim != own
                && self
                    .intersect_shape(prim, ray, t_max)
                    .is_some_and(|h| !self.is_boundary(&h))
        };
        match &self.shape_packets {
            // Without boundaries a shape the packets find blocks: its own test is theirs.
            Some(packets) if !self.boundaries && own < n_shapes => packets.each_except(ray, t_max, own, |_| true),
            Some(packets) if !self.boundaries => packets.each(ray, t_max, |_| true),
            Some(packets) => packets.each_except(ray, t_max, own, blocks),
            None => self.shape_bvh.any_hit(ray, t_max, |prim, _| blocks(prim)),
        }
    }

    /// World bounds of everything.
    pub fn bounds(&self) -> Aabb {
        self.shape_bvh.bounds().union(self.triangle_bvh.bounds())
    }

    /// Number of primitives (shapes plus triangles).
    pub fn primitive_count(&self) -> usize {
        self.shapes.len() + self.triangles.len()
    }

    /// Whether a triangle hit falls in a cut-out of its mesh, where rays pass through: the
    /// material's coverage there is below its cutoff or, without one, below a number drawn from
    /// the ray and the triangle (the same each time the same ray meets it).
    #[inline]
    fn is_hole(&self, ray: &Ray, h: &TriangleBvhHit) -> bool {
        if !self.cutouts {
            return false;
        }
        let tri_ref = self.triangle_refs[h.prim as usize];
        let mesh = &self.meshes[tri_ref.mesh as usize];
        let Some(alpha) = &self.materials[mesh.material as usize].alpha else {
            return false;
        };
        let coverage = alpha
            .coverage
            .eval(&self.textures, mesh.uv_at(tri_ref.index, h.u, h.v))
            .x;
        match alpha.cutoff {
            Some(cutoff) => coverage < cutoff,
            None => {
                let bits = [ray.origin.to_array(), ray.dir.to_array()]
                    .iter()
                    .flatten()
                    .fold(u64::from(h.prim), |acc, c| {
                        crate::sampling::mix64(acc ^ u64::from(c.to_bits()))
                    });
                ((bits >> 40) as f32 / (1u64 << 24) as f32) >= coverage
            }
        }
    }

    /// The closest hit in `(0, t_max)` given `triangle`, the tree's nearest triangle hit:
    /// the nearest solid triangle's or a shape's.
    #[inline]
    fn closest_of(&self, ray: &Ray, t_max: f32, triangle: Option<TriangleBvhHit>) -> Option<Intersection> {
        let triangle = self
            .solid_triangle(ray, t_max, triangle)
            .map(|h| self.triangle_intersection(h));
        self.closest_shape(ray, t_max, triangle)
    }

    /// The nearest triangle hit in `(0, t_max)` not in a cut-out, given the nearest `hit` of all.
    #[inline(always)]
    fn solid_triangle(&self, ray: &Ray, t_max: f32, hit: Option<TriangleBvhHit>) -> Option<TriangleBvhHit> {
        let hit = hit?;
        if !self.is_hole(ray, &hit) {
            return Some(hit);
        }
        self.solid_behind_hole(ray, t_max)
    }

    /// The nearest triangle hit in `(0, t_max)` not in a cut-out, where the nearest of all is in
    /// one. Rare: every hit along the ray, the nearest solid one kept.
    #[cold]
    #[inline(never)]
    fn solid_behind_hole(&self, ray: &Ray, t_max: f32) -> Option<TriangleBvhHit> {
        let mut best: Option<TriangleBvhHit> = None;
        self.triangle_bvh.each_hit(ray, t_max, |h| {
            if best.is_none_or(|b| h.t < b.t) && !self.is_hole(ray, &h) {
                best = Some(h);
            }
            false
        });
        best
    }

    /// The closest hit in `(0, t_max)`.
    #[inline]
    pub fn intersect(&self, ray: &Ray, t_max: f32) -> Option<Intersection> {
        self.closest_of(ray, t_max, self.triangle_bvh.closest_hit(ray, t_max))
    }

    /// Whether rays traced together ([`Scene::intersect_stream`]) are faster than one by one:
    /// the triangles' tree is larger than the caches, so the stream overlaps its misses, or
    /// its streams sort without branches.
    pub fn streams_pay(&self) -> bool {
        self.triangle_bvh.walks() && (self.triangle_bvh.fetches_ahead() || self.triangle_bvh.streams_sort())
    }

    /// The closest hit in `(0, ∞)` of each ray, into `hits` (one per ray): [`Scene::intersect`]
    /// ray by ray, with the same answers. The triangles' tree is walked for several rays at once
    /// when it is large ([`TriangleBvh::closest_hits`]), so their cache misses overlap; a few
    /// triangles, and shapes in packets, are tested a ray a lane
    /// ([`TriangleBvh::closest_each`], [`ShapePackets::closest_each`]): a floor and a glass ball
    /// cost a ray a fraction of testing each ray alone.
    ///
    /// # Panics
    /// If `hits` and `rays` differ in length.
    pub fn intersect_stream(&self, rays: &[Ray], hits: &mut [Option<Intersection>]) {
        assert_eq!(rays.len(), hits.len(), "one hit slot per ray");
        // The triangles first, then the shapes within the nearest solid one.
        let mut triangles = vec![None; rays.len()];
        if self.triangle_bvh.walks() {
            self.triangle_bvh.closest_hits(rays, f32::INFINITY, &mut triangles);
        } else if !self.triangle_bvh.is_empty() {
            self.triangle_bvh.closest_each(rays, &mut triangles);
        }
        if self.cutouts {
            for (ray, triangle) in rays.iter().zip(&mut triangles) {
                *triangle = self.solid_triangle(ray, f32::INFINITY, *triangle);
            }
        }
        let Some(packets) = &self.shape_packets else {
            for ((ray, hit), triangle) in rays.iter().zip(hits).zip(triangles) {
                let triangle = triangle.map(|h| self.triangle_intersection(h));
                *hit = self.closest_shape(ray, f32::INFINITY, triangle);
            }
            return;
        };
        let t_max: Vec<f32> = triangles.iter().map(|h| h.map_or(f32::INFINITY, |h| h.t)).collect();
        let mut picks = vec![None; rays.len()];
        packets.closest_each(rays, &t_max, &mut picks);
        for (i, (ray, hit)) in rays.iter().zip(hits).enumerate() {
            let triangle = triangles[i].map(|h| self.triangle_intersection(h));
            *hit = match picks[i] {
                None => triangle,
                pick => self.picked_shape(ray, t_max[i], triangle, pick),
            };
        }
    }

    /// The closest hit in `(0, t_max)` of the shapes and `best`, the nearest triangle's.
    #[inline(always)]
    fn closest_shape(&self, ray: &Ray, t_max: f32, best: Option<Intersection>) -> Option<Intersection> {
        let t_max = best.map_or(t_max, |h| h.t);
        match &self.shape_packets {
            Some(packets) => self.picked_shape(ray, t_max, best, packets.closest(ray, t_max)),
            None => {
                let mut best = best;
                self.shape_bvh.closest_hit(ray, t_max, |prim, t_max| {
                    let hit = self.intersect_shape(prim, ray, t_max)?;
                    best = Some(hit);
                    Some(hit.t)
                });
                best
            }
        }
    }

    /// [`Scene::closest_shape`] given the packets' `pick` for `(0, t_max)`, `t_max` bounded by
    /// `best`. The packets find the shape and `t` by its own test's arithmetic; the record at
    /// that `t` is its test's. Should there be none, the hierarchy decides.
    #[inline]
    fn picked_shape(
        &self,
        ray: &Ray,
        t_max: f32,
        best: Option<Intersection>,
        pick: Option<(u32, f32)>,
    ) -> Option<Intersection> {
        let Some((prim, t)) = pick else {
            return best;
        };
        match self.shapes[prim as usize].packet_hit_at(ray, t) {
            Some(hit) => Some(shape_intersection(prim, hit)),
            None => self.hierarchy_shape(ray, t_max, best),
        }
    }

    /// The closest shape hit in `(0, t_max)` by the shapes' hierarchy, or `best`: where the
    /// packets' pick has no record (rare). Out of line, and written apart from
    /// [`Scene::closest_shape`]'s own walk on purpose: one walk shared by both went out of line
    /// on the hot path (a 1M-triangle scene's render 1.5% more instructions; 3.4% with it
    /// always inlined).
    #[cold]
    #[inline(never)]
    fn hierarchy_shape(&self, ray: &Ray, t_max: f32, mut best: Option<Intersection>) -> Option<Intersection> {
        self.shape_bvh.closest_hit(ray, t_max, |prim, t_max| {
            let hit = self.intersect_shape(prim, ray, t_max)?;
            best = Some(hit);
            Some(hit.t)
        });
        best
    }

    /// The closest hit along `ray` that is not only a boundary between media, and the ray it
    /// lies on (moved past the boundaries crossed; the same ray where there are none).
    #[inline]
    pub fn intersect_solid(&self, ray: &Ray) -> Option<(Ray, Intersection)> {
        let mut ray = *ray;
        for _ in 0..1024 {
            let isect = self.intersect(&ray, f32::INFINITY)?;
            if !self.is_boundary(&isect) {
                return Some((ray, isect));
            }
            if let Some(solid) = self.solid_at_boundary(&ray, &isect) {
                return Some((ray, solid));
            }
            let boundary = self.surface(&ray, &isect);
            ray = Ray::new(boundary.ray_origin(ray.dir), ray.dir);
        }
        None
    }

    /// A surface that is not a boundary within a hair of the boundary hit `isect` along `ray`
    /// (a floor that a cube of fog rests on, the cube's bottom face in the floor's plane): a
    /// walk meets that surface there, inside the medium, instead of crossing the boundary —
    /// past it, the continuing ray would start beyond the floor too. `None` without one.
    pub fn solid_at_boundary(&self, ray: &Ray, isect: &Intersection) -> Option<Intersection> {
        let point = ray.at(isect.t);
        // A hair: a relative step, in units of the ray's direction.
        let hair = 1e-4 * (1.0 + point.abs().max_element()) / ray.dir.length().max(1e-30);
        let start = (isect.t - hair).max(0.0);
        let probe = Ray::new(ray.at(start), ray.dir);
        let mut solid: Option<Intersection> = None;
        self.any_hit(&probe, isect.t + hair - start, |h| {
            if !self.is_boundary(h) && solid.is_none_or(|s| h.t < s.t) {
                solid = Some(*h);
            }
            false
        });
        solid.map(|s| Intersection { t: start + s.t, ..s })
    }

    /// Calls `visit(hit)` for each primitive the segment `(0, t_max)` meets (its nearest hit
    /// within the segment), until `visit` returns true; returns whether it did.
    pub fn any_hit(&self, ray: &Ray, t_max: f32, mut visit: impl FnMut(&Intersection) -> bool) -> bool {
        let mut shape = |prim: u32| self.intersect_shape(prim, ray, t_max).is_some_and(|h| visit(&h));
        let shapes = match &self.shape_packets {
            Some(packets) => packets.each(ray, t_max, &mut shape),
            None => self.shape_bvh.any_hit(ray, t_max, |prim, _| shape(prim)),
        };
        shapes
            || self.triangle_bvh.each_hit(ray, t_max, |h| {
                !self.is_hole(ray, &h) && visit(&self.triangle_intersection(h))
            })
    }

    /// A triangle hit as an intersection.
    #[inline]
    fn triangle_intersection(&self, h: TriangleBvhHit) -> Intersection {
        Intersection {
            t: h.t,
            prim: self.shapes.len() as u32 + h.prim,
            normal_or_bary: Vec3::new(h.u, h.v, 0.0),
            uv: Vec2::ZERO,
            part: 0,
            local_point: Vec3::ZERO,
        }
    }

    /// The nearest hit of shape `prim` in `(0, t_max)`.
    #[inline]
    fn intersect_shape(&self, prim: u32, ray: &Ray, t_max: f32) -> Option<Intersection> {
        let hit = self.shapes[prim as usize].intersect_object_normal(ray, t_max)?;
        Some(shape_intersection(prim, hit))
    }

    /// The nearest hit of one primitive (shapes first, then triangles) in `(0, t_max)`.
    #[inline]
    fn intersect_prim(&self, prim: u32, ray: &Ray, t_max: f32) -> Option<Intersection> {
        let n_shapes = self.shapes.len() as u32;
        if prim < n_shapes {
            self.intersect_shape(prim, ray, t_max)
        } else {
            let hit = self.triangles[(prim - n_shapes) as usize].intersect(ray, t_max)?;
            let hit = TriangleBvhHit {
                t: hit.t,
                prim: prim - n_shapes,
                u: hit.u,
                v: hit.v,
            };
            (!self.is_hole(ray, &hit)).then(|| self.triangle_intersection(hit))
        }
    }

    /// The material id of a part of shape `i`: a CSG solid's leaf, or the shape's own.
    #[inline]
    fn part_material(&self, i: usize, part: u32) -> u32 {
        match &self.shapes[i].kind {
            crate::geometry::ShapeKind::Csg(csg) => csg.materials()[part as usize],
            _ => self.shape_materials[i],
        }
    }

    /// Every material id of shape `i` (a CSG solid's leaves', or its own).
    fn shape_material_ids(&self, i: usize) -> &[u32] {
        match &self.shapes[i].kind {
            crate::geometry::ShapeKind::Csg(csg) => csg.materials(),
            _ => std::slice::from_ref(&self.shape_materials[i]),
        }
    }

    /// The primitive's `transmissive` colour when it is the same all over it (no texture, no
    /// per-vertex materials): shadow rays then need no surface evaluation.
    #[inline]
    pub fn uniform_transmissive(&self, prim: u32) -> Option<Vec3> {
        let n_shapes = self.shapes.len() as u32;
        let material = if prim < n_shapes {
            let ids = self.shape_material_ids(prim as usize);
            let first = self.materials[ids[0] as usize].transmissive;
            if ids.iter().any(|&id| self.materials[id as usize].transmissive != first) {
                return None;
            }
            ids[0]
        } else {
            let mesh = &self.meshes[self.triangle_refs[(prim - n_shapes) as usize].mesh as usize];
            if mesh.vertex_materials.is_some() {
                return None;
            }
            mesh.material
        };
        match self.materials[material as usize].transmissive {
            crate::material::Channel::Constant(c) => Some(c),
            crate::material::Channel::Texture(_) => None,
        }
    }

    /// The next crossing of the same primitive beyond `hit` (a closed shape is crossed twice),
    /// as an intersection along the same `ray` with `t < t_max`. Triangles are crossed once.
    pub fn next_crossing(&self, ray: &Ray, hit: &Intersection, t_max: f32) -> Option<Intersection> {
        if hit.prim as usize >= self.shapes.len() {
            return None;
        }
        let shape = &self.shapes[hit.prim as usize];
        // Restart just past the hit, by a step relative to the hit's magnitude.
        let point = ray.at(hit.t);
        let step = 1e-4 * (1.0 + point.abs().max_element()) / ray.dir.length().max(1e-30);
        let t0 = hit.t + step;
        if t0 >= t_max {
            return None;
        }
        let next = shape.intersect_object_normal(&Ray::new(ray.at(t0), ray.dir), t_max - t0)?;
        Some(shape_intersection(hit.prim, ShapeHit { t: t0 + next.t, ..next }))
    }

    /// Asks the cache for the first things [`Scene::surface`] reads of a triangle `hit`: its
    /// reference to its mesh, and its copy of the triangle (for the geometric normal). A hint,
    /// for a wave of hits shaded one after another: it changes no result.
    #[inline]
    pub(crate) fn prefetch_reference(&self, hit: &Intersection) {
        let index = self.hit_triangle_index(hit);
        if let Some(tri_ref) = self.triangle_refs.get(index) {
            crate::accel::lanes::prefetch(tri_ref);
            // Its first and last bytes: a triangle may straddle two cache lines.
            let triangle = self.triangles.as_ptr().wrapping_add(index).cast::<u8>();
            crate::accel::lanes::prefetch(triangle);
            crate::accel::lanes::prefetch(triangle.wrapping_add(std::mem::size_of::<Triangle>() - 1));
        }
    }

    /// [`Scene::prefetch_reference`]'s next step, once the reference is at hand: the triangle's
    /// vertex indices.
    #[inline]
    pub(crate) fn prefetch_indices(&self, hit: &Intersection) {
        if let Some(tri_ref) = self.hit_triangle_ref(hit) {
            let indices = &self.meshes[tri_ref.mesh as usize].indices;
            crate::accel::lanes::prefetch(indices.as_ptr().wrapping_add(tri_ref.index as usize));
        }
    }

    /// The mesh reference of a triangle `hit` (`None` for a shape's).
    #[inline]
    fn hit_triangle_ref(&self, hit: &Intersection) -> Option<&TriangleRef> {
        self.triangle_refs.get(self.hit_triangle_index(hit))
    }

    /// The triangle number of `hit` (out of range for a shape's).
    #[inline]
    fn hit_triangle_index(&self, hit: &Intersection) -> usize {
        hit.prim.wrapping_sub(self.shapes.len() as u32) as usize
    }

    /// Full shading data for an intersection found along `ray`.
    pub fn surface(&self, ray: &Ray, hit: &Intersection) -> SurfaceHit {
        let n_shapes = self.shapes.len() as u32;
        if hit.prim < n_shapes {
            // From the point put on the surface in object space: `ray.at(t)` would carry the
            // error of `t`, which a non-uniform scale can turn into shadow acne.
            let shape = &self.shapes[hit.prim as usize];
            let (point, point_error) = shape.world_point(hit.local_point);
            let normal = shape.world_normal(hit.normal_or_bary);
            return SurfaceHit {
                t: hit.t,
                point,
                point_error,
                geometric_normal: normal,
                shading_normal: normal,
                uv: hit.uv,
                material: MaterialRef::One(self.choose(
                    self.part_material(hit.prim as usize, hit.part),
                    point,
                    ray.dir,
                    hit.uv,
                )),
                object: ObjectRef::Shape(hit.prim),
                prim: hit.prim,
                media: Media::VACUUM,
            };
        }
        let tri_index = (hit.prim - n_shapes) as usize;
        let tri_ref = self.triangle_refs[tri_index];
        let mesh = &self.meshes[tri_ref.mesh as usize];
        let [i0, i1, i2] = mesh.indices[tri_ref.index as usize].map(|i| i as usize);
        let (b1, b2) = (hit.normal_or_bary.x, hit.normal_or_bary.y);
        let w = [1.0 - b1 - b2, b1, b2];
        let uv = mesh.uv_at(tri_ref.index, b1, b2);
        let mut geometric_normal = self.triangles[tri_index].geometric_normal();
        let shading_normal = match &mesh.normals {
            Some(n) => {
                let s = (n[i0] * w[0] + n[i1] * w[1] + n[i2] * w[2]).normalize_or_zero();
                if s == Vec3::ZERO {
                    geometric_normal
                } else {
                    // Trust the file's normals for which side is outside.
                    if s.dot(geometric_normal) < 0.0 {
                        geometric_normal = -geometric_normal;
                    }
                    s
                }
            }
            None => geometric_normal,
        };
        let point = ray.at(hit.t);
        let (material, id) = match &mesh.vertex_materials {
            Some(ids) => (
                MaterialRef::Blend {
                    ids: [ids[i0], ids[i1], ids[i2]],
                    weights: w,
                },
                mesh.material,
            ),
            None => {
                let id = self.choose(mesh.material, point, ray.dir, uv);
                (MaterialRef::One(id), id)
            }
        };
        let shading_normal = match (&mesh.tangents, self.materials[id as usize].normal_map) {
            (Some(t), Some((texture, scale))) => {
                let tangent = t[i0] * w[0] + t[i1] * w[1] + t[i2] * w[2];
                let sign = if t[i0].w < 0.0 { -1.0 } else { 1.0 };
                let texel = self.textures[texture as usize].lookup(uv);
                crate::geometry::tangents::bend(
                    shading_normal,
                    geometric_normal,
                    tangent.truncate(),
                    sign,
                    texel,
                    scale,
                )
            }
            _ => shading_normal,
        };
        SurfaceHit {
            t: hit.t,
            point,
            point_error: Vec3::ZERO,
            geometric_normal,
            shading_normal,
            uv,
            material,
            object: ObjectRef::Mesh(tri_ref.mesh),
            prim: hit.prim,
            media: Media::VACUUM,
        }
    }

    /// The primitives other than `except` whose bounds come within the cube of half-size `r`
    /// around `point`: only they can stand between the point and photons gathered nearby.
    /// Shapes whose surface provably stays farther than `r` are left out too.
    pub fn occluders_near(&self, point: Vec3, r: f32, except: u32) -> Occluders {
        let query = Aabb::new(point - Vec3::splat(r), point + Vec3::splat(r));
        // Segments from the point end at photons within `r`, both ends moved off their surfaces.
        let reach = r * (1.0 + 1e-3) + 2e-4 * (1.0 + point.abs().max_element());
        let n_shapes = self.shapes.len() as u32;
        let mut found = Occluders::default();
        let overflowed = self.shape_bvh.any_overlap(&query, |prim| {
            if prim != except && self.shapes[prim as usize].may_come_within(point, reach) {
                found.push(prim);
            }
            found.overflowed
        });
        if !overflowed {
            self.triangle_bvh.any_overlap(&query, |tri| {
                let prim = n_shapes + tri;
                if prim != except && self.triangles[tri as usize].plane_distance(point) <= reach {
                    found.push(prim);
                }
                found.overflowed
            });
        }
        found
    }

    /// The segments from one gather point `a` (on a surface with normal `a_normal`) to the
    /// photons around it, tested against `occluders` ([`Scene::occluders_near`]).
    pub fn segments_from<'a>(&'a self, occluders: &'a Occluders, a: Vec3, a_normal: Vec3) -> SegmentsFrom<'a> {
        let from = crate::math::offset_along(a, a_normal);
        let n_shapes = self.shapes.len() as u32;
        let inside = occluders.prims().iter().enumerate().fold(0u32, |mask, (i, &prim)| {
            let holds = prim < n_shapes && self.shapes[prim as usize].interior_holds_point(from);
            mask | (u32::from(holds) << i)
        });
        SegmentsFrom {
            scene: self,
            occluders,
            from,
            inside,
        }
    }

    /// Whether the straight segment between two surface points is free of geometry; each end is
    /// moved off its surface to the side its normal points to (the side it is seen or lit from),
    /// whatever the segment's direction, so a segment along a floor stays above it.
    pub fn segment_clear(&self, a: Vec3, a_normal: Vec3, b: Vec3, b_normal: Vec3) -> bool {
        segment_ray(a, a_normal, b, b_normal)
            .is_none_or(|(ray, len)| !self.any_hit(&ray, len, |h| !self.is_boundary(h)))
    }

    /// The material id of an object (a mesh's base material).
    pub fn object_material(&self, object: ObjectRef) -> u32 {
        match object {
            ObjectRef::Shape(i) => self.shape_materials[i as usize],
            ObjectRef::Mesh(i) => self.meshes[i as usize].material,
        }
    }

    /// Every object with its world bounds, shapes first.
    pub fn objects(&self) -> impl Iterator<Item = (ObjectRef, Aabb)> + '_ {
        let shapes = self
            .shapes
            .iter()
            .enumerate()
            .map(|(i, s)| (ObjectRef::Shape(i as u32), s.bounds));
        let meshes = self
            .meshes
            .iter()
            .enumerate()
            .map(|(i, m)| (ObjectRef::Mesh(i as u32), m.bounds));
        shapes.chain(meshes)
    }

    /// Whether an object can reflect or refract specularly (anywhere on it).
    pub fn object_is_specular(&self, object: ObjectRef) -> bool {
        self.any_material_of(object, Material::is_specular)
    }

    /// Whether a caustic can show on an object: it is diffuse or glossy somewhere.
    pub fn object_receives(&self, object: ObjectRef) -> bool {
        self.any_material_of(object, Material::may_receive)
    }

    /// Whether any material the object uses (a mesh's per-vertex ones included) passes `test`.
    fn any_material_of(&self, object: ObjectRef, test: impl Fn(&Material) -> bool) -> bool {
        match object {
            ObjectRef::Mesh(i) => {
                let mesh = &self.meshes[i as usize];
                match &mesh.vertex_materials {
                    Some(ids) => ids.iter().any(|&id| self.material_or_part(id, &test, MAX_MIX_DEPTH)),
                    None => self.material_or_part(mesh.material, &test, MAX_MIX_DEPTH),
                }
            }
            ObjectRef::Shape(i) => self
                .shape_material_ids(i as usize)
                .iter()
                .any(|&id| self.material_or_part(id, &test, MAX_MIX_DEPTH)),
        }
    }

    /// Whether material `id`, or a part of it if it is a mix, passes `test`.
    fn material_or_part(&self, id: u32, test: &dyn Fn(&Material) -> bool, depth: u32) -> bool {
        let m = &self.materials[id as usize];
        test(m)
            || depth > 0
                && m.mix.is_some_and(|mix| {
                    mix.materials
                        .iter()
                        .any(|&part| self.material_or_part(part, test, depth - 1))
                })
    }

    /// The material a surface point of material `id` shows: `id` itself, or for a mix one of
    /// its parts, chosen by a hash of the point and the ray's direction (the same point seen
    /// along the same ray always shows the same part; pbrt-v4 chooses so).
    #[inline(always)]
    fn choose(&self, id: u32, point: Vec3, dir: Vec3, uv: Vec2) -> u32 {
        if !self.mixes {
            return id;
        }
        self.choose_mixed(id, point, dir, uv)
    }

    #[inline(never)]
    fn choose_mixed(&self, id: u32, point: Vec3, dir: Vec3, uv: Vec2) -> u32 {
        let mut id = id;
        let words = [point.x, point.y, point.z, dir.x, dir.y, dir.z].map(f32::to_bits);
        for level in 0..MAX_MIX_DEPTH {
            let Some(mix) = self.materials[id as usize].mix else {
                break;
            };
            let amount = mix.amount.eval(&self.textures, uv).x;
            let hash = words.iter().fold(u64::from(level) ^ u64::from(id) << 32, |h, &w| {
                crate::sampling::mix64(h ^ u64::from(w))
            });
            let u = (hash >> 40) as f32 / (1u64 << 24) as f32;
            id = mix.materials[usize::from(u < amount)];
        }
        id
    }
}

/// The unit ray from `a` to `b` and its length, each end moved off its surface along its normal;
/// `None` when the ends coincide.
fn segment_ray(a: Vec3, a_normal: Vec3, b: Vec3, b_normal: Vec3) -> Option<(Ray, f32)> {
    let from = crate::math::offset_along(a, a_normal);
    let to = crate::math::offset_along(b, b_normal);
    let d = to - from;
    let len = d.length();
    (len > 0.0).then(|| (Ray::new(from, d / len), len))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fixed stream of numbers in [−1, 1) (xorshift).
    fn uniform_pm1() -> impl FnMut() -> f32 {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 40) as f32 / (1u64 << 24) as f32 * 2.0 - 1.0
        }
    }

    /// Shadow rays tested together block where each alone does: segments from a bumpy sheet of
    /// 135,000 triangles (streamed) towards points around it, short, long and unending, passing
    /// over nothing, over a ball or over one of the sheet's triangles.
    #[test]
    fn shadow_rays_together_block_as_alone() {
        let ball = "translate(0, 0, 1, scale(0.5, sphere { material = { diffuse = (1,1,1); } }))";
        let scene = build::test_scene(&format!("{ball}\n{}", build::bumpy_sheet(260)));
        assert!(scene.shadows_stream());
        let n_shapes = scene.shapes().len() as u32;
        let mut u = uniform_pm1();
        let shadows: Vec<ShadowRay> = (0..3000)
            .map(|i| {
                let origin = Vec3::new(u() * 2.0, u() * 2.0, 0.4 + 0.4 * u());
                let to = Vec3::new(u() * 3.0, u() * 3.0, u() * 2.0) - origin;
                let own = [u32::MAX, 0, n_shapes + (i as u32 * 37) % 135_200][i % 3];
                let t_max = [to.length(), f32::INFINITY, 0.0, 0.05][i % 4];
                ShadowRay {
                    ray: Ray::new(origin, to.normalize()),
                    t_max,
                    own,
                }
            })
            .collect();
        let mut blocked = vec![false; shadows.len()];
        scene.blocks_each(&shadows, &mut blocked);
        for (s, b) in shadows.iter().zip(&blocked) {
            assert_eq!(*b, scene.blocks(s), "{s:?}");
        }
        let count = blocked.iter().filter(|&&b| b).count();
        assert!((300..2700).contains(&count), "{count} of 3000 blocked");
    }

    /// Shapes and a mesh in one scene: the closest hit and the hits visited by `any_hit` are
    /// those of testing every primitive, whichever hierarchy holds it.
    #[test]
    fn queries_match_testing_every_primitive() {
        let scene = build::test_scene(
            "sphere { material = { diffuse = (1,1,1); } }
             translate(1.5, 0, 0, box { material = { diffuse = (1,1,1); } })
             scale(2, 2, 2, cone { height = 1; bottom_radius = 0.5; top_radius = 0.2; material = { diffuse = (1,1,1); } })
             polymesh { points = ((-2,-2,-1), (2,-2,-1), (2,2,-1), (-2,2,-1), (0,0,1.2), (-1,0.5,-0.5));
                        faces = ((0,1,2), (0,2,3), (0,1,4), (1,2,4), (2,3,4), (3,0,4), (5,4,0), (5,5,1));
                        material = { diffuse = (1,1,1); } }",
        );
        assert!(!scene.shapes().is_empty() && scene.triangles().len() >= 7);
        let mut f = uniform_pm1();
        let prims = scene.primitive_count() as u32;
        let mut hits = 0;
        for _ in 0..4000 {
            let origin = Vec3::new(f(), f(), f()) * 4.0;
            let target = Vec3::new(f(), f(), f()) * 1.5;
            let ray = Ray::new(origin, target - origin);
            let t_max = if f() > 0.5 { f32::INFINITY } else { 0.5 + f().abs() };
            let every: Vec<Intersection> = (0..prims)
                .filter_map(|p| scene.intersect_prim(p, &ray, t_max))
                .collect();
            let nearest = every.iter().map(|h| h.t).fold(f32::INFINITY, f32::min);
            let got = scene.intersect(&ray, t_max);
            match got {
                Some(h) => {
                    assert_eq!(h.t, nearest, "{ray:?}");
                    assert!(every.contains(&h), "{h:?} is one primitive's own hit");
                    hits += 1;
                }
                None => assert!(every.is_empty(), "{ray:?} missed {every:?}"),
            }
            let mut visited = Vec::new();
            assert!(!scene.any_hit(&ray, t_max, |h| {
                visited.push(*h);
                false
            }));
            visited.sort_by_key(|h| h.prim);
            assert_eq!(visited, every, "{ray:?}");
        }
        assert!(hits > 1000, "{hits} hits");
    }

    /// A wave of rays traced together finds, ray by ray and to the bit, what each ray finds
    /// alone: over a mesh large enough to walk its tree, over two triangles tested without
    /// one and over none, beside shapes in a hierarchy (a ball and a box) or in packets
    /// (squares and balls, tested a ray a lane where the triangles do not walk), zero
    /// directions included.
    #[test]
    fn rays_traced_together_find_what_each_finds_alone() {
        let floor = "polymesh { points = ((-2,-2,0),(2,-2,0),(2,2,0),(-2,2,0)); faces = ((0,1,2),(0,2,3));
                     material = { diffuse = (1,1,1); } }";
        let in_hierarchy = "translate(0.5, 0, 0.2, scale(0.6, 0.6, 0.6, sphere { material = { diffuse = (1,1,1); } }))
                            translate(-1, 1, 0, box { material = { diffuse = (1,1,1); } })";
        let in_packets = "translate(0.5, 0, 0.2, scale(0.6, sphere { material = { diffuse = (1,1,1); } }))
                          translate(-1, 1, 0.3, scale(0.4, sphere { material = { diffuse = (1,1,1); } }))
                          translate(0, 0, -0.5, scale(3, square { material = { diffuse = (1,1,1); } }))
                          translate(1, -1, 0.5, rotate(1, 0, 0, 0.7, scale(1.5, square { material = { diffuse = (1,1,1); } })))
                          translate(-1.5, 0, 0.5, rotate(0, 1, 0, 1.2, scale(2, square { material = { diffuse = (1,1,1); } })))";
        // A lamp alone is in a packet too (a wave's rays test it eight at a time).
        let lone = "translate(0.5, 0, 0.2, scale(0.6, sphere { material = { diffuse = (1,1,1); } }))";
        for (mesh, walks) in [
            (build::bumpy_sheet(12), true),
            (floor.to_string(), false),
            (String::new(), false),
        ] {
            for (shapes, packed) in [(in_hierarchy, false), (in_packets, true), (lone, true)] {
                let mut scene = build::test_scene(&format!("{mesh}\n{shapes}"));
                assert_eq!(scene.triangle_bvh.walks(), walks);
                assert_eq!(scene.shape_packets.is_some(), packed);
                let mut f = uniform_pm1();
                let mut rays: Vec<Ray> = (0..3000)
                    .map(|_| {
                        let origin = Vec3::new(f(), f(), f()) * 3.0;
                        Ray::new(origin, Vec3::new(f(), f(), f()) * 1.5 - origin)
                    })
                    .collect();
                rays.insert(17, Ray::new(Vec3::new(0.5, 0.0, 0.2), Vec3::ZERO));
                rays.push(Ray::new(Vec3::ZERO, Vec3::ZERO));
                let mut together = vec![None; rays.len()];
                scene.intersect_stream(&rays, &mut together);
                let alone: Vec<Option<Intersection>> = rays.iter().map(|r| scene.intersect(r, f32::INFINITY)).collect();
                assert_eq!(together, alone);
                // The packets pick what the shapes' hierarchy picks, with the same records.
                let packets = scene.shape_packets.take();
                for (i, (ray, hit)) in rays.iter().zip(&alone).enumerate() {
                    assert_eq!(*hit, scene.intersect(ray, f32::INFINITY), "ray {i}");
                }
                scene.shape_packets = packets;
                let n_shapes = scene.shapes().len() as u32;
                let hits = |triangle: bool| {
                    alone
                        .iter()
                        .flatten()
                        .filter(|h| (h.prim >= n_shapes) == triangle)
                        .count()
                };
                assert!(
                    (hits(true) > 300 || mesh.is_empty()) && hits(false) > 300,
                    "{} triangle and {} shape hits",
                    hits(true),
                    hits(false)
                );
            }
        }
    }

    /// Segments from a gather point, tested against the primitives near it and skipping those
    /// whose convex interior holds both ends, find what testing the whole scene finds: inside
    /// and outside a ring (an open cylinder), a box and a sphere.
    #[test]
    fn segments_from_a_point_match_testing_the_whole_scene() {
        let scene = build::test_scene(
            "scale(3, 3, 2, cone { capped = false; height = 1; bottom_radius = 0.5; top_radius = 0.5; material = { diffuse = (1,1,1); } })
             translate(0, 0, -0.5, scale(8, 8, 1, box { material = { diffuse = (1,1,1); } }))
             translate(2.5, 0, 1, scale(0.4, 0.4, 0.4, sphere { material = { diffuse = (1,1,1); } }))",
        );
        let mut f = uniform_pm1();
        let ring = &scene.shapes[0];
        let (mut blocked, mut held) = (0, 0);
        for _ in 0..20_000 {
            let mut point = || Vec3::new(2.2 * f(), 2.2 * f(), 1.0 + f());
            let (a, b) = (point(), point());
            let (na, nb) = (
                Vec3::new(f(), f(), f()).normalize_or(Vec3::Z),
                Vec3::new(f(), f(), f()).normalize_or(Vec3::Z),
            );
            let occluders = scene.occluders_near(a, 1.01 * a.distance(b) + 1e-3, u32::MAX);
            let clear = scene.segments_from(&occluders, a, na).clear_to(b, nb);
            assert_eq!(clear, scene.segment_clear(a, na, b, nb), "{a} {b}");
            blocked += usize::from(!clear);
            held += usize::from(ring.interior_holds(a, b));
        }
        assert!(
            blocked > 2_000 && held > 2_000,
            "{blocked} blocked, {held} inside the ring"
        );
    }

    /// Texture coordinates are computed for shapes whose material reads a texture, and left at
    /// zero for the others (which do not need them).
    #[test]
    fn texture_coordinates_only_where_a_texture_reads_them() {
        let dir = std::env::temp_dir().join(format!("caustica-uv-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        // Red on the left half (u < 0.5), blue on the right.
        let mut image = image::RgbImage::new(2, 1);
        image.put_pixel(0, 0, image::Rgb([255, 0, 0]));
        image.put_pixel(1, 0, image::Rgb([0, 0, 255]));
        image.save(dir.join("halves.png")).unwrap();
        let text = "SBT-raytracer 1.0
            camera { position = (0,0,5); viewdir = (0,0,-1); updir = (0,1,0); }
            translate(-1.5, 0, 0, sphere { material = { diffuse = map(\"halves.png\"); } })
            translate(1.5, 0, 0, sphere { material = { diffuse = (0.5, 0.5, 0.5); } })
            translate(0, 2, 0, cone { height = 1; bottom_radius = 0.5; top_radius = 0.5; capped = false;
                                      material = { specular = map(\"halves.png\"); } })
            translate(0, -2, 0, cone { height = 1; bottom_radius = 0.5; top_radius = 0.5; capped = false;
                                       material = { diffuse = (1, 1, 1); } })";
        let scene = crate::loader::from_text(text, &dir, &Default::default());
        std::fs::remove_dir_all(&dir).unwrap();
        let scene = scene.unwrap();
        assert_eq!(
            scene.shapes().iter().map(|s| s.needs_uv).collect::<Vec<_>>(),
            [true, false, true, false]
        );
        // Rays along −y meet each shape at its +y side: a quarter turn around z, so u = 0.25
        // (the texture's red half), halfway up (v = 0.5).
        let hit = |center: Vec3, dir: Vec3| {
            let ray = Ray::new(center - dir * 3.0, dir);
            let isect = scene.intersect(&ray, f32::INFINITY).expect("a hit");
            scene.surface(&ray, &isect)
        };
        let textured = hit(Vec3::new(-1.5, 0.0, 0.0), Vec3::new(0.0, -1.0, 0.0));
        assert!(
            (textured.uv - Vec2::new(0.25, 0.5)).abs().max_element() < 1e-5,
            "{:?}",
            textured.uv
        );
        assert_eq!(scene.phong(&textured).diffuse, Vec3::X);
        let plain = hit(Vec3::new(1.5, 0.0, 0.0), Vec3::new(0.0, -1.0, 0.0));
        assert_eq!(plain.uv, Vec2::ZERO);
        assert_eq!(scene.phong(&plain).diffuse, Vec3::splat(0.5));
        let cone = hit(Vec3::new(0.0, 2.0, 0.5), Vec3::new(0.0, -1.0, 0.0));
        assert!(
            (cone.uv - Vec2::new(0.25, 0.5)).abs().max_element() < 1e-5,
            "{:?}",
            cone.uv
        );
        let plain_cone = hit(Vec3::new(0.0, -2.0, 0.5), Vec3::new(0.0, -1.0, 0.0));
        assert_eq!(plain_cone.uv, Vec2::ZERO);
    }
}
