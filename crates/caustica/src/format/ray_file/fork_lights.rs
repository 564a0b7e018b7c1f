//! Spot and area lights as the course forks spell them, for both readers: each reader reads the
//! values, these builders check them and turn them into the description's lights.
//!
//! Spot-light cones, by the fork that wrote them:
//! - `size` (the full cone angle, degrees) and `blend` (0–1): HKUST 2019 (danvim/COMP4411-Trace);
//!   lit fully within size·(1 − blend)/2 of the axis, fading smoothly to dark at size/2;
//! - `angle` (the half-angle, radians), a hard edge, and `central_direction`: HKUST 2017
//!   (snowboat/RayTracingS17);
//! - `cone_angle` and `penumbra` (degrees) with `target` and `cutoff_distance`: an HKUST team
//!   fork (COMP4411-Team/Trace); dark beyond `cone_angle`, fading over `penumbra` inside it;
//! - `inner` and `outer` (half-angles, degrees): HKUST 2020 (Alsctiho/Comp4411-Trace), and
//!   caustica's own spelling; `exponent` adds a cos^e falloff.
//!
//! Warn lights, spot lights whose brightness falls off as cos^p of the angle to their axis
//! (Warn 1983) over the whole half-space in front of them:
//! - `warn_model_light { central_direction; specular_exponent; xflapmin … zflapmax; }`: HKUST
//!   2017 (snowboat/RayTracingS17);
//! - `warn_light { normal; p; xmin … zmax; cutoff_distance; }`: an HKUST team fork
//!   (COMP4411-Team/Trace);
//! - `warn_light { direction; size; type; }`: HKUST 2019 (danvim/COMP4411-Trace), a beam of
//!   radius `size` at unit distance whose cross-section `type` picks (read as a round beam).
//!
//! Flaps (a box the light is confined to) are not modelled; a warning says so.
//!
//! Area lights: `light_radius` (UT 2018, chipbuster/p2-raytracer) or `bottom_radius` (UT 2019,
//! michaelasper/ray-tracer) makes a point light a ball of that radius; `u` and `v` (edge vectors
//! from the corner `position`) make a parallelogram (COMP4411-Team/Trace).

use super::ast::{LightDesc, Span};
use crate::description::SoftShapeDesc;
use crate::ParseError;
use glam::Vec3;

/// Fields of `spot_light`, in any spelling.
pub(crate) const SPOT_FIELDS: &[&str] = &[
    "position",
    "color",
    "colour",
    "direction",
    "central_direction",
    "target",
    "size",
    "blend",
    "angle",
    "cone_angle",
    "penumbra",
    "inner",
    "outer",
    "exponent",
    "cutoff_distance",
    "constant_attenuation_coeff",
    "linear_attenuation_coeff",
    "quadratic_attenuation_coeff",
];

/// Fields of `area_light`.
pub(crate) const AREA_FIELDS: &[&str] = &[
    "position",
    "color",
    "colour",
    "light_radius",
    "bottom_radius",
    "radius",
    "u",
    "v",
    "constant_attenuation_coeff",
    "linear_attenuation_coeff",
    "quadratic_attenuation_coeff",
];

/// Fields of `warn_light` and `warn_model_light`, in any fork's spelling.
pub(crate) const WARN_FIELDS: &[&str] = &[
    "position",
    "color",
    "colour",
    "direction",
    "central_direction",
    "normal",
    "target",
    "specular_exponent",
    "p",
    "exponent",
    "size",
    "type",
    "xflapmin",
    "xflapmax",
    "yflapmin",
    "yflapmax",
    "zflapmin",
    "zflapmax",
    "xmin",
    "xmax",
    "ymin",
    "ymax",
    "zmin",
    "zmax",
    "cutoff_distance",
    "constant_attenuation_coeff",
    "linear_attenuation_coeff",
    "quadratic_attenuation_coeff",
];

/// The Warn lights' flaps: the box, in world coordinates, their light is confined to.
const WARN_FLAPS: [&str; 12] = [
    "xflapmin", "xflapmax", "yflapmin", "yflapmax", "zflapmin", "zflapmax", "xmin", "xmax", "ymin", "ymax", "zmin",
    "zmax",
];

/// Whether `key` holds a vector (the others hold numbers).
pub(crate) fn is_vector_field(key: &str) -> bool {
    matches!(
        key,
        "position" | "color" | "colour" | "direction" | "central_direction" | "normal" | "target" | "u" | "v"
    )
}

/// The values of a light block as read, each with where it was written.
#[derive(Default)]
pub(crate) struct LightFields {
    vectors: Vec<(&'static str, Vec3, Span)>,
    numbers: Vec<(&'static str, f32, Span)>,
    /// Remarks for the scene's warnings.
    pub warnings: Vec<(String, Span)>,
}

impl LightFields {
    /// Records `key = value` (a field of `fields`); a second value for a key is an error.
    pub fn vector(&mut self, fields: &[&'static str], key: &str, value: Vec3, span: Span) -> Result<(), ParseError> {
        let key = self.check(fields, key, &span)?;
        self.vectors.push((key, value, span));
        Ok(())
    }

    /// Records `key = number`.
    pub fn number(&mut self, fields: &[&'static str], key: &str, value: f32, span: Span) -> Result<(), ParseError> {
        let key = self.check(fields, key, &span)?;
        self.numbers.push((key, value, span));
        Ok(())
    }

    fn check(&self, fields: &[&'static str], key: &str, span: &Span) -> Result<&'static str, ParseError> {
        let key = *fields.iter().find(|f| **f == key).expect("a known field");
        let same = |k: &str| k == key || (matches!(k, "color" | "colour") && matches!(key, "color" | "colour"));
        if self.vectors.iter().any(|(k, ..)| same(k)) || self.numbers.iter().any(|(k, ..)| same(k)) {
            return Err(ParseError::new(
                format!("this light has a second `{key}`"),
                span.clone(),
            ));
        }
        Ok(key)
    }

    fn vec(&self, key: &str) -> Option<(Vec3, Span)> {
        self.vectors
            .iter()
            .find(|(k, ..)| *k == key)
            .map(|(_, v, s)| (*v, s.clone()))
    }

    fn num(&self, key: &str) -> Option<(f32, Span)> {
        self.numbers
            .iter()
            .find(|(k, ..)| *k == key)
            .map(|(_, v, s)| (*v, s.clone()))
    }

    fn color(&self) -> Option<Vec3> {
        self.vec("color").or_else(|| self.vec("colour")).map(|(c, _)| c)
    }

    /// The course falloff (a, b, c): the dialect's default (`default_falloff`), or the
    /// coefficients given; under HKUST defaults coefficients count only when one is positive.
    fn attenuation(&self, default_falloff: [f32; 3], hkust: bool) -> [f32; 3] {
        let keys = [
            "constant_attenuation_coeff",
            "linear_attenuation_coeff",
            "quadratic_attenuation_coeff",
        ];
        let given: Vec<Option<f32>> = keys.iter().map(|k| self.num(k).map(|(v, _)| v)).collect();
        if given.iter().all(Option::is_none) {
            return default_falloff;
        }
        let mut abc = if hkust { [0.0; 3] } else { default_falloff };
        for (slot, value) in abc.iter_mut().zip(&given) {
            if let Some(v) = value {
                *slot = *v;
            }
        }
        if hkust && abc.iter().all(|&c| c <= 0.0) {
            [1.0, 0.0, 0.0]
        } else {
            abc
        }
    }

    /// The direction a light shines: one of `keys` (a `target` point is aimed at from `position`).
    fn aim(&self, what: &str, keys: &[&str], position: Vec3, block: &Span) -> Result<Vec3, ParseError> {
        let aims: Vec<&str> = keys.iter().copied().filter(|k| self.vec(k).is_some()).collect();
        match aims.as_slice() {
            [] => Err(self.required(what, keys[0], block)),
            ["target"] => Ok(self.vec("target").map(|(t, _)| t - position).unwrap_or_default()),
            [one] => Ok(self.vec(one).map(|(d, _)| d).unwrap_or_default()),
            [_, second, ..] => {
                let span = self.vec(second).map(|(_, s)| s).unwrap_or(block.clone());
                Err(ParseError::new(
                    format!(
                        "give the light's aim once (`{}` and `{second}` are both given)",
                        aims[0]
                    ),
                    span,
                ))
            }
        }
    }

    /// A `cutoff_distance`, which no light here models, gets a warning at its place.
    fn warn_cutoff(&self, warnings: &mut Vec<(String, Span)>) {
        if let Some((c, span)) = self.num("cutoff_distance") {
            warnings.push((
                format!(
                    "`cutoff_distance = {c}` is not modelled: the light falls off with its attenuation coefficients instead of (1 − d/{c})²"
                ),
                span,
            ));
        }
    }

    fn required(&self, what: &str, key: &str, block: &Span) -> ParseError {
        ParseError::new(format!("`{what}` needs a `{key}`"), block.clone())
    }

    /// The spot light these fields describe; `falloff` is the dialect's point-light default.
    pub fn spot(
        self,
        block: Span,
        falloff: [f32; 3],
        hkust: bool,
    ) -> Result<(LightDesc, Vec<(String, Span)>), ParseError> {
        let position = self
            .vec("position")
            .ok_or_else(|| self.required("spot_light", "position", &block))?
            .0;
        let color = self
            .color()
            .ok_or_else(|| self.required("spot_light", "color", &block))?;
        let direction = self.aim(
            "spot_light",
            &["direction", "central_direction", "target"],
            position,
            &block,
        )?;
        let spellings: [(&[&str], &str); 4] = [
            (&["size", "blend"], "size"),
            (&["angle"], "angle"),
            (&["cone_angle", "penumbra"], "cone_angle"),
            (&["inner", "outer"], "outer"),
        ];
        let used: Vec<&[&str]> = spellings
            .iter()
            .filter(|(keys, _)| keys.iter().any(|k| self.num(k).is_some()))
            .map(|(keys, _)| *keys)
            .collect();
        if used.len() > 1 {
            let span = self
                .num(used[1][0])
                .or_else(|| self.num(used[1][1]))
                .map_or(block.clone(), |(_, s)| s);
            return Err(ParseError::new(
                format!(
                    "give the spot light's cone in one spelling (`{}` and `{}` come from different course forks)",
                    used[0][0], used[1][0]
                ),
                span,
            ));
        }
        let degrees = |key: &str, max: f32| -> Result<Option<f32>, ParseError> {
            match self.num(key) {
                Some((v, span)) if !(0.0..=max).contains(&v) => Err(ParseError::new(
                    format!("`{key}` must be between 0 and {max}, not {v}"),
                    span,
                )),
                other => Ok(other.map(|(v, _)| v)),
            }
        };
        let (inner, outer) = match used.first().map(|k| k[0]) {
            Some("size") => {
                let size = degrees("size", 360.0)?.ok_or_else(|| self.required("spot_light", "size", &block))?;
                let blend = degrees("blend", 1.0)?.unwrap_or(0.0);
                (0.5 * size * (1.0 - blend), 0.5 * size)
            }
            Some("angle") => {
                let angle = self.num("angle").expect("given");
                if !(0.0..=std::f32::consts::PI).contains(&angle.0) {
                    return Err(ParseError::new(
                        format!(
                            "`angle` is the spot's half-angle in radians, between 0 and π, not {}",
                            angle.0
                        ),
                        angle.1,
                    ));
                }
                (angle.0.to_degrees(), angle.0.to_degrees())
            }
            Some("cone_angle") => {
                let cone =
                    degrees("cone_angle", 180.0)?.ok_or_else(|| self.required("spot_light", "cone_angle", &block))?;
                let penumbra = degrees("penumbra", 180.0)?.unwrap_or(0.0);
                ((cone - penumbra).max(0.0), cone)
            }
            Some(_) => {
                let outer = degrees("outer", 180.0)?.ok_or_else(|| self.required("spot_light", "outer", &block))?;
                let inner = degrees("inner", 180.0)?.unwrap_or(outer);
                if inner > outer {
                    let span = self.num("inner").map_or(block.clone(), |(_, s)| s);
                    return Err(ParseError::new(
                        format!("`inner` ({inner}°) must not exceed `outer` ({outer}°)"),
                        span,
                    ));
                }
                (inner, outer)
            }
            None => (45.0, 45.0),
        };
        let exponent = match self.num("exponent") {
            Some((e, span)) if !(e >= 0.0 && e.is_finite()) => {
                return Err(ParseError::new(format!("`exponent` must be 0 or more, not {e}"), span))
            }
            other => other.map_or(0.0, |(e, _)| e),
        };
        let mut warnings = self.warnings.clone();
        self.warn_cutoff(&mut warnings);
        Ok((
            LightDesc::Spot {
                position,
                direction,
                color,
                attenuation: self.attenuation(falloff, hkust),
                inner_degrees: inner,
                outer_degrees: outer,
                exponent,
                span: block,
            },
            warnings,
        ))
    }

    /// The Warn light these fields describe (`what` is its keyword): a spot light lit over the
    /// half-space it faces with a cos^p falloff, or a hard beam of radius `size` at unit distance.
    pub fn warn(
        self,
        what: &str,
        block: Span,
        falloff: [f32; 3],
        hkust: bool,
    ) -> Result<(LightDesc, Vec<(String, Span)>), ParseError> {
        let position = self
            .vec("position")
            .ok_or_else(|| self.required(what, "position", &block))?
            .0;
        let color = self.color().ok_or_else(|| self.required(what, "color", &block))?;
        let direction = self.aim(
            what,
            &["direction", "central_direction", "normal", "target"],
            position,
            &block,
        )?;
        let exponents: Vec<(f32, Span)> = ["specular_exponent", "p", "exponent"]
            .iter()
            .filter_map(|k| self.num(k))
            .collect();
        let exponent = match exponents.as_slice() {
            [] => 0.0,
            [(e, span)] if !(*e >= 0.0 && e.is_finite()) => {
                return Err(ParseError::new(
                    format!("the Warn exponent must be 0 or more, not {e}"),
                    span.clone(),
                ))
            }
            [(e, _)] => *e,
            [_, (_, span), ..] => return Err(ParseError::new("give the Warn light's exponent once", span.clone())),
        };
        let half_angle = match self.num("size") {
            Some((size, span)) if !(size > 0.0 && size.is_finite()) => {
                return Err(ParseError::new(format!("`size` must be positive, not {size}"), span))
            }
            Some((size, _)) => size.atan().to_degrees(),
            None => 90.0,
        };
        let mut warnings = self.warnings.clone();
        if let Some((kind, span)) = self.num("type") {
            warnings.push((
                format!("the beam's shape (`type = {kind}`) is not modelled: the Warn light's beam is round"),
                span,
            ));
        }
        let flaps: Vec<(&str, f32, Span)> = WARN_FLAPS
            .iter()
            .filter_map(|k| self.num(k).map(|(v, s)| (*k, v, s)))
            .collect();
        if !flaps.is_empty() {
            let list: Vec<String> = flaps.iter().map(|(k, v, _)| format!("{k} = {v}")).collect();
            let start = flaps.iter().map(|(_, _, s)| s.start).min().unwrap_or(block.start);
            let end = flaps.iter().map(|(_, _, s)| s.end).max().unwrap_or(block.end);
            warnings.push((
                format!(
                    "the Warn light's flaps ({}) are not modelled: it also lights what lies outside them",
                    list.join(", ")
                ),
                start..end,
            ));
        }
        self.warn_cutoff(&mut warnings);
        Ok((
            LightDesc::Spot {
                position,
                direction,
                color,
                attenuation: self.attenuation(falloff, hkust),
                inner_degrees: half_angle,
                outer_degrees: half_angle,
                exponent,
                span: block,
            },
            warnings,
        ))
    }

    /// The area light these fields describe; `falloff` is the dialect's point-light default.
    pub fn area(self, block: Span, falloff: [f32; 3], hkust: bool) -> Result<LightDesc, ParseError> {
        let position = self
            .vec("position")
            .ok_or_else(|| self.required("area_light", "position", &block))?
            .0;
        let color = self
            .color()
            .ok_or_else(|| self.required("area_light", "color", &block))?;
        let radii: Vec<(f32, Span)> = ["light_radius", "bottom_radius", "radius"]
            .iter()
            .filter_map(|k| self.num(k))
            .collect();
        let (u, v) = (self.vec("u"), self.vec("v"));
        let shape = match (radii.as_slice(), u, v) {
            ([(r, span)], None, None) => {
                if !(*r >= 0.0 && r.is_finite()) {
                    return Err(ParseError::new(format!("an area light's radius must be 0 or more, not {r}"), span.clone()));
                }
                SoftShapeDesc::Sphere {
                    center: position,
                    radius: *r,
                }
            }
            ([], Some((u, su)), Some((v, _))) => {
                if u.cross(v).length_squared() <= 0.0 || !u.cross(v).is_finite() {
                    return Err(ParseError::new("the area light's `u` and `v` span no area", su));
                }
                SoftShapeDesc::Parallelogram { corner: position, u, v }
            }
            ([], None, None) => {
                return Err(self.required("area_light", "light_radius` (a ball) or `u` and `v", &block));
            }
            ([], Some((_, s)), None) | ([], None, Some((_, s))) => {
                return Err(ParseError::new("an area light needs both edge vectors `u` and `v`", s))
            }
            ([_, (_, s), ..], _, _) | ([(_, s)], _, _) => {
                return Err(ParseError::new(
                    "give the area light one size: a radius (`light_radius`, `bottom_radius` or `radius`) or the edges `u` and `v`",
                    s.clone(),
                ))
            }
        };
        // The parallelogram's fork divides by d² + 0.01 (its LIGHT_EPSILON) whatever the dialect.
        let falloff = match shape {
            SoftShapeDesc::Parallelogram { .. } | SoftShapeDesc::Ellipse { .. } => [0.01, 0.0, 1.0],
            SoftShapeDesc::Sphere { .. } => falloff,
        };
        Ok(LightDesc::Soft {
            shape,
            color,
            attenuation: self.attenuation(falloff, hkust),
            span: block,
        })
    }
}
