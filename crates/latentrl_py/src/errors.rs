//! Python exception classes, the single mapping from core errors to them, and [`guard`],
//! which every exported function runs its work in so that no Rust panic reaches Python.

use std::any::Any;
use std::panic::{AssertUnwindSafe, catch_unwind};

use ::sim::SimError;
use latent_core::CoreError;
use pyo3::create_exception;
use pyo3::exceptions::{PyKeyboardInterrupt, PyValueError};
use pyo3::prelude::*;

create_exception!(
    latentrl._native,
    LatentrlError,
    PyValueError,
    "Base class of latentrl's errors (a ValueError)."
);
create_exception!(
    latentrl._native,
    InvalidInputError,
    LatentrlError,
    "An argument had the wrong shape, a non-finite value or an impossible value."
);
create_exception!(
    latentrl._native,
    NumericalError,
    LatentrlError,
    "A computation could not be carried out stably (e.g. a kernel matrix not positive definite)."
);

create_exception!(
    latentrl._native,
    InternalError,
    LatentrlError,
    "A bug in latentrl's Rust core (a caught panic); please report it with the message."
);

/// Where to report an [`InternalError`].
const REPORT: &str = "this is a bug in latentrl; please report it with this message and the call that raised it";

/// The text of a panic payload (`panic!` with a literal or a formatted message), or a
/// placeholder for any other payload.
pub fn panic_message(payload: &(dyn Any + Send)) -> String {
    if let Some(s) = payload.downcast_ref::<&str>() {
        (*s).to_string()
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s.clone()
    } else {
        "unknown panic payload".to_string()
    }
}

/// The message of the [`InternalError`] raised for a panic with `payload`.
pub fn internal_message(payload: &(dyn Any + Send)) -> String {
    format!("internal error (Rust panic): {}; {REPORT}", panic_message(payload))
}

/// Runs `work`, the body of an exported function; a panic in it (on this thread, in a rayon
/// worker it joins, or re-raised from a joined thread) becomes the `Err` of
/// [`internal_message`] instead of unwinding.
pub fn catch<T, E>(work: impl FnOnce() -> Result<T, E>, on_panic: impl FnOnce(String) -> E) -> Result<T, E> {
    catch_unwind(AssertUnwindSafe(work)).unwrap_or_else(|payload| Err(on_panic(internal_message(&*payload))))
}

/// [`catch`] with a panic raised as [`InternalError`]: wraps every `#[pyfunction]` and
/// `#[pymethods]` body, so Python never sees pyo3's `PanicException` (a BaseException).
pub fn guard<T>(work: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch(work, InternalError::new_err)
}

/// Converts a core error into its Python exception; the message says what and where.
pub fn to_py(err: CoreError) -> PyErr {
    let msg = err.to_string();
    match err {
        CoreError::Shape { .. }
        | CoreError::NonFinite { .. }
        | CoreError::Empty { .. }
        | CoreError::InvalidParameter { .. }
        | CoreError::NoValidStart { .. }
        | CoreError::Param(_)
        | CoreError::Plant { .. }
        | CoreError::TooLarge { .. } => InvalidInputError::new_err(msg),
        CoreError::NotPositiveDefinite { .. } | CoreError::Overflow { .. } => NumericalError::new_err(msg),
        CoreError::Cancelled => PyKeyboardInterrupt::new_err(msg),
    }
}

/// Converts a plant error into its Python exception: the core's errors as [`to_py`], every
/// other `sim` error is bad input.
pub fn sim_to_py(err: SimError) -> PyErr {
    let msg = err.to_string();
    match err {
        SimError::Input(core) => to_py(core),
        SimError::Unreachable { .. }
        | SimError::MissingFile { .. }
        | SimError::MalformedUrdf { .. }
        | SimError::UnsupportedJointType { .. }
        | SimError::Mesh { .. }
        | SimError::UnknownJoint { .. }
        | SimError::UnknownLink { .. }
        | SimError::InvalidJointParameter { .. }
        | SimError::Param(_)
        | SimError::Task { .. }
        | SimError::UnknownObstacle { .. }
        | SimError::DemoColumns { .. } => InvalidInputError::new_err(msg),
    }
}

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("LatentrlError", py.get_type::<LatentrlError>())?;
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    m.add("InternalError", py.get_type::<InternalError>())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn caught<T>(work: impl FnOnce() -> Result<T, String>) -> Result<T, String> {
        catch(work, |msg| msg)
    }

    #[test]
    fn results_pass_through() {
        assert_eq!(caught(|| Ok(3)), Ok(3));
        assert_eq!(caught::<()>(|| Err("bad input".into())), Err("bad input".into()));
    }

    #[test]
    fn panics_become_errors_with_message_and_hint() {
        let literal = caught::<()>(|| panic!("literal")).unwrap_err();
        assert!(
            literal.contains("literal") && literal.contains("please report"),
            "{literal}"
        );
        let formatted = caught::<()>(|| panic!("index {} out of range", 7)).unwrap_err();
        assert!(formatted.contains("index 7 out of range"), "{formatted}");
        let other = caught::<()>(|| std::panic::panic_any(42_u8)).unwrap_err();
        assert!(other.contains("unknown panic payload"), "{other}");
    }

    #[test]
    fn panics_in_rayon_and_joined_threads_are_caught() {
        use rayon::prelude::*;
        let msg = caught::<Vec<u32>>(|| {
            Ok((0..64_u32)
                .into_par_iter()
                .map(|i| if i == 33 { panic!("worker {i}") } else { i })
                .collect())
        })
        .unwrap_err();
        assert!(msg.contains("worker 33"), "{msg}");
        let msg = caught::<()>(|| {
            std::thread::scope(|s| s.spawn(|| panic!("thread")).join()).map_err(|p| std::panic::resume_unwind(p))
        })
        .unwrap_err();
        assert!(msg.contains("thread"), "{msg}");
    }
}
