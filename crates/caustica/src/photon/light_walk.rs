//! The one random walk on the light side: physical photons, the light tracer's paths and vcm's
//! light subpaths all leave a light through [`walk_light`], which finds each surface, makes its
//! BSDF, hands the vertex to the walk's [`LightVisitor`] (store a photon, join it to the eye,
//! keep it for connections and merging), lets the visitor draw the bounce (the BSDF's sample,
//! or vcm's mixture aimed at mirrors and glass), and carries the throughput on through
//! [`continue_light`]: Veach's correction for interpolated normals, Russian roulette, the
//! spectral hero's termination at a dispersive surface, absorption inside glass and the depth,
//! written once. Over a large mesh [`walk_together`] takes many walks together, a wave of rays
//! per bounce, the camera side's as the light side's. (The course
//! model's caustic photons follow the course's own Phong rules, not a BSDF: their loop is
//! [`super::trace::trace_path`].)

use crate::bsdf::{adjoint_correction, Bsdf, BsdfSample, Transport};
use crate::math::Ray;
use crate::medium::{Media, Medium, Phase, VACUUM};
use crate::sampling::Rng;
use crate::scene::{Intersection, Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};
use glam::Vec3;
use std::ops::Range;

/// A surface a light walk has reached, as its visitor sees it.
pub struct LightArrival<'a> {
    /// The surface point.
    pub hit: &'a SurfaceHit,
    /// Unit direction back along the arriving ray.
    pub wo: Vec3,
    /// Its BSDF, seen from `wo`.
    pub bsdf: &'a Bsdf,
    /// What the walk carries on arrival (flux for photons).
    pub throughput: Spectrum,
    /// Only the hero wavelength is left (a dispersive surface was passed).
    pub dispersed: bool,
    /// Surfaces met so far, this one included (1 at the first).
    pub length: u32,
}

/// What a light walk's user does at each vertex and how the walk bounces there.
pub trait LightVisitor {
    /// At each surface reached: stores, splats or records the vertex. `false` ends the walk here.
    fn visit(&mut self, at: &LightArrival) -> bool;

    /// At each scattering point in a medium: stores, splats or records it. `false` ends the walk.
    fn visit_medium(&mut self, at: &MediumArrival) -> bool;

    /// The bounce at a scattering point and the roulette that judges it: by default the phase
    /// function's own sample.
    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        Some((at.sample_phase(rng), Roulette::KeepFlux))
    }

    /// The bounce at `at` and the roulette that judges it: by default the BSDF's own sample, the
    /// flux kept nearly constant.
    fn bounce(&mut self, at: &LightArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        at.bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Importance)
            .map(|s| (s, Roulette::KeepFlux))
    }
}

/// A scattering point a walk has reached inside a medium, as its visitor sees it.
pub struct MediumArrival<'a> {
    /// The point, as a hit without a surface ([`SurfaceHit::in_medium`]): its medium on both
    /// sides.
    pub hit: &'a SurfaceHit,
    /// The medium's phase function.
    pub phase: Phase,
    /// Unit direction back along the arriving ray.
    pub wo: Vec3,
    /// What the walk carries on arrival (the scattering's weight included).
    pub throughput: Spectrum,
    /// Only the hero wavelength is left.
    pub dispersed: bool,
    /// Vertices met so far, this one included.
    pub length: u32,
}

impl<'a> MediumArrival<'a> {
    /// This point as a surface arrival whose lobes are `bsdf` (its phase function, for users
    /// that treat it as any smooth vertex).
    pub fn as_light_arrival<'b>(&self, bsdf: &'b Bsdf) -> LightArrival<'b>
    where
        'a: 'b,
    {
        LightArrival {
            hit: self.hit,
            wo: self.wo,
            bsdf,
            throughput: self.throughput,
            dispersed: self.dispersed,
            length: self.length,
        }
    }

    /// The phase function's sample from this point, as a bounce: a smooth one whose weight is 1.
    pub fn sample_phase(&self, rng: &mut Rng) -> BsdfSample {
        let (wi, pdf) = self.phase.sample(self.wo, rng.uniform2());
        BsdfSample {
            wi,
            weight: Spectrum::ONE,
            pdf,
            specular: false,
            transmitted: false,
            dispersive: false,
        }
    }
}

/// Where a walk's next segment ends.
pub enum Step {
    /// At a surface: its hit (with the media on its two sides) and the ray's parameter there.
    Surface(SurfaceHit),
    /// At a scattering point in a medium ([`SurfaceHit::in_medium`]).
    Medium(SurfaceHit),
    /// Out of the scene.
    Escaped,
}

impl Step {
    /// Where a segment along `ray` through a scene without media ends, given its closest hit.
    #[inline]
    pub fn without_media(scene: &Scene, ray: &Ray, isect: Option<Intersection>) -> Step {
        match isect {
            Some(isect) => Step::Surface(scene.surface(ray, &isect)),
            None => Step::Escaped,
        }
    }
}

/// What both walks carry from vertex to vertex: the medium they are in (fog, or the inside of
/// an absorbing glass), whose free flights and absorption each segment samples, and the one
/// that surrounded them before they entered a glass.
#[derive(Clone, Copy, Debug)]
pub struct Passage {
    medium: u32,
    outer: u32,
}

impl Passage {
    /// A walk starting in `medium`.
    pub fn new(scene: &Scene, medium: u32) -> Passage {
        Passage {
            medium,
            outer: scene.ambient_medium(),
        }
    }

    /// Where the segment along `ray` ends: the next surface, a scattering point in the medium
    /// the walk is in, or out of the scene; `throughput` pays the medium on the way, at the
    /// wavelengths `wl`. Boundaries between media are crossed on the way, not returned.
    #[inline]
    pub fn next(
        &mut self,
        scene: &Scene,
        ray: &Ray,
        throughput: &mut Spectrum,
        wl: &Wavelengths,
        rng: &mut Rng,
    ) -> Step {
        if !scene.has_media() {
            return Step::without_media(scene, ray, scene.intersect(ray, f32::INFINITY));
        }
        self.next_passing(scene, ray, (throughput, wl), rng, |_| false)
    }

    /// [`Passage::next`], passing the media for which `passes` holds without scattering in
    /// them: `throughput` pays their transmittance.
    pub fn next_passing(
        &mut self,
        scene: &Scene,
        ray: &Ray,
        (throughput, wl): (&mut Spectrum, &Wavelengths),
        rng: &mut Rng,
        passes: impl Fn(u32) -> bool,
    ) -> Step {
        let length = ray.dir.length();
        let dir = ray.dir / length;
        let mut ray = Ray::new(ray.origin, dir);
        // Distance from the first ray's origin to this one's.
        let mut travelled = 0.0;
        for _ in 0..1024 {
            let isect = scene.intersect(&ray, f32::INFINITY);
            if self.medium != VACUUM {
                let segment = scene.medium_segment(&ray, (0.0, isect.map_or(f32::INFINITY, |i| i.t)));
                let medium = scene.medium(self.medium);
                if passes(self.medium) {
                    *throughput *= medium.transmittance(&ray, segment, wl, rng);
                } else if let Some(t) = medium.sample_flight(&ray, segment, wl, throughput, rng) {
                    let mut hit = SurfaceHit::in_medium(ray.at(t), self.medium);
                    hit.t = (travelled + t) / length;
                    return Step::Medium(hit);
                }
            }
            let Some(mut isect) = isect else {
                return Step::Escaped;
            };
            if scene.is_boundary(&isect) {
                if let Some(solid) = scene.solid_at_boundary(&ray, &isect) {
                    isect = solid;
                }
            }
            let mut hit = scene.surface(&ray, &isect);
            if scene.is_boundary(&isect) {
                self.medium = scene.medium_beyond(&hit, dir, self.medium, &mut self.outer);
                let origin = hit.ray_origin(dir);
                travelled += (origin - ray.origin).length();
                ray = Ray::new(origin, dir);
                continue;
            }
            let beyond = scene.medium_beyond(&hit, dir, self.medium, &mut self.outer.clone());
            hit.media = if dir.dot(hit.geometric_normal) < 0.0 {
                Media {
                    front: self.medium,
                    back: beyond,
                }
            } else {
                Media {
                    front: beyond,
                    back: self.medium,
                }
            };
            hit.t = (travelled + isect.t) / length;
            return Step::Surface(hit);
        }
        Step::Escaped
    }

    /// The media along `ray` (unit direction) as the walk would pass them without scattering,
    /// up to the first surface that is not a boundary: `f(medium, t0, t1)` for each stretch of
    /// a medium, in order, as distances from the ray's origin (one stretch where a boundary
    /// has the same medium on both sides).
    pub fn pieces(&self, scene: &Scene, ray: &Ray, mut f: impl FnMut(u32, f32, f32)) {
        let (mut medium, mut outer) = (self.medium, self.outer);
        let mut piece = *ray;
        let mut travelled = 0.0;
        let mut pending: Option<(u32, f32, f32)> = None;
        for _ in 0..1024 {
            let isect = scene.intersect(&piece, f32::INFINITY);
            if medium != VACUUM {
                let (a, b) = scene.medium_segment(&piece, (0.0, isect.map_or(f32::INFINITY, |i| i.t)));
                if a < b {
                    let (a, b) = (travelled + a, travelled + b);
                    pending = match pending {
                        Some((m, start, end)) if m == medium && a - end <= 1e-3 * end.max(1.0) => Some((m, start, b)),
                        Some((m, start, end)) => {
                            f(m, start, end);
                            Some((medium, a, b))
                        }
                        None => Some((medium, a, b)),
                    };
                }
            }
            let crossed = isect.filter(|i| scene.is_boundary(i) && scene.solid_at_boundary(&piece, i).is_none());
            let Some(isect) = crossed else {
                break;
            };
            let hit = scene.surface(&piece, &isect);
            medium = scene.medium_beyond(&hit, ray.dir, medium, &mut outer);
            let origin = hit.ray_origin(ray.dir);
            travelled += (origin - piece.origin).length();
            piece = Ray::new(origin, ray.dir);
        }
        if let Some((m, start, end)) = pending {
            f(m, start, end);
        }
    }

    /// Walks the media along `ray` (unit direction) as [`Passage::pieces`] finds them, for a
    /// camera ray that passes them and gathers the light scattered along its way (the beam
    /// queries of vcm and ppm): `f(stretch, rng)` for each stretch of a medium for which
    /// `gathers` holds, which reads what light keeps from the ray's origin to any point of it;
    /// the media of the other stretches only dim those after them.
    pub fn along_media(
        &self,
        scene: &Scene,
        ray: &Ray,
        wl: &Wavelengths,
        rng: &mut Rng,
        gathers: impl Fn(u32) -> bool,
        mut f: impl FnMut(&Stretch, &mut Rng),
    ) {
        let mut before = wl.grey(1.0);
        let mut steps = Vec::new();
        self.pieces(scene, ray, |id, t0, t1| {
            let medium = scene.medium(id);
            if !gathers(id) {
                before *= medium.transmittance(ray, (t0, t1), wl, rng);
                return;
            }
            medium.transmittance_steps(ray, (t0, t1), wl, rng, &mut steps);
            let stretch = Stretch {
                id,
                medium,
                span: (t0, t1),
                before,
                steps: &steps,
                wl,
            };
            f(&stretch, rng);
            before = stretch.kept(t1);
        });
    }

    /// After a bounce at the surface `hit` that goes on along `sample`: through the surface,
    /// the walk is in the medium beyond it.
    #[inline]
    pub fn cross(&mut self, scene: &Scene, hit: &SurfaceHit, sample: &BsdfSample) {
        if sample.transmitted && scene.has_media() {
            self.medium = scene.medium_beyond(hit, sample.wi, self.medium, &mut self.outer);
        }
    }
}

/// A stretch of one medium along a ray ([`Passage::along_media`]).
pub struct Stretch<'s> {
    /// The medium's number.
    pub id: u32,
    /// The medium.
    pub medium: &'s Medium,
    /// Where it starts and ends along the ray.
    pub span: (f32, f32),
    /// What the media before it keep.
    pub before: Spectrum,
    /// A density grid's transmittance from the start, a step function (empty: homogeneous).
    steps: &'s [(f32, Spectrum)],
    wl: &'s Wavelengths,
}

impl Stretch<'_> {
    /// What light keeps from the ray's origin to `t` (held within the stretch).
    pub fn kept(&self, t: f32) -> Spectrum {
        let (t0, t1) = self.span;
        let t = t.clamp(t0, t1);
        self.before
            * if self.medium.grid.is_none() {
                self.medium.kept_homogeneous(t - t0, self.wl)
            } else {
                match self.steps.partition_point(|s| s.0 <= t) {
                    0 => self.wl.grey(1.0),
                    i => self.steps[i - 1].1,
                }
            }
    }

    /// Where a beam query of `radius` looks: a radius beyond where the medium starts at a surface
    /// (not at the ray's origin) and where it ends. Met obliquely, the tube around the ray
    /// reaches past such a surface on one side and misses the medium's light on the other; the
    /// light beyond the ends makes up for it (exactly, for a flat boundary met at up to 45°).
    pub fn reach(&self, radius: f32) -> (f32, f32) {
        let (t0, t1) = self.span;
        (t0 - if t0 > 0.0 { radius } else { 0.0 }, t1 + radius)
    }
}

/// Follows light from `ray` carrying `throughput` from a light in `medium` at the wavelengths
/// `wl` through at most `max_surfaces` vertices (surfaces and scattering points), handing each
/// to `visitor`. Returns the rays traced (surfaces found
/// and the last ray's miss).
pub fn walk_light(
    scene: &Scene,
    ray: Ray,
    carried: (Spectrum, u32),
    wl: &Wavelengths,
    max_surfaces: u32,
    rng: &mut Rng,
    visitor: &mut impl LightVisitor,
) -> u64 {
    let mut walk = LightWalk::new(scene, ray, carried, max_surfaces);
    walk.finish(scene, wl, rng, visitor);
    walk.rays
}

/// A light walk between its rays: [`walk_light`] takes one to its end; [`walk_together`] takes
/// many a ray at a time, tracing each wave of rays together.
#[derive(Clone, Debug)]
pub struct LightWalk {
    /// The ray to follow next.
    ray: Ray,
    throughput: Spectrum,
    /// Only the hero wavelength is left.
    dispersed: bool,
    passage: Passage,
    /// Vertices met once the next ray has found its own (1 for the light's ray).
    length: u32,
    ended: bool,
    max_surfaces: u32,
    /// Rays traced so far.
    rays: u64,
}

impl LightWalk {
    /// A walk leaving a light in `medium` along `ray` carrying `throughput`, through at most
    /// `max_surfaces` vertices.
    pub fn new(scene: &Scene, ray: Ray, (throughput, medium): (Spectrum, u32), max_surfaces: u32) -> LightWalk {
        LightWalk {
            ray,
            throughput,
            dispersed: false,
            passage: Passage::new(scene, medium),
            length: 1,
            ended: max_surfaces == 0,
            max_surfaces,
            rays: 0,
        }
    }

    /// The ray the walk follows next; `None` once it has ended.
    pub fn pending(&self) -> Option<&Ray> {
        (!self.ended).then_some(&self.ray)
    }

    /// Rays traced so far.
    pub fn rays(&self) -> u64 {
        self.rays
    }

    /// Takes the walk to its end, a ray at a time.
    fn finish(&mut self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng, visitor: &mut impl LightVisitor) {
        while !self.ended {
            let step = self.passage.next(scene, &self.ray, &mut self.throughput, wl, rng);
            self.arrive(scene, &step, wl, rng, visitor);
        }
    }

    /// Takes the pending ray's `step`: hands the vertex to `visitor`, lets it bounce, and sets
    /// up the next ray, or ends the walk.
    fn arrive(&mut self, scene: &Scene, step: &Step, wl: &Wavelengths, rng: &mut Rng, visitor: &mut impl LightVisitor) {
        self.rays += 1;
        let length = self.length;
        // Ended unless the bounce below carries on.
        self.ended = true;
        let wo = -self.ray.dir;
        let (hit, sample, roulette) = match step {
            Step::Escaped => return,
            Step::Medium(hit) => {
                let at = MediumArrival {
                    hit,
                    phase: scene.medium(hit.media.back).phase,
                    wo,
                    throughput: self.throughput,
                    dispersed: self.dispersed,
                    length,
                };
                if !visitor.visit_medium(&at) {
                    return;
                }
                let Some((sample, roulette)) = visitor.bounce_medium(&at, rng) else {
                    return;
                };
                (hit, sample, roulette)
            }
            Step::Surface(hit) => {
                let bsdf = Bsdf::at(scene, hit, wo, wl);
                let at = LightArrival {
                    hit,
                    wo,
                    bsdf: &bsdf,
                    throughput: self.throughput,
                    dispersed: self.dispersed,
                    length,
                };
                if !visitor.visit(&at) {
                    return;
                }
                let Some((sample, roulette)) = visitor.bounce(&at, rng) else {
                    return;
                };
                (hit, sample, roulette)
            }
        };
        let carried = (&mut self.throughput, &mut self.dispersed);
        if !continue_light(hit, wo, &sample, roulette, carried, wl, rng) {
            return;
        }
        self.passage.cross(scene, hit, &sample);
        self.ray = Ray::new(hit.ray_origin(sample.wi), sample.wi);
        if length < self.max_surfaces {
            self.length = length + 1;
            self.ended = false;
        }
    }
}

/// The waves a caller of [`walk_together`] splits the light paths `indices` into, in order:
/// `together` (where streams pay, [`Scene::streams_pay`]), 256 paths a wave, enough for the
/// stream's loads to overlap, as a tile's camera paths; else one path a wave, whose walk keeps
/// its own state and output in the cache (waves of 256 there made `vcm` 11–17% and `lt` 6–9%
/// slower on the Cornell box and the glass ball, where inside a million-triangle mesh they made
/// `ppm`, `lt` and `vcm` 1.3–1.7× faster).
pub fn light_waves(together: bool, indices: Range<u64>) -> impl Iterator<Item = Range<u64>> {
    let wave = if together { 256 } else { 1 };
    let end = indices.end;
    indices
        .step_by(wave)
        .map(move |first| first..(first + wave as u64).min(end))
}

/// A light path [`walk_together`] takes with others.
pub type LightPath<V> = Walker<LightWalk, V>;

impl<V: LightVisitor> Walk<V> for LightWalk {
    fn next_ray(&self) -> Option<&Ray> {
        self.pending()
    }

    fn take_step(&mut self, scene: &Scene, step: &Step, wl: &Wavelengths, rng: &mut Rng, visitor: &mut V) {
        self.arrive(scene, step, wl, rng, visitor);
    }

    fn walk_to_end(&mut self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng, visitor: &mut V) {
        self.finish(scene, wl, rng, visitor);
    }
}

/// A walk between its rays whose vertices a visitor `V` takes: the camera side's
/// [`CameraWalk`](crate::integrator::camera_walk::CameraWalk) or the light side's [`LightWalk`].
pub trait Walk<V> {
    /// The ray it follows next; `None` once it has ended.
    fn next_ray(&self) -> Option<&Ray>;

    /// Takes the pending ray's `step` (where its segment ends).
    fn take_step(&mut self, scene: &Scene, step: &Step, wl: &Wavelengths, rng: &mut Rng, visitor: &mut V);

    /// Takes it to its end a ray at a time, media sampled on the way.
    fn walk_to_end(&mut self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng, visitor: &mut V);
}

/// One of the paths [`walk_together`] takes: its walk, wavelengths, random stream and visitor.
pub struct Walker<W, V> {
    /// The walk.
    pub walk: W,
    /// Its wavelengths.
    pub wl: Wavelengths,
    /// Its random stream.
    pub rng: Rng,
    /// What it does at each vertex.
    pub visitor: V,
}

/// How many walks ahead of the one taking its step [`walk_together`] fetches a hit's vertex
/// indices.
const PREFETCH_AHEAD: usize = 4;

/// Takes every walker's walk to its end, as each alone would and with the same results, in
/// waves: the pending rays of all live walks are traced together ([`Scene::intersect_stream`]),
/// then each walk takes its step. In scenes with media (where a segment's end depends on the
/// path's random numbers), or for one walker, the walks go one at a time.
pub fn walk_together<W: Walk<V>, V>(scene: &Scene, walkers: &mut [Walker<W, V>]) {
    walk_together_settling(scene, walkers, |_| {});
}

/// [`walk_together`], calling `settle(walkers)` after each wave's steps (a wave's shadow rays
/// tested together) where the walks go in waves ([`in_waves`]).
pub fn walk_together_settling<W: Walk<V>, V>(
    scene: &Scene,
    walkers: &mut [Walker<W, V>],
    mut settle: impl FnMut(&mut [Walker<W, V>]),
) {
    if !in_waves(scene, walkers.len()) {
        for w in walkers {
            w.walk.walk_to_end(scene, &w.wl, &mut w.rng, &mut w.visitor);
        }
        return;
    }
    let mut live: Vec<usize> = (0..walkers.len())
        .filter(|&i| walkers[i].walk.next_ray().is_some())
        .collect();
    let (mut rays, mut hits) = (Vec::with_capacity(live.len()), Vec::with_capacity(live.len()));
    while !live.is_empty() {
        rays.clear();
        rays.extend(live.iter().map(|&i| *walkers[i].walk.next_ray().expect("a live walk")));
        hits.resize(live.len(), None);
        scene.intersect_stream(&rays, &mut hits);
        // A large mesh's hits miss the cache twice before shading (the triangle's reference,
        // then its vertex indices): both are fetched ahead of the walks that read them.
        hits.iter().flatten().for_each(|hit| scene.prefetch_reference(hit));
        let mut wave = rays.iter().zip(&hits);
        let mut ahead = hits.iter().skip(PREFETCH_AHEAD);
        live.retain(|&i| {
            if let Some(Some(hit)) = ahead.next() {
                scene.prefetch_indices(hit);
            }
            let (ray, &hit) = wave.next().expect("one ray per live walk");
            let w = &mut walkers[i];
            let step = Step::without_media(scene, ray, hit);
            w.walk.take_step(scene, &step, &w.wl, &mut w.rng, &mut w.visitor);
            w.walk.next_ray().is_some()
        });
        settle(walkers);
    }
}

/// Whether [`walk_together`] walks `walkers` walks in waves: not in scenes with media (where a
/// segment's end depends on the path's random numbers), nor for one walker.
pub fn in_waves(scene: &Scene, walkers: usize) -> bool {
    !scene.has_media() && walkers >= 2
}

/// How a light-side walk decides to go on.
#[derive(Clone, Copy, Debug)]
pub enum Roulette {
    /// Survive with the share of the throughput the bounce keeps, so that flux stays nearly
    /// constant along the path (photon mapping, light tracing).
    KeepFlux,
    /// As `KeepFlux` at mirrors and glass; elsewhere also in proportion to how far the
    /// throughput has fallen below `start`, its value at the light (vcm); `aimed`: the bounce
    /// was aimed at a mirror or glass and goes on with the little it carries.
    TowardsStart {
        /// The throughput's largest channel as it left the light.
        start: f32,
        /// The bounce was aimed at a mirror or glass.
        aimed: bool,
    },
}

/// Carries the walk's `(throughput, dispersed)` through the bounce `sample` drawn at `hit`
/// (seen from `wo`), or ends the walk (`false`): the sample's weight with Veach's correction,
/// the roulette, and at a dispersive surface only the hero wavelength onwards (`dispersed`
/// records it).
pub fn continue_light(
    hit: &SurfaceHit,
    wo: Vec3,
    sample: &BsdfSample,
    roulette: Roulette,
    (throughput, dispersed): (&mut Spectrum, &mut bool),
    wl: &Wavelengths,
    rng: &mut Rng,
) -> bool {
    let Some(correction) = adjoint_correction(hit.shading_normal, hit.geometric_normal, wo, sample.wi) else {
        return false;
    };
    let weight = sample.weight * correction;
    let q = match roulette {
        Roulette::TowardsStart { aimed: true, .. } => 1.0,
        Roulette::TowardsStart { start, .. } if !sample.specular => {
            (weight.max_element() * (throughput.max_element() / start).min(1.0)).min(1.0)
        }
        _ => weight.max_element().min(1.0),
    };
    if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
        return false;
    }
    *throughput *= weight / q;
    if sample.dispersive {
        wl.terminate_secondary(throughput, dispersed);
    }
    true
}
