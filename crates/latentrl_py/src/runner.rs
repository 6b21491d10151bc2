//! What every trial runner of the binding shares: the run arguments and the latent maps read
//! from Python (the core checks them: `TrialOptions::from_args`, `LatentArgs::check`), the
//! polling worker (GIL released, Ctrl-C and progress every 0.1 s) and the result dict.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use latent_core::trials::{Corner, LatentArgs};
use latent_core::{GpMap, ResultArray, RunArgs, TrialOptions};
use numpy::{PyArray1, PyArrayMethods};
use pyo3::conversion::FromPyObjectOwned;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::type_name;
use crate::errors::{InvalidInputError, to_py};
use crate::gp::PyGpMap;
use crate::projection::EncoderObject;

/// How often the calling thread wakes to check Ctrl-C and report progress.
const POLL: Duration = Duration::from_millis(100);

pub(crate) fn invalid(msg: String) -> PyErr {
    InvalidInputError::new_err(msg)
}

/// `value` as a `T`, or the error naming `name` and what it should be.
fn arg<'py, T: FromPyObjectOwned<'py>>(name: &str, what: &str, value: &Bound<'py, PyAny>) -> PyResult<T> {
    value
        .extract()
        .map_err(|_| invalid(format!("{name}: expected {what}, got {}", type_name(value))))
}

/// `value` unless it is None.
fn given<'a, 'py>(value: Option<&'a Bound<'py, PyAny>>) -> Option<&'a Bound<'py, PyAny>> {
    value.filter(|v| !v.is_none())
}

/// A GpMap argument, or None.
pub(crate) fn gp_map<'a, 'py>(name: &str, value: Option<&'a Bound<'py, PyAny>>) -> PyResult<Option<&'a GpMap>> {
    match given(value) {
        None => Ok(None),
        Some(v) => v
            .cast::<PyGpMap>()
            .map(|m| Some(&m.get().inner))
            .map_err(|_| invalid(format!("{name}: expected a GpMap, got {}", type_name(v)))),
    }
}

/// A corner of the latent box: its numbers, or the name of its type; None for None.
pub(crate) fn corner(value: Option<&Bound<'_, PyAny>>) -> Option<Corner> {
    given(value).map(|v| v.extract::<Vec<f64>>().map_err(|_| type_name(v)))
}

/// The latent maps and box as given (an encoder of the wrong type is refused here).
pub(crate) fn latent_args<'a, 'py>(
    decoder: Option<&'a Bound<'py, PyAny>>,
    encoder: Option<&'a EncoderObject>,
    low: Option<&Bound<'py, PyAny>>,
    high: Option<&Bound<'py, PyAny>>,
) -> PyResult<LatentArgs<'a>> {
    Ok(LatentArgs {
        decoder: gp_map("decoder", decoder)?,
        encoder: encoder.map(EncoderObject::get),
        low: corner(low),
        high: corner(high),
    })
}

/// The arguments every trial runner takes, as given.
pub(crate) struct RunArguments<'a, 'py> {
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

impl<'py> RunArguments<'_, 'py> {
    /// The trial options (checked by the core; `rollout` as `RunArgs::rollout`) and the
    /// progress callback.
    pub(crate) fn check(self, rollout: Option<(String, bool)>) -> PyResult<(TrialOptions, Option<Bound<'py, PyAny>>)> {
        let int = |name, value| arg(name, "an int", value);
        let optional = |name, value| given(value).map(|v| int(name, v)).transpose();
        let ints = |name, value| given(value).map_or(Ok(Vec::new()), |v| arg(name, "a sequence of ints", v));
        let args = RunArgs {
            n_trials: int("n_trials", self.n_trials)?,
            episodes: int("episodes", self.episodes)?,
            base_seed: int("base_seed", self.base_seed)?,
            first_trial: optional("first_trial", self.first_trial)?,
            record_episodes: ints("record_episodes", self.record_episodes)?,
            test_episodes: optional("test_episodes", self.test_episodes)?,
            record_test_episodes: ints("record_test_episodes", self.record_test_episodes)?,
            keep_weights: self.return_weights,
            rollout,
        };
        let options = TrialOptions::from_args(&args).map_err(to_py)?;
        let progress = self.progress.filter(|p| !p.is_none());
        if let Some(p) = &progress
            && !p.is_callable()
        {
            return Err(invalid(format!(
                "progress: expected a callable or None, got {}",
                type_name(p)
            )));
        }
        Ok((options, progress))
    }
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

/// Named arrays (`latent_core::trial_arrays`, a survey's) as a dict of NumPy arrays.
pub(crate) fn named_arrays(py: Python<'_>, arrays: Vec<(String, ResultArray)>) -> PyResult<Bound<'_, PyDict>> {
    let out = PyDict::new(py);
    for (name, array) in arrays {
        match array {
            ResultArray::F64(v, shape) => out.set_item(name, PyArray1::from_vec(py, v).reshape(shape)?),
            ResultArray::I8(v, shape) => out.set_item(name, PyArray1::from_vec(py, v).reshape(shape)?),
            ResultArray::U8(v, shape) => out.set_item(name, PyArray1::from_vec(py, v).reshape(shape)?),
            ResultArray::I64(v, shape) => out.set_item(name, PyArray1::from_vec(py, v).reshape(shape)?),
            ResultArray::Bool(v, shape) => out.set_item(name, PyArray1::from_vec(py, v).reshape(shape)?),
            ResultArray::Count(n) => out.set_item(name, n),
            ResultArray::None => out.set_item(name, py.None()),
        }?;
    }
    Ok(out)
}
