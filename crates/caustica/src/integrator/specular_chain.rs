//! The camera paths of the photon-mapping integrators: a camera ray followed through mirrors
//! and glass to the smooth surfaces where photons are gathered.

use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::math::{offset_origin, Ray, Vec3};
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};

/// Follows a camera ray through mirrors and glass, adding the emission it meets. At each smooth
/// surface it adds `beta · at_smooth(hit, bsdf, wo, path length)`; where the surface's BSDF then
/// samples a smooth lobe the chain ends with `beta · beyond(hit, sample, path length)` (nothing
/// for photon mapping, a final gather for Jensen's method). With `through_specular` off, a
/// camera ray that meets a mirror or glass first stops there.
#[allow(clippy::too_many_arguments)]
pub fn camera_chain<S, B>(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    through_specular: bool,
    rng: &mut Rng,
    mut at_smooth: S,
    mut beyond: B,
) -> Vec3
where
    S: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, &mut Rng) -> Vec3,
    B: FnMut(&SurfaceHit, &BsdfSample, f32, &mut Rng) -> Vec3,
{
    let mut ray = ray;
    let mut beta = Vec3::ONE;
    let mut l = Vec3::ZERO;
    let mut path_length = 0.0f32;
    for depth in 0..=max_depth {
        let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
            // Only the camera and specular chains get here: the sky counts in full.
            l += beta * scene.lights().escaped(ray.dir);
            break;
        };
        let hit = scene.surface(&ray, &isect);
        path_length += isect.t;
        let wo = -ray.dir;
        // Only the camera and specular chains reach here: emission counts in full.
        l += beta * super::direct::emitted(scene, &hit);
        let bsdf = Bsdf::at(scene, &hit, wo);
        if bsdf.is_black() {
            break;
        }
        if bsdf.is_smooth() {
            l += beta * at_smooth(&hit, &bsdf, wo, path_length, rng);
        }
        if depth == max_depth {
            break;
        }
        let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) else {
            break;
        };
        if !sample.specular {
            l += beta * beyond(&hit, &sample, path_length, rng);
            break;
        }
        if depth == 0 && !through_specular {
            break;
        }
        beta *= sample.weight;
        ray = Ray::new(offset_origin(hit.point, hit.geometric_normal, sample.wi), sample.wi);
    }
    l
}
