//! NumPy ⇄ nalgebra. A C-ordered `(N, q)` array is read as a column-major `q×N` matrix
//! (one point per column) and written back the same way, so nothing is transposed.

use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;

use crate::errors::InvalidInputError;

/// `(N, q)` array → q×N matrix, points as columns. `name` appears in error messages.
pub fn points(name: &str, array: &PyReadonlyArray2<'_, f64>) -> PyResult<DMatrix<f64>> {
    let [n, q] = [array.shape()[0], array.shape()[1]];
    if n == 0 || q == 0 {
        return Err(InvalidInputError::new_err(format!("{name} is empty: shape ({n}, {q})")));
    }
    let values: Vec<f64> = match array.as_slice() {
        Ok(slice) => slice.to_vec(),
        Err(_) => array.as_array().iter().copied().collect(),
    };
    Ok(DMatrix::from_vec(q, n, values))
}

/// A 1-D array of exactly `len` values.
pub fn fixed<const LEN: usize>(name: &str, array: &PyReadonlyArray1<'_, f64>) -> PyResult<[f64; LEN]> {
    let values: Vec<f64> = array.as_array().iter().copied().collect();
    values.try_into().map_err(|v: Vec<f64>| {
        InvalidInputError::new_err(format!("{name}: expected shape ({LEN},), got ({},)", v.len()))
    })
}

/// q×N matrix → `(N, q)` array, without copying the buffer.
pub fn to_points<'py>(py: Python<'py>, matrix: DMatrix<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (q, n) = matrix.shape();
    PyArray1::from_vec(py, matrix.data.into()).reshape([n, q])
}

/// Vector → 1-D array, without copying the buffer.
pub fn to_vector<'py>(py: Python<'py>, vector: DVector<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, vector.data.into())
}
