//! NumPy ⇄ nalgebra. A C-ordered `(N, q)` array is read as a column-major `q×N` matrix
//! (one point per column) and written back the same way, so nothing is transposed.

use nalgebra::{DMatrix, DVector};
use numpy::{PyArray1, PyArray2, PyArrayMethods, PyReadonlyArray1, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
use serde::Serialize;
use serde::de::DeserializeOwned;

use crate::errors::InvalidInputError;

/// `(N, q)` array → q×N matrix, points as columns. `name` appears in error messages.
pub fn points(name: &str, array: &PyReadonlyArray2<'_, f64>) -> PyResult<DMatrix<f64>> {
    let [n, q] = [array.shape()[0], array.shape()[1]];
    if n == 0 || q == 0 {
        return Err(InvalidInputError::new_err(format!("{name} is empty: shape ({n}, {q})")));
    }
    // ndarray's `as_slice` is the row-major buffer only (numpy's would also hand out a
    // Fortran-ordered one, whose memory order is the transpose).
    let view = array.as_array();
    let values: Vec<f64> = match view.as_slice() {
        Some(slice) => slice.to_vec(),
        None => view.iter().copied().collect(),
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

/// Rows of a `(N, D)` array of postures, or None.
pub fn rows(name: &str, array: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Option<Vec<Vec<f64>>>> {
    array
        .map(|a| {
            let m = points(name, &a)?;
            Ok(m.column_iter().map(|c| c.iter().copied().collect()).collect())
        })
        .transpose()
}

/// q×N matrix → `(N, q)` array, without copying the buffer.
pub fn to_points<'py>(py: Python<'py>, matrix: DMatrix<f64>) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let (q, n) = matrix.shape();
    PyArray1::from_vec(py, matrix.data.into()).reshape([n, q])
}

/// Rows of `width` values, one after the other → `(N, width)` array, without copying the buffer.
pub fn to_rows(py: Python<'_>, width: usize, values: Vec<f64>) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let n = values.len() / width;
    PyArray1::from_vec(py, values).reshape([n, width])
}

/// Vector → 1-D array, without copying the buffer.
pub fn to_vector<'py>(py: Python<'py>, vector: DVector<f64>) -> Bound<'py, PyArray1<f64>> {
    PyArray1::from_vec(py, vector.data.into())
}

/// The Python type name of `value`, for error messages.
pub(crate) fn type_name(value: &Bound<'_, PyAny>) -> String {
    value
        .get_type()
        .name()
        .map(|n| n.to_string())
        .unwrap_or_else(|_| "?".into())
}

/// The deepest nesting of lists and dicts a configuration may have (a task nests 4 levels;
/// the conversion recurses per level, and 200 000 nested lists overflowed the stack).
const MAX_CONFIG_DEPTH: usize = 32;

/// A configuration (`TaskConfig`, `LearnerConfig`, …) from a Python dict: read as the TOML
/// value it stands for, then deserialised as a task file is, so a bad value gets the task
/// file's message (`learner.gamma: invalid type: string "x", expected a number`), naming `what` and
/// the key path. A None value is a key left out (TOML has no null).
pub fn config_from<T: DeserializeOwned>(what: &str, value: &Bound<'_, PyAny>) -> PyResult<T> {
    let fail = |path: &str, message: String| {
        let at = if path == "." || path.is_empty() {
            String::new()
        } else {
            format!("{path}: ")
        };
        InvalidInputError::new_err(format!("{what}: {at}{message}"))
    };
    if !value.is_instance_of::<PyDict>() {
        return Err(fail("", format!("expected a dict of keys, got {}", type_name(value))));
    }
    let value = toml_value(value, "", 0).map_err(|(path, message)| fail(&path, message))?;
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        fail(&path, latent_core::error::plain_types(e.into_inner().message()))
    })
}

/// [`config_from`], or the configuration's defaults for None.
pub fn config_or_default<T: DeserializeOwned + Default>(what: &str, value: Option<&Bound<'_, PyAny>>) -> PyResult<T> {
    value
        .filter(|v| !v.is_none())
        .map_or(Ok(T::default()), |v| config_from(what, v))
}

/// A Python value as a TOML value, by its own type: a bool is never a number, a string never a
/// bool (NumPy arrays and scalars through `tolist`). Err: (key path, what is wrong).
fn toml_value(value: &Bound<'_, PyAny>, path: &str, depth: usize) -> Result<toml::Value, (String, String)> {
    let join = |key: &str| {
        if path.is_empty() {
            key.to_string()
        } else {
            format!("{path}.{key}")
        }
    };
    let wrong = |what: String| (path.to_string(), what);
    if depth > MAX_CONFIG_DEPTH {
        return Err(wrong(format!("nested deeper than {MAX_CONFIG_DEPTH} lists or tables")));
    }
    if let Ok(b) = value.cast::<PyBool>() {
        return Ok(toml::Value::Boolean(b.is_true()));
    }
    if value.is_instance_of::<PyInt>() {
        let i: i64 = value
            .extract()
            .map_err(|_| wrong(format!("the integer {value} is too large")))?;
        return Ok(toml::Value::Integer(i));
    }
    if let Ok(f) = value.cast::<PyFloat>() {
        return Ok(toml::Value::Float(f.value()));
    }
    if let Ok(s) = value.cast::<PyString>() {
        return Ok(toml::Value::String(s.to_string()));
    }
    if let Ok(map) = value.cast::<PyDict>() {
        let mut table = toml::Table::new();
        for (k, v) in map.iter() {
            let key: String = k
                .extract()
                .map_err(|_| wrong(format!("a key must be a string, got {k}")))?;
            if !v.is_none() {
                let item = toml_value(&v, &join(&key), depth + 1)?;
                table.insert(key, item);
            }
        }
        return Ok(toml::Value::Table(table));
    }
    if value.hasattr("tolist").unwrap_or(false) && !value.is_instance_of::<PyList>() {
        let plain = value.call_method0("tolist").map_err(|e| wrong(e.to_string()))?;
        return toml_value(&plain, path, depth);
    }
    if value.is_instance_of::<PyList>() || value.is_instance_of::<PyTuple>() {
        let items = value.try_iter().map_err(|e| wrong(e.to_string()))?;
        let mut array = Vec::new();
        for (i, item) in items.enumerate() {
            let item = item.map_err(|e| wrong(e.to_string()))?;
            if item.is_none() {
                return Err(wrong(format!("item {i} is None")));
            }
            array.push(toml_value(&item, path, depth + 1)?);
        }
        return Ok(toml::Value::Array(array));
    }
    Err(wrong(format!(
        "invalid type: {} {value}, expected a bool, number, string, list or dict",
        type_name(value)
    )))
}

/// A configuration as a Python dict (nested tables as dicts, none as None).
pub fn config_to<'py, T: Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    pythonize::pythonize(py, value).map_err(|e| InvalidInputError::new_err(e.to_string()))
}
