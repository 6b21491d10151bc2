//! What the physics-simulated trial runners share (`arms.rs`, Experiment 2; `lift.rs`,
//! Experiment 3): the URDF argument, the physics keys of the config dict, and the call of a
//! 2-D latent learner on a plant built once per trial.

use std::path::PathBuf;

use ::sim::latent::{Latent2d, run_latent_trials};
use ::sim::{SimOptions, UrdfModel};
use latent_core::{LearnerConfig, Plant};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::{sim_to_py, to_py};
use crate::rl::{Checked, float, gp_map, int_in, invalid, latent_args, pack_results, run_with_polling, type_name};

/// A str value of config key `name`.
pub(crate) fn string(name: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    value
        .extract()
        .map_err(|_| invalid(format!("config[{name:?}]: expected a str, got {}", type_name(value))))
}

/// Sets physics key `key` (dt, substeps, solver_iterations, pgs_iterations, kp, kd); `Ok(false)` if it is
/// none of them.
pub(crate) fn set_sim_key(sim: &mut SimOptions, key: &str, v: &Bound<'_, PyAny>) -> PyResult<bool> {
    match key {
        "dt" => sim.dt = float(key, v)?,
        "substeps" => sim.substeps = int_in("config[\"substeps\"]", v, 1, 1_000_000)? as usize,
        "solver_iterations" => sim.solver_iterations = int_in("config[\"solver_iterations\"]", v, 1, 1000)? as usize,
        "pgs_iterations" => sim.pgs_iterations = int_in("config[\"pgs_iterations\"]", v, 1, 1000)? as usize,
        "kp" => sim.gains.kp = float(key, v)?,
        "kd" => sim.gains.kd = float(key, v)?,
        _ => return Ok(false),
    }
    Ok(true)
}

/// Adds every physics key (effective values) to `d`.
pub(crate) fn echo_sim(d: &Bound<'_, PyDict>, sim: &SimOptions) -> PyResult<()> {
    d.set_item("dt", sim.dt)?;
    d.set_item("substeps", sim.substeps)?;
    d.set_item("solver_iterations", sim.solver_iterations)?;
    d.set_item("pgs_iterations", sim.pgs_iterations)?;
    d.set_item("kp", sim.gains.kp)?;
    d.set_item("kd", sim.gains.kd)
}

/// A URDF given as a path (str or os.PathLike) or as the XML text itself (a str starting
/// with "<").
pub(crate) fn urdf_model(urdf: &Bound<'_, PyAny>) -> PyResult<UrdfModel> {
    if let Ok(text) = urdf.extract::<String>()
        && text.trim_start().starts_with('<')
    {
        return UrdfModel::parse(&text).map_err(sim_to_py);
    }
    let path: PathBuf = urdf
        .extract()
        .map_err(|_| invalid(format!("urdf: expected a path or URDF text, got {}", type_name(urdf))))?;
    UrdfModel::from_file(path).map_err(sim_to_py)
}

/// Checks the latent maps `[decoder, encoder]` and box `[low, high]`, builds one plant (bad
/// links, limits or dimensions fail here with the plant's own message) and the learner,
/// runs the trials with polling and returns the result dict (trajectories of the plant's
/// `task_dim` columns) without "config".
pub(crate) fn run_latent_2d<'py, P, F>(
    py: Python<'py>,
    run: &Checked<'py>,
    maps: [Bound<'py, PyAny>; 2],
    corners: [&Bound<'py, PyAny>; 2],
    context: &str,
    learner_config: &LearnerConfig,
    make_plant: F,
) -> PyResult<Bound<'py, PyDict>>
where
    P: Plant,
    F: Fn(usize) -> ::sim::error::Result<P> + Sync,
{
    let [decoder, encoder] = maps.map(Some);
    let latent = latent_args(
        gp_map("decoder", &decoder)?,
        gp_map("encoder", &encoder)?,
        Some(corners[0]),
        Some(corners[1]),
        context,
    )?;
    let probe = make_plant(run.options.first_trial).map_err(sim_to_py)?;
    let space = Latent2d {
        decoder: latent.decoder,
        encoder: latent.encoder,
        low: &latent.low,
        high: &latent.high,
    };
    let (template, _) = space.build(learner_config, probe.posture_dim()).map_err(to_py)?;
    let task_dim = probe.task_dim();
    drop(probe);
    let options = &run.options;
    let results = run_with_polling(py, options, run.progress.as_ref(), |cancel, done| {
        run_latent_trials(&make_plant, learner_config, &space, options, cancel, done)
    })?;
    pack_results(py, &results, &template, options, task_dim)
}

/// Defines the `#[pyfunction]` `$name(urdf, *, decoder, encoder, latent_low, latent_high,
/// n_trials, episodes, base_seed, first_trial, config, record_episodes, test_episodes,
/// record_test_episodes, return_weights, progress)` of one URDF robot: the invoking module's
/// `apply_config` turns `config` into the plant's and learner's configs, `$plant::new(model,
/// config)` builds a plant per trial, [`run_latent_2d`] runs them, and the module's
/// `echo_config` fills the result's "config". `$context` names the robot in error messages.
macro_rules! robot_trials {
    ($(#[$doc:meta])* $name:ident, $plant:ident, $context:literal) => {
        $(#[$doc])*
        #[pyfunction]
        #[pyo3(signature = (
            urdf, *, decoder, encoder, latent_low, latent_high, n_trials, episodes, base_seed,
            first_trial = None, config = None, record_episodes = None, test_episodes = None,
            record_test_episodes = None, return_weights = false, progress = None,
        ))]
        #[allow(clippy::too_many_arguments)]
        pub fn $name<'py>(
            py: Python<'py>,
            urdf: &Bound<'py, PyAny>,
            decoder: Bound<'py, PyAny>,
            encoder: Bound<'py, PyAny>,
            latent_low: &Bound<'py, PyAny>,
            latent_high: &Bound<'py, PyAny>,
            n_trials: &Bound<'py, PyAny>,
            episodes: &Bound<'py, PyAny>,
            base_seed: &Bound<'py, PyAny>,
            first_trial: Option<&Bound<'py, PyAny>>,
            config: Option<&Bound<'py, PyAny>>,
            record_episodes: Option<&Bound<'py, PyAny>>,
            test_episodes: Option<&Bound<'py, PyAny>>,
            record_test_episodes: Option<&Bound<'py, PyAny>>,
            return_weights: bool,
            progress: Option<Bound<'py, PyAny>>,
        ) -> PyResult<Bound<'py, PyDict>> {
            $crate::errors::guard(|| {
                #[rustfmt::skip]
                let run = $crate::rl::RunArgs { n_trials, episodes, base_seed, first_trial, config, record_episodes,
                                                test_episodes, record_test_episodes, return_weights, progress }.check()?;
                let (plant, learner_config) = apply_config(run.config.as_ref())?;
                let model = $crate::simconfig::urdf_model(urdf)?;
                let make_plant = |_| $plant::new(model.clone(), plant.clone());
                let out = $crate::simconfig::run_latent_2d(
                    py,
                    &run,
                    [decoder, encoder],
                    [latent_low, latent_high],
                    $context,
                    &learner_config,
                    make_plant,
                )?;
                out.set_item("config", echo_config(py, &plant, &learner_config)?)?;
                Ok(out)
            })
        }
    };
}
pub(crate) use robot_trials;
