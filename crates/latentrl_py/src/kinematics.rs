//! Binding of `sim::kinematics`: batch forward and inverse kinematics of the two planar arms
//! and their grip error.

use ::sim::PlanarArms;
use ::sim::kinematics::{GripTest, grip_error_batch};
use nalgebra::DMatrix;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points};
use crate::errors::{InvalidInputError, guard, sim_to_py};

/// The rows of `array` (named `name` in errors), which must be `(N, 4)`.
fn rows_of_four(name: &str, array: &PyReadonlyArray2<'_, f64>) -> PyResult<DMatrix<f64>> {
    let matrix = points(name, array)?;
    if matrix.nrows() != 4 {
        return Err(InvalidInputError::new_err(format!(
            "{name}: expected shape (N, 4), got ({}, {})",
            matrix.ncols(),
            matrix.nrows()
        )));
    }
    Ok(matrix)
}

/// `f` of the PlanarArms over the rows of `array` `(N, 4)` (named `name` in errors), as `(N, 4)`.
fn batch<'py>(
    py: Python<'py>,
    name: &str,
    array: &PyReadonlyArray2<'py, f64>,
    f: fn(&PlanarArms, &[f64]) -> ::sim::error::Result<Vec<f64>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    guard(|| {
        let matrix = rows_of_four(name, array)?;
        let out = py
            .detach(|| f(&PlanarArms::default(), matrix.as_slice()))
            .map_err(sim_to_py)?;
        to_points(py, DMatrix::from_vec(4, matrix.ncols(), out))
    })
}

/// Hands `(N, 4)` `[x_L, y_L, x_R, y_R]` of postures `(N, 4)` `[q1_L, q2_L, q1_R, q2_R]`
/// (default geometry: shoulders (±0.15, 0), links 0.3 + 0.3 m).
#[pyfunction]
pub fn arms_fk<'py>(py: Python<'py>, postures: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    batch(py, "postures", &postures, PlanarArms::forward_batch)
}

/// Elbows `(N, 4)` `[x_L, y_L, x_R, y_R]` of postures `(N, 4)` (for drawing).
#[pyfunction]
pub fn arms_elbows<'py>(py: Python<'py>, postures: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    batch(py, "postures", &postures, PlanarArms::elbows_batch)
}

/// Postures `(N, 4)` (elbows outward, shoulder angles continuous in front of the body) that
/// put the hands at `hands` `(N, 4)`; an unreachable row raises InvalidInputError.
#[pyfunction]
pub fn arms_ik<'py>(py: Python<'py>, hands: PyReadonlyArray2<'py, f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    batch(py, "hands", &hands, PlanarArms::inverse_batch)
}

/// Grip error `(N,)` in metres of hands `(N, 4)` by `test`: `"distance"`
/// `| ‖hand_R − hand_L‖ − 0.1 |` or `"vector"` `‖(hand_R − hand_L) − (0.1, 0)‖`.
#[pyfunction]
#[pyo3(signature = (hands, test = "distance"))]
pub fn grip_error<'py>(
    py: Python<'py>,
    hands: PyReadonlyArray2<'py, f64>,
    test: &str,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    guard(|| {
        let test: GripTest = test.parse().map_err(sim_to_py)?;
        let matrix = rows_of_four("hands", &hands)?;
        let out = py
            .detach(|| grip_error_batch(matrix.as_slice(), test))
            .map_err(sim_to_py)?;
        Ok(out.into_pyarray(py))
    })
}
