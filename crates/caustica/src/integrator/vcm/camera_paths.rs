//! Camera subpaths: each vertex gathers the emitters it hits, next-event estimation, the
//! connections to the pass's light vertices and, at its first smooth vertex, merging
//! ([`super::merging`]), every strategy weighted by [`mis`].

use super::*;
use crate::photon::light_walk::{walk_together, MediumArrival, Passage, Walker};

/// One camera subpath on its walk: its MIS sums, the variants merging at the first vertex
/// needs, and the radiance gathered.
pub(super) struct CameraSubpath<'v, 'a> {
    vcm: &'v Vcm<'a>,
    pass: &'v PassData,
    /// The light subpath this pixel connects to.
    own: usize,
    wl: &'v Wavelengths,
    work: &'v mut CameraWork,
    l: Spectrum,
    partial: Partial,
    /// The vertex before (the eye at first).
    previous: Vec3,
    /// The last bounce's density, for the sky and suns (None: seen directly or by a mirror).
    last_pdf: Option<f32>,
    /// The sums as they would be without merging at the first vertex, taken if the second
    /// turns out to be a mirror or glass (the eye then sees a caustic there), and the sums
    /// with it, kept along the mirrors and glass that follow: light that reached them from
    /// a diffuse surface (not a direct caustic) is merged at the first vertex again.
    without_first_merge: Partial,
    with_first_merge: Option<Partial>,
    /// The sums without merging at the last vertex, for an emitter hit next (light reaches
    /// that vertex first).
    without_last_merge: Partial,
    /// Whether the path scattered off a smooth lobe before: merging is a strategy at the
    /// first vertex where it does (the delta lobes of coated glass, as mirrors and glass,
    /// pass the merge on to the next vertex).
    smooth_before: bool,
    /// Whether the first vertex lies where caustics are focused.
    first_focused: bool,
}

impl CameraVisitor for CameraSubpath<'_, '_> {
    fn escaped(&mut self, dir: Vec3, throughput: Spectrum, length: u32) {
        let seen = self.vcm.escaped(
            dir,
            self.previous,
            self.last_pdf,
            &self.without_last_merge,
            length,
            self.wl,
        );
        self.l += throughput * seen;
    }

    // Until the path first scatters off a smooth lobe, it passes the media where beam queries
    // gather the light (it never stops there), and each segment gathers along its way
    // ([`super::beams`]).
    fn passes(&self, medium: u32) -> bool {
        self.gathers_beams() && self.vcm.merges_in_medium(medium)
    }

    fn segment(&mut self, ray: &Ray, passage: &Passage, carried: (Spectrum, bool), length: u32, rng: &mut Rng) {
        if !self.gathers_beams() {
            return;
        }
        let (vcm, pass, partial, wl) = (self.vcm, self.pass, self.partial, self.wl);
        let seen = vcm.gather_beam(ray, passage, carried, &partial, length, pass, wl, rng, self.work);
        self.work.merged += seen;
        self.l += seen;
    }

    // A scattering point is a smooth vertex whose lobes are the phase function: it gathers
    // next-event estimation and connections as a surface does, but never merges (where it
    // would be the path's first smooth vertex, the path passes on: a beam query merges there).
    fn visit_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> bool {
        let wl = self.wl;
        visit_as_surface(self, at, wl, rng)
    }

    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let wl = self.wl;
        bounce_as_surface(self, at, wl, rng)
    }

    fn visit(&mut self, at: &CameraArrival, rng: &mut Rng) -> bool {
        let (vcm, f, wl) = (self.vcm, &self.pass.factors, self.wl);
        let (hit, bsdf, wo, length) = (at.hit, at.bsdf, at.wo, at.length);
        let d2 = (hit.point - self.previous).length_squared();
        let previous = self.previous;
        self.previous = hit.point;
        let cos_in = bsdf.cos(wo);
        self.partial.arrive(d2, cos_in);
        let le = crate::integrator::direct::emitted(vcm.scene, hit, wo, wl);
        if le != Spectrum::ZERO {
            self.without_last_merge.arrive(d2, cos_in);
            let weight = vcm.emitter_weight(hit, &self.without_last_merge, previous, wo, d2, length);
            self.l += at.throughput * le * weight;
        }
        if length == 2 && !bsdf.is_smooth() && self.first_focused {
            self.without_first_merge.arrive(d2, cos_in);
            self.with_first_merge = Some(self.partial);
            self.partial = self.without_first_merge;
        } else if let Some(mut with) = self.with_first_merge {
            with.arrive(d2, cos_in);
            self.with_first_merge = Some(with);
            if bsdf.is_smooth() {
                self.partial = with;
                self.with_first_merge = None;
            }
        }
        if !vcm.settings.connections && length > 1 {
            // The sum's first term stands for a connection that makes this vertex (for an
            // emitter, next-event estimation, counted above).
            self.partial.vcm = 0.0;
        }
        if length >= vcm.max_length || bsdf.is_black() {
            return false;
        }
        if length == 1 {
            self.first_focused = vcm.focus.contains(hit.point);
        }
        if bsdf.is_smooth() {
            let merges_here = !self.smooth_before && !hit.is_in_medium();
            let v = CameraVertex {
                hit,
                bsdf,
                wo,
                throughput: at.throughput,
                partial: self.partial,
                length,
                dispersed: at.dispersed,
                along: None,
            };
            self.l += vcm.direct(&v, f, wl, rng, self.work);
            let paths = &self.pass.paths;
            let own = self.own;
            if vcm.settings.connections && own + 1 < paths.ends.len() {
                let (start, end) = (paths.ends[own] as usize, paths.ends[own + 1] as usize);
                for z in &paths.vertices[start..end] {
                    self.l += vcm.connect(&v, z, f, wl, merges_here, rng);
                }
            }
            if merges_here && f.merge > 0.0 {
                let merged = vcm.merge(&v, self.pass, self.work);
                self.work.merged += merged;
                self.l += merged;
            }
        }
        true
    }

    fn bounce(&mut self, at: &CameraArrival, rng: &mut Rng) -> Option<BsdfSample> {
        let (f, bsdf, wo, length) = (&self.pass.factors, at.bsdf, at.wo, at.length);
        let sample = bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Radiance)?;
        let merges_here = bsdf.is_smooth() && !self.smooth_before && !at.hit.is_in_medium();
        let cos_out = bsdf.cos(sample.wi);
        self.smooth_before |= !sample.specular;
        if sample.specular {
            self.partial.scatter_specular(cos_out);
            if let Some(with) = self.with_first_merge.as_mut() {
                with.scatter_specular(cos_out);
            }
            self.without_last_merge = self.partial;
            if length == 1 {
                self.without_first_merge = self.partial;
            }
            self.last_pdf = None;
        } else {
            let reverse = self
                .vcm
                .light_pdf(bsdf, at.hit.point, wo, bsdf.pdf_reverse(wo, sample.wi));
            self.without_last_merge = self.partial;
            self.without_last_merge.scatter(f, sample.pdf, reverse, cos_out, false);
            if length == 1 {
                self.without_first_merge = self.without_last_merge;
            }
            if length == 1 && !at.hit.is_in_medium() {
                // An emitter hit next is direct light at the first vertex: no light tracing
                // there either (its term is the sum's first at the eye's first vertex).
                self.without_last_merge = Partial {
                    vcm: 0.0,
                    ..self.partial
                };
                self.without_last_merge.scatter(f, sample.pdf, reverse, cos_out, false);
            }
            self.partial.scatter(f, sample.pdf, reverse, cos_out, merges_here);
            self.last_pdf = Some(sample.pdf);
        }
        Some(sample)
    }
}

/// What a walked camera subpath gathered (black if not finite); its rays counted in its work.
pub(super) fn camera_radiance(path: CameraPath<CameraSubpath>) -> Spectrum {
    let l = path.visitor.l;
    path.visitor.work.rays += path.walk.rays();
    if l.is_finite() {
        l
    } else {
        Spectrum::ZERO
    }
}

impl CameraSubpath<'_, '_> {
    /// Whether the path's segments gather light by beam queries: before its first smooth vertex.
    fn gathers_beams(&self) -> bool {
        !self.smooth_before && self.pass.factors.merge > 0.0 && self.vcm.scatters
    }
}

impl<'a> Vcm<'a> {
    /// Radiance along the camera ray `ray`, joined to the pass's light subpaths (`own`: the
    /// one this pixel connects to).
    pub(super) fn camera_path(
        &self,
        ray: Ray,
        pass: &PassData,
        own: usize,
        wl: &Wavelengths,
        rng: &mut Rng,
        work: &mut CameraWork,
    ) -> Spectrum {
        let Some(mut path) = self.camera_subpath(ray, (pass, own), wl, rng.clone(), work) else {
            return Spectrum::ZERO;
        };
        walk_together(self.scene, std::slice::from_mut(&mut path));
        *rng = path.rng.clone();
        camera_radiance(path)
    }

    /// The camera subpath along `ray` (`None`: the camera sees nothing that way), joined to the
    /// light subpaths of `pass` (`own`: the one its pixel connects to), drawing from `rng`.
    pub(super) fn camera_subpath<'v>(
        &'v self,
        ray: Ray,
        (pass, own): (&'v PassData, usize),
        wl: &'v Wavelengths,
        rng: Rng,
        work: &'v mut CameraWork,
    ) -> Option<CameraPath<CameraSubpath<'v, 'a>>> {
        let camera_pdf = self.sensor.importance(ray.dir);
        if camera_pdf <= 0.0 {
            return None;
        }
        let visitor = CameraSubpath {
            vcm: self,
            pass,
            own,
            wl,
            work,
            l: Spectrum::ZERO,
            partial: Partial::camera(&pass.factors, camera_pdf),
            previous: ray.origin,
            last_pdf: None,
            without_first_merge: Partial::default(),
            with_first_merge: None,
            without_last_merge: Partial::default(),
            smooth_before: false,
            first_focused: false,
        };
        Some(Walker {
            walk: CameraWalk::new(self.scene, ray, wl, (self.max_length, ROULETTE_DEPTH)),
            wl: *wl,
            rng,
            visitor,
        })
    }

    /// What a camera path leaving `from` in `dir` after `length` segments sees of the sky and
    /// suns: those that start light subpaths weighed against every strategy (`camera`: the
    /// sums without merging at the last vertex, where light arrives first), any other against
    /// next-event estimation alone, as in the path tracer (`last_pdf`: the last bounce's).
    fn escaped(
        &self,
        dir: Vec3,
        from: Vec3,
        last_pdf: Option<f32>,
        camera: &Partial,
        length: u32,
        wl: &Wavelengths,
    ) -> Spectrum {
        let lights = self.scene.lights();
        let mut l = lights.escaped_weighted_except(dir, last_pdf, wl, |number| self.emitters.emits(number));
        for number in 0..lights.len() {
            if let Some((radiance, direct, emission)) = self.emitters.far_seen(self.scene, number, from, dir) {
                let weight = if length == 1 {
                    1.0
                } else {
                    mis::emitter_hit(
                        camera,
                        direct * self.direct_samples(number, length - 1) as f32,
                        emission,
                    )
                };
                l += wl.unbounded(radiance) * weight;
            }
        }
        l
    }

    /// The weight of an emitter the camera path hit after `length` segments.
    fn emitter_weight(&self, hit: &SurfaceHit, camera: &Partial, from: Vec3, wo: Vec3, d2: f32, length: u32) -> f32 {
        if length == 1 {
            return 1.0;
        }
        let lights = self.scene.lights();
        let Some((number, light)) = lights.area_light_of(hit) else {
            return 1.0;
        };
        if !self.emitters.emits(number) {
            return 1.0;
        }
        let normal = hit.geometric_normal;
        // Next-event estimation at the vertex before took this many samples.
        let samples = self.direct_samples(number, length - 1) as f32;
        let direct = samples
            * lights.direct_probability(number)
            * light.pdf_towards(from, hit.point, normal)
            * normal.dot(wo).abs()
            / d2;
        let emission = self.emitters.emission_pdf(number, light, hit.point, normal, wo);
        mis::emitter_hit(camera, direct, emission)
    }

    /// Next-event samples of emitter `number` at the camera vertex `length` segments from the
    /// eye: [`FIRST_VERTEX_LIGHT_SAMPLES`] for a light with a size at the first, whose penumbrae
    /// the eye sees directly.
    fn direct_samples(&self, number: usize, length: u32) -> u32 {
        match self.scene.lights().get(number) {
            Some(crate::light::Light::Area(_)) if length == 1 => FIRST_VERTEX_LIGHT_SAMPLES,
            _ => 1,
        }
    }

    /// Next-event estimation at a camera vertex: every light when there are few, else one by
    /// power (as the path tracer).
    pub(super) fn direct(
        &self,
        v: &CameraVertex,
        f: &Factors,
        wl: &Wavelengths,
        rng: &mut Rng,
        work: &mut CameraWork,
    ) -> Spectrum {
        if v.length + 1 > self.max_length {
            return Spectrum::ZERO;
        }
        let lights = self.scene.lights();
        let mut l = Spectrum::ZERO;
        let takes = |wi: Vec3| v.bsdf.may_take(wi);
        // A wall's f, cosine and densities at once: the values asked one by one, for less.
        let lambertian = v.bsdf.plain_lambertian(v.wo);
        let mut one = |number: usize, pick: f32, rng: &mut Rng| {
            work.rays += 1;
            if self.emitters.emits(number) {
                let samples = if v.along.is_some() {
                    1
                } else {
                    self.direct_samples(number, v.length)
                };
                for _ in 0..samples {
                    let choice = lights.direct_probability(number);
                    let Some(s) = lights.sample_light(number, choice, (self.scene, v.hit, &takes), wl, rng) else {
                        continue;
                    };
                    let lit = lambertian.as_ref().and_then(|lambertian| lambertian.toward(s.wi));
                    let value = lit.map_or_else(|| v.bsdf.eval(v.wo, s.wi), |(f, _, _)| f);
                    if value == Spectrum::ZERO {
                        continue;
                    }
                    let cos_here = lit.map_or_else(|| v.bsdf.cos(s.wi), |(_, cos, _)| cos);
                    // Lit, a Lambertian lobe's reverse density is its density of drawing `wo`.
                    let reverse = match (&lambertian, lit) {
                        (Some(lambertian), Some(_)) => lambertian.reverse,
                        _ => v.bsdf.pdf_reverse(v.wo, s.wi),
                    };
                    let pdfs = DirectPdfs {
                        bsdf: lit.map_or_else(|| v.bsdf.pdf(v.wo, s.wi), |(_, _, pdf)| pdf),
                        bsdf_reverse: self.light_pdf(v.bsdf, v.hit.point, v.wo, reverse),
                        // Several samples are one strategy of that many times the density.
                        direct: s.direct_pdf * samples as f32,
                        emission: self.emitters.emission_pdf_of(self.scene, number, &s, v.hit.point),
                        cos_here,
                        cos_light: s.cos_light,
                        delta: s.delta,
                    };
                    // Light reaches this vertex first: merging is no strategy here, and light
                    // tracing none either if it is the eye's first on a surface (the sum's first
                    // term there).
                    let camera = if v.length == 1 && !v.hit.is_in_medium() {
                        Partial { vcm: 0.0, ..v.partial }
                    } else {
                        v.partial
                    };
                    let weight = match v.along {
                        Some((sigma, t)) => {
                            let first = pdfs.direct * pdfs.cos_light / (pdfs.emission * pdfs.cos_here);
                            let d = if s.distance.is_finite() { s.distance } else { 0.0 };
                            mis::direct_along(f, &v.partial, beams::direct_share((first, d), sigma, t))
                        }
                        None => mis::direct(f, &camera, &pdfs, false),
                    };
                    l += v.throughput * value * s.contribution * (cos_here * weight / samples as f32);
                }
            } else if let Some(s) = lights.sample_light(number, pick, (self.scene, v.hit, &takes), wl, rng) {
                // Far lights and lights with a size: the camera's strategies only.
                let lit = lambertian.as_ref().and_then(|lambertian| lambertian.toward(s.wi));
                let value = lit.map_or_else(|| v.bsdf.eval(v.wo, s.wi), |(f, _, _)| f);
                // (A point a free flight picked on a beam's segment is not scattered from.)
                let weight = if s.pdf > 0.0 && v.along.is_none() {
                    power_heuristic(s.pdf, lit.map_or_else(|| v.bsdf.pdf(v.wo, s.wi), |(_, _, pdf)| pdf))
                } else {
                    1.0
                };
                let cos = lit.map_or_else(|| v.bsdf.cos(s.wi), |(_, cos, _)| cos);
                l += v.throughput * value * s.contribution * (cos * weight);
            }
        };
        if lights.samples_every_light() {
            for number in 0..lights.len() {
                if lights.direct_probability(number) > 0.0 {
                    one(number, 1.0, rng);
                }
            }
        } else if let Some((number, pick)) = lights.pick_for_direct(rng.uniform()) {
            one(number, pick, rng);
        }
        l
    }

    /// A connection between a camera vertex and a light vertex (`camera_merges`: merging is a
    /// strategy at the camera vertex).
    fn connect(
        &self,
        v: &CameraVertex,
        z: &LightVertex,
        f: &Factors,
        wl: &Wavelengths,
        camera_merges: bool,
        rng: &mut Rng,
    ) -> Spectrum {
        if v.length + z.length + 1 > self.max_length {
            return Spectrum::ZERO;
        }
        let to = z.hit.point - v.hit.point;
        let d2 = to.length_squared();
        if !(d2 > 0.0 && d2.is_finite()) {
            return Spectrum::ZERO;
        }
        let dir = to / d2.sqrt();
        let camera_f = v.bsdf.eval(v.wo, dir);
        if camera_f == Spectrum::ZERO {
            return Spectrum::ZERO;
        }
        let light_bsdf = self.vertex_bsdf(&z.hit, z.wo, wl);
        let light_f = light_bsdf.eval_in(z.wo, -dir, Transport::Importance);
        if light_f == Spectrum::ZERO {
            return Spectrum::ZERO;
        }
        let cos_camera = v.bsdf.cos(dir);
        let cos_light = light_bsdf.cos(dir);
        let pdfs = ConnectionPdfs {
            camera_to_light: v.bsdf.pdf(v.wo, dir) * cos_light / d2,
            camera_reverse: self.light_pdf(v.bsdf, v.hit.point, v.wo, v.bsdf.pdf_reverse(v.wo, dir)),
            light_to_camera: self.light_pdf(&light_bsdf, z.hit.point, -dir, light_bsdf.pdf(z.wo, -dir)) * cos_camera
                / d2,
            light_reverse: light_bsdf.pdf_reverse(z.wo, -dir),
        };
        // The camera vertex is smooth, so merging is no strategy at the light vertex.
        let weight = mis::connection(f, &v.partial, &z.partial, &pdfs, (camera_merges, false));
        let (ng_c, ng_l) = (v.hit.geometric_normal, z.hit.geometric_normal);
        let side_c = if ng_c.dot(dir) >= 0.0 { ng_c } else { -ng_c };
        let side_l = if ng_l.dot(dir) <= 0.0 { ng_l } else { -ng_l };
        if !self.scene.segment_clear(v.hit.point, side_c, z.hit.point, side_l) {
            return Spectrum::ZERO;
        }
        let g = cos_camera * cos_light / d2;
        // The media between the two (fog, or the inside of one rough glass) take their share.
        let inside = if self.scene.has_media() {
            self.scene.transmittance_towards(v.hit, dir, d2.sqrt(), wl, rng)
        } else {
            Spectrum::ONE
        };
        v.throughput
            * camera_f
            * light_f
            * z.throughput
            * inside
            * (g * weight * both_dispersed(v.dispersed, z.dispersed))
    }
}

impl Vcm<'_> {
    /// The lobes of a stored vertex seen from `wo`: a surface's BSDF, or the phase function of
    /// the medium a scattering point is in.
    pub(super) fn vertex_bsdf(&self, hit: &SurfaceHit, wo: Vec3, wl: &Wavelengths) -> Bsdf {
        if hit.is_in_medium() {
            Bsdf::phase(self.scene.medium(hit.media.back).phase.g, wo, wl)
        } else {
            Bsdf::at(self.scene, hit, wo, wl)
        }
    }
}

/// Both subpaths kept only the hero wavelength, so each scaled it by the number of wavelengths:
/// one of the factors goes.
pub(super) fn both_dispersed(a: bool, b: bool) -> f32 {
    if a && b {
        1.0 / SAMPLES as f32
    } else {
        1.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::{Control, NoProgress};

    /// Light subpaths walked together, and a tile's camera subpaths, make the image each walked
    /// alone makes, bit for bit, every subpath's vertices kept in order (for connections) and
    /// focus pixels' further samples included: a spot light through a glass ball onto a floor,
    /// its caustic in view.
    #[test]
    fn waves_make_the_image_single_walks_make() {
        let scene = crate::scene::build::spot_through_glass("");
        let cancel = std::sync::atomic::AtomicBool::new(false);
        let control = || Control {
            progress: &NoProgress,
            cancel: &cancel,
        };
        let settings = VcmSettings {
            focus_samples: 3,
            connections: true,
            ..VcmSettings::default()
        };
        let mut vcm = Vcm::new(&scene, settings, 40, 40, 5);
        assert!(vcm.prepare(control()));
        let focused = vcm.focus_pixels.iter().filter(|&&f| f).count();
        assert!(focused > 5, "{focused} focus pixels");
        // Each subpath's vertices, where camera paths find them (by `ends`), in index order.
        let wl = Wavelengths::Rgb;
        let count = vcm.pixels() as u64 * 2;
        let lists = [true, false].map(|waves| {
            vcm.waves = waves;
            let mut scratch = Scratch::default();
            let f = Factors::new(0.05, count as f32);
            vcm.light_paths((1, count), &f, &wl, true, &cancel, &mut scratch)
                .expect("not cancelled");
            let paths = scratch.paths;
            let subpaths: Vec<Vec<Vec3>> = paths
                .ends
                .windows(2)
                .map(|w| {
                    paths.vertices[w[0] as usize..w[1] as usize]
                        .iter()
                        .map(|v| v.hit.point)
                        .collect()
                })
                .collect();
            (subpaths, paths.merge_points, paths.splats, paths.rays)
        });
        assert_eq!(lists[0].0.len(), count as usize);
        assert!(
            lists[0].0.iter().filter(|v| !v.is_empty()).count() > 100,
            "subpaths with vertices"
        );
        assert!(
            lists[0].1.len() > 100 && lists[0].2.len() > 100,
            "merge points and splats"
        );
        assert_eq!(lists[0], lists[1]);
        let films = [true, false].map(|waves| {
            vcm.waves = waves;
            vcm.render_pass(1, control()).expect("not cancelled")
        });
        assert!(films[0].iter().any(|p| p.x > 0.0), "a lit image");
        assert_eq!(films[0], films[1]);
    }
}
