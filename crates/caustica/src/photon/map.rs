//! The photon map: photons in kd-tree order, and the radiance estimates both shading models make
//! from it:
//!
//! ```text
//! L(x, ωo) ≈ Σ_p f(x, ωo, ωp) Φp / (π r²)
//! ```
//!
//! (Jensen 1996, eq. 6), with the reflectance evaluated for each photon's own incoming direction
//! and a disc-shaped gather: photons whose stored normal disagrees with the receiver's, or that
//! lie off its tangent plane, do not count — light cannot bleed through a thin wall or round a
//! corner.
//!
//! - The course model ([`PhotonMap::radiance`]): by default each photon spread over its own
//!   kernel, as wide as its distance to its k-th nearest photon ([`super::kernel`]); or the k
//!   nearest photons within a largest radius ([`Estimator::Nearest`]); an optional cone filter
//!   (eq. 7), the course's Phong reflectance, and photons that other geometry hides from the
//!   point left out.
//! - The physical model: the photons within a fixed radius (progressive photon mapping,
//!   [`PhotonMap::radiance_within`]) or the k nearest (Jensen's global and caustic maps,
//!   [`PhotonMap::radiance_nearest`]), with the BSDF the camera paths use.

use super::budget::{trace_photons, PhotonSettings, PhotonStats};
use super::kd_tree::{KdTree, Neighbor};
use super::kernel::{self, Gather, Kernels, NearLeaves};
use super::{Photon, DISPERSED};
use crate::bsdf::Bsdf;
use crate::material::SurfaceParams;
use crate::math::Vec3;
use crate::progress::Control;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, SAMPLES};
use std::cell::RefCell;
use std::f32::consts::PI;

/// The course model's two radiance estimates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// Each photon spread over a kernel as wide as its distance to its k-th nearest photon on the
    /// same surface ([`super::kernel`]): the default.
    Kernels,
    /// Jensen's: the k nearest photons around the point, within the largest radius.
    Nearest,
}

/// How the radiance estimate gathers photons.
#[derive(Clone, Debug, PartialEq)]
pub struct EstimateSettings {
    /// Which estimate.
    pub estimator: Estimator,
    /// Photons per estimate: the k nearest, or the neighbour that sets a kernel's width.
    pub k: usize,
    /// Largest gather (or kernel) radius; `None` picks one from the photons
    /// ([`PhotonMap::auto_radius`]).
    pub max_radius: Option<f32>,
    /// Least kernel radius, in pixel widths where the camera path meets the surface (the
    /// kernel estimate only).
    pub min_pixels: f32,
    /// Cone filter constant (Jensen's k ≥ 1); `None` for a plain box (uniform) filter.
    pub cone_filter: Option<f32>,
    /// Least cosine between a photon's stored normal and the receiver's normal.
    pub min_normal_cosine: f32,
    /// Largest distance off the receiver's tangent plane, as a fraction of the gather radius.
    pub max_plane_distance: f32,
}

impl Default for EstimateSettings {
    fn default() -> Self {
        EstimateSettings {
            estimator: Estimator::Kernels,
            k: 100,
            max_radius: None,
            min_pixels: MIN_PIXELS,
            cone_filter: Some(1.1),
            min_normal_cosine: MIN_NORMAL_COSINE,
            max_plane_distance: MAX_PLANE_DISTANCE,
        }
    }
}

/// Least cosine between a photon's stored normal and the receiver's normal.
const MIN_NORMAL_COSINE: f32 = 0.7;
/// Least kernel radius in pixel widths: a kernel one pixel across (a wider one cut the lens
/// spot's peak by a quarter against a 5M-photon reference).
const MIN_PIXELS: f32 = 0.5;
/// The automatic largest kernel radius, as a fraction of the diagonal of the photons' bounds: wide
/// enough for a few sparse photons to spread into a glow across a wall.
const KERNEL_REACH: f32 = 1.0 / 8.0;
/// Largest distance off the receiver's tangent plane, as a fraction of the gather radius.
const MAX_PLANE_DISTANCE: f32 = 0.25;

/// Stored photons and the tree over them.
pub struct PhotonMap {
    photons: Vec<Photon>,
    tree: KdTree,
    auto_radius: f32,
    /// The photons' kernels, for the kernel estimate.
    kernels: Option<Kernels>,
    /// What the photon pass did.
    pub stats: PhotonStats,
    /// Tells this map's per-thread lists of leaves from another's.
    id: u64,
}

/// The next [`PhotonMap`]'s identity.
static NEXT_MAP_ID: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

fn next_map_id() -> u64 {
    NEXT_MAP_ID.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// A nearby estimate's radius times this bounds the first photon search: the density rarely
/// falls by more than its square (2.25×) within a pixel.
const NARROW_SCALE: f32 = 1.5;

thread_local! {
    static NEIGHBORS: RefCell<Vec<Neighbor>> = const { RefCell::new(Vec::new()) };
    static NEAR_LEAVES: RefCell<NearLeaves> = RefCell::new(NearLeaves::default());
}

impl PhotonMap {
    /// Traces photons through `scene` and builds the map for `estimate`.
    pub fn trace(scene: &Scene, settings: &PhotonSettings, estimate: &EstimateSettings, control: Control) -> PhotonMap {
        let (photons, stats) = trace_photons(scene, settings, control);
        PhotonMap::from_photons(photons, stats, estimate)
    }

    /// Builds the map over `photons` (reordering them), without an automatic radius.
    pub fn new(mut photons: Vec<Photon>) -> PhotonMap {
        let tree = KdTree::build(&mut photons);
        PhotonMap {
            photons,
            tree,
            auto_radius: 0.0,
            kernels: None,
            stats: PhotonStats::default(),
            id: next_map_id(),
        }
    }

    /// Builds the map over photons (reordering them) for `estimate`: the automatic radius for
    /// its k and, for the kernel estimate, every photon's kernel.
    pub fn from_photons(mut photons: Vec<Photon>, stats: PhotonStats, estimate: &EstimateSettings) -> PhotonMap {
        let tree = KdTree::build(&mut photons);
        let mut map = PhotonMap {
            photons,
            tree,
            auto_radius: 0.0,
            kernels: None,
            stats,
            id: next_map_id(),
        };
        let k = estimate.k.max(1);
        match estimate.estimator {
            Estimator::Nearest => map.auto_radius = map.density_radius(k),
            Estimator::Kernels => {
                let bounds = map
                    .photons
                    .iter()
                    .fold(crate::math::Aabb::EMPTY, |b, p| b.with_point(p.position));
                map.auto_radius = if bounds.is_empty() {
                    0.0
                } else {
                    KERNEL_REACH * bounds.extent().length()
                };
                let max_radius = estimate.max_radius.unwrap_or(map.auto_radius);
                let radii = kernel::kernel_radii(&map.tree, &map.photons, k, max_radius, estimate.min_normal_cosine);
                let normals: Vec<Vec3> = map.photons.iter().map(Photon::normal).collect();
                map.kernels = Some(Kernels::new(&map.tree, &map.photons, normals, radii));
            }
        }
        map
    }

    /// The photons, in tree order.
    pub fn photons(&self) -> &[Photon] {
        &self.photons
    }

    /// Number of photons.
    pub fn len(&self) -> usize {
        self.photons.len()
    }

    /// Heap bytes the map owns: the photons, the tree and the kernels.
    pub fn heap_bytes(&self) -> usize {
        self.photons.capacity() * std::mem::size_of::<Photon>()
            + self.tree.heap_bytes()
            + self.kernels.as_ref().map_or(0, Kernels::heap_bytes)
    }

    /// Whether the map holds no photon.
    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// The automatic largest radius. For the k-nearest estimate, twice the median distance to
    /// the k-th nearest photon, measured around 256 photons spread through the map: where photons
    /// are dense the k nearest lie well inside it; where they are sparse it stops the gather from
    /// reaching across the scene. For the kernel estimate, an eighth of the diagonal of the
    /// photons' bounds.
    pub fn auto_radius(&self) -> f32 {
        self.auto_radius
    }

    fn density_radius(&self, k: usize) -> f32 {
        2.0 * super::typical_knn_distance(&self.tree, &self.photons, k.max(1))
    }

    /// Reflected radiance at a surface point with material values `params` towards `wo` from
    /// the photons nearby; `n` is the unit normal facing `wo`, and `pixel` the width of a pixel
    /// where the camera path meets the point (0 when no camera looks). Where other geometry
    /// comes within the gather radius, photons the point cannot see in a straight line (behind
    /// a wall, across a ring's rim) are left out.
    #[allow(clippy::too_many_arguments)]
    pub fn radiance(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        params: &SurfaceParams,
        n: Vec3,
        wo: Vec3,
        settings: &EstimateSettings,
        pixel: f32,
    ) -> Vec3 {
        self.gather(scene, hit, n, settings, pixel, None, |wi| {
            params.phong_reflectance(n, wo, wi)
        })
        .0
    }

    /// Photon flux per area arriving at a surface point from the side `n` faces (the reflected
    /// radiance of a white Lambertian receiver, kd = 1), and the gather radius used (the
    /// narrowest kernel for the kernel estimate). Multiplied by kd it equals
    /// [`PhotonMap::radiance`] on any receiver without a specular lobe.
    pub fn irradiance(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        n: Vec3,
        settings: &EstimateSettings,
        pixel: f32,
    ) -> (Vec3, f32) {
        self.irradiance_near(scene, hit, n, settings, pixel, None)
    }

    /// [`PhotonMap::irradiance`] given the gather radius of an estimate made nearby, which
    /// narrows the k-nearest photon search; the result is the same (the search widens if it
    /// must).
    pub fn irradiance_near(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        n: Vec3,
        settings: &EstimateSettings,
        pixel: f32,
        radius_nearby: Option<f32>,
    ) -> (Vec3, f32) {
        self.gather(scene, hit, n, settings, pixel, radius_nearby, |wi| {
            if n.dot(wi) > 0.0 {
                Vec3::ONE
            } else {
                Vec3::ZERO
            }
        })
    }

    /// The estimate `settings` asks for at `hit`, and its radius.
    #[allow(clippy::too_many_arguments)]
    fn gather(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        n: Vec3,
        settings: &EstimateSettings,
        pixel: f32,
        radius_nearby: Option<f32>,
        reflectance: impl Fn(Vec3) -> Vec3,
    ) -> (Vec3, f32) {
        if self.photons.is_empty() || settings.k == 0 {
            return (Vec3::ZERO, 0.0);
        }
        let max_r = settings.max_radius.unwrap_or(self.auto_radius);
        if max_r.is_nan() || max_r <= 0.0 {
            return (Vec3::ZERO, 0.0);
        }
        match (settings.estimator, &self.kernels) {
            (Estimator::Kernels, Some(kernels)) => {
                let gather = Gather {
                    scene,
                    hit,
                    n,
                    min_radius: settings.min_pixels * pixel,
                    max_radius: max_r,
                    cone_filter: settings.cone_filter,
                    min_normal_cosine: settings.min_normal_cosine,
                    max_plane_distance: settings.max_plane_distance,
                };
                NEIGHBORS.with(|cell| {
                    NEAR_LEAVES.with(|near| {
                        kernel::estimate(
                            &gather,
                            &self.tree,
                            kernels,
                            &self.photons,
                            (self.id, &mut near.borrow_mut()),
                            &mut cell.borrow_mut(),
                            reflectance,
                        )
                    })
                })
            }
            (Estimator::Kernels, None) => panic!("the photon map was built without kernels"),
            (Estimator::Nearest, _) => self.gather_nearest(scene, hit, n, settings, max_r, radius_nearby, reflectance),
        }
    }

    /// Σ f(ωi) Φ w / (π r² norm) over the accepted photons among the k nearest to `hit`
    /// within `max_r`, and the radius r.
    #[allow(clippy::too_many_arguments)]
    fn gather_nearest(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        n: Vec3,
        settings: &EstimateSettings,
        max_r: f32,
        radius_nearby: Option<f32>,
        reflectance: impl Fn(Vec3) -> Vec3,
    ) -> (Vec3, f32) {
        let point = hit.point;
        NEIGHBORS.with(|cell| {
            let mut neighbors = cell.borrow_mut();
            let full = max_r * max_r;
            // The k nearest within a narrower radius, when there are k, are the k nearest.
            let narrow = radius_nearby.map_or(f32::INFINITY, |r| (NARROW_SCALE * r) * (NARROW_SCALE * r));
            let mut r2 = f32::NAN;
            if narrow < full {
                r2 = self
                    .tree
                    .k_nearest_unordered(&self.photons, point, settings.k, narrow, &mut neighbors);
                if neighbors.len() < settings.k {
                    r2 = f32::NAN;
                }
            }
            if r2.is_nan() {
                r2 = self
                    .tree
                    .k_nearest_unordered(&self.photons, point, settings.k, full, &mut neighbors);
            }
            if neighbors.is_empty() || r2.is_nan() || r2 <= 0.0 {
                return (Vec3::ZERO, 0.0);
            }
            let r = r2.sqrt();
            let occluders = scene.occluders_near(point, r, hit.prim);
            let segments = (!occluders.is_empty()).then(|| scene.segments_from(&occluders, point, n));
            let mut sum = Vec3::ZERO;
            // Photons on one surface share a normal code: decode it once.
            let mut normal = (None, Vec3::ZERO);
            for nb in neighbors.iter() {
                let photon = &self.photons[nb.slot as usize];
                let offset = photon.position - point;
                if offset.dot(n).abs() > settings.max_plane_distance * r {
                    continue;
                }
                let code = photon.normal_code();
                if normal.0 != Some(code) {
                    normal = (Some(code), photon.normal());
                }
                if normal.1.dot(n) < settings.min_normal_cosine {
                    continue;
                }
                let f = reflectance(-photon.direction());
                if f == Vec3::ZERO {
                    continue;
                }
                if segments
                    .as_ref()
                    .is_some_and(|s| !s.clear_to(photon.position, normal.1))
                {
                    continue;
                }
                let weight = match settings.cone_filter {
                    Some(k) => (1.0 - nb.dist2.sqrt() / (k * r)).max(0.0),
                    None => 1.0,
                };
                sum += f * photon.power() * weight;
            }
            let normalisation = match settings.cone_filter {
                Some(k) => 1.0 - 2.0 / (3.0 * k),
                None => 1.0,
            };
            (sum / (PI * r2 * normalisation), r)
        })
    }

    /// Flux per area arriving at the surface point seen straight down `-n` from just above
    /// `point` (Σ Φ / π r², the irradiance of a white Lambertian receiver): for checks.
    pub fn flux_density(&self, scene: &Scene, point: Vec3, n: Vec3, settings: &EstimateSettings) -> Vec3 {
        let ray = crate::math::Ray::new(point + n * 1e-3, -n);
        let Some(isect) = scene.intersect(&ray, 2e-3) else {
            return Vec3::ZERO;
        };
        let hit = scene.surface(&ray, &isect);
        let white = SurfaceParams {
            diffuse: Vec3::ONE,
            ..SurfaceParams::default()
        };
        self.radiance(scene, &hit, &white, n, n, settings, 0.0)
    }

    /// Reflected radiance at `point` towards `wo` from the photons within radius `r` (physical
    /// model) that had at least `min_left` bounces left ([`Photon::bounces_left`]; 0: all);
    /// `dispersed` says the camera path left its secondary wavelengths behind.
    pub fn radiance_within(
        &self,
        point: Vec3,
        bsdf: &Bsdf,
        wo: Vec3,
        (r, min_left): (f32, u8),
        dispersed: bool,
    ) -> Spectrum {
        self.radiance_within_of(point, bsdf, wo, (r, min_left), dispersed, |_| true)
    }

    /// [`PhotonMap::radiance_within`] from the photons `kept` says count.
    pub fn radiance_within_of(
        &self,
        point: Vec3,
        bsdf: &Bsdf,
        wo: Vec3,
        (r, min_left): (f32, u8),
        dispersed: bool,
        kept: impl Fn(&Photon) -> bool,
    ) -> Spectrum {
        if self.photons.is_empty() || r.is_nan() || r <= 0.0 {
            return Spectrum::ZERO;
        }
        let n = bsdf.normal();
        let mut sum = Spectrum::ZERO;
        self.tree.for_each_within(&self.photons, point, r * r, |slot, _| {
            let photon = &self.photons[slot as usize];
            if photon.bounces_left() >= min_left
                && accepts(photon, point, n, r, bsdf.transmits_smoothly())
                && kept(photon)
            {
                sum += bsdf.eval(wo, -photon.direction()) * photon_power(photon, dispersed);
            }
        });
        sum / (PI * r * r)
    }

    /// Radiance a point in a medium scatters towards `wo` from the volume photons within `r`
    /// (those with at least `min_left` bounces left): Σ p(wo, ωp) Φp / (4/3 π r³) over σs, the
    /// medium's scattering coefficient there (photons are stored where they scatter, at a
    /// density σs times the fluence).
    pub fn in_scattered_within(
        &self,
        point: Vec3,
        phase: &Bsdf,
        wo: Vec3,
        (r, min_left): (f32, u8),
        dispersed: bool,
        sigma_s: Spectrum,
    ) -> Spectrum {
        if self.photons.is_empty() || r.is_nan() || r <= 0.0 {
            return Spectrum::ZERO;
        }
        let mut sum = Spectrum::ZERO;
        self.tree.for_each_within(&self.photons, point, r * r, |slot, _| {
            let photon = &self.photons[slot as usize];
            if photon.bounces_left() >= min_left {
                sum += phase.eval(wo, -photon.direction()) * photon_power(photon, dispersed);
            }
        });
        let density = sum / (4.0 / 3.0 * PI * r * r * r);
        Spectrum::select(sigma_s.cmpgt(Spectrum::ZERO), density / sigma_s, Spectrum::ZERO)
    }

    /// The beam radiance estimate: light scattered towards `wo` along the segment
    /// `origin + t dir` (`dir` unit, `t` within `span`) from the volume photons square to it
    /// within `radius(t)` (at most `max_radius`) that may still bounce `min_left` times: each
    /// one's power through `phase`, times `kept(t)` (what reaches the segment's start from
    /// there), over π radius(t)².
    #[allow(clippy::too_many_arguments)]
    pub fn in_scattered_along(
        &self,
        (origin, dir): (Vec3, Vec3),
        span: (f32, f32),
        (max_radius, radius): (f32, impl Fn(f32) -> f32),
        (phase, wo): (&Bsdf, Vec3),
        (min_left, dispersed): (u8, bool),
        mut kept: impl FnMut(f32) -> Spectrum,
    ) -> Spectrum {
        if self.photons.is_empty() || max_radius.is_nan() || max_radius <= 0.0 {
            return Spectrum::ZERO;
        }
        let mut sum = Spectrum::ZERO;
        self.tree
            .for_each_near_segment(&self.photons, (origin, dir), span, max_radius, |slot, t, d2| {
                let photon = &self.photons[slot as usize];
                let r = radius(t);
                if d2 >= r * r || photon.bounces_left() < min_left {
                    return;
                }
                let light = phase.eval(wo, -photon.direction()) * photon_power(photon, dispersed);
                sum += kept(t) * light / (PI * r * r);
            });
        sum
    }

    /// Reflected radiance at `point` towards `wo` from the `k` nearest photons within
    /// `max_radius`, the radius being the distance to the k-th.
    pub fn radiance_nearest(
        &self,
        point: Vec3,
        bsdf: &Bsdf,
        wo: Vec3,
        (k, max_radius): (usize, f32),
        dispersed: bool,
    ) -> Spectrum {
        if self.photons.is_empty() || k == 0 || max_radius.is_nan() || max_radius <= 0.0 {
            return Spectrum::ZERO;
        }
        let n = bsdf.normal();
        NEIGHBORS.with(|cell| {
            let mut neighbors = cell.borrow_mut();
            let r2 = self
                .tree
                .k_nearest(&self.photons, point, k, max_radius * max_radius, &mut neighbors);
            if neighbors.is_empty() || r2.is_nan() || r2 <= 0.0 {
                return Spectrum::ZERO;
            }
            let r = r2.sqrt();
            let mut sum = Spectrum::ZERO;
            // The k-th photon only marks the radius: counting it too would bias the density by
            // k / (k − 1) (the k-th nearest lies on the disc's rim, not inside it).
            let skip = usize::from(neighbors.len() == k && k > 1);
            for nb in neighbors.iter().skip(skip) {
                let photon = &self.photons[nb.slot as usize];
                if accepts(photon, point, n, r, bsdf.transmits_smoothly()) {
                    sum += bsdf.eval(wo, -photon.direction()) * photon_power(photon, dispersed);
                }
            }
            sum / (PI * r2)
        })
    }

    /// Twice the median distance to the k-th nearest photon around up to 256 photons spread
    /// through the map: a gather radius that holds about k photons where they are typical.
    pub fn typical_radius(&self, k: usize) -> f32 {
        2.0 * super::typical_knn_distance(&self.tree, &self.photons, k)
    }
}

/// A photon's power as a camera path gathers it: a photon that dispersed carries its hero's
/// weight for the whole path, which a camera path that dispersed too has already applied.
#[inline]
fn photon_power(photon: &Photon, camera_dispersed: bool) -> Spectrum {
    let power = photon.spectrum();
    if camera_dispersed && photon.flags & DISPERSED != 0 {
        power / SAMPLES as f32
    } else {
        power
    }
}

/// Whether a photon counts at a receiver: near its tangent plane, on a surface facing its way —
/// or, where light passes diffusely through (`both_faces`), facing either way.
#[inline]
fn accepts(photon: &Photon, point: Vec3, n: Vec3, r: f32, both_faces: bool) -> bool {
    let cos = photon.normal().dot(n);
    (photon.position - point).dot(n).abs() <= MAX_PLANE_DISTANCE * r
        && (cos >= MIN_NORMAL_COSINE || both_faces && -cos >= MIN_NORMAL_COSINE)
}
