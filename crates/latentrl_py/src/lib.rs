//! `latentrl._native`: the module table. Each file converts one core module; nothing is decided here.
//! What each class, method and function does is written once, in `python/latentrl/_native.pyi`.
#![allow(missing_docs)]

mod bimanual;
mod convert;
mod errors;
mod fallcheck;
mod gp;
mod kinematics;
mod projection;
mod runner;
mod task;
mod urdf;
mod world;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    m.add("MAX_GP_POINTS", latent_core::gp::MAX_GP_POINTS)?;
    m.add("MAX_EPISODES", latent_core::trials::MAX_EPISODES)?;
    m.add_class::<gp::PyGpMap>()?;
    m.add_class::<projection::PyProjection>()?;
    m.add_class::<world::PySim>()?;
    m.add_class::<task::PyTask>()?;
    m.add_class::<task::PyTaskPlant>()?;
    m.add_class::<task::PyLatentPolicy>()?;
    m.add_class::<bimanual::PyBimanualPlant>()?;
    m.add_function(wrap_pyfunction!(gp::gplvm_nll_grad, m)?)?;
    m.add_function(wrap_pyfunction!(gp::gplvm_back_constrained_nll_grad, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::arms_fk, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::arms_elbows, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::arms_ik, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::grip_error, m)?)?;
    m.add_function(wrap_pyfunction!(fallcheck::fall_check, m)?)?;
    m.add_function(wrap_pyfunction!(bimanual::run_bimanual_trials, m)?)?;
    m.add_function(wrap_pyfunction!(bimanual::bimanual_config, m)?)?;
    m.add_function(wrap_pyfunction!(bimanual::latent_refusal, m)?)?;
    m.add_function(wrap_pyfunction!(task::bimanual_schema, m)?)?;
    m.add_function(wrap_pyfunction!(task::run_task_trials, m)?)?;
    m.add_function(wrap_pyfunction!(task::latent_survey, m)?)?;
    m.add_function(wrap_pyfunction!(task::learner_values, m)?)?;
    m.add_function(wrap_pyfunction!(task::task_schema, m)?)?;
    m.add_function(wrap_pyfunction!(task::run_config, m)?)?;
    m.add_function(wrap_pyfunction!(task::end_reasons, m)?)?;
    m.add_function(wrap_pyfunction!(urdf::urdf_info, m)?)?;
    m.add_function(wrap_pyfunction!(urdf::demo_columns, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
