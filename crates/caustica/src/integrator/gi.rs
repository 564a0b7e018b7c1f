//! Jensen's full photon-mapping method ("Global illumination using photon maps", EGWR 1996),
//! split into independent passes so that it converges and merges like the other integrators.
//!
//! At the first smooth surface a camera path meets (after mirrors and glass): direct light by
//! next-event estimation, caustics from the caustic map (photons that came by mirrors and glass
//! only, L S+ D) within a radius that shrinks pass by pass as in progressive photon mapping (a
//! fixed k-nearest radius would blur a sharp caustic by the same amount forever), and indirect
//! diffuse light by final gathering: a BSDF-sampled gather ray
//! follows mirrors and glass to the next smooth surface and reads the global map's radiance
//! estimate there (photons of every path, direct ones included). The global map's radius starts
//! where about k photons fall and shrinks like the caustic radius, so the method's bias vanishes
//! as passes grow instead of staying at the k-nearest blur of one map. Each pass traces its own maps
//! and one gather ray per pixel, so N passes gather N rays per pixel.
//!
//! A gather ray that reaches a light, directly or by a specular chain, adds nothing: next-event
//! estimation and the caustic map already count those paths.
//!
//! In media, photons are also stored where they scatter (Jensen's volume photon map): a camera
//! path passes the media before its first smooth surface and gathers along the way, as `ppm`
//! does, next-event estimation and the volume photons that did not come straight from a light
//! (the beam radiance estimate, [`BeamEstimate`]); a gather ray that scatters reads every
//! volume photon there, as it reads the global map on a surface.

use super::beam_estimate::BeamEstimate;
use super::direct::{bsdf_can_reach_light, direct_by_bsdf, direct_light, emitted, power_heuristic};
use super::ppm::{pass_wavelengths, settings_spectral, PHOTON_SEED};
use super::radius::{pixel_angle, radius_factor, InitialRadius};
use super::specular_chain::{camera_chain, camera_chains, chain_pass, gathers, AtSmooth, Beyond};
use super::tiles::sample_pass;
use super::Progressive;
use crate::bsdf::{Bsdf, Transport};
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::{Passage, Step};
use crate::photon::map::PhotonMap;
use crate::photon::trace::trace_count_in_media;
use crate::photon::{is_caustic, is_direct, needed_bounces_left};
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::Scene;
use crate::spectrum::{Spectrum, Wavelengths};

/// Settings of the photon-map global illumination integrator.
#[derive(Clone, Debug, PartialEq)]
pub struct GiSettings {
    /// Photons emitted per pass (they fill both maps).
    pub photons_per_pass: u64,
    /// Photons a global-map estimate holds on average in the first pass (its radius then
    /// shrinks pass by pass like the caustic radius).
    pub k_global: usize,
    /// Caustic-map gather radius of the first pass; it shrinks like progressive photon mapping's.
    pub caustic_radius: InitialRadius,
    /// Knaus & Zwicker's α for the caustic radius.
    pub alpha: f32,
    /// `--depth` N: light reaches the eye after scattering at no more than N + 1 surfaces
    /// ([`scattering_surfaces`](super::config::scattering_surfaces)), counting the mirrors and
    /// glass of the camera path, the surfaces its final gather meets and the bounces of the
    /// photons it reads there ([`Photon::bounces_left`](crate::photon::Photon::bounces_left)).
    pub max_depth: u32,
    /// Follow camera rays through mirrors and glass (off: what a camera sees by a mirror or
    /// through glass is black, as in a particle tracer's image — for comparing with one).
    pub specular_camera_paths: bool,
    /// Carry light at sampled wavelengths instead of RGB (`None`: when the scene has a
    /// dispersive glass).
    pub spectral: Option<bool>,
}

impl Default for GiSettings {
    fn default() -> Self {
        GiSettings {
            photons_per_pass: 200_000,
            k_global: 50,
            caustic_radius: InitialRadius::Pixels(2.0),
            alpha: 2.0 / 3.0,
            max_depth: 64,
            specular_camera_paths: true,
            spectral: None,
        }
    }
}

/// One pass's two maps and their largest gather radii.
pub struct GiMaps {
    /// Every stored photon.
    pub global: PhotonMap,
    /// Photons that came by mirrors and glass only.
    pub caustic: PhotonMap,
    /// Every photon stored where it scattered in a medium (gather rays read it)...
    pub volume: PhotonMap,
    /// ...and those that did not come straight from a light (camera paths read them beside
    /// next-event estimation).
    pub volume_indirect: PhotonMap,
    /// Twice the typical distance to the k-th nearest global photon.
    global_radius: f32,
    /// The same among the volume photons.
    volume_radius: f32,
    /// This pass's shrink factor of the gather radii.
    caustic_factor: f32,
}

/// The integrator over a whole image.
pub struct Gi<'a> {
    scene: &'a Scene,
    /// The scene's camera fitted to the image ([`Camera::fitted`]).
    camera: crate::camera::Camera,
    settings: GiSettings,
    width: usize,
    height: usize,
    seed: u64,
    pixel_angle: f32,
    /// Whether direct light also comes by BSDF sampling (emissive objects or a sky), weighted
    /// against the light sample.
    mis: bool,
    /// Whether light is carried at sampled wavelengths.
    spectral: bool,
    /// Whether a tile's camera chains walk together ([`Scene::streams_pay`]).
    pub(super) waves: bool,
}

impl<'a> Gi<'a> {
    /// A renderer for `scene` at `width`×`height`.
    pub fn new(scene: &'a Scene, settings: GiSettings, width: usize, height: usize, seed: u64) -> Gi<'a> {
        let camera = scene.camera().fitted(width, height);
        Gi {
            scene,
            width,
            height,
            seed,
            pixel_angle: pixel_angle(&camera, height),
            camera,
            mis: bsdf_can_reach_light(scene),
            spectral: settings_spectral(&settings.spectral, scene),
            waves: scene.streams_pay(),
            settings,
        }
    }

    /// The maps of pass `pass`, at the pass's wavelengths `wl`.
    pub fn maps(&self, pass: u64, wl: &Wavelengths, control: Control) -> GiMaps {
        let (photons, volume) = trace_count_in_media(
            self.scene,
            self.settings.photons_per_pass,
            (self.seed ^ PHOTON_SEED, pass),
            self.settings.max_depth,
            wl,
            control,
        );
        let caustic: Vec<_> = photons.iter().copied().filter(is_caustic).collect();
        let volume_indirect: Vec<_> = volume.iter().copied().filter(|p| !is_direct(p)).collect();
        let global = PhotonMap::new(photons);
        let caustic = PhotonMap::new(caustic);
        let volume = PhotonMap::new(volume);
        let volume_indirect = PhotonMap::new(volume_indirect);
        // Largest radii: past these a k-NN estimate reaches across the scene for nothing.
        let global_radius = global.typical_radius(self.settings.k_global) * 2.0;
        let volume_radius = if volume.is_empty() {
            0.0
        } else {
            volume.typical_radius(self.settings.k_global) * 2.0
        };
        GiMaps {
            global,
            caustic,
            volume,
            volume_indirect,
            global_radius,
            volume_radius,
            caustic_factor: radius_factor(pass, self.settings.alpha),
        }
    }

    fn radiance(&self, maps: &GiMaps, ray: Ray, wl: &Wavelengths, rng: &mut Rng) -> Spectrum {
        let s = &self.settings;
        camera_chain(
            self.scene,
            ray,
            s.max_depth,
            (s.specular_camera_paths, false),
            wl,
            rng,
            self.gathers(maps, wl),
            &mut self.beams(maps, wl),
        )
    }

    /// [`Gi::radiance`] along each of a tile's camera rays, walked together.
    fn radiances(&self, maps: &GiMaps, starts: Vec<(Ray, Rng)>, wl: &Wavelengths) -> Vec<Spectrum> {
        let s = &self.settings;
        camera_chains(
            self.scene,
            starts,
            s.max_depth,
            (s.specular_camera_paths, false),
            wl,
            self.gathers(maps, wl),
            || self.beams(maps, wl),
        )
    }

    /// What a camera chain gathers at its smooth surface (next-event estimation and the
    /// caustic photons around it) and beyond it (a final gather).
    fn gathers<'s>(
        &'s self,
        maps: &'s GiMaps,
        wl: &'s Wavelengths,
    ) -> (impl AtSmooth + Clone + 's, impl Beyond + Clone + 's) {
        let s = &self.settings;
        gathers(
            move |hit, bsdf, wo, path_length, dispersed, left, _caustic_only, rng| {
                let r = s.caustic_radius.at(self.pixel_angle, path_length) * maps.caustic_factor;
                let min_left = needed_bounces_left(s.max_depth, left);
                let direct = direct_light(self.scene, hit, bsdf, wo, self.mis, wl, rng);
                if bsdf.is_phase() {
                    // In a medium: the volume photons within a ball, as ppm gathers them.
                    let sigma_s = self.scene.medium(hit.media.back).sigma_s_at(hit.point, wl);
                    let indirect = &maps.volume_indirect;
                    return direct
                        + indirect.in_scattered_within(hit.point, bsdf, wo, (r, min_left), dispersed, sigma_s);
                }
                direct
                    + maps
                        .caustic
                        .radiance_within(hit.point, bsdf, wo, (r, min_left), dispersed)
            },
            move |hit, sample, path_length, dispersed, left, rng| {
                if hit.is_in_medium() {
                    // The volume photons counted the rest.
                    return if self.mis {
                        sample.weight * direct_by_bsdf(self.scene, hit, sample, wl, rng)
                    } else {
                        Spectrum::ZERO
                    };
                }
                let origin = hit.ray_origin(sample.wi);
                let gather = Gather {
                    from: Some((hit.point, sample.pdf)),
                    path_length,
                    dispersed,
                    level: 0,
                    left,
                    medium: hit.media.towards(hit.geometric_normal, sample.wi),
                };
                sample.weight * self.gather(maps, Ray::new(origin, sample.wi), gather, wl, rng)
            },
        )
    }

    /// The beam estimate of a camera chain's segments through media.
    fn beams<'s>(&'s self, maps: &'s GiMaps, wl: &'s Wavelengths) -> BeamEstimate<'s> {
        let s = &self.settings;
        BeamEstimate {
            scene: self.scene,
            volume: &maps.volume_indirect,
            radius: s.caustic_radius,
            pixel_angle: self.pixel_angle,
            factor: maps.caustic_factor,
            max_depth: s.max_depth,
            wl,
        }
    }

    /// Light arriving along a gather ray: the global map's estimate at the smooth surface it
    /// reaches through mirrors and glass. Where that surface is closer than the global map's
    /// gather radius (corners, contact shadows) the map's blur would show, so up to
    /// [`EXACT_LEVELS`] times the light there is computed like at the first surface instead.
    /// Emission the ray meets straight away (an emitter or the sky) counts weighted against the
    /// light sample of the point it left (`from`: that point and the ray's pdf; none when the
    /// ray left by a specular lobe, whose lights the caustic map counts). Each surface the ray
    /// meets uses one of the surfaces `--depth` leaves the path (`at.left`), and photons read
    /// at one have bounced no more often than the path may still scatter beyond it: at
    /// `--depth` N light never comes from more than N + 1 surfaces, as in the other integrators.
    fn gather(&self, maps: &GiMaps, ray: Ray, at: Gather, wl: &Wavelengths, rng: &mut Rng) -> Spectrum {
        let scene = self.scene;
        let lights = scene.lights();
        let s = &self.settings;
        let mut ray = ray;
        let mut beta = wl.grey(1.0);
        let mut dispersed = at.dispersed;
        let mut path_length = at.path_length;
        let mut segment = 0.0f32;
        // Emission at the first surface (or sky) the ray meets, weighted against the light sample.
        let mut emitted_first = Spectrum::ZERO;
        let mut direct_from = at.from.filter(|_| self.mis);
        let mut left = at.left;
        let mut passage = Passage::new(scene, at.medium);
        loop {
            let hit = match passage.next(scene, &ray, &mut beta, wl, rng) {
                Step::Escaped => {
                    if let Some((_, pdf)) = direct_from {
                        return beta * lights.escaped_weighted(ray.dir, Some(pdf), wl);
                    }
                    break;
                }
                Step::Medium(hit) => {
                    // Scattered in a medium: every volume photon there.
                    if left == 0 {
                        break;
                    }
                    let wo = -ray.dir.normalize();
                    let medium = scene.medium(hit.media.back);
                    let phase = Bsdf::phase(medium.phase.g, wo, wl);
                    let r = maps.volume_radius * 0.5 * maps.caustic_factor;
                    let min_left = needed_bounces_left(s.max_depth, left - 1);
                    let sigma_s = medium.sigma_s_at(hit.point, wl);
                    let l = maps
                        .volume
                        .in_scattered_within(hit.point, &phase, wo, (r, min_left), dispersed, sigma_s);
                    return emitted_first + beta * l;
                }
                Step::Surface(hit) => hit,
            };
            // (Gather rays' directions are unit: the parameter is the distance.)
            path_length += hit.t;
            segment += hit.t;
            let wo = -ray.dir;
            if let Some((point, pdf)) = direct_from.take() {
                let le = emitted(scene, &hit, wo, wl);
                if le != Spectrum::ZERO {
                    emitted_first = beta * le * power_heuristic(pdf, lights.pdf_direct(point, &hit));
                }
            }
            // Past the surfaces `--depth` allows, only what this one emits counts.
            if left == 0 {
                break;
            }
            left -= 1;
            let bsdf = Bsdf::at(scene, &hit, wo, wl);
            if bsdf.is_black() {
                break;
            }
            if bsdf.is_smooth() {
                let min_left = needed_bounces_left(s.max_depth, left);
                if at.level >= EXACT_LEVELS || segment > maps.global_radius {
                    let r = maps.global_radius * 0.5 * maps.caustic_factor;
                    let global = maps
                        .global
                        .radiance_within(hit.point, &bsdf, wo, (r, min_left), dispersed);
                    return emitted_first + beta * global;
                }
                let r = s.caustic_radius.at(self.pixel_angle, path_length) * maps.caustic_factor;
                let mut l = direct_light(scene, &hit, &bsdf, wo, self.mis, wl, rng);
                l += maps
                    .caustic
                    .radiance_within(hit.point, &bsdf, wo, (r, min_left), dispersed);
                if let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) {
                    let next = Ray::new(hit.ray_origin(sample.wi), sample.wi);
                    let mut weight = sample.weight;
                    let mut next_dispersed = dispersed;
                    if sample.dispersive {
                        wl.terminate_secondary(&mut weight, &mut next_dispersed);
                    }
                    let deeper = Gather {
                        from: (!sample.specular).then_some((hit.point, sample.pdf)),
                        path_length,
                        dispersed: next_dispersed,
                        level: at.level + 1,
                        left,
                        medium: hit.media.towards(hit.geometric_normal, sample.wi),
                    };
                    l += weight * self.gather(maps, next, deeper, wl, rng);
                }
                return emitted_first + beta * l;
            }
            let Some(sample) = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance) else {
                break;
            };
            beta *= sample.weight;
            if sample.dispersive {
                wl.terminate_secondary(&mut beta, &mut dispersed);
            }
            passage.cross(scene, &hit, &sample);
            ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
        }
        emitted_first
    }
}

/// Where a gather ray starts: the point and pdf it left by (for weighting the emission it meets
/// straight away; none after a specular lobe), the camera path's length so far, whether the
/// camera path has dispersed, how many gathers deep it is, at how many more surfaces the path
/// may scatter beyond the one it leaves, and the medium it starts in.
#[derive(Clone, Copy, Debug)]
struct Gather {
    from: Option<(Vec3, f32)>,
    path_length: f32,
    dispersed: bool,
    level: u32,
    left: u32,
    /// The medium the ray starts in.
    medium: u32,
}

/// Gather bounces computed exactly, rather than read from the global map, for close surfaces.
const EXACT_LEVELS: u32 = 2;

impl Progressive for Gi<'_> {
    fn render_pass(&self, pass: u64, control: Control) -> Option<Vec<Vec3>> {
        let wl = pass_wavelengths(self.spectral, self.seed, pass);
        let maps = self.maps(pass, &wl, control);
        if control.cancelled() {
            return None;
        }
        let camera = &self.camera;
        if self.waves {
            // A tile's chains walked together: the same random streams, so the same image.
            let size = (self.width, self.height, self.seed);
            return chain_pass(size, pass, control, camera, &wl, |starts| {
                self.radiances(&maps, starts, &wl)
            });
        }
        sample_pass(self.width, self.height, self.seed, pass, control, |sx, sy, rng| {
            wl.to_rgb(self.radiance(&maps, camera.generate_ray(sx, sy), &wl, rng))
        })
    }
}
