//! What every trial runner of the binding shares: checked run arguments, the latent maps and
//! box, the polling worker (GIL released, Ctrl-C and progress every 0.1 s) and the one result
//! dict. Arguments are checked here; every decision is the core's.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use latent_core::{EpisodeRecord, GpMap, Learner, TrialOptions, TrialResult};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::type_name;
use crate::errors::{InvalidInputError, to_py};
use crate::gp::PyGpMap;

/// Most episode records one call may return (≈ 0.5 GB of per-episode arrays).
pub(crate) const MAX_EPISODES: usize = 10_000_000;

/// Most values of recorded paths one call may return (2 GiB of float64).
pub(crate) const MAX_PATH_VALUES: usize = 1 << 28;

/// How often the calling thread wakes to check Ctrl-C and report progress.
const POLL: Duration = Duration::from_millis(100);

pub(crate) fn invalid(msg: String) -> PyErr {
    InvalidInputError::new_err(msg)
}

/// A Python int in `[min, max]`.
pub(crate) fn int_in(name: &str, value: &Bound<'_, PyAny>, min: i128, max: i128) -> PyResult<i128> {
    let v: i128 = value
        .extract()
        .map_err(|_| invalid(format!("{name}: expected an int, got {}", type_name(value))))?;
    if v < min || v > max {
        return Err(invalid(format!("{name} must lie in [{min}, {max}], got {v}")));
    }
    Ok(v)
}

pub(crate) fn gp_map<'a, 'py>(
    name: &str,
    value: &'a Option<Bound<'py, PyAny>>,
) -> PyResult<Option<&'a Bound<'py, PyGpMap>>> {
    match value {
        None => Ok(None),
        Some(v) if v.is_none() => Ok(None),
        Some(v) => v
            .cast::<PyGpMap>()
            .map(Some)
            .map_err(|_| invalid(format!("{name}: expected a GpMap, got {}", type_name(v)))),
    }
}

fn corner(name: &'static str, value: Option<&Bound<'_, PyAny>>, dim: usize, context: &str) -> PyResult<Vec<f64>> {
    let value = value
        .filter(|v| !v.is_none())
        .ok_or_else(|| invalid(format!("{name} is required {context}")))?;
    let v: Vec<f64> = value.extract().map_err(|_| {
        invalid(format!(
            "{name}: expected a 1-D array of {dim} numbers, got {}",
            type_name(value)
        ))
    })?;
    if v.len() != dim {
        return Err(invalid(format!(
            "{name}: expected shape ({dim},) (the decoder's input dimension), got ({},)",
            v.len()
        )));
    }
    latent_core::error::check_finite(name, &v).map_err(to_py)?;
    Ok(v)
}

/// A latent learner's maps and box, checked: decoder and encoder given, corners of the
/// decoder's input dimension, `high > low`. `context` ends the "is required" messages.
pub(crate) struct LatentArgs<'a, E: ?Sized> {
    /// Latent → posture.
    pub decoder: &'a GpMap,
    /// Posture → latent.
    pub encoder: &'a E,
    /// Lower corner of the latent box.
    pub low: Vec<f64>,
    /// Upper corner of the latent box.
    pub high: Vec<f64>,
}

pub(crate) fn latent_args<'a, 'py, E: ?Sized>(
    decoder: Option<&'a Bound<'py, PyGpMap>>,
    encoder: Option<&'a E>,
    latent_low: Option<&Bound<'py, PyAny>>,
    latent_high: Option<&Bound<'py, PyAny>>,
    context: &str,
) -> PyResult<LatentArgs<'a, E>> {
    let decoder: &GpMap = &decoder
        .ok_or_else(|| invalid(format!("decoder (a GpMap latent → posture) is required {context}")))?
        .get()
        .inner;
    let encoder = encoder.ok_or_else(|| invalid(format!("encoder (posture → latent) is required {context}")))?;
    let dim = decoder.input_dim();
    let low = corner("latent_low", latent_low, dim, context)?;
    let high = corner("latent_high", latent_high, dim, context)?;
    if let Some(k) = (0..dim).find(|&k| high[k] <= low[k]) {
        return Err(invalid(format!(
            "latent_high[{k}] = {} must exceed latent_low[{k}] = {}",
            high[k], low[k]
        )));
    }
    Ok(LatentArgs {
        decoder,
        encoder,
        low,
        high,
    })
}

/// The arguments every trial runner takes, as given (checked by [`RunArgs::check`]).
pub(crate) struct RunArgs<'a, 'py> {
    pub n_trials: &'a Bound<'py, PyAny>,
    pub episodes: &'a Bound<'py, PyAny>,
    pub base_seed: &'a Bound<'py, PyAny>,
    pub first_trial: Option<&'a Bound<'py, PyAny>>,
    pub record_episodes: Option<&'a Bound<'py, PyAny>>,
    pub test_episodes: Option<&'a Bound<'py, PyAny>>,
    pub record_test_episodes: Option<&'a Bound<'py, PyAny>>,
    pub return_weights: bool,
    pub progress: Option<Bound<'py, PyAny>>,
}

/// [`RunArgs`] checked: the trial options and the progress callback.
pub(crate) struct Checked<'py> {
    pub options: TrialOptions,
    pub progress: Option<Bound<'py, PyAny>>,
}

/// A sequence of episode indices in `[0, n)`, or empty for None.
fn indices(name: &str, value: Option<&Bound<'_, PyAny>>, n: usize) -> PyResult<Vec<usize>> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(Vec::new());
    };
    let list: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| invalid(format!("{name}: expected a sequence of ints, got {}", type_name(value))))?
        .collect::<PyResult<_>>()?;
    list.iter()
        .map(|e| int_in(&format!("{name}[i]"), e, 0, n as i128 - 1).map(|v| v as usize))
        .collect()
}

impl<'py> RunArgs<'_, 'py> {
    /// Checks every argument.
    pub(crate) fn check(self) -> PyResult<Checked<'py>> {
        let n_trials = int_in("n_trials", self.n_trials, 1, 1_000_000)? as usize;
        let episodes = int_in("episodes", self.episodes, 1, 100_000_000)? as usize;
        let base_seed = int_in("base_seed", self.base_seed, 0, u64::MAX as i128)? as u64;
        let first_trial = match self.first_trial.filter(|v| !v.is_none()) {
            Some(v) => int_in("first_trial", v, 0, 1 << 40)? as usize,
            None => 0,
        };
        let test_episodes = match self.test_episodes.filter(|v| !v.is_none()) {
            Some(v) => int_in("test_episodes", v, 0, 100_000_000)? as usize,
            None => 0,
        };
        let total = n_trials as u128 * (episodes + test_episodes) as u128;
        if total > MAX_EPISODES as u128 {
            return Err(invalid(format!(
                "n_trials × (episodes + test_episodes) = {total} episode records in one call, more than {MAX_EPISODES}; \
                 run fewer trials at a time (the runners save trial by trial)"
            )));
        }
        let options = TrialOptions {
            n_trials,
            first_trial,
            episodes,
            base_seed,
            record_episodes: indices("record_episodes", self.record_episodes, episodes)?,
            keep_weights: self.return_weights,
            test_episodes,
            record_test_episodes: indices("record_test_episodes", self.record_test_episodes, test_episodes)?,
            phase: latent_core::Phase::Train,
        };
        options.validate().map_err(to_py)?;
        let progress = self.progress.filter(|p| !p.is_none());
        if let Some(p) = &progress
            && !p.is_callable()
        {
            return Err(invalid(format!(
                "progress: expected a callable or None, got {}",
                type_name(p)
            )));
        }
        Ok(Checked { options, progress })
    }
}

/// The units of progress of trials: `n_trials × (episodes + test_episodes)` episodes.
pub(crate) fn episodes_in(options: &TrialOptions) -> usize {
    options.n_trials * (options.episodes + options.test_episodes)
}

/// Runs `run(cancel, done)` (the trials, or any long native call) on a worker thread; this
/// thread wakes every [`POLL`], re-attaches, checks for Ctrl-C and reports progress, `done`
/// out of `total`. Ctrl-C sets `cancel` and raises once the worker has stopped.
pub(crate) fn run_with_polling<T, F>(
    py: Python<'_>,
    total: usize,
    progress: Option<&Bound<'_, PyAny>>,
    run: F,
) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&AtomicBool, &AtomicUsize) -> PyResult<T> + Send,
{
    let cancel = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    std::thread::scope(|scope| {
        // Finished also when it panics (a flag set after `run` would never be set).
        let worker = scope.spawn(|| run(&cancel, &done));
        let stop = |err: PyErr| {
            cancel.store(true, Ordering::Relaxed);
            err
        };
        let mut failure = None;
        loop {
            let finished = py.detach(|| {
                let deadline = Instant::now() + POLL;
                while !worker.is_finished() && Instant::now() < deadline {
                    std::thread::sleep(Duration::from_millis(2));
                }
                worker.is_finished()
            });
            if finished {
                break;
            }
            if let Err(e) = py.check_signals() {
                failure = Some(stop(e));
                break;
            }
            if let Some(cb) = progress
                && let Err(e) = cb.call1((done.load(Ordering::Relaxed), total))
            {
                failure = Some(stop(e));
                break;
            }
        }
        // On failure the cancel flag is set: the trials stop after their current episode.
        let joined = py.detach(|| worker.join());
        if let Some(e) = failure {
            return Err(e);
        }
        // A panic in the worker (or a rayon thread under it) goes on unwinding here, for the
        // exported function's `guard` to raise as InternalError.
        let results = joined.unwrap_or_else(|panic| std::panic::resume_unwind(panic))?;
        if let Some(cb) = progress {
            cb.call1((done.load(Ordering::Relaxed), total))?;
        }
        Ok(results)
    })
}

/// The result dict of every trial runner (see `run_bimanual_trials`' docs) except "config":
/// per-episode and per-test-episode arrays, padded trajectories of `task_dim` columns,
/// weights and the learner's grid.
/// Refuses, before any trial runs, recorded paths too large to return: `trials × recorded
/// episodes × (max_steps + 1) × row` values.
pub(crate) fn check_recording(options: &TrialOptions, max_steps: usize, row: usize) -> PyResult<()> {
    let records = options.record_episodes.len() + options.record_test_episodes.len();
    let values = options.n_trials as u128 * records as u128 * (max_steps as u128 + 1) * row as u128;
    if values > MAX_PATH_VALUES as u128 {
        return Err(invalid(format!(
            "recording {records} episodes of up to {max_steps} steps × {row} values in each of {} trials needs \
             {values} values, more than {MAX_PATH_VALUES} (2 GiB); record fewer episodes or run fewer trials at a time",
            options.n_trials
        )));
    }
    Ok(())
}

pub(crate) fn pack_results<'py>(
    py: Python<'py>,
    results: &[TrialResult],
    template: &Learner,
    options: &TrialOptions,
    task_dim: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let rows = template.rules().max_steps + 1;
    pack_episodes(py, &out, "", results, options.episodes, |r| &r.episodes)?;
    pack_episodes(py, &out, "test_", results, options.test_episodes, |r| &r.tests)?;
    let paths = |name: &str, n: usize, of: fn(&TrialResult) -> &[Vec<f64>]| -> PyResult<()> {
        let mut traj = vec![f64::NAN; results.len() * n * rows * task_dim];
        for (i, r) in results.iter().enumerate() {
            for (j, path) in of(r).iter().enumerate() {
                let start = (i * n + j) * rows * task_dim;
                let len = path.len().min(rows * task_dim);
                traj[start..start + len].copy_from_slice(&path[..len]);
            }
        }
        out.set_item(
            name,
            PyArray1::from_vec(py, traj).reshape([results.len(), n, rows, task_dim])?,
        )
    };
    paths("trajectories", options.record_episodes.len(), |r| &r.trajectories)?;
    paths("test_trajectories", options.record_test_episodes.len(), |r| {
        &r.test_trajectories
    })?;
    let per_episode = |name: &str, n: usize, width: usize, of: fn(&TrialResult) -> &[f64]| -> PyResult<()> {
        let mut rows = vec![f64::NAN; results.len() * n * width];
        for (i, r) in results.iter().enumerate() {
            let len = of(r).len().min(n * width);
            rows[i * n * width..i * n * width + len].copy_from_slice(&of(r)[..len]);
        }
        out.set_item(name, PyArray1::from_vec(py, rows).reshape([results.len(), n, width])?)
    };
    per_episode("test_starts", options.test_episodes, task_dim, |r| &r.test_starts)?;
    per_episode("mean_states", options.episodes, template.grid().dim(), |r| {
        &r.mean_states
    })?;
    out.set_item(
        "finished",
        PyArray1::from_vec(py, results.iter().map(|r| r.finished).collect::<Vec<bool>>()),
    )?;
    out.set_item(
        "trials",
        PyArray1::from_vec(py, results.iter().map(|r| r.trial as i64).collect::<Vec<i64>>()),
    )?;
    let m = template.weights().len();
    if options.keep_weights {
        let mut w = Vec::with_capacity(results.len() * m);
        for r in results {
            w.extend_from_slice(r.weights.as_deref().unwrap_or(&[]));
        }
        out.set_item("weights", PyArray1::from_vec(py, w).reshape([results.len(), m])?)?;
    } else {
        out.set_item("weights", py.None())?;
    }
    out.set_item("learner_low", PyArray1::from_vec(py, template.grid().low().to_vec()))?;
    out.set_item("learner_high", PyArray1::from_vec(py, template.grid().high().to_vec()))?;
    out.set_item("spacing", PyArray1::from_vec(py, template.grid().spacing().to_vec()))?;
    out.set_item("n_actions", template.n_actions())?;
    out.set_item("n_centres", m)?;
    Ok(out)
}

/// `{prefix}returns`, `ends`, `steps`, `reached`, `passed` (T, n) of the records `of(trial)`.
fn pack_episodes<'py>(
    py: Python<'py>,
    out: &Bound<'py, PyDict>,
    prefix: &str,
    results: &[TrialResult],
    n: usize,
    of: fn(&TrialResult) -> &[EpisodeRecord],
) -> PyResult<()> {
    let t = results.len();
    let mut returns = vec![f64::NAN; t * n];
    let mut ends = vec![-1i8; t * n];
    let mut steps = vec![0i64; t * n];
    let mut reached = vec![false; t * n];
    let mut passed = vec![false; t * n];
    for (i, r) in results.iter().enumerate() {
        for (e, rec) in of(r).iter().enumerate() {
            let k = i * n + e;
            returns[k] = rec.ret;
            ends[k] = rec.end.code() as i8;
            steps[k] = rec.steps as i64;
            reached[k] = rec.reached;
            passed[k] = rec.passed;
        }
    }
    out.set_item(
        format!("{prefix}returns"),
        PyArray1::from_vec(py, returns).reshape([t, n])?,
    )?;
    out.set_item(format!("{prefix}ends"), PyArray1::from_vec(py, ends).reshape([t, n])?)?;
    out.set_item(format!("{prefix}steps"), PyArray1::from_vec(py, steps).reshape([t, n])?)?;
    out.set_item(
        format!("{prefix}reached"),
        PyArray1::from_vec(py, reached).reshape([t, n])?,
    )?;
    out.set_item(
        format!("{prefix}passed"),
        PyArray1::from_vec(py, passed).reshape([t, n])?,
    )?;
    Ok(())
}
