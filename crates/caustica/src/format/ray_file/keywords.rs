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
    "warn_light",
    "warn_model_light",
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
    "quadric",
    "hyperboloid",
    "hyperbolic_paraboloid",
    "paraboloid",
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

/// Constructs added by students in forks of the course skeleton whose meaning caustica cannot
/// reproduce: as objects or fields they are skipped with a warning, elsewhere refused.
pub(crate) const EXTENSIONS: &[&str] = &[
    "light_radius",
    "bump_mapping",
    "bump",
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

/// Whether `word` names a student extension caustica does not read.
pub(crate) fn is_extension(word: &str) -> bool {
    EXTENSIONS.contains(&word)
}

/// The warning for an object or block that is skipped; `what` is how it is written.
pub(crate) fn skipped_object(word: &str, what: &str) -> String {
    if is_extension(word) {
        format!("skipped `{what}`: `{word}` is a student extension of the course format that caustica does not read; the rest of the scene is read without it")
    } else {
        format!(
            "skipped `{what}`: caustica does not know the object `{word}`; the rest of the scene is read without it"
        )
    }
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
    "warn_light",
    "warn_model_light",
    "skybox",
    "ambient_light",
    "medium",
    "material",
    "sphere",
    "box",
    "square",
    "cylinder",
    "cone",
    "torus",
    "metaballs",
    "metaball",
    "quadric",
    "hyperboloid",
    "hyperbolic_paraboloid",
    "paraboloid",
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
