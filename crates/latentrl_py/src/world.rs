//! Binding of `sim::world`: a URDF robot in a rapier3d world with PD servos ([`World`]),
//! driven from Python one RL step (or `n` physics steps) per call.

use std::path::PathBuf;

use ::sim::fall::reset_on_floor;
use ::sim::task::ObstacleConfig;
use ::sim::urdf::LoadOptions;
use ::sim::{FallCriteria, Obstacle, RootMode, World, WorldConfig};
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::convert::{config_or_default, fixed};
use crate::errors::{InvalidInputError, guard, sim_to_py, to_py};

/// A URDF robot in a rapier3d world, every actuated joint PD-servoed to its target.
#[pyclass(name = "Sim", module = "latentrl._native")]
pub struct PySim {
    inner: World,
}

#[pymethods]
impl PySim {
    #[new]
    #[pyo3(signature = (urdf, *, root = RootMode::default().as_str(), floor = None, physics = None, servo = None,
                        balance_inertia = LoadOptions::default().balance_inertia))]
    fn new(
        py: Python<'_>,
        urdf: &Bound<'_, PyAny>,
        root: &str,
        floor: Option<f64>,
        physics: Option<&Bound<'_, PyAny>>,
        servo: Option<&Bound<'_, PyAny>>,
        balance_inertia: bool,
    ) -> PyResult<Self> {
        guard(|| {
            let root = RootMode::parse("root", root).map_err(|e| to_py(e.into()))?;
            #[rustfmt::skip]
            let config = WorldConfig { root, floor, physics: config_or_default("physics", physics)?,
                                       servo: config_or_default("servo", servo)? };
            let path: PathBuf = urdf
                .extract()
                .map_err(|_| InvalidInputError::new_err("urdf: expected a path or the URDF XML as a str"))?;
            let options = LoadOptions { balance_inertia };
            let inner = py.detach(|| World::from_urdf(&path, options, config));
            inner.map(|inner| Self { inner }).map_err(sim_to_py)
        })
    }

    #[getter]
    fn joint_names(&self) -> Vec<&str> {
        self.inner.model().joint_names()
    }

    #[getter]
    fn dt(&self) -> f64 {
        self.inner.rl_dt()
    }

    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }

    fn reset(&mut self, posture: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        guard(|| self.inner.reset(&posture.as_array().to_vec()).map_err(sim_to_py))
    }

    #[pyo3(signature = (posture, sole, clearance = ::sim::fall::GROUND_CLEARANCE))]
    fn reset_on_ground(&mut self, posture: PyReadonlyArray1<'_, f64>, sole: &str, clearance: f64) -> PyResult<()> {
        guard(|| reset_on_floor(&mut self.inner, &posture.as_array().to_vec(), sole, clearance).map_err(sim_to_py))
    }

    fn base_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let t = self.inner.base_pose().translation;
        PyArray1::from_vec(py, vec![t.x, t.y, t.z])
    }

    #[pyo3(signature = (soles, *, min_base_height, max_sole_tilt = ::sim::fall::MAX_SOLE_TILT))]
    fn fall_status(
        &self,
        soles: Vec<String>,
        min_base_height: f64,
        max_sole_tilt: f64,
    ) -> PyResult<(bool, f64, f64, Option<String>)> {
        guard(|| {
            let criteria = FallCriteria {
                min_base_height,
                max_sole_tilt,
                soles,
            };
            let s = self.inner.fall_status(&criteria).map_err(sim_to_py)?;
            Ok((s.fell, s.base_height, s.sole_tilt, s.ground_contact))
        })
    }

    fn set_targets(&mut self, targets: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        guard(|| self.inner.set_targets(&targets.as_array().to_vec()).map_err(sim_to_py))
    }

    fn targets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.targets().to_vec())
    }

    #[pyo3(signature = (n = None))]
    fn step(&mut self, py: Python<'_>, n: Option<i64>) -> PyResult<()> {
        guard(|| {
            let wrong = |n| InvalidInputError::new_err(format!("n: expected an int >= 0 or None, got {n}"));
            let n = n.map(|n| usize::try_from(n).map_err(|_| wrong(n))).transpose()?;
            let inner = &mut self.inner;
            py.detach(|| inner.advance(n));
            Ok(())
        })
    }

    fn joint_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.joint_positions())
    }

    fn joint_velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.joint_velocities())
    }

    fn frame_position<'py>(&self, py: Python<'py>, link: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            Ok(PyArray1::from_vec(
                py,
                self.inner.link_position(link).map_err(sim_to_py)?.into(),
            ))
        })
    }

    #[pyo3(signature = (center, half_extents, *, sensor = ObstacleConfig::default().sensor,
                        name = ObstacleConfig::default().name))]
    fn add_box_obstacle(
        &mut self,
        center: PyReadonlyArray1<'_, f64>,
        half_extents: PyReadonlyArray1<'_, f64>,
        sensor: bool,
        name: String,
    ) -> PyResult<usize> {
        guard(|| {
            let (center, half_extents) = (
                fixed::<3>("center", &center)?,
                fixed::<3>("half_extents", &half_extents)?,
            );
            let obstacle = Obstacle::aligned_box(&name, center, half_extents, sensor);
            self.inner.add_obstacle(obstacle).map_err(sim_to_py)
        })
    }

    fn contacts(&self) -> PyResult<Vec<(String, usize)>> {
        guard(|| {
            let contacts = self.inner.contacts();
            Ok(contacts.into_iter().map(|c| (c.link, c.obstacle)).collect())
        })
    }

    fn __repr__(&self) -> String {
        self.inner.to_string()
    }
}
