//! Binding of `sim::world`: a URDF robot in a rapier3d world with PD servos ([`World`]),
//! driven from Python one RL step (or `n` physics steps) per call.

use std::path::PathBuf;

use ::sim::fall::reset_on_ground;
use ::sim::urdf::LoadOptions;
use ::sim::{FallCriteria, Obstacle, ObstacleShape, RootMode, UrdfModel, World, WorldConfig};
use nalgebra::Isometry3;
use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;

use crate::convert::{config_or_default, fixed};
use crate::errors::{InvalidInputError, guard, sim_to_py};

/// A 1-D array of any length, copied into a `Vec` (the sim checks the length).
fn vector(array: &PyReadonlyArray1<'_, f64>) -> Vec<f64> {
    array.as_array().iter().copied().collect()
}

/// A URDF robot in a rapier3d world, every actuated joint PD-servoed to its target.
#[pyclass(name = "Sim", module = "latentrl._native")]
pub struct PySim {
    inner: World,
}

#[pymethods]
impl PySim {
    /// Builds the world from `urdf`: a path, or the URDF XML itself (a str starting with `<`).
    /// `root` "fixed" or "floating"; `floor` the height of a floor half-space (normal +z) or
    /// None; `physics` and `servo` dicts of the task file's `[physics]` and `[servo]` keys;
    /// `balance_inertia` repairs inertias the physics cannot take (`urdf-info --balance-inertia`).
    #[new]
    #[pyo3(signature = (urdf, *, root = "fixed", floor = None, physics = None, servo = None, balance_inertia = false))]
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
            let root = RootMode::from_name(root).ok_or_else(|| {
                InvalidInputError::new_err(format!("root: expected \"fixed\" or \"floating\", got {root:?}"))
            })?;
            #[rustfmt::skip]
            let config = WorldConfig { root, floor, physics: config_or_default("physics", physics)?,
                                       servo: config_or_default("servo", servo)? };
            let path: PathBuf = urdf
                .extract()
                .map_err(|_| InvalidInputError::new_err("urdf: expected a path or the URDF XML as a str"))?;
            let options = LoadOptions { balance_inertia };
            let model = py
                .detach(|| UrdfModel::from_xml_or_file(&path, options))
                .map_err(sim_to_py)?;
            let inner = py.detach(|| World::new(model, config)).map_err(sim_to_py)?;
            Ok(Self { inner })
        })
    }

    /// Names of the actuated joints, in the order of postures and targets.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        crate::convert::owned(self.inner.model().joint_names())
    }

    /// Duration of one RL step, `dt · substeps` (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.inner.rl_dt()
    }

    /// Simulated time since the last reset (s).
    #[getter]
    fn time(&self) -> f64 {
        self.inner.time()
    }

    /// Teleports the robot to `posture` (num_joints,) at rest and aims the servos at it.
    fn reset(&mut self, posture: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        guard(|| self.inner.reset(&vector(&posture)).map_err(sim_to_py))
    }

    /// Teleports a floating robot to `posture` at rest standing on the floor: the base is
    /// placed so that link `sole` lies flat, its lowest corner `clearance` m above the ground
    /// (needs a `floor`).
    #[pyo3(signature = (posture, sole, clearance = ::sim::fall::GROUND_CLEARANCE))]
    fn reset_on_ground(&mut self, posture: PyReadonlyArray1<'_, f64>, sole: &str, clearance: f64) -> PyResult<()> {
        guard(|| {
            let ground =
                self.inner.config().floor.ok_or_else(|| {
                    InvalidInputError::new_err("reset_on_ground: this Sim has no floor (pass floor=...)")
                })?;
            reset_on_ground(&mut self.inner, &vector(&posture), sole, ground, clearance, None).map_err(sim_to_py)
        })
    }

    /// World position (3,) of the root link's origin (the floating base).
    fn base_position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let t = self.inner.base_pose().translation;
        PyArray1::from_vec(py, vec![t.x, t.y, t.z])
    }

    /// The fall test now: `(fell, base_height, sole_tilt, ground_contact)`, fallen when the
    /// base origin is below `min_base_height` (m), a link of `soles` tilts more than
    /// `max_sole_tilt` (rad) or another link touches the floor (the first such link, else None).
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

    /// Sets every servo target (num_joints,), clamped to the joint limits.
    fn set_targets(&mut self, targets: PyReadonlyArray1<'_, f64>) -> PyResult<()> {
        guard(|| self.inner.set_targets(&vector(&targets)).map_err(sim_to_py))
    }

    /// The servo targets after clamping (num_joints,).
    fn targets<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.targets().to_vec())
    }

    /// Advances `n` physics steps of `dt`, or one RL step (`substeps` of them) when `n` is None.
    #[pyo3(signature = (n = None))]
    fn step(&mut self, py: Python<'_>, n: Option<i64>) -> PyResult<()> {
        let steps = match n {
            None => self.inner.config().physics.substeps,
            Some(n) => usize::try_from(n)
                .map_err(|_| InvalidInputError::new_err(format!("n: expected an int >= 0 or None, got {n}")))?,
        };
        let inner = &mut self.inner;
        guard(|| {
            py.detach(|| inner.step(steps));
            Ok(())
        })
    }

    /// The joint positions (num_joints,): the reached posture.
    fn joint_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.joint_positions())
    }

    /// The joint velocities (num_joints,).
    fn joint_velocities<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.inner.joint_velocities())
    }

    /// World position (3,) of link `link`'s frame (e.g. a hand).
    fn frame_position<'py>(&self, py: Python<'py>, link: &str) -> PyResult<Bound<'py, PyArray1<f64>>> {
        guard(|| {
            let frame = self.inner.frame(link, [0.0; 3]).map_err(sim_to_py)?;
            Ok(PyArray1::from_vec(py, self.inner.frame_position(&frame).to_vec()))
        })
    }

    /// Adds a static axis-aligned box at `center` (3,) with `half_extents` (3,); returns its id.
    /// A sensor (default) is passed through but still reported by `contacts`.
    #[pyo3(signature = (center, half_extents, *, sensor = true, name = "box"))]
    fn add_box_obstacle(
        &mut self,
        center: PyReadonlyArray1<'_, f64>,
        half_extents: PyReadonlyArray1<'_, f64>,
        sensor: bool,
        name: &str,
    ) -> PyResult<usize> {
        guard(|| {
            let [x, y, z] = fixed::<3>("center", &center)?;
            let obstacle = Obstacle {
                name: name.to_string(),
                shape: ObstacleShape::Box {
                    half_extents: fixed::<3>("half_extents", &half_extents)?,
                },
                pose: Isometry3::translation(x, y, z),
                sensor,
            };
            self.inner.add_obstacle(obstacle).map_err(sim_to_py)
        })
    }

    /// Every (link name, obstacle id) pair whose shapes are within the contact margin.
    fn contacts(&self) -> PyResult<Vec<(String, usize)>> {
        guard(|| {
            Ok(self
                .inner
                .contacts()
                .into_iter()
                .map(|c| (c.link, c.obstacle))
                .collect())
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Sim(robot={:?}, joints={}, dt={})",
            self.inner.model().name(),
            self.inner.num_joints(),
            self.inner.rl_dt()
        )
    }
}
