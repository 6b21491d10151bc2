//! Binding of `sim::task::TaskPlant`: a task's robot in its world, stepped from Python.

use std::sync::Arc;

use ::sim::task::TaskPlant;
use ::sim::world::{POSE_WIDTH, POSITION_WIDTH};
use latent_core::trials::seeded_start;
use latent_core::{EndReason, Plant};
use numpy::{PyArray1, PyArray2, PyReadonlyArray1, PyReadonlyArray2};
use pyo3::prelude::*;

use crate::convert::{points, rows, to_points, to_rows};
use crate::errors::{guard, sim_to_py};
use crate::task::PyTask;

/// `classify`'s result: one code per posture and the effector positions.
type CodesEffectorsTargets<'py> = (
    Bound<'py, PyArray1<i8>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// The robot of a task in its world (`sim::task::TaskPlant`).
#[pyclass(name = "TaskPlant", module = "latentrl._native")]
pub struct PyTaskPlant {
    inner: TaskPlant,
}

#[pymethods]
impl PyTaskPlant {
    #[new]
    #[pyo3(signature = (task, demos = None))]
    fn new(py: Python<'_>, task: &PyTask, demos: Option<PyReadonlyArray2<'_, f64>>) -> PyResult<Self> {
        guard(|| {
            let demos = rows("demos", demos)?;
            let task = Arc::clone(&task.inner);
            let inner = py
                .detach(|| TaskPlant::new(task, demos.as_deref()))
                .map_err(sim_to_py)?;
            Ok(Self { inner })
        })
    }

    fn reset(&mut self, posture: PyReadonlyArray1<'_, f64>) -> PyResult<Option<u8>> {
        guard(|| Ok(self.inner.reset(&posture.as_array().to_vec()).map(EndReason::code)))
    }

    fn step<'py>(
        &mut self,
        py: Python<'py>,
        target: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<(f64, Option<u8>, Bound<'py, PyArray1<f64>>)> {
        guard(|| {
            let target = target.as_array().to_vec();
            let inner = &mut self.inner;
            let (out, reached) = py.detach(|| inner.step_checked(&target)).map_err(sim_to_py)?;
            Ok((
                out.reward,
                out.end.map(EndReason::code),
                PyArray1::from_vec(py, reached),
            ))
        })
    }

    fn classify<'py>(
        &mut self,
        py: Python<'py>,
        postures: PyReadonlyArray2<'py, f64>,
    ) -> PyResult<CodesEffectorsTargets<'py>> {
        guard(|| {
            let postures = points("postures", &postures)?;
            let inner = &mut self.inner;
            let c = py.detach(|| inner.classify(&postures)).map_err(sim_to_py)?;
            Ok((
                PyArray1::from_vec(py, c.codes),
                to_points(py, c.effectors)?,
                to_points(py, c.targets)?,
            ))
        })
    }

    fn sample_start<'py>(&mut self, py: Python<'py>, seed: u64) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, seeded_start(&mut self.inner, seed))
    }

    fn effectors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.effectors().to_vec())
    }

    fn target_position<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        to_rows(py, POSITION_WIDTH, self.inner.target_position())
    }

    fn joint_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.world().joint_positions())
    }

    fn targets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.world().targets().to_vec())
    }

    fn row<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.task_row())
    }

    fn link_poses<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        to_rows(py, POSE_WIDTH, self.inner.world().link_pose_rows())
    }

    fn constraint_errors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.constraint_errors())
    }

    fn support_margin(&self) -> PyResult<f64> {
        guard(|| self.inner.support_margin().map_err(sim_to_py))
    }

    fn pose_links<'py>(
        &mut self,
        py: Python<'py>,
        base: PyReadonlyArray1<'py, f64>,
        joints: PyReadonlyArray1<'py, f64>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        guard(|| {
            let base = crate::convert::fixed::<POSE_WIDTH>("base", &base)?;
            let joints = joints.as_array().to_vec();
            to_rows(
                py,
                POSE_WIDTH,
                self.inner.pose_links(&joints, &base).map_err(sim_to_py)?,
            )
        })
    }

    fn center_of_mass<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            Ok(PyArray1::from_vec(
                py,
                self.inner.center_of_mass().map_err(sim_to_py)?.to_vec(),
            ))
        })
    }

    fn reward(&self) -> f64 {
        self.inner.reward()
    }

    fn reached(&self) -> bool {
        self.inner.reached_target()
    }
}
