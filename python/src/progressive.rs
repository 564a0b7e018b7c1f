//! `caustica.progressive()`: a render session run pass by pass from a Python loop, and
//! `caustica.merge()`, the command line's `caustica merge`.
//!
//! The session borrows its scene, so it lives on a worker thread of its own that owns the
//! scene; each Python call sends it a job and waits for the answer ([`crate::wait`]).

use crate::arrays::film_array;
use crate::options::{self, RENDER};
use crate::scene::{SceneArg, SceneSource};
use crate::{wait, InternalError, Outcome};
use caustica::film::Film;
use caustica::integrator::config::thread_pool;
use caustica::integrator::partial::merge_files;
use caustica::integrator::{PassPlan, RenderSession, Resize, RunSummary};
use caustica::progress::{Control, NoProgress};
use caustica::Error;
use numpy::PyArray3;
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, Sender};
use std::sync::Arc;
use std::time::Instant;

/// Work for the session's thread.
type Job = Box<dyn for<'a> FnOnce(&mut Worker<'a>) + Send>;

/// The session and where its plan stands, on the worker thread.
struct Worker<'a> {
    session: RenderSession<'a>,
    plan: PassPlan,
    pool: rayon::ThreadPool,
    cancel: Arc<AtomicBool>,
    stopped: Arc<AtomicBool>,
    /// The next pass to consider.
    next: u64,
    /// When the first pass began (the plan's time limit counts from there).
    start: Option<Instant>,
    /// The cost of the passes this run rendered, in full passes.
    cost_done: f64,
    /// The last pass was resized to the time left: the next call ends the run.
    finished_after: bool,
    partial: Option<PathBuf>,
    save_every: f64,
    last_save: Instant,
    finished: bool,
    /// Seconds spent reading and building the scene.
    load_seconds: (f64, f64),
}

impl Worker<'_> {
    /// The run so far as the library reports it, in JSON.
    fn report(&self) -> caustica::Result<String> {
        let render = self.start.map_or(0.0, |s| s.elapsed().as_secs_f64());
        let summary = RunSummary {
            complete: self.finished && !self.cancel.load(Ordering::SeqCst),
            photon_seconds: self.session.photon_seconds(),
            render_seconds: (render - self.session.photon_seconds()).max(0.0),
        };
        let (parse, build) = self.load_seconds;
        let report = self.session.report(&summary, self.load_seconds, parse + build + render);
        serde_json::to_string(&report).map_err(|e| Error::InvalidSettings(format!("cannot report the run: {e}")))
    }
}

impl Worker<'_> {
    /// Renders the plan's next pass that the sums do not hold yet; `None` when the plan is done
    /// or the run was cancelled.
    fn next_pass(&mut self) -> caustica::Result<Option<Film>> {
        if self.finished {
            return Ok(None);
        }
        if self.finished_after {
            self.finish()?;
            return Ok(None);
        }
        if self.stopped.load(Ordering::SeqCst) {
            self.finish()?;
            return Ok(None);
        }
        let start = *self.start.get_or_insert_with(Instant::now);
        // The integrator's work before its first pass (vcm's pilots) counts in the time, and
        // sizes the passes.
        let control = Control {
            progress: &NoProgress,
            cancel: &self.cancel,
        };
        let session = &mut self.session;
        if !self.pool.install(|| session.prepare(control)) {
            if self.stopped.load(Ordering::SeqCst) {
                self.finish()?;
            }
            return Ok(None);
        }
        // The session's rule for a run's passes (under a time limit vcm's last fills it).
        let share = loop {
            let size = self
                .session
                .next_pass(&self.plan, self.next, self.cost_done, start.elapsed().as_secs_f64());
            let share = match size {
                Resize::Stop => {
                    self.finish()?;
                    return Ok(None);
                }
                Resize::To(share) => Some(share),
                Resize::Own => None,
            };
            // A merged part may hold passes of the plan already.
            if !self.session.accumulator().holds(self.next) {
                break share;
            }
            self.next += 1;
        };
        let next_cost = share.unwrap_or_else(|| self.session.pass_cost(self.next));
        let pass = self.next;
        let session = &mut self.session;
        if !self.pool.install(|| session.render_sized_pass(pass, share, control)) {
            // Cancelled: the pass is dropped (by Ctrl-C the caller raises instead).
            if self.stopped.load(Ordering::SeqCst) {
                self.finish()?;
            }
            return Ok(None);
        }
        self.cost_done += next_cost;
        self.next += 1;
        if share.is_some() {
            // A resized pass was sized to the time left: the run ends with it.
            self.finished_after = true;
        }
        if self.partial.is_some() && self.last_save.elapsed().as_secs_f64() >= self.save_every {
            self.save_partial()?;
        }
        Ok(Some(self.session.image()))
    }

    /// The run is over: the sums go to the partial file.
    fn finish(&mut self) -> caustica::Result<()> {
        if !self.finished {
            self.finished = true;
            self.save_partial()?;
        }
        Ok(())
    }

    fn save_partial(&mut self) -> caustica::Result<()> {
        if let Some(path) = &self.partial {
            if self.session.pass_count() > 0 {
                self.session.accumulator().save(path)?;
            }
        }
        self.last_save = Instant::now();
        Ok(())
    }
}

/// A progressive render: iterate over it for the running mean after each pass.
///
/// ```python
/// run = caustica.progressive(scene, model="physical", integrator="ppm", passes=64)
/// for image in run:          # float32 (height, width, 3), the mean of the passes so far
///     ...
/// ```
///
/// `cancel()` (from any thread) stops the pass in flight and ends the iteration; the passes
/// completed stay (`image()`, `save_partial()`). Ctrl-C raises KeyboardInterrupt out of the
/// loop and drops only the pass in flight: iterating again goes on. Used in a `with` block, the
/// run is cancelled when the block ends.
#[pyclass(module = "caustica", frozen)]
pub struct Progressive {
    jobs: Sender<Job>,
    cancel: Arc<AtomicBool>,
    stopped: Arc<AtomicBool>,
    width: usize,
    height: usize,
    integrator: &'static str,
}

impl Progressive {
    /// Runs `job` on the session's thread and waits for its answer; Ctrl-C cancels the pass in
    /// flight, waits for the thread to drop it and raises.
    fn call<T: Send + 'static>(
        &self,
        py: Python<'_>,
        job: impl for<'a> FnOnce(&mut Worker<'a>) -> caustica::Result<T> + Send + 'static,
    ) -> PyResult<T> {
        let (tx, rx) = mpsc::channel::<Outcome<T>>();
        let job: Job = Box::new(move |worker| {
            let _ = tx.send(catch_unwind(AssertUnwindSafe(|| job(worker))));
        });
        self.jobs
            .send(job)
            .map_err(|_| InternalError::new_err("the render session's thread has ended"))?;
        let result = wait(py, &self.cancel, rx, true);
        if result.is_err() && !self.stopped.load(Ordering::SeqCst) {
            // After Ctrl-C the run stays usable.
            self.cancel.store(false, Ordering::SeqCst);
        }
        result
    }
}

#[pymethods]
impl Progressive {
    fn __iter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    fn __next__<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyArray3<f32>>>> {
        match self.call(py, |w| w.next_pass())? {
            Some(film) => film_array(py, &film).map(Some),
            None => Ok(None),
        }
    }

    fn __enter__(slf: PyRef<'_, Self>) -> PyRef<'_, Self> {
        slf
    }

    #[pyo3(signature = (*_args))]
    fn __exit__(&self, _args: &Bound<'_, pyo3::types::PyTuple>) -> bool {
        self.cancel();
        false
    }

    /// Stops the run: the pass in flight is dropped and the iteration ends. Safe to call from
    /// any thread, while another waits for a pass.
    fn cancel(&self) {
        self.stopped.store(true, Ordering::SeqCst);
        self.cancel.store(true, Ordering::SeqCst);
    }

    /// The mean of the passes so far (for the course model: its one image), float32
    /// (height, width, 3).
    fn image<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f32>>> {
        let film = self.call(py, |w| Ok(w.session.image()))?;
        film_array(py, &film)
    }

    /// Adds the sums of partial files of the same run (written by `partial=` here or by
    /// `caustica render --partial`); parts of another run, or holding a pass already here, are
    /// refused. The plan's passes that a part holds are not rendered again.
    #[pyo3(signature = (*parts))]
    fn merge(&self, py: Python<'_>, parts: Vec<PathBuf>) -> PyResult<()> {
        self.call(py, move |w| {
            if !w.session.integrator().is_progressive() {
                return Err(Error::InvalidSettings(
                    "the course model renders one image and keeps no sums to merge".into(),
                ));
            }
            let merged = merge_files(&parts)?;
            w.session.merge(&merged)
        })
    }

    /// Writes the sums of the passes so far to `path` (atomically), for `merge()` or
    /// `caustica merge`.
    fn save_partial(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        self.call(py, move |w| w.session.accumulator().save(&path))
    }

    /// Passes held: rendered here or merged in.
    #[getter]
    fn passes(&self, py: Python<'_>) -> PyResult<u64> {
        self.call(py, |w| Ok(w.session.pass_count()))
    }

    /// The passes held, as half-open ranges (start, end).
    #[getter]
    fn pass_ranges(&self, py: Python<'_>) -> PyResult<Vec<(u64, u64)>> {
        self.call(py, |w| Ok(w.session.accumulator().passes.clone()))
    }

    /// (width, height) of the image.
    #[getter]
    fn size(&self) -> (usize, usize) {
        (self.width, self.height)
    }

    /// The integrator's name: whitted, path, ppm, gi, lt or vcm.
    #[getter]
    fn integrator(&self) -> &'static str {
        self.integrator
    }

    /// What the run did so far, as a dict: the fields `caustica render --json` prints but the
    /// files written and the preview (`integrator`, `model`, `width`, `height`, `complete`,
    /// `seconds`, and the passes and photons a full pass traces, or the course model's photons).
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let text = self.call(py, |w| w.report())?;
        py.import("json")?.call_method1("loads", (text,))
    }

    /// Everything that must agree for two runs' sums to merge (scene, size, seed, settings).
    #[getter]
    fn fingerprint(&self, py: Python<'_>) -> PyResult<String> {
        self.call(py, |w| Ok(w.session.fingerprint().to_string()))
    }
}

impl Drop for Progressive {
    fn drop(&mut self) {
        // The worker stops at its next job: there is none once the sender is gone.
        self.cancel.store(true, Ordering::SeqCst);
    }
}

/// Starts a progressive render of `scene` (a `Scene`, a path, or None for the built-in ring)
/// with `render()`'s options plus `save_every` (seconds between writes of the `partial` file;
/// it is also written when the run ends). Nothing is rendered until it is iterated.
///
/// The physical integrators (path, ppm, gi, lt) yield the running mean after each pass of the plan
/// `passes` (N or "A..B", 64 by default) or until `time` seconds have passed; the course
/// model's Whitted renderer yields its one image.
#[pyfunction]
#[pyo3(signature = (scene=None, **options))]
pub fn progressive(
    py: Python<'_>,
    scene: Option<SceneArg>,
    options: Option<&Bound<'_, PyDict>>,
) -> PyResult<Progressive> {
    let mut allowed = RENDER.to_vec();
    allowed.push("save_every");
    let options = options::parse(py, "progressive", &allowed, options)?;
    let source = SceneSource::new(py, scene, &options)?;
    let cancel = Arc::new(AtomicBool::new(false));
    let stopped = Arc::new(AtomicBool::new(false));
    let (jobs, inbox) = mpsc::channel::<Job>();
    let (ready_tx, ready_rx) = mpsc::channel::<Outcome<(usize, usize, &'static str)>>();
    let (worker_cancel, worker_stopped) = (Arc::clone(&cancel), Arc::clone(&stopped));
    let thread = std::thread::Builder::new()
        .name("caustica-session".into())
        .spawn(move || {
            let save_every = options.save_every;
            let start = || -> caustica::Result<_> {
                source.check_early(&options)?;
                let pool = thread_pool(options.threads)?;
                let loaded = source.load()?;
                let config = options.config.over_scene(&options.given, loaded.scene.hints());
                let integrator = config.integrator()?;
                let plan = if integrator.is_progressive() {
                    config.plan()?
                } else {
                    PassPlan {
                        first: 0,
                        end: Some(1),
                        time_limit: None,
                    }
                };
                Ok((config, plan, pool, loaded))
            };
            let (config, plan, pool, loaded) = match catch_unwind(AssertUnwindSafe(start)) {
                Ok(Ok(started)) => started,
                Ok(Err(e)) => {
                    let _ = ready_tx.send(Ok(Err(e)));
                    return;
                }
                Err(panic) => {
                    let _ = ready_tx.send(Err(panic));
                    return;
                }
            };
            let session = match config
                .render_options(loaded.scene_id.clone())
                .and_then(|o| RenderSession::new(&loaded.scene, o))
            {
                Ok(session) => session,
                Err(e) => {
                    let _ = ready_tx.send(Ok(Err(e)));
                    return;
                }
            };
            let (width, height) = session.size();
            let _ = ready_tx.send(Ok(Ok((width, height, session.integrator().name()))));
            let mut worker = Worker {
                session,
                next: plan.first,
                plan,
                pool,
                cancel: worker_cancel,
                stopped: worker_stopped,
                start: None,
                cost_done: 0.0,
                finished_after: false,
                partial: config.partial,
                save_every,
                last_save: Instant::now(),
                finished: false,
                load_seconds: loaded.seconds,
            };
            while let Ok(job) = inbox.recv() {
                job(&mut worker);
            }
        });
    thread.map_err(|e| InternalError::new_err(format!("cannot start a thread: {e}")))?;
    let (width, height, integrator) = wait(py, &cancel, ready_rx, true)?;
    Ok(Progressive {
        jobs,
        cancel,
        stopped,
        width,
        height,
        integrator,
    })
}

/// Merges the partial files of a run split across processes or machines into its image (the
/// mean of all their passes), as `caustica merge PARTS… -o image.exr` does; with `partial`, the
/// merged sums are also written there. Parts of different runs, or sharing a pass, are refused.
#[pyfunction]
#[pyo3(signature = (parts, *, partial=None))]
pub fn merge<'py>(
    py: Python<'py>,
    parts: Vec<PathBuf>,
    partial: Option<PathBuf>,
) -> PyResult<Bound<'py, PyArray3<f32>>> {
    let cancel = Arc::new(AtomicBool::new(false));
    let film = crate::run_interruptible(py, &cancel, true, move || {
        let merged = merge_files(&parts)?;
        if let Some(path) = &partial {
            merged.save(path)?;
        }
        Ok(merged.film())
    })?;
    film_array(py, &film)
}
