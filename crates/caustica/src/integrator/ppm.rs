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

use super::direct::{bsdf_can_reach_light, direct_by_bsdf, direct_light};
use super::radius::{pixel_angle, radius_factor, InitialRadius};
use super::specular_chain::camera_chain;
use super::tiles::sample_pass;
use super::Progressive;
use crate::math::{Ray, Vec3};
use crate::photon::is_direct;
use crate::photon::map::PhotonMap;
use crate::photon::trace::trace_count;
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::Scene;

/// Settings of progressive photon mapping.
#[derive(Clone, Debug, PartialEq)]
pub struct PpmSettings {
    /// Photons emitted per pass.
    pub photons_per_pass: u64,
    /// Knaus & Zwicker's α in (0, 1): the share of the radius reduction kept per pass.
    pub alpha: f32,
    /// Radius of the first pass.
    pub initial_radius: InitialRadius,
    /// Longest specular chain from the camera, and longest photon path.
    pub max_depth: u32,
    /// Follow camera rays through mirrors and glass (off: what a camera sees by a mirror or
    /// through glass is black, as in a particle tracer's image — for comparing with one).
    pub specular_camera_paths: bool,
}

impl Default for PpmSettings {
    fn default() -> Self {
        PpmSettings {
            photons_per_pass: 200_000,
            alpha: 2.0 / 3.0,
            initial_radius: InitialRadius::Pixels(2.0),
            max_depth: 64,
            specular_camera_paths: true,
        }
    }
}

/// Seed offset that separates photon streams from camera streams.
pub(crate) const PHOTON_SEED: u64 = 0x70_686f_746f_6e73;

/// The progressive photon mapper over a whole image.
pub struct Ppm<'a> {
    scene: &'a Scene,
    settings: PpmSettings,
    width: usize,
    height: usize,
    seed: u64,
    /// Width of a pixel at unit distance from the eye.
    pixel_angle: f32,
    /// Whether direct light also comes by BSDF sampling (emissive objects or a sky), weighted
    /// against the light sample.
    mis: bool,
}

impl<'a> Ppm<'a> {
    /// A renderer for `scene` at `width`×`height`.
    pub fn new(scene: &'a Scene, settings: PpmSettings, width: usize, height: usize, seed: u64) -> Ppm<'a> {
        let pixel_angle = pixel_angle(scene.camera(), height);
        Ppm {
            scene,
            settings,
            width,
            height,
            seed,
            pixel_angle,
            mis: bsdf_can_reach_light(scene),
        }
    }

    /// The photons of pass `pass` that the estimate uses (all but direct ones).
    pub fn photon_map(&self, pass: u64, control: Control) -> PhotonMap {
        let mut photons = trace_count(
            self.scene,
            self.settings.photons_per_pass,
            self.seed ^ PHOTON_SEED,
            pass,
            self.settings.max_depth,
            control,
        );
        photons.retain(|p| !is_direct(p));
        PhotonMap::new(photons)
    }

    /// Radiance along a camera ray with the photons of one pass: smooth lobes are counted in
    /// full at the first smooth surface (next-event estimation and photons), only specular ones
    /// continue the path.
    fn radiance(&self, map: &PhotonMap, ray: Ray, radius_factor: f32, rng: &mut Rng) -> Vec3 {
        camera_chain(
            self.scene,
            ray,
            self.settings.max_depth,
            self.settings.specular_camera_paths,
            rng,
            |hit, bsdf, wo, path_length, rng| {
                let r = self.settings.initial_radius.at(self.pixel_angle, path_length) * radius_factor;
                direct_light(self.scene, hit, bsdf, wo, self.mis, rng) + map.radiance_within(hit.point, bsdf, wo, r)
            },
            |hit, sample, _, _| {
                if self.mis {
                    sample.weight * direct_by_bsdf(self.scene, hit, sample)
                } else {
                    Vec3::ZERO
                }
            },
        )
    }
}

impl Progressive for Ppm<'_> {
    fn render_pass(&self, pass: u64, control: Control) -> Option<Vec<Vec3>> {
        let map = self.photon_map(pass, control);
        if control.cancelled() {
            return None;
        }
        let factor = radius_factor(pass, self.settings.alpha);
        let camera = self.scene.camera();
        sample_pass(self.width, self.height, self.seed, pass, control, |sx, sy, rng| {
            self.radiance(&map, camera.generate_ray(sx, sy), factor, rng)
        })
    }
}
