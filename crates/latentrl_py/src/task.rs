//! Binding of `sim::task`: a task (file or dict) as `Task`, its plant as `TaskPlant`, its
//! trials in one call, and the schema of its keys.

use std::path::PathBuf;
use std::sync::Arc;

use ::sim::task::survey::{DEFAULT_MAX_POINTS, LearnerGrid, survey};
use ::sim::task::{SchemaTable, Task, TaskConfig, TaskPlant, TaskTrials};
use ::sim::urdf::ShapeSummary;
use latent_core::trials::seeded_start;
use latent_core::{EndReason, LatentPolicy, Params, Plant, RunConfig};
use nalgebra::DMatrix;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::convert::{config_from, config_or_default, config_to, points, to_points};
use crate::errors::{guard, sim_to_py, to_py};
use crate::projection::EncoderObject;
use crate::runner::{RunArguments, latent_args, named_arrays, run_with_polling};

/// `classify`'s result: one code per posture and the effector positions.
type CodesEffectorsTargets<'py> = (
    Bound<'py, PyArray1<i8>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// A checked task: its configuration and its robot (docs/tasks.md).
#[pyclass(name = "Task", module = "latentrl._native", frozen)]
pub struct PyTask {
    pub inner: Arc<Task>,
}

#[pymethods]
impl PyTask {
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        guard(|| {
            let task = py.detach(|| Task::load(&path)).map_err(sim_to_py)?;
            Ok(Self { inner: Arc::new(task) })
        })
    }

    #[staticmethod]
    #[pyo3(signature = (config, base_dir = PathBuf::from("."), origin = "<dict>"))]
    fn from_dict(py: Python<'_>, config: &Bound<'_, PyAny>, base_dir: PathBuf, origin: &str) -> PyResult<Self> {
        guard(|| {
            let config: TaskConfig = config_from(origin, config)?;
            let task = py
                .detach(|| Task::from_config(config, &base_dir, origin))
                .map_err(sim_to_py)?;
            Ok(Self { inner: Arc::new(task) })
        })
    }

    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guard(|| config_to(py, self.inner.config()))
    }

    #[getter]
    fn name(&self) -> String {
        self.inner.config().name.clone()
    }

    #[getter]
    fn origin(&self) -> String {
        self.inner.origin().to_string()
    }

    #[getter]
    fn joint_names(&self) -> Vec<&str> {
        self.inner.model().joint_names()
    }

    #[getter]
    fn link_names(&self) -> Vec<&str> {
        self.inner.model().link_names()
    }

    #[getter]
    fn edges(&self) -> Vec<(&str, &str)> {
        self.inner.model().edges()
    }

    fn collision_shapes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let model = self.inner.model();
        config_to(py, &ShapeSummary::all(&model.collision_shapes(), &model.link_names()))
    }

    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.model().warnings().to_vec()
    }

    #[getter]
    fn effectors(&self) -> Vec<String> {
        self.inner.config().effectors.clone()
    }

    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.model().joints().iter().map(|j| j.lower).collect())
    }

    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.model().joints().iter().map(|j| j.upper).collect())
    }

    #[getter]
    fn row_len(&self) -> usize {
        self.inner.row_len()
    }

    #[getter]
    fn rl_dt(&self) -> f64 {
        self.inner.world_config().rl_dt()
    }

    fn __repr__(&self) -> String {
        self.inner.to_string()
    }
}

/// Rows of a `(N, D)` array of postures, or None.
fn rows(name: &str, array: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Option<Vec<Vec<f64>>>> {
    array
        .map(|a| {
            let m = points(name, &a)?;
            Ok(m.column_iter().map(|c| c.iter().copied().collect()).collect())
        })
        .transpose()
}

/// The robot of a task in its world (`sim::task::TaskPlant`).
#[pyclass(name = "TaskPlant", module = "latentrl._native")]
pub struct PyTaskPlant {
    inner: TaskPlant,
}

#[pymethods]
impl PyTaskPlant {
    #[new]
    #[pyo3(signature = (task, demos = None))]
    fn new(py: Python<'_>, task: &PyTask, demos: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Self> {
        guard(|| {
            let demos = rows("demos", demos)?;
            let task = Arc::clone(&task.inner);
            let inner = py
                .detach(|| TaskPlant::new(task, demos.as_deref()))
                .map_err(sim_to_py)?;
            Ok(Self { inner })
        })
    }

    fn reset(&mut self, posture: PyReadonlyArray1<'_, f64>) -> PyResult<Option<u8>> {
        guard(|| Ok(self.inner.reset(&posture.as_array().to_vec()).map(EndReason::code)))
    }

    fn step<'py>(
        &mut self,
        py: Python<'py>,
        target: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(f64, Option<u8>, Bound<'py, PyArray1<f64>>)> {
        guard(|| {
            let target = target.as_array().to_vec();
            let inner = &mut self.inner;
            let (out, reached) = py.detach(|| inner.step_checked(&target)).map_err(sim_to_py)?;
            Ok((
                out.reward,
                out.end.map(EndReason::code),
                PyArray1::from_vec(py, reached),
            ))
        })
    }

    fn classify<'py>(
        &mut self,
        py: Python<'py>,
        postures: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<CodesEffectorsTargets<'py>> {
        guard(|| {
            let postures = points("postures", &postures)?;
            let inner = &mut self.inner;
            let c = py.detach(|| inner.classify(&postures)).map_err(sim_to_py)?;
            Ok((
                PyArray1::from_vec(py, c.codes),
                to_points(py, c.effectors)?,
                to_points(py, c.targets)?,
            ))
        })
    }

    fn sample_start<'py>(&mut self, py: Python<'py>, seed: u64) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, seeded_start(&mut self.inner, seed))
    }

    fn effectors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.effectors().to_vec())
    }

    fn target_position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = self.inner.effectors().len() / 3;
        to_points(py, DMatrix::from_vec(3, e, self.inner.target_position()))
    }

    fn joint_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.world().joint_positions())
    }

    fn targets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.world().targets().to_vec())
    }

    fn row<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.task_row())
    }

    fn link_poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = self.inner.world().link_pose_rows();
        to_points(py, DMatrix::from_vec(7, rows.len() / 7, rows))
    }

    fn constraint_errors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.constraint_errors())
    }

    fn support_margin(&self) -> PyResult<f64> {
        guard(|| self.inner.support_margin().map_err(sim_to_py))
    }

    fn pose_links<'py>(
        &mut self,
        py: Python<'py>,
        base: PyReadonlyArray1<'py, f64>,
        joints: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(|| {
            let base = crate::convert::fixed::<7>("base", &base)?;
            let joints = joints.as_array().to_vec();
            self.inner.place_row(&joints, &base).map_err(sim_to_py)?;
            self.link_poses(py)
        })
    }

    fn center_of_mass<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            Ok(PyArray1::from_vec(
                py,
                self.inner.center_of_mass().map_err(sim_to_py)?.to_vec(),
            ))
        })
    }

    fn reward(&self) -> f64 {
        self.inner.reward()
    }

    fn reached(&self) -> bool {
        self.inner.reached_target()
    }
}

/// A task's trials in parallel (`sim::task::TaskTrials`).
#[pyfunction]
#[pyo3(signature = (
    task, *, decoder, encoder, latent_low, latent_high, n_trials, episodes, base_seed, demos = None,
    weights = None, rollout = None, test_starts = false, first_trial = None, record_episodes = None, test_episodes = None,
    record_test_episodes = None, return_weights = false, progress = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn run_task_trials<'py>(
    py: Python<'py>,
    task: &PyTask,
    decoder: Bound<'py, PyAny>,
    encoder: Bound<'py, PyAny>,
    latent_low: &Bound<'py, PyAny>,
    latent_high: &Bound<'py, PyAny>,
    n_trials: &Bound<'py, PyAny>,
    episodes: &Bound<'py, PyAny>,
    base_seed: &Bound<'py, PyAny>,
    demos: Option<PyReadonlyArray2<'py, f64>>,
    weights: Option<PyReadonlyArray1<'py, f64>>,
    rollout: Option<&str>,
    test_starts: bool,
    first_trial: Option<&Bound<'py, PyAny>>,
    record_episodes: Option<&Bound<'py, PyAny>>,
    test_episodes: Option<&Bound<'py, PyAny>>,
    record_test_episodes: Option<&Bound<'py, PyAny>>,
    return_weights: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        #[rustfmt::skip]
        let (options, progress) = RunArguments { n_trials, episodes, base_seed, first_trial, record_episodes,
            test_episodes, record_test_episodes, return_weights, progress }
            .check(rollout.map(|name| (name.to_string(), test_starts)))?;
        let demos = rows("demos", demos)?;
        let encoder = EncoderObject::extract("encoder", &encoder)?;
        let args = latent_args(Some(&decoder), Some(&encoder), Some(latent_low), Some(latent_high))?;
        let latent = args.check("").map_err(to_py)?;
        let weights = weights.map(|w| w.as_array().to_vec());
        let trials = TaskTrials::new(
            Arc::clone(&task.inner),
            demos.as_deref(),
            &latent,
            weights.as_deref(),
            options,
        )
        .map_err(sim_to_py)?;
        let total = trials.options.total_episodes();
        let results = run_with_polling(py, total, progress.as_ref(), |c, d| trials.run(c, d).map_err(sim_to_py))?;
        let out = named_arrays(py, trials.arrays(&results))?;
        out.set_item("task", config_to(py, trials.task().config())?)?;
        Ok(out)
    })
}

/// The task's latent space at rest (`sim::task::survey`).
#[pyfunction]
#[pyo3(signature = (task, *, decoder, latent_low, latent_high, demos = None, max_points = DEFAULT_MAX_POINTS, physics = false, progress = None))]
#[allow(clippy::too_many_arguments)]
pub fn latent_survey<'py>(
    py: Python<'py>,
    task: &PyTask,
    decoder: Bound<'py, PyAny>,
    latent_low: &Bound<'py, PyAny>,
    latent_high: &Bound<'py, PyAny>,
    demos: Option<PyReadonlyArray2<'py, f64>>,
    max_points: usize,
    physics: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let args = latent_args(Some(&decoder), None, Some(latent_low), Some(latent_high))?;
        let (decoder, low, high) = args.check_box("").map_err(to_py)?;
        let demos = rows("demos", demos)?;
        let task = Arc::clone(&task.inner);
        let at = LearnerGrid::for_survey(&task, demos.as_deref(), &low, &high, max_points).map_err(sim_to_py)?;
        let s = run_with_polling(py, at.grid.len(), progress.as_ref(), |cancel, done| {
            survey(&task, demos.as_deref(), decoder, &at, physics, cancel, done).map_err(sim_to_py)
        })?;
        let out = named_arrays(py, s.arrays())?;
        out.update(config_to(py, &s.summary())?.cast()?)?;
        Ok(out)
    })
}

/// V(z) (Eq. 7) at `points` of a learner's own features.
#[pyfunction]
pub fn learner_values<'py>(
    py: Python<'py>,
    learner: &Bound<'py, PyAny>,
    low: Vec<f64>,
    high: Vec<f64>,
    weights: Option<PyReadonlyArray1<'py, f64>>,
    points: PyReadonlyArray2<'py, f64>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let config: latent_core::LearnerConfig = config_from("learner", learner)?;
        let weights = weights.map(|w| w.as_array().to_vec());
        let policy = LatentPolicy::new(&config, &low, &high, weights.as_deref()).map_err(to_py)?;
        let z = crate::convert::points("points", &points)?;
        let values = py.detach(|| policy.values(&z)).map_err(to_py)?;
        Ok(PyArray1::from_vec(py, values))
    })
}

/// Schema tables as a list of dicts `{key, doc, rule, kind, default}`, one per key.
fn schema_list(py: Python<'_>, tables: Vec<SchemaTable>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for e in tables.into_iter().flat_map(|table| table.entries) {
        let entry = PyDict::new(py);
        entry.set_item("key", e.key)?;
        entry.set_item("doc", e.doc)?;
        entry.set_item("rule", e.rule)?;
        entry.set_item("kind", e.kind)?;
        entry.set_item("default", config_to(py, &e.default)?)?;
        out.append(entry)?;
    }
    Ok(out)
}

/// Every key of a task file, as `schema_list`.
#[pyfunction]
pub fn task_schema(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    guard(|| schema_list(py, TaskConfig::schema_tables()))
}

/// The keys of Experiment 1's configuration, as `schema_list`.
#[pyfunction]
pub fn bimanual_schema(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    guard(|| schema_list(py, ::sim::bimanual::schema_tables()))
}

/// The run settings `run` (a dict of `[run]` keys; defaults for the rest) checked: every key's
/// effective value, or InvalidInputError naming `run.<key>` and its rule.
#[pyfunction]
#[pyo3(signature = (run = None))]
pub fn run_config<'py>(py: Python<'py>, run: Option<&Bound<'py, PyAny>>) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let config: RunConfig = config_or_default("run", run)?;
        config.check_fields("run").map_err(|e| to_py(e.into()))?;
        config_to(py, &config)
    })
}

/// The end reasons by code: their names in results files (0 timeout … 6 success).
#[pyfunction]
pub fn end_reasons() -> Vec<&'static str> {
    EndReason::ALL.iter().map(|e| e.name()).collect()
}

/// A trained latent policy (`latent_core::LatentPolicy`) with its GPLVM maps.
#[pyclass(name = "LatentPolicy", module = "latentrl._native", frozen)]
pub struct PyLatentPolicy {
    policy: LatentPolicy,
    decoder: Py<crate::gp::PyGpMap>,
    encoder: EncoderObject,
}

#[pymethods]
impl PyLatentPolicy {
    #[new]
    fn new(
        learner: &Bound<'_, PyAny>,
        low: Vec<f64>,
        high: Vec<f64>,
        weights: PyReadonlyArray1<'_, f64>,
        decoder: Bound<'_, crate::gp::PyGpMap>,
        encoder: &Bound<'_, PyAny>,
    ) -> PyResult<Self> {
        guard(|| {
            let encoder = EncoderObject::extract("encoder", encoder)?;
            let config: latent_core::LearnerConfig = config_from("learner", learner)?;
            let weights = weights.as_array().to_vec();
            let policy = LatentPolicy::new(&config, &low, &high, Some(&weights)).map_err(to_py)?;
            policy.check_maps(&decoder.get().inner, encoder.get()).map_err(to_py)?;
            #[rustfmt::skip]
            return Ok(Self { policy, decoder: decoder.unbind(), encoder });
        })
    }

    #[allow(clippy::type_complexity)]
    fn act<'py>(
        &self,
        py: Python<'py>,
        posture: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<f64>>,
    )> {
        guard(|| {
            let posture = posture.as_array().to_vec();
            let (decoder, encoder) = (&self.decoder.get().inner, self.encoder.get());
            let a = self.policy.act(decoder, encoder, &posture).map_err(to_py)?;
            let array = |v| PyArray1::from_vec(py, v);
            Ok((array(a.target), array(a.z), array(a.next)))
        })
    }

    fn values<'py>(&self, py: Python<'py>, points: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            let z = crate::convert::points("points", &points)?;
            Ok(PyArray1::from_vec(py, self.policy.values(&z).map_err(to_py)?))
        })
    }
}
