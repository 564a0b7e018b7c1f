//! The one random walk on the camera side: the path tracer, the photon-mapping integrators'
//! camera chains (`ppm`'s visible points, `gi`'s final gather) and vcm's camera subpaths all
//! follow a camera ray through [`walk_camera`], which finds each surface, makes its BSDF, hands
//! the vertex to the walk's [`CameraVisitor`] (emission, next-event estimation, photons,
//! connections, merging), lets the visitor draw the bounce, and carries the throughput on
//! through [`continue_camera`]: the spectral hero's termination at a dispersive surface,
//! Russian roulette, absorption inside glass and the depth, written once. The light side's walk is
//! [`crate::photon::light_walk`].

use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::{MediumArrival, Passage, Step, Walk, Walker};
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};

/// A surface a camera walk has reached, as its visitor sees it.
pub struct CameraArrival<'a> {
    /// The surface point.
    pub hit: &'a SurfaceHit,
    /// Its BSDF, seen from `wo`.
    pub bsdf: &'a Bsdf,
    /// Unit direction back along the arriving ray.
    pub wo: Vec3,
    /// The ray's parameter at the hit.
    pub t: f32,
    /// The path's throughput on arrival.
    pub throughput: Spectrum,
    /// Only the hero wavelength is left (a dispersive surface was passed).
    pub dispersed: bool,
    /// Surfaces met so far, this one included (1 at the first).
    pub length: u32,
}

/// What a visitor that treats a scattering point as any smooth vertex does there: `visit` it as
/// a surface whose lobes are the phase function.
pub fn visit_as_surface<V: CameraVisitor>(
    visitor: &mut V,
    at: &MediumArrival,
    wl: &Wavelengths,
    rng: &mut Rng,
) -> bool {
    let bsdf = Bsdf::phase(at.phase.g, at.wo, wl);
    visitor.visit(&CameraArrival::in_medium(at, &bsdf), rng)
}

/// [`visit_as_surface`]'s bounce: the visitor's own, through the phase function's lobes.
pub fn bounce_as_surface<V: CameraVisitor>(
    visitor: &mut V,
    at: &MediumArrival,
    wl: &Wavelengths,
    rng: &mut Rng,
) -> Option<BsdfSample> {
    let bsdf = Bsdf::phase(at.phase.g, at.wo, wl);
    visitor.bounce(&CameraArrival::in_medium(at, &bsdf), rng)
}

impl<'a> CameraArrival<'a> {
    /// A scattering point as an arrival whose lobes are `bsdf` (its phase function, for users
    /// that treat it as any smooth vertex).
    pub fn in_medium(at: &MediumArrival<'a>, bsdf: &'a Bsdf) -> CameraArrival<'a> {
        CameraArrival {
            hit: at.hit,
            bsdf,
            wo: at.wo,
            t: at.hit.t,
            throughput: at.throughput,
            dispersed: at.dispersed,
            length: at.length,
        }
    }
}

/// What a camera walk's user does at each vertex, where the path leaves the scene, and how it
/// bounces.
pub trait CameraVisitor {
    /// The path left the scene along `dir` after `length - 1` surfaces, carrying `throughput`.
    fn escaped(&mut self, dir: Vec3, throughput: Spectrum, length: u32);

    /// At each surface reached: emission, next-event estimation, gathers. `false` ends the walk.
    fn visit(&mut self, at: &CameraArrival, rng: &mut Rng) -> bool;

    /// At each scattering point in a medium: next-event estimation, gathers. `false` ends the
    /// walk.
    fn visit_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> bool;

    /// The bounce at a scattering point: by default the phase function's sample. `None` ends
    /// the walk.
    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<BsdfSample> {
        Some(at.sample_phase(rng))
    }

    /// Before each segment of a walk through a scene with media: the ray from the last vertex
    /// (the eye at first), the passage as the segment starts, the throughput and whether only
    /// the hero wavelength is left, and the number of the vertex the segment leads to. By
    /// default nothing (vcm gathers light along it: a beam query).
    fn segment(&mut self, _ray: &Ray, _passage: &Passage, _carried: (Spectrum, bool), _length: u32, _rng: &mut Rng) {}

    /// Whether the next segment passes `medium` without scattering, the throughput paying its
    /// transmittance (the visitor gathers the light scattered there some other way). By default
    /// never.
    fn passes(&self, _medium: u32) -> bool {
        false
    }

    /// The bounce at `at`: by default the BSDF's own sample. `None` ends the walk.
    fn bounce(&mut self, at: &CameraArrival, rng: &mut Rng) -> Option<BsdfSample> {
        at.bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Radiance)
    }
}

/// Follows the camera ray `ray` at the wavelengths `wl` through at most `max_surfaces`
/// surfaces, handing each to `visitor`; Russian roulette from the `roulette_from`-th surface's
/// bounce on (`u32::MAX`: never). Returns the rays traced (surfaces found and the last miss).
pub fn walk_camera(
    scene: &Scene,
    ray: Ray,
    wl: &Wavelengths,
    limits: (u32, u32),
    rng: &mut Rng,
    visitor: &mut impl CameraVisitor,
) -> u64 {
    let mut walk = CameraWalk::new(scene, ray, wl, limits);
    walk_to_end(scene, &mut walk, wl, rng, visitor);
    walk.rays
}

/// Takes `walk` to its end, a ray at a time.
fn walk_to_end(
    scene: &Scene,
    walk: &mut CameraWalk,
    wl: &Wavelengths,
    rng: &mut Rng,
    visitor: &mut impl CameraVisitor,
) {
    while walk.pending().is_some() {
        let step = walk.trace(scene, wl, rng, visitor);
        walk.arrive(scene, &step, wl, rng, visitor);
    }
}

/// A camera walk between its rays: [`walk_camera`] takes one to its end; [`walk_together`](crate::photon::light_walk::walk_together)
/// takes many a ray at a time, tracing each wave of rays together.
#[derive(Clone, Debug)]
pub struct CameraWalk {
    /// The ray to follow next.
    ray: Ray,
    throughput: Spectrum,
    /// Only the hero wavelength is left.
    dispersed: bool,
    passage: Passage,
    /// Surfaces met once the next ray has found its own (1 for the eye's ray).
    length: u32,
    ended: bool,
    max_surfaces: u32,
    roulette_from: u32,
    /// Rays traced so far.
    rays: u64,
}

impl CameraWalk {
    /// A walk starting along `ray`, through at most `max_surfaces` surfaces, Russian roulette
    /// from the `roulette_from`-th surface's bounce on.
    pub fn new(scene: &Scene, ray: Ray, wl: &Wavelengths, (max_surfaces, roulette_from): (u32, u32)) -> CameraWalk {
        CameraWalk {
            ray,
            throughput: wl.grey(1.0),
            dispersed: false,
            passage: Passage::new(scene, scene.camera_medium()),
            length: 1,
            ended: max_surfaces == 0,
            max_surfaces,
            roulette_from,
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

    /// Where the pending ray's segment ends, media sampled on the way.
    fn trace(&mut self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng, visitor: &mut impl CameraVisitor) -> Step {
        if scene.has_media() {
            let carried = (self.throughput, self.dispersed);
            visitor.segment(&self.ray, &self.passage, carried, self.length, rng);
            self.passage
                .next_passing(scene, &self.ray, (&mut self.throughput, wl), rng, |m| visitor.passes(m))
        } else {
            self.passage.next(scene, &self.ray, &mut self.throughput, wl, rng)
        }
    }

    /// Takes the pending ray's `step`: hands the vertex to `visitor`, lets it bounce, and sets
    /// up the next ray, or ends the walk.
    fn arrive(
        &mut self,
        scene: &Scene,
        step: &Step,
        wl: &Wavelengths,
        rng: &mut Rng,
        visitor: &mut impl CameraVisitor,
    ) {
        self.rays += 1;
        let length = self.length;
        // Ended unless the bounce below carries on.
        self.ended = true;
        let wo = -self.ray.dir;
        // The hit by reference: moving it out of `step` copied it in 16-byte pieces, each
        // waiting on the narrower stores that had just written it.
        let (hit, sample) = match step {
            Step::Escaped => {
                visitor.escaped(self.ray.dir, self.throughput, length);
                return;
            }
            Step::Medium(hit) => {
                let at = MediumArrival {
                    hit,
                    phase: scene.medium(hit.media.back).phase,
                    wo: wo.normalize(),
                    throughput: self.throughput,
                    dispersed: self.dispersed,
                    length,
                };
                if !visitor.visit_medium(&at, rng) {
                    return;
                }
                let Some(sample) = visitor.bounce_medium(&at, rng) else {
                    return;
                };
                (hit, sample)
            }
            Step::Surface(hit) => {
                let bsdf = Bsdf::at(scene, hit, wo, wl);
                let at = CameraArrival {
                    hit,
                    bsdf: &bsdf,
                    wo,
                    t: hit.t,
                    throughput: self.throughput,
                    dispersed: self.dispersed,
                    length,
                };
                if !visitor.visit(&at, rng) {
                    return;
                }
                let Some(sample) = visitor.bounce(&at, rng) else {
                    return;
                };
                (hit, sample)
            }
        };
        let roulette = length >= self.roulette_from;
        if !continue_camera(&sample, roulette, (&mut self.throughput, &mut self.dispersed), wl, rng) {
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

/// A camera path [`walk_together`](crate::photon::light_walk::walk_together) takes with others.
pub type CameraPath<V> = Walker<CameraWalk, V>;

impl<V: CameraVisitor> Walk<V> for CameraWalk {
    fn next_ray(&self) -> Option<&Ray> {
        self.pending()
    }

    fn take_step(&mut self, scene: &Scene, step: &Step, wl: &Wavelengths, rng: &mut Rng, visitor: &mut V) {
        self.arrive(scene, step, wl, rng, visitor);
    }

    fn walk_to_end(&mut self, scene: &Scene, wl: &Wavelengths, rng: &mut Rng, visitor: &mut V) {
        walk_to_end(scene, self, wl, rng, visitor);
    }
}

/// Carries a camera path's `(throughput, dispersed)` through the bounce `sample`, or ends the
/// path (`false`): the sample's weight, at a dispersive surface only the hero wavelength
/// onwards, and with `roulette` a survival chance of the throughput's largest channel (at most
/// 0.95).
pub fn continue_camera(
    sample: &BsdfSample,
    roulette: bool,
    (throughput, dispersed): (&mut Spectrum, &mut bool),
    wl: &Wavelengths,
    rng: &mut Rng,
) -> bool {
    *throughput *= sample.weight;
    if sample.dispersive {
        wl.terminate_secondary(throughput, dispersed);
    }
    if roulette {
        let q = throughput.max_element().min(0.95);
        if q.is_nan() || q <= 0.0 || rng.uniform() >= q {
            return false;
        }
        *throughput /= q;
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::medium::VACUUM;
    use crate::photon::light_walk::{walk_light, walk_together, LightArrival, LightVisitor, LightWalk};
    use crate::scene::build::test_scene;

    /// Every arrival's length and throughput, and the escapes.
    #[derive(Default)]
    struct Record {
        arrivals: Vec<(u32, f32)>,
        escaped: u32,
    }

    impl CameraVisitor for Record {
        fn escaped(&mut self, _dir: Vec3, _throughput: Spectrum, _length: u32) {
            self.escaped += 1;
        }
        fn visit(&mut self, at: &CameraArrival, _rng: &mut Rng) -> bool {
            self.arrivals.push((at.length, at.throughput.x));
            true
        }
        fn visit_medium(&mut self, at: &MediumArrival, _rng: &mut Rng) -> bool {
            self.arrivals.push((at.length, at.throughput.x));
            true
        }
    }

    impl LightVisitor for Record {
        fn visit(&mut self, at: &LightArrival) -> bool {
            self.arrivals.push((at.length, at.throughput.x));
            true
        }
        fn visit_medium(&mut self, at: &MediumArrival) -> bool {
            self.arrivals.push((at.length, at.throughput.x));
            true
        }
    }

    /// 200 walkers of `walk(ray)` from `start`'s rays and random streams, each recording its
    /// arrivals.
    fn walkers<W>(
        start: &impl Fn(u64) -> (Ray, Rng),
        wl: Wavelengths,
        walk: impl Fn(Ray) -> W,
    ) -> Vec<Walker<W, Record>> {
        (0..200)
            .map(|i| {
                let (ray, rng) = start(i);
                Walker {
                    walk: walk(ray),
                    wl,
                    rng,
                    visitor: Record::default(),
                }
            })
            .collect()
    }

    /// Camera walks and light walks taken together, a wave of rays per bounce, make the same arrivals in the
    /// same order with the same numbers as each walk alone: in a closed room around a bumpy
    /// mesh that walks its tree, with Russian roulette, and in the same room filled with fog
    /// (where the walks go one at a time).
    #[test]
    fn walks_taken_together_are_the_walks_taken_alone() {
        let room = "scale(6, 6, 6, sphere { material = { diffuse = (0.7, 0.6, 0.5); } })";
        let sheet = crate::scene::build::bumpy_sheet(12);
        let fog = "translate(0, 0, 1, scale(3, 3, 1.5, box { material = {
                   absorption = (0.1, 0.1, 0.1); scattering = (0.3, 0.3, 0.3); boundary = true; } }))";
        for objects in [format!("{room}\n{sheet}"), format!("{room}\n{sheet}\n{fog}")] {
            let scene = test_scene(&objects);
            assert_eq!(scene.has_media(), objects.contains("boundary"));
            let wl = Wavelengths::Rgb;
            let start = |i: u64| {
                let mut rng = Rng::new(7, i);
                let dir = Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, -1.0);
                (Ray::new(Vec3::new(0.0, 0.0, 2.5), dir), rng)
            };
            let limits = (12, 2);
            let mut paths = walkers(&start, wl, |ray| CameraWalk::new(&scene, ray, &wl, limits));
            walk_together(&scene, &mut paths);
            let mut surfaces = 0;
            for (i, together) in paths.iter_mut().enumerate() {
                let (ray, mut rng) = start(i as u64);
                let mut alone = Record::default();
                let rays = walk_camera(&scene, ray, &wl, limits, &mut rng, &mut alone);
                assert_eq!(together.visitor.arrivals, alone.arrivals, "path {i}");
                assert_eq!(together.visitor.escaped, alone.escaped);
                assert_eq!(together.walk.rays(), rays);
                assert_eq!(together.rng.uniform(), rng.uniform(), "the same numbers drawn");
                surfaces += alone.arrivals.len();
            }
            assert!(surfaces > 400, "{surfaces} surfaces");

            // Light walks the same way, from the same rays, with their own roulette.
            let carried = (wl.grey(2.0), scene.camera_medium());
            let mut paths = walkers(&start, wl, |ray| LightWalk::new(&scene, ray, carried, 12));
            walk_together(&scene, &mut paths);
            let mut surfaces = 0;
            for (i, together) in paths.iter_mut().enumerate() {
                let (ray, mut rng) = start(i as u64);
                let mut alone = Record::default();
                let rays = walk_light(&scene, ray, carried, &wl, 12, &mut rng, &mut alone);
                assert_eq!(together.visitor.arrivals, alone.arrivals, "light path {i}");
                assert_eq!(together.walk.rays(), rays);
                assert_eq!(together.rng.uniform(), rng.uniform(), "the same numbers drawn");
                surfaces += alone.arrivals.len();
            }
            assert!(surfaces > 400, "{surfaces} light surfaces");
        }
    }

    /// Inside a grey sphere (albedo 0.5) every ray meets a surface. Without roulette a walk
    /// goes to its depth, one ray a surface, halving its throughput at each bounce; with
    /// roulette from the first bounce each survival (one in two) restores it to 1, so a camera
    /// walk makes 2 visits on average; a light walk's roulette keeps its flux the same way.
    #[test]
    fn walks_go_to_their_depth_and_their_roulettes_keep_the_mean() {
        let scene = test_scene("scale(3, 3, 3, sphere { material = { diffuse = (0.5, 0.5, 0.5); } })");
        let wl = Wavelengths::Rgb;
        let ray = |rng: &mut Rng| Ray::new(Vec3::ZERO, Vec3::new(rng.uniform() - 0.5, rng.uniform() - 0.5, 1.0));
        let mut rng = Rng::new(1, 0);
        let mut record = Record::default();
        let rays = walk_camera(&scene, ray(&mut rng), &wl, (7, u32::MAX), &mut rng, &mut record);
        assert_eq!(rays, 7);
        assert_eq!(record.escaped, 0);
        for (i, &(length, throughput)) in record.arrivals.iter().enumerate() {
            assert_eq!(length, i as u32 + 1);
            let expected = 0.5f32.powi(i as i32);
            assert!(
                (throughput - expected).abs() <= 1e-5 * expected,
                "{throughput} at {length}"
            );
        }
        assert_eq!(record.arrivals.len(), 7);

        let (walks, mut visits, mut camera) = (20_000, 0usize, Record::default());
        let mut light = Record::default();
        for _ in 0..walks {
            walk_camera(&scene, ray(&mut rng), &wl, (1000, 1), &mut rng, &mut camera);
            walk_light(
                &scene,
                ray(&mut rng),
                (wl.grey(1.0), VACUUM),
                &wl,
                1000,
                &mut rng,
                &mut light,
            );
        }
        for (name, record) in [("camera", &camera), ("light", &light)] {
            visits += record.arrivals.len();
            let mean = record.arrivals.len() as f64 / walks as f64;
            assert!((mean - 2.0).abs() < 0.05, "{name}: {mean} visits a walk");
            assert!(
                record.arrivals.iter().all(|&(_, t)| (t - 1.0).abs() < 1e-5),
                "{name}: the roulette restores the throughput"
            );
        }
        assert!(visits > 70_000, "{visits}");
    }
}
