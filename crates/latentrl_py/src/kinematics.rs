//! Binding of `sim::kinematics`: batch forward and inverse kinematics of the two planar arms
//! and their grip error.

use ::sim::PlanarArms;
use ::sim::kinematics::{GripTest, grip_error_batch};
use nalgebra::DMatrix;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points};
use crate::errors::{InvalidInputError, guard, sim_to_py};

/// `f` of the rows of `array` (named `name` in errors), which must be `(N, 4)`, with the GIL
/// released: (N, its result).
fn rows_of_four<T: Send>(
    py: Python<'_>,
    name: &str,
    array: &PyReadonlyArray2<'_, f64>,
    f: impl FnOnce(&[f64]) -> ::sim::error::Result<T> + Send,
) -> PyResult<(usize, T)> {
    let matrix = points(name, array)?;
    if matrix.nrows() != 4 {
        let shape = (matrix.ncols(), matrix.nrows());
        return Err(InvalidInputError::new_err(format!(
            "{name}: expected shape (N, 4), got {shape:?}"
        )));
    }
    Ok((matrix.ncols(), py.detach(|| f(matrix.as_slice())).map_err(sim_to_py)?))
}

/// `f` of the PlanarArms over the rows of `array` `(N, 4)`, as `(N, 4)`.
fn batch<'py>(
    py: Python<'py>,
    name: &str,
    array: &PyReadonlyArray2<'py, f64>,
    f: fn(&PlanarArms, &[f64]) -> ::sim::error::Result<Vec<f64>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    guard(|| {
        let (n, out) = rows_of_four(py, name, array, |rows| f(&PlanarArms::default(), rows))?;
        to_points(py, DMatrix::from_vec(4, n, out))
    })
}

/// Hands `(N, 4)` of postures `(N, 4)` (default geometry).
#[pyfunction]
pub fn arms_fk<'py>(py: Python<'py>, postures: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    batch(py, "postures", &postures, PlanarArms::forward_batch)
}

/// Elbows `(N, 4)` of postures `(N, 4)` (for drawing).
#[pyfunction]
pub fn arms_elbows<'py>(py: Python<'py>, postures: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    batch(py, "postures", &postures, PlanarArms::elbows_batch)
}

/// Postures `(N, 4)` that put the hands at `hands` `(N, 4)`.
#[pyfunction]
pub fn arms_ik<'py>(py: Python<'py>, hands: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    batch(py, "hands", &hands, PlanarArms::inverse_batch)
}

/// Grip error `(N,)` in metres of hands `(N, 4)` by `test` ("distance" or "vector").
#[pyfunction]
#[pyo3(signature = (hands, test = GripTest::DEFAULT.name()))]
pub fn grip_error<'py>(
    py: Python<'py>,
    hands: PyReadonlyArray2<'py, f64>,
    test: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let test: GripTest = test.parse().map_err(sim_to_py)?;
        let (_, out) = rows_of_four(py, "hands", &hands, |rows| grip_error_batch(rows, test))?;
        Ok(out.into_pyarray(py))
    })
}
