//! Binding of `sim::bimanual`: Experiment 1 trials (the kinematic two-hand toy) in one call.

use ::sim::bimanual::{BimanualConfig, BimanualLearner, BimanualTrials, check_tables};
use latent_core::LearnerConfig;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::{config_or_default, config_to};
use crate::errors::{guard, to_py};
use crate::projection::EncoderObject;
use crate::runner::{RunArguments, latent_args, named_arrays, run_with_polling};

/// Experiment 1's trials in parallel (`sim::bimanual::BimanualTrials`).
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
        let encoder = encoder.filter(|e| !e.is_none());
        let encoder = encoder.map(|e| EncoderObject::extract("encoder", &e)).transpose()?;
        let args = latent_args(decoder.as_ref(), encoder.as_ref(), latent_low, latent_high)?;
        let latent = args.check_given("for the latent learner").map_err(to_py)?;
        let trials =
            BimanualTrials::new(plant, config, BimanualLearner::new(latent.as_ref()), options).map_err(to_py)?;
        let total = trials.options.total_episodes();
        let results = run_with_polling(py, total, progress.as_ref(), |c, d| trials.run(c, d).map_err(to_py))?;
        named_arrays(py, trials.arrays(&results))
    })
}

/// Experiment 1's configuration checked: `(plant, learner)` with every key's effective value.
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

/// Experiment 1's kinematic two-hand toy as a plant (`sim::bimanual::BimanualPlant`).
#[pyclass(name = "BimanualPlant", module = "latentrl._native")]
pub struct PyBimanualPlant {
    inner: ::sim::BimanualPlant,
}

#[pymethods]
impl PyBimanualPlant {
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

    fn reset(&mut self, posture: numpy::PyReadonlyArray1<'_, f64>) -> PyResult<Option<u8>> {
        guard(|| {
            let end = self.inner.reset_checked(&posture.as_array().to_vec()).map_err(to_py)?;
            Ok(end.map(|e| e.code()))
        })
    }

    fn step(&mut self, target: numpy::PyReadonlyArray1<'_, f64>) -> PyResult<(f64, Option<u8>)> {
        guard(|| {
            let out = self.inner.step_checked(&target.as_array().to_vec()).map_err(to_py)?;
            Ok((out.reward, out.end.map(|e| e.code())))
        })
    }

    fn sample_start<'py>(&mut self, py: Python<'py>, seed: u64) -> Bound<'py, numpy::PyArray1<f64>> {
        numpy::PyArray1::from_vec(py, latent_core::trials::seeded_start(&mut self.inner, seed))
    }

    fn state<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        numpy::PyArray1::from_vec(py, self.inner.state().to_vec())
    }

    fn reached(&self) -> bool {
        use latent_core::Plant;
        self.inner.reached_target()
    }

    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        config_to(py, self.inner.config())
    }
}

/// The code of the rule a latent target `z` breaks (`latent_core::episode::refusal`), or None.
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
