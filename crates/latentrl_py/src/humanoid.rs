//! Binding of `sim::humanoid`: the fall check of the floating humanoid in one call.

use ::sim::humanoid::{FallCheckConfig, run_fall_check};
use ::sim::{PdGains, PhysicsSim, RootMode, SimOptions};
use nalgebra::DMatrix;
use numpy::{PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, to_points};
use crate::errors::{InvalidInputError, guard, sim_to_py};

/// Columns of the returned table, one row per target.
const COLUMNS: usize = 6;

/// Runs the fall check of `sim::humanoid::run_fall_check` on the URDF at `urdf_path`
/// (floating root, ground at z = 0): stand at `start` `(D,)`, hold each row of `targets`
/// `(M, D)` for `hold` s under PD servos (`kp` N·m/rad, `kd` N·m·s/rad, torque capped at
/// `max_force` and at the URDF effort), physics step `dt`, `solver_iterations`,
/// `pgs_iterations`.
/// Returns `(M, 6)`: fell (0/1), smallest support margin (m), final support margin (m),
/// grip error at the end (hand distance − `grip_width`, m), largest |grip error| (m),
/// base height at the end (m).
#[pyfunction]
#[pyo3(signature = (urdf_path, start, targets, *, hold, kp, kd, max_force, dt, solver_iterations, pgs_iterations, grip_width))]
#[allow(clippy::too_many_arguments)]
pub fn humanoid_fall_check<'py>(
    py: Python<'py>,
    urdf_path: &str,
    start: PyReadonlyArray1<'py, f64>,
    targets: PyReadonlyArray2<'py, f64>,
    hold: f64,
    kp: f64,
    kd: f64,
    max_force: f64,
    dt: f64,
    solver_iterations: usize,
    pgs_iterations: usize,
    grip_width: f64,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    guard(|| {
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
        let gains = PdGains::new(kp, kd, max_force).map_err(sim_to_py)?;
        let options = SimOptions {
            root: RootMode::Floating,
            ground: Some(0.0),
            gains,
            dt,
            solver_iterations,
            pgs_iterations,
            ..SimOptions::default()
        };
        let config = FallCheckConfig {
            hold,
            grip_width,
            ..FallCheckConfig::default()
        };
        let path = urdf_path.to_string();
        let reports = py
            .detach(|| {
                let mut sim = PhysicsSim::from_urdf_file(&path, options)?;
                run_fall_check(&mut sim, &start, &rows, &config)
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
            ];
            out.column_mut(j).copy_from_slice(&row);
        }
        to_points(py, out)
    })
}
