//! Lights of the `.ray` format: point lights with the course's attenuation, directional lights.

use crate::math::Vec3;

/// The closed set of lights.
#[derive(Clone, Debug, PartialEq)]
pub enum Light {
    /// A point light with attenuation f(d) = min(1, 1 / (a + b d + c d²)) (§5).
    Point {
        /// World position.
        position: Vec3,
        /// Colour (intensity).
        color: Vec3,
        /// (a, b, c).
        attenuation: [f32; 3],
    },
    /// A light from infinitely far away; `direction` is the unit direction light travels.
    Directional {
        /// Unit travel direction.
        direction: Vec3,
        /// Colour (irradiance on a surface facing the light).
        color: Vec3,
    },
}

/// What a light sends to a point: the unit direction towards the light, the distance to it
/// (infinite for a directional light) and the incident colour before shadowing.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the point towards the light.
    pub wi: Vec3,
    /// Distance to the light.
    pub distance: f32,
    /// Colour × distance attenuation.
    pub intensity: Vec3,
}

impl Light {
    /// Illumination of point `p`.
    pub fn sample_li(&self, p: Vec3) -> Option<LightSample> {
        match *self {
            Light::Point {
                position,
                color,
                attenuation,
            } => {
                let to_light = position - p;
                let distance = to_light.length();
                if distance == 0.0 || !distance.is_finite() {
                    return None;
                }
                Some(LightSample {
                    wi: to_light / distance,
                    distance,
                    intensity: color * distance_attenuation(attenuation, distance),
                })
            }
            Light::Directional { direction, color } => Some(LightSample {
                wi: -direction,
                distance: f32::INFINITY,
                intensity: color,
            }),
        }
    }

    /// The light's colour.
    pub fn color(&self) -> Vec3 {
        match self {
            Light::Point { color, .. } | Light::Directional { color, .. } => *color,
        }
    }
}

/// The course's falloff min(1, 1 / (a + b d + c d²)); 1 where the denominator is not positive.
#[inline]
pub fn distance_attenuation(abc: [f32; 3], d: f32) -> f32 {
    let denom = abc[0] + abc[1] * d + abc[2] * d * d;
    if denom <= 0.0 {
        1.0
    } else {
        (1.0 / denom).min(1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attenuation_follows_the_course_formula() {
        assert_eq!(distance_attenuation([0.0, 0.0, 1.0], 2.0), 0.25);
        assert_eq!(distance_attenuation([0.0, 0.0, 1.0], 0.5), 1.0, "clamped to 1");
        let stock = [0.25, 0.003372407, 0.000045492];
        let d = 17.32;
        let expected = 1.0 / (0.25 + 0.003372407 * d + 0.000045492 * d * d);
        assert!((distance_attenuation(stock, d) - expected.min(1.0)).abs() < 1e-6);
    }

    #[test]
    fn directional_light_comes_from_against_its_direction() {
        let l = Light::Directional {
            direction: -Vec3::Z,
            color: Vec3::ONE,
        };
        let s = l.sample_li(Vec3::ZERO).unwrap();
        assert_eq!(s.wi, Vec3::Z);
        assert!(s.distance.is_infinite());
    }
}
