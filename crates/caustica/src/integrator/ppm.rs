//! Progressive photon mapping in Knaus & Zwicker's probabilistic form ("Progressive photon
//! mapping: a probabilistic approach", TOG 2011): every pass is an independent photon-mapping
//! render whose gather radius shrinks with the pass index, r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1), and the
//! image is the mean of the passes. Bias and variance both vanish as passes grow, so the mean
//! converges to the true image — caustics of point lights included.
//!
//! Per pass: photons from every light are traced and stored on smooth surfaces after at least
//! one bounce; camera paths follow mirrors and glass to their first smooth surface, where direct
//! light comes from next-event estimation and everything else (caustics, indirect diffuse light)
//! from the photons within the pass's radius.

use super::beam_estimate::BeamEstimate;
use super::direct::{bsdf_can_reach_light, direct_by_bsdf, direct_light};
use super::radius::{pixel_angle, radius_factor, InitialRadius};
use super::specular_chain::{camera_chain, camera_chains, chain_pass, gathers, AtSmooth, Beyond};
use super::tiles::sample_pass;
use super::Progressive;
use crate::math::{Ray, Vec3};
use crate::photon::map::PhotonMap;
use crate::photon::trace::trace_count_in_media;
use crate::photon::{is_caustic, is_direct, needed_bounces_left, Photon};
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::Scene;
use crate::spectrum::{Spectrum, Wavelengths};

/// Settings of progressive photon mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct PpmSettings {
    /// Photons emitted per pass.
    pub photons_per_pass: u64,
    /// Knaus & Zwicker's α in (0, 1): the share of the radius reduction kept per pass.
    pub alpha: f32,
    /// Radius of the first pass.
    pub initial_radius: InitialRadius,
    /// `--depth` N: light reaches the eye after scattering at no more than N + 1 surfaces
    /// ([`scattering_surfaces`](super::config::scattering_surfaces)): camera paths follow at
    /// most N mirrors and glass to a smooth surface, and photons gathered there after k of
    /// them have made at most N − k bounces.
    pub max_depth: u32,
    /// Follow camera rays through mirrors and glass (off: what a camera sees by a mirror or
    /// through glass is black, as in a particle tracer's image — for comparing with one).
    pub specular_camera_paths: bool,
    /// Follow camera rays through sharp highlights ([`Bsdf::is_sharply_glossy`]), which then
    /// gather only the photons that came by mirrors and glass alone (off: the paths end there
    /// and the peaked lobe weighs every photon, as before 2026-12-03).
    ///
    /// [`Bsdf::is_sharply_glossy`]: crate::bsdf::Bsdf::is_sharply_glossy
    pub glossy_camera_paths: bool,
    /// Carry light at sampled wavelengths instead of RGB (`None`: when the scene has a
    /// dispersive glass).
    pub spectral: Option<bool>,
}

impl Default for PpmSettings {
    fn default() -> Self {
        PpmSettings {
            photons_per_pass: 200_000,
            alpha: 2.0 / 3.0,
            initial_radius: InitialRadius::Pixels(2.0),
            max_depth: 64,
            specular_camera_paths: true,
            glossy_camera_paths: true,
            spectral: None,
        }
    }
}

/// Seed offset that separates photon streams from camera streams.
pub(crate) const PHOTON_SEED: u64 = 0x70_686f_746f_6e73;

/// Seed offset of the streams that draw each pass's wavelengths.
pub(crate) const WAVELENGTH_SEED: u64 = 0x7761_7665_6c65_6e67;

/// The wavelengths every path of pass `pass` carries: photons and camera paths must agree, so
/// one set serves the whole pass (RGB channels when not `spectral`). Passes draw them from the
/// van der Corput sequence (randomly shifted by the seed), so any run of consecutive passes
/// covers the spectrum evenly and colour converges like 1/passes rather than its square root.
pub(crate) fn pass_wavelengths(spectral: bool, seed: u64, pass: u64) -> Wavelengths {
    if !spectral {
        return Wavelengths::Rgb;
    }
    let shift = Rng::new(seed ^ WAVELENGTH_SEED, 0).uniform() as f64;
    let u = (radical_inverse(pass) + shift).fract();
    Wavelengths::sample(u as f32)
}

/// The base-2 radical inverse of `i`: its bits mirrored about the binary point.
fn radical_inverse(i: u64) -> f64 {
    i.reverse_bits() as f64 * (1.0 / 18_446_744_073_709_551_616.0)
}

/// Whether a scene renders spectrally: as asked, or when it has a dispersive glass.
pub(crate) fn settings_spectral(asked: &Option<bool>, scene: &Scene) -> bool {
    asked.unwrap_or_else(|| scene.has_dispersion())
}

/// The progressive photon mapper over a whole image.
pub struct Ppm<'a> {
    scene: &'a Scene,
    /// The scene's camera fitted to the image ([`Camera::fitted`]).
    camera: crate::camera::Camera,
    settings: PpmSettings,
    width: usize,
    height: usize,
    seed: u64,
    /// Width of a pixel at unit distance from the eye.
    pixel_angle: f32,
    /// Whether direct light also comes by BSDF sampling (emissive objects or a sky), weighted
    /// against the light sample.
    mis: bool,
    /// Whether light is carried at sampled wavelengths.
    spectral: bool,
    /// Whether a tile's camera chains walk together ([`Scene::streams_pay`]).
    pub(super) waves: bool,
}

impl<'a> Ppm<'a> {
    /// A renderer for `scene` at `width`×`height`.
    pub fn new(scene: &'a Scene, settings: PpmSettings, width: usize, height: usize, seed: u64) -> Ppm<'a> {
        let camera = scene.camera().fitted(width, height);
        let pixel_angle = pixel_angle(&camera, height);
        Ppm {
            scene,
            camera,
            width,
            height,
            seed,
            pixel_angle,
            mis: bsdf_can_reach_light(scene),
            spectral: settings_spectral(&settings.spectral, scene),
            waves: scene.streams_pay(),
            settings,
        }
    }

    /// The photons of pass `pass` that the estimate uses (all but direct ones), at the pass's
    /// wavelengths `wl`.
    pub fn photon_map(&self, pass: u64, wl: &Wavelengths, control: Control) -> PhotonMap {
        self.photon_maps(pass, wl, control).0
    }

    /// The photons of pass `pass` that the estimate uses, on surfaces and in media.
    fn photon_maps(&self, pass: u64, wl: &Wavelengths, control: Control) -> (PhotonMap, PhotonMap) {
        let (mut photons, mut volume) = trace_count_in_media(
            self.scene,
            self.settings.photons_per_pass,
            (self.seed ^ PHOTON_SEED, pass),
            self.settings.max_depth,
            wl,
            control,
        );
        photons.retain(|p| !is_direct(p));
        volume.retain(|p| !is_direct(p));
        (PhotonMap::new(photons), PhotonMap::new(volume))
    }

    /// Radiance along a camera ray with the photons of one pass: smooth lobes are counted in
    /// full at the first smooth surface that is not sharply glossy (next-event estimation and
    /// photons); specular lobes and sharp highlights continue the path, a highlight counting
    /// direct light and the photons that reached it by mirrors and glass alone.
    fn radiance(
        &self,
        maps: (&PhotonMap, &PhotonMap),
        ray: Ray,
        radius_factor: f32,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Spectrum {
        camera_chain(
            self.scene,
            ray,
            self.settings.max_depth,
            self.through(),
            wl,
            rng,
            self.gathers(maps, radius_factor, wl),
            &mut self.beams(maps.1, radius_factor, wl),
        )
    }

    /// [`Ppm::radiance`] along each of a tile's camera rays, walked together.
    fn radiances(
        &self,
        maps: (&PhotonMap, &PhotonMap),
        starts: Vec<(Ray, Rng)>,
        radius_factor: f32,
        wl: &Wavelengths,
    ) -> Vec<Spectrum> {
        camera_chains(
            self.scene,
            starts,
            self.settings.max_depth,
            self.through(),
            wl,
            self.gathers(maps, radius_factor, wl),
            || self.beams(maps.1, radius_factor, wl),
        )
    }

    /// Whether camera paths go on through mirrors and glass, and through sharp highlights.
    fn through(&self) -> (bool, bool) {
        (self.settings.specular_camera_paths, self.settings.glossy_camera_paths)
    }

    /// What a camera chain gathers at its smooth surface (next-event estimation and the
    /// photons around it) and beyond it (the BSDF half of direct light).
    fn gathers<'s>(
        &'s self,
        (map, volume): (&'s PhotonMap, &'s PhotonMap),
        radius_factor: f32,
        wl: &'s Wavelengths,
    ) -> (impl AtSmooth + Clone + 's, impl Beyond + Clone + 's) {
        gathers(
            move |hit, bsdf, wo, path_length, dispersed, left, caustic_only, rng| {
                let r = self.settings.initial_radius.at(self.pixel_angle, path_length) * radius_factor;
                let min_left = needed_bounces_left(self.settings.max_depth, left);
                let direct = direct_light(self.scene, hit, bsdf, wo, self.mis, wl, rng);
                if bsdf.is_phase() {
                    // In a medium: the volume photons within a ball of the same radius.
                    let sigma_s = self.scene.medium(hit.media.back).sigma_s_at(hit.point, wl);
                    return direct + volume.in_scattered_within(hit.point, bsdf, wo, (r, min_left), dispersed, sigma_s);
                }
                let kept = |photon: &Photon| !caustic_only || is_caustic(photon);
                direct + map.radiance_within_of(hit.point, bsdf, wo, (r, min_left), dispersed, kept)
            },
            move |hit, sample, _, _, _, rng| {
                if self.mis {
                    sample.weight * direct_by_bsdf(self.scene, hit, sample, wl, rng)
                } else {
                    Spectrum::ZERO
                }
            },
        )
    }

    /// The beam estimate of a camera chain's segments through media.
    fn beams<'s>(&'s self, volume: &'s PhotonMap, radius_factor: f32, wl: &'s Wavelengths) -> BeamEstimate<'s> {
        BeamEstimate {
            scene: self.scene,
            volume,
            radius: self.settings.initial_radius,
            pixel_angle: self.pixel_angle,
            factor: radius_factor,
            max_depth: self.settings.max_depth,
            wl,
        }
    }
}

impl Progressive for Ppm<'_> {
    fn render_pass(&self, pass: u64, control: Control) -> Option<Vec<Vec3>> {
        let wl = pass_wavelengths(self.spectral, self.seed, pass);
        let (map, volume) = self.photon_maps(pass, &wl, control);
        if control.cancelled() {
            return None;
        }
        let factor = radius_factor(pass, self.settings.alpha);
        let camera = &self.camera;
        if self.waves {
            // A tile's chains walked together: the same random streams, so the same image.
            let size = (self.width, self.height, self.seed);
            return chain_pass(size, pass, control, camera, &wl, |starts| {
                self.radiances((&map, &volume), starts, factor, &wl)
            });
        }
        sample_pass(self.width, self.height, self.seed, pass, control, |sx, sy, rng| {
            wl.to_rgb(self.radiance((&map, &volume), camera.generate_ray(sx, sy), factor, &wl, rng))
        })
    }
}
