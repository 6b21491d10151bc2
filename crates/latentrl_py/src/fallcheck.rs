//! Binding of `sim::fallcheck`: the fall check of a floating robot's task in one call.

use ::sim::World;
use ::sim::fallcheck::{FallCheckConfig, run_fall_check_observed};
use nalgebra::DMatrix;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points};
use crate::errors::{InvalidInputError, guard, sim_to_py};
use crate::task::PyTask;

/// Columns of the returned table, one row per target.
const COLUMNS: usize = 7;
/// Columns of a recorded frame before the joint positions: time, fell, base x y z, base
/// quaternion x y z w.
const FRAME_HEAD: usize = 9;

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
        if let Some(bad) = record_times.iter().find(|t| !(t.is_finite() && **t >= 0.0)) {
            return Err(InvalidInputError::new_err(format!(
                "record_times: expected finite times ≥ 0 s, got {bad}"
            )));
        }
        let start: Vec<f64> = start.as_array().iter().copied().collect();
        let targets = points("targets", &targets)?;
        if targets.nrows() != start.len() {
            return Err(InvalidInputError::new_err(format!(
                "targets: expected shape (M, {}), got ({}, {})",
                start.len(),
                targets.ncols(),
                targets.nrows()
            )));
        }
        let rows: Vec<Vec<f64>> = targets.column_iter().map(|c| c.iter().copied().collect()).collect();
        let task = &task.inner;
        let config = FallCheckConfig::for_task(task, hold).map_err(sim_to_py)?;
        let world = task.world_config();
        let dt = world.physics.dt;
        let mut pending: Vec<f64> = record_times.iter().map(|t| (t / dt).round()).collect();
        pending.sort_by(|a, b| b.total_cmp(a));
        let mut frames: Vec<f64> = Vec::new();
        let reports = py
            .detach(|| {
                let mut sim = World::new(task.model().clone(), world)?;
                run_fall_check_observed(&mut sim, &start, &rows, &config, |sim, fell| {
                    let done = (sim.time() / dt).round();
                    while pending.last().is_some_and(|&step| done >= step) {
                        pending.pop();
                        let base = sim.base_pose();
                        frames.extend([sim.time(), f64::from(u8::from(fell))]);
                        frames.extend(base.translation.vector.iter());
                        frames.extend(base.rotation.coords.iter());
                        frames.extend(sim.joint_positions());
                    }
                })
            })
            .map_err(sim_to_py)?;
        let mut out = DMatrix::zeros(COLUMNS, reports.len());
        for (j, r) in reports.iter().enumerate() {
            let row = [
                f64::from(u8::from(r.fell)),
                r.min_margin,
                r.final_margin,
                r.grip_error,
                r.max_grip_error,
                r.status.base_height,
                r.fall_time.unwrap_or(f64::NAN),
            ];
            out.column_mut(j).copy_from_slice(&row);
        }
        let width = FRAME_HEAD + start.len();
        let frames = DMatrix::from_vec(width, frames.len() / width, frames);
        Ok((to_points(py, out)?, to_points(py, frames)?))
    })
}
