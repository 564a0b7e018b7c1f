//! `caustica.Scene` and `caustica.render()`.

use crate::arrays::film_array;
use crate::options::{self, Options};
use crate::run_interruptible;
use caustica::description::RenderHints;
use caustica::format::Format;
use caustica::integrator::config::thread_pool;
use caustica::integrator::{image_size, RenderSession};
use caustica::loader::{load_timed, LoadSettings};
use caustica::progress::{Control, NoProgress};
use caustica::scene::summary::{LoadSeconds, SceneReport};
use caustica::scene::Scene;
use caustica::Error;
use numpy::PyArray3;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// A scene file read and built once, to render or query many times.
///
/// `Scene(path)` reads a `.ray` file; `Scene()` is the built-in ring scene (what
/// `caustica render` renders without a file). `cone_quirks` and `dialect` are the command
/// line's `--cone-quirks` and `--dialect`. A malformed file raises `SceneError`, whose message
/// begins with file:line:col.
#[pyclass(name = "Scene", module = "caustica", frozen)]
pub struct PyScene {
    pub(crate) loaded: Arc<LoadedScene>,
}

/// A built scene and what the front ends say of it.
pub struct LoadedScene {
    /// The scene.
    pub scene: Scene,
    /// What identifies it in a render's fingerprint (so parts merge with the command line's).
    pub scene_id: String,
    /// The file as the user named it.
    pub name: String,
    /// `info()` as JSON text.
    pub report: String,
    /// Seconds spent reading and building it.
    pub seconds: (f64, f64),
}

impl LoadedScene {
    /// Reads and builds the scene at `path` (the built-in ring for `None`).
    pub fn load(path: Option<PathBuf>, settings: &LoadSettings) -> caustica::Result<LoadedScene> {
        let loaded = load_timed(path.as_deref(), settings, &NoProgress)?;
        let name = path.map_or_else(|| "<built-in ring scene>".to_string(), |p| p.display().to_string());
        let summary = loaded.scene.summary();
        let report = serde_json::to_string(&SceneReport {
            scene: name.clone(),
            summary: &summary,
            seconds: LoadSeconds {
                parse: loaded.parse_seconds,
                build: loaded.build_seconds,
            },
        })
        .map_err(|e| Error::InvalidSettings(format!("cannot describe the scene: {e}")))?;
        Ok(LoadedScene {
            scene: loaded.scene,
            scene_id: loaded.scene_id,
            name,
            report,
            seconds: (loaded.parse_seconds, loaded.build_seconds),
        })
    }
}

#[pymethods]
impl PyScene {
    #[new]
    #[pyo3(signature = (path=None, *, cone_quirks=false, dialect=None))]
    fn new(py: Python<'_>, path: Option<PathBuf>, cone_quirks: bool, dialect: Option<String>) -> PyResult<PyScene> {
        let settings = LoadSettings::new(cone_quirks, dialect.as_deref()).map_err(|e| crate::to_py(py, e))?;
        let cancel = Arc::new(AtomicBool::new(false));
        // Loading cannot be cancelled: after Ctrl-C it finishes unseen.
        let loaded = run_interruptible(py, &cancel, false, move || LoadedScene::load(path, &settings))?;
        Ok(PyScene {
            loaded: Arc::new(loaded),
        })
    }

    /// What was read, as a dict: the same as `caustica info --json` prints (`scene`, `camera`,
    /// `lights`, `area_lights`, `ambient`, counts, `objects`, `materials`, `bounds`,
    /// `warnings`, and `seconds` spent reading and building).
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        py.import("json")?.call_method1("loads", (self.loaded.report.as_str(),))
    }

    /// The file as it was named (`<built-in ring scene>` for the built-in one).
    #[getter]
    fn path(&self) -> String {
        self.loaded.name.clone()
    }

    /// Remarks made while reading and building.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.loaded.scene.warnings().to_vec()
    }

    /// The image size (width, height) a render of `width` pixels has: the height follows the
    /// camera's aspect ratio unless given.
    #[pyo3(signature = (width=512, height=None))]
    fn size(&self, width: usize, height: Option<usize>) -> (usize, usize) {
        image_size(self.loaded.scene.camera(), width, height)
    }

    /// What a render at this size does when its aspect differs from the camera's (the picture
    /// cropped or extended by the format's rule, never stretched), in words; `None` when it
    /// does not differ.
    #[pyo3(signature = (width=512, height=None))]
    fn camera_fit(&self, width: usize, height: Option<usize>) -> Option<String> {
        let (width, height) = image_size(self.loaded.scene.camera(), width, height);
        self.loaded.scene.camera().fit_note(width, height)
    }

    fn __repr__(&self) -> String {
        format!("caustica.Scene({:?})", self.loaded.name)
    }
}

/// A scene given to a function: a `Scene`, a path, or none (the built-in ring).
#[derive(FromPyObject)]
pub enum SceneArg {
    /// Already loaded.
    Loaded(Py<PyScene>),
    /// A file to read.
    Path(PathBuf),
}

/// Where a worker finds its scene.
pub enum SceneSource {
    /// Loaded already.
    Loaded(Arc<LoadedScene>),
    /// To be read on the worker thread.
    File(Option<PathBuf>, LoadSettings),
}

impl SceneSource {
    /// The scene of `scene`, with the load options given among `options` (refused beside a
    /// `Scene`, which was read with its own).
    pub fn new(py: Python<'_>, scene: Option<SceneArg>, options: &Options) -> PyResult<SceneSource> {
        match scene {
            Some(SceneArg::Loaded(scene)) => {
                if options.load.is_some() {
                    return Err(PyValueError::new_err(
                        "cone_quirks and dialect apply when a file is read: give them to caustica.Scene()",
                    ));
                }
                Ok(SceneSource::Loaded(Arc::clone(&scene.bind(py).get().loaded)))
            }
            Some(SceneArg::Path(path)) => Ok(SceneSource::File(Some(path), options.load.clone().unwrap_or_default())),
            None => Ok(SceneSource::File(None, options.load.clone().unwrap_or_default())),
        }
    }

    /// The options over what is known of the scene before it is read (a scene already read, or
    /// a pbrt or glTF file's physical units), checked as the command line checks them first.
    pub fn check_early(&self, options: &Options) -> caustica::Result<()> {
        let hints = match self {
            SceneSource::Loaded(scene) => scene.scene.hints().clone(),
            SceneSource::File(path, settings) => RenderHints {
                physical: path
                    .as_deref()
                    .is_some_and(|p| matches!(settings.read.format_of(p), Format::Pbrt | Format::Gltf)),
                ..RenderHints::default()
            },
        };
        options.config.clone().over_scene(&options.given, &hints).integrator()?;
        Ok(())
    }

    /// The scene, read now if need be.
    pub fn load(self) -> caustica::Result<Arc<LoadedScene>> {
        match self {
            SceneSource::Loaded(scene) => Ok(scene),
            SceneSource::File(path, settings) => LoadedScene::load(path, &settings).map(Arc::new),
        }
    }
}

/// Renders a scene and returns the image: a float32 array of shape (height, width, 3), linear
/// RGB, rows from the top — the pixels `caustica render SCENE --… -o image.exr` writes with the
/// same options.
///
/// `scene` is a `Scene`, a path, or None for the built-in ring. The options are the command
/// line's, `-` written `_`: model, integrator, width, height, aa, depth, threads, seed, photons,
/// max_emitted, photons_per_light, no_aim, max_memory, k, radius, cone_filter,
/// no_estimate_reuse, passes (N or "A..B"), time, partial (a path: the sums of the passes are
/// saved there, for merge()), footprint, alpha, no_camera_specular, spectral (True, False or
/// None for the default: spectral when a glass disperses), no_spectral, cone_quirks, dialect.
///
/// The GIL is released while it renders; Ctrl-C stops the render and raises KeyboardInterrupt
/// (a partial file still gets the passes completed).
#[pyfunction]
#[pyo3(signature = (scene=None, **options))]
pub fn render<'py>(
    py: Python<'py>,
    scene: Option<SceneArg>,
    options: Option<&Bound<'py, PyDict>>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let options = options::parse(py, "render", options::RENDER, options)?;
    let source = SceneSource::new(py, scene, &options)?;
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&cancel);
    let film = run_interruptible(py, &cancel, true, move || {
        // In the command line's order: options, then the scene, then the two together.
        source.check_early(&options)?;
        let pool = thread_pool(options.threads)?;
        let loaded = source.load()?;
        let config = options.config.over_scene(&options.given, loaded.scene.hints());
        config.integrator()?;
        let plan = config.plan()?;
        let mut session = RenderSession::new(&loaded.scene, config.render_options(loaded.scene_id.clone())?)?;
        let control = Control {
            progress: &NoProgress,
            cancel: &flag,
        };
        pool.install(|| session.run(&plan, control, |_| Ok(())))?;
        if session.pass_count() == 0 {
            return Err(Error::Interrupted);
        }
        if let Some(path) = &config.partial {
            session.accumulator().save(path)?;
        }
        Ok(session.image())
    })?;
    film_array(py, &film)
}
