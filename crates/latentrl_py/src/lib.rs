//! `latentrl._native`: the module table. Each file converts one core module; nothing is decided here.
//! What each class, method and function does is written once, in `python/latentrl/_native.pyi`.
#![allow(missing_docs)]

mod bimanual;
mod convert;
mod errors;
mod fallcheck;
mod gp;
mod kinematics;
mod plant;
mod policy;
mod projection;
mod runner;
mod schema;
mod task;
mod urdf;
mod world;

#[pyo3::pymodule]
mod _native {
    use pyo3::prelude::*;

    #[pymodule_export]
    use super::bimanual::{PyBimanualPlant, bimanual_config, latent_refusal, run_bimanual_trials};
    #[pymodule_export]
    use super::gp::{PyGpMap, gplvm_back_constrained_nll_grad, gplvm_nll_grad};
    #[pymodule_export]
    use super::kinematics::{arms_elbows, arms_fk, arms_ik, grip_error};
    #[pymodule_export]
    use super::schema::{bimanual_schema, end_reasons, run_config, task_schema};
    #[pymodule_export]
    use super::task::{PyTask, latent_survey, run_task_trials};
    #[pymodule_export]
    use super::{fallcheck::fall_check, plant::PyTaskPlant, policy::PyLatentPolicy, policy::learner_values};
    #[pymodule_export]
    use super::{projection::PyProjection, urdf::demo_columns, urdf::urdf_info, world::PySim};

    #[pymodule_init]
    fn init(m: &Bound<'_, PyModule>) -> PyResult<()> {
        super::errors::register(m)?;
        m.add("MAX_GP_POINTS", latent_core::gp::MAX_GP_POINTS)?;
        m.add("MAX_EPISODES", latent_core::run::MAX_EPISODES)?;
        m.add("__version__", env!("CARGO_PKG_VERSION"))
    }
}
