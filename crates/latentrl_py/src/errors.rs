//! Python exception classes and the single mapping from core errors to them.

use ::sim::SimError;
use latent_core::CoreError;
use pyo3::create_exception;
use pyo3::exceptions::PyValueError;
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

/// Converts a core error into its Python exception; the message says what and where.
pub fn to_py(err: CoreError) -> PyErr {
    let msg = err.to_string();
    match err {
        CoreError::Shape { .. }
        | CoreError::NonFinite { .. }
        | CoreError::Empty { .. }
        | CoreError::InvalidParameter { .. }
        | CoreError::NoValidStart { .. }
        | CoreError::Plant { .. } => InvalidInputError::new_err(msg),
        CoreError::NotPositiveDefinite { .. } => NumericalError::new_err(msg),
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
        | SimError::UnsupportedGeometry { .. }
        | SimError::UnknownJoint { .. }
        | SimError::UnknownLink { .. }
        | SimError::InvalidJointParameter { .. }
        | SimError::UnknownObstacle { .. } => InvalidInputError::new_err(msg),
    }
}

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("LatentrlError", py.get_type::<LatentrlError>())?;
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add("NumericalError", py.get_type::<NumericalError>())?;
    Ok(())
}
