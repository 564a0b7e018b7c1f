//! Merging: a camera vertex gathers the pass's light vertices within the merging radius
//! from the hash grid ([`HashGrid`]), as progressive photon mapping does.

use super::*;

impl<'a> Vcm<'a> {
    /// Merging: the light vertices within the radius of a camera vertex, as a density estimate.
    pub(super) fn merge(&self, v: &CameraVertex, pass: &PassData, work: &mut CameraWork) -> Spectrum {
        let mut sum = Spectrum::ZERO;
        let focused = v.length == 1 && self.focus.contains(v.hit.point);
        let ng = v.hit.geometric_normal;
        let f = &pass.factors;
        // Most camera vertices are Lambertian: their f and reverse density are the same for
        // every candidate.
        let lambertian = v.bsdf.lambertian(v.wo);
        // A light subpath's aimed cones do not depend on where its light came from.
        let (plain_share, aimed) = match (&self.bounce_aim, &lambertian) {
            (Some(aim), Some(_)) => (1.0 - aim.share(), aim.share() * aim.pdf(v.hit.point, v.wo)),
            _ => (1.0, 0.0),
        };
        pass.grid.query(v.hit.point, pass.radius, |slot| {
            work.candidates += 1;
            let z = &pass.merge_vertices[slot];
            if v.length + z.length > self.max_length || (focused && z.direct_caustic) {
                return;
            }
            // Light on another face (a wall's far side, a corner) is not light here.
            if z.normal.dot(ng) < 0.7 {
                return;
            }
            let (value, pdf, reverse) = match &lambertian {
                Some(l) => match l.pdf(z.wo) {
                    Some(pdf) => (l.f, pdf, l.reverse),
                    None => return,
                },
                None => {
                    let value = v.bsdf.eval(v.wo, z.wo);
                    if value == Spectrum::ZERO {
                        return;
                    }
                    (value, v.bsdf.pdf(v.wo, z.wo), v.bsdf.pdf_reverse(v.wo, z.wo))
                }
            };
            let reverse = plain_share * reverse + aimed;
            let weight = mis::merge(f, &v.partial, &z.partial, pdf, reverse);
            sum += value * z.throughput * (weight * both_dispersed(v.dispersed, z.dispersed));
        });
        v.throughput * sum / (std::f32::consts::PI * pass.radius * pass.radius * f.light_paths)
    }
}
