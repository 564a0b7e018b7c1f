//! Light leaving the lights: the start of every photon and light subpath (photon mapping's
//! photons, the light tracer's paths, vcm's light subpaths), with the densities weights need —
//! how likely emission made a point and a direction (pbrt-v4's `SampleLe`/`PDF_Le`, SmallVCM's
//! `Emit`). Next-event estimation's side is [`super::LightSet::sample_light`]; the two meet in
//! [`Emitters::emission_pdf_of`].
//!
//! Every light takes part in every strategy it can. A directional light, a sun or the sky
//! starts its light on a plane across its beam outside the scene ([`Beam`]; the sky's beam is
//! the direction its own sampling draws), so their densities are per unit area across the
//! beam, with no distance to the first vertex. The course forks' lights with a size start
//! theirs from a point on them; no ray meets them, so camera paths reach them by next-event
//! estimation alone.
//!
//! Aiming ([`Aim`]): a share of the light leaves towards the bounding spheres of the mirrors
//! and glass (the caustics' sources), the rest everywhere the light shines; near lights (points,
//! spots, emissive objects, lights with a size) and far ones (directional lights, suns, the
//! sky) each have their own aim. A sphere lamp aims from the half of it that faces the chosen
//! target. Every density is the mixture's, for the throughput and for every strategy's weight
//! alike, so aiming changes where the samples go, never the expected image. Photon mapping
//! aims the far lights at the mirrors and glass in view ([`LightSet::emit`]); the course model
//! aims all its light at the caustics' sources; vcm chooses its shares ([`crate::integrator::vcm`]).

use super::aim::{Aim, LampAim};
use super::area::{AreaLight, AreaSample};
use super::beam::Beam;
use super::{DirectSample, Light, LightSet};
use crate::description::EmittingFaces;
use crate::math::{Ray, Vec3};
use crate::sampling::{Distribution1D, Rng};
use crate::scene::Scene;
use crate::spectrum::{Spectrum, Wavelengths};
use glam::Vec2;
use std::f32::consts::PI;

/// What one emission sample of a light draws from: the scene, the light's number and the
/// probability it was taken with, the sample's two random pairs (the point's and the
/// direction's), and the wavelengths.
#[derive(Clone, Copy)]
pub(super) struct EmitArgs<'a> {
    pub scene: &'a Scene,
    pub number: usize,
    pub pick: f32,
    pub u: Vec2,
    pub u_dir: Vec2,
    pub wl: &'a Wavelengths,
}

impl<'a> EmitArgs<'a> {
    /// The light's number, its probability, the two random pairs and the wavelengths.
    pub(super) fn parts(self) -> (usize, f32, Vec2, Vec2, &'a Wavelengths) {
        (self.number, self.pick, self.u, self.u_dir, self.wl)
    }
}

/// The lights that start photons and light subpaths, chosen in proportion to their power.
#[derive(Clone, Debug, Default)]
pub struct Emitters {
    /// Probability of choosing each light of the scene's set (0: not an emitter here).
    pub(super) probability: Vec<f32>,
    /// Light numbers of the emitters, and their choice distribution.
    numbers: Vec<usize>,
    choice: Option<Distribution1D>,
    /// Where points, spots, emissive objects and lights with a size aim a share of their light.
    pub(super) near: Option<Aim>,
    /// Each sphere lamp's view of `near`'s targets (by light number; `None`: not a sphere lamp,
    /// or nothing aimed at).
    lamps: Vec<Option<LampAim>>,
    /// Where directional lights, suns and the sky aim a share of theirs.
    pub(super) far: Option<Aim>,
    /// Each light's beam, for the directional lights and suns.
    pub(super) beams: Vec<Option<Beam>>,
    /// The scene's sphere, for the sky's beams (one per direction).
    pub(super) sphere: (Vec3, f32),
}

/// The start of a light subpath.
#[derive(Clone, Copy, Debug)]
pub struct Emission {
    /// Leaves the light.
    pub ray: Ray,
    /// Radiance × cosine over the density of the whole sample (choice of light included).
    pub throughput: Spectrum,
    /// Density of the point (area) × direction (solid angle), choice of light included.
    pub emission_pdf: f32,
    /// Cosine between the direction and the light's normal (1 for a point).
    pub cos: f32,
    /// The light is a point or spot.
    pub delta: bool,
    /// Light number.
    pub light: usize,
    /// The point's unit normal (for an emissive object; the direction for a point).
    pub normal: Vec3,
    /// The light is a directional light or a sun: the densities are across the beam, and the
    /// first segment's length does not change them.
    pub far: bool,
    /// The point on a light with an area it left, for the light tracer to show the light itself.
    pub origin: Option<EmissionPoint>,
}

/// A sampled point on an emitting surface.
#[derive(Clone, Copy, Debug)]
pub struct EmissionPoint {
    /// World position.
    pub point: Vec3,
    /// Unit geometric normal, naming its faces.
    pub normal: Vec3,
    /// The faces light leaves by.
    pub faces: EmittingFaces,
    /// Emitted radiance over the density of the point (area density × the light's choice).
    pub radiance: Spectrum,
}

impl LightSet {
    /// One photon from a light chosen by power: its throughput is its flux before division by
    /// the number of photons emitted. `None` if the sample carries nothing.
    pub fn emit(&self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng) -> Option<Emission> {
        self.emitters().emit(scene, wl, rng)
    }
}

impl Emitters {
    /// The emitters of `lights` in the scene's sphere (`center`, `radius`): points, spots,
    /// emissive objects and lights with a size aimed as `near` says, directional lights, suns
    /// and the sky as `far` says.
    pub fn new(lights: &[Light], sphere: (Vec3, f32), near: Option<Aim>, far: Option<Aim>) -> Emitters {
        let powers: Vec<f32> = lights.iter().map(|light| light.power(sphere.1).max(0.0)).collect();
        let (targets, share) = far.as_ref().map_or((&[][..], 0.0), |a| (a.targets(), a.share()));
        let beams = lights
            .iter()
            .map(|light| match *light {
                Light::Directional { direction, .. } => Some(Beam::new(direction, None, sphere, targets, share)),
                Light::Sun {
                    direction,
                    cos_max,
                    one_minus_cos,
                    ..
                } => Some(Beam::new(
                    direction,
                    Some((cos_max, one_minus_cos)),
                    sphere,
                    targets,
                    share,
                )),
                _ => None,
            })
            .collect();
        let numbers: Vec<usize> = (0..powers.len()).filter(|&i| powers[i] > 0.0).collect();
        let total: f32 = numbers.iter().map(|&i| powers[i]).sum();
        let probability = powers
            .iter()
            .map(|&p| {
                if total > 0.0 && total.is_finite() {
                    p / total
                } else {
                    0.0
                }
            })
            .collect();
        let weights: Vec<f32> = numbers.iter().map(|&i| powers[i]).collect();
        let choice = (total > 0.0 && total.is_finite()).then(|| Distribution1D::new(&weights));
        let lamps = lights
            .iter()
            .map(|light| match (light, &near) {
                (Light::Area(area), Some(aim)) => {
                    area.sphere().map(|(center, radius)| aim.seen_from_lamp(center, radius))
                }
                _ => None,
            })
            .collect();
        Emitters {
            probability,
            numbers,
            choice,
            lamps,
            near,
            far,
            beams,
            sphere,
        }
    }

    /// Solid-angle density of a direction `dir` leaving `from`, whose density without aiming
    /// is `plain`: the mixture of that and the aimed cones.
    pub(super) fn direction_pdf(&self, from: Vec3, dir: Vec3, plain: f32) -> f32 {
        match &self.near {
            None => plain,
            Some(aim) => (1.0 - aim.share()) * plain + aim.share() * aim.pdf(from, dir),
        }
    }

    /// Draws whether this subpath is aimed; if so, the aim and the random numbers its sample
    /// uses.
    pub(super) fn aimed_lobe(&self, rng: &mut Rng) -> Option<(&Aim, f32, Vec2)> {
        let aim = self.near.as_ref()?;
        let (u_lobe, u_pick, u) = (rng.uniform(), rng.uniform(), rng.uniform2());
        (u_lobe < aim.share()).then_some((aim, u_pick, u))
    }

    /// Draws whether this subpath is aimed; if so, its direction from `from`.
    pub(super) fn aimed(&self, from: Vec3, rng: &mut Rng) -> Option<Option<Vec3>> {
        self.aimed_lobe(rng).map(|(aim, u_pick, u)| aim.sample(from, u_pick, u))
    }

    /// How sphere lamp `number` aims its share of light (`None`: it is not one, or nothing is
    /// aimed at).
    pub(super) fn lamp(&self, number: usize) -> Option<&LampAim> {
        self.lamps.get(number)?.as_ref()
    }

    /// Density (area × solid angle) of leaving emissive object `light` (number `number`) at
    /// `point`, of unit normal `normal`, in `dir`, whose direction density without aiming is
    /// `plain`.
    pub(super) fn start_pdf(
        &self,
        (number, light): (usize, &AreaLight),
        point: Vec3,
        normal: Vec3,
        dir: Vec3,
        plain: f32,
    ) -> f32 {
        let area = light.pdf_area(normal);
        match (&self.near, self.lamp(number)) {
            (None, _) => area * plain,
            (Some(aim), Some(lamp)) => (1.0 - aim.share()) * area * plain + aim.share() * lamp.pdf(point, dir),
            (Some(_), None) => area * self.direction_pdf(point, dir, plain),
        }
    }

    /// Area density of the start point `sample` on emissive object `light` (number `number`;
    /// before the choice of light): a sphere lamp's aimed starts lie on the halves facing their
    /// targets.
    pub(super) fn point_pdf(&self, (number, light): (usize, &AreaLight), sample: &AreaSample) -> f32 {
        let area = light.pdf_area(sample.normal);
        match (&self.near, self.lamp(number)) {
            (Some(aim), Some(lamp)) => (1.0 - aim.share()) * area + aim.share() * lamp.point_pdf(sample.point),
            _ => area,
        }
    }

    /// Whether light `number` starts light subpaths.
    pub fn emits(&self, number: usize) -> bool {
        self.probability.get(number).is_some_and(|&p| p > 0.0)
    }

    /// Whether no light starts light subpaths.
    pub fn is_empty(&self) -> bool {
        self.choice.is_none()
    }

    /// The start of a light subpath from a light chosen by power, at the wavelengths `wl`.
    pub fn emit(&self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng) -> Option<Emission> {
        let (choice, u) = (self.choice.as_ref()?, rng.uniform());
        // One light needs no search (a tenth of a sphere lamp's emission).
        let slot = match self.numbers.len() {
            1 => 0,
            _ => choice.sample(u).1,
        };
        let number = self.numbers[slot];
        self.emit_light(scene, number, self.probability[number], wl, rng)
    }

    /// The start of a light subpath from light `number` itself (its densities without the
    /// choice of light): the course model shares its photons between the lights itself.
    pub fn emit_from(&self, scene: &Scene, number: usize, wl: &Wavelengths, rng: &mut Rng) -> Option<Emission> {
        if !self.emits(number) {
            return None;
        }
        self.emit_light(scene, number, 1.0, wl, rng)
    }

    /// The start of a light subpath from light `number`, taken with probability `pick`.
    fn emit_light(&self, scene: &Scene, number: usize, pick: f32, wl: &Wavelengths, rng: &mut Rng) -> Option<Emission> {
        let (u, u_dir) = (rng.uniform2(), rng.uniform2());
        let light = scene.lights().get(number)?;
        let args = EmitArgs {
            scene,
            number,
            pick,
            u,
            u_dir,
            wl,
        };
        match light {
            Light::Point { .. } | Light::Spot { .. } => self.emit_point(light, args, rng),
            Light::Area(_) => self.emit_area(light, args, rng),
            Light::Directional { .. } | Light::Sun { .. } => self.emit_distant(light, args, rng),
            Light::Environment(_) => self.emit_sky(light, args, rng),
            Light::Soft(_) => self.emit_soft(light, args, rng),
        }
    }

    /// Area density with which next-event estimation from `from` draws the start of `e`.
    pub fn direct_pdf(&self, scene: &Scene, e: &Emission, from: Vec3) -> f32 {
        let lights = scene.lights();
        let choice = lights.direct_probability(e.light);
        match lights.get(e.light) {
            Some(Light::Area(light)) => {
                let to = from - e.ray.origin;
                let d2 = to.length_squared();
                let cos = e.normal.dot(to).abs() / d2.sqrt();
                choice * light.pdf_towards(from, e.ray.origin, e.normal) * cos / d2
            }
            Some(Light::Soft(light)) => choice * light.pdf_area_towards(from, e.ray.origin, e.normal),
            // A sun's and the sky's are per solid angle (no distance to a far light).
            Some(Light::Sun { .. }) => choice * self.beams[e.light].as_ref().map_or(0.0, Beam::direction_pdf),
            Some(Light::Environment(env)) => choice * env.pdf(-e.ray.dir),
            _ => choice,
        }
    }

    /// What a camera path leaving `from` in direction `dir` (unit) sees of far light `number`
    /// (a sun or the sky): its radiance, next-event estimation's solid-angle density of that
    /// direction, and emission's density of the subpath that would have come along it (`None`:
    /// the light is neither or starts no subpaths, or `dir` misses the sun).
    pub fn far_seen(&self, scene: &Scene, number: usize, from: Vec3, dir: Vec3) -> Option<(Vec3, f32, f32)> {
        if !self.emits(number) {
            return None;
        }
        let choice = scene.lights().direct_probability(number);
        let emit = self.probability[number];
        match scene.lights().get(number)? {
            light @ Light::Sun { .. } => {
                let beam = self.beams.get(number)?.as_ref()?;
                if !beam.holds(-dir) {
                    return None;
                }
                let direct = choice * beam.direction_pdf();
                let emission = emit * beam.direction_pdf() * beam.across_pdf(from, -dir);
                Some((light.sun_radiance(), direct, emission))
            }
            Light::Environment(env) => {
                let pdf = env.pdf(dir);
                let emission = emit * pdf * self.sky_beam(-dir).across_pdf(from, -dir);
                Some((env.radiance(dir), choice * pdf, emission))
            }
            _ => None,
        }
    }

    /// The sky's beam travelling in `dir`.
    pub(super) fn sky_beam(&self, dir: Vec3) -> Beam {
        let (targets, share) = self.far.as_ref().map_or((&[][..], 0.0), |a| (a.targets(), a.share()));
        Beam::new(dir, None, self.sphere, targets, share)
    }

    /// Emission's density (point × direction, choice included) of leaving emissive object
    /// `light` (number `number`) at `point`, of unit normal `normal`, in direction `dir`.
    pub fn emission_pdf(&self, number: usize, light: &AreaLight, point: Vec3, normal: Vec3, dir: Vec3) -> f32 {
        if !light.faces.emit_towards(normal, dir) {
            return 0.0;
        }
        let plain = normal.dot(dir).abs() / (PI * light.faces.count());
        self.probability[number] * self.start_pdf((number, light), point, normal, dir, plain)
    }

    /// Emission's density (point × direction, choice included) of the start that next-event
    /// estimation's sample `s` of light `number`, taken from `from`, joins: the light subpath
    /// that would have left the light's point towards `from`.
    pub fn emission_pdf_of(&self, scene: &Scene, number: usize, s: &DirectSample, from: Vec3) -> f32 {
        let emit = self.probability.get(number).copied().unwrap_or(0.0);
        if emit <= 0.0 {
            return 0.0;
        }
        let out = -s.wi;
        match scene.lights().get(number) {
            Some(light @ (Light::Point { .. } | Light::Spot { .. })) => {
                emit * self.direction_pdf(s.point, out, super::point::plain_pdf(light, out))
            }
            Some(Light::Area(light)) => self.emission_pdf(number, light, s.point, s.normal, out),
            Some(Light::Directional { .. } | Light::Sun { .. }) => self.beams[number]
                .as_ref()
                .map_or(0.0, |beam| emit * beam.direction_pdf() * beam.across_pdf(from, out)),
            Some(Light::Environment(env)) => emit * env.pdf(s.wi) * self.sky_beam(out).across_pdf(from, out),
            Some(Light::Soft(light)) => emit * self.direction_pdf(s.point, out, s.cos_light / PI) / light.area(),
            None => 0.0,
        }
    }
}

/// The sign of the normal a cosine-weighted emission leaves along, and the direction's own
/// random pair: the one emitting face, or either face with the first number split between them.
pub(crate) fn emitting_side(light: &AreaLight, u: Vec2) -> (f32, Vec2) {
    match light.faces.sign() {
        Some(side) => (side, u),
        None if u.x < 0.5 => (1.0, Vec2::new(u.x * 2.0, u.y)),
        None => (-1.0, Vec2::new(u.x * 2.0 - 1.0, u.y)),
    }
}

/// The radiance an emissive object sends from its sampled point `sample`, at the wavelengths
/// `wl`.
pub(crate) fn area_radiance(light: &AreaLight, scene: &Scene, sample: &AreaSample, wl: &Wavelengths) -> Spectrum {
    match (light.uniform, wl.is_spectral()) {
        (true, false) => light.radiance.extend(0.0),
        (true, true) => scene
            .material_spectra(scene.object_material(light.object))
            .emission(light.radiance, wl),
        (false, _) => wl.unbounded(emission_at(scene, sample)),
    }
}

/// The emitted radiance at a sampled light point, read from its material by a short ray.
fn emission_at(scene: &Scene, sample: &AreaSample) -> Vec3 {
    let eps = 1e-3 * (1.0 + sample.point.abs().max_element());
    let ray = Ray::new(sample.point + sample.normal * eps, -sample.normal);
    match scene.intersect(&ray, 2.0 * eps) {
        Some(isect) => scene.emission(&scene.surface(&ray, &isect)),
        None => Vec3::ZERO,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::light::aim::Target;
    use crate::math::Aabb;
    use crate::scene::build::test_scene as scene;

    /// Uniform, aimed only, and aimed with 0.7 of the light: each must carry the same expected
    /// flux.
    fn aims(targets: &[Target]) -> [Option<Aim>; 3] {
        [None, Aim::every(targets, 1.0), Aim::every(targets, 0.7)]
    }

    /// `light` alone in an empty scene, with its emitters aimed as `aim` says (near and far
    /// alike), across the sphere around `bounds`.
    fn emitters_of(light: &Light, aim: Option<Aim>, bounds: Aabb) -> (Scene, Emitters) {
        let mut s = scene("");
        s.set_lights(vec![light.clone()]);
        let sphere = Target::around(&bounds);
        let e = Emitters::new(s.lights().as_slice(), (sphere.center, sphere.radius), aim.clone(), aim);
        (s, e)
    }

    fn bounds() -> Aabb {
        Aabb::new(Vec3::splat(-10.0), Vec3::splat(10.0))
    }

    /// The expected power per photon times the fraction of photons reaching a set must equal the
    /// light's power into that set, whatever the aiming.
    #[test]
    fn aimed_point_emission_preserves_power_into_a_target() {
        let light = Light::Point {
            position: Vec3::new(0.0, 0.0, 5.0),
            color: Vec3::ONE,
            attenuation: [0.0, 0.0, 1.0],
        };
        let targets = [
            Target {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            Target {
                center: Vec3::new(0.5, 0.0, 0.0),
                radius: 1.0,
            },
            Target {
                center: Vec3::new(3.0, 0.0, 0.0),
                radius: 0.5,
            },
        ];
        let target = &targets[0];
        let cos_max = (1.0f32 - 1.0 / 25.0).sqrt();
        let exact = 2.0 * PI * (1.0 - cos_max); // intensity 1 × solid angle of the first sphere
        for aim in aims(&targets) {
            let (s, e) = emitters_of(&light, aim.clone(), bounds());
            let mut rng = Rng::new(1, 0);
            let n = 200_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let Some(photon) = e.emit_from(&s, 0, &Wavelengths::Rgb, &mut rng) else {
                    continue;
                };
                let (ray, power) = (photon.ray, photon.throughput);
                let to = target.center - ray.origin;
                if ray.dir.dot(to.normalize()) >= cos_max {
                    sum += power.x as f64;
                }
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.02,
                "aim {aim:?}: {estimate} vs {exact}"
            );
        }
    }

    #[test]
    fn aimed_directional_emission_preserves_flux_through_a_target() {
        let light = Light::Directional {
            direction: Vec3::new(0.0, 0.0, -1.0),
            color: Vec3::splat(2.0),
        };
        let targets = [
            Target {
                center: Vec3::ZERO,
                radius: 1.0,
            },
            Target {
                center: Vec3::new(0.8, 0.0, 0.0),
                radius: 1.0,
            },
        ];
        let exact = 2.0 * PI; // irradiance 2 through the unit disc across the beam
        for aim in aims(&targets) {
            let small = Aabb::new(Vec3::splat(-3.0), Vec3::splat(3.0));
            let (s, e) = emitters_of(&light, aim.clone(), small);
            let mut rng = Rng::new(2, 0);
            let n = 2_000_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                let Some(photon) = e.emit_from(&s, 0, &Wavelengths::Rgb, &mut rng) else {
                    continue;
                };
                let (ray, power) = (photon.ray, photon.throughput);
                let p = ray.origin;
                if p.x * p.x + p.y * p.y <= 1.0 {
                    sum += power.x as f64;
                }
            }
            let estimate = sum / n as f64;
            assert!(
                (estimate / exact as f64 - 1.0).abs() < 0.02,
                "aim {aim:?}: {estimate} vs {exact}"
            );
        }
    }

    /// Photons carry the lamp's whole useful power: π·A·Le from each face that lights anything,
    /// the outer face only for a closed lamp that absorbs its own inward light.
    #[test]
    fn emitted_flux_is_the_lamps_power() {
        let lamp = "scale(0.5, sphere { material = { emissive = (2, 2, 2); } })";
        for (objects, faces, outward) in [
            (lamp.to_string(), 1.0, true),
            (
                format!("{lamp} scale(0.1, sphere {{ material = {{ diffuse = (1,1,1); }} }})"),
                2.0,
                false,
            ),
            (
                "scale(0.5, sphere { material = { emissive = (2, 2, 2); diffuse = (0.5, 0.5, 0.5); } })".to_string(),
                2.0,
                false,
            ),
        ] {
            let s = scene(&objects);
            let lights = s.lights();
            let faces_emitting = if outward {
                crate::description::EmittingFaces::Front
            } else {
                crate::description::EmittingFaces::Both
            };
            assert_eq!(lights.area_lights().next().unwrap().faces, faces_emitting, "{objects}");
            let mut rng = Rng::new(3, 0);
            let n = 100_000;
            let mut sum = 0.0f64;
            for _ in 0..n {
                if let Some(p) = lights.emit(&s, &Wavelengths::Rgb, &mut rng) {
                    sum += p.throughput.x as f64;
                    let outside = (p.ray.origin - Vec3::ZERO).dot(p.ray.dir) > 0.0;
                    assert!(outside || !outward, "an outward-only lamp emitted inwards");
                }
            }
            let exact = faces * std::f64::consts::PI * (4.0 * std::f64::consts::PI * 0.25) * 2.0;
            assert!(
                (sum / n as f64 / exact - 1.0).abs() < 0.01,
                "{objects}: {} vs {exact}",
                sum / n as f64
            );
        }
    }

    /// The flux that far lights send through a sphere in the scene: E·πr² for a directional
    /// light or a sun, πr²·∫L dω for the sky — whether the photons are aimed at the sphere or
    /// spread over the scene.
    #[test]
    fn far_lights_send_their_flux_through_a_sphere_aimed_or_not() {
        use crate::light::Environment;
        use crate::texture::Texture;
        let sky_map = Texture::new(
            16,
            8,
            (0..128)
                .map(|i| if i == 20 { Vec3::splat(50.0) } else { Vec3::splat(0.3) })
                .collect(),
        )
        .unwrap();
        let sky = Environment::new(Vec3::new(1.0, 0.8, 0.6), Some(sky_map), crate::math::Mat3::IDENTITY);
        let sky_flux_density = sky.luminance_integral();
        let target = Target {
            center: Vec3::new(0.7, -0.2, 0.4),
            radius: 0.6,
        };
        // The box whose sphere has radius 3.
        let scene_box = Aabb::new(Vec3::splat(-1.732), Vec3::splat(1.732));
        let lights = [
            (
                Light::Directional {
                    direction: Vec3::new(0.2, -1.0, 0.1).normalize(),
                    color: Vec3::splat(2.0),
                },
                2.0 * PI * 0.36,
            ),
            (
                Light::sun(Vec3::new(-0.3, -1.0, 0.2).normalize(), Vec3::splat(2.0), 5.0),
                2.0 * PI * 0.36 * 2.0 / (1.0 + 2.5f32.to_radians().cos()),
            ),
            (Light::Environment(sky), PI * 0.36 * sky_flux_density),
        ];
        for (light, exact) in lights {
            let targets = [target];
            for aim in aims(&targets) {
                let (s, e) = emitters_of(&light, aim.clone(), scene_box);
                let mut rng = Rng::new(4, 0);
                let n = 400_000;
                let mut sum = 0.0f64;
                for _ in 0..n {
                    let Some(p) = e.emit_from(&s, 0, &Wavelengths::Rgb, &mut rng) else {
                        continue;
                    };
                    // Does the ray pass through the sphere?
                    let oc = target.center - p.ray.origin;
                    let t = oc.dot(p.ray.dir);
                    if t > 0.0 && (oc - p.ray.dir * t).length_squared() <= target.radius * target.radius {
                        sum += crate::math::luminance(p.throughput.truncate()) as f64;
                    }
                }
                let estimate = sum / n as f64;
                assert!(
                    (estimate / exact as f64 - 1.0).abs() < 0.02,
                    "{light:?} aim {aim:?}: {estimate} vs {exact}"
                );
            }
        }
    }
}
