//! Merging in media: the beam radiance estimate (Jarosz et al. 2008; the point–beam estimator
//! of UPBP, Křivánek et al. 2014). Until a camera path first scatters off a smooth lobe, it
//! passes media without stopping (its throughput pays their transmittance), and each
//! of its segments gathers every light vertex in them within the merging radius of the ray: each
//! adds its light, scattered by the phase function towards the eye and dimmed on the way there,
//! over the disc π r² the ray sweeps. Light tracing joins each such vertex to one pixel; the beam
//! query spreads it over the pixels whose rays pass it, so thin fog, which camera paths seldom
//! stop in, comes out smooth, and the surfaces behind it are reached by every camera path instead
//! of the share a free flight lets through.
//!
//! A path whose first smooth camera-side vertex lies in such a medium is then made by three
//! strategies: light tracing; the beam query, whose density is merging's with the camera's
//! density of the point per unit volume (the free flights' distance densities left out, as a
//! beam query draws none on the camera's side and light tracing's and its light subpaths are the
//! same); and, for light reaching the point first, next-event estimation at a point a free
//! flight picks on the segment, which does not go on from there (a point light in fog is best
//! sampled so). Against that last one the distance densities count: σt exp(−σt t) for the free
//! flight from the segment's start, σt exp(−σt d) for the light subpath's from the light
//! ([`direct_share`]), taken as if homogeneous at the medium's largest σt (the weights only need
//! both sides to agree). In a density grid one ratio-tracking walk along the segment estimates
//! the transmittance to every point of it at once (a step function, unbiased at each point).

use super::*;
use crate::photon::light_walk::Passage;

/// Next-event estimation's density against the light subpath's, for light reaching a point in a
/// medium of largest σt `sigma` first, `t` from the camera segment's start: `first` is the light
/// subpath's first MIS sum there (the two without distance densities), `d` its distance from the
/// light (0 for a far light), and the free flights' densities exp(−σ t) and exp(−σ d) are put in
/// (σ cancels).
pub(super) fn direct_share((first, d): (f32, f32), sigma: f32, t: f32) -> f32 {
    first * (-sigma * (t - d)).clamp(-80.0, 80.0).exp()
}

impl Vcm<'_> {
    /// Whether light vertices in medium `id` are merged, and camera paths pass it before their
    /// first smooth vertex: beam queries are on, and the medium scatters.
    pub(super) fn merges_in_medium(&self, id: u32) -> bool {
        if !self.settings.beams || id == crate::medium::VACUUM {
            return false;
        }
        let medium = self.scene.medium(id);
        !medium.only_absorbs() && !medium.is_clear()
    }

    /// Along the camera segment `ray` that `passage` starts, for a camera path carrying
    /// `(throughput, dispersed)` with the MIS sums `camera` (after its last bounce), the segment
    /// leading to its vertex `length`: the beam query, and next-event estimation at a point a free
    /// flight picks in each medium it passes.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather_beam(
        &self,
        ray: &Ray,
        passage: &Passage,
        (throughput, dispersed): (Spectrum, bool),
        camera: &Partial,
        length: u32,
        pass: &PassData,
        wl: &Wavelengths,
        rng: &mut Rng,
        work: &mut CameraWork,
    ) -> Spectrum {
        let dir = ray.dir.normalize();
        let ray = Ray::new(ray.origin, dir);
        let wo = -dir;
        let (f, radius) = (&pass.factors, pass.radius);
        let vertices = &pass.paths.volume_vertices;
        let (mut merged, mut direct) = (Spectrum::ZERO, Spectrum::ZERO);
        let gathers = |id| self.merges_in_medium(id);
        passage.along_media(self.scene, &ray, wl, rng, gathers, |stretch, rng| {
            let (id, medium, (t0, t1)) = (stretch.id, stretch.medium, stretch.span);
            let sigma = medium.majorant();
            let at = |t: f32| {
                let mut at = *camera;
                at.arrive(t * t, 1.0);
                at
            };
            // Next-event estimation where a free flight stops (it goes no further).
            let mut carried = stretch.before;
            if length < self.max_length {
                if let Some(t) = medium.sample_flight(&ray, (t0, t1), wl, &mut carried, rng) {
                    let hit = SurfaceHit::in_medium(ray.at(t), id);
                    let bsdf = Bsdf::phase(medium.phase.g, wo, wl);
                    let v = CameraVertex {
                        hit: &hit,
                        bsdf: &bsdf,
                        wo,
                        throughput: carried,
                        partial: at(t),
                        length,
                        dispersed,
                        along: Some((sigma, t)),
                    };
                    direct += self.direct(&v, f, wl, rng, work);
                }
            }
            let span = stretch.reach(radius);
            pass.volume_tree
                .for_each_near_segment(vertices, (ray.origin, dir), span, radius, |slot, t, _| {
                    work.candidates += 1;
                    let z = &vertices[slot as usize];
                    if z.medium != id || length + z.length > self.max_length {
                        return;
                    }
                    let t = t.clamp(t0, t1);
                    let phase = medium.phase.eval(wo, z.wo);
                    let weight = mis::beam(f, &at(t), direct_share(z.direct, sigma, t));
                    merged +=
                        stretch.kept(t) * z.throughput * (phase * weight * both_dispersed(dispersed, z.dispersed));
                });
        });
        let merged = merged / (std::f32::consts::PI * radius * radius * f.light_paths);
        throughput * (merged + direct)
    }
}
