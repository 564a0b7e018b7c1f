//! Light subpaths: traced from the lights' emission ([`Emitters`]), each smooth vertex stored
//! for connections and merging and joined to the eye (light tracing), a share of the bounces
//! off Lambertian surfaces aimed at the mirrors and glass.

use super::*;
use crate::photon::light_walk::{light_waves, walk_together, LightPath, LightWalk, MediumArrival, Walker};

/// Mixed into the seed of the streams joins to the eye draw from.
const EYE_SEED: u64 = 0x6579_6573_7663_6d21;

impl<'a> Vcm<'a> {
    /// Starts light subpath `index` of pass `pass`: its walk stores its smooth vertices into
    /// `out` and joins each to the eye (the pilot run, `to_eye` false, only stores).
    #[inline]
    fn start_light<'v>(
        &'v self,
        (pass, index): (u64, u64),
        (f, wl): (&'v Factors, &'v Wavelengths),
        to_eye: bool,
        out: &'v mut LightPaths,
    ) -> Option<LightPath<Subpath<'v, 'a>>> {
        let scene = self.scene;
        let mut rng = Rng::new(self.seed ^ LIGHT_SEED, (pass << 40) ^ index);
        let emission = self.emitters.emit(scene, wl, &mut rng)?;
        let surfaces = self.max_length.saturating_sub(1);
        let carried = (emission.throughput, scene.light_medium(emission.light));
        Some(Walker {
            walk: LightWalk::new(scene, emission.ray, carried, surfaces),
            wl: *wl,
            rng,
            visitor: Subpath {
                vcm: self,
                f,
                wl,
                start: emission.throughput.max_element(),
                previous: emission.ray.origin,
                emission,
                to_eye,
                connected: self.settings.connections && index < self.pixels() as u64,
                out,
                partial: Partial::default(),
                all_specular: true,
                eye_rng: Rng::new(self.seed ^ EYE_SEED, (pass << 40) ^ index),
            },
        })
    }

    /// Traces the light subpaths `indices` of pass `pass` into `out`, in index order, a wave at
    /// a time; in waves of more than one path each into its own lists first.
    fn trace_lights(
        &self,
        (pass, indices): (u64, std::ops::Range<u64>),
        fw: (&Factors, &Wavelengths),
        to_eye: bool,
        out: &mut LightPaths,
    ) {
        // The lists of a wave's paths, reused by the batch's waves (kept only for the batch:
        // kept for the pass, every batch's added half again to vcm's memory).
        let mut own: Vec<LightPaths> = Vec::new();
        for wave in light_waves(self.waves, indices) {
            if wave.end - wave.start == 1 {
                // One path a wave: straight into the batch's lists.
                let mut path = self.start_light((pass, wave.start), fw, to_eye, out);
                walk_together(self.scene, path.as_mut_slice());
                if let Some(path) = path.as_mut() {
                    path.visitor.out.rays += path.walk.rays();
                }
                out.ends.push(out.vertices.len() as u32);
                continue;
            }
            own.resize_with(wave.clone().count(), LightPaths::default);
            let mut paths: Vec<_> = wave
                .zip(own.iter_mut())
                .filter_map(|(i, path_out)| self.start_light((pass, i), fw, to_eye, path_out))
                .collect();
            walk_together(self.scene, &mut paths);
            for path in paths {
                path.visitor.out.rays += path.walk.rays();
            }
            for path_out in own.iter_mut() {
                path_out.ends.push(path_out.vertices.len() as u32);
                out.append(path_out);
                path_out.clear();
            }
        }
    }

    /// Light tracing: the light vertex seen by the eye, splatted onto its pixel.
    /// `direct`: for light reaching a scattering point first, what [`beams::direct_share`] reads.
    fn trace_to_eye(
        &self,
        v: &LightVertex,
        direct: (f32, f32),
        bsdf: &Bsdf,
        (f, wl): (&Factors, &Wavelengths),
        rng: &mut Rng,
        splats: &mut Vec<(u32, Vec3)>,
    ) {
        // Direct light on surfaces is the camera strategies' (see the module's notes); in a
        // medium, where a camera ray rarely stops inside a thin beam, light tracing shares it.
        if (v.length == 1 && !v.hit.is_in_medium()) || v.length + 1 > self.max_length {
            return;
        }
        let Some(s) = self.sensor.sample(v.hit.point) else {
            return;
        };
        let value = bsdf.eval_in(v.wo, s.to_eye, Transport::Importance);
        if value == Spectrum::ZERO {
            return;
        }
        let (ns, ng) = (v.hit.shading_normal, v.hit.geometric_normal);
        let wo_ng = v.wo.dot(ng).abs();
        let medium = bsdf.is_phase();
        if (wo_ng <= 0.0 && !medium) || !self.scene.unoccluded(&v.hit, s.to_eye, s.distance) {
            return;
        }
        let inv_d2 = 1.0 / (s.distance * s.distance);
        // The adjoint BSDF's shading-normal correction, as in light tracing (none in a medium).
        let cos = if medium {
            1.0
        } else {
            s.to_eye.dot(ng).abs() * v.wo.dot(ns).abs() / wo_ng
        };
        let camera_pdf = s.importance * bsdf.cos(s.to_eye) * inv_d2;
        let weight = if medium && self.merges_in_medium(v.hit.media.back) {
            let sigma = self.scene.medium(v.hit.media.back).majorant();
            let direct = beams::direct_share(direct, sigma, s.distance);
            mis::light_tracing_beside_beams(f, camera_pdf, direct)
        } else {
            mis::light_tracing(
                f,
                &v.partial,
                camera_pdf,
                bsdf.pdf_reverse(v.wo, s.to_eye),
                v.length > 1 && !medium && !(v.direct_caustic && self.focus.contains(v.hit.point)),
            )
        };
        let kept = if self.scene.has_media() {
            self.scene.transmittance_towards(&v.hit, s.to_eye, s.distance, wl, rng)
        } else {
            Spectrum::ONE
        };
        let splat = v.throughput * value * kept * (cos * inv_d2 * s.importance * weight / f.light_paths);
        let rgb = wl.to_rgb(splat);
        if rgb.is_finite() {
            splats.push((s.pixel as u32, rgb));
        }
    }

    /// The first `count` light subpaths of pass `pass`, traced in batches in parallel and kept
    /// in index order in `scratch.paths` (emptied first; `scratch.batches` lends the batches'
    /// memory). `None` when `cancel` is set. `to_eye`: joined to the eye (a pilot that only
    /// looks for the focus does not).
    pub(super) fn light_paths(
        &self,
        (pass, count): (u64, u64),
        f: &Factors,
        wl: &Wavelengths,
        to_eye: bool,
        cancel: &AtomicBool,
        scratch: &mut Scratch,
    ) -> Option<()> {
        let batch_count = count.div_ceil(BATCH) as usize;
        let batches = &mut scratch.batches;
        batches.resize_with(batches.len().max(batch_count), LightPaths::default);
        let complete = batches[..batch_count].par_iter_mut().enumerate().all(|(b, out)| {
            if cancel.load(Ordering::Relaxed) {
                return false;
            }
            out.clear();
            let b = b as u64;
            let indices = b * BATCH..((b + 1) * BATCH).min(count);
            self.trace_lights((pass, indices), (f, wl), to_eye, out);
            true
        });
        if !complete {
            return None;
        }
        let all = &mut scratch.paths;
        all.clear();
        all.ends.push(0);
        for batch in &batches[..batch_count] {
            all.append(batch);
        }
        Some(())
    }

    /// The density with which a light subpath leaves a vertex at `point`, with `bsdf`, in `dir`
    /// where the BSDF alone draws it with density `plain`: on a Lambertian surface, the mixture
    /// with the cones aimed at mirrors and glass ([`BOUNCE_AIM_SHARE`]).
    pub(super) fn light_pdf(&self, bsdf: &Bsdf, point: Vec3, dir: Vec3, plain: f32) -> f32 {
        match &self.bounce_aim {
            Some(aim) if bsdf.is_lambertian() => (1.0 - aim.share()) * plain + aim.share() * aim.pdf(point, dir),
            _ => plain,
        }
    }
}

/// One light subpath on its walk: its MIS sums so far, and where its vertices go.
struct Subpath<'v, 'a> {
    vcm: &'v Vcm<'a>,
    f: &'v Factors,
    wl: &'v Wavelengths,
    emission: Emission,
    /// Joined to the eye (light tracing): not in the pilot that only stores.
    to_eye: bool,
    /// Its vertices are kept for a pixel's connections.
    connected: bool,
    out: &'v mut LightPaths,
    partial: Partial,
    /// The vertex before (the light's point at first).
    previous: Vec3,
    /// The throughput's largest channel as it left the light (the roulette's reference).
    start: f32,
    /// Only mirrors and glass so far.
    all_specular: bool,
    /// What joins to the eye draw from (the transmittance of a density grid).
    eye_rng: Rng,
}

impl LightVisitor for Subpath<'_, '_> {
    // A scattering point is a smooth vertex whose lobes are the phase function: stored for
    // connections and joined to the eye, but not merged (see the camera side).
    fn visit_medium(&mut self, at: &MediumArrival) -> bool {
        let bsdf = Bsdf::phase(at.phase.g, at.wo, self.wl);
        self.visit(&at.as_light_arrival(&bsdf))
    }

    fn bounce_medium(&mut self, at: &MediumArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        let bsdf = Bsdf::phase(at.phase.g, at.wo, self.wl);
        self.bounce(&at.as_light_arrival(&bsdf), rng)
    }

    fn visit(&mut self, at: &LightArrival) -> bool {
        let (vcm, f, emission) = (self.vcm, self.f, &self.emission);
        let (hit, wo, bsdf, length) = (*at.hit, at.wo, at.bsdf, at.length);
        if length == 1 {
            // Next-event estimation's density of the light point depends on where it is
            // seen from (a sphere is sampled by its cone).
            let direct = vcm.emitters.direct_pdf(vcm.scene, emission, hit.point);
            self.partial = Partial::light(f, emission.emission_pdf, direct, emission.cos, emission.delta);
        }
        // A far light's densities are across its beam: no distance to its first vertex.
        let d2 = if length == 1 && emission.far {
            1.0
        } else {
            (hit.point - self.previous).length_squared()
        };
        // A far light's distance is none: its light starts at the scene's edge.
        let from_light = if emission.far { 0.0 } else { d2.sqrt() };
        self.previous = hit.point;
        let partial = &mut self.partial;
        partial.arrive(d2, bsdf.cos(wo));
        if !vcm.settings.connections && length > 1 {
            // The sum's first term stands for a connection that makes this vertex.
            partial.vcm = 0.0;
        }
        let direct_caustic = length > 1 && self.all_specular;
        let direct = if length == 1 && hit.is_in_medium() {
            (partial.vcm, from_light)
        } else {
            (0.0, 0.0)
        };
        if bsdf.is_smooth() {
            let vertex = LightVertex {
                hit,
                wo,
                throughput: at.throughput,
                partial: *partial,
                length,
                dispersed: at.dispersed,
                direct_caustic,
            };
            if self.to_eye {
                // Direct light is not traced to the eye (see trace_to_eye).
                self.out.rays += u64::from(length > 1);
                vcm.trace_to_eye(
                    &vertex,
                    direct,
                    bsdf,
                    (f, self.wl),
                    &mut self.eye_rng,
                    &mut self.out.splats,
                );
            }
            // Light reaching a surface first is never merged (see the module's notes); in a
            // medium camera rays gather all of it along their way ([`super::beams`]).
            if hit.is_in_medium() {
                if vcm.merges_in_medium(hit.media.back) {
                    self.out.volume_vertices.push(VolumeVertex {
                        point: hit.point,
                        wo,
                        throughput: at.throughput,
                        direct,
                        medium: hit.media.back,
                        length,
                        dispersed: at.dispersed,
                    });
                }
            } else if length > 1 {
                self.out.merge_points.push(hit.point);
                self.out.merge_vertices.push(MergeVertex {
                    wo,
                    normal: hit.geometric_normal,
                    throughput: at.throughput,
                    partial: *partial,
                    length,
                    dispersed: at.dispersed,
                    direct_caustic,
                });
            }
            if self.connected {
                self.out.vertices.push(vertex);
            }
        }
        self.all_specular &= !bsdf.is_smooth();
        // A further vertex must still reach the eye within the longest path.
        length + 2 <= vcm.max_length
    }

    fn bounce(&mut self, at: &LightArrival, rng: &mut Rng) -> Option<(BsdfSample, Roulette)> {
        let (bsdf, wo) = (at.bsdf, at.wo);
        let aim = self.vcm.bounce_aim.as_ref().filter(|_| bsdf.is_lambertian());
        let (sample, towards_target) = light_bounce(bsdf, at.hit.point, wo, aim, rng)?;
        let cos_out = bsdf.cos(sample.wi);
        if sample.specular {
            self.partial.scatter_specular(cos_out);
        } else {
            // A light vertex with a smooth vertex after it is never the camera path's first
            // smooth one: no merging here.
            let reverse = bsdf.pdf_reverse(wo, sample.wi);
            self.partial.scatter(self.f, sample.pdf, reverse, cos_out, false);
        }
        // Flux, as the photon tracer carries it (without Veach's correction a caustic
        // through smooth-shaded glass came out 1.7% brighter than the photon tracer's),
        // the roulette keeping the subpath's power near its start; a bounce aimed at a
        // mirror or glass goes on with the little it carries (the point of aiming it), and a
        // diffuse bounce after it brings the power back or ends the subpath.
        let roulette = Roulette::TowardsStart {
            start: self.start,
            aimed: towards_target,
        };
        Some((sample, roulette))
    }
}

/// A light subpath's next direction at a surface with `bsdf` seen from `wo`: from the BSDF, or
/// with `aim` from the mixture of the BSDF and the cones towards the mirrors and glass (its
/// weight and density the mixture's). Also whether the direction lies in an aimed cone.
fn light_bounce(bsdf: &Bsdf, point: Vec3, wo: Vec3, aim: Option<&Aim>, rng: &mut Rng) -> Option<(BsdfSample, bool)> {
    let Some(aim) = aim else {
        return bsdf
            .sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance)
            .map(|s| (s, false));
    };
    let wi = if rng.uniform() < aim.share() {
        aim.sample(point, rng.uniform(), rng.uniform2())?
    } else {
        bsdf.sample(wo, rng.uniform(), rng.uniform2(), Transport::Importance)?
            .wi
    };
    let aimed = aim.pdf(point, wi);
    let pdf = (1.0 - aim.share()) * bsdf.pdf(wo, wi) + aim.share() * aimed;
    let value = bsdf.eval_in(wo, wi, Transport::Importance);
    if pdf.is_nan() || pdf <= 0.0 || value == Spectrum::ZERO {
        return None;
    }
    let sample = BsdfSample {
        wi,
        weight: value * (bsdf.normal().dot(wi).abs() / pdf),
        pdf,
        specular: false,
        transmitted: false,
        dispersive: false,
    };
    Some((sample, aimed > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::light::aim::Target;
    use crate::material::{Lobes, SurfaceParams};

    /// A light subpath's bounce off a Lambertian surface with a share aimed at a sphere: every
    /// weight is f·cos over the mixture's density, the mean weight is the albedo, and the light
    /// sent into the sphere's cone is the same as without aiming, carried by many more samples.
    #[test]
    fn aimed_bounces_carry_the_bsdfs_light() {
        let n = Vec3::Z;
        let wo = Vec3::new(0.3, -0.4, 0.866).normalize();
        let params = SurfaceParams {
            diffuse: Vec3::splat(0.7),
            ..SurfaceParams::default()
        };
        let bsdf = Bsdf::new(&Lobes::new(&params), n, n, wo, &Wavelengths::Rgb, None, None);
        assert!(bsdf.is_lambertian());
        let point = Vec3::ZERO;
        let target = Target {
            center: Vec3::new(1.0, 0.5, 0.8),
            radius: 0.3,
        };
        let aim = Aim::new(&[target], 0.3).unwrap();
        let (axis, cos_max) = target.cone_from(point);
        let count = 400_000;
        // (mean weight, mean weight into the cone, share of samples into the cone)
        let run = |aim: Option<&Aim>, seed: u64| {
            let mut rng = Rng::new(seed, 0);
            let (mut all, mut into, mut hits) = (0.0f64, 0.0f64, 0u32);
            for _ in 0..count {
                let Some((s, towards)) = light_bounce(&bsdf, point, wo, aim, &mut rng) else {
                    continue;
                };
                let inside = s.wi.dot(axis) >= cos_max;
                assert_eq!(towards, aim.is_some() && inside, "{s:?}");
                let plain = bsdf.pdf(wo, s.wi);
                let pdf = aim.map_or(plain, |a| (1.0 - a.share()) * plain + a.share() * a.pdf(point, s.wi));
                assert!((s.pdf - pdf).abs() <= 1e-5 * pdf, "{} against {pdf}", s.pdf);
                let expected = bsdf.eval(wo, s.wi) * (s.wi.z / pdf);
                assert!((s.weight - expected).length() <= 1e-4 * expected.length(), "{s:?}");
                all += s.weight.x as f64;
                if inside {
                    into += s.weight.x as f64;
                    hits += 1;
                }
            }
            (all / count as f64, into / count as f64, hits as f64 / count as f64)
        };
        let (plain_all, plain_into, plain_hits) = run(None, 1);
        let (aimed_all, aimed_into, aimed_hits) = run(Some(&aim), 2);
        assert!((plain_all - 0.7).abs() < 0.005, "{plain_all}");
        assert!((aimed_all - 0.7).abs() < 0.005, "{aimed_all}");
        assert!(
            (aimed_into / plain_into - 1.0).abs() < 0.02,
            "into the cone: aimed {aimed_into} against {plain_into}"
        );
        assert!(aimed_hits > 5.0 * plain_hits, "{aimed_hits} against {plain_hits}");
    }
}
