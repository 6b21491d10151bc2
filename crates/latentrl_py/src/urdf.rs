//! Binding of `sim::urdf`: what a URDF holds, as plain dicts (for `latentrl urdf-info` and for
//! drawing a robot).

use std::path::PathBuf;

use ::sim::UrdfModel;
use ::sim::urdf::LoadOptions;
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use crate::convert::config_to;
use crate::errors::{guard, sim_to_py};

/// What a checked URDF file holds (`sim::urdf::UrdfSummary`), as a dict.
#[pyfunction]
#[pyo3(signature = (path, *, balance_inertia = LoadOptions::default().balance_inertia))]
pub fn urdf_info<'py>(py: Python<'py>, path: PathBuf, balance_inertia: bool) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let options = LoadOptions { balance_inertia };
        let summary = py
            .detach(|| UrdfModel::summary_of_file(&path, options))
            .map_err(sim_to_py)?;
        config_to(py, &summary)
    })
}

/// The demonstration column of each actuated joint (`UrdfModel::demo_columns`).
#[pyfunction]
pub fn demo_columns(
    py: Python<'_>,
    path: PathBuf,
    names: Vec<String>,
    postures: PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<usize>> {
    guard(|| {
        let rows: Vec<Vec<f64>> = postures.as_array().rows().into_iter().map(|r| r.to_vec()).collect();
        py.detach(|| UrdfModel::demo_columns_of_file(&path, &names, &rows))
            .map_err(sim_to_py)
    })
}
