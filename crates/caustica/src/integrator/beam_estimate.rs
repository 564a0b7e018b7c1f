//! The beam radiance estimate of the photon-mapping integrators (Jarosz et al. 2008): a camera
//! path passes the media before its first smooth surface, and along each segment gathers
//! next-event estimation at one point a free flight picks (light straight from a light) and the
//! volume photons within a radius of the ray (the rest), each dimmed on its way to the
//! segment's start. `ppm` and `gi` gather this way ([`Along`]).

use super::direct::direct_light;
use super::radius::InitialRadius;
use super::specular_chain::Along;
use crate::bsdf::Bsdf;
use crate::math::Ray;
use crate::photon::light_walk::Passage;
use crate::photon::map::PhotonMap;
use crate::photon::needed_bounces_left;
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};

/// One pass's beam estimate: its volume photons (none that came straight from a light) and
/// their gather radius, `radius` at a point's distance from the eye shrunk by `factor`.
pub struct BeamEstimate<'p> {
    /// The scene.
    pub scene: &'p Scene,
    /// The volume photons gathered.
    pub volume: &'p PhotonMap,
    /// The gather radius before the pass's shrinking.
    pub radius: InitialRadius,
    /// Width of a pixel at unit distance from the eye.
    pub pixel_angle: f32,
    /// This pass's shrink factor of the radius.
    pub factor: f32,
    /// `--depth`: photons gathered have bounced no more than the path may still scatter.
    pub max_depth: u32,
    /// The pass's wavelengths.
    pub wl: &'p Wavelengths,
}

impl Along for BeamEstimate<'_> {
    fn passes(&self, medium: u32) -> bool {
        let medium = self.scene.medium(medium);
        !self.volume.is_empty() && !medium.only_absorbs() && !medium.is_clear()
    }

    fn gather(
        &mut self,
        ray: &Ray,
        passage: &Passage,
        (_, dispersed): (Spectrum, bool),
        (path_length, left): (f32, u32),
        rng: &mut Rng,
    ) -> Spectrum {
        if self.volume.is_empty() {
            // No medium is passed (no ray to cast for its stretches).
            return Spectrum::ZERO;
        }
        let (scene, wl) = (self.scene, self.wl);
        let dir = ray.dir.normalize();
        let ray = Ray::new(ray.origin, dir);
        let wo = -dir;
        let min_left = needed_bounces_left(self.max_depth, left);
        let radius = |t: f32| self.radius.at(self.pixel_angle, path_length + t) * self.factor;
        let volume = self.volume;
        let mut l = Spectrum::ZERO;
        passage.along_media(
            scene,
            &ray,
            wl,
            rng,
            |id| self.passes(id),
            |stretch, rng| {
                let (medium, (t0, t1)) = (stretch.medium, stretch.span);
                let phase = Bsdf::phase(medium.phase.g, wo, wl);
                let mut carried = stretch.before;
                if let Some(t) = medium.sample_flight(&ray, (t0, t1), wl, &mut carried, rng) {
                    // Nothing is sampled from this point on: the light sample counts in full.
                    let hit = SurfaceHit::in_medium(ray.at(t), stretch.id);
                    l += carried * direct_light(scene, &hit, &phase, wo, false, wl, rng);
                }
                let reach = radius(t1);
                l += volume.in_scattered_along(
                    (ray.origin, dir),
                    stretch.reach(reach),
                    (reach, |t: f32| radius(t.clamp(t0, t1))),
                    (&phase, wo),
                    (min_left, dispersed),
                    |t| stretch.kept(t),
                );
            },
        );
        l
    }
}
