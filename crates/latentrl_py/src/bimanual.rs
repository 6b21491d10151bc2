//! Binding of `sim::bimanual`: Experiment 1 trials (the kinematic two-hand toy) in one call.

use ::sim::bimanual::{BimanualConfig, BimanualLearner, BimanualTrials, check_tables};
use latent_core::LearnerConfig;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{config_or_default, config_to};
use crate::errors::{guard, to_py};
use crate::projection::EncoderObject;
use crate::runner::{RunArguments, latent_args, pack_results, run_with_polling};

/// Runs Experiment 1 (docs/method.md §Experiment 1) trials in parallel in Rust and returns their
/// records.
///
/// With `decoder`, `encoder`, `latent_low` and `latent_high` the latent learner runs (the
/// actions of `learner`, default the 2d axes; RBFs over [latent_low, latent_high]); without
/// them the full-space learner (12 actions, RBFs over the hands' box).
/// n_trials, episodes: T trials of E episodes each.
/// base_seed: trial i draws from ChaCha8(base_seed, stream i): same seed ⇒ same arrays,
///     whatever the thread count.
/// first_trial: run trials first_trial .. first_trial + n_trials (to resume); None means 0.
/// plant: a dict of BimanualConfig keys (`plant_schema()`); learner: a dict of LearnerConfig
///     keys (`learner_schema()`); keys left out keep their defaults, unknown keys are errors.
/// decoder, encoder: a GpMap latent (d) → posture (4), and a GpMap or a Projection posture (4) → latent (d).
/// latent_low, latent_high: (d,) corners of the latent box.
/// record_episodes: episode indices whose hand trajectories are recorded in every trial.
/// test_episodes: K frozen test episodes after training (no TD updates); None or 0 for none.
/// record_test_episodes: test-episode indices whose hand trajectories are recorded.
/// return_weights: also return each trial's final value-function weights.
/// progress: called as progress(episodes_done, episodes_total) about every 0.1 s and at
///     the end (test episodes count); an exception in it stops the run and propagates.
///
/// Returns a dict: "returns" (T, E) float64 (NaN where not run), "ends" (T, E) int8 (the
/// codes of END_REASONS; -1 not run), "steps" (T, E) int64, "reached" (T, E) bool, "passed"
/// (T, E) bool (always False here), the same five for the test episodes as "test_returns",
/// "test_ends", "test_steps", "test_reached", "test_passed" (T, K), "finished" (T,) bool,
/// "trials" (T,) int64, "trajectories" (T, R, max_steps + 1, 4) float64 hands (x_L, y_L,
/// x_R, y_R) after the reset and after each plant step, NaN-padded, "test_trajectories"
/// likewise, "test_starts" (T, K, 4) the row at the start of every test episode (NaN where
/// not run), "mean_states" (T, E, n) each training episode's mean learner state (n: 4 full,
/// d latent; NaN where not run), "weights" (T, M) float64 or None, "learner_low" / "learner_high" / "spacing"
/// (d,) of the RBF grid, "n_actions", "n_centres", and "plant" / "learner" (the effective
/// configurations). Ctrl-C stops all trials and raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (
    *, n_trials, episodes, base_seed, first_trial = None, plant = None, learner = None, decoder = None,
    encoder = None, latent_low = None, latent_high = None, record_episodes = None,
    test_episodes = None, record_test_episodes = None, return_weights = false, progress = None,
))]
#[allow(clippy::too_many_arguments)]
pub fn run_bimanual_trials<'py>(
    py: Python<'py>,
    n_trials: &Bound<'py, PyAny>,
    episodes: &Bound<'py, PyAny>,
    base_seed: &Bound<'py, PyAny>,
    first_trial: Option<&Bound<'py, PyAny>>,
    plant: Option<&Bound<'py, PyAny>>,
    learner: Option<&Bound<'py, PyAny>>,
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
        #[rustfmt::skip]
        let (options, progress) = RunArguments { n_trials, episodes, base_seed, first_trial, record_episodes,
            test_episodes, record_test_episodes, return_weights, progress }.check(None)?;
        let plant: BimanualConfig = config_or_default("plant", plant)?;
        let config: LearnerConfig = config_or_default("learner", learner)?;
        check_tables(&plant, &config).map_err(to_py)?;
        let encoder = encoder.filter(|e| !e.is_none());
        let encoder = encoder.map(|e| EncoderObject::extract("encoder", &e)).transpose()?;
        let args = latent_args(decoder.as_ref(), encoder.as_ref(), latent_low, latent_high)?;
        let latent = args.given().then(|| args.check("for the latent learner")).transpose();
        let latent = latent.map_err(to_py)?;
        let trials =
            BimanualTrials::new(plant, config, BimanualLearner::new(latent.as_ref()), options).map_err(to_py)?;
        let total = trials.options.total_episodes();
        let results = run_with_polling(py, total, progress.as_ref(), |cancel, done| {
            trials.run(cancel, done).map_err(to_py)
        })?;
        let out = pack_results(py, &results, &trials.template, &trials.options, 4)?;
        out.set_item("plant", config_to(py, &trials.plant)?)?;
        out.set_item("learner", config_to(py, &trials.config)?)?;
        Ok(out)
    })
}

/// Experiment 1's configuration checked: `(plant, learner)` dicts with every key's effective
/// value, or InvalidInputError naming the key and its rule.
#[pyfunction]
#[pyo3(signature = (plant = None, learner = None))]
pub fn bimanual_config<'py>(
    py: Python<'py>,
    plant: Option<&Bound<'py, PyAny>>,
    learner: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
    guard(|| {
        let (plant, learner): (BimanualConfig, LearnerConfig) = (
            config_or_default("plant", plant)?,
            config_or_default("learner", learner)?,
        );
        check_tables(&plant, &learner).map_err(to_py)?;
        Ok((config_to(py, &plant)?, config_to(py, &learner)?))
    })
}

/// Experiment 1's kinematic two-hand toy as a plant (`sim::bimanual::BimanualPlant`): the
/// Gymnasium environment's state and rules.
#[pyclass(name = "BimanualPlant", module = "latentrl._native")]
pub struct PyBimanualPlant {
    inner: ::sim::BimanualPlant,
}

#[pymethods]
impl PyBimanualPlant {
    /// The toy with `plant` (a dict of BimanualConfig keys; defaults for the rest).
    #[new]
    #[pyo3(signature = (plant = None))]
    fn new(plant: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        guard(|| {
            let config: BimanualConfig = config_or_default("plant", plant)?;
            Ok(Self {
                inner: ::sim::BimanualPlant::new(config).map_err(to_py)?,
            })
        })
    }

    /// Puts the hands at `posture` (4,): None, or the code of the rule it breaks.
    fn reset(&mut self, posture: numpy::PyReadonlyArray1<'_, f64>) -> PyResult<Option<u8>> {
        use latent_core::Plant;
        guard(|| {
            let x = crate::convert::fixed::<4>("posture", &posture)?;
            latent_core::error::check_finite("posture", &x).map_err(to_py)?;
            Ok(self.inner.reset(&x).map(|e| e.code()))
        })
    }

    /// Moves the hands to `target` (4,): `(reward, end code or None)`.
    fn step(&mut self, target: numpy::PyReadonlyArray1<'_, f64>) -> PyResult<(f64, Option<u8>)> {
        use latent_core::Plant;
        guard(|| {
            let x = crate::convert::fixed::<4>("target", &target)?;
            latent_core::error::check_finite("target", &x).map_err(to_py)?;
            let out = self.inner.step(&x, &mut [0.0; 4]);
            Ok((out.reward, out.end.map(|e| e.code())))
        })
    }

    /// A start (4,) by the toy's rule (left hand Gaussian around `start_mean`, right = left +
    /// grip) from ChaCha8 seeded with `seed`.
    fn sample_start<'py>(&mut self, py: Python<'py>, seed: u64) -> Bound<'py, numpy::PyArray1<f64>> {
        use latent_core::Plant;
        let mut x = [0.0; 4];
        self.inner.sample_start(&mut latent_core::trial_rng(seed, 0), &mut x);
        numpy::PyArray1::from_vec(py, x.to_vec())
    }

    /// The hands (4,): x_L, y_L, x_R, y_R.
    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        numpy::PyArray1::from_vec(py, self.inner.state().to_vec())
    }

    /// Whether the hands are within the reach radius of the target.
    fn reached(&self) -> bool {
        use latent_core::Plant;
        self.inner.reached_target()
    }

    /// The effective configuration.
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        config_to(py, self.inner.config())
    }
}

/// Whether a latent target `z` (d,) is refused (`latent_core::refused`): the code of the box
/// exit (2) or the variance gate (5; `variance` and `threshold` given), or None.
#[pyfunction]
#[pyo3(signature = (z, low, high, variance = None, threshold = None))]
pub fn latent_refusal(
    z: Vec<f64>,
    low: Vec<f64>,
    high: Vec<f64>,
    variance: Option<f64>,
    threshold: Option<f64>,
) -> PyResult<Option<u8>> {
    guard(|| {
        let refusal = latent_core::episode::refusal(&z, &low, &high, variance, threshold).map_err(to_py)?;
        Ok(refusal.map(|e| e.code()))
    })
}
