//! Binding of `sim::fallcheck`: the fall check of a floating robot's task in one call.

use ::sim::fallcheck::{FRAME_HEAD, REPORT_COLUMNS, run_task_fall_check};
use nalgebra::DMatrix;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points};
use crate::errors::{guard, sim_to_py};
use crate::task::PyTask;

/// The fall check's per-target table and its recorded frames.
type TableAndFrames<'py> = (Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>);

/// Runs the fall check (`sim::fallcheck::run_fall_check`) of `task` (a floating robot with a
/// `[fall]` rule and a distance constraint, the grip): in the task's world, stand at `start`
/// `(D,)`, hold each row of `targets` `(M, D)` for `hold` s.
/// Returns `(table, frames)`. `table` `(M, 7)`: fell (0/1), smallest support margin (m),
/// final support margin (m), grip error at the end (hand distance − `grip_width`, m),
/// largest |grip error| (m), base height at the end (m), time of the fall (s since the
/// start, NaN while standing). `frames` `(K, 9 + D)`, one per `record_times` entry (s) that
/// the check reaches, taken at the first check (every 4 physics steps) at or after it: time
/// (s), fell (0/1), base position (m), base quaternion (x, y, z, w), joint positions.
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
        let start: Vec<f64> = start.as_array().iter().copied().collect();
        let targets = points("targets", &targets)?;
        let task = &task.inner;
        let (reports, frames) = py
            .detach(|| run_task_fall_check(task, &start, &targets, hold, &record_times))
            .map_err(sim_to_py)?;
        let table = reports.iter().flat_map(|r| r.row()).collect();
        let table = DMatrix::from_vec(REPORT_COLUMNS.len(), reports.len(), table);
        let width = FRAME_HEAD + start.len();
        let frames = DMatrix::from_vec(width, frames.len() / width, frames);
        Ok((to_points(py, table)?, to_points(py, frames)?))
    })
}
