//! The format-neutral scene description: what every scene reader produces and the scene builder
//! consumes. Plain data with source spans; no rendering types and no file syntax.
//!
//! Transforms are already flattened: every object carries its `world_from_object` matrix.
//! Materials are already resolved: each object holds the finished material it renders with.

use crate::error::Span;
pub use crate::texture::ImageSource;
use crate::texture::{Encoding, Sampler, Wrap};
use glam::{Mat4, Vec2, Vec3, Vec4};
use std::path::PathBuf;

/// A whole scene.
#[derive(Clone, Debug, Default)]
pub struct SceneDescription {
    /// The camera, if the file has one.
    pub camera: Option<CameraDesc>,
    /// Lights, in file order.
    pub lights: Vec<LightDesc>,
    /// Ambient light Ia of the course shading (summed).
    pub ambient: Vec3,
    /// Every primitive, in file order, with its world transform and material.
    pub objects: Vec<ObjectDesc>,
    /// Non-fatal remarks made while reading, each with a span.
    pub warnings: Vec<(String, Span)>,
    /// What the file says about how to render it (image size, integrator); a front end's own
    /// options win over these.
    pub hints: RenderHints,
    /// Participating media, which materials' [`InterfaceDesc`]s name by index.
    pub media: Vec<MediumDesc>,
    /// The medium that fills the scene where no interface says otherwise (haze), if any.
    pub ambient_medium: Option<usize>,
    /// The media lights are in, where the file says (light index, medium); other lights' are
    /// found from the surfaces around them.
    pub light_media: Vec<(usize, Option<usize>)>,
    /// The medium the camera is in, where the file says (pbrt's `CameraMedium`); otherwise it
    /// is found from the surfaces around the eye.
    pub camera_medium: Option<usize>,
}

/// A participating medium: coefficients per unit of length (RGB, already scaled) and a
/// Henyey–Greenstein phase function; on a grid, the density multiplies both.
#[derive(Clone, Debug, PartialEq)]
pub struct MediumDesc {
    /// Its name in the file, if any.
    pub name: Option<String>,
    /// σa, absorption.
    pub sigma_a: Vec3,
    /// σs, scattering.
    pub sigma_s: Vec3,
    /// Henyey–Greenstein's mean cosine.
    pub g: f32,
    /// A density grid, or `None`: homogeneous.
    pub grid: Option<GridDesc>,
    /// Where it was defined.
    pub span: Span,
}

/// A density on a regular grid of samples (x fastest), spanning the unit cube of grid space.
#[derive(Clone, Debug, PartialEq)]
pub struct GridDesc {
    /// Samples along x, y and z.
    pub dims: [usize; 3],
    /// The densities.
    pub values: Vec<f32>,
    /// From world space to the grid's unit cube.
    pub grid_from_world: Mat4,
}

/// Which media a material's surface separates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct InterfaceDesc {
    /// Against the outward normal.
    pub inside: MediumSide,
    /// On the outward normal's side.
    pub outside: MediumSide,
}

/// One side of a medium boundary.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MediumSide {
    /// This medium (an index into [`SceneDescription::media`]), or `None`: vacuum.
    Medium(Option<usize>),
    /// Whatever surrounded a path before it went in.
    Surrounding,
}

/// Render settings a scene file asks for (pbrt-v4's `Film`, `Integrator` and `Sampler`,
/// glTF's camera aspect). `RenderConfig` applies them unless a front end overrides them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenderHints {
    /// Image width in pixels.
    pub width: Option<usize>,
    /// Image height in pixels.
    pub height: Option<usize>,
    /// Whether the file is in radiometric units, so the physical model is its natural reading.
    pub physical: bool,
    /// The integrator the file names.
    pub integrator: Option<IntegratorHint>,
    /// pbrt's `maxdepth`: the most scattering events on a path (`--depth` is one less).
    pub max_depth: Option<u32>,
    /// Samples per pixel (pbrt's `pixelsamples`): passes of the physical integrators.
    pub samples: Option<u32>,
    /// Photons per pass (pbrt's sppm `photonsperiteration`).
    pub photons_per_pass: Option<usize>,
    /// Gather radius in scene units (pbrt's sppm `radius`).
    pub radius: Option<f32>,
    /// A medium scatters light: the physical model renders the scene (the course model knows
    /// no media).
    pub scattering_media: bool,
    /// The output file the scene names (pbrt's `Film "filename"`), as written.
    pub output: Option<PathBuf>,
}

/// An integrator a scene file asks for, in caustica's terms.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum IntegratorHint {
    /// A path tracer.
    Path,
    /// Progressive photon mapping.
    Ppm,
    /// A light tracer (particle tracer).
    LightTracer,
    /// A bidirectional method: vertex connection and merging stands for it.
    Bidirectional,
}

/// A pinhole camera: the eye and the image plane it looks through. The plane's centre lies at
/// `eye + view`; it spans `up × height` vertically and `(up × −view) × height × aspect_ratio`
/// horizontally. The vectors are used as given (not normalised), so readers that want a
/// conventional camera pass unit, perpendicular vectors.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraDesc {
    /// Eye position.
    pub position: Vec3,
    /// From the eye to the image-plane centre.
    pub view: Vec3,
    /// The image plane's upward direction.
    pub up: Vec3,
    /// Image-plane height per unit of `up` (2·tan(fov/2) for unit vectors).
    pub height: f32,
    /// Width / height.
    pub aspect_ratio: f32,
    /// The image plane's rightward direction per unit, when it is not `up × −view` (a
    /// left-handed camera such as pbrt's); `None` for the usual right-handed one.
    pub right: Option<Vec3>,
    /// Which span keeps its field of view when the image's aspect differs from `aspect_ratio`.
    pub fov_axis: FovAxis,
    /// A thin lens for depth of field; `None`: a pinhole.
    pub lens: Option<ThinLens>,
    /// Where the camera is described.
    pub span: Span,
}

/// A thin lens: the camera's rays leave a disc of `radius` around the eye, across the image
/// plane, and those through one point of the image meet again at the distance `focus` along
/// the view (pbrt's `lensradius` and `focaldistance`; Blender's focal length over twice the
/// f-stop, and its focus distance).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThinLens {
    /// The aperture's radius, in scene units.
    pub radius: f32,
    /// The distance in focus, along the view.
    pub focus: f32,
}

/// The axis whose field of view a format fixes: an image of another aspect than the camera's
/// widens or narrows along the other one, so nothing is stretched.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum FovAxis {
    /// The vertical span (glTF's `yfov`, the course's `fov`, OBJ's framing).
    #[default]
    Vertical,
    /// The shorter of the two spans (pbrt's `fov`).
    Shorter,
}

/// A light.
#[derive(Clone, Debug)]
pub enum LightDesc {
    /// A point light.
    Point {
        /// Position in world space.
        position: Vec3,
        /// Colour (intensity), not clamped.
        color: Vec3,
        /// Attenuation (constant a, linear b, quadratic c); parser default (0, 0, 1).
        attenuation: [f32; 3],
        /// Where the block is.
        span: Span,
    },
    /// A light from infinitely far away.
    Directional {
        /// The direction the light travels, as written (not normalised).
        direction: Vec3,
        /// Colour, not clamped.
        color: Vec3,
        /// Where the block is.
        span: Span,
    },
    /// A point light shining into a cone.
    Spot {
        /// Position in world space.
        position: Vec3,
        /// The direction it shines, as written (not normalised).
        direction: Vec3,
        /// Colour (intensity on the axis).
        color: Vec3,
        /// Attenuation (constant a, linear b, quadratic c).
        attenuation: [f32; 3],
        /// Half-angle of full intensity, in degrees.
        inner_degrees: f32,
        /// Half-angle beyond which it is dark, in degrees (at least `inner_degrees`).
        outer_degrees: f32,
        /// Exponent of a cos^e falloff from the axis (0: none).
        exponent: f32,
        /// Where the block is.
        span: Span,
    },
    /// A sun: a far light of small angular size.
    Sun {
        /// The direction its light travels, as written (not normalised).
        direction: Vec3,
        /// Irradiance on a surface facing it.
        color: Vec3,
        /// Angular diameter in degrees (0.53 for the sun seen from the earth).
        angle_degrees: f32,
        /// Where the block is.
        span: Span,
    },
    /// A light with a size (the course forks' `area_light`): the course model shades with it as
    /// a point light at its centre whose shadows are soft; the physical model samples its
    /// surface and emits photons from it.
    Soft {
        /// Its shape and place.
        shape: SoftShapeDesc,
        /// A ball's colour is its intensity, as a point light's; a parallelogram's is the
        /// radiance of its front face.
        color: Vec3,
        /// The course's (a, b, c) falloff with distance from the centre.
        attenuation: [f32; 3],
        /// Where the block is.
        span: Span,
    },
    /// A cube map around the scene (six images, seen from inside), the background of both
    /// models and the sky of the physical one.
    Skybox {
        /// The images looking along +x, −x, +y, −y, +z and −z, resolved against the scene's folder.
        faces: [PathBuf; 6],
        /// How each face is laid out.
        layout: SkyboxLayout,
        /// Radiance scale.
        color: Vec3,
        /// Where the block is (for errors reading the images).
        span: Span,
    },
    /// The sky around the scene: radiance `color` times an optional latitude–longitude image.
    Environment {
        /// Radiance scale.
        color: Vec3,
        /// The image (EXR, Radiance HDR or PFM, or pixels given as numbers), a file resolved
        /// against the scene's folder.
        map: Option<ImageSource>,
        /// The image's frame turned into the world's (a rotation; identity: +y up, the image's
        /// centre towards −z).
        rotation: glam::Mat3,
        /// The image is pbrt-v4's equal-area octahedral square (its frame +z up) rather than
        /// latitude–longitude; it is resampled to latitude–longitude when loaded.
        equal_area: bool,
        /// Where the block is (and the map's file name in it, for errors reading it).
        span: Span,
    },
}

/// The shape of a [`LightDesc::Soft`] light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SoftShapeDesc {
    /// A ball (radius 0 is a point light).
    Sphere {
        /// Centre.
        center: Vec3,
        /// Radius.
        radius: f32,
    },
    /// A parallelogram `corner + s·u + t·v` (s, t in [0, 1]) lit on the side u × v points to.
    Parallelogram {
        /// One corner.
        corner: Vec3,
        /// First edge.
        u: Vec3,
        /// Second edge.
        v: Vec3,
    },
    /// The ellipse inscribed in the parallelogram `corner + s·u + t·v`: its centre
    /// `corner + (u + v)/2`, its half-axes u/2 and v/2; lit on the side u × v points to
    /// (Blender's disk and ellipse area lights).
    Ellipse {
        /// The parallelogram's corner.
        corner: Vec3,
        /// First edge (a diameter's length and direction).
        u: Vec3,
        /// Second edge.
        v: Vec3,
    },
}

/// How the six images of a skybox are oriented.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkyboxLayout {
    /// Each face seen from inside the box, upright for the four sides (top face: its bottom
    /// edge meets the front face; bottom face: its top edge meets the front).
    Inside,
    /// The UT course skeleton's cube map (its `CubeMap::getColor`), whose x axis is mirrored.
    UtCubeMap,
}

/// A material parameter: a constant or a texture map.
#[derive(Clone, Debug, PartialEq)]
pub enum Param {
    /// A constant colour (scalars are stored as grey triples).
    Constant(Vec3),
    /// A checkerboard over the texture coordinates: `even` where ⌊u·su⌋ + ⌊v·sv⌋ is even
    /// (pbrt-v4's `checkerboard` texture).
    Checkerboard {
        /// The colour of even cells (the one at the origin).
        even: Vec3,
        /// The colour of odd cells.
        odd: Vec3,
        /// Cells per unit of u and v.
        scale: Vec2,
    },
    /// An image map (`map("file")`, pbrt's `imagemap`, glTF's and OBJ's textures).
    Texture(Box<ImageMap>),
}

/// An image map: its image, how the image's values are decoded and how it is sampled.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageMap {
    /// The image.
    pub source: ImageSource,
    /// How integer texels become linear values.
    pub encoding: Encoding,
    /// Transform, wrap, filter and factor.
    pub sampler: Sampler,
    /// Where the map is written, for messages when the image cannot be read.
    pub span: Span,
}

impl ImageMap {
    /// A map of the course's `.ray` kind: `path` read as stored, clamped, bilinear.
    pub fn course(path: PathBuf, span: Span) -> ImageMap {
        ImageMap {
            source: ImageSource::File(path),
            encoding: Encoding::Linear,
            sampler: Sampler::default(),
            span,
        }
    }

    /// A colour map of a physical format (glTF, pbrt, OBJ): sRGB-decoded, repeating, bilinear.
    pub fn colour(source: ImageSource, span: Span) -> ImageMap {
        ImageMap {
            source,
            encoding: Encoding::Srgb,
            sampler: Sampler {
                wrap: [Wrap::Repeat; 2],
                ..Sampler::default()
            },
            span,
        }
    }
}

impl Param {
    /// A constant grey parameter.
    pub fn grey(value: f32) -> Param {
        Param::Constant(Vec3::splat(value))
    }
}

/// A finished material (all fields present; defaults and inheritance applied).
#[derive(Clone, Debug, PartialEq)]
pub struct MaterialDesc {
    /// ke
    pub emissive: Param,
    /// ka
    pub ambient: Param,
    /// ks
    pub specular: Param,
    /// kr
    pub reflective: Param,
    /// kd
    pub diffuse: Param,
    /// kt
    pub transmissive: Param,
    /// Phong exponent (a constant is a grey triple; a texture is luminance × 128, §6.1).
    pub shininess: Param,
    /// Index of refraction (grey triple); with `abbe`, the index n_d at 587.6 nm.
    pub index: Param,
    /// Abbe number V_d of a dispersive glass (caustica extension): n_F − n_C = (n_d − 1) / V_d.
    pub abbe: Option<f32>,
    /// Name registered with `name`, if any.
    pub name: Option<String>,
    /// The physical model's reading when the format describes one the course fields cannot
    /// (metals, coated and translucent surfaces, thin glass); `None`: the course fields' own
    /// physical reading (docs/radiometry.md). The course fields always hold the closest course
    /// reading.
    pub physical: Option<PhysicalMaterial>,
    /// A normal map bending the shading normal of meshes with texture coordinates.
    pub normal_map: Option<NormalMap>,
    /// glTF's metallic-roughness texture: where it is given, the physical reading at each point
    /// follows it instead of `physical`.
    pub metallic_roughness: Option<MetallicRoughness>,
    /// Coverage of a mesh's surface (its x channel): where it is below the cutoff, or with no
    /// cutoff at random in proportion, rays and photons pass through.
    pub alpha: Option<Alpha>,
    /// Which faces of the surface send out its `emissive` light.
    pub emitting_faces: EmittingFaces,
    /// Absorption inside a solid glass, per unit of length (RGB, ≥ 0): light crossing a
    /// length d inside keeps exp(−σ d) (Beer–Lambert; glTF's `KHR_materials_volume`
    /// attenuation). `None`: clear.
    pub absorption: Option<Vec3>,
    /// The media on the two sides of the surface (`None`: it changes no path's medium).
    pub interface: Option<InterfaceDesc>,
    /// Only a boundary between media (pbrt's `interface`): paths pass it unchanged and it is not
    /// drawn.
    pub boundary: bool,
    /// pbrt's `mix`: the physical reading takes one of two materials at each point; the course
    /// fields above hold the larger part.
    pub mix: Option<Box<MixDesc>>,
    /// A clear coat over the physical reading (glTF's `KHR_materials_clearcoat`, pbrt-v4's
    /// `coatedconductor`).
    pub clearcoat: Option<ClearCoat>,
    /// The clear coat's textures, where it has some.
    pub clearcoat_maps: Option<ClearCoatMaps>,
    /// The physical lobe's roughness from a texture (pbrt's textured `roughness`).
    pub roughness_map: Option<RoughnessMap>,
}

/// A clear dielectric coat over a material: it reflects `weight`·F(θ) (Fresnel of index `eta`,
/// smooth or GGX of α `alpha`), and what lies under it is seen through it both ways, times
/// (1 − weight·F(θo))(1 − weight·F(θi)): reciprocal, and never more than all the light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClearCoat {
    /// How much of the surface the coat covers (glTF's `clearcoatFactor`), 0 to 1.
    pub weight: f32,
    /// The coat's index.
    pub eta: f32,
    /// The coat's GGX α (below [`SMOOTH_ALPHA`] a smooth coat).
    pub alpha: f32,
}

/// A clear coat's textures (glTF's `clearcoatTexture` and `clearcoatRoughnessTexture`), their
/// factors included: where given, the coat's weight is the first's x channel, and its
/// roughness the second's y channel (GGX α its square).
#[derive(Clone, Debug, PartialEq)]
pub struct ClearCoatMaps<P = Param> {
    /// The weight.
    pub weight: Option<P>,
    /// The roughness.
    pub roughness: Option<P>,
}

impl<P> ClearCoatMaps<P> {
    /// The same with each texture mapped by `f`.
    pub fn try_map<Q, E>(&self, mut f: impl FnMut(&P) -> Result<Q, E>) -> Result<ClearCoatMaps<Q>, E> {
        Ok(ClearCoatMaps {
            weight: self.weight.as_ref().map(&mut f).transpose()?,
            roughness: self.roughness.as_ref().map(&mut f).transpose()?,
        })
    }
}

/// A roughness read from a texture: at each point the GGX α of the physical reading
/// (conductor, coated diffuse, rough dielectric) is the texture's x channel, or its square root
/// with `remap` (pbrt's `remaproughness`); a dielectric smoother than [`SMOOTH_ALPHA`] there is
/// smooth.
#[derive(Clone, Debug, PartialEq)]
pub struct RoughnessMap<P = Param> {
    /// The texture (its x channel).
    pub texture: P,
    /// How the value becomes α.
    pub remap: RoughnessRemap,
}

/// How a roughness texture's value r becomes the GGX α.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RoughnessRemap {
    /// α = r (pbrt without `remaproughness`).
    Alpha,
    /// α = √r (pbrt's `remaproughness`).
    Sqrt,
    /// α = r² (Blender's and glTF's perceptual roughness).
    Square,
}

impl RoughnessRemap {
    /// The α of a texture value `r` (≥ 0).
    #[inline]
    pub fn alpha(self, r: f32) -> f32 {
        match self {
            RoughnessRemap::Alpha => r,
            RoughnessRemap::Sqrt => r.sqrt(),
            RoughnessRemap::Square => r * r,
        }
    }
}

/// pbrt's `mix` material: at each point the second material with probability `amount` (its
/// first channel), else the first, chosen by a hash of the point and the direction the light
/// leaves by, as pbrt-v4 chooses: in the mean the two BSDFs blend by `amount`.
#[derive(Clone, Debug, PartialEq)]
pub struct MixDesc {
    /// The two materials.
    pub materials: [MaterialDesc; 2],
    /// The second's share.
    pub amount: Param,
}

/// The faces of a surface that emit. A face is named by the geometric normal: a triangle's
/// `(b − a) × (c − a)`, a shape's outward normal. The course model, OBJ and glTF emit from both;
/// pbrt's area lights from the front unless `twosided`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum EmittingFaces {
    /// Both faces.
    #[default]
    Both,
    /// The face the geometric normal points out of.
    Front,
    /// The other face.
    Back,
}

impl EmittingFaces {
    /// Whether light leaves a surface of unit geometric normal `normal` towards `dir`.
    #[inline]
    pub fn emit_towards(self, normal: Vec3, dir: Vec3) -> bool {
        match self {
            EmittingFaces::Both => true,
            EmittingFaces::Front => normal.dot(dir) > 0.0,
            EmittingFaces::Back => normal.dot(dir) < 0.0,
        }
    }

    /// The sign of the normal that points out of the one emitting face; `None` for both.
    #[inline]
    pub fn sign(self) -> Option<f32> {
        match self {
            EmittingFaces::Both => None,
            EmittingFaces::Front => Some(1.0),
            EmittingFaces::Back => Some(-1.0),
        }
    }

    /// How many faces emit.
    #[inline]
    pub fn count(self) -> f32 {
        if self == EmittingFaces::Both {
            2.0
        } else {
            1.0
        }
    }
}

/// How much of a surface is there: glTF's `alphaMode` MASK (a cutoff) and BLEND (none: a ray
/// passes with the chance 1 − coverage).
#[derive(Clone, Debug, PartialEq)]
pub struct Alpha<P = Param> {
    /// Coverage in [0, 1], in the x channel.
    pub coverage: P,
    /// MASK's `alphaCutoff`; `None` for BLEND.
    pub cutoff: Option<f32>,
}

/// How a coated diffuse material's base and coat share the light.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coating {
    /// The coat's underside sends the base's light back down to it, again and again (pbrt-v4's
    /// layered `coateddiffuse`): the base's albedo r counts as r / (η²(1 − r·F̄ᵢ)), F̄ᵢ the
    /// coat's mean reflectance from inside.
    Layered,
    /// Light crosses the coat once each way (glTF's Fresnel mix, pbrt-v3's plastic): the base
    /// is seen times (1 − F(θo))(1 − F(θi)).
    Fresnel,
    /// The coat's reflection added to the whole base (Blender 3's Principled BSDF, whose
    /// specular lobe takes nothing from its diffuse one): brighter than any physical varnish,
    /// by up to the coat's reflectance at grazing angles.
    Added,
}

/// Below this GGX α a surface is smooth: a perfect mirror, or glass that refracts by Snell's law.
pub const SMOOTH_ALPHA: f32 = 1e-3;

/// A physically based material beyond the course fields' reading, generic over how a colour is
/// given (`Param` in the description, a scene channel once built). Roughness is the GGX α.
#[derive(Clone, Debug, PartialEq)]
pub enum PhysicalMaterial<P = Param> {
    /// A metal: Fresnel reflectance of the complex index η + ik per channel, or of the index
    /// that gives `reflectance` at normal incidence (η = 1, k = 2√r/√(1 − r)).
    Conductor {
        /// Real part of the index (RGB).
        eta: Vec3,
        /// Imaginary part (RGB).
        k: Vec3,
        /// Reflectance at normal incidence instead of η and k.
        reflectance: Option<P>,
        /// GGX α; below 1e-3 a perfect mirror.
        roughness: f32,
    },
    /// A Lambertian base under a clear dielectric coat of index `eta`.
    CoatedDiffuse {
        /// Albedo of the base.
        reflectance: P,
        /// Index of the coat.
        eta: f32,
        /// GGX α of the coat; below 1e-3 smooth.
        roughness: f32,
        /// What the coat reflects, per channel, times its Fresnel reflectance: 1 for a clear coat;
        /// glTF's specular weight times its specular colour (`KHR_materials_specular`). The base
        /// under it loses its largest channel's share.
        coat_tint: P,
        /// How the base and the coat share the light.
        layering: Coating,
    },
    /// Lambertian reflection and Lambertian transmission (leaves, paper, lampshades).
    DiffuseTransmission {
        /// Reflected albedo.
        reflectance: P,
        /// Transmitted albedo.
        transmittance: P,
    },
    /// A thin-walled dielectric (glTF transmission without a volume): Fresnel reflection of
    /// both faces, the rest passes straight through, tinted.
    ThinDielectric {
        /// Index of the sheet.
        eta: f32,
        /// Colour of the light that passes.
        tint: P,
    },
    /// A rough dielectric interface (frosted glass): GGX microfacet reflection and refraction
    /// (Walter et al. 2007) between outside and an inside of index `eta`.
    RoughDielectric {
        /// Index of the inside.
        eta: f32,
        /// GGX α (at least 1e-3; below, the interface is smooth).
        roughness: f32,
        /// Colour of the light that crosses.
        tint: P,
        /// Abbe number: the index depends on the wavelength (Cauchy's law) under spectral
        /// transport.
        abbe: Option<f32>,
    },
}

impl<P> PhysicalMaterial<P> {
    /// The same material with each colour converted by `f`.
    pub fn try_map<Q, E>(&self, mut f: impl FnMut(&P) -> Result<Q, E>) -> Result<PhysicalMaterial<Q>, E> {
        Ok(match self {
            PhysicalMaterial::Conductor {
                eta,
                k,
                reflectance,
                roughness,
            } => PhysicalMaterial::Conductor {
                eta: *eta,
                k: *k,
                reflectance: reflectance.as_ref().map(&mut f).transpose()?,
                roughness: *roughness,
            },
            PhysicalMaterial::CoatedDiffuse {
                reflectance,
                eta,
                roughness,
                coat_tint,
                layering,
            } => PhysicalMaterial::CoatedDiffuse {
                reflectance: f(reflectance)?,
                eta: *eta,
                roughness: *roughness,
                coat_tint: f(coat_tint)?,
                layering: *layering,
            },
            PhysicalMaterial::DiffuseTransmission {
                reflectance,
                transmittance,
            } => PhysicalMaterial::DiffuseTransmission {
                reflectance: f(reflectance)?,
                transmittance: f(transmittance)?,
            },
            PhysicalMaterial::ThinDielectric { eta, tint } => PhysicalMaterial::ThinDielectric {
                eta: *eta,
                tint: f(tint)?,
            },
            PhysicalMaterial::RoughDielectric {
                eta,
                roughness,
                tint,
                abbe,
            } => PhysicalMaterial::RoughDielectric {
                eta: *eta,
                roughness: *roughness,
                tint: f(tint)?,
                abbe: *abbe,
            },
        })
    }
}

impl MaterialDesc {
    /// A Lambertian reflector of reflectance `reflectance` (both models).
    pub fn lambert(reflectance: Param) -> MaterialDesc {
        MaterialDesc {
            diffuse: reflectance,
            ..MaterialDesc::default()
        }
    }

    /// A base of reflectance `base` under a clear coat of index `eta` and GGX α, sharing the
    /// light as `layering` says.
    pub fn coated(base: Param, eta: f32, alpha: f32, layering: Coating) -> MaterialDesc {
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        let mut m = MaterialDesc::lambert(base.clone());
        m.physical = Some(PhysicalMaterial::CoatedDiffuse {
            reflectance: base,
            eta,
            roughness: alpha,
            coat_tint: Param::grey(1.0),
            layering,
        });
        m.course_gloss(Vec3::splat(f0), alpha);
        m
    }

    /// A smooth mirror of reflectance `r` (pbrt's `conductor` with `reflectance`, v3's `mirror`).
    pub fn mirror(r: Param) -> MaterialDesc {
        let f0 = match &r {
            Param::Constant(c) => *c,
            _ => Vec3::splat(0.8),
        };
        let mut m = MaterialDesc {
            physical: Some(PhysicalMaterial::Conductor {
                eta: Vec3::ONE,
                k: Vec3::ZERO,
                reflectance: Some(r),
                roughness: 0.0,
            }),
            ..MaterialDesc::default()
        };
        m.course_gloss(f0, 0.0);
        m
    }

    /// The course reading of a glossy lobe of normal reflectance `f0` and GGX α: a mirror when
    /// smooth, else a Phong highlight of exponent 2/α² − 2 (the Beckmann–Phong correspondence).
    pub fn course_gloss(&mut self, f0: Vec3, alpha: f32) {
        if alpha < 1e-3 {
            self.reflective = Param::Constant(f0);
        } else {
            self.specular = Param::Constant(f0);
            self.shininess = Param::grey((2.0 / (alpha * alpha) - 2.0).clamp(1.0, 10_000.0));
        }
    }

    /// Every image map the material reads (colours, physical lobes, cut-outs, normal map).
    pub fn image_maps(&self) -> Vec<ImageMap> {
        let mut maps = Vec::new();
        let mut visit = |p: &Param| {
            if let Param::Texture(m) = p {
                maps.push((**m).clone());
            }
            Ok::<(), ()>(())
        };
        for p in [
            &self.emissive,
            &self.ambient,
            &self.specular,
            &self.reflective,
            &self.diffuse,
            &self.transmissive,
            &self.shininess,
            &self.index,
        ] {
            let _ = visit(p);
        }
        if let Some(p) = &self.physical {
            let _ = p.try_map(&mut visit);
        }
        if let Some(a) = &self.alpha {
            let _ = visit(&a.coverage);
        }
        if let Some(mr) = &self.metallic_roughness {
            let _ = mr.try_map(&mut visit);
        }
        if let Some(maps) = &self.clearcoat_maps {
            let _ = maps.try_map(&mut visit);
        }
        if let Some(r) = &self.roughness_map {
            let _ = visit(&r.texture);
        }
        if let Some(mix) = &self.mix {
            let _ = visit(&mix.amount);
            for m in &mix.materials {
                maps.extend(m.image_maps());
            }
        }
        maps.extend(self.normal_map.as_ref().map(|n| n.map.clone()));
        maps
    }
}

impl Default for MaterialDesc {
    /// The all-default material of §6.1: colours zero, shininess 0, index 1.
    fn default() -> Self {
        MaterialDesc {
            emissive: Param::grey(0.0),
            ambient: Param::grey(0.0),
            specular: Param::grey(0.0),
            reflective: Param::grey(0.0),
            diffuse: Param::grey(0.0),
            transmissive: Param::grey(0.0),
            shininess: Param::grey(0.0),
            index: Param::grey(1.0),
            abbe: None,
            name: None,
            physical: None,
            normal_map: None,
            metallic_roughness: None,
            alpha: None,
            emitting_faces: EmittingFaces::Both,
            absorption: None,
            interface: None,
            boundary: false,
            mix: None,
            clearcoat: None,
            clearcoat_maps: None,
            roughness_map: None,
        }
    }
}

/// glTF's metallic-roughness model with its texture, generic over how a colour is given: at
/// each point metalness is the texture's blue times `metallic`, roughness its green times
/// `roughness` (GGX α = roughness²); a point at least half metal is a conductor of the base
/// colour's reflectance, the rest the base colour under a clear coat of index `coat` (or bare
/// Lambert without one), or, for solid glass (`glass`), a dielectric tinted by the base colour:
/// rough where the roughness says so, else smooth.
#[derive(Clone, Debug, PartialEq)]
pub struct MetallicRoughness<P = Param> {
    /// The base colour.
    pub base: P,
    /// The texture (linear).
    pub texture: P,
    /// `metallicFactor`.
    pub metallic: f32,
    /// `roughnessFactor`.
    pub roughness: f32,
    /// The dielectric's coat index (`None`: no specular layer).
    pub coat: Option<f32>,
    /// What that coat reflects per channel, times its Fresnel reflectance
    /// ([`PhysicalMaterial::CoatedDiffuse`]'s `coat_tint`).
    pub coat_tint: P,
    /// Solid glass's index and Abbe number, where the material transmits.
    pub glass: Option<(f32, Option<f32>)>,
}

impl MetallicRoughness<Param> {
    /// The same with each colour mapped by `f`.
    pub fn try_map<Q, E>(&self, mut f: impl FnMut(&Param) -> Result<Q, E>) -> Result<MetallicRoughness<Q>, E> {
        Ok(MetallicRoughness {
            base: f(&self.base)?,
            texture: f(&self.texture)?,
            metallic: self.metallic,
            roughness: self.roughness,
            coat: self.coat,
            coat_tint: f(&self.coat_tint)?,
            glass: self.glass,
        })
    }
}

/// A tangent-space normal map: its image (linear), and the scale of its x and y.
#[derive(Clone, Debug, PartialEq)]
pub struct NormalMap {
    /// The image; texels map [0, 1] to normal components in [−1, 1].
    pub map: ImageMap,
    /// Multiplies the normal's x and y (glTF's `normalTexture.scale`).
    pub scale: f32,
}

/// A primitive placed in the world.
#[derive(Clone, Debug)]
pub struct ObjectDesc {
    /// The object-space shape.
    pub shape: ShapeDesc,
    /// Object-space to world-space matrix (column-vector convention).
    pub world_from_object: Mat4,
    /// The object's material (for a trimesh with per-vertex materials, the base material).
    pub material: MaterialDesc,
    /// Where the primitive's keyword is.
    pub span: Span,
}

/// Object-space shapes of §7.
#[derive(Clone, Debug)]
pub enum ShapeDesc {
    /// Unit sphere at the origin.
    Sphere,
    /// Cube [-0.5, 0.5]³.
    Box,
    /// Square [-0.5, 0.5]² in the z = 0 plane.
    Square,
    /// Radius 1 about +z, z ∈ [0, 1].
    Cylinder {
        /// End caps (always true in the UT dialect; UW `capped`).
        capped: bool,
    },
    /// Cone about +z from z = 0 to z = height.
    Cone {
        /// Height (default 1).
        height: f32,
        /// Radius at z = 0 (default 1).
        bottom_radius: f32,
        /// Radius at z = height (default 0).
        top_radius: f32,
        /// End discs (default true).
        capped: bool,
    },
    /// Triangle mesh (polygons already fan-triangulated, indices validated).
    Trimesh(Box<TrimeshDesc>),
    /// Torus about +z: a tube of radius `minor_radius` around the circle of radius
    /// `major_radius` in the z = 0 plane (a course-fork extension).
    Torus {
        /// Radius of the ring.
        major_radius: f32,
        /// Radius of the tube.
        minor_radius: f32,
    },
    /// Metaballs (a course-fork extension).
    Metaballs(Box<MetaballsDesc>),
    /// Constructive solid geometry (a course-fork extension): its operands carry their own
    /// world transforms and materials; the object's own transform and material are unused.
    Csg(Box<CsgDesc>),
    /// Disc of radius 1 in the z = 0 plane about the origin, with a hole of radius `inner`
    /// (0 ≤ inner < 1); its normal is +z.
    Disk {
        /// Radius of the hole.
        inner: f32,
    },
}

/// A CSG operation on two or more operands, applied from the left: `a − b − c` for a difference.
#[derive(Clone, Debug)]
pub struct CsgDesc {
    /// Which operation.
    pub op: CsgOpDesc,
    /// The operands (closed shapes or other CSG objects), each placed in the world.
    pub operands: Vec<ObjectDesc>,
}

/// The CSG operations.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CsgOpDesc {
    /// Inside any operand.
    Union,
    /// Inside every operand.
    Intersection,
    /// Inside the first operand and none of the others.
    Difference,
}

/// Metaballs: balls (centre, radius) blended into one surface.
#[derive(Clone, Debug, PartialEq)]
pub struct MetaballsDesc {
    /// Centre and radius of each ball.
    pub balls: Vec<(Vec3, f32)>,
    /// How they blend.
    pub model: BlobModelDesc,
}

/// How metaballs blend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BlobModelDesc {
    /// Σ K(|p − c|/R) = threshold, K(x) = 1 − x³(6x² − 15x + 10) for x < 1.
    Field {
        /// The level of the surface.
        threshold: f32,
    },
    /// The polynomial smooth minimum (of width `blend`) of the balls' distances is zero.
    SmoothUnion {
        /// Width of the blend.
        blend: f32,
    },
}

/// A triangle mesh in object space.
#[derive(Clone, Debug, Default)]
pub struct TrimeshDesc {
    /// Vertex positions.
    pub points: Vec<Vec3>,
    /// Triangles as 0-based vertex indices, all < `points.len()`.
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex normals (same length as `points`) if given or generated.
    pub normals: Option<Vec<Vec3>>,
    /// Per-vertex materials (same length as `points`) if given.
    pub materials: Option<Vec<MaterialDesc>>,
    /// Per-vertex texture coordinates (UW `texture_uv`), same length as `points`.
    pub uvs: Option<Vec<Vec2>>,
    /// Per-vertex tangents (glTF's `TANGENT`: the direction of increasing u, and in w the
    /// bitangent's sign), same length as `points`; generated where a normal map needs them.
    pub tangents: Option<Vec<Vec4>>,
}

/// Vertex attributes that are not finite (a NaN normal in an exporter's PLY or glTF) repaired
/// in place, with a warning for each kind counting them: a normal is recomputed from the
/// triangles around its vertex (area-weighted), a texture coordinate read as (0, 0). Triangles
/// on vertices whose positions are not finite are left for the reader or the scene build to drop.
pub fn repair_vertex_attributes(
    points: &[Vec3],
    triangles: &[[u32; 3]],
    normals: &mut Option<Vec<Vec3>>,
    uvs: &mut Option<Vec<Vec2>>,
) -> Vec<String> {
    let mut warnings = Vec::new();
    let lost = points.iter().filter(|p| !p.is_finite()).count();
    if lost > 0 {
        warnings.push(format!(
            "{lost} of {} vertex positions are not finite: the triangles using them are left out",
            points.len()
        ));
    }
    if let Some(ns) = normals.as_mut() {
        let broken: Vec<bool> = ns.iter().map(|n| !n.is_finite()).collect();
        let count = broken.iter().filter(|&&b| b).count();
        if count > 0 {
            for n in ns.iter_mut().filter(|n| !n.is_finite()) {
                *n = Vec3::ZERO;
            }
            for tri in triangles {
                let [a, b, c] = tri.map(|i| points.get(i as usize).copied().unwrap_or(Vec3::NAN));
                // Twice the area along the face normal: larger faces weigh more.
                let face = (b - a).cross(c - a);
                if !face.is_finite() {
                    continue;
                }
                for &i in tri {
                    if broken.get(i as usize) == Some(&true) {
                        ns[i as usize] += face;
                    }
                }
            }
            for (n, _) in ns.iter_mut().zip(&broken).filter(|(_, &b)| b) {
                *n = n.normalize_or_zero();
            }
            warnings.push(format!(
                "{count} of {} vertex normals are not finite: recomputed from the faces around them",
                ns.len()
            ));
        }
    }
    if let Some(uvs) = uvs.as_mut() {
        let count = uvs.iter().filter(|uv| !uv.is_finite()).count();
        if count > 0 {
            for uv in uvs.iter_mut().filter(|uv| !uv.is_finite()) {
                *uv = Vec2::ZERO;
            }
            warnings.push(format!(
                "{count} of {} texture coordinates are not finite: read as (0, 0)",
                uvs.len()
            ));
        }
    }
    warnings
}
