//! The camera paths of the photon-mapping integrators: a camera ray followed through mirrors,
//! glass and (for `ppm`) sharp highlights to the smooth surfaces where photons are gathered.

use super::camera_walk::{
    bounce_as_surface, visit_as_surface, walk_camera, CameraArrival, CameraPath, CameraVisitor, CameraWalk,
};
use super::tiles::sample_pass_tiles;
use crate::bsdf::{Bsdf, BsdfSample, Transport};
use crate::camera::Camera;
use crate::math::{Ray, Vec3};
use crate::photon::light_walk::{walk_together, MediumArrival, Passage, Walker};
use crate::progress::Control;
use crate::sampling::Rng;
use crate::scene::{Scene, SurfaceHit};
use crate::spectrum::{Spectrum, Wavelengths};

/// Follows a camera ray through at most `max_depth` mirrors and glass at the wavelengths `wl`,
/// adding the emission it meets. At each smooth surface it adds
/// `beta · at_smooth(hit, bsdf, wo, path length, dispersed, left)`; where the surface's BSDF
/// then samples a smooth lobe the chain ends with
/// `beta · beyond(hit, sample, path length, dispersed, left)` (the BSDF half of direct light
/// for photon mapping, a final gather for Jensen's method). `left` is how many more surfaces
/// light may have scattered at beyond this one (`--depth` less the mirrors and glass before
/// it): photons gathered here may have bounced that often at most. With `through_specular` off, a camera ray that meets a
/// mirror or glass first stops there. A dispersive glass leaves the hero wavelength alone; both
/// closures are told whether that happened (photons that dispersed too must then not count the
/// hero's weight twice, see [`crate::photon::DISPERSED`]).
///
/// With `through_glossy` (and `through_specular`), at a surface whose smooth lobes are all
/// sharp ([`Bsdf::is_sharply_glossy`]: a glass's or a metal's highlight) the path goes on in
/// the direction its BSDF draws, glossy or specular, until the last depth, and `at_smooth` is
/// told (its `caustic_only` argument) to gather only the photons that came by mirrors and glass
/// alone (L S+): the light the path going on cannot find from a point lamp. What comes by a
/// diffuse bounce, which a photon estimate would weigh by the lobe's peak, is found further
/// along instead; emitters and the sky the path meets after going on through the glossy lobe
/// count no more (the BSDF sample there and those photons have counted them).
///
/// `along` may have the chain pass media up to its first smooth surface and gather the light
/// scattered along the way instead ([`Along`]).
#[allow(clippy::too_many_arguments)]
pub fn camera_chain<S, B>(
    scene: &Scene,
    ray: Ray,
    max_depth: u32,
    (through_specular, through_glossy): (bool, bool),
    wl: &Wavelengths,
    rng: &mut Rng,
    (at_smooth, beyond): (S, B),
    along: &mut dyn Along,
) -> Spectrum
where
    S: AtSmooth,
    B: Beyond,
{
    let mut chain = Chain::new(
        scene,
        max_depth,
        (through_specular, through_glossy),
        wl,
        (at_smooth, beyond),
        along,
    );
    walk_camera(scene, ray, wl, chain.limits(), rng, &mut chain);
    chain.l
}

/// [`camera_chain`] for each of `starts` (a camera ray and the random stream its chain draws
/// from), the chains walked together: each bounce's rays traced as one wave
/// ([`walk_together`]), which pays where the scene's triangles outgrow the caches or their
/// streams sort without branches ([`Scene::streams_pay`]). `along` gives each chain its own
/// [`Along`]. The same radiance as each chain alone, in the order of `starts`.
pub fn camera_chains<S, B, A>(
    scene: &Scene,
    starts: Vec<(Ray, Rng)>,
    max_depth: u32,
    through: (bool, bool),
    wl: &Wavelengths,
    (at_smooth, beyond): (S, B),
    along: impl Fn() -> A,
) -> Vec<Spectrum>
where
    S: AtSmooth + Clone,
    B: Beyond + Clone,
    A: Along,
{
    let mut alongs: Vec<A> = starts.iter().map(|_| along()).collect();
    let mut chains: Vec<CameraPath<Chain<S, B>>> = starts
        .into_iter()
        .zip(&mut alongs)
        .map(|((ray, rng), along)| {
            let chain = Chain::new(
                scene,
                max_depth,
                through,
                wl,
                (at_smooth.clone(), beyond.clone()),
                along,
            );
            Walker {
                walk: CameraWalk::new(scene, ray, wl, chain.limits()),
                wl: *wl,
                rng,
                visitor: chain,
            }
        })
        .collect();
    walk_together(scene, &mut chains);
    chains.into_iter().map(|c| c.visitor.l).collect()
}

/// A pass of camera chains with a tile's chains walked together ([`camera_chains`]):
/// `radiances` takes a tile's camera rays with their pixels' random streams, those
/// [`sample_pass_tiles`] draws, and gives each chain's radiance in order; the image is
/// [`sample_pass`](super::tiles::sample_pass)'s with the chains walked one by one.
pub fn chain_pass(
    (width, height, seed): (usize, usize, u64),
    pass: u64,
    control: Control,
    camera: &Camera,
    wl: &Wavelengths,
    radiances: impl Fn(Vec<(Ray, Rng)>) -> Vec<Spectrum> + Sync,
) -> Option<Vec<Vec3>> {
    sample_pass_tiles(width, height, seed, pass, control, |points| {
        let starts = points
            .into_iter()
            .map(|p| (camera.generate_ray(p.screen.0, p.screen.1), p.rng))
            .collect();
        radiances(starts).into_iter().map(|l| wl.to_rgb(l)).collect()
    })
}

/// What a camera chain adds at its smooth surface ([`camera_chain`]'s `at_smooth`):
/// `(hit, bsdf, wo, path length, dispersed, surfaces left, caustic only, rng)`.
pub trait AtSmooth: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, bool, u32, bool, &mut Rng) -> Spectrum {}

impl<F: FnMut(&SurfaceHit, &Bsdf, Vec3, f32, bool, u32, bool, &mut Rng) -> Spectrum> AtSmooth for F {}

/// What a camera chain adds beyond its smooth surface ([`camera_chain`]'s `beyond`):
/// `(hit, sample, path length, dispersed, surfaces left, rng)`.
pub trait Beyond: FnMut(&SurfaceHit, &BsdfSample, f32, bool, u32, &mut Rng) -> Spectrum {}

impl<F: FnMut(&SurfaceHit, &BsdfSample, f32, bool, u32, &mut Rng) -> Spectrum> Beyond for F {}

/// A chain's two closures, their arguments' types given by [`AtSmooth`] and [`Beyond`].
pub fn gathers<S: AtSmooth, B: Beyond>(at_smooth: S, beyond: B) -> (S, B) {
    (at_smooth, beyond)
}

/// What a camera chain gathers along its segments through media before its first smooth
/// surface, passing those media without stopping ([`BeamEstimate`](super::beam_estimate::BeamEstimate)).
pub trait Along {
    /// Whether the chain passes `medium` and gathers along it.
    fn passes(&self, medium: u32) -> bool;

    /// The light gathered along `ray` (from the chain's last vertex, `path_length` from the
    /// eye), the chain carrying `(throughput, dispersed)`, light gathered there having
    /// scattered at most `left` more times.
    fn gather(
        &mut self,
        ray: &Ray,
        passage: &Passage,
        carried: (Spectrum, bool),
        path_length_left: (f32, u32),
        rng: &mut Rng,
    ) -> Spectrum;
}

/// A camera chain on its walk (see [`camera_chain`]).
struct Chain<'c, S, B> {
    scene: &'c Scene,
    wl: &'c Wavelengths,
    max_depth: u32,
    /// (through_specular, through_glossy)
    through: (bool, bool),
    at_smooth: S,
    beyond: B,
    /// Radiance gathered so far.
    l: Spectrum,
    path_length: f32,
    /// Set once the path has gone on through a highlight's glossy lobe: the emitters it meets
    /// from there on were counted by that surface's BSDF sample (straight on) or its caustic
    /// photons (by mirrors and glass). Not by its specular lobes, which no photon reaches.
    past_highlight: bool,
    /// The surface reached is the chain's last: its sample is drawn, but not followed.
    last: bool,
    along: &'c mut dyn Along,
    /// A smooth surface was reached: no more gathering along segments.
    smooth_seen: bool,
}

impl<S, B> CameraVisitor for Chain<'_, S, B>
where
    S: AtSmooth,
    B: Beyond,
{
    fn escaped(&mut self, dir: Vec3, throughput: Spectrum, _length: u32) {
        // Only the camera and specular chains get here: the sky counts in full.
        if !self.past_highlight {
            self.l += throughput * self.scene.lights().escaped(dir, self.wl);
        }
    }

    fn passes(&self, medium: u32) -> bool {
        !self.smooth_seen && self.along.passes(medium)
    }

    fn segment(&mut self, ray: &Ray, passage: &Passage, carried: (Spectrum, bool), length: u32, rng: &mut Rng) {
        let depth = length - 1;
        if self.smooth_seen || depth > self.max_depth {
            return;
        }
        let left = self.max_depth - depth;
        self.l += carried.0 * self.along.gather(ray, passage, carried, (self.path_length, left), rng);
    }

    fn visit(&mut self, at: &CameraArrival, rng: &mut Rng) -> bool {
        let (hit, bsdf, wo) = (at.hit, at.bsdf, at.wo);
        self.path_length += at.t;
        self.smooth_seen |= bsdf.is_smooth();
        // Only the camera and specular chains reach here: emission counts in full.
        if !self.past_highlight {
            self.l += at.throughput * super::direct::emitted(self.scene, hit, wo, self.wl);
        }
        if bsdf.is_black() {
            return false;
        }
        let depth = at.length - 1;
        let (through_specular, through_glossy) = self.through;
        self.last = depth == self.max_depth || depth == 0 && !through_specular;
        if bsdf.is_smooth() {
            let left = self.max_depth - depth;
            let goes_on_glossy = self.goes_on_glossy(bsdf, through_glossy && through_specular);
            self.l += at.throughput
                * (self.at_smooth)(hit, bsdf, wo, self.path_length, at.dispersed, left, goes_on_glossy, rng);
        }
        true
    }

    // A scattering point is a smooth vertex whose lobes are the phase function: the chain
    // gathers there and ends.
    fn visit_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> bool {
        let wl = self.wl;
        visit_as_surface(self, at, wl, rng)
    }

    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let wl = self.wl;
        bounce_as_surface(self, at, wl, rng)
    }

    fn bounce(&mut self, at: &CameraArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let sample = at
            .bsdf
            .sample(at.wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?;
        if !sample.specular {
            // Even at the last depth: light that comes straight from an emitter has scattered
            // at this surface only (the BSDF half of its direct light).
            let left = self.max_depth - (at.length - 1);
            self.l += at.throughput * (self.beyond)(at.hit, &sample, self.path_length, at.dispersed, left, rng);
            let (through_specular, through_glossy) = self.through;
            if !self.goes_on_glossy(at.bsdf, through_glossy && through_specular) {
                return None;
            }
            self.past_highlight = true;
        }
        (!self.last).then_some(sample)
    }
}

impl<'c, S, B> Chain<'c, S, B> {
    /// A chain that has gathered nothing yet.
    fn new(
        scene: &'c Scene,
        max_depth: u32,
        through: (bool, bool),
        wl: &'c Wavelengths,
        (at_smooth, beyond): (S, B),
        along: &'c mut dyn Along,
    ) -> Self {
        Chain {
            scene,
            wl,
            max_depth,
            through,
            at_smooth,
            beyond,
            along,
            smooth_seen: false,
            l: Spectrum::ZERO,
            path_length: 0.0,
            past_highlight: false,
            last: false,
        }
    }

    /// The walk's surfaces and roulette start ([`walk_camera`]): no roulette, as a chain ends
    /// at its first smooth surface, or after `max_depth` mirrors.
    fn limits(&self) -> (u32, u32) {
        (self.max_depth.saturating_add(1), u32::MAX)
    }

    /// Whether the chain goes on through this surface's sharp highlight (`through`: glossy and
    /// specular chains are asked for), not at its last surface.
    fn goes_on_glossy(&self, bsdf: &Bsdf, through: bool) -> bool {
        through && !self.last && bsdf.is_sharply_glossy()
    }
}

#[cfg(test)]
mod tests {
    use crate::integrator::gi::{Gi, GiSettings};
    use crate::integrator::ppm::{Ppm, PpmSettings};
    use crate::integrator::Progressive;
    use crate::progress::{Control, NoProgress};

    /// A tile's camera chains walked together make the image each chain walked alone makes,
    /// bit for bit, for ppm (through glass and a metal's sharp highlight) and gi (final
    /// gathers from the first smooth surface): a spot light through a glass ball onto a floor
    /// beside a polished ball.
    #[test]
    fn chains_walked_together_make_the_image_single_chains_make() {
        let scene = crate::scene::build::spot_through_glass(
            "translate(0, 0.4, 1.1, scale(0.4, sphere { material = { diffuse = (0.1, 0.1, 0.1); \
             specular = (0.8, 0.8, 0.8); shininess = 200; } }))",
        );
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let control = || Control {
            progress: &NoProgress,
            cancel: &cancel,
        };
        // The pass rendered with waves and without, and how many pixels it lights.
        let both_ways = |mut render: Box<dyn FnMut(bool) -> Vec<crate::math::Vec3> + '_>| {
            let films = [true, false].map(&mut render);
            assert_eq!(films[0], films[1]);
            films[0].iter().filter(|p| p.x > 0.0).count()
        };
        let settings = PpmSettings {
            photons_per_pass: 20_000,
            ..PpmSettings::default()
        };
        let mut ppm = Ppm::new(&scene, settings, 40, 40, 3);
        let lit = both_ways(Box::new(|waves| {
            ppm.waves = waves;
            ppm.render_pass(1, control()).expect("not cancelled")
        }));
        assert!(lit > 400, "{lit} pixels lit by ppm");
        let mut gi = Gi::new(
            &scene,
            GiSettings {
                photons_per_pass: 5_000,
                ..GiSettings::default()
            },
            24,
            24,
            3,
        );
        let lit = both_ways(Box::new(|waves| {
            gi.waves = waves;
            gi.render_pass(1, control()).expect("not cancelled")
        }));
        assert!(lit > 100, "{lit} pixels lit by gi");
    }
}
