//! Binding of `sim::urdf`: what a URDF holds, as plain dicts (for `latentrl urdf-info` and for
//! drawing a robot).

use std::path::PathBuf;

use ::sim::UrdfModel;
use ::sim::urdf::{LoadOptions, ShapeInfo, ShapeSummary};
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;

use crate::convert::config_to;
use crate::errors::{guard, sim_to_py};

/// Shapes as a list of dicts `{link, kind, size, origin, file, hull, points}` (`sim::urdf::ShapeSummary`).
pub fn shape_list<'py>(py: Python<'py>, shapes: &[ShapeInfo], links: &[&str]) -> PyResult<Bound<'py, PyAny>> {
    config_to(py, &ShapeSummary::all(shapes, links))
}

/// Reads and checks a URDF file (meshes hulled, through the cache; inertias repaired with
/// `balance_inertia`) and returns what it holds: `{name, joints, links, collision, visual,
/// total_mass, warnings}` (warnings: what was repaired, one sentence each); each joint a dict `{name, type,
/// lower, upper, effort, velocity, damping, friction, mimic}` (mimic: `{leader, multiplier,
/// offset}` or None), actuated joints first in URDF order, then the mimic ones.
#[pyfunction]
#[pyo3(signature = (path, *, balance_inertia = false))]
pub fn urdf_info<'py>(py: Python<'py>, path: PathBuf, balance_inertia: bool) -> PyResult<Bound<'py, PyAny>> {
    guard(|| {
        let options = LoadOptions { balance_inertia };
        let cache = ::sim::urdf::cache::default_folder();
        let model = py
            .detach(|| UrdfModel::from_file_with_options(&path, cache.as_deref(), options))
            .map_err(sim_to_py)?;
        config_to(py, &model.summary())
    })
}

/// The columns of demonstrations named `names` (postures `(N, len(names))`) as the robot's
/// postures: for each actuated joint in URDF order, the index of its column (any order; a
/// mimic joint's column is checked against its leader and dropped; `UrdfModel::demo_columns`).
#[pyfunction]
pub fn demo_columns(
    py: Python<'_>,
    path: PathBuf,
    names: Vec<String>,
    postures: PyReadonlyArray2<'_, f64>,
) -> PyResult<Vec<usize>> {
    guard(|| {
        let array = postures.as_array();
        if array.ncols() != names.len() {
            return Err(pyo3::exceptions::PyValueError::new_err(format!(
                "postures: {} columns for {} joint names",
                array.ncols(),
                names.len()
            )));
        }
        let rows: Vec<Vec<f64>> = array.rows().into_iter().map(|r| r.to_vec()).collect();
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        py.detach(|| UrdfModel::from_file(&path).and_then(|m| m.demo_columns(&names, &rows)))
            .map_err(sim_to_py)
    })
}
