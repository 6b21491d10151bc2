//! Binding of `sim::arms`: Experiment 2 trials (two simulated planar arms, RL in a GPLVM
//! latent space) in one call. The shared argument checks, polling and result dict are in
//! `rl.rs`; only the plant's config keys live here.

use ::sim::arms::{ArmsConfig, ArmsPlant, Wall, learner_config};
use latent_core::LearnerConfig;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::sim_to_py;
use crate::rl::{apply_config_dict, echo_learner, float, floats, invalid, type_name};
use crate::simconfig::{echo_sim, robot_trials, set_sim_key, string};

/// The plant keys of Experiment 2's config dict, in the order they are documented and echoed.
const ARMS_KEYS: [&str; 17] = [
    "target",
    "theta",
    "length_scale",
    "walls",
    "grip",
    "drop_tolerance",
    "penalty",
    "reached_rms",
    "left_hand",
    "right_hand",
    "start_posture",
    "dt",
    "substeps",
    "solver_iterations",
    "pgs_iterations",
    "kp",
    "kd",
];

fn walls(value: &Bound<'_, PyAny>) -> PyResult<Vec<Wall>> {
    let rows: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| {
            invalid(format!(
                "config[\"walls\"]: expected a sequence of [x_min, y_min, x_max, y_max], got {}",
                type_name(value)
            ))
        })?
        .collect::<PyResult<_>>()?;
    rows.iter()
        .map(|row| {
            floats::<4>("walls[i]", row).map(|[x0, y0, x1, y1]| Wall {
                low: [x0, y0],
                high: [x1, y1],
            })
        })
        .collect()
}

/// Applies `config` (a dict of overrides) to the Experiment 2 defaults.
fn apply_config(config: Option<&Bound<'_, PyDict>>) -> PyResult<(ArmsConfig, LearnerConfig)> {
    let mut plant = ArmsConfig::default();
    let mut learner = learner_config();
    apply_config_dict(config, &ARMS_KEYS, &mut learner, |key, v, learner| {
        match key {
            "target" => plant.target = floats(key, v)?,
            "theta" => plant.theta = float(key, v)?,
            "length_scale" => plant.length_scale = float(key, v)?,
            "walls" => plant.walls = walls(v)?,
            "grip" => plant.grip = floats(key, v)?,
            "drop_tolerance" => plant.drop_tolerance = float(key, v)?,
            "penalty" => {
                plant.penalty = float(key, v)?;
                learner.penalty = plant.penalty;
            }
            "reached_rms" => plant.reached_rms = float(key, v)?,
            "left_hand" => plant.left_hand = string(key, v)?,
            "right_hand" => plant.right_hand = string(key, v)?,
            "start_posture" => plant.start_posture = floats(key, v)?,
            _ => return set_sim_key(&mut plant.sim, key, v),
        }
        Ok(true)
    })?;
    plant.validate().map_err(sim_to_py)?;
    Ok((plant, learner))
}

/// The effective configuration as a dict (every plant and learner key).
fn echo_config<'py>(py: Python<'py>, plant: &ArmsConfig, learner: &LearnerConfig) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("target", plant.target.to_vec())?;
    d.set_item("theta", plant.theta)?;
    d.set_item("length_scale", plant.length_scale)?;
    let walls: Vec<[f64; 4]> = plant
        .walls
        .iter()
        .map(|w| [w.low[0], w.low[1], w.high[0], w.high[1]])
        .collect();
    d.set_item("walls", walls)?;
    d.set_item("grip", plant.grip.to_vec())?;
    d.set_item("drop_tolerance", plant.drop_tolerance)?;
    d.set_item("penalty", plant.penalty)?;
    d.set_item("reached_rms", plant.reached_rms)?;
    d.set_item("left_hand", &plant.left_hand)?;
    d.set_item("right_hand", &plant.right_hand)?;
    d.set_item("start_posture", plant.start_posture.to_vec())?;
    echo_sim(&d, &plant.sim)?;
    echo_learner(&d, learner)?;
    Ok(d)
}

robot_trials! {
    /// Runs Experiment 2 (SPEC §4.2, paper Fig. 6) trials in parallel in Rust: two planar arms
    /// from `urdf`, simulated with rapier3d and PD servos, learning in a 2-D GPLVM latent space
    /// (8 actions: orthogonal + diagonal; 20 × 20 RBFs over [latent_low, latent_high]); one
    /// physics world per trial.
    ///
    /// urdf: path (str or os.PathLike) of the arms' URDF, or its XML text.
    /// decoder, encoder: GpMap latent (2) → posture (joints) and posture → latent.
    /// latent_low, latent_high: (2,) corners of the latent box.
    /// n_trials, episodes, base_seed, first_trial, record_episodes, test_episodes,
    ///     record_test_episodes, return_weights, progress: as for run_bimanual_trials. Test
    ///     episodes start only with both hands below the walls.
    /// config: overrides of the defaults (SPEC §4.2 table) — plant: target ([-0.05, 0.47,
    ///     0.05, 0.47]), theta (0.35), length_scale (0.3 m), walls ([[-1, 0.30, -0.36, 0.37],
    ///     [-0.06, 0.30, 1, 0.37]], each [x_min, y_min, x_max, y_max], tested on the hand
    ///     positions only), grip ([0.1, 0]), drop_tolerance (0.005), penalty (-1), reached_rms
    ///     (0.05), left_hand / right_hand ("left_hand" / "right_hand", URDF links),
    ///     start_posture (the plant's own start, used with start="plant"), dt (1/240),
    ///     substeps (12), solver_iterations (2), kp (5000), kd (50); learner (paper Exp. 2):
    ///     alpha (0.8), gamma (0.99), initial_weight (0), beta (20), step_fraction (0.2),
    ///     max_steps (1000), centres_per_dim (20), rbf_width (1), rbf_cutoff (3),
    ///     variance_threshold (None), start ("uniform" | "plant"), max_start_draws (1000).
    ///     Unknown keys raise InvalidInputError.
    ///
    /// Returns the dict of run_bimanual_trials ("passed": both hands below the walls at the
    /// start and above them at some step), trajectories as hands (x_L, y_L, x_R, y_R), and
    /// "config" with every key above.
    run_arms_trials,
    ArmsPlant,
    "for the arms"
}
