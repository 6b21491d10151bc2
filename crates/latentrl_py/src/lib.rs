//! `latentrl._native`: the module table. Each file converts one core module; nothing is decided here.
#![allow(missing_docs)]

mod arms;
mod convert;
mod errors;
mod gp;
mod humanoid;
mod lift;
mod physics;
mod rl;
mod sim;
mod simconfig;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add_class::<gp::PyGpMap>()?;
    m.add_class::<physics::PySim>()?;
    m.add_function(wrap_pyfunction!(gp::gplvm_nll_grad, m)?)?;
    m.add_function(wrap_pyfunction!(sim::arms_fk, m)?)?;
    m.add_function(wrap_pyfunction!(sim::arms_elbows, m)?)?;
    m.add_function(wrap_pyfunction!(sim::arms_ik, m)?)?;
    m.add_function(wrap_pyfunction!(humanoid::humanoid_fall_check, m)?)?;
    m.add_function(wrap_pyfunction!(rl::run_bimanual_trials, m)?)?;
    m.add_function(wrap_pyfunction!(arms::run_arms_trials, m)?)?;
    m.add_function(wrap_pyfunction!(lift::run_lift_trials, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
