//! Binding of `latent_core::{episode, trials}` and `sim::bimanual`: Experiment 1 trials in
//! one call, and what every trial runner shares (checked arguments, the learner keys of the
//! config dict, the latent maps, the polling worker, the result dict). Arguments are
//! checked here; every decision is the core's.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use ::sim::bimanual::{BimanualConfig, BimanualLearner, run_bimanual_trials as run_core};
use latent_core::{EpisodeRecord, GpMap, Learner, LearnerConfig, StartMode, TrialOptions, TrialResult};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{InvalidInputError, guard, to_py};
use crate::gp::PyGpMap;

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

pub(crate) fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

pub(crate) fn float(name: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    let v: f64 = value
        .extract()
        .map_err(|_| invalid(format!("config[{name:?}]: expected a number, got {}", type_name(value))))?;
    if !v.is_finite() {
        return Err(invalid(format!("config[{name:?}] must be finite, got {v}")));
    }
    Ok(v)
}

pub(crate) fn floats<const N: usize>(name: &str, value: &Bound<'_, PyAny>) -> PyResult<[f64; N]> {
    let v: Vec<f64> = value.extract().map_err(|_| {
        invalid(format!(
            "config[{name:?}]: expected a sequence of {N} numbers, got {}",
            type_name(value)
        ))
    })?;
    let arr: [f64; N] = v
        .try_into()
        .map_err(|v: Vec<f64>| invalid(format!("config[{name:?}]: expected {N} numbers, got {}", v.len())))?;
    if let Some(x) = arr.iter().find(|x| !x.is_finite()) {
        return Err(invalid(format!("config[{name:?}] must be finite, got {x}")));
    }
    Ok(arr)
}

/// The learner keys of every runner's config dict, in the order they are documented and echoed.
pub(crate) const LEARNER_KEYS: [&str; 12] = [
    "alpha",
    "gamma",
    "initial_weight",
    "beta",
    "step_fraction",
    "max_steps",
    "centres_per_dim",
    "rbf_width",
    "rbf_cutoff",
    "variance_threshold",
    "start",
    "max_start_draws",
];

/// Sets learner key `key` of a config dict; `Ok(false)` if `key` is not a learner key.
pub(crate) fn set_learner_key(learner: &mut LearnerConfig, key: &str, v: &Bound<'_, PyAny>) -> PyResult<bool> {
    match key {
        "alpha" => learner.td.alpha = float(key, v)?,
        "gamma" => learner.td.gamma = float(key, v)?,
        "initial_weight" => learner.td.initial_weight = float(key, v)?,
        "beta" => learner.beta = float(key, v)?,
        "step_fraction" => learner.step_fraction = float(key, v)?,
        "max_steps" => learner.max_steps = int_in("config[\"max_steps\"]", v, 1, 100_000_000)? as usize,
        "centres_per_dim" => {
            learner.rbf.centres_per_dim = int_in("config[\"centres_per_dim\"]", v, 2, 100_000)? as usize
        }
        "rbf_width" => learner.rbf.width = float(key, v)?,
        "rbf_cutoff" => learner.rbf.cutoff = float(key, v)?,
        "variance_threshold" => learner.variance_threshold = if v.is_none() { None } else { Some(float(key, v)?) },
        "start" => {
            let s: String = v
                .extract()
                .map_err(|_| invalid("config[\"start\"]: expected \"plant\" or \"uniform\"".into()))?;
            learner.start = match s.as_str() {
                "plant" => StartMode::FromPlant,
                "uniform" => StartMode::UniformInBox,
                other => {
                    return Err(invalid(format!(
                        "config[\"start\"]: expected \"plant\" or \"uniform\", got {other:?}"
                    )));
                }
            }
        }
        "max_start_draws" => {
            learner.max_start_draws = int_in("config[\"max_start_draws\"]", v, 1, 1_000_000_000)? as usize
        }
        _ => return Ok(false),
    }
    Ok(true)
}

/// Adds every learner key (effective values) to `d`.
pub(crate) fn echo_learner(d: &Bound<'_, PyDict>, learner: &LearnerConfig) -> PyResult<()> {
    d.set_item("alpha", learner.td.alpha)?;
    d.set_item("gamma", learner.td.gamma)?;
    d.set_item("initial_weight", learner.td.initial_weight)?;
    d.set_item("beta", learner.beta)?;
    d.set_item("step_fraction", learner.step_fraction)?;
    d.set_item("max_steps", learner.max_steps)?;
    d.set_item("centres_per_dim", learner.rbf.centres_per_dim)?;
    d.set_item("rbf_width", learner.rbf.width)?;
    d.set_item("rbf_cutoff", learner.rbf.cutoff)?;
    d.set_item("variance_threshold", learner.variance_threshold)?;
    d.set_item(
        "start",
        if learner.start == StartMode::FromPlant {
            "plant"
        } else {
            "uniform"
        },
    )?;
    d.set_item("max_start_draws", learner.max_start_draws)?;
    Ok(())
}

/// Applies a config dict: `set_plant(key, value)` first (`Ok(false)` if not a plant key),
/// then the learner keys; any other key is an error listing `plant_keys` and the learner's.
pub(crate) fn apply_config_dict(
    config: Option<&Bound<'_, PyDict>>,
    plant_keys: &[&str],
    learner: &mut LearnerConfig,
    mut set_plant: impl FnMut(&str, &Bound<'_, PyAny>, &mut LearnerConfig) -> PyResult<bool>,
) -> PyResult<()> {
    let Some(config) = config else {
        return Ok(());
    };
    for (key, value) in config.iter() {
        let key: String = key
            .extract()
            .map_err(|_| invalid(format!("config: keys must be strings, got {}", type_name(&key))))?;
        if !set_plant(&key, &value, learner)? && !set_learner_key(learner, &key, &value)? {
            let valid: Vec<&str> = plant_keys.iter().chain(&LEARNER_KEYS).copied().collect();
            return Err(invalid(format!(
                "config: unknown key {key:?}; valid keys: {}",
                valid.join(", ")
            )));
        }
    }
    learner.validate().map_err(to_py)
}

/// The plant keys of Experiment 1's config dict.
const BIMANUAL_KEYS: [&str; 12] = [
    "drop_tolerance",
    "grip",
    "obstacle_centre",
    "obstacle_radius",
    "box_low",
    "box_high",
    "target",
    "theta",
    "start_mean",
    "start_sd",
    "penalty",
    "reached_rms",
];

/// Applies `config` (a dict of overrides) to the defaults.
fn apply_config(config: Option<&Bound<'_, PyDict>>) -> PyResult<(BimanualConfig, LearnerConfig)> {
    let mut plant = BimanualConfig::default();
    let mut learner = LearnerConfig::default();
    apply_config_dict(config, &BIMANUAL_KEYS, &mut learner, |key, v, learner| {
        match key {
            "drop_tolerance" => plant.drop_tolerance = float(key, v)?,
            "grip" => plant.grip = floats(key, v)?,
            "obstacle_centre" => plant.obstacle_centre = floats(key, v)?,
            "obstacle_radius" => plant.obstacle_radius = float(key, v)?,
            "box_low" => plant.box_low = float(key, v)?,
            "box_high" => plant.box_high = float(key, v)?,
            "target" => plant.target = floats(key, v)?,
            "theta" => plant.theta = float(key, v)?,
            "start_mean" => plant.start_mean = floats(key, v)?,
            "start_sd" => plant.start_sd = float(key, v)?,
            "penalty" => {
                plant.penalty = float(key, v)?;
                learner.penalty = plant.penalty;
            }
            "reached_rms" => plant.reached_rms = float(key, v)?,
            _ => return Ok(false),
        }
        Ok(true)
    })?;
    plant.validate().map_err(to_py)?;
    Ok((plant, learner))
}

/// The effective configuration as a dict (every plant and learner key).
fn echo_config<'py>(py: Python<'py>, plant: &BimanualConfig, learner: &LearnerConfig) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("drop_tolerance", plant.drop_tolerance)?;
    d.set_item("grip", plant.grip.to_vec())?;
    d.set_item("obstacle_centre", plant.obstacle_centre.to_vec())?;
    d.set_item("obstacle_radius", plant.obstacle_radius)?;
    d.set_item("box_low", plant.box_low)?;
    d.set_item("box_high", plant.box_high)?;
    d.set_item("target", plant.target.to_vec())?;
    d.set_item("theta", plant.theta)?;
    d.set_item("start_mean", plant.start_mean.to_vec())?;
    d.set_item("start_sd", plant.start_sd)?;
    d.set_item("penalty", plant.penalty)?;
    d.set_item("reached_rms", plant.reached_rms)?;
    echo_learner(&d, learner)?;
    Ok(d)
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
pub(crate) struct LatentArgs<'a> {
    /// Latent → posture.
    pub decoder: &'a GpMap,
    /// Posture → latent.
    pub encoder: &'a GpMap,
    /// Lower corner of the latent box.
    pub low: Vec<f64>,
    /// Upper corner of the latent box.
    pub high: Vec<f64>,
}

pub(crate) fn latent_args<'a, 'py>(
    decoder: Option<&'a Bound<'py, PyGpMap>>,
    encoder: Option<&'a Bound<'py, PyGpMap>>,
    latent_low: Option<&Bound<'py, PyAny>>,
    latent_high: Option<&Bound<'py, PyAny>>,
    context: &str,
) -> PyResult<LatentArgs<'a>> {
    let decoder: &GpMap = &decoder
        .ok_or_else(|| invalid(format!("decoder (a GpMap latent → posture) is required {context}")))?
        .get()
        .inner;
    let encoder: &GpMap = &encoder
        .ok_or_else(|| invalid(format!("encoder (a GpMap posture → latent) is required {context}")))?
        .get()
        .inner;
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
    pub config: Option<&'a Bound<'py, PyAny>>,
    pub record_episodes: Option<&'a Bound<'py, PyAny>>,
    pub test_episodes: Option<&'a Bound<'py, PyAny>>,
    pub record_test_episodes: Option<&'a Bound<'py, PyAny>>,
    pub return_weights: bool,
    pub progress: Option<Bound<'py, PyAny>>,
}

/// [`RunArgs`] checked: the trial options, the config dict and the progress callback.
pub(crate) struct Checked<'py> {
    pub options: TrialOptions,
    pub config: Option<Bound<'py, PyDict>>,
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
        let config = match self.config.filter(|c| !c.is_none()) {
            Some(c) => Some(
                c.cast::<PyDict>()
                    .map_err(|_| invalid(format!("config: expected a dict, got {}", type_name(c))))?
                    .clone(),
            ),
            None => None,
        };
        let options = TrialOptions {
            n_trials,
            first_trial,
            episodes,
            base_seed,
            record_episodes: indices("record_episodes", self.record_episodes, episodes)?,
            keep_weights: self.return_weights,
            test_episodes,
            record_test_episodes: indices("record_test_episodes", self.record_test_episodes, test_episodes)?,
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
        Ok(Checked {
            options,
            config,
            progress,
        })
    }
}

/// Runs Experiment 1 (SPEC §4.1) trials in parallel in Rust and returns their records.
///
/// learner: "full" (12 actions, 20⁴ RBFs over the hands' box) or "latent" (2·d orthogonal
///     actions, 20^d RBFs over [latent_low, latent_high]; needs decoder, encoder and both
///     corners).
/// n_trials, episodes: T trials of E episodes each.
/// base_seed: trial i draws from ChaCha8(base_seed, stream i): same seed ⇒ same arrays,
///     whatever the thread count.
/// first_trial: run trials first_trial .. first_trial + n_trials (to resume a sweep);
///     None means 0.
/// config: overrides of the defaults (SPEC §4.1) — plant: drop_tolerance (0.1), grip
///     ([0.1, 0]), obstacle_centre ([0.5, 0.5]), obstacle_radius (0.2), box_low (-0.5),
///     box_high (1.5), target ([0, 0, 0.1, 0]), theta (0.75), start_mean ([1, 1]),
///     start_sd (0.1), penalty (-1, also the learner's box/gate penalty), reached_rms (0.1);
///     learner: alpha (0.9), gamma (0.95), initial_weight (0), beta (10), step_fraction
///     (0.2), max_steps (500), centres_per_dim (20), rbf_width (1, σ/spacing), rbf_cutoff
///     (3, in σ), variance_threshold (None), start ("plant" | "uniform"), max_start_draws
///     (1000). Unknown keys raise InvalidInputError.
/// decoder, encoder: GpMap latent (d) → posture (4) and posture (4) → latent (d).
/// latent_low, latent_high: (d,) corners of the latent box.
/// record_episodes: episode indices whose hand trajectories are recorded in every trial.
/// test_episodes: K frozen test episodes after training (no TD updates; starts the plant
///     admits for tests); None or 0 for none.
/// record_test_episodes: test-episode indices whose hand trajectories are recorded.
/// return_weights: also return each trial's final value-function weights.
/// progress: called as progress(episodes_done, episodes_total) about every 0.1 s and at
///     the end (test episodes count); an exception in it stops the run and propagates.
///
/// Returns a dict: "returns" (T, E) float64 (NaN where not run), "ends" (T, E) int8
/// (0 time-out, 1 obstacle, 2 box exit, 3 drop, 4 fall, 5 variance gate; -1 not run),
/// "steps" (T, E) int64, "reached" (T, E) bool (RMS hand distance to the target
/// ≤ reached_rms at some step), "passed" (T, E) bool (the plant's waypoint passed; always
/// False here), the same five for the test episodes as "test_returns", "test_ends",
/// "test_steps", "test_reached", "test_passed" (T, K), "finished" (T,) bool, "trials" (T,)
/// int64 trial indices, "trajectories" (T, R, max_steps + 1, 4) float64 hands (x_L, y_L,
/// x_R, y_R) after the reset and after each plant step, NaN-padded, "test_trajectories"
/// (T, R', max_steps + 1, 4) likewise, "weights" (T, M) float64 or None, "learner_low" /
/// "learner_high" / "spacing" (d,) of the RBF grid, "n_actions", "n_centres", and "config"
/// (every key above, effective values).
/// Ctrl-C stops all trials and raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (
    learner, *, n_trials, episodes, base_seed, first_trial = None, config = None, decoder = None,
    encoder = None, latent_low = None, latent_high = None, record_episodes = None,
    test_episodes = None, record_test_episodes = None, return_weights = false, progress = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn run_bimanual_trials<'py>(
    py: Python<'py>,
    learner: &Bound<'py, PyAny>,
    n_trials: &Bound<'py, PyAny>,
    episodes: &Bound<'py, PyAny>,
    base_seed: &Bound<'py, PyAny>,
    first_trial: Option<&Bound<'py, PyAny>>,
    config: Option<&Bound<'py, PyAny>>,
    decoder: Option<Bound<'py, PyAny>>,
    encoder: Option<Bound<'py, PyAny>>,
    latent_low: Option<&Bound<'py, PyAny>>,
    latent_high: Option<&Bound<'py, PyAny>>,
    record_episodes: Option<&Bound<'py, PyAny>>,
    test_episodes: Option<&Bound<'py, PyAny>>,
    record_test_episodes: Option<&Bound<'py, PyAny>>,
    return_weights: bool,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let name: String = learner.extract().map_err(|_| {
            invalid(format!(
                "learner: expected \"full\" or \"latent\", got {}",
                type_name(learner)
            ))
        })?;
        #[rustfmt::skip]
        let run = RunArgs { n_trials, episodes, base_seed, first_trial, config, record_episodes, test_episodes,
                            record_test_episodes, return_weights, progress }.check()?;
        let (plant, learner_config) = apply_config(run.config.as_ref())?;
        let decoder = gp_map("decoder", &decoder)?;
        let encoder = gp_map("encoder", &encoder)?;
        let latent;
        let bimanual = match name.as_str() {
            "full" => {
                let given = |v: Option<&Bound<'py, PyAny>>| v.is_some_and(|v| !v.is_none());
                if decoder.is_some() || encoder.is_some() || given(latent_low) || given(latent_high) {
                    return Err(invalid(
                        "learner=\"full\" takes no decoder, encoder, latent_low or latent_high (they are for learner=\"latent\")".into(),
                    ));
                }
                BimanualLearner::Full
            }
            "latent" => {
                latent = latent_args(decoder, encoder, latent_low, latent_high, "for learner=\"latent\"")?;
                BimanualLearner::Latent {
                    decoder: latent.decoder,
                    encoder: latent.encoder,
                    low: &latent.low,
                    high: &latent.high,
                }
            }
            other => {
                return Err(invalid(format!(
                    "learner: expected \"full\" or \"latent\", got {other:?}"
                )));
            }
        };
        // Validates the learner (grid size, dimensions) before any thread starts.
        let (template, _) = bimanual.build(&plant, &learner_config).map_err(to_py)?;
        let options = &run.options;
        let results = run_with_polling(py, options, run.progress.as_ref(), |cancel, done| {
            run_core(&plant, &learner_config, &bimanual, options, cancel, done)
        })?;
        let out = pack_results(py, &results, &template, options, 4)?;
        out.set_item("config", echo_config(py, &plant, &learner_config)?)?;
        Ok(out)
    })
}

/// Runs `run(cancel, done)` (the trials) on a worker thread; this thread wakes every
/// [`POLL`], re-attaches, checks for Ctrl-C and reports progress out of
/// `n_trials × (episodes + test_episodes)`.
pub(crate) fn run_with_polling<F>(
    py: Python<'_>,
    options: &TrialOptions,
    progress: Option<&Bound<'_, PyAny>>,
    run: F,
) -> PyResult<Vec<TrialResult>>
where
    F: FnOnce(&AtomicBool, &AtomicUsize) -> latent_core::Result<Vec<TrialResult>> + Send,
{
    let cancel = AtomicBool::new(false);
    let done = AtomicUsize::new(0);
    let total = options.n_trials * (options.episodes + options.test_episodes);
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
        let results = joined
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
            .map_err(to_py)?;
        if let Some(cb) = progress {
            cb.call1((done.load(Ordering::Relaxed), total))?;
        }
        Ok(results)
    })
}

/// The result dict of every trial runner (see `run_bimanual_trials`' docs) except "config":
/// per-episode and per-test-episode arrays, padded trajectories of `task_dim` columns,
/// weights and the learner's grid.
pub(crate) fn pack_results<'py>(
    py: Python<'py>,
    results: &[TrialResult],
    template: &Learner,
    options: &TrialOptions,
    task_dim: usize,
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    let rows = template.config().max_steps + 1;
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
    out.set_item(
        "finished",
        PyArray1::from_vec(py, results.iter().map(|r| r.finished).collect::<Vec<bool>>()),
    )?;
    out.set_item(
        "trials",
        PyArray1::from_vec(py, results.iter().map(|r| r.trial as i64).collect::<Vec<i64>>()),
    )?;
    let m = template.grid().len();
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
