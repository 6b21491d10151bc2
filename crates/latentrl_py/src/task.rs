//! Binding of `sim::task`: a task (file or dict) as `Task`, its plant as `TaskPlant`, its
//! trials in one call, and the schema of its keys.

use std::path::PathBuf;
use std::sync::Arc;

use ::sim::task::survey::{DEFAULT_MAX_POINTS, LearnerGrid, survey};
use ::sim::task::{SchemaTable, Task, TaskConfig, TaskPlant, TaskTrials};
use latent_core::{EndReason, LatentPolicy, Params, Plant, RunConfig, trial_rng};
use nalgebra::DMatrix;
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::convert::{config_from, config_or_default, config_to, points, to_points};
use crate::errors::{guard, sim_to_py, to_py};
use crate::projection::EncoderObject;
use crate::runner::{RunArguments, invalid, latent_args, pack_results, run_with_polling};

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

fn code(end: Option<EndReason>) -> Option<u8> {
    end.map(EndReason::code)
}

#[pymethods]
impl PyTask {
    /// Reads a TOML task file (the URDF path relative to its folder).
    #[staticmethod]
    fn load(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        guard(|| {
            let task = py.detach(|| Task::load(&path)).map_err(sim_to_py)?;
            Ok(Self { inner: Arc::new(task) })
        })
    }

    /// A task from a dict of task-file keys; the URDF path is relative to `base_dir`, `origin`
    /// names the task in errors.
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

    /// Every key with its effective value, as a dict of task-file keys.
    fn to_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        guard(|| config_to(py, self.inner.config()))
    }

    /// The task's name.
    #[getter]
    fn name(&self) -> String {
        self.inner.config().name.clone()
    }

    /// Where the task came from (its file, or the name given).
    #[getter]
    fn origin(&self) -> String {
        self.inner.origin().to_string()
    }

    /// Names of the robot's actuated joints, the columns of its postures.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        crate::convert::owned(self.inner.model().joint_names())
    }

    /// Names of every URDF link, in URDF order.
    #[getter]
    fn link_names(&self) -> Vec<String> {
        crate::convert::owned(self.inner.model().link_names())
    }

    /// `(parent link, child link)` of every URDF joint: the kinematic tree.
    #[getter]
    fn edges(&self) -> Vec<(String, String)> {
        self.inner
            .model()
            .edges()
            .into_iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect()
    }

    /// Every collision shape as a dict (`urdf_info`'s shapes), to draw the robot.
    fn collision_shapes<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let model = self.inner.model();
        crate::urdf::shape_list(py, &model.collision_shapes(), &model.link_names())
    }

    /// What loading its URDF repaired (`balance_inertia` and the like), one sentence each.
    #[getter]
    fn warnings(&self) -> Vec<String> {
        self.inner.model().warnings().to_vec()
    }

    /// The names of the task's effectors.
    #[getter]
    fn effectors(&self) -> Vec<String> {
        self.inner.config().effectors.clone()
    }

    /// Lower joint limits (rad or m; -inf for continuous joints).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.model().joints().iter().map(|j| j.lower).collect())
    }

    /// Upper joint limits.
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.model().joints().iter().map(|j| j.upper).collect())
    }

    /// Columns of a recorded path row: 3 per effector, base pose (7), joints.
    #[getter]
    fn row_len(&self) -> usize {
        self.inner.row_len()
    }

    /// Duration of one RL step (s).
    #[getter]
    fn rl_dt(&self) -> f64 {
        self.inner.world_config().rl_dt()
    }

    fn __repr__(&self) -> String {
        format!(
            "Task({:?}, robot={:?}, joints={}, effectors={:?})",
            self.inner.config().name,
            self.inner.model().name(),
            self.inner.model().joints().len(),
            self.inner.config().effectors
        )
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

/// The robot of a task in its world: the one plant of the learner, the environments and the
/// figures (docs/tasks.md has the rules it applies).
#[pyclass(name = "TaskPlant", module = "latentrl._native")]
pub struct PyTaskPlant {
    inner: TaskPlant,
}

#[pymethods]
impl PyTaskPlant {
    /// The task's robot standing at its home posture: demo `episode.start_demo` of `demos`
    /// `(N, D)` if given, else zeros clamped into the limits.
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

    /// Puts the robot at `posture` (D,); returns None if it may start an episode, else the code
    /// of the rule it breaks (END_REASONS: 1 obstacle, 2 outside the joint limits, 3 drop, 4 fall).
    fn reset(&mut self, posture: PyReadonlyArray1<'_, f64>) -> PyResult<Option<u8>> {
        guard(|| Ok(code(self.inner.reset(&posture.as_array().to_vec()))))
    }

    /// Tracks `target` (D,) for one RL step: `(reward, end code or None, reached posture (D,))`.
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        target: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(f64, Option<u8>, Bound<'py, PyArray1<f64>>)> {
        guard(|| {
            let target = target.as_array().to_vec();
            let d = self.inner.posture_dim();
            if target.len() != d {
                return Err(invalid(format!(
                    "target: expected shape ({d},), got ({},)",
                    target.len()
                )));
            }
            let mut reached = vec![0.0; d];
            let inner = &mut self.inner;
            let out = py.detach(|| inner.step(&target, &mut reached));
            Ok((out.reward, code(out.end), PyArray1::from_vec(py, reached)))
        })
    }

    /// For each posture of `postures` (M, D) at rest: the code of the rule it breaks (0: none;
    /// 1 obstacle, 2 outside the joint limits, 3 drop, 4 fall), the effector positions (M, 3E)
    /// and the target's (M, 3E) in the world (they differ by posture if `target.relative_to`
    /// is set).
    fn classify<'py>(
        &mut self,
        py: Python<'py>,
        postures: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<CodesEffectorsTargets<'py>> {
        guard(|| {
            let postures = points("postures", &postures)?;
            let inner = &mut self.inner;
            let c = py.detach(|| inner.classify(&postures)).map_err(sim_to_py)?;
            let e = self.inner.effectors().len();
            let (effectors, targets) = (
                DMatrix::from_vec(e, c.codes.len(), c.effectors),
                DMatrix::from_vec(e, c.codes.len(), c.targets),
            );
            Ok((
                PyArray1::from_vec(py, c.codes),
                to_points(py, effectors)?,
                to_points(py, targets)?,
            ))
        })
    }

    /// A start posture drawn by the task's start rule (its home plus ±`episode.start_noise`
    /// uniform noise per joint) from ChaCha8 seeded with `seed`.
    fn sample_start<'py>(&mut self, py: Python<'py>, seed: u64) -> Bound<'py, PyArray1<f64>> {
        let mut posture = vec![0.0; self.inner.posture_dim()];
        self.inner.sample_start(&mut trial_rng(seed, 0), &mut posture);
        PyArray1::from_vec(py, posture)
    }

    /// The effector positions (3E,): x, y, z per effector.
    fn effectors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.effectors().to_vec())
    }

    /// The target h* in the world now (E, 3): `target.position`, moved with
    /// `target.relative_to`'s origin if set.
    fn target_position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let e = self.inner.effectors().len() / 3;
        to_points(py, DMatrix::from_vec(3, e, self.inner.target_position()))
    }

    /// The reached joint positions (D,).
    fn joint_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.world().joint_positions())
    }

    /// The servo targets after clamping (D,).
    fn targets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.world().targets().to_vec())
    }

    /// The task-space row recorded in paths: effectors, base position and quaternion (x, y, z,
    /// w), joints.
    fn row<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let mut row = vec![0.0; self.inner.task_dim()];
        self.inner.task_position(&mut row);
        PyArray1::from_vec(py, row)
    }

    /// World poses (L, 7) of every URDF link (position, quaternion x, y, z, w), in the order of
    /// `Task.link_names`; NaN for a link without a body.
    fn link_poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let rows = self.inner.world().link_pose_rows();
        to_points(py, DMatrix::from_vec(7, rows.len() / 7, rows))
    }

    /// Each constraint's error now (distance: signed m; offset: m; orientation: rad; plane: m
    /// outside the bounds), in task-file order.
    fn constraint_errors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.constraint_errors())
    }

    /// The static support margin now (m, positive inside the soles' polygon; needs a fall rule).
    fn support_margin(&self) -> PyResult<f64> {
        guard(|| self.inner.support_margin().map_err(sim_to_py))
    }

    /// Link poses (L, 7) of the robot at `joints` (D,) with its base at `base` (7,: position,
    /// quaternion x, y, z, w; ignored for a fixed root): the native kinematics of a recorded
    /// path row, to draw it. Moves the robot there.
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

    /// The robot's centre of mass now (3,), from the URDF inertials.
    fn center_of_mass<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            Ok(PyArray1::from_vec(
                py,
                self.inner.center_of_mass().map_err(sim_to_py)?.to_vec(),
            ))
        })
    }

    /// The reward now.
    fn reward(&self) -> f64 {
        self.inner.reward()
    }

    /// Whether the effectors are within the task's reach radius of the target.
    fn reached(&self) -> bool {
        self.inner.reached_target()
    }
}

/// One trial runner for every task: trials of the task's latent learner (`task.learner`,
/// `task.episode`) in parallel in Rust, one plant per trial (a fresh world per episode for a
/// floating robot).
///
/// task: a Task. decoder: GpMap latent (d) → posture (D); encoder: GpMap or Projection
/// posture → latent. latent_low, latent_high: (d,) corners of the latent box. demos: (N, D) demonstrations (a "demo" start
/// uses row `episode.start_demo`). weights: (M,) value weights to start from (a saved policy;
/// default w₀ everywhere). rollout: run the `episodes` frozen, each action "greedy", "softmax"
/// or "random" (the control), each episode from its own generator (the same starts for each);
/// test_starts: a rollout starts where the frozen tests do.
/// n_trials, episodes, base_seed, first_trial, record_episodes, test_episodes,
/// record_test_episodes, return_weights, progress: as for run_bimanual_trials.
///
/// Returns the dict of run_bimanual_trials with paths of `task.row_len` columns (effectors,
/// base pose, joints) and "task" (the effective task as a dict).
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
        let task = Arc::clone(&task.inner);
        let trials = TaskTrials::new(
            Arc::clone(&task),
            demos.as_deref(),
            &latent,
            weights.as_deref(),
            options,
        )
        .map_err(sim_to_py)?;
        let total = trials.options.total_episodes();
        let results = run_with_polling(py, total, progress.as_ref(), |cancel, done| {
            trials.run(cancel, done).map_err(sim_to_py)
        })?;
        let out = pack_results(py, &results, &trials.template, &trials.options, task.row_len())?;
        out.set_item("task", config_to(py, task.config())?)?;
        Ok(out)
    })
}

/// The task's latent space at rest (`sim::task::survey`): a grid over [latent_low,
/// latent_high] at the task's learner step (coarsened to at most `max_points` points), each
/// point decoded by `decoder` and classified by the task's plant. Returns {shape, stride,
/// spacing, points (M, d), codes (M,), reward (M,), distance (M,), reached (M,), effectors
/// (M, 3E), moves (M,): fewest learner moves to the target region, -1 for none; with `physics`
/// each move also run from rest through the physics: blocked (M·A,) and moves_in_physics (M,)}.
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
        let out = PyDict::new(py);
        let (m, d) = (s.grid.len(), low.len());
        out.set_item("shape", s.grid.shape().to_vec())?;
        out.set_item("stride", s.grid.stride())?;
        out.set_item("spacing", s.grid.spacing().to_vec())?;
        out.set_item("points", to_points(py, DMatrix::from_vec(d, m, s.grid.points()))?)?;
        out.set_item("codes", PyArray1::from_vec(py, s.codes))?;
        out.set_item("reward", PyArray1::from_vec(py, s.reward))?;
        out.set_item("distance", PyArray1::from_vec(py, s.distance))?;
        out.set_item("reached", PyArray1::from_vec(py, s.reached))?;
        let e = s.effectors.len() / m.max(1);
        out.set_item("effectors", to_points(py, DMatrix::from_vec(e, m, s.effectors))?)?;
        let moves = |m: &[Option<usize>]| m.iter().map(|x| x.map_or(-1, |v| v as i64)).collect::<Vec<i64>>();
        out.set_item("moves", PyArray1::from_vec(py, moves(&s.moves_to_target)))?;
        out.set_item("moves_in_physics", PyArray1::from_vec(py, moves(&s.moves_in_physics)))?;
        out.set_item("blocked", PyArray1::from_vec(py, s.blocked))?;
        out.set_item("region_points", s.region_points)?;
        if let Some(c) = s.closest {
            let closest = PyDict::new(py);
            closest.set_item("point", c.point)?;
            closest.set_item("effectors", c.effectors)?;
            closest.set_item("distance", c.distance)?;
            closest.set_item("reward", c.reward)?;
            out.set_item("closest", closest)?;
        }
        Ok(out)
    })
}

/// V(z) = wᵀ b(z) (Eq. 7) at `points` (M, d) for the learner `learner` (a dict of LearnerConfig
/// keys) over the latent box [low, high] with weights (M',), or as built (w₀) if none: the
/// learner's own sparse features, as its look-ahead sees them.
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

/// Every key of a task file as dicts `{key, doc, rule, kind, default}`, table by table: the
/// source of docs/tasks.md and of the CLI's flags.
#[pyfunction]
pub fn task_schema(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    guard(|| schema_list(py, TaskConfig::schema_tables()))
}

/// The keys of Experiment 1's configuration (`plant.*`: the bimanual toy, `learner.*`), as
/// `task_schema`.
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

/// A trained latent policy (`latent_core::LatentPolicy`): the learner's grid and weights over
/// the latent box with the GPLVM's maps; it acts greedily (the action of the largest look-ahead
/// value).
#[pyclass(name = "LatentPolicy", module = "latentrl._native", frozen)]
pub struct PyLatentPolicy {
    policy: LatentPolicy,
    decoder: Py<crate::gp::PyGpMap>,
    encoder: EncoderObject,
}

#[pymethods]
impl PyLatentPolicy {
    /// The policy of `learner` (a dict of LearnerConfig keys) over [low, high] with `weights`,
    /// decoding with `decoder` (latent → posture) and encoding with `encoder`.
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

    /// The next servo target for the reached `posture` (D,): encode it, take the greedy latent
    /// step (clamped into the box), decode. Returns `(target (D,), z (d,), next z (d,))`.
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

    /// V(z) at `points` (M, d): the learner's own values.
    fn values<'py>(&self, py: Python<'py>, points: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            let z = crate::convert::points("points", &points)?;
            Ok(PyArray1::from_vec(py, self.policy.values(&z).map_err(to_py)?))
        })
    }
}
