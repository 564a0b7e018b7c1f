//! The lights vertex connection and merging starts its light subpaths from, with the densities
//! its weights need: how likely emission made a point and direction, and how likely
//! next-event estimation would have drawn the same point.
//!
//! Every light takes part in every strategy it can. A directional light, a sun or the sky
//! starts its subpaths on a plane across its beam outside the scene ([`Beam`]; the sky's beam
//! is the direction its own sampling draws), so their densities are per unit area across the
//! beam, with no distance to the first vertex. The course forks' lights with a size start
//! theirs from a point on them; no ray meets them, so camera paths reach them by next-event
//! estimation alone.
//!
//! Aiming: a share of the light subpaths leaves towards the bounding spheres of the mirrors and
//! glass (the caustics' sources), the rest everywhere the light shines ([`Aim`]); a sphere lamp
//! aims from the half of it that faces the chosen target. Every density
//! below is the mixture's, for the subpath's throughput and for every strategy's weight alike,
//! so aiming changes where the samples go (many more caustic paths), never the expected image.

use crate::light::emission::{area_radiance, emitting_side, Target};
use crate::light::{spot_profile, AreaLight, Light, LightSet};
use crate::math::{offset_origin, Frame, Ray, Vec3};
use crate::sampling::{
    sample_cosine_hemisphere, sample_uniform_cone, sample_uniform_disc, sample_uniform_sphere, uniform_cone_pdf,
    uniform_sphere_pdf, Distribution1D, Rng,
};
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use glam::Vec2;
use std::f32::consts::PI;

/// The lights that start light subpaths, chosen in proportion to their power.
pub struct Emitters {
    /// Probability of choosing each light of the scene's set (0: not an emitter here).
    probability: Vec<f32>,
    /// Light numbers of the emitters, and their choice distribution.
    numbers: Vec<usize>,
    choice: Option<Distribution1D>,
    aim: Option<Aim>,
    /// Each light's beam, for the directional lights and suns.
    beams: Vec<Option<Beam>>,
    /// The scene's sphere, for the sky's beams (one per direction).
    sphere: (Vec3, f32),
}

/// The share of a directional light's or sun's subpaths aimed at the mirrors and glass: their
/// beam covers the whole scene, where a glass may take a hundredth of it.
pub const FAR_AIM_SHARE: f32 = 0.5;

/// Where a directional light's or sun's subpaths start: a plane across the beam outside the
/// scene, a point on it from a mixture of discs (the scene's, and each target's as the beam
/// sees it, by area), then a direction along the beam (a sun's: uniform in its cone).
#[derive(Clone, Debug)]
pub struct Beam {
    /// Unit travel direction of the beam's centre.
    direction: Vec3,
    frame: Frame,
    plane_origin: Vec3,
    /// The scene's disc, centred on the plane's origin.
    scene_radius: f32,
    /// The targets' discs on the plane, the first `target_count` of them (held inline: the
    /// sky builds a beam for every direction it samples or is seen in).
    targets: [(Vec2, f32); MAX_TARGETS],
    target_count: usize,
    /// π Σ r² over the targets.
    target_area: f32,
    /// The share of starts on the targets' discs (0 without targets).
    share: f32,
    /// A sun's cone: cos θ and 1 − cos θ of its angular radius.
    sun: Option<(f32, f32)>,
}

impl Beam {
    /// The beam of a light travelling in `direction` (a sun's centre; `sun`: its cone) across
    /// the scene's sphere (`center`, `radius`), `share` of it aimed at `targets` (more than
    /// [`MAX_TARGETS`]: at one sphere around them, as [`Aim`] does).
    pub fn new(
        direction: Vec3,
        sun: Option<(f32, f32)>,
        (center, radius): (Vec3, f32),
        targets: &[Target],
        share: f32,
    ) -> Beam {
        let frame = Frame::from_normal(direction);
        let plane_origin = center - direction * (radius * 2.0 + 1.0);
        // A sun's subpaths lean by up to its angular radius: each disc widens so that every
        // leaning ray that can reach its sphere starts inside it.
        let lean = sun.map_or(0.0, |(cos_max, _)| (1.0 - cos_max * cos_max).max(0.0).sqrt() / cos_max);
        let disc = |t: &Target| {
            let local = frame.to_local(t.center - plane_origin);
            (
                Vec2::new(local.x, local.y),
                t.radius + (local.z.max(0.0) + t.radius) * lean,
            )
        };
        let scene_radius = disc(&Target { center, radius }).1;
        let all;
        let targets = if targets.len() <= MAX_TARGETS {
            targets
        } else {
            all = [around(targets)];
            &all[..]
        };
        let mut discs = [(Vec2::ZERO, 0.0); MAX_TARGETS];
        for (d, t) in discs.iter_mut().zip(targets) {
            *d = disc(t);
        }
        let target_count = targets.len();
        let target_area: f32 = discs[..target_count].iter().map(|(_, r)| PI * r * r).sum();
        let share = if target_area > 0.0 { share.clamp(0.0, 1.0) } else { 0.0 };
        Beam {
            direction,
            frame,
            plane_origin,
            scene_radius,
            targets: discs,
            target_count,
            target_area,
            share,
            sun,
        }
    }

    /// A start on the plane: the point and its area density there.
    fn sample(&self, u_lobe: f32, u_pick: f32, u: Vec2) -> Option<(Vec3, f32)> {
        let (center, radius) = if u_lobe < self.share {
            let mut x = u_pick * self.target_area;
            let mut chosen = *self.discs().last()?;
            for &(c, r) in self.discs() {
                let a = PI * r * r;
                if x < a {
                    chosen = (c, r);
                    break;
                }
                x -= a;
            }
            chosen
        } else {
            (Vec2::ZERO, self.scene_radius)
        };
        let p = center + sample_uniform_disc(u) * radius;
        let pdf = self.plane_pdf(p);
        (pdf > 0.0).then(|| (self.plane_origin + self.frame.x * p.x + self.frame.y * p.y, pdf))
    }

    /// The targets' discs on the plane.
    fn discs(&self) -> &[(Vec2, f32)] {
        &self.targets[..self.target_count]
    }

    /// Area density of a start at `p` on the plane (the mixture's).
    fn plane_pdf(&self, p: Vec2) -> f32 {
        let inside = |c: Vec2, r: f32| (p - c).length_squared() <= r * r * (1.0 + 1e-5);
        let mut pdf = 0.0;
        if inside(Vec2::ZERO, self.scene_radius) {
            pdf += (1.0 - self.share) / (PI * self.scene_radius * self.scene_radius);
        }
        if self.share > 0.0 {
            let count = self.discs().iter().filter(|&&(c, r)| inside(c, r)).count();
            pdf += self.share * count as f32 / self.target_area;
        }
        pdf
    }

    /// Density, per unit area across the ray, of a start whose ray travels in `dir` through
    /// `point`: the plane's density where that ray leaves it, over the cosine of its lean.
    fn across_pdf(&self, point: Vec3, dir: Vec3) -> f32 {
        let lean = dir.dot(self.direction);
        if lean.is_nan() || lean <= 0.0 {
            return 0.0;
        }
        let back = (point - self.plane_origin).dot(self.direction) / lean;
        let local = self.frame.to_local(point - dir * back - self.plane_origin);
        self.plane_pdf(Vec2::new(local.x, local.y)) / lean
    }

    /// Solid-angle density of a direction within a sun's cone (1 for a directional light,
    /// whose one direction is a delta).
    fn direction_pdf(&self) -> f32 {
        self.sun
            .map_or(1.0, |(_, one_minus_cos)| 1.0 / (2.0 * PI * one_minus_cos))
    }

    /// Whether `dir` (travelling) lies in the beam: a sun's cone (a directional light's never).
    fn holds(&self, dir: Vec3) -> bool {
        self.sun.is_some_and(|(cos_max, _)| dir.dot(self.direction) >= cos_max)
    }
}

/// Where a share of the light subpaths is aimed: cones from the light point towards the
/// targets, each chosen in proportion to its solid angle.
#[derive(Clone, Debug)]
pub struct Aim {
    targets: Vec<Target>,
    /// The share of subpaths aimed (the rest leave as without aiming).
    share: f32,
}

/// More targets than this are aimed at as one sphere around them all: every density
/// evaluation visits each target.
const MAX_TARGETS: usize = 8;

/// A sphere around all of `targets` (not empty).
fn around(targets: &[Target]) -> Target {
    let center = targets.iter().map(|t| t.center).sum::<Vec3>() / targets.len() as f32;
    let radius = targets
        .iter()
        .map(|t| (t.center - center).length() + t.radius)
        .fold(0.0, f32::max);
    Target { center, radius }
}

impl Aim {
    /// Aiming `share` of the subpaths at `targets` (`None` when there is nothing to aim at).
    pub fn new(targets: &[Target], share: f32) -> Option<Aim> {
        if targets.is_empty() || !(share > 0.0 && share <= 1.0) {
            return None;
        }
        let targets = if targets.len() <= MAX_TARGETS {
            targets.to_vec()
        } else {
            vec![around(targets)]
        };
        Some(Aim { targets, share })
    }

    /// The share of samples aimed.
    pub fn share(&self) -> f32 {
        self.share
    }

    /// A target, chosen in proportion to the solid angle it subtends from `from` (`None`: none
    /// subtends any).
    fn pick(&self, from: Vec3, u_pick: f32) -> Option<&Target> {
        let total: f32 = self.targets.iter().map(|t| 1.0 - t.cone_from(from).1).sum();
        if total.is_nan() || total <= 0.0 {
            return None;
        }
        let mut x = u_pick * total;
        for (i, t) in self.targets.iter().enumerate() {
            let w = 1.0 - t.cone_from(from).1;
            if x < w || i + 1 == self.targets.len() {
                return Some(t);
            }
            x -= w;
        }
        None
    }

    /// A direction from `from` into one of the cones (`None`: they have no solid angle).
    pub(super) fn sample(&self, from: Vec3, u_pick: f32, u: Vec2) -> Option<Vec3> {
        let (axis, cos_max) = self.pick(from, u_pick)?.cone_from(from);
        Some(sample_uniform_cone(u, axis, cos_max))
    }

    /// The solid-angle density of [`Aim::sample`] at `dir`: each cone holding `dir` adds
    /// its share 1/(2π Σ(1 − cos)) (its weight over its own solid angle).
    pub(super) fn pdf(&self, from: Vec3, dir: Vec3) -> f32 {
        let (mut total, mut inside) = (0.0, 0u32);
        for t in &self.targets {
            let (axis, cos_max) = t.cone_from(from);
            total += 1.0 - cos_max;
            if dir.dot(axis) >= cos_max {
                inside += 1;
            }
        }
        if total > 0.0 {
            inside as f32 / (2.0 * PI * total)
        } else {
            0.0
        }
    }

    /// An aimed start on a sphere lamp (centre, radius) from a point drawn uniformly on it
    /// (`normal`, its unit normal): a target by its solid angle from the centre, the point
    /// mirrored onto the half of the lamp facing that target, then a direction in the
    /// target's cone from it. Drawn anywhere on the lamp, half the aimed starts would face
    /// away from their target. Returns the start's normal and direction.
    fn sample_from_sphere(
        &self,
        center: Vec3,
        radius: f32,
        normal: Vec3,
        u_pick: f32,
        u: Vec2,
    ) -> Option<(Vec3, Vec3)> {
        let target = self.pick(center, u_pick)?;
        let facing = target.cone_from(center).0;
        let along = normal.dot(facing);
        let normal = if along < 0.0 {
            normal - 2.0 * along * facing
        } else {
            normal
        };
        let (axis, cos_max) = target.cone_from(center + normal * radius);
        Some((normal, sample_uniform_cone(u, axis, cos_max)))
    }

    /// The density (area × solid angle) of [`Aim::sample_from_sphere`]'s start at the lamp's
    /// point `point`, leaving in `dir`.
    fn sphere_pdf(&self, center: Vec3, radius: f32, point: Vec3, dir: Vec3) -> f32 {
        let total: f32 = self.targets.iter().map(|t| 1.0 - t.cone_from(center).1).sum();
        if total.is_nan() || total <= 0.0 {
            return 0.0;
        }
        // From the point, not a caller's normal (which may face either way).
        let normal = point - center;
        let half_area = 2.0 * PI * radius * radius;
        let mut pdf = 0.0;
        for t in &self.targets {
            let (facing, cos_center) = t.cone_from(center);
            if normal.dot(facing) < 0.0 {
                continue;
            }
            let (axis, cos_max) = t.cone_from(point);
            if dir.dot(axis) >= cos_max {
                pdf += (1.0 - cos_center) / total * uniform_cone_pdf(cos_max) / half_area;
            }
        }
        pdf
    }
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
}

/// One next-event sample of an emitter.
#[derive(Clone, Copy, Debug)]
pub struct DirectSample {
    /// Unit direction to the light point.
    pub wi: Vec3,
    /// Distance to the light point.
    pub distance: f32,
    /// Radiance (intensity / d² for a point) over the solid-angle density.
    pub contribution: Spectrum,
    /// Solid-angle density of the sample, choice included (for a point: the choice × d²).
    pub direct_pdf: f32,
    /// Emission's density of the light point and of the direction towards the shading point.
    pub emission_pdf: f32,
    /// Cosine at the light (1 for a point).
    pub cos_light: f32,
    /// The light is a point or spot.
    pub delta: bool,
}

impl Emitters {
    /// The emitters of `scene`'s lights, aimed as `aim` says (directional lights, suns and
    /// the sky aim [`FAR_AIM_SHARE`] at the same targets).
    pub fn new(lights: &LightSet, aim: Option<Aim>) -> Emitters {
        let sphere = lights.scene_sphere();
        let powers: Vec<f32> = lights.iter().map(|light| light.power(sphere.1).max(0.0)).collect();
        let targets = aim.as_ref().map_or(&[][..], |a| &a.targets[..]);
        let beams = lights
            .iter()
            .map(|light| match *light {
                Light::Directional { direction, .. } => {
                    Some(Beam::new(direction, None, sphere, targets, FAR_AIM_SHARE))
                }
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
                    FAR_AIM_SHARE,
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
        Emitters {
            probability,
            numbers,
            choice,
            aim,
            beams,
            sphere,
        }
    }

    /// Solid-angle density of a direction `dir` leaving `from`, whose density without aiming
    /// is `plain`: the mixture of that and the aimed cones.
    fn direction_pdf(&self, from: Vec3, dir: Vec3, plain: f32) -> f32 {
        match &self.aim {
            None => plain,
            Some(aim) => (1.0 - aim.share) * plain + aim.share * aim.pdf(from, dir),
        }
    }

    /// Draws whether this subpath is aimed; if so, the aim and the random numbers its sample
    /// uses.
    fn aimed_lobe(&self, rng: &mut Rng) -> Option<(&Aim, f32, Vec2)> {
        let aim = self.aim.as_ref()?;
        let (u_lobe, u_pick, u) = (rng.uniform(), rng.uniform(), rng.uniform2());
        (u_lobe < aim.share).then_some((aim, u_pick, u))
    }

    /// Draws whether this subpath is aimed; if so, its direction from `from`.
    fn aimed(&self, from: Vec3, rng: &mut Rng) -> Option<Option<Vec3>> {
        self.aimed_lobe(rng).map(|(aim, u_pick, u)| aim.sample(from, u_pick, u))
    }

    /// Density (area × solid angle) of leaving emissive object `light` at `point`, of unit
    /// normal `normal`, in `dir`, whose direction density without aiming is `plain`.
    fn start_pdf(&self, light: &AreaLight, point: Vec3, normal: Vec3, dir: Vec3, plain: f32) -> f32 {
        let area = light.pdf_area(normal);
        match (&self.aim, light.sphere()) {
            (None, _) => area * plain,
            (Some(aim), Some((center, radius))) => {
                (1.0 - aim.share) * area * plain + aim.share * aim.sphere_pdf(center, radius, point, dir)
            }
            (Some(_), None) => area * self.direction_pdf(point, dir, plain),
        }
    }

    /// Solid-angle density, without aiming, of a point or spot light's direction `dir`.
    fn point_plain_pdf(light: &Light, dir: Vec3) -> f32 {
        match light {
            Light::Spot {
                direction, cos_outer, ..
            } if dir.dot(*direction) < *cos_outer => 0.0,
            Light::Spot { cos_outer, .. } => uniform_cone_pdf(*cos_outer),
            _ => uniform_sphere_pdf(),
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

    /// The start of a light subpath, at the wavelengths `wl`.
    pub fn emit(&self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng) -> Option<Emission> {
        let (_, slot, _) = self.choice.as_ref()?.sample(rng.uniform());
        let number = self.numbers[slot];
        let pick = self.probability[number];
        let (u, u_dir) = (rng.uniform2(), rng.uniform2());
        match scene.lights().get(number)? {
            light @ Light::Point { position, color, .. } => {
                let dir = match self.aimed(*position, rng) {
                    Some(aimed) => aimed?,
                    None => sample_uniform_sphere(u),
                };
                let pdf = pick * self.direction_pdf(*position, dir, Self::point_plain_pdf(light, dir));
                (pdf > 0.0).then(|| Emission {
                    ray: Ray::new(*position, dir),
                    throughput: wl.unbounded(*color) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: true,
                    light: number,
                    normal: dir,
                    far: false,
                })
            }
            light @ Light::Spot {
                position,
                direction,
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => {
                let dir = match self.aimed(*position, rng) {
                    Some(aimed) => aimed?,
                    None => sample_uniform_cone(u, *direction, *cos_outer),
                };
                let profile = spot_profile(dir.dot(*direction), *cos_inner, *cos_outer, *exponent);
                let pdf = pick * self.direction_pdf(*position, dir, Self::point_plain_pdf(light, dir));
                (profile > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(*position, dir),
                    throughput: wl.unbounded(*color) * (profile / pdf),
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: true,
                    light: number,
                    normal: dir,
                    far: false,
                })
            }
            Light::Area(light) => {
                let mut sample = light.sample(scene, rng.uniform(), u)?;
                let (dir, normal) = match self.aimed_lobe(rng) {
                    Some((aim, u_pick, u_aim)) => {
                        let dir = match light.sphere() {
                            Some((center, radius)) => {
                                let (normal, dir) =
                                    aim.sample_from_sphere(center, radius, sample.normal, u_pick, u_aim)?;
                                sample.normal = normal;
                                sample.point = center + normal * radius;
                                dir
                            }
                            None => aim.sample(sample.point, u_pick, u_aim)?,
                        };
                        // Leaves by the face it points out of, if that face emits.
                        let side = if dir.dot(sample.normal) >= 0.0 { 1.0 } else { -1.0 };
                        if light.faces.sign().is_some_and(|s| s != side) {
                            return None;
                        }
                        (dir, sample.normal * side)
                    }
                    None => {
                        // A face at random, or the one that emits, then a cosine-weighted
                        // direction.
                        let (side, u2) = emitting_side(light, u_dir);
                        let normal = sample.normal * side;
                        (
                            Frame::from_normal(normal).to_world(sample_cosine_hemisphere(u2)),
                            normal,
                        )
                    }
                };
                let le = area_radiance(light, scene, &sample, wl);
                let cos = dir.dot(normal);
                let plain = cos / (PI * light.faces.count());
                let pdf = pick * self.start_pdf(light, sample.point, sample.normal, dir, plain);
                (cos > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(offset_origin(sample.point, sample.normal, dir), dir),
                    throughput: le * (cos / pdf),
                    emission_pdf: pdf,
                    cos,
                    delta: false,
                    light: number,
                    normal,
                    far: false,
                })
            }
            light @ (Light::Directional { .. } | Light::Sun { .. }) => {
                let beam = self.beams[number].as_ref()?;
                let (origin, plane_pdf) = beam.sample(rng.uniform(), rng.uniform(), u)?;
                let (dir, radiance) = match beam.sun {
                    Some((cos_max, _)) => (
                        sample_uniform_cone(u_dir, beam.direction, cos_max),
                        light.sun_radiance(),
                    ),
                    None => (beam.direction, light.color()),
                };
                let lean = dir.dot(beam.direction);
                let pdf = pick * beam.direction_pdf() * plane_pdf / lean;
                (lean > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(origin, dir),
                    throughput: wl.unbounded(radiance) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: beam.sun.is_none(),
                    light: number,
                    normal: dir,
                    far: true,
                })
            }
            Light::Environment(env) => {
                // A direction by the sky's own sampling, then a start across that beam.
                let sky = env.sample(u_dir)?;
                let dir = -sky.wi;
                let (origin, plane_pdf) = self.sky_beam(dir).sample(rng.uniform(), rng.uniform(), u)?;
                let pdf = pick * sky.pdf * plane_pdf;
                (pdf > 0.0).then(|| Emission {
                    ray: Ray::new(origin, dir),
                    throughput: wl.unbounded(sky.radiance) / pdf,
                    emission_pdf: pdf,
                    cos: 1.0,
                    delta: false,
                    light: number,
                    normal: dir,
                    far: true,
                })
            }
            Light::Soft(light) => {
                // A point uniform by area, then a cosine-weighted direction (or an aimed one).
                let s = light.sample_point(u);
                let dir = match self.aimed(s.point, rng) {
                    Some(aimed) => aimed?,
                    None => Frame::from_normal(s.normal).to_world(sample_cosine_hemisphere(u_dir)),
                };
                let cos = dir.dot(s.normal);
                let pdf = pick * self.direction_pdf(s.point, dir, cos.max(0.0) / PI) / light.area();
                (cos > 0.0 && pdf > 0.0).then(|| Emission {
                    ray: Ray::new(s.point, dir),
                    throughput: wl.unbounded(s.radiance) * (cos / pdf),
                    emission_pdf: pdf,
                    cos,
                    // No ray meets it: camera paths never reach it but by next-event estimation.
                    delta: true,
                    light: number,
                    normal: s.normal,
                    far: false,
                })
            }
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
    fn sky_beam(&self, dir: Vec3) -> Beam {
        let targets = self.aim.as_ref().map_or(&[][..], |a| &a.targets[..]);
        Beam::new(dir, None, self.sphere, targets, FAR_AIM_SHARE)
    }

    /// Emission's density (point × direction, choice included) of leaving emissive object
    /// `light` (number `number`) at `point`, of unit normal `normal`, in direction `dir`.
    pub fn emission_pdf(&self, number: usize, light: &AreaLight, point: Vec3, normal: Vec3, dir: Vec3) -> f32 {
        if !light.faces.emit_towards(normal, dir) {
            return 0.0;
        }
        let plain = normal.dot(dir).abs() / (PI * light.faces.count());
        self.probability[number] * self.start_pdf(light, point, normal, dir, plain)
    }

    /// A next-event sample of emitter `number` for the point `hit`, visibility included.
    pub fn sample_direct(
        &self,
        scene: &Scene,
        number: usize,
        hit: &SurfaceHit,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Option<DirectSample> {
        let lights = scene.lights();
        let choice = lights.direct_probability(number);
        let emit = self.probability[number];
        let (u_pick, u) = (rng.uniform(), rng.uniform2());
        let p = hit.point;
        let point_light = |light: &Light, position: Vec3, intensity: Vec3| {
            let to = position - p;
            let d2 = to.length_squared();
            if !(d2 > 0.0 && d2.is_finite()) || intensity == Vec3::ZERO {
                return None;
            }
            let distance = d2.sqrt();
            let wi = to / distance;
            let dir_pdf = self.direction_pdf(position, -wi, Self::point_plain_pdf(light, -wi));
            scene.unoccluded(hit, wi, distance).then(|| DirectSample {
                wi,
                distance,
                contribution: wl.unbounded(intensity) / (choice * d2),
                direct_pdf: choice * d2,
                emission_pdf: emit * dir_pdf,
                cos_light: 1.0,
                delta: true,
            })
        };
        match lights.get(number)? {
            light @ Light::Point { position, color, .. } => point_light(light, *position, *color),
            light @ Light::Spot {
                position,
                direction,
                color,
                cos_inner,
                cos_outer,
                exponent,
                ..
            } => {
                let out = (p - *position).normalize_or_zero();
                let profile = spot_profile(out.dot(*direction), *cos_inner, *cos_outer, *exponent);
                if profile <= 0.0 {
                    return None;
                }
                point_light(light, *position, *color * profile)
            }
            Light::Area(light) => {
                let drawn = light.sample_towards(scene, p, u_pick, u)?;
                let point = drawn.point;
                let to = point.point - p;
                let distance = to.length();
                if distance.is_nan() || distance <= 0.0 || drawn.pdf_solid <= 0.0 {
                    return None;
                }
                let wi = to / distance;
                let le = crate::light::visible_emission(scene, light, hit, &drawn, wi, distance, wl)?;
                let direct_pdf = choice * drawn.pdf_solid;
                let cos_light = point.normal.dot(wi).abs();
                Some(DirectSample {
                    wi,
                    distance,
                    contribution: le / direct_pdf,
                    direct_pdf,
                    emission_pdf: self.emission_pdf(number, light, point.point, point.normal, -wi),
                    cos_light,
                    delta: false,
                })
            }
            light @ (Light::Directional { .. } | Light::Sun { .. }) => {
                let beam = self.beams[number].as_ref()?;
                let (wi, radiance) = match beam.sun {
                    Some((cos_max, _)) => (sample_uniform_cone(u, -beam.direction, cos_max), light.sun_radiance()),
                    None => (-beam.direction, light.color()),
                };
                if radiance == Vec3::ZERO || !scene.unoccluded(hit, wi, f32::INFINITY) {
                    return None;
                }
                let direct_pdf = choice * beam.direction_pdf();
                Some(DirectSample {
                    wi,
                    distance: f32::INFINITY,
                    contribution: wl.unbounded(radiance) / direct_pdf,
                    direct_pdf,
                    emission_pdf: emit * beam.direction_pdf() * beam.across_pdf(p, -wi),
                    cos_light: 1.0,
                    delta: beam.sun.is_none(),
                })
            }
            Light::Environment(env) => {
                let sky = env.sample(u)?;
                if sky.radiance == Vec3::ZERO || !scene.unoccluded(hit, sky.wi, f32::INFINITY) {
                    return None;
                }
                let direct_pdf = choice * sky.pdf;
                Some(DirectSample {
                    wi: sky.wi,
                    distance: f32::INFINITY,
                    contribution: wl.unbounded(sky.radiance) / direct_pdf,
                    direct_pdf,
                    emission_pdf: emit * sky.pdf * self.sky_beam(-sky.wi).across_pdf(p, -sky.wi),
                    cos_light: 1.0,
                    delta: false,
                })
            }
            Light::Soft(light) => {
                let (s, pdf_solid) = light.sample_towards(p, u)?;
                let to = s.point - p;
                let distance = to.length();
                if distance.is_nan() || distance <= 0.0 || pdf_solid <= 0.0 {
                    return None;
                }
                let wi = to / distance;
                let cos_light = -s.normal.dot(wi);
                if cos_light <= 0.0 || !scene.unoccluded(hit, wi, distance) {
                    return None;
                }
                let direct_pdf = choice * pdf_solid;
                let plain = cos_light / PI;
                Some(DirectSample {
                    wi,
                    distance,
                    contribution: wl.unbounded(s.radiance) / direct_pdf,
                    direct_pdf,
                    emission_pdf: emit * self.direction_pdf(s.point, -wi, plain) / light.area(),
                    cos_light,
                    delta: true,
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn target(x: f32, y: f32, z: f32, radius: f32) -> Target {
        Target {
            center: Vec3::new(x, y, z),
            radius,
        }
    }

    #[test]
    fn aimed_density_integrates_to_one_over_the_sphere() {
        // Two overlapping cones and one apart, seen from the origin.
        let aim = Aim::new(
            &[
                target(0.0, 0.0, -2.0, 0.5),
                target(0.3, 0.0, -2.0, 0.4),
                target(2.0, 1.0, 0.0, 0.3),
            ],
            1.0,
        )
        .unwrap();
        let mut rng = Rng::new(7, 0);
        let n = 400_000;
        let mean: f64 = (0..n)
            .map(|_| aim.pdf(Vec3::ZERO, sample_uniform_sphere(rng.uniform2())) as f64)
            .sum::<f64>()
            / n as f64;
        let integral = mean * 4.0 * std::f64::consts::PI;
        assert!((integral - 1.0).abs() < 0.01, "∫ pdf dω = {integral}");
    }

    #[test]
    fn aimed_samples_follow_their_density() {
        // Apart cones: E[1 / pdf] over the samples is the solid angle they cover, Σ 2π(1 − cos).
        let targets = [
            target(0.0, 0.0, -2.0, 0.5),
            target(2.0, 1.0, 0.0, 0.3),
            target(0.0, 3.0, 0.0, 0.2),
        ];
        let aim = Aim::new(&targets, 1.0).unwrap();
        let from = Vec3::new(0.1, -0.2, 0.3);
        let exact: f32 = targets.iter().map(|t| 2.0 * PI * (1.0 - t.cone_from(from).1)).sum();
        let mut rng = Rng::new(11, 0);
        let n = 200_000;
        let mut sum = 0.0f64;
        for _ in 0..n {
            let dir = aim.sample(from, rng.uniform(), rng.uniform2()).unwrap();
            let pdf = aim.pdf(from, dir);
            assert!(pdf > 0.0, "a sample outside every cone: {dir:?}");
            sum += 1.0 / pdf as f64;
        }
        let estimate = sum / n as f64;
        assert!((estimate / exact as f64 - 1.0).abs() < 0.01, "{estimate} vs {exact}");
    }

    /// A sphere lamp of radius 0.5 at the origin and two targets in different directions.
    fn lamp_aim() -> (Aim, f32) {
        let aim = Aim::new(&[target(0.0, -3.0, 0.0, 1.0), target(2.5, -2.0, 0.5, 0.8)], 1.0).unwrap();
        (aim, 0.5)
    }

    #[test]
    fn aimed_sphere_lamp_density_integrates_to_one() {
        // Over the lamp's area and every direction: E[pdf] over uniform points and directions
        // times 4πr² · 4π.
        let (aim, radius) = lamp_aim();
        let mut rng = Rng::new(5, 0);
        let n = 1_000_000;
        let mean: f64 = (0..n)
            .map(|_| {
                let point = sample_uniform_sphere(rng.uniform2()) * radius;
                aim.sphere_pdf(Vec3::ZERO, radius, point, sample_uniform_sphere(rng.uniform2())) as f64
            })
            .sum::<f64>()
            / n as f64;
        let measure = 4.0 * std::f64::consts::PI * (radius * radius) as f64 * 4.0 * std::f64::consts::PI;
        let integral = mean * measure;
        assert!((integral - 1.0).abs() < 0.02, "∫∫ pdf dA dω = {integral}");
    }

    #[test]
    fn aimed_sphere_lamp_starts_follow_their_density() {
        // E[q / pdf] over the aimed starts, q the uniform density over the lamp's points and
        // directions, is the share of all (point, direction) pairs the aiming can draw, which
        // uniform pairs estimate independently. Only starts near the rim of the half facing
        // the target can leave inwards (17% with these wide cones), against about half when
        // drawn anywhere on the lamp.
        let (aim, radius) = lamp_aim();
        let q = 1.0 / (4.0 * PI * radius * radius * 4.0 * PI);
        let mut rng = Rng::new(9, 0);
        let n = 400_000;
        let (mut sum, mut inwards) = (0.0f64, 0);
        for _ in 0..n {
            let uniform = sample_uniform_sphere(rng.uniform2());
            let (normal, dir) = aim
                .sample_from_sphere(Vec3::ZERO, radius, uniform, rng.uniform(), rng.uniform2())
                .unwrap();
            inwards += (dir.dot(normal) <= 0.0) as usize;
            let pdf = aim.sphere_pdf(Vec3::ZERO, radius, normal * radius, dir);
            assert!(pdf > 0.0, "a start the density says cannot be drawn");
            sum += (q / pdf) as f64;
        }
        let drawn_share = sum / n as f64;
        let m = 2_000_000;
        let reachable = (0..m)
            .filter(|_| {
                let point = sample_uniform_sphere(rng.uniform2()) * radius;
                aim.sphere_pdf(Vec3::ZERO, radius, point, sample_uniform_sphere(rng.uniform2())) > 0.0
            })
            .count() as f64
            / m as f64;
        assert!(
            (drawn_share / reachable - 1.0).abs() < 0.03,
            "{drawn_share} vs {reachable}"
        );
        let inwards = inwards as f64 / n as f64;
        assert!(inwards < 0.25, "{inwards} of the aimed starts leave inwards");
    }

    /// A sun's beam 3° across, a third aimed at two targets, over a scene of radius 4.
    fn sun_beam() -> Beam {
        let cos_max = (1.5f32).to_radians().cos();
        Beam::new(
            Vec3::new(-1.2, -1.5, 0.3).normalize(),
            Some((cos_max, 1.0 - cos_max)),
            (Vec3::ZERO, 4.0),
            &[target(0.0, 0.5, 0.0, 0.5), target(1.0, 0.3, 1.0, 0.3)],
            1.0 / 3.0,
        )
    }

    #[test]
    fn beam_density_integrates_to_one_over_its_plane() {
        let beam = sun_beam();
        // The scene's disc holds the targets' discs: uniform points over its bounding square.
        let half = beam.scene_radius;
        let mut rng = Rng::new(3, 0);
        let n = 1_000_000;
        let mean: f64 = (0..n)
            .map(|_| {
                let u = rng.uniform2();
                beam.plane_pdf(Vec2::new((2.0 * u.x - 1.0) * half, (2.0 * u.y - 1.0) * half)) as f64
            })
            .sum::<f64>()
            / n as f64;
        let integral = mean * (2.0 * half as f64).powi(2);
        assert!((integral - 1.0).abs() < 0.01, "∫ pdf dA = {integral}");
    }

    #[test]
    fn beam_starts_carry_their_density_along_the_ray() {
        // The density across the ray, read anywhere along it, is the start's on the plane
        // over the cosine of its lean; the aimed share lands on the targets' discs.
        let beam = sun_beam();
        let mut rng = Rng::new(4, 0);
        let mut on_targets = 0;
        let n = 20_000;
        for _ in 0..n {
            let (origin, pdf) = beam.sample(rng.uniform(), rng.uniform(), rng.uniform2()).unwrap();
            let (cos_max, _) = beam.sun.unwrap();
            let dir = sample_uniform_cone(rng.uniform2(), beam.direction, cos_max);
            let along = beam.across_pdf(origin + dir * (3.0 + 6.0 * rng.uniform()), dir);
            let expected = pdf / dir.dot(beam.direction);
            assert!((along / expected - 1.0).abs() < 1e-3, "{along} vs {expected}");
            let local = beam.frame.to_local(origin - beam.plane_origin);
            let p = Vec2::new(local.x, local.y);
            on_targets += beam.discs().iter().any(|&(c, r)| (p - c).length_squared() <= r * r) as usize;
        }
        // A third aimed, plus the uniform starts that fall on the targets' discs anyway.
        let share = on_targets as f64 / n as f64;
        let area_share = (beam.target_area / (PI * beam.scene_radius * beam.scene_radius)) as f64;
        let expected = 1.0 / 3.0 + 2.0 / 3.0 * area_share;
        assert!((share - expected).abs() < 0.02, "{share} vs {expected}");
    }

    #[test]
    fn from_inside_a_target_every_direction_is_aimed() {
        let aim = Aim::new(&[target(0.0, 0.0, 0.0, 1.0)], 1.0).unwrap();
        let pdf = aim.pdf(Vec3::new(0.1, 0.0, 0.0), Vec3::X);
        assert!((pdf - uniform_sphere_pdf()).abs() < 1e-6, "{pdf}");
    }

    #[test]
    fn many_targets_become_one_around_them_all() {
        let targets: Vec<Target> = (0..20).map(|i| target(i as f32, 0.0, -5.0, 0.25)).collect();
        let aim = Aim::new(&targets, 0.5).unwrap();
        assert_eq!(aim.targets.len(), 1);
        let all = aim.targets[0];
        for t in &targets {
            assert!((t.center - all.center).length() + t.radius <= all.radius * 1.0001);
        }
        assert!(Aim::new(&[], 0.5).is_none() && Aim::new(&targets, 0.0).is_none());
    }
}
