//! Binding of `sim::urdf`: what a URDF holds, as plain dicts (for `latentrl urdf-info` and for
//! drawing a robot).

use std::path::PathBuf;

use ::sim::UrdfModel;
use ::sim::urdf::{JointKind, LoadOptions, ShapeInfo};
use numpy::PyReadonlyArray2;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{guard, sim_to_py};

/// One shape as a dict `{link, kind, size, origin, file, hull}` (origin: position and
/// quaternion x, y, z, w in the link's frame; file: a mesh's resolved path or None; hull:
/// `{triangles, vertices, cached}` for a collision mesh, else None).
pub fn shape_dict<'py>(py: Python<'py>, s: &ShapeInfo, links: &[&str]) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("link", links[s.link])?;
    d.set_item("kind", s.kind)?;
    d.set_item("size", &s.size)?;
    let t = s.origin.translation.vector;
    let q = s.origin.rotation.coords;
    d.set_item("origin", vec![t.x, t.y, t.z, q.x, q.y, q.z, q.w])?;
    d.set_item("file", &s.file)?;
    let hull = match s.hull {
        Some((triangles, vertices, cached)) => {
            let h = PyDict::new(py);
            h.set_item("triangles", triangles)?;
            h.set_item("vertices", vertices)?;
            h.set_item("cached", cached)?;
            Some(h)
        }
        None => None,
    };
    d.set_item("hull", hull)?;
    d.set_item("points", &s.points)?;
    Ok(d)
}

/// Shapes as a list of [`shape_dict`]s.
pub fn shape_list<'py>(py: Python<'py>, shapes: &[ShapeInfo], links: &[&str]) -> PyResult<Bound<'py, PyList>> {
    let out = PyList::empty(py);
    for s in shapes {
        out.append(shape_dict(py, s, links)?)?;
    }
    Ok(out)
}

fn kind_name(kind: JointKind) -> &'static str {
    match kind {
        JointKind::Revolute => "revolute",
        JointKind::Continuous => "continuous",
        JointKind::Prismatic => "prismatic",
    }
}

/// Reads and checks a URDF file (meshes hulled, through the cache; inertias repaired with
/// `balance_inertia`) and returns what it holds: `{name, joints, links, collision, visual,
/// total_mass, warnings}` (warnings: what was repaired, one sentence each); each joint a dict `{name, type,
/// lower, upper, effort, velocity, damping, friction, mimic}` (mimic: `{leader, multiplier,
/// offset}` or None), actuated joints first in URDF order, then the mimic ones.
#[pyfunction]
#[pyo3(signature = (path, *, balance_inertia = false))]
pub fn urdf_info<'py>(py: Python<'py>, path: PathBuf, balance_inertia: bool) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let options = LoadOptions { balance_inertia };
        let cache = ::sim::urdf::cache::default_folder();
        let model = py
            .detach(|| UrdfModel::from_file_with_options(&path, cache.as_deref(), options))
            .map_err(sim_to_py)?;
        let links = model.link_names();
        let joints = PyList::empty(py);
        let mimics = model.mimics().iter().map(|m| (&m.joint, Some(m)));
        for (j, mimic) in model.joints().iter().map(|j| (j, None)).chain(mimics) {
            let d = PyDict::new(py);
            d.set_item("name", &j.name)?;
            d.set_item("type", kind_name(j.kind))?;
            d.set_item("lower", j.lower)?;
            d.set_item("upper", j.upper)?;
            d.set_item("effort", j.effort)?;
            d.set_item("velocity", j.velocity)?;
            d.set_item("damping", j.damping)?;
            d.set_item("friction", j.friction)?;
            let coupling = match mimic {
                Some(m) => {
                    let c = PyDict::new(py);
                    c.set_item("leader", &model.joints()[m.leader].name)?;
                    c.set_item("multiplier", m.multiplier)?;
                    c.set_item("offset", m.offset)?;
                    Some(c)
                }
                None => None,
            };
            d.set_item("mimic", coupling)?;
            joints.append(d)?;
        }
        let out = PyDict::new(py);
        out.set_item("name", model.name())?;
        out.set_item("joints", joints)?;
        out.set_item("links", &links)?;
        out.set_item("collision", shape_list(py, &model.collision_shapes(), &links)?)?;
        out.set_item("visual", shape_list(py, &model.visual_shapes(), &links)?)?;
        out.set_item("total_mass", model.total_mass())?;
        out.set_item("warnings", model.warnings())?;
        Ok(out)
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
