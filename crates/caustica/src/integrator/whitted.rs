//! The course's Whitted ray tracer (§9): emission, ambient, Phong per light with the course's
//! attenuation and shadows filtered by each occluder's `transmissive`, recursive mirror
//! reflection and refraction (no Fresnel), plus an optional caustic term from the photon map.

use crate::material::{channel_indices, refraction_geometry, SurfaceParams};
use crate::math::{offset_origin, reflect, refract, Ray, Vec3};
use crate::scene::{Scene, SurfaceHit};

/// Settings of the Whitted integrator.
#[derive(Clone, Debug, PartialEq)]
pub struct WhittedSettings {
    /// Maximum number of recursive reflection/refraction bounces.
    pub max_depth: u32,
    /// Spawn reflection rays for rays travelling inside a transmissive object (the 2019 skeleton's
    /// expected behaviour is false).
    pub internal_reflection: bool,
    /// Add highlights where a transmissive surface is seen from its back (expected: false).
    pub backface_specular: bool,
    /// Let a pixel's samples share the caustic estimate of its first hit where that is safe
    /// (see [`render`]).
    pub reuse_caustic_estimates: bool,
}

impl Default for WhittedSettings {
    fn default() -> Self {
        WhittedSettings {
            max_depth: 5,
            internal_reflection: false,
            backface_specular: false,
            reuse_caustic_estimates: true,
        }
    }
}

/// A ray crosses a sphere, box, cylinder or cone at most this many times.
const MAX_CROSSINGS_PER_SHAPE: usize = 4;

/// Recursion stops once a path's weight falls below this: it could not change an 8-bit pixel.
const MIN_PATH_WEIGHT: f32 = 1.0 / 1024.0;

/// Radiance along `ray` (unit direction). `caustic(hit, params, wo, n, depth, length)` adds
/// light estimated from photons at a surface point, given its material values, the direction to
/// the viewer, the normal facing it, the recursion depth (0 for the camera ray's own hit) and
/// the length of the path from the camera.
pub fn radiance<C>(scene: &Scene, settings: &WhittedSettings, ray: &Ray, caustic: &C) -> Vec3
where
    C: Fn(&SurfaceHit, &SurfaceParams, Vec3, Vec3, u32, f32) -> Vec3,
{
    trace(scene, settings, ray, 0, 0.0, Vec3::ONE, caustic)
}

#[allow(clippy::too_many_arguments)]
fn trace<C>(
    scene: &Scene,
    settings: &WhittedSettings,
    ray: &Ray,
    depth: u32,
    length: f32,
    weight: Vec3,
    caustic: &C,
) -> Vec3
where
    C: Fn(&SurfaceHit, &SurfaceParams, Vec3, Vec3, u32, f32) -> Vec3,
{
    let Some(isect) = scene.intersect(ray, f32::INFINITY) else {
        return scene.lights().background(ray.dir);
    };
    let hit = scene.surface(ray, &isect);
    let length = length + isect.t * ray.dir.length();
    let p = &scene.phong(&hit);
    let d = ray.dir;
    let wo = -d;
    // Rays meeting the outward normal from behind are inside the object.
    let entering = d.dot(hit.geometric_normal) < 0.0;
    let n = if d.dot(hit.shading_normal) > 0.0 {
        -hit.shading_normal
    } else {
        hit.shading_normal
    };
    let inside_transmissive = !entering && p.transmissive != Vec3::ZERO;

    let mut color = p.emissive + p.ambient * scene.ambient();
    let shade_specular = settings.backface_specular || !inside_transmissive;
    let local = SurfaceParams {
        specular: if shade_specular { p.specular } else { Vec3::ZERO },
        ..*p
    };
    if local.diffuse != Vec3::ZERO || local.specular != Vec3::ZERO {
        color += direct_light(scene, &hit, &local, n, wo);
        // Inside glass the shadow rays (filtered by kt) already bring all the light the course
        // model gives there; photons are not stored on that side either.
        if !inside_transmissive {
            color += caustic(&hit, p, wo, n, depth, length);
        }
    }

    if depth >= settings.max_depth {
        return color;
    }
    if p.reflective != Vec3::ZERO && (settings.internal_reflection || !inside_transmissive) {
        let w = weight * p.reflective;
        if w.max_element() >= MIN_PATH_WEIGHT {
            let dir = reflect(d, n);
            let origin = hit.ray_origin(dir);
            color += p.reflective * trace(scene, settings, &Ray::new(origin, dir), depth + 1, length, w, caustic);
        }
    }
    if p.transmissive != Vec3::ZERO {
        let w = weight * p.transmissive;
        if w.max_element() >= MIN_PATH_WEIGHT {
            // A dispersive glass (caustica's `abbe`) gives each colour channel its own index:
            // the ray splits into one per channel still carried.
            let indices = channel_indices(p.index, scene.abbe(&hit));
            for (mask, index) in channel_rays(weight, indices) {
                let index = if index.is_nan() { p.index } else { index };
                let (eta, n_in) = refraction_geometry(index, entering, hit.shading_normal);
                // Total internal reflection turns the transmitted ray back inside (as photons do).
                let dir = refract(d, n_in, eta).unwrap_or_else(|| reflect(d, n_in));
                let origin = hit.ray_origin(dir);
                let kt = p.transmissive * mask;
                color += kt
                    * trace(
                        scene,
                        settings,
                        &Ray::new(origin, dir),
                        depth + 1,
                        length,
                        w * mask,
                        caustic,
                    );
            }
        }
    }
    color
}

/// The refracted rays a path carrying `weight` splits into: one with every channel and `index`'s
/// own index when not dispersive (or only one channel is left), else one per channel still
/// carried, each masked to it.
fn channel_rays(weight: Vec3, indices: Option<[f32; 3]>) -> impl Iterator<Item = (Vec3, f32)> {
    let carried: Vec<usize> = (0..3).filter(|&c| weight[c] > 0.0).collect();
    let rays: Vec<(Vec3, f32)> = match indices {
        None => vec![(Vec3::ONE, f32::NAN)],
        Some(n) if carried.len() == 1 => vec![(Vec3::ONE, n[carried[0]])],
        Some(n) => carried
            .iter()
            .map(|&c| {
                let mut mask = Vec3::ZERO;
                mask[c] = 1.0;
                (mask, n[c])
            })
            .collect(),
    };
    rays.into_iter()
}

/// Σ over lights of f(d)·S·I ⊙ [kd (N·L) + ks (V·R)^ns].
fn direct_light(scene: &Scene, hit: &SurfaceHit, params: &SurfaceParams, n: Vec3, wo: Vec3) -> Vec3 {
    let mut sum = Vec3::ZERO;
    for light in scene.lights().course_lights() {
        let Some(ls) = light.sample_li(hit.point) else { continue };
        let cos = n.dot(ls.wi);
        if cos <= 0.0 {
            continue;
        }
        let shadow = match light.shadow_targets(hit.point) {
            None => transmittance_from(scene, hit.ray_origin(ls.wi), hit.point, ls.wi, ls.distance),
            // A light with a size: the mean over shadow rays to points spread over it.
            Some(targets) => {
                let (mut sum, mut n) = (Vec3::ZERO, 0.0f32);
                for q in targets {
                    let to = q - hit.point;
                    let d = to.length();
                    if d > 0.0 {
                        let wi = to / d;
                        sum += transmittance_from(scene, hit.ray_origin(wi), hit.point, wi, d);
                    }
                    n += 1.0;
                }
                sum / n.max(1.0)
            }
        };
        if shadow == Vec3::ZERO {
            continue;
        }
        sum += ls.intensity * shadow * params.phong_reflectance(n, wo, ls.wi) * cos;
    }
    sum
}

/// The product of the `transmissive` colours of everything between `point` and a light at
/// `distance` along `wi` (zero when an opaque object is in the way).
pub fn transmittance(scene: &Scene, point: Vec3, geometric_normal: Vec3, wi: Vec3, distance: f32) -> Vec3 {
    transmittance_from(scene, offset_origin(point, geometric_normal, wi), point, wi, distance)
}

/// [`transmittance`] along the shadow ray from `origin`, which is `point` moved off its surface.
fn transmittance_from(scene: &Scene, origin: Vec3, point: Vec3, wi: Vec3, distance: f32) -> Vec3 {
    let ray = Ray::new(origin, wi);
    let t_max = if distance.is_finite() {
        (distance - (origin - point).length()) * (1.0 - 1e-5)
    } else {
        f32::INFINITY
    };
    let mut filter = Vec3::ONE;
    // Every crossing of a surface filters by its kt: a closed glass object filters twice.
    let blocked = scene.any_hit(&ray, t_max, |isect| {
        let mut crossing = Some(*isect);
        for _ in 0..MAX_CROSSINGS_PER_SHAPE {
            let Some(hit) = crossing else { break };
            filter *= match scene.uniform_transmissive(hit.prim) {
                Some(kt) => kt,
                None => scene.phong(&scene.surface(&ray, &hit)).transmissive,
            };
            if filter == Vec3::ZERO {
                return true;
            }
            crossing = scene.next_crossing(&ray, &hit, t_max);
        }
        false
    });
    if blocked {
        Vec3::ZERO
    } else {
        filter
    }
}

/// The caustic estimates of a pixel's first sample at each recursion depth (primitive, point,
/// gather radius, flux per area), reused by its other samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct PixelCaustic {
    entries: [Option<(u32, Vec3, f32, Vec3)>; CACHED_DEPTHS],
}

/// Depths whose estimates a pixel keeps: the camera ray's hit and the first mirror bounces.
const CACHED_DEPTHS: usize = 4;

/// Reuse only within this fraction of the gather radius: the estimate is a kernel average over
/// that radius, so it barely changes across so small a step.
const REUSE_FRACTION: f32 = 0.25;

/// Renders the Whitted image, adding the photon map's caustics where a map is given.
///
/// With `settings.reuse_caustic_estimates` (see docs/radiometry.md), the samples of one pixel
/// share the caustic estimate its first sample made at the same recursion depth when they land
/// on the same primitive of a receiver without a specular lobe, within a quarter of the gather
/// radius; every other estimate is computed afresh.
pub fn render(
    scene: &Scene,
    caustics: Option<(&crate::photon::PhotonMap, &crate::photon::EstimateSettings)>,
    settings: &WhittedSettings,
    image: &super::ImageSettings,
    control: crate::progress::Control,
) -> (crate::film::Film, bool) {
    let camera = &scene.camera().fitted(image.width, image.height);
    let reuse = settings.reuse_caustic_estimates;
    // A pixel's width at unit distance along a camera path.
    let pixel_angle = super::radius::pixel_angle(camera, image.height);
    super::tiles::render_tiles(image, control, "render", |sx, sy, _rng, pixel: &mut PixelCaustic| {
        let ray = camera.generate_ray(sx, sy);
        let Some((map, estimate)) = caustics else {
            return radiance(
                scene,
                settings,
                &ray,
                &|_: &SurfaceHit, _: &SurfaceParams, _: Vec3, _: Vec3, _: u32, _: f32| Vec3::ZERO,
            );
        };
        let cache = std::cell::Cell::new(*pixel);
        let color = radiance(
            scene,
            settings,
            &ray,
            &|hit: &SurfaceHit, p: &SurfaceParams, wo: Vec3, n: Vec3, depth: u32, length: f32| {
                if p.diffuse == Vec3::ZERO && p.specular == Vec3::ZERO {
                    return Vec3::ZERO;
                }
                let pixel_width = pixel_angle * length;
                let slot = depth as usize;
                if !reuse || slot >= CACHED_DEPTHS || p.specular != Vec3::ZERO {
                    return map.radiance(scene, hit, p, n, wo, estimate, pixel_width);
                }
                let mut entries = cache.get();
                let mut nearby = None;
                if let Some((prim, point, r, flux)) = entries.entries[slot] {
                    if prim == hit.prim && point.distance(hit.point) <= REUSE_FRACTION * r {
                        return p.diffuse * flux;
                    }
                    nearby = (prim == hit.prim && r > 0.0).then_some(r);
                }
                let (flux, r) = map.irradiance_near(scene, hit, n, estimate, pixel_width, nearby);
                if entries.entries[slot].is_none() {
                    entries.entries[slot] = Some((hit.prim, hit.point, r, flux));
                    cache.set(entries);
                }
                p.diffuse * flux
            },
        );
        *pixel = cache.get();
        color
    })
}
