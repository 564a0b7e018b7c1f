//! Keyword options, by the command line's names with `_` for `-`, into the library's
//! `RenderConfig` and the few settings beside it.

use crate::to_py;
use caustica::integrator::{GivenOptions, RenderConfig};
use caustica::loader::LoadSettings;
use caustica::photon::Estimator;
use pyo3::conversion::FromPyObjectOwned;
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyInt, PyString};
use std::path::PathBuf;

/// The options of `render()` (and `progressive()`, which adds `save_every`).
pub const RENDER: &[&str] = &[
    "model",
    "integrator",
    "width",
    "height",
    "aa",
    "depth",
    "threads",
    "seed",
    "photons",
    "max_emitted",
    "photons_per_light",
    "no_aim",
    "max_memory",
    "k",
    "radius",
    "cone_filter",
    "estimate",
    "no_estimate_reuse",
    "passes",
    "time",
    "partial",
    "footprint",
    "alpha",
    "no_camera_specular",
    "vertex_connections",
    "no_beams",
    "spectral",
    "no_spectral",
    "cone_quirks",
    "dialect",
];

/// The options of `photons()`: those of `caustica photons` that choose the photons.
pub const PHOTONS: &[&str] = &[
    "photons",
    "max_emitted",
    "photons_per_light",
    "no_aim",
    "max_memory",
    "seed",
    "threads",
    "cone_quirks",
    "dialect",
];

/// Options as given.
pub struct Options {
    /// Everything that shapes the image.
    pub config: RenderConfig,
    /// Which of the options a scene file also sets were given (not None), so the file's own
    /// settings fill the rest as on the command line ([`RenderConfig::over_scene`]).
    pub given: GivenOptions,
    /// `threads`.
    pub threads: Option<usize>,
    /// `cone_quirks` and `dialect`, when either was given.
    pub load: Option<LoadSettings>,
    /// `save_every` (progressive runs with `partial`).
    pub save_every: f64,
}

/// Reads `kwargs` for `function`, which takes the options named in `allowed`.
pub fn parse(
    py: Python<'_>,
    function: &str,
    allowed: &[&str],
    kwargs: Option<&Bound<'_, PyDict>>,
) -> PyResult<Options> {
    let mut options = Options {
        config: RenderConfig::default(),
        given: GivenOptions::default(),
        threads: None,
        load: None,
        save_every: 10.0,
    };
    let (mut cone_quirks, mut dialect, mut load_given) = (false, None::<String>, false);
    let (mut spectral, mut no_spectral) = (None, false);
    let Some(kwargs) = kwargs else {
        return Ok(options);
    };
    for (key, value) in kwargs.iter() {
        let key: String = key.extract()?;
        if !allowed.contains(&key.as_str()) {
            let hint = match key.as_str() {
                "output" | "o" => " (the image is returned as an array)",
                "quiet" | "json" | "exposure" | "tone_map" => {
                    " (it only changes what the command line prints or writes)"
                }
                _ => "",
            };
            return Err(PyTypeError::new_err(format!(
                "{function}() got an unexpected keyword argument '{key}'{hint}; its options are: {}",
                allowed.join(", ")
            )));
        }
        let v = Value {
            function,
            key: &key,
            value: &value,
        };
        let c = &mut options.config;
        let g = &mut options.given;
        match key.as_str() {
            "model" => {
                c.model = v
                    .optional(Value::text)?
                    .map(|s| s.parse())
                    .transpose()
                    .map_err(|e| to_py(py, e))?;
                g.model_or_integrator |= c.model.is_some();
            }
            "integrator" => {
                c.integrator = v
                    .optional(Value::text)?
                    .map(|s| s.parse())
                    .transpose()
                    .map_err(|e| to_py(py, e))?;
                g.model_or_integrator |= c.integrator.is_some();
            }
            "width" => {
                c.width = v.whole()?;
                g.width = true;
            }
            "height" => {
                c.height = v.optional(Value::whole)?;
                g.height = c.height.is_some();
            }
            "aa" => c.aa = v.whole()?,
            "depth" => {
                c.depth = v.optional(Value::whole)?;
                g.depth = c.depth.is_some();
            }
            "threads" => options.threads = v.optional(Value::whole)?,
            "seed" => c.seed = v.whole()?,
            "photons" => {
                c.photons = v.whole()?;
                c.light_paths = Some(c.photons as u64);
                g.photons = true;
            }
            "max_emitted" => c.max_emitted = v.optional(Value::whole)?,
            "photons_per_light" => c.photons_per_light = v.optional(Value::counts)?,
            "no_aim" => c.no_aim = v.flag()?,
            "max_memory" => c.max_memory = v.whole()?,
            "k" => c.k = v.whole()?,
            "radius" => {
                c.radius = v.optional(Value::number)?.map(|r| r as f32);
                g.radius = c.radius.is_some();
            }
            "cone_filter" => c.cone_filter = v.number()? as f32,
            "estimate" => {
                c.estimator = match v.text()?.as_str() {
                    "kernels" => Estimator::Kernels,
                    "nearest" => Estimator::Nearest,
                    other => {
                        return Err(PyValueError::new_err(format!(
                            "estimate must be 'kernels' or 'nearest', not '{other}'"
                        )))
                    }
                }
            }
            "no_estimate_reuse" => c.no_estimate_reuse = v.flag()?,
            "passes" => {
                c.passes = v.optional(Value::passes)?;
                g.passes = c.passes.is_some();
            }
            "time" => {
                c.time = v.optional(Value::number)?;
                g.time = c.time.is_some();
            }
            "partial" => c.partial = v.optional(Value::path)?,
            "footprint" => c.footprint = v.optional(Value::number)?.map(|px| px as f32),
            "alpha" => c.alpha = v.number()? as f32,
            "no_camera_specular" => c.no_camera_specular = v.flag()?,
            "vertex_connections" => c.vertex_connections = v.flag()?,
            "no_beams" => c.no_beams = v.flag()?,
            "spectral" => spectral = v.optional(Value::flag)?,
            "no_spectral" => no_spectral = v.flag()?,
            "save_every" => options.save_every = v.number()?,
            "cone_quirks" => {
                cone_quirks = v.flag()?;
                load_given = true;
            }
            "dialect" => {
                dialect = v.optional(Value::text)?;
                load_given = true;
            }
            _ => unreachable!("every allowed option is read"),
        }
    }
    // `no_spectral` is the command line's spelling of `spectral=False`.
    options.config.spectral = match (spectral, no_spectral) {
        (Some(true), true) => {
            return Err(PyValueError::new_err(format!(
                "{function}(): spectral=True and no_spectral=True contradict each other"
            )))
        }
        (_, true) => Some(false),
        (given, false) => given,
    };
    if !(options.save_every > 0.0 && options.save_every.is_finite()) {
        return Err(PyValueError::new_err("save_every must be a positive number of seconds"));
    }
    if load_given {
        options.load = Some(LoadSettings::new(cone_quirks, dialect.as_deref()).map_err(|e| to_py(py, e))?);
    }
    Ok(options)
}

/// One keyword's value, read as the type its option takes.
struct Value<'a, 'py> {
    function: &'a str,
    key: &'a str,
    value: &'a Bound<'py, PyAny>,
}

impl<'py> Value<'_, 'py> {
    fn wrong(&self, expected: &str) -> PyErr {
        let shown = self.value.repr().map(|r| r.to_string()).unwrap_or_else(|_| "?".into());
        PyTypeError::new_err(format!(
            "{}(): {} must be {expected}, not {shown}",
            self.function, self.key
        ))
    }

    fn optional<T>(&self, read: impl FnOnce(&Self) -> PyResult<T>) -> PyResult<Option<T>> {
        if self.value.is_none() {
            Ok(None)
        } else {
            read(self).map(Some)
        }
    }

    /// A whole number in the range of `T` (not a bool, though Python counts bools as ints).
    fn whole<T: FromPyObjectOwned<'py>>(&self) -> PyResult<T> {
        if !self.value.is_instance_of::<PyInt>() || self.value.is_instance_of::<PyBool>() {
            return Err(self.wrong("a whole number"));
        }
        self.value.extract::<T>().map_err(|_| {
            PyValueError::new_err(format!(
                "{}(): {} = {} is out of range",
                self.function, self.key, self.value
            ))
        })
    }

    fn number(&self) -> PyResult<f64> {
        if self.value.is_instance_of::<PyBool>() || self.value.is_instance_of::<PyString>() {
            return Err(self.wrong("a number"));
        }
        self.value.extract::<f64>().map_err(|_| self.wrong("a number"))
    }

    fn flag(&self) -> PyResult<bool> {
        self.value.extract::<bool>().map_err(|_| self.wrong("True or False"))
    }

    fn text(&self) -> PyResult<String> {
        self.value.extract::<String>().map_err(|_| self.wrong("a string"))
    }

    fn path(&self) -> PyResult<PathBuf> {
        self.value.extract::<PathBuf>().map_err(|_| self.wrong("a path"))
    }

    /// Photon counts per light: a sequence of whole numbers.
    fn counts(&self) -> PyResult<Vec<usize>> {
        if self.value.is_instance_of::<PyString>() {
            return Err(self.wrong("a list of whole numbers"));
        }
        self.value
            .extract::<Vec<usize>>()
            .map_err(|_| self.wrong("a list of whole numbers"))
    }

    /// `N` (an int) or `"N"` or `"A..B"`, as `--passes` takes.
    fn passes(&self) -> PyResult<String> {
        if self.value.is_instance_of::<PyInt>() && !self.value.is_instance_of::<PyBool>() {
            return Ok(self.value.to_string());
        }
        self.value
            .extract::<String>()
            .map_err(|_| self.wrong("a pass count N or a range \"A..B\""))
    }
}
