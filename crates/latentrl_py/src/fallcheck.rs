//! Binding of `sim::fallcheck`: the fall check of a floating robot's task in one call.

use ::sim::fallcheck::run_task_fall_check;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points};
use crate::errors::{guard, sim_to_py};
use crate::task::PyTask;

/// The fall check's per-target table and its recorded frames.
type TableAndFrames<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// The fall check of `task` (`sim::fallcheck::run_task_fall_check`): `(table, frames)`.
#[pyfunction]
#[pyo3(signature = (task, start, targets, *, hold, record_times = Vec::new()))]
pub fn fall_check<'py>(
    py: Python<'py>,
    task: &PyTask,
    start: PyReadonlyArray1<'py, f64>,
    targets: PyReadonlyArray2<'py, f64>,
    hold: f64,
    record_times: Vec<f64>,
) -> PyResult<TableAndFrames<'py>> {
    guard(|| {
        let start = start.as_array().to_vec();
        let targets = points("targets", &targets)?;
        let task = &task.inner;
        let check = py
            .detach(|| run_task_fall_check(task, &start, &targets, hold, &record_times))
            .map_err(sim_to_py)?;
        Ok((to_points(py, check.table())?, to_points(py, check.frames)?))
    })
}
