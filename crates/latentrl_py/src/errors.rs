//! Python exception classes, the single mapping from core errors to them, and [`guard`],
//! which every exported function runs its work in so that no Rust panic reaches Python.

use ::sim::SimError;
use latent_core::CoreError;
use latent_core::error::ErrorKind;
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

/// [`latent_core::panic::catch`] with a panic raised as [`InternalError`]: wraps every `#[pyfunction]` and
/// `#[pymethods]` body, so Python never sees pyo3's `PanicException` (a BaseException).
pub fn guard<T>(work: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    latent_core::panic::catch(work, InternalError::new_err)
}

/// Converts a core error into the Python exception of its kind; the message says what and where.
pub fn to_py(err: CoreError) -> PyErr {
    raise(err.kind(), err.to_string())
}

/// Converts a plant error into the Python exception of its kind.
pub fn sim_to_py(err: SimError) -> PyErr {
    raise(err.kind(), err.to_string())
}

fn raise(kind: ErrorKind, msg: String) -> PyErr {
    match kind {
        ErrorKind::Input => InvalidInputError::new_err(msg),
        ErrorKind::Numerical => NumericalError::new_err(msg),
        ErrorKind::Cancelled => PyKeyboardInterrupt::new_err(msg),
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
