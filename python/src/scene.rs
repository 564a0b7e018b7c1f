//! `caustica.Scene` and `caustica.render()`.

use crate::arrays::film_array;
use crate::options::{self, Options};
use crate::run_interruptible;
use caustica::description::{RenderHints, SceneDescription};
use caustica::format::Format;
use caustica::integrator::config::thread_pool;
use caustica::integrator::{image_size, RenderSession};
use caustica::loader::{load_timed, LoadSettings};
use caustica::progress::{Control, NoProgress};
use caustica::scene::build::{build, BuildSettings};
use caustica::scene::summary::{LoadSeconds, SceneReport};
use caustica::scene::Scene;
use caustica::Error;
use numpy::PyArray3;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::fmt::Write;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::Instant;

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
        LoadedScene::new(
            loaded.scene,
            loaded.scene_id,
            name,
            (loaded.parse_seconds, loaded.build_seconds),
        )
    }

    /// Builds a scene described in memory (`Scene.from_dict`), read in `read_seconds`.
    pub fn from_description(desc: SceneDescription, read_seconds: f64) -> caustica::Result<LoadedScene> {
        let start = Instant::now();
        // The description's every value, so that parts of one split render merge only with
        // parts of the same scene.
        let mut id = Fingerprint::default();
        let _ = write!(id, "{desc:?}");
        let scene = build(&desc, &BuildSettings::default())
            .map_err(|e| Error::InvalidSettings(format!("the scene cannot be built: {}", e.message)))?;
        let seconds = (read_seconds, start.elapsed().as_secs_f64());
        LoadedScene::new(
            scene,
            format!("dict:{:016x}", id.0),
            "<scene from a dict>".into(),
            seconds,
        )
    }

    fn new(scene: Scene, scene_id: String, name: String, seconds: (f64, f64)) -> caustica::Result<LoadedScene> {
        let summary = scene.summary();
        let report = serde_json::to_string(&SceneReport {
            scene: name.clone(),
            summary: &summary,
            seconds: LoadSeconds {
                parse: seconds.0,
                build: seconds.1,
            },
        })
        .map_err(|e| Error::InvalidSettings(format!("cannot describe the scene: {e}")))?;
        Ok(LoadedScene {
            scene,
            scene_id,
            name,
            report,
            seconds,
        })
    }
}

/// FNV-1a over text written to it: a stable hash of a description's `Debug` form, without
/// holding the text.
struct Fingerprint(u64);

impl Default for Fingerprint {
    fn default() -> Self {
        Fingerprint(0xcbf2_9ce4_8422_2325)
    }
}

impl std::fmt::Write for Fingerprint {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        for b in s.bytes() {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
        Ok(())
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

    /// A scene described in memory: a dict of a `camera`, `materials` by name, `shapes`
    /// (meshes from numpy arrays, spheres) and `lights`, in radiometric units
    /// (docs/python.md, "Scenes from Python"). A key or value caustica cannot use raises
    /// ValueError or TypeError naming it, e.g. `shapes[1].indices[4]: vertex 9 is out of range`.
    #[staticmethod]
    fn from_dict(py: Python<'_>, description: &Bound<'_, PyAny>) -> PyResult<PyScene> {
        let start = Instant::now();
        let desc = crate::scene_dict::description(description)?;
        let read = start.elapsed().as_secs_f64();
        let cancel = Arc::new(AtomicBool::new(false));
        let loaded = run_interruptible(py, &cancel, false, move || LoadedScene::from_description(desc, read))?;
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
