//! Photon paths for both shading models: a photon leaves a light, meets surfaces, and at each
//! one its model decides what is stored there and where the photon goes next.
//!
//! - [`CourseModel`] (the course's caustics, Jensen 1996): photons follow mirrors
//!   (`reflective`) and glass (`transmissive`, `index`, total internal reflection), pick up the
//!   colour of what they meet, and are stored where they land on a diffuse or glossy surface
//!   after at least one specular bounce (L S+ D). Russian roulette chooses reflection,
//!   refraction or absorption with probabilities from the surface's colours and divides the
//!   power by the probability taken. Photons from a point light are scaled by d²·f(d) for their
//!   path length d (the course's falloff f, §5), which is exactly 1 when f = 1/d²: caustics then
//!   fall off the same way as the course's direct light (docs/radiometry.md).
//! - [`PhysicalPhotons`]: photons scatter by the same BSDF the camera paths use and are stored
//!   wherever they meet a smooth (diffuse or glossy) surface, their history in their flags;
//!   Russian roulette keeps each photon's flux nearly constant. They walk the light side's one
//!   walk, a wave of photons at a time ([`walk_together`]), as the light tracer's paths and vcm's
//!   light subpaths do.
//!
//! Two drivers emit: [`super::budget::trace_photons`] stores a budget of caustic photons shared
//! between the lights (course), [`trace_count`] emits a fixed number from lights chosen by power
//! (physical). Both are deterministic whatever the thread count: photon `i` draws from its own
//! random stream and batches are concatenated in order.

use super::light_walk::{
    light_waves, walk_together, LightArrival, LightPath, LightVisitor, LightWalk, MediumArrival, Roulette, Walker,
};
use super::{Photon, DIFFUSE, DISPERSED, MAX_BOUNCES_LEFT, REFLECTED, REFRACTED};
use crate::bsdf::{BsdfSample, Transport};
use crate::light::{distance_attenuation, Light};
use crate::material::{channel_indices, refraction_geometry};
use crate::math::{reflect, refract, Ray, Vec3};
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use rayon::prelude::*;

/// Photons traced by one parallel task.
pub(crate) const BATCH: u64 = 4096;

/// Emits `count` photons from lights chosen by power, under the physical model at the
/// wavelengths `wl`, from stream `stream` of `seed`, and returns those stored, their flux
/// already divided by `count`.
pub fn trace_count(
    scene: &Scene,
    count: u64,
    stream: (u64, u64),
    max_bounces: u32,
    wl: &Wavelengths,
    control: Control,
) -> Vec<Photon> {
    trace_count_in_media(scene, count, stream, max_bounces, wl, control).0
}

/// [`trace_count`], also returning the photons stored where they scattered in a medium (its
/// second list, empty without media that scatter).
pub fn trace_count_in_media(
    scene: &Scene,
    count: u64,
    (seed, stream): (u64, u64),
    max_bounces: u32,
    wl: &Wavelengths,
    control: Control,
) -> (Vec<Photon>, Vec<Photon>) {
    let lights = scene.lights();
    if lights.is_empty() || count == 0 {
        return (Vec::new(), Vec::new());
    }
    let emitter = PhotonEmitter {
        scene,
        stream: (seed, stream),
        scale: 1.0 / count as f32,
        max_bounces,
        wl,
    };
    let parts: Vec<(Vec<Photon>, Vec<Photon>)> = (0..count.div_ceil(BATCH))
        .into_par_iter()
        .map(|b| {
            let (mut out, mut volume) = (Vec::new(), Vec::new());
            if control.cancelled() {
                return (out, volume);
            }
            let mut own: Vec<(Vec<Photon>, Vec<Photon>)> = Vec::new();
            for wave in light_waves(scene.streams_pay(), b * BATCH..((b + 1) * BATCH).min(count)) {
                if wave.end - wave.start == 1 {
                    // One path a wave: straight into the batch's lists.
                    let mut path = emitter.start(wave.start, (&mut out, &mut volume));
                    walk_together(scene, path.as_mut_slice());
                    continue;
                }
                // Each path stores into its own lists, appended in photon order.
                own.resize_with(wave.clone().count(), Default::default);
                let mut paths: Vec<_> = wave
                    .zip(&mut own)
                    .filter_map(|(i, (out, volume))| emitter.start(i, (out, volume)))
                    .collect();
                walk_together(scene, &mut paths);
                for (path_out, path_volume) in &mut own {
                    out.append(path_out);
                    volume.append(path_volume);
                }
            }
            (out, volume)
        })
        .collect();
    let (surface, volume): (Vec<_>, Vec<_>) = parts.into_iter().unzip();
    (surface.concat(), volume.concat())
}

/// What starts [`trace_count_in_media`]'s photons.
struct PhotonEmitter<'s> {
    scene: &'s Scene,
    /// Seed and stream.
    stream: (u64, u64),
    /// Each photon's share of the lights' flux.
    scale: f32,
    max_bounces: u32,
    wl: &'s Wavelengths,
}

impl PhotonEmitter<'_> {
    /// Photon `i`'s walk from a light chosen by power, storing into `(out, volume)`.
    #[inline]
    fn start<'o>(
        &self,
        i: u64,
        (out, volume): (&'o mut Vec<Photon>, &'o mut Vec<Photon>),
    ) -> Option<LightPath<PhysicalPhotons<'o>>> {
        let (scene, (seed, stream)) = (self.scene, self.stream);
        let mut rng = Rng::new(seed, (stream << 40) ^ i);
        let emitted = scene.lights().emit(scene, self.wl, &mut rng)?;
        let flux = emitted.throughput * self.scale;
        let medium = scene.light_medium(emitted.light);
        let surfaces = self.max_bounces.saturating_add(1);
        Some(Walker {
            walk: LightWalk::new(scene, emitted.ray, (flux, medium), surfaces),
            wl: *self.wl,
            rng,
            visitor: PhysicalPhotons {
                max_bounces: self.max_bounces,
                flags: 0,
                out,
                volume: Some(volume),
            },
        })
    }
}

/// Runs `photon(i, out)` for each photon index of a batch; returns what they stored and, for
/// each photon, the number stored up to and including it.
pub(crate) fn trace_batch(
    indices: std::ops::Range<u64>,
    mut photon: impl FnMut(u64, &mut Vec<Photon>),
) -> (Vec<Photon>, Vec<u32>) {
    let mut out = Vec::new();
    let mut ends = Vec::with_capacity((indices.end - indices.start) as usize);
    for i in indices {
        photon(i, &mut out);
        ends.push(out.len() as u32);
    }
    (out, ends)
}

/// A photon on its way: what it carries and what it has met.
#[derive(Clone, Copy, Debug)]
pub struct PhotonState {
    /// Power (flux): RGB, or at the pass's wavelengths.
    pub power: Spectrum,
    /// [`REFLECTED`], [`REFRACTED`], [`DIFFUSE`] and [`DISPERSED`] so far.
    pub flags: u8,
    /// Length of the path so far.
    pub length: f32,
    /// Bounces made so far (surfaces met before the one it is at).
    pub bounces: u32,
}

/// Follows one course photon from `ray` carrying `power`; pushes what it stores to `out`.
pub fn trace_path(
    scene: &Scene,
    model: &CourseModel,
    mut ray: Ray,
    power: Spectrum,
    max_bounces: u32,
    rng: &mut Rng,
    out: &mut Vec<Photon>,
) {
    let mut photon = PhotonState {
        power,
        flags: 0,
        length: 0.0,
        bounces: 0,
    };
    for bounces in 0..=max_bounces {
        let Some(isect) = scene.intersect(&ray, f32::INFINITY) else {
            return;
        };
        let hit = scene.surface(&ray, &isect);
        photon.length += isect.t * ray.dir.length();
        photon.bounces = bounces;
        let Some(dir) = model.interact(scene, &hit, &ray, &mut photon, rng, out) else {
            return;
        };
        ray = Ray::new(hit.ray_origin(dir), dir);
    }
}

/// The course's caustic photons from one light.
pub struct CourseModel<'a> {
    /// The light the photons come from (its falloff scales what is stored).
    pub light: &'a Light,
    /// Store every photon at its first surface instead (a map of direct light, for checks).
    pub first_hit: bool,
    /// Reflect by `reflective` inside glass too, not only by total internal reflection (as the
    /// Whitted renderer's setting of the same name).
    pub internal_reflection: bool,
}

impl CourseModel<'_> {
    /// At `hit` in `scene`, reached along `ray`: pushes what is stored there to `out`, updates
    /// the photon's power and flags, and returns the unit direction it leaves in (`None`:
    /// absorbed).
    fn interact(
        &self,
        scene: &Scene,
        hit: &SurfaceHit,
        ray: &Ray,
        photon: &mut PhotonState,
        rng: &mut Rng,
        out: &mut Vec<Photon>,
    ) -> Option<Vec3> {
        let p = &scene.phong(hit);
        let d = ray.dir;
        let entering = d.dot(hit.geometric_normal) < 0.0;
        let facing = if d.dot(hit.shading_normal) > 0.0 {
            -hit.shading_normal
        } else {
            hit.shading_normal
        };
        // Inside glass the light is what the course's shadow rays already bring through it
        // (filtered by kt): a photon stored there would count it twice.
        let inside_transmissive = !entering && p.transmissive != Vec3::ZERO;
        let receives = (p.diffuse != Vec3::ZERO || p.specular != Vec3::ZERO) && !inside_transmissive;
        if receives && (photon.flags != 0 || self.first_hit) {
            let stored = photon.power.truncate() * falloff_scale(self.light, photon.length);
            out.push(Photon::new(hit.point, stored, d, facing, photon.flags));
        }
        if self.first_hit {
            return None;
        }
        // Inside glass photons reflect as the camera's rays do: only by total internal
        // reflection, unless internal reflection is asked for (so no chain inside can gain power).
        let reflects = self.internal_reflection || !inside_transmissive;
        let pr = if reflects {
            p.reflective.max_element().max(0.0)
        } else {
            0.0
        };
        let pt = p.transmissive.max_element().max(0.0);
        let norm = (pr + pt).max(1.0);
        let (pr, pt) = (pr / norm, pt / norm);
        let u = rng.uniform();
        if u < pr {
            photon.power *= (p.reflective / pr).extend(0.0);
            photon.flags |= REFLECTED;
            Some(reflect(d, facing))
        } else if u < pr + pt {
            photon.power *= (p.transmissive / pt).extend(0.0);
            photon.flags |= REFRACTED;
            let mut index = p.index;
            if let Some(indices) = channel_indices(p.index, scene.abbe(hit)) {
                // A dispersive glass: the photon goes on in one colour channel, chosen by its
                // power (and divided by the probability), refracted by that channel's index.
                let rgb = photon.power.truncate().max(Vec3::ZERO);
                let total = rgb.x + rgb.y + rgb.z;
                if total > 0.0 {
                    let pick = rng.uniform() * total;
                    let c = if pick < rgb.x {
                        0
                    } else if pick < rgb.x + rgb.y {
                        1
                    } else {
                        2
                    };
                    let mut single = Vec3::ZERO;
                    single[c] = total;
                    photon.power = single.extend(0.0);
                    index = indices[c];
                }
            }
            let (eta, n_in) = refraction_geometry(index, entering, hit.shading_normal);
            Some(refract(d, n_in, eta).unwrap_or_else(|| reflect(d, n_in)))
        } else {
            None
        }
    }
}

/// d²·f(d) for a point light's course falloff f; 1 for other lights.
#[inline]
pub fn falloff_scale(light: &Light, path_length: f32) -> f32 {
    match light {
        Light::Point { attenuation, .. } | Light::Spot { attenuation, .. } => {
            path_length * path_length * distance_attenuation(*attenuation, path_length)
        }
        Light::Soft(soft) => path_length * path_length * distance_attenuation(soft.attenuation, path_length),
        _ => 1.0,
    }
}

/// Photons under the physical model: every smooth surface a light walk meets stores one, with
/// the walk's history in its flags.
pub struct PhysicalPhotons<'o> {
    /// The bounces a photon may make (`--depth`): what it has left is stored with it.
    pub max_bounces: u32,
    /// [`REFLECTED`], [`REFRACTED`], [`DIFFUSE`] and [`DISPERSED`] so far.
    pub flags: u8,
    /// Where the photons go.
    pub out: &'o mut Vec<Photon>,
    /// Where photons that scatter in a medium go (`None`: they are not kept).
    pub volume: Option<&'o mut Vec<Photon>>,
}

impl LightVisitor for PhysicalPhotons<'_> {
    // A photon that scatters in a medium is kept there too, its normal the direction it
    // arrived from (a volume photon has none).
    fn visit_medium(&mut self, at: &MediumArrival) -> bool {
        if let Some(volume) = self.volume.as_mut() {
            let left = self
                .max_bounces
                .saturating_sub(at.length - 1)
                .min(MAX_BOUNCES_LEFT as u32) as u8;
            volume.push(Photon::with_spectrum(
                at.hit.point,
                at.throughput,
                -at.wo,
                at.wo,
                self.flags | left << 4,
            ));
        }
        true
    }

    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        // Scattering in a medium is a diffuse bounce: what follows is no caustic.
        self.flags |= DIFFUSE;
        Some((at.sample_phase(rng), Roulette::KeepFlux))
    }

    fn visit(&mut self, at: &LightArrival) -> bool {
        if at.bsdf.is_smooth() {
            let left = self
                .max_bounces
                .saturating_sub(at.length - 1)
                .min(MAX_BOUNCES_LEFT as u32) as u8;
            self.out.push(Photon::with_spectrum(
                at.hit.point,
                at.throughput,
                -at.wo,
                at.bsdf.normal(),
                self.flags | left << 4,
            ));
        }
        true
    }

    fn bounce(&mut self, at: &LightArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        let sample = at
            .bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Importance)?;
        // Recorded now: they matter only to photons stored after the bounce survives.
        if sample.dispersive {
            self.flags |= DISPERSED;
        }
        self.flags |= if !sample.specular {
            DIFFUSE
        } else if sample.transmitted {
            REFRACTED
        } else {
            REFLECTED
        };
        Some((sample, Roulette::KeepFlux))
    }
}
