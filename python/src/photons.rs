//! `caustica.photons()`: the course model's caustic photon map as numpy arrays, for plots.

use crate::options::{self, PHOTONS};
use crate::run_interruptible;
use crate::scene::{SceneArg, SceneSource};
use caustica::integrator::config::thread_pool;
use caustica::photon::{EstimateSettings, Estimator, PhotonMap, REFLECTED, REFRACTED};
use caustica::progress::{Control, NoProgress};
use caustica::Error;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

/// The stored caustic photons, one row each, in the photon map's (kd-tree) order — the order of
/// `caustica photons --ply`.
#[pyclass(module = "caustica", frozen)]
pub struct Photons {
    /// float32 (n, 3): where each photon landed, in world space.
    #[pyo3(get)]
    positions: Py<PyArray2<f32>>,
    /// float32 (n, 3): each photon's power (flux), RGB.
    #[pyo3(get)]
    powers: Py<PyArray2<f32>>,
    /// float32 (n, 3): each photon's incoming direction, as the unit vector it travelled along
    /// (pointing into the surface it landed on).
    #[pyo3(get)]
    directions: Py<PyArray2<f32>>,
    /// bool (n,): the path met a mirror.
    #[pyo3(get)]
    reflected: Py<PyArray1<bool>>,
    /// bool (n,): the path went through glass.
    #[pyo3(get)]
    refracted: Py<PyArray1<bool>>,
    count: usize,
    /// Photons emitted to store these.
    #[pyo3(get)]
    emitted: u64,
    /// Whether some light stopped at the emission cap before it stored its share.
    #[pyo3(get)]
    cap_reached: bool,
}

#[pymethods]
impl Photons {
    fn __len__(&self) -> usize {
        self.count
    }

    fn __repr__(&self) -> String {
        format!("caustica.Photons({} stored of {} emitted)", self.count, self.emitted)
    }
}

/// Traces the course model's caustic photons through `scene` (a `Scene`, a path, or None for
/// the built-in ring) with the options of `caustica photons`: photons, max_emitted,
/// photons_per_light, no_aim, max_memory, seed, threads (and cone_quirks, dialect for a path).
/// With the same options a course render (`render()`) gathers from this very map.
#[pyfunction]
#[pyo3(signature = (scene=None, **options))]
pub fn photons(py: Python<'_>, scene: Option<SceneArg>, options: Option<&Bound<'_, PyDict>>) -> PyResult<Photons> {
    let options = options::parse(py, "photons", PHOTONS, options)?;
    let source = SceneSource::new(py, scene, &options)?;
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&cancel);
    let map = run_interruptible(py, &cancel, true, move || {
        source.check_early(&options)?;
        let pool = thread_pool(options.threads)?;
        let loaded = source.load()?;
        let config = options.config.over_scene(&options.given, loaded.scene.hints());
        config.integrator()?;
        let settings = config.photon_settings();
        let control = Control {
            progress: &NoProgress,
            cancel: &flag,
        };
        // Only the photons are returned: the cheapest map will do.
        let estimate = EstimateSettings {
            estimator: Estimator::Nearest,
            k: 1,
            ..EstimateSettings::default()
        };
        let map = pool.install(|| PhotonMap::trace(&loaded.scene, &settings, &estimate, control));
        if control.cancelled() {
            return Err(Error::Interrupted);
        }
        Ok(map)
    })?;
    let stored = map.photons();
    let rows = |f: &dyn Fn(&caustica::photon::Photon) -> [f32; 3]| -> PyResult<Py<PyArray2<f32>>> {
        let data: Vec<f32> = stored.iter().flat_map(f).collect();
        Ok(PyArray1::from_vec(py, data).reshape([stored.len(), 3])?.unbind())
    };
    let flags = |bit: u8| PyArray1::from_vec(py, stored.iter().map(|p| p.flags & bit != 0).collect()).unbind();
    Ok(Photons {
        positions: rows(&|p| p.position.to_array())?,
        powers: rows(&|p| p.power().to_array())?,
        directions: rows(&|p| p.direction().to_array())?,
        reflected: flags(REFLECTED),
        refracted: flags(REFRACTED),
        count: stored.len(),
        emitted: map.stats.emitted,
        cap_reached: map.stats.cap_reached,
    })
}
