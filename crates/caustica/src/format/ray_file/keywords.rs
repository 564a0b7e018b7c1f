//! Reserved words of dialect T and the names of student extensions both dialects reject.

use super::ast::Span;
use crate::ParseError;

/// Every reserved word of dialect T (UT list plus the UW additions `look_at` and `texture_uv`).
pub(crate) const RESERVED: &[&str] = &[
    "SBT-raytracer",
    "camera",
    "position",
    "viewdir",
    "updir",
    "aspectratio",
    "fov",
    "quaternian",
    "look_at",
    "point_light",
    "directional_light",
    "sun_light",
    "environment_light",
    "spot_light",
    "area_light",
    "skybox",
    "angle",
    "ambient_light",
    "color",
    "colour",
    "direction",
    "constant_attenuation_coeff",
    "linear_attenuation_coeff",
    "quadratic_attenuation_coeff",
    "sphere",
    "box",
    "square",
    "cylinder",
    "cone",
    "torus",
    "metaballs",
    "metaball",
    "trimesh",
    "polymesh",
    "capped",
    "major_radius",
    "minor_radius",
    "height",
    "bottom_radius",
    "top_radius",
    "points",
    "faces",
    "normals",
    "materials",
    "gennormals",
    "texture_uv",
    "translate",
    "scale",
    "rotate",
    "transform",
    "union",
    "intersection",
    "difference",
    "subtraction",
    "material",
    "emissive",
    "ambient",
    "specular",
    "reflective",
    "diffuse",
    "transmissive",
    "shininess",
    "index",
    "abbe",
    "name",
    "map",
    "true",
    "false",
];

/// Whether `word` is reserved in dialect T.
pub(crate) fn is_reserved(word: &str) -> bool {
    RESERVED.contains(&word)
}

/// Constructs added by students in forks of the course skeleton; caustica reads none of them.
pub(crate) const EXTENSIONS: &[&str] = &[
    "warn_light",
    "warn_model_light",
    "light_radius",
    "quadric",
    "hyperboloid",
    "hyperbolic_paraboloid",
    "bump_mapping",
    "bump",
    "objfile",
    "map_points",
    "particles",
    "emitter",
    "fluid",
    "moving_sphere",
    "diffuse_map",
    "emission",
    "absorb",
    "marble",
];

/// The end of every student-extension message (used to prefer these errors over others).
const EXTENSION_MESSAGE: &str = "is a student extension of the course format that caustica does not read";

/// Whether `error` is the rejection of a student extension.
pub(crate) fn is_extension_error(error: &ParseError) -> bool {
    error.message.ends_with(EXTENSION_MESSAGE)
}

/// The rejection error for a student extension, if `word` names one.
pub(crate) fn extension_error(word: &str, span: &Span) -> Option<ParseError> {
    EXTENSIONS.contains(&word).then(|| {
        ParseError::new(format!("`{word}` {EXTENSION_MESSAGE}"), span.clone())
            .with_help("remove it or replace it with the standard primitives, lights and material fields")
    })
}

/// Material colour fields, in the order the course documents them.
pub(crate) const COLOUR_FIELDS: &[&str] = &[
    "emissive",
    "ambient",
    "specular",
    "reflective",
    "diffuse",
    "transmissive",
];

/// Statements that may start an item at the top level of a file (both dialects).
pub(crate) const TOP_LEVEL: &[&str] = &[
    "camera",
    "point_light",
    "directional_light",
    "sun_light",
    "environment_light",
    "spot_light",
    "area_light",
    "skybox",
    "ambient_light",
    "material",
    "sphere",
    "box",
    "square",
    "cylinder",
    "cone",
    "torus",
    "metaballs",
    "metaball",
    "trimesh",
    "polymesh",
    "translate",
    "scale",
    "rotate",
    "transform",
    "union",
    "intersection",
    "difference",
    "subtraction",
    "csg",
];
