//! The multiple-importance weights of vertex connection and merging, computed as the paths
//! grow (Georgiev, "Implementing vertex connection and merging", 2012): each subpath carries
//! three running sums, from which every strategy's weight against all the others that could
//! have made the same full path follows in constant time.
//!
//! Densities are per unit area or solid angle as named; `mis` raises them to the heuristic's
//! power (the balance heuristic: merging and light tracing weigh their many samples fairly).
//! Russian roulette is left out of the densities on purpose: the weights of one path then
//! sum to exactly one across strategies, whatever each side's roulette did.
//!
//! Merging may be switched off at a vertex for a whole class of paths (the integrator does so
//! where the eye sees a caustic directly, so light tracing keeps its sharp focus): the
//! functions then take `merges = false` for that vertex, and every strategy of those paths
//! leaves the same term out, so their weights still sum to one.

/// The heuristic's power applied to a density (or a ratio of densities).
#[inline]
pub fn mis(x: f32) -> f32 {
    x
}

/// The strategies' constants of one pass.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factors {
    /// η = π r² · light paths: how many times likelier merging finds a light vertex than a
    /// connection makes it (0 when merging is off).
    pub merge: f32,
    /// 1 / η.
    pub connect: f32,
    /// Light paths per pass.
    pub light_paths: f32,
}

impl Factors {
    /// The constants for merging radius `radius` (0: no merging) and `light_paths` paths.
    pub fn new(radius: f32, light_paths: f32) -> Factors {
        let eta = std::f32::consts::PI * radius * radius * light_paths;
        Factors {
            merge: if eta > 0.0 { mis(eta) } else { 0.0 },
            connect: if eta > 0.0 { mis(1.0 / eta) } else { 0.0 },
            light_paths,
        }
    }
}

/// The running sums of one subpath at its last vertex (Georgiev's dVCM, dVC, dVM).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Partial {
    /// Weight of the strategies that make the last vertex by the other side's last step.
    pub vcm: f32,
    /// Weight of the connections further back.
    pub vc: f32,
    /// Weight of the merges further back.
    pub vm: f32,
}

impl Partial {
    /// A camera subpath leaving the eye in a direction of solid-angle density `camera_pdf`
    /// (per pixel sample).
    pub fn camera(factors: &Factors, camera_pdf: f32) -> Partial {
        Partial {
            vcm: mis(factors.light_paths / camera_pdf),
            vc: 0.0,
            vm: 0.0,
        }
    }

    /// A light subpath: emitted with density `emission_pdf` (position × direction, choice of
    /// light included) from a point that next-event estimation draws with area density
    /// `direct_pdf`, leaving at cosine `cos_light` (1 for a point light); `delta`: the light
    /// is a point.
    pub fn light(factors: &Factors, emission_pdf: f32, direct_pdf: f32, cos_light: f32, delta: bool) -> Partial {
        let vc = if delta { 0.0 } else { mis(cos_light / emission_pdf) };
        Partial {
            vcm: mis(direct_pdf / emission_pdf),
            vc,
            vm: vc * factors.connect,
        }
    }

    /// Arrival at the next vertex `distance_sq` away, at cosine `cos` to its normal.
    pub fn arrive(&mut self, distance_sq: f32, cos: f32) {
        self.vcm *= mis(distance_sq);
        let inv = 1.0 / mis(cos);
        self.vcm *= inv;
        self.vc *= inv;
        self.vm *= inv;
    }

    /// Scattering through a smooth lobe of density `pdf` towards a direction at cosine
    /// `cos_out`, whose reverse density is `reverse_pdf`; `merges`: merging is a strategy at
    /// this vertex.
    pub fn scatter(&mut self, factors: &Factors, pdf: f32, reverse_pdf: f32, cos_out: f32, merges: bool) {
        let g = mis(cos_out / pdf);
        let reverse = mis(reverse_pdf);
        let (merge, one) = if merges { (factors.merge, 1.0) } else { (0.0, 0.0) };
        let vc = g * (self.vc * reverse + self.vcm + merge);
        let vm = g * (self.vm * reverse + self.vcm * factors.connect + one);
        *self = Partial {
            vcm: mis(1.0 / pdf),
            vc,
            vm,
        };
    }

    /// Scattering through a delta lobe (mirror, glass) towards cosine `cos_out`: no strategy
    /// but following the path can make the next vertex.
    pub fn scatter_specular(&mut self, cos_out: f32) {
        self.vcm = 0.0;
        self.vc *= mis(cos_out);
        self.vm *= mis(cos_out);
    }
}

/// Weight of light tracing: light vertex `light` joined to the eye, whose camera would make
/// the point with area density `camera_pdf` per pixel sample; `reverse_pdf`: the density of the
/// camera path turning from the point towards the previous light vertex; `merges`: a camera
/// path could merge there.
pub fn light_tracing(factors: &Factors, light: &Partial, camera_pdf: f32, reverse_pdf: f32, merges: bool) -> f32 {
    let merge = if merges { factors.merge } else { 0.0 };
    let w_light = mis(camera_pdf / factors.light_paths) * (merge + light.vcm + light.vc * mis(reverse_pdf));
    1.0 / (1.0 + w_light)
}

/// Weight of a camera path that hits an emitter: next-event estimation would draw the point
/// with area density `direct_pdf`, emission would make the last segment with density
/// `emission_pdf` (position × direction).
pub fn emitter_hit(camera: &Partial, direct_pdf: f32, emission_pdf: f32) -> f32 {
    let w_camera = mis(direct_pdf) * camera.vcm + mis(emission_pdf) * camera.vc;
    1.0 / (1.0 + w_camera)
}

/// Densities of one next-event sample.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DirectPdfs {
    /// The BSDF's density towards the light.
    pub bsdf: f32,
    /// The BSDF's density back along the camera path, had it arrived from the light.
    pub bsdf_reverse: f32,
    /// Next-event estimation's solid-angle density (choice of light included).
    pub direct: f32,
    /// Emission's density of the point and of the direction to the shading point.
    pub emission: f32,
    /// Cosine at the shading point.
    pub cos_here: f32,
    /// Cosine at the light (1 for a point).
    pub cos_light: f32,
    /// The light is a point: no BSDF sample hits it.
    pub delta: bool,
}

/// Weight of next-event estimation at a camera vertex (`merges`: merging is a strategy there).
pub fn direct(factors: &Factors, camera: &Partial, p: &DirectPdfs, merges: bool) -> f32 {
    let merge = if merges { factors.merge } else { 0.0 };
    let w_light = if p.delta { 0.0 } else { mis(p.bsdf / p.direct) };
    let w_camera = mis(p.emission * p.cos_here / (p.direct * p.cos_light))
        * (merge + camera.vcm + camera.vc * mis(p.bsdf_reverse));
    1.0 / (w_light + 1.0 + w_camera)
}

/// Densities of one connection between a camera vertex and a light vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConnectionPdfs {
    /// The camera vertex's BSDF making the light vertex (area density).
    pub camera_to_light: f32,
    /// The camera vertex's BSDF turning back along the camera path (solid angle).
    pub camera_reverse: f32,
    /// The light vertex's BSDF making the camera vertex (area density).
    pub light_to_camera: f32,
    /// The light vertex's BSDF turning back along the light path (solid angle).
    pub light_reverse: f32,
}

/// Weight of a connection between two subpaths (`camera_merges`, `light_merges`: merging is a
/// strategy at the camera vertex, at the light vertex).
pub fn connection(
    factors: &Factors,
    camera: &Partial,
    light: &Partial,
    p: &ConnectionPdfs,
    (camera_merges, light_merges): (bool, bool),
) -> f32 {
    let camera_merge = if camera_merges { factors.merge } else { 0.0 };
    let light_merge = if light_merges { factors.merge } else { 0.0 };
    let w_light = mis(p.camera_to_light) * (light_merge + light.vcm + light.vc * mis(p.light_reverse));
    let w_camera = mis(p.light_to_camera) * (camera_merge + camera.vcm + camera.vc * mis(p.camera_reverse));
    1.0 / (w_light + 1.0 + w_camera)
}

/// Weight of merging a camera vertex with a light vertex found within the radius: the camera
/// BSDF draws the light's arrival direction with density `camera_pdf`, and the camera path's
/// arrival direction from it with `camera_reverse`.
pub fn merge(factors: &Factors, camera: &Partial, light: &Partial, camera_pdf: f32, camera_reverse: f32) -> f32 {
    let w_light = light.vcm * factors.connect + light.vm * mis(camera_pdf);
    let w_camera = camera.vcm * factors.connect + camera.vm * mis(camera_reverse);
    1.0 / (w_light + 1.0 + w_camera)
}

/// Weight of a beam query's gather of a light vertex in a medium where the camera path (its
/// sums `camera`, arrived there with a cosine of one) has not scattered off a smooth lobe
/// before (see [`super::beams`]): its rivals are light tracing and, for light reaching the
/// point first, next-event estimation where a free flight cuts the segment, as camera paths
/// never stop there;
/// `direct`: next-event estimation along the segment against the light subpath (see
/// [`super::beams::direct_share`]).
pub fn beam(factors: &Factors, camera: &Partial, direct: f32) -> f32 {
    1.0 / (1.0 + (camera.vcm + mis(direct)) * factors.connect)
}

/// Weight of next-event estimation at a point a free flight chose on such a segment, whose
/// light subpath would make the point `direct` times less likely (the sums' first term at the
/// light's side, with both distance densities): its rivals are the beam query and light
/// tracing.
pub fn direct_along(factors: &Factors, camera: &Partial, direct: f32) -> f32 {
    1.0 / (1.0 + (factors.merge + camera.vcm) / mis(direct))
}

/// Weight of light tracing a light vertex in such a medium, whose camera would make the point
/// with density `camera_pdf` per unit volume (distances' densities left out) per pixel sample:
/// its rivals are the beam query and, for light reaching it first, next-event estimation
/// (`direct`, as for [`beam`]).
pub fn light_tracing_beside_beams(factors: &Factors, camera_pdf: f32, direct: f32) -> f32 {
    1.0 / (1.0 + mis(camera_pdf / factors.light_paths) * (factors.merge + mis(direct)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// A path x0 (a point on an area light), x1 … xn (smooth surfaces), then the eye, with
    /// random geometry and densities. Every strategy's weight from the running sums must equal
    /// its density over the sum of all strategies' densities (the balance heuristic written
    /// out), and the weights must sum to one — also when merging is left out at some vertices.
    #[test]
    fn weights_of_all_strategies_sum_to_one() {
        for (case, n) in [1usize, 2, 3, 5, 7].iter().cycle().take(80).enumerate() {
            let n = *n;
            let mut rng = Rng::new(17, case as u64);
            // Whether merging is a strategy at each vertex: all on in every fourth case, else
            // at random.
            let merges: Vec<bool> = (0..=n).map(|_| case % 4 == 0 || rng.uniform() < 0.5).collect();
            // Connections between the subpaths' inner vertices: off in every third case.
            let connects = case % 3 != 1;
            // Light tracing of direct light (n = 1): off in four cases of five.
            let traces = n > 1 || case % 5 == 0;
            let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.uniform();
            // d2[i]: x_i to x_{i+1}; de2: x_n to the eye.
            let d2: Vec<f32> = (0..n).map(|_| r(0.05, 4.0)).collect();
            let de2 = r(1.0, 9.0);
            // Cosines at x_i towards x_{i+1} (forward; the eye for x_n) and towards x_{i-1}.
            let cf: Vec<f32> = (0..=n).map(|_| r(0.05, 1.0)).collect();
            let cb: Vec<f32> = (0..=n).map(|_| r(0.05, 1.0)).collect();
            // Solid-angle densities: light side at x_i towards x_{i+1}, camera side towards x_{i-1}.
            let pl: Vec<f32> = (0..=n).map(|_| r(0.05, 3.0)).collect();
            let pc: Vec<f32> = (0..=n).map(|_| r(0.05, 3.0)).collect();
            let (pos_pdf, dir_pdf, nee_pdf, camera_w) = (r(0.5, 5.0), r(0.05, 1.0), r(0.5, 5.0), r(0.5, 50.0));
            let (radius, light_paths) = (r(0.001, 0.05), r(100.0, 10_000.0));
            let f = Factors::new(radius, light_paths);
            let eta = std::f32::consts::PI * radius * radius * light_paths;

            // Area densities of each vertex made by the light side and by the camera side.
            let mut al = vec![0.0f64; n + 1];
            al[0] = pos_pdf as f64;
            for i in 1..=n {
                let w = if i == 1 { dir_pdf } else { pl[i - 1] };
                al[i] = (w * cb[i] / d2[i - 1]) as f64;
            }
            let mut ac = vec![0.0f64; n + 1];
            ac[n] = (camera_w * cf[n] / de2) as f64;
            for i in (1..=n).rev() {
                ac[i - 1] = (pc[i] * cf[i - 1] / d2[i - 1]) as f64;
            }
            let light_prod = |s: usize| al[..s].iter().product::<f64>();
            let camera_prod = |s: usize| ac[s..].iter().product::<f64>();
            // Written out: s light vertices joined to n + 1 − s camera vertices.
            let mut explicit = Vec::new();
            explicit.push(("hit", camera_prod(0)));
            explicit.push(("direct", nee_pdf as f64 * camera_prod(1)));
            for s in 2..=n {
                if connects {
                    explicit.push(("connect", light_prod(s) * camera_prod(s)));
                }
            }
            if traces {
                explicit.push(("trace", light_prod(n + 1) * light_paths as f64));
            }
            for j in (1..=n).filter(|&j| merges[j]) {
                explicit.push(("merge", eta as f64 * light_prod(j + 1) * camera_prod(j)));
            }
            let total: f64 = explicit.iter().map(|e| e.1).sum();

            // The running sums.
            let emission = pos_pdf * dir_pdf;
            let light_at = |j: usize| {
                let mut p = Partial::light(&f, emission, nee_pdf, cf[0], false);
                p.arrive(d2[0], cb[1]);
                for i in 1..j {
                    p.scatter(&f, pl[i], pc[i], cf[i], merges[i]);
                    p.arrive(d2[i], cb[i + 1]);
                    if !connects {
                        p.vcm = 0.0;
                    }
                }
                p
            };
            let camera_at = |j: usize| {
                let mut p = Partial::camera(&f, camera_w);
                p.arrive(de2, cf[n]);
                if !traces {
                    p.vcm = 0.0;
                }
                for i in ((j + 1)..=n).rev() {
                    p.scatter(&f, pc[i], pl[i], cb[i], merges[i]);
                    p.arrive(d2[i - 1], cf[i - 1]);
                    if !connects {
                        p.vcm = 0.0;
                    }
                }
                p
            };
            let mut recursive = Vec::new();
            let mut hit = camera_at(1);
            hit.scatter(&f, pc[1], pl[1], cb[1], merges[1]);
            hit.arrive(d2[0], cf[0]);
            recursive.push(emitter_hit(&hit, nee_pdf, emission));
            let direct_pdfs = DirectPdfs {
                bsdf: pc[1],
                bsdf_reverse: pl[1],
                direct: nee_pdf * d2[0] / cf[0],
                emission,
                cos_here: cb[1],
                cos_light: cf[0],
                delta: false,
            };
            recursive.push(direct(&f, &camera_at(1), &direct_pdfs, merges[1]));
            for s in (2..=n).filter(|_| connects) {
                let pdfs = ConnectionPdfs {
                    camera_to_light: pc[s] * cf[s - 1] / d2[s - 1],
                    camera_reverse: pl[s],
                    light_to_camera: pl[s - 1] * cb[s] / d2[s - 1],
                    light_reverse: pc[s - 1],
                };
                let flags = (merges[s], merges[s - 1]);
                recursive.push(connection(&f, &camera_at(s), &light_at(s - 1), &pdfs, flags));
            }
            if traces {
                recursive.push(light_tracing(
                    &f,
                    &light_at(n),
                    camera_w * cf[n] / de2,
                    pc[n],
                    merges[n],
                ));
            }
            for j in (1..=n).filter(|&j| merges[j]) {
                recursive.push(merge(&f, &camera_at(j), &light_at(j), pc[j], pl[j]));
            }

            assert_eq!(recursive.len(), explicit.len());
            let sum: f64 = recursive.iter().map(|&w| w as f64).sum();
            assert!((sum - 1.0).abs() < 1e-3, "case {case} (n = {n}): weights sum to {sum}");
            for (w, (name, p)) in recursive.iter().zip(&explicit) {
                let expected = p / total;
                assert!(
                    (*w as f64 - expected).abs() < 1e-3 * expected.max(1e-3),
                    "case {case}, {name}: {w} against {expected}"
                );
            }
        }
    }

    /// In a medium where camera paths pass until their first smooth vertex, a path eye → y (a
    /// scattering point, t from the eye) → light (d from y) is made by light tracing, the beam
    /// query and next-event estimation at a point a free flight picked: the three weights, each
    /// from its own side's sums, are the balance heuristic's and sum to one; with light that
    /// bounced before y, the first two alone.
    #[test]
    fn beam_strategies_sum_to_one() {
        let mut rng = Rng::new(23, 0);
        for case in 0..200 {
            let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.uniform();
            let (camera_w, t, d, sigma) = (r(0.5, 50.0), r(0.05, 4.0), r(0.05, 4.0), r(0.01, 3.0));
            let (pos_pdf, dir_pdf, nee_pdf, cos_light) = (r(0.5, 5.0), r(0.05, 1.0), r(0.5, 5.0), r(0.05, 1.0));
            let f = Factors::new(r(0.001, 0.05), r(100.0, 10_000.0));
            let eta = f.merge as f64;
            // Each strategy's density (per unit volume at y, the common camera direction left out).
            let (t, d) = (t as f64, d as f64);
            let flight = |x: f64| sigma as f64 * (-(sigma as f64) * x).exp();
            // The light's point by area, its direction by solid angle; next-event estimation's
            // point by area.
            let light_y = (pos_pdf * dir_pdf) as f64 / (d * d) * flight(d);
            let camera_y = camera_w as f64 / (t * t);
            let traced = light_y * f.light_paths as f64;
            let gathered = light_y * camera_y * eta;
            let nee = camera_y * flight(t) * nee_pdf as f64;
            let total = traced + gathered + nee;

            let mut camera = Partial::camera(&f, camera_w);
            camera.arrive((t * t) as f32, 1.0);
            let mut light = Partial::light(&f, pos_pdf * dir_pdf, nee_pdf, cos_light, false);
            light.arrive((d * d) as f32, 1.0);
            let first = (light.vcm, d as f32);
            let share = super::super::beams::direct_share(first, sigma, t as f32);
            let w_traced = light_tracing_beside_beams(&f, camera_w / (t * t) as f32, share);
            let w_beam = beam(&f, &camera, share);
            // Next-event estimation's own side: its solid-angle density and the light's cosine.
            let direct_w = nee_pdf * (d * d) as f32 / cos_light;
            let from_eye = (direct_w * cos_light / (pos_pdf * dir_pdf), d as f32);
            let w_nee = direct_along(
                &f,
                &camera,
                super::super::beams::direct_share(from_eye, sigma, t as f32),
            );
            for (name, w, p) in [
                ("traced", w_traced, traced),
                ("beam", w_beam, gathered),
                ("nee", w_nee, nee),
            ] {
                let expected = p / total;
                assert!(
                    (w as f64 - expected).abs() < 1e-3 * expected.max(1e-3),
                    "case {case}, {name}: {w} against {expected}"
                );
            }
            // Light that bounced before y: light tracing and the beam query only.
            let (w_traced, w_beam) = (
                light_tracing_beside_beams(&f, camera_w / (t * t) as f32, 0.0),
                beam(&f, &camera, 0.0),
            );
            assert!(((w_traced + w_beam) as f64 - 1.0).abs() < 1e-4, "case {case}");
            assert!(
                (w_beam as f64 - gathered / (gathered + traced)).abs() < 1e-3,
                "case {case}"
            );
        }
    }
}
