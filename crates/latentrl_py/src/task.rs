//! Binding of `sim::task`: a task (file or dict) as `Task`, and what runs on it in one call: its
//! trials (`sim::task::TaskTrials`) and its latent survey (`sim::task::survey`).

use std::path::PathBuf;
use std::sync::Arc;

use ::sim::task::survey::{DEFAULT_MAX_POINTS, TaskSurvey};
use ::sim::task::{Task, TaskConfig, TaskTrials};
use ::sim::urdf::ShapeSummary;
use numpy::{PyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{config_from, config_to, rows};
use crate::errors::{guard, sim_to_py, to_py};
use crate::projection::EncoderObject;
use crate::runner::{RunArguments, latent_args, named_arrays, run_with_polling};

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
    #[pyo3(signature = (config, base_dir = PathBuf::from(Task::CONFIG_BASE_DIR), origin = Task::CONFIG_ORIGIN))]
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
    weights: Option<PyReadonlyArray2<'py, f64>>,
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
        let (task, weights) = (Arc::clone(&task.inner), rows("weights", weights)?.unwrap_or_default());
        let trials = TaskTrials::new(task, demos.as_deref(), &latent, &weights, options).map_err(sim_to_py)?;
        let total = trials.options.total_episodes();
        let results = run_with_polling(py, total, progress.as_ref(), |c, d| trials.run(c, d).map_err(sim_to_py))?;
        named_arrays(py, trials.arrays(&results))
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
        let latent = latent_args(Some(&decoder), None, Some(latent_low), Some(latent_high))?;
        let demos = rows("demos", demos)?;
        let task = Arc::clone(&task.inner);
        let survey = TaskSurvey::new(task, demos.as_deref(), latent, max_points, physics).map_err(sim_to_py)?;
        let s = run_with_polling(py, survey.points(), progress.as_ref(), |cancel, done| {
            survey.run(cancel, done).map_err(sim_to_py)
        })?;
        let out = named_arrays(py, s.arrays())?;
        out.update(config_to(py, &s.summary())?.cast()?)?;
        Ok(out)
    })
}
