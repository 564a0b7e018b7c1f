//! `caustica.Scene.from_dict`: a scene built in memory — a dict of plain values and numpy
//! arrays — read into the format-neutral description every file reader produces
//! (docs/python.md, "Scenes from Python"). Errors name the key and the index at fault.

use caustica::description::{
    Alpha, CameraDesc, ClearCoat, ClearCoatMaps, Coating, EmittingFaces, FovAxis, ImageMap, ImageSource,
    IntegratorHint, InterfaceDesc, LightDesc, MaterialDesc, MediumDesc, MediumSide, MixDesc, NormalMap, ObjectDesc,
    Param, PhysicalMaterial, RenderHints, RoughnessMap, RoughnessRemap, SceneDescription, ShapeDesc, SoftShapeDesc,
    ThinLens, TrimeshDesc, SMOOTH_ALPHA,
};
use caustica::math::{Affine2, Mat3, Mat4, Vec2, Vec3, Vec4};
use caustica::texture::{Encoding, Wrap};
use numpy::{PyArrayMethods, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use std::collections::HashMap;
use std::path::PathBuf;

/// A key's place in the dict, for messages: `shapes[2].indices`.
#[derive(Clone)]
struct At(String);

impl At {
    fn key(&self, key: &str) -> At {
        if self.0.is_empty() {
            At(key.to_string())
        } else {
            At(format!("{}.{key}", self.0))
        }
    }

    fn index(&self, i: usize) -> At {
        At(format!("{}[{i}]", self.0))
    }

    fn error(&self, message: impl std::fmt::Display) -> PyErr {
        PyValueError::new_err(format!("{}: {message}", self.0))
    }

    fn type_error(&self, message: impl std::fmt::Display) -> PyErr {
        PyTypeError::new_err(format!("{}: {message}", self.0))
    }
}

/// A dict's keys, each read at most once; what is left when `done` is called is refused, so a
/// misspelt key is an error rather than silently a default.
struct Table<'py> {
    dict: Bound<'py, PyDict>,
    at: At,
    read: Vec<String>,
}

impl<'py> Table<'py> {
    fn new(value: &Bound<'py, PyAny>, at: At) -> PyResult<Table<'py>> {
        let dict = value
            .cast::<PyDict>()
            .map_err(|_| at.type_error("expected a dict"))?
            .clone();
        Ok(Table {
            dict,
            at,
            read: Vec::new(),
        })
    }

    fn get(&mut self, key: &str) -> PyResult<Option<Bound<'py, PyAny>>> {
        self.read.push(key.to_string());
        Ok(self.dict.get_item(key)?.filter(|v| !v.is_none()))
    }

    fn float(&mut self, key: &str, default: f32) -> PyResult<f32> {
        match self.get(key)? {
            Some(v) => {
                let x: f64 = v
                    .extract()
                    .map_err(|_| self.at.key(key).type_error("expected a number"))?;
                if !x.is_finite() {
                    return Err(self.at.key(key).error(format!("{x} is not finite")));
                }
                Ok(x as f32)
            }
            None => Ok(default),
        }
    }

    /// A colour: a number (grey) or three.
    fn colour(&mut self, key: &str, default: Vec3) -> PyResult<Vec3> {
        match self.get(key)? {
            Some(v) => colour(&v, &self.at.key(key)),
            None => Ok(default),
        }
    }

    /// A colour that may be a texture: a number, three, or an image (`image_map`, sRGB unless
    /// it says otherwise).
    fn param(&mut self, key: &str, default: Vec3) -> PyResult<Param> {
        self.param_encoded(key, default, Encoding::Srgb)
    }

    /// A value that may be a texture, its image read as `encoding` unless it says otherwise.
    fn param_encoded(&mut self, key: &str, default: Vec3, encoding: Encoding) -> PyResult<Param> {
        match self.get(key)? {
            Some(v) if v.cast::<PyDict>().is_ok() => {
                image_map(&v, self.at.key(key), encoding).map(|m| Param::Texture(Box::new(m)))
            }
            Some(v) => colour(&v, &self.at.key(key)).map(Param::Constant),
            None => Ok(Param::Constant(default)),
        }
    }

    /// A share in [0, 1]: a number, or a texture (linear, its first channel).
    fn share(&mut self, key: &str, default: f32) -> PyResult<Param> {
        let p = self.param_encoded(key, Vec3::splat(default), Encoding::Linear)?;
        if let Param::Constant(c) = p {
            if !(0.0..=1.0).contains(&c.x) {
                return Err(self.at.key(key).error(format!("a share between 0 and 1, not {}", c.x)));
            }
            return Ok(Param::grey(c.x));
        }
        Ok(p)
    }

    fn vec3(&mut self, key: &str) -> PyResult<Option<Vec3>> {
        match self.get(key)? {
            Some(v) => vec3(&v, &self.at.key(key)).map(Some),
            None => Ok(None),
        }
    }

    fn required_vec3(&mut self, key: &str) -> PyResult<Vec3> {
        self.vec3(key)?.ok_or_else(|| self.at.key(key).error("required"))
    }

    fn string(&mut self, key: &str) -> PyResult<Option<String>> {
        match self.get(key)? {
            Some(v) => v
                .extract()
                .map(Some)
                .map_err(|_| self.at.key(key).type_error("expected a string")),
            None => Ok(None),
        }
    }

    fn flag(&mut self, key: &str, default: bool) -> PyResult<bool> {
        match self.get(key)? {
            Some(v) => v
                .extract()
                .map_err(|_| self.at.key(key).type_error("expected True or False")),
            None => Ok(default),
        }
    }

    /// One of the names `options` gives, as its value; `None` when the key is absent.
    fn choice<T: Copy>(&mut self, key: &str, options: &[(&str, T)]) -> PyResult<Option<T>> {
        let Some(name) = self.string(key)? else {
            return Ok(None);
        };
        if let Some((_, value)) = options.iter().find(|(n, _)| *n == name) {
            return Ok(Some(*value));
        }
        let quoted: Vec<String> = options.iter().map(|(n, _)| format!("\"{n}\"")).collect();
        let listed = match quoted.split_last() {
            Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
            _ => quoted.join(""),
        };
        Err(self.at.key(key).error(format!("{listed}, not \"{name}\"")))
    }

    /// A whole number above 0 (`what` says of what, for the message).
    fn whole(&mut self, key: &str, what: &str) -> PyResult<Option<u64>> {
        match self.get(key)? {
            Some(v) => match v.extract::<u64>() {
                Ok(n) if n > 0 => Ok(Some(n)),
                _ => Err(self.at.key(key).error(format!("expected a whole number {what}above 0"))),
            },
            None => Ok(None),
        }
    }

    /// Refuses keys that were not read.
    fn done(self) -> PyResult<()> {
        for key in self.dict.keys() {
            let name: String = key.extract().map_err(|_| self.at.type_error("keys are strings"))?;
            if !self.read.contains(&name) {
                return Err(self.at.key(&name).error("not a key caustica reads here"));
            }
        }
        Ok(())
    }
}

fn floats(value: &Bound<'_, PyAny>, at: &At) -> PyResult<Vec<f64>> {
    if let Ok(x) = value.extract::<f64>() {
        return Ok(vec![x]);
    }
    let v: Vec<f64> = value
        .extract()
        .map_err(|_| at.type_error("expected a number or a sequence of numbers"))?;
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(at.index(i).error(format!("{} is not finite", v[i])));
    }
    Ok(v)
}

fn colour(value: &Bound<'_, PyAny>, at: &At) -> PyResult<Vec3> {
    match floats(value, at)?.as_slice() {
        [g] => Ok(Vec3::splat(*g as f32)),
        [r, g, b] => Ok(Vec3::new(*r as f32, *g as f32, *b as f32)),
        other => Err(at.error(format!("a colour is one number or three, not {}", other.len()))),
    }
}

fn vec3(value: &Bound<'_, PyAny>, at: &At) -> PyResult<Vec3> {
    match floats(value, at)?.as_slice() {
        [x, y, z] => Ok(Vec3::new(*x as f32, *y as f32, *z as f32)),
        other => Err(at.error(format!("expected three numbers, not {}", other.len()))),
    }
}

/// An image: `{"file": path}` or `{"array": pixels}` (`image_source`), with `"encoding":
/// "srgb" | "linear" | "alpha"` (the alpha channel, as coverage), `"scale": colour`, `"wrap":
/// "repeat" | "clamp" | "mirror"`, `"filter": "linear" | "nearest"`; the encoding defaults to
/// `encoding` (sRGB for colours), wrap to repeat, filter to linear.
fn image_map(value: &Bound<'_, PyAny>, at: At, encoding: Encoding) -> PyResult<ImageMap> {
    let mut t = Table::new(value, at.clone())?;
    let source = image_source(&mut t, &at)?
        .ok_or_else(|| at.error("an image is a `file` (PNG, JPEG, EXR, HDR, …) or an `array` of pixels"))?;
    let mut map = ImageMap::colour(source, 0..0);
    let encodings = [
        ("srgb", Encoding::Srgb),
        ("linear", Encoding::Linear),
        ("alpha", Encoding::Coverage),
    ];
    map.encoding = t.choice("encoding", &encodings)?.unwrap_or(encoding);
    map.sampler.scale = t.colour("scale", Vec3::ONE)?;
    let wraps = [
        ("repeat", Wrap::Repeat),
        ("clamp", Wrap::Clamp),
        ("mirror", Wrap::Mirror),
    ];
    map.sampler.wrap = [t.choice("wrap", &wraps)?.unwrap_or(Wrap::Repeat); 2];
    map.sampler.nearest = t
        .choice("filter", &[("linear", false), ("nearest", true)])?
        .unwrap_or(false);
    if let Some(m) = t.get("uv_transform")? {
        let at = at.key("uv_transform");
        let m = array(&m, 3, &at)?;
        let m = m.as_slice().map_err(|_| at.error("not contiguous"))?;
        if m.len() != 9 || m[6..] != [0.0, 0.0, 1.0] || m.iter().any(|x| !x.is_finite()) {
            return Err(at.error("expected a 3×3 affine matrix of numbers (its last row 0, 0, 1)"));
        }
        // numpy's rows: (u', v') = m · (u, v, 1).
        map.sampler.transform = Affine2::from_cols(Vec2::new(m[0], m[3]), Vec2::new(m[1], m[4]), Vec2::new(m[2], m[5]));
    }
    t.done()?;
    Ok(map)
}

/// The image a table names: its `file`, or its `array` of pixels (numpy, shape (h, w) or
/// (h, w, c) with c from 1 to 4, rows from the top; 8- and 16-bit integers are stored values
/// decoded by the encoding, floats linear values); `None` when it names neither.
fn image_source(t: &mut Table, at: &At) -> PyResult<Option<ImageSource>> {
    let file = t.string("file")?;
    let array = t.get("array")?;
    match (file, array) {
        (Some(_), Some(_)) => Err(at.error("an image is a `file` or an `array`, not both")),
        (Some(file), None) => {
            let file = PathBuf::from(file);
            if !file.is_file() {
                return Err(at.key("file").error(format!("no file `{}`", file.display())));
            }
            Ok(Some(ImageSource::File(file)))
        }
        (None, Some(a)) => pixels(&a, &at.key("array")).map(Some),
        (None, None) => Ok(None),
    }
}

/// Pixels from a numpy array, named for messages by where they are in the dict.
fn pixels(value: &Bound<'_, PyAny>, at: &At) -> PyResult<ImageSource> {
    let np = value.py().import("numpy")?;
    let a = np
        .call_method1("asarray", (value,))
        .map_err(|e| at.type_error(format!("not an array ({e})")))?;
    let shape: Vec<usize> = a.getattr("shape")?.extract()?;
    let (height, width, channels) = match shape.as_slice() {
        [h, w] => (*h, *w, 1),
        [h, w, c] if (1..=4).contains(c) => (*h, *w, *c),
        _ => {
            return Err(at.error(format!(
                "expected an array of shape (h, w) or (h, w, c) with 1 to 4 channels, not {shape:?}"
            )))
        }
    };
    if width == 0 || height == 0 {
        return Err(at.error("the image is empty"));
    }
    let dtype = a.getattr("dtype")?;
    let kind: String = dtype.getattr("kind")?.extract()?;
    let size: usize = dtype.getattr("itemsize")?.extract()?;
    let largest = match (kind.as_str(), size) {
        ("u", 1) => Some(255.0),
        ("u", 2) => Some(65535.0),
        ("f", _) => None,
        _ => {
            return Err(at.type_error(format!(
                "pixels are 8- or 16-bit unsigned integers or floats, not {}",
                dtype.str()?
            )))
        }
    };
    let flat = np.call_method1("ascontiguousarray", (a.call_method0("ravel")?, "float32"))?;
    let flat = flat
        .cast_into::<numpy::PyArray1<f32>>()
        .map_err(|_| at.error("not an array of numbers"))?;
    let ro = flat.readonly();
    let mut values = ro.as_slice().map_err(|_| at.error("not contiguous"))?.to_vec();
    if let Some(i) = values.iter().position(|v| !v.is_finite()) {
        return Err(at.error(format!("value {i} is not finite")));
    }
    if let Some(largest) = largest {
        values.iter_mut().for_each(|v| *v /= largest);
    }
    Ok(ImageSource::Pixels {
        name: at.0.clone(),
        width,
        height,
        channels,
        values: values.into(),
        integer: largest.is_some(),
    })
}

/// An array of shape (n, `columns`), as float32 (anything numpy turns into numbers).
fn array<'py>(value: &Bound<'py, PyAny>, columns: usize, at: &At) -> PyResult<PyReadonlyArray2<'py, f32>> {
    let np = value.py().import("numpy")?;
    let a = np
        .call_method1("ascontiguousarray", (value, "float32"))
        .map_err(|e| at.type_error(format!("not an array of numbers ({e})")))?;
    let a = a
        .cast_into::<numpy::PyArray2<f32>>()
        .map_err(|_| at.error(format!("expected an array of shape (n, {columns})")))?;
    let ro = a.readonly();
    if ro.shape()[1] != columns {
        return Err(at.error(format!(
            "expected an array of shape (n, {columns}), not {:?}",
            ro.shape()
        )));
    }
    Ok(ro)
}

/// A 4×4 matrix (rows as usual in numpy: `m @ p` maps a column point).
fn matrix(value: &Bound<'_, PyAny>, at: &At) -> PyResult<Mat4> {
    let a = array(value, 4, at)?;
    let s = a.as_slice().map_err(|_| at.error("not contiguous"))?;
    if s.len() != 16 {
        return Err(at.error("expected a 4×4 matrix"));
    }
    if let Some(i) = s.iter().position(|x| !x.is_finite()) {
        return Err(at.error(format!("element {i} is not finite")));
    }
    let m = Mat4::from_cols_array(&[
        s[0], s[4], s[8], s[12], s[1], s[5], s[9], s[13], s[2], s[6], s[10], s[14], s[3], s[7], s[11], s[15],
    ]);
    if Mat3::from_mat4(m).determinant().abs() < 1e-12 || m.row(3) != Vec4::W {
        return Err(at.error("not an affine transform of full rank"));
    }
    Ok(m)
}

/// A rotation: a 3×3 matrix (numpy's rows) whose columns are orthonormal, turning right-handed
/// frames into right-handed ones.
fn rotation(value: &Bound<'_, PyAny>, at: &At) -> PyResult<Mat3> {
    let a = array(value, 3, at)?;
    let s = a.as_slice().map_err(|_| at.error("not contiguous"))?;
    if s.len() != 9 {
        return Err(at.error("expected a 3×3 matrix"));
    }
    let m = Mat3::from_cols_array(&[s[0], s[3], s[6], s[1], s[4], s[7], s[2], s[5], s[8]]);
    let off = (m.transpose() * m - Mat3::IDENTITY).to_cols_array();
    if !m.is_finite() || off.iter().any(|x| x.abs() > 1e-4) || (m.determinant() - 1.0).abs() > 1e-4 {
        return Err(at.error("not a rotation (orthonormal columns, determinant 1)"));
    }
    Ok(m)
}

/// Reads `dict` into a scene description.
pub fn description(dict: &Bound<'_, PyAny>) -> PyResult<SceneDescription> {
    let mut top = Table::new(dict, At(String::new()))?;
    let mut desc = SceneDescription {
        hints: RenderHints {
            physical: true,
            ..RenderHints::default()
        },
        ..SceneDescription::default()
    };
    if let Some(c) = top.get("camera")? {
        let (camera, size) = camera(&c, At("camera".into()))?;
        desc.camera = Some(camera);
        (desc.hints.width, desc.hints.height) = size;
    }
    // Media by name, before the materials that put them inside their objects.
    let media = by_name(&mut top, "media", medium)?;
    let mut names: Vec<&String> = media.keys().collect();
    names.sort();
    let numbers: HashMap<String, usize> = names.iter().enumerate().map(|(i, n)| ((*n).clone(), i)).collect();
    desc.media = names.iter().map(|n| media[*n].clone()).collect();
    if let Some(name) = top.string("medium")? {
        let number = *numbers
            .get(&name)
            .ok_or_else(|| At("medium".into()).error(format!("no medium named \"{name}\" in `media`")))?;
        desc.ambient_medium = Some(number);
        desc.camera_medium = Some(number);
    }
    let materials = by_name(&mut top, "materials", |v, at| material(v, at, &numbers))?;
    // Meshes by name, for shapes that place them (instances of one mesh share its arrays).
    let meshes = by_name(&mut top, "meshes", |value, at| {
        let mut t = Table::new(value, at.clone())?;
        let mesh = mesh(&mut t, &at)?;
        t.done()?;
        Ok(mesh)
    })?;
    if let Some(shapes) = top.get("shapes")? {
        let at = At("shapes".into());
        let list = shapes.cast::<PyList>().map_err(|_| at.type_error("expected a list"))?;
        for (i, s) in list.iter().enumerate() {
            desc.objects.push(shape(&s, at.index(i), &materials, &meshes)?);
        }
    }
    if let Some(lights) = top.get("lights")? {
        let at = At("lights".into());
        let list = lights.cast::<PyList>().map_err(|_| at.type_error("expected a list"))?;
        for (i, l) in list.iter().enumerate() {
            desc.lights.push(light(&l, at.index(i))?);
        }
    }
    if let Some(r) = top.get("render")? {
        render_hints(&r, At("render".into()), &mut desc.hints)?;
    }
    top.done()?;
    Ok(desc)
}

/// How the scene asks to be rendered, as a file's `Integrator` and `Sampler` do: `integrator`
/// ("path", "ppm", "lt" or "vcm"), `passes`, `max_depth` (scattering events on a path),
/// `photons` per pass and the gather `radius`. A call's own options win.
fn render_hints(value: &Bound<'_, PyAny>, at: At, hints: &mut RenderHints) -> PyResult<()> {
    let mut t = Table::new(value, at.clone())?;
    hints.integrator = t.choice(
        "integrator",
        &[
            ("path", IntegratorHint::Path),
            ("ppm", IntegratorHint::Ppm),
            ("lt", IntegratorHint::LightTracer),
            ("vcm", IntegratorHint::Bidirectional),
        ],
    )?;
    hints.samples = t.whole("passes", "")?.map(|n| n.min(u64::from(u32::MAX)) as u32);
    hints.max_depth = t.whole("max_depth", "")?.map(|n| n.min(1 << 16) as u32);
    hints.photons_per_pass = t.whole("photons", "")?.map(|n| n as usize);
    hints.radius = match t.float("radius", 0.0)? {
        r if r > 0.0 => Some(r),
        0.0 => None,
        r => return Err(at.key("radius").error(format!("a radius is above 0, not {r}"))),
    };
    t.done()
}

/// A dict of things by name at `key`, each read by `read` at its place.
fn by_name<T>(
    top: &mut Table,
    key: &str,
    read: impl Fn(&Bound<'_, PyAny>, At) -> PyResult<T>,
) -> PyResult<HashMap<String, T>> {
    let mut out = HashMap::new();
    if let Some(m) = top.get(key)? {
        let at = At(key.into());
        let m = m
            .cast::<PyDict>()
            .map_err(|_| at.type_error(format!("expected a dict of {key} by name")))?;
        for (name, value) in m.iter() {
            let name: String = name.extract().map_err(|_| at.type_error("names are strings"))?;
            let item = read(&value, at.key(&name))?;
            out.insert(name, item);
        }
    }
    Ok(out)
}

/// An image size a description asks for: width and height, each optional.
type Size = (Option<usize>, Option<usize>);

/// The camera, and the image size it asks for.
fn camera(value: &Bound<'_, PyAny>, at: At) -> PyResult<(CameraDesc, Size)> {
    let mut t = Table::new(value, at.clone())?;
    let fov = t.float("fov", 40.0)?;
    if !(fov > 0.0 && fov < 179.0) {
        return Err(at.key("fov").error(format!("{fov}° is not between 0 and 179")));
    }
    let fov_axis = t
        .choice(
            "fov_axis",
            &[("vertical", FovAxis::Vertical), ("shorter", FovAxis::Shorter)],
        )?
        .unwrap_or(FovAxis::Vertical);
    let width = t.whole("width", "of pixels ")?.map(|n| n as usize);
    let height = t.whole("height", "of pixels ")?.map(|n| n as usize);
    let aspect = match (t.float("aspect", 0.0)?, width, height) {
        (a, _, _) if a > 0.0 => a,
        (_, Some(w), Some(h)) => w as f32 / h as f32,
        _ => 4.0 / 3.0,
    };
    let (position, view, up, right) = match t.get("matrix")? {
        Some(m) => {
            // Blender's and glTF's camera: it looks down its −z, +y up.
            let m = matrix(&m, &at.key("matrix"))?;
            let right = m.transform_vector3(Vec3::X).normalize();
            (
                m.transform_point3(Vec3::ZERO),
                m.transform_vector3(-Vec3::Z).normalize(),
                m.transform_vector3(Vec3::Y).normalize(),
                Some(right),
            )
        }
        None => {
            let eye = t.required_vec3("eye")?;
            let look_at = t.required_vec3("look_at")?;
            let up = t.vec3("up")?.unwrap_or(Vec3::Y);
            let view = (look_at - eye).normalize_or_zero();
            if view == Vec3::ZERO {
                return Err(at.key("look_at").error("the same point as eye"));
            }
            let up = (up - view * view.dot(up)).normalize_or_zero();
            if up == Vec3::ZERO {
                return Err(at.key("up").error("parallel to the direction of view"));
            }
            (eye, view, up, None)
        }
    };
    let shift = match t.get("shift")? {
        Some(v) => match floats(&v, &at.key("shift"))?.as_slice() {
            [x, y] => Vec2::new(*x as f32, *y as f32),
            _ => return Err(at.key("shift").error("expected two numbers")),
        },
        None => Vec2::ZERO,
    };
    let aperture = t.float("aperture", 0.0)?;
    let focus = t.float("focus_distance", 0.0)?;
    let lens = match (aperture, focus) {
        (a, _) if a < 0.0 => return Err(at.key("aperture").error(format!("a radius is not negative, not {a}"))),
        (a, f) if a > 0.0 && f <= 0.0 => {
            return Err(at
                .key("focus_distance")
                .error("an aperture needs a focus distance above 0"))
        }
        (a, f) => (a > 0.0).then_some(ThinLens { radius: a, focus: f }),
    };
    let crop = match t.get("crop")? {
        Some(v) => {
            let (Some(w), Some(h)) = (width, height) else {
                return Err(at.key("crop").error("a crop needs the camera's `width` and `height`"));
            };
            let c: [usize; 4] = v
                .extract()
                .map_err(|_| at.key("crop").type_error("expected four whole numbers"))?;
            if !(c[0] < c[1] && c[1] <= w && c[2] < c[3] && c[3] <= h) {
                return Err(at.key("crop").error(format!(
                    "[x begin, x end, y begin, y end] within the {w}×{h} image, not {c:?}"
                )));
            }
            Some((c, w, h))
        }
        None => None,
    };
    t.done()?;
    let plane_height = 2.0 * (fov.to_radians() * 0.5).tan();
    // The image plane's spans, right and up; shift and crop move its centre off the axis, so
    // its rightward direction is given rather than worked out from the view.
    let right = right.unwrap_or_else(|| up.cross(-view));
    let (span_u, span_v) = (right * plane_height * aspect, up * plane_height);
    // Blender's lens shift: in units of the plane's larger side.
    let larger = plane_height * aspect.max(1.0);
    let mut view = view + right * shift.x * larger + up * shift.y * larger;
    let (mut height, mut aspect, mut size) = (plane_height, aspect, (width, height));
    if let Some((c, w, h)) = crop {
        // Pixels x in c[0]..c[1], rows (from the top) in c[2]..c[3]: the same pixels as in the
        // whole image.
        let (x0, x1) = (c[0] as f32 / w as f32, c[1] as f32 / w as f32);
        let (y0, y1) = (1.0 - c[3] as f32 / h as f32, 1.0 - c[2] as f32 / h as f32);
        view += span_u * (0.5 * (x0 + x1) - 0.5) + span_v * (0.5 * (y0 + y1) - 0.5);
        height = plane_height * (y1 - y0);
        aspect *= (x1 - x0) / (y1 - y0);
        size = (Some(c[1] - c[0]), Some(c[3] - c[2]));
    }
    let camera = CameraDesc {
        position,
        view,
        up,
        height,
        aspect_ratio: aspect,
        right: Some(right),
        fov_axis,
        lens,
        span: 0..0,
    };
    Ok((camera, size))
}

/// A material: its `type`'s physical reading, with the course fields that go with it.
/// A participating medium: `{"absorption": σa, "scattering": σs, "g": mean cosine}`, the
/// coefficients per unit of length (three numbers each, default 0), g from −1 to 1 (default 0).
fn medium(value: &Bound<'_, PyAny>, at: At) -> PyResult<MediumDesc> {
    let mut t = Table::new(value, at.clone())?;
    let sigma_a = t.colour("absorption", Vec3::ZERO)?;
    let sigma_s = t.colour("scattering", Vec3::ZERO)?;
    for (key, v) in [("absorption", sigma_a), ("scattering", sigma_s)] {
        if !(v.cmpge(Vec3::ZERO).all() && v.is_finite()) {
            return Err(at
                .key(key)
                .error(format!("per unit of length, each value zero or more, not {v}")));
        }
    }
    let g = t.float("g", 0.0)?;
    if !(g > -1.0 && g < 1.0) {
        return Err(at
            .key("g")
            .error(format!("a mean cosine strictly between −1 and 1, not {g}")));
    }
    t.done()?;
    Ok(MediumDesc {
        name: None,
        sigma_a,
        sigma_s,
        g,
        grid: None,
        span: 0..0,
    })
}

/// A material; `media` numbers the scene's media by name, for its `inside` and `outside`.
fn material(value: &Bound<'_, PyAny>, at: At, media: &HashMap<String, usize>) -> PyResult<MaterialDesc> {
    let mut t = Table::new(value, at.clone())?;
    let kind = t.string("type")?.ok_or_else(|| at.key("type").error("required"))?;
    // The GGX α: `alpha` itself, or `roughness` (α = roughness², Blender's and glTF's reading),
    // which may be a texture (its first channel, linear).
    let mut roughness_map = None;
    let mut alpha = |t: &mut Table| -> PyResult<f32> {
        let a = t.float("alpha", -1.0)?;
        let r = t.param_encoded("roughness", Vec3::splat(-1.0), Encoding::Linear)?;
        match (a, r) {
            (a, Param::Constant(r)) if a >= 0.0 && r.x >= 0.0 => {
                Err(at.error("a roughness is `alpha` or `roughness`, not both"))
            }
            (a, _) if a > 1.0 => Err(at.key("alpha").error(format!("GGX α is between 0 and 1, not {a}"))),
            (a, Param::Constant(_)) if a >= 0.0 => Ok(a),
            (_, Param::Constant(r)) if r.x > 1.0 => Err(at
                .key("roughness")
                .error(format!("a roughness is between 0 and 1, not {}", r.x))),
            (_, Param::Constant(r)) => Ok(r.x.max(0.0) * r.x.max(0.0)),
            (a, _) if a >= 0.0 => Err(at.error("a roughness is `alpha` or `roughness`, not both")),
            (_, texture) => {
                roughness_map = Some(RoughnessMap {
                    texture,
                    remap: RoughnessRemap::Square,
                });
                // Rough where the texture says; the map sets α point by point.
                Ok(0.25)
            }
        }
    };
    let ior = |t: &mut Table| -> PyResult<f32> {
        let n = t.float("ior", 1.5)?;
        if n < 1.0 {
            return Err(at
                .key("ior")
                .error(format!("an index of refraction is at least 1, not {n}")));
        }
        Ok(n)
    };
    let mut m = match kind.as_str() {
        "diffuse" => MaterialDesc::lambert(t.param("reflectance", Vec3::splat(0.5))?),
        // Only where one medium meets another: not drawn, passed unbent.
        "boundary" => MaterialDesc {
            boundary: true,
            ..MaterialDesc::default()
        },
        "glass" => {
            let (eta, alpha) = (ior(&mut t)?, alpha(&mut t)?);
            let tint = t.param("tint", Vec3::ONE)?;
            let abbe = match t.float("abbe", 0.0)? {
                v if v > 0.0 => Some(v),
                _ => None,
            };
            let mut m = MaterialDesc {
                transmissive: tint.clone(),
                index: Param::grey(eta),
                abbe,
                absorption: t
                    .colour("absorption", Vec3::ZERO)
                    .map(|a| (a != Vec3::ZERO).then_some(a))?,
                ..MaterialDesc::default()
            };
            if alpha >= SMOOTH_ALPHA {
                m.physical = Some(PhysicalMaterial::RoughDielectric {
                    eta,
                    roughness: alpha,
                    tint,
                    abbe,
                });
            }
            m
        }
        "thin_glass" => {
            let eta = ior(&mut t)?;
            let tint = t.param("tint", Vec3::ONE)?;
            MaterialDesc {
                transmissive: tint.clone(),
                index: Param::grey(1.0),
                physical: Some(PhysicalMaterial::ThinDielectric { eta, tint }),
                ..MaterialDesc::default()
            }
        }
        "conductor" => {
            let alpha = alpha(&mut t)?;
            let reflectance = match t.get("reflectance")? {
                Some(_) => Some(t.param("reflectance", Vec3::ONE)?),
                None => None,
            };
            let (eta, k) = (t.vec3("eta")?, t.vec3("k")?);
            let (eta, k, reflectance) = match (reflectance, eta, k) {
                (Some(r), None, None) => (Vec3::ONE, Vec3::ZERO, Some(r)),
                (None, Some(eta), Some(k)) => (eta, k, None),
                _ => {
                    return Err(at.error("a conductor has `reflectance`, or `eta` and `k` (each three numbers)"));
                }
            };
            let f0 = match &reflectance {
                Some(Param::Constant(r)) => *r,
                Some(_) => Vec3::splat(0.8),
                None => {
                    let (n, k2) = (eta, k * k);
                    ((n - Vec3::ONE) * (n - Vec3::ONE) + k2) / ((n + Vec3::ONE) * (n + Vec3::ONE) + k2)
                }
            };
            let mut m = MaterialDesc {
                physical: Some(PhysicalMaterial::Conductor {
                    eta,
                    k,
                    reflectance,
                    roughness: alpha,
                }),
                ..MaterialDesc::default()
            };
            m.course_gloss(f0, alpha);
            m
        }
        "mix" => {
            // At each point one of the two, the second with probability `amount` (pbrt's mix).
            let amount = t.share("amount", 0.5)?;
            let parts = t
                .get("materials")?
                .ok_or_else(|| at.key("materials").error("required"))?;
            let list = parts
                .cast::<PyList>()
                .map_err(|_| at.key("materials").type_error("expected a list of two materials"))?;
            if list.len() != 2 {
                return Err(at.key("materials").error(format!("two materials, not {}", list.len())));
            }
            let first = material(&list.get_item(0)?, at.key("materials").index(0), media)?;
            let second = material(&list.get_item(1)?, at.key("materials").index(1), media)?;
            // The course model reads the larger part (the first where a texture decides).
            let mut m = match amount {
                Param::Constant(a) if a.x >= 0.5 => second.clone(),
                _ => first.clone(),
            };
            m.mix = Some(Box::new(MixDesc {
                materials: [first, second],
                amount,
            }));
            m
        }
        "coated" => {
            let base = t.param("reflectance", Vec3::splat(0.5))?;
            let (eta, alpha) = (ior(&mut t)?, alpha(&mut t)?);
            let layerings = [
                ("layered", Coating::Layered),
                ("fresnel", Coating::Fresnel),
                ("added", Coating::Added),
            ];
            let layering = t.choice("layering", &layerings)?.unwrap_or(Coating::Layered);
            MaterialDesc::coated(base, eta, alpha, layering)
        }
        other => {
            return Err(at.key("type").error(format!(
                "\"diffuse\", \"glass\", \"thin_glass\", \"conductor\", \"coated\", \"mix\" or \"boundary\", not \"{other}\""
            )))
        }
    };
    // The media inside and outside the object (names in `media`); outside defaults to whatever
    // surrounds it.
    let side = |t: &mut Table, key: &str| -> PyResult<Option<MediumSide>> {
        match t.string(key)? {
            None => Ok(None),
            Some(name) => match media.get(&name) {
                Some(&n) => Ok(Some(MediumSide::Medium(Some(n)))),
                None => Err(at.key(key).error(format!("no medium named \"{name}\" in `media`"))),
            },
        }
    };
    let (inside, outside) = (side(&mut t, "inside")?, side(&mut t, "outside")?);
    if inside.is_some() || outside.is_some() {
        m.interface = Some(InterfaceDesc {
            inside: inside.unwrap_or(MediumSide::Medium(None)),
            outside: outside.unwrap_or(MediumSide::Surrounding),
        });
    } else if m.boundary {
        return Err(at.error("a boundary has a medium `inside` (or `outside`)"));
    }
    if roughness_map.is_some() {
        if m.mix.is_some() {
            return Err(at.key("roughness").error("a mix's roughness is its parts'"));
        }
        m.roughness_map = roughness_map;
    }
    // What the surface emits, its normal map and coat hold for a mix's parts too: the part
    // shown at a point is what the light and camera paths see there.
    let emission = t.param("emission", Vec3::ZERO)?;
    if matches!(emission, Param::Constant(e) if e.min_element() < 0.0) {
        return Err(at.key("emission").error("a radiance is not negative"));
    }
    if emission != Param::grey(0.0) {
        let faces = if t.flag("two_sided", false)? {
            EmittingFaces::Both
        } else {
            EmittingFaces::Front
        };
        every_part(&mut m, &mut |p| {
            p.emissive = emission.clone();
            p.emitting_faces = faces;
        });
    }
    if let Some(c) = t.get("clearcoat")? {
        let (coat, maps) = clearcoat(&c, at.key("clearcoat"))?;
        every_part(&mut m, &mut |p| {
            p.clearcoat = Some(coat);
            p.clearcoat_maps = maps.clone();
        });
    }
    let coverage = t.param_encoded("coverage", Vec3::ONE, Encoding::Coverage)?;
    let cutoff = match t.float("coverage_cutoff", -1.0)? {
        c if c < 0.0 => None,
        c if c <= 1.0 => Some(c),
        c => {
            return Err(at
                .key("coverage_cutoff")
                .error(format!("a cutoff between 0 and 1, not {c}")))
        }
    };
    match coverage {
        Param::Constant(c) if c.x >= 1.0 => {}
        Param::Constant(c) if c.x < 0.0 => {
            return Err(at
                .key("coverage")
                .error(format!("a share between 0 and 1, not {}", c.x)))
        }
        coverage => m.alpha = Some(Alpha { coverage, cutoff }),
    }
    if let Some(n) = t.get("normal_map")? {
        let at = at.key("normal_map");
        let mut nt = Table::new(&n, at.clone())?;
        let scale = nt.float("strength", 1.0)?;
        let file = nt.get("file")?.ok_or_else(|| at.key("file").error("required"))?;
        nt.done()?;
        let spec = PyDict::new(n.py());
        spec.set_item("file", file)?;
        // Tangent-space normals are data: linear.
        let map = image_map(&spec, at.clone(), Encoding::Linear)?;
        let normal_map = NormalMap { map, scale };
        every_part(&mut m, &mut |p| p.normal_map = Some(normal_map.clone()));
    }
    t.done()?;
    Ok(m)
}

/// Applies `f` to a material and, for a mix, to each of its parts.
fn every_part(m: &mut MaterialDesc, f: &mut dyn FnMut(&mut MaterialDesc)) {
    f(m);
    if let Some(mix) = m.mix.as_mut() {
        for part in &mut mix.materials {
            every_part(part, f);
        }
    }
}

/// A clear coat: `{"weight": share, "roughness": r (α = r²), "ior": n}`, weight and roughness
/// numbers or textures (linear; the weight's first channel, the roughness's second).
fn clearcoat(value: &Bound<'_, PyAny>, at: At) -> PyResult<(ClearCoat, Option<ClearCoatMaps>)> {
    let mut t = Table::new(value, at.clone())?;
    let weight = t.share("weight", 1.0)?;
    let roughness = t.share("roughness", 0.0)?;
    let eta = t.float("ior", 1.5)?;
    if eta < 1.0 {
        return Err(at
            .key("ior")
            .error(format!("an index of refraction is at least 1, not {eta}")));
    }
    t.done()?;
    let constant = |p: &Param| match p {
        Param::Constant(c) => Some(c.x),
        _ => None,
    };
    let r = constant(&roughness).unwrap_or(0.5);
    let coat = ClearCoat {
        weight: constant(&weight).unwrap_or(1.0),
        eta,
        alpha: r * r,
    };
    let maps = ClearCoatMaps {
        weight: constant(&weight).is_none().then_some(weight),
        roughness: constant(&roughness).is_none().then_some(roughness),
    };
    let any = maps.weight.is_some() || maps.roughness.is_some();
    Ok((coat, any.then_some(maps)))
}

fn shape(
    value: &Bound<'_, PyAny>,
    at: At,
    materials: &HashMap<String, MaterialDesc>,
    meshes: &HashMap<String, TrimeshDesc>,
) -> PyResult<ObjectDesc> {
    let mut t = Table::new(value, at.clone())?;
    let kind = t.string("type")?.ok_or_else(|| at.key("type").error("required"))?;
    let name = t
        .string("material")?
        .ok_or_else(|| at.key("material").error("required"))?;
    let material = materials
        .get(&name)
        .cloned()
        .ok_or_else(|| at.key("material").error(format!("no material named \"{name}\"")))?;
    let placed = match t.get("matrix")? {
        Some(m) => matrix(&m, &at.key("matrix"))?,
        None => Mat4::IDENTITY,
    };
    let (shape, world) = match kind.as_str() {
        "sphere" => {
            let centre = t.vec3("center")?.unwrap_or(Vec3::ZERO);
            let radius = t.float("radius", 1.0)?;
            if radius <= 0.0 {
                return Err(at.key("radius").error(format!("a radius is above 0, not {radius}")));
            }
            let local = Mat4::from_translation(centre) * Mat4::from_scale(Vec3::splat(radius));
            (ShapeDesc::Sphere, placed * local)
        }
        "mesh" => (ShapeDesc::Trimesh(Box::new(mesh(&mut t, &at)?)), placed),
        "instance" => {
            let name = t.string("mesh")?.ok_or_else(|| at.key("mesh").error("required"))?;
            let mesh = meshes
                .get(&name)
                .ok_or_else(|| at.key("mesh").error(format!("no mesh named \"{name}\" in `meshes`")))?;
            (ShapeDesc::Trimesh(Box::new(mesh.clone())), placed)
        }
        other => {
            return Err(at
                .key("type")
                .error(format!("\"mesh\", \"instance\" or \"sphere\", not \"{other}\"")))
        }
    };
    t.done()?;
    Ok(ObjectDesc {
        shape,
        world_from_object: world,
        material,
        span: 0..0,
    })
}

fn mesh(t: &mut Table, at: &At) -> PyResult<TrimeshDesc> {
    let positions = t
        .get("positions")?
        .ok_or_else(|| at.key("positions").error("required"))?;
    let positions = array(&positions, 3, &at.key("positions"))?;
    let points: Vec<Vec3> = rows3(&positions, &at.key("positions"))?;
    let n = points.len();
    let indices = t.get("indices")?.ok_or_else(|| at.key("indices").error("required"))?;
    let np = indices.py().import("numpy")?;
    let indices = np.call_method1("ascontiguousarray", (&indices, "int64")).map_err(|e| {
        at.key("indices")
            .type_error(format!("not an array of whole numbers ({e})"))
    })?;
    let indices = indices
        .cast_into::<numpy::PyArray2<i64>>()
        .map_err(|_| at.key("indices").error("expected an array of shape (m, 3)"))?;
    let indices = indices.readonly();
    if indices.shape()[1] != 3 {
        return Err(at
            .key("indices")
            .error(format!("expected an array of shape (m, 3), not {:?}", indices.shape())));
    }
    let flat = indices
        .as_slice()
        .map_err(|_| at.key("indices").error("not contiguous"))?;
    let mut triangles = Vec::with_capacity(flat.len() / 3);
    for (i, tri) in flat.chunks_exact(3).enumerate() {
        let mut out = [0u32; 3];
        for (j, &v) in tri.iter().enumerate() {
            if v < 0 || v as usize >= n {
                return Err(at
                    .key("indices")
                    .index(i)
                    .error(format!("vertex {v} is out of range ({n} vertices)")));
            }
            out[j] = v as u32;
        }
        triangles.push(out);
    }
    let normals = match t.get("normals")? {
        Some(v) => {
            let a = array(&v, 3, &at.key("normals"))?;
            let normals = rows3(&a, &at.key("normals"))?;
            if normals.len() != n {
                return Err(at
                    .key("normals")
                    .error(format!("{} rows for {n} vertices", normals.len())));
            }
            Some(normals)
        }
        None => None,
    };
    let uvs = match t.get("uvs")? {
        Some(v) => {
            let a = array(&v, 2, &at.key("uvs"))?;
            let s = a.as_slice().map_err(|_| at.key("uvs").error("not contiguous"))?;
            let uvs: Vec<Vec2> = s.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect();
            if uvs.len() != n {
                return Err(at.key("uvs").error(format!("{} rows for {n} vertices", uvs.len())));
            }
            Some(uvs)
        }
        None => None,
    };
    let tangents = match t.get("tangents")? {
        Some(v) => {
            let a = array(&v, 4, &at.key("tangents"))?;
            let s = a.as_slice().map_err(|_| at.key("tangents").error("not contiguous"))?;
            let tangents: Vec<Vec4> = s.chunks_exact(4).map(Vec4::from_slice).collect();
            if tangents.len() != n {
                return Err(at
                    .key("tangents")
                    .error(format!("{} rows for {n} vertices", tangents.len())));
            }
            if let Some(i) = tangents.iter().position(|v| !v.is_finite()) {
                return Err(at.key("tangents").index(i).error("not finite"));
            }
            Some(tangents)
        }
        None => None,
    };
    Ok(TrimeshDesc {
        points,
        triangles,
        normals,
        materials: None,
        uvs,
        tangents,
    })
}

fn rows3(a: &PyReadonlyArray2<'_, f32>, at: &At) -> PyResult<Vec<Vec3>> {
    let s = a.as_slice().map_err(|_| at.error("not contiguous"))?;
    let rows: Vec<Vec3> = s.chunks_exact(3).map(Vec3::from_slice).collect();
    if let Some(i) = rows.iter().position(|p| !p.is_finite()) {
        return Err(at.index(i).error("not finite"));
    }
    Ok(rows)
}

fn light(value: &Bound<'_, PyAny>, at: At) -> PyResult<LightDesc> {
    let mut t = Table::new(value, at.clone())?;
    let kind = t.string("type")?.ok_or_else(|| at.key("type").error("required"))?;
    let span = 0..0;
    let direction = |t: &mut Table| -> PyResult<Vec3> {
        let d = t.required_vec3("direction")?;
        if d.length_squared() == 0.0 {
            return Err(at.key("direction").error("a direction is not zero"));
        }
        Ok(d)
    };
    let light = match kind.as_str() {
        "point" => LightDesc::Point {
            position: t.required_vec3("position")?,
            color: t.colour("intensity", Vec3::ONE)?,
            attenuation: [0.0, 0.0, 1.0],
            span,
        },
        "spot" => {
            let outer = t.float("angle", 45.0)?;
            let inner = t.float("inner_angle", outer)?;
            let exponent = t.float("exponent", 0.0)?;
            if exponent < 0.0 {
                return Err(at
                    .key("exponent")
                    .error(format!("a falloff exponent is not negative, not {exponent}")));
            }
            if !(0.0..=90.0).contains(&outer) || !(0.0..=outer).contains(&inner) {
                return Err(at.error(format!(
                    "0 ≤ inner_angle ≤ angle ≤ 90 (degrees from the axis), not {inner} and {outer}"
                )));
            }
            LightDesc::Spot {
                position: t.required_vec3("position")?,
                direction: direction(&mut t)?,
                color: t.colour("intensity", Vec3::ONE)?,
                attenuation: [0.0, 0.0, 1.0],
                inner_degrees: inner,
                outer_degrees: outer,
                exponent,
                span,
            }
        }
        "sun" => {
            let direction = direction(&mut t)?;
            let color = t.colour("irradiance", Vec3::ONE)?;
            match t.float("angle", 0.0)? {
                a if a > 0.0 => LightDesc::Sun {
                    direction,
                    color,
                    angle_degrees: a,
                    span,
                },
                _ => LightDesc::Directional { direction, color, span },
            }
        }
        "sphere" => {
            let radius = t.float("radius", 0.0)?;
            if radius < 0.0 {
                return Err(at
                    .key("radius")
                    .error(format!("a radius is not negative, not {radius}")));
            }
            // A ball of intensity I in every direction: radiance I/(πr²) over its surface.
            LightDesc::Soft {
                shape: SoftShapeDesc::Sphere {
                    center: t.required_vec3("position")?,
                    radius,
                },
                color: t.colour("intensity", Vec3::ONE)?,
                attenuation: [0.0, 0.0, 1.0],
                span,
            }
        }
        "area" => {
            let (corner, u, v) = (t.required_vec3("corner")?, t.required_vec3("u")?, t.required_vec3("v")?);
            if u.cross(v).length_squared() == 0.0 {
                return Err(at.error("the edges `u` and `v` span no area"));
            }
            let ellipse = t.choice("shape", &[("rectangle", false), ("ellipse", true)])?;
            let shape = if ellipse == Some(true) {
                SoftShapeDesc::Ellipse { corner, u, v }
            } else {
                SoftShapeDesc::Parallelogram { corner, u, v }
            };
            LightDesc::Soft {
                shape,
                color: t.colour("radiance", Vec3::ONE)?,
                attenuation: [0.0, 0.0, 1.0],
                span,
            }
        }
        "environment" => {
            let color = t.colour("radiance", Vec3::ONE)?;
            let map = image_source(&mut t, &at)?;
            let rotation = match t.get("rotation")? {
                Some(r) => rotation(&r, &at.key("rotation"))?,
                None => Mat3::IDENTITY,
            };
            LightDesc::Environment {
                color,
                map,
                rotation,
                equal_area: false,
                span,
            }
        }
        other => {
            return Err(at.key("type").error(format!(
                "\"point\", \"sphere\", \"spot\", \"sun\", \"area\" or \"environment\", not \"{other}\""
            )))
        }
    };
    t.done()?;
    Ok(light)
}
