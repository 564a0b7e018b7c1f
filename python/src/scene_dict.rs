//! `caustica.Scene.from_dict`: a scene built in memory — a dict of plain values and numpy
//! arrays — read into the format-neutral description every file reader produces
//! (docs/python.md, "Scenes from Python"). Errors name the key and the index at fault.

use caustica::description::{
    CameraDesc, EmittingFaces, FovAxis, ImageMap, ImageSource, LightDesc, MaterialDesc, MixDesc, NormalMap, ObjectDesc,
    Param, PhysicalMaterial, RenderHints, SceneDescription, ShapeDesc, SoftShapeDesc, TrimeshDesc, SMOOTH_ALPHA,
};
use caustica::math::{Mat3, Mat4, Vec2, Vec3, Vec4};
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

    /// A colour that may be a texture: a number, three, or an image (`image_map`).
    fn param(&mut self, key: &str, default: Vec3) -> PyResult<Param> {
        match self.get(key)? {
            Some(v) if v.cast::<PyDict>().is_ok() => {
                image_map(&v, self.at.key(key), Encoding::Srgb).map(|m| Param::Texture(Box::new(m)))
            }
            Some(v) => colour(&v, &self.at.key(key)).map(Param::Constant),
            None => Ok(Param::Constant(default)),
        }
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

/// An image from a file: `{"file": path, "encoding": "srgb" | "linear", "scale": colour,
/// "wrap": "repeat" | "clamp" | "mirror", "filter": "linear" | "nearest"}`; the encoding
/// defaults to `encoding` (sRGB for colours), wrap to repeat, filter to linear.
fn image_map(value: &Bound<'_, PyAny>, at: At, encoding: Encoding) -> PyResult<ImageMap> {
    let mut t = Table::new(value, at.clone())?;
    let file: PathBuf = t
        .string("file")?
        .ok_or_else(|| at.key("file").error("required (an image file: PNG, JPEG, EXR, HDR, …)"))?
        .into();
    if !file.is_file() {
        return Err(at.key("file").error(format!("no file `{}`", file.display())));
    }
    let mut map = ImageMap::colour(ImageSource::File(file), 0..0);
    map.encoding = match t.string("encoding")?.as_deref() {
        None => encoding,
        Some("srgb") => Encoding::Srgb,
        Some("linear") => Encoding::Linear,
        Some(other) => {
            return Err(at
                .key("encoding")
                .error(format!("\"srgb\" or \"linear\", not \"{other}\"")))
        }
    };
    map.sampler.scale = t.colour("scale", Vec3::ONE)?;
    let wrap = match t.string("wrap")?.as_deref() {
        None | Some("repeat") => Wrap::Repeat,
        Some("clamp") => Wrap::Clamp,
        Some("mirror") => Wrap::Mirror,
        Some(other) => {
            return Err(at
                .key("wrap")
                .error(format!("\"repeat\", \"clamp\" or \"mirror\", not \"{other}\"")))
        }
    };
    map.sampler.wrap = [wrap; 2];
    map.sampler.nearest = match t.string("filter")?.as_deref() {
        None | Some("linear") => false,
        Some("nearest") => true,
        Some(other) => {
            return Err(at
                .key("filter")
                .error(format!("\"linear\" or \"nearest\", not \"{other}\"")))
        }
    };
    t.done()?;
    Ok(map)
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
    let mut materials: HashMap<String, MaterialDesc> = HashMap::new();
    if let Some(m) = top.get("materials")? {
        let at = At("materials".into());
        let m = m
            .cast::<PyDict>()
            .map_err(|_| at.type_error("expected a dict of materials by name"))?;
        for (name, value) in m.iter() {
            let name: String = name.extract().map_err(|_| at.type_error("names are strings"))?;
            let material = material(&value, at.key(&name))?;
            materials.insert(name, material);
        }
    }
    if let Some(shapes) = top.get("shapes")? {
        let at = At("shapes".into());
        let list = shapes.cast::<PyList>().map_err(|_| at.type_error("expected a list"))?;
        for (i, s) in list.iter().enumerate() {
            desc.objects.push(shape(&s, at.index(i), &materials)?);
        }
    }
    if let Some(lights) = top.get("lights")? {
        let at = At("lights".into());
        let list = lights.cast::<PyList>().map_err(|_| at.type_error("expected a list"))?;
        for (i, l) in list.iter().enumerate() {
            desc.lights.push(light(&l, at.index(i))?);
        }
    }
    top.done()?;
    Ok(desc)
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
    let fov_axis = match t.string("fov_axis")?.as_deref() {
        None | Some("vertical") => FovAxis::Vertical,
        Some("shorter") => FovAxis::Shorter,
        Some(other) => {
            return Err(at
                .key("fov_axis")
                .error(format!("\"vertical\" or \"shorter\", not \"{other}\"")))
        }
    };
    let size = |t: &mut Table, key: &str| -> PyResult<Option<usize>> {
        match t.get(key)? {
            Some(v) => match v.extract::<usize>() {
                Ok(n) if n > 0 => Ok(Some(n)),
                _ => Err(at.key(key).error("expected a whole number of pixels above 0")),
            },
            None => Ok(None),
        }
    };
    let (width, height) = (size(&mut t, "width")?, size(&mut t, "height")?);
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
    t.done()?;
    let camera = CameraDesc {
        position,
        view,
        up,
        height: 2.0 * (fov.to_radians() * 0.5).tan(),
        aspect_ratio: aspect,
        right,
        fov_axis,
        span: 0..0,
    };
    Ok((camera, (width, height)))
}

/// A material: its `type`'s physical reading, with the course fields that go with it.
fn material(value: &Bound<'_, PyAny>, at: At) -> PyResult<MaterialDesc> {
    let mut t = Table::new(value, at.clone())?;
    let kind = t.string("type")?.ok_or_else(|| at.key("type").error("required"))?;
    let alpha = |t: &mut Table| -> PyResult<f32> {
        let a = t.float("alpha", 0.0)?;
        if !(0.0..=1.0).contains(&a) {
            return Err(at.key("alpha").error(format!("GGX α is between 0 and 1, not {a}")));
        }
        Ok(a)
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
            let amount = t.float("amount", 0.5)?;
            if !(0.0..=1.0).contains(&amount) {
                return Err(at.key("amount").error(format!("a share between 0 and 1, not {amount}")));
            }
            let parts = t
                .get("materials")?
                .ok_or_else(|| at.key("materials").error("required"))?;
            let list = parts
                .cast::<PyList>()
                .map_err(|_| at.key("materials").type_error("expected a list of two materials"))?;
            if list.len() != 2 {
                return Err(at.key("materials").error(format!("two materials, not {}", list.len())));
            }
            let first = material(&list.get_item(0)?, at.key("materials").index(0))?;
            let second = material(&list.get_item(1)?, at.key("materials").index(1))?;
            // The course model reads the larger part.
            let mut m = if amount >= 0.5 { second.clone() } else { first.clone() };
            m.mix = Some(Box::new(MixDesc {
                materials: [first, second],
                amount: Param::grey(amount),
            }));
            m
        }
        "coated" => {
            let base = t.param("reflectance", Vec3::splat(0.5))?;
            let (eta, alpha) = (ior(&mut t)?, alpha(&mut t)?);
            MaterialDesc::coated(base, eta, alpha, true)
        }
        other => {
            return Err(at.key("type").error(format!(
                "\"diffuse\", \"glass\", \"thin_glass\", \"conductor\", \"coated\" or \"mix\", not \"{other}\""
            )))
        }
    };
    let emission = t.param("emission", Vec3::ZERO)?;
    if matches!(emission, Param::Constant(e) if e.min_element() < 0.0) {
        return Err(at.key("emission").error("a radiance is not negative"));
    }
    if emission != Param::grey(0.0) {
        m.emissive = emission;
        if !t.flag("two_sided", false)? {
            m.emitting_faces = EmittingFaces::Front;
        }
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
        m.normal_map = Some(NormalMap { map, scale });
    }
    t.done()?;
    Ok(m)
}

fn shape(value: &Bound<'_, PyAny>, at: At, materials: &HashMap<String, MaterialDesc>) -> PyResult<ObjectDesc> {
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
        other => return Err(at.key("type").error(format!("\"mesh\" or \"sphere\", not \"{other}\""))),
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
    Ok(TrimeshDesc {
        points,
        triangles,
        normals,
        materials: None,
        uvs,
        tangents: None,
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
        "area" => {
            let (corner, u, v) = (t.required_vec3("corner")?, t.required_vec3("u")?, t.required_vec3("v")?);
            if u.cross(v).length_squared() == 0.0 {
                return Err(at.error("the edges `u` and `v` span no area"));
            }
            LightDesc::Soft {
                shape: SoftShapeDesc::Parallelogram { corner, u, v },
                color: t.colour("radiance", Vec3::ONE)?,
                attenuation: [0.0, 0.0, 1.0],
                span,
            }
        }
        "environment" => LightDesc::Environment {
            color: t.colour("radiance", Vec3::ONE)?,
            map: t.string("file")?.map(Into::into),
            rotation: Mat3::IDENTITY,
            equal_area: false,
            span,
        },
        other => {
            return Err(at.key("type").error(format!(
                "\"point\", \"spot\", \"sun\", \"area\" or \"environment\", not \"{other}\""
            )))
        }
    };
    t.done()?;
    Ok(light)
}
