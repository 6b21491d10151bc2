//! Binding of `sim::lift`: Experiment 3 trials (the simulated humanoid lifting an object, RL
//! in a GPLVM latent space) in one call. The shared checks, polling and result dict are in
//! `rl.rs` and `simconfig.rs`; only the plant's config keys live here.

use ::sim::lift::{LiftConfig, LiftPlant, box_obstacle, learner_config};
use ::sim::{Obstacle, ObstacleShape};
use latent_core::LearnerConfig;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::errors::sim_to_py;
use crate::rl::{apply_config_dict, echo_learner, float, floats, invalid, type_name};
use crate::simconfig::{echo_sim, robot_trials, set_sim_key, string};

/// The plant keys of Experiment 3's config dict, in the order they are documented and echoed.
const LIFT_KEYS: [&str; 22] = [
    "target",
    "theta",
    "length_scale",
    "grip_width",
    "drop_tolerance",
    "penalty",
    "reached_rms",
    "hands",
    "soles",
    "max_sole_tilt",
    "base_height_fraction",
    "obstacles",
    "start_posture",
    "start_noise",
    "min_start_margin",
    "dt",
    "substeps",
    "solver_iterations",
    "pgs_iterations",
    "kp",
    "kd",
    "max_force",
];

fn pair(name: &str, value: &Bound<'_, PyAny>) -> PyResult<[String; 2]> {
    let v: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| {
            invalid(format!(
                "config[{name:?}]: expected two link names, got {}",
                type_name(value)
            ))
        })?
        .collect::<PyResult<_>>()?;
    match v.as_slice() {
        [a, b] => Ok([string(name, a)?, string(name, b)?]),
        _ => Err(invalid(format!(
            "config[{name:?}]: expected two link names, got {}",
            v.len()
        ))),
    }
}

fn obstacles(value: &Bound<'_, PyAny>) -> PyResult<Vec<Obstacle>> {
    let rows: Vec<Bound<'_, PyAny>> = value
        .try_iter()
        .map_err(|_| {
            invalid(format!(
                "config[\"obstacles\"]: expected a sequence of [cx, cy, cz, hx, hy, hz], got {}",
                type_name(value)
            ))
        })?
        .collect::<PyResult<_>>()?;
    rows.iter()
        .enumerate()
        .map(|(i, row)| {
            floats::<6>("obstacles[i]", row)
                .map(|[cx, cy, cz, hx, hy, hz]| box_obstacle(&format!("box {i}"), [cx, cy, cz], [hx, hy, hz]))
        })
        .collect()
}

/// Applies `config` (a dict of overrides) to the Experiment 3 defaults.
fn apply_config(config: Option<&Bound<'_, PyDict>>) -> PyResult<(LiftConfig, LearnerConfig)> {
    let mut plant = LiftConfig::default();
    let mut learner = learner_config();
    apply_config_dict(config, &LIFT_KEYS, &mut learner, |key, v, learner| {
        match key {
            "target" => plant.target = floats(key, v)?,
            "theta" => plant.theta = float(key, v)?,
            "length_scale" => plant.length_scale = float(key, v)?,
            "grip_width" => plant.grip_width = float(key, v)?,
            "drop_tolerance" => plant.drop_tolerance = float(key, v)?,
            "penalty" => {
                plant.penalty = float(key, v)?;
                learner.penalty = plant.penalty;
            }
            "reached_rms" => plant.reached_rms = float(key, v)?,
            "hands" => plant.hands = pair(key, v)?,
            "soles" => plant.soles = pair(key, v)?,
            "max_sole_tilt" => plant.max_sole_tilt = float(key, v)?,
            "base_height_fraction" => plant.base_height_fraction = float(key, v)?,
            "obstacles" => plant.obstacles = obstacles(v)?,
            "start_posture" => {
                plant.start_posture = if v.is_none() {
                    None
                } else {
                    Some(v.extract().map_err(|_| {
                        invalid(format!(
                            "config[\"start_posture\"]: expected a sequence of numbers or None, got {}",
                            type_name(v)
                        ))
                    })?)
                }
            }
            "start_noise" => plant.start_noise = float(key, v)?,
            "min_start_margin" => plant.min_start_margin = float(key, v)?,
            "max_force" => plant.sim.gains.max_force = float(key, v)?,
            _ => return set_sim_key(&mut plant.sim, key, v),
        }
        Ok(true)
    })?;
    plant.validate().map_err(sim_to_py)?;
    Ok((plant, learner))
}

/// The effective configuration as a dict (every plant and learner key).
fn echo_config<'py>(py: Python<'py>, plant: &LiftConfig, learner: &LearnerConfig) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    d.set_item("target", plant.target.to_vec())?;
    d.set_item("theta", plant.theta)?;
    d.set_item("length_scale", plant.length_scale)?;
    d.set_item("grip_width", plant.grip_width)?;
    d.set_item("drop_tolerance", plant.drop_tolerance)?;
    d.set_item("penalty", plant.penalty)?;
    d.set_item("reached_rms", plant.reached_rms)?;
    d.set_item("hands", plant.hands.to_vec())?;
    d.set_item("soles", plant.soles.to_vec())?;
    d.set_item("max_sole_tilt", plant.max_sole_tilt)?;
    d.set_item("base_height_fraction", plant.base_height_fraction)?;
    let boxes: Vec<Vec<f64>> = plant
        .obstacles
        .iter()
        .filter_map(|o| match o.shape {
            ObstacleShape::Box { half_extents: h } => {
                let t = o.pose.translation.vector;
                Some(vec![t.x, t.y, t.z, h[0], h[1], h[2]])
            }
            _ => None,
        })
        .collect();
    d.set_item("obstacles", boxes)?;
    d.set_item("start_posture", plant.start_posture.clone())?;
    d.set_item("start_noise", plant.start_noise)?;
    d.set_item("min_start_margin", plant.min_start_margin)?;
    echo_sim(&d, &plant.sim)?;
    d.set_item("max_force", plant.sim.gains.max_force)?;
    echo_learner(&d, learner)?;
    Ok(d)
}

robot_trials! {
    /// Runs Experiment 3 (SPEC §4.3, paper Fig. 7b–e, 8) trials in parallel in Rust: the
    /// floating humanoid from `urdf` standing on a floor, simulated with rapier3d and servo PD,
    /// learning in a 2-D GPLVM latent space (8 actions: orthogonal + diagonal; 20 × 20 RBFs
    /// over [latent_low, latent_high]); one plant per trial and a fresh physics world per
    /// episode.
    ///
    /// urdf: path (str or os.PathLike) of the humanoid's URDF, or its XML text.
    /// decoder, encoder: GpMap latent (2) → posture (19 joints) and posture → latent.
    /// latent_low, latent_high: (2,) corners of the latent box.
    /// n_trials, episodes, base_seed, first_trial, record_episodes, test_episodes,
    ///     record_test_episodes, return_weights, progress: as for run_bimanual_trials.
    /// config: overrides of the defaults (docs/exp3.md) — plant: target (h*, 6 numbers: both
    ///     hands' x, y, z), theta (0.35), length_scale (0.1 m), grip_width (0.10),
    ///     drop_tolerance (0.02), penalty (-1), reached_rms (0.02), hands (["l_hand",
    ///     "r_hand"]), soles (["l_foot", "r_foot"]), max_sole_tilt (20° in rad),
    ///     base_height_fraction (0.5), obstacles ([[0.215, 0, 0.175, 0.05, 0.12, 0.125]]: axis-
    ///     aligned sensor boxes [cx, cy, cz, hx, hy, hz]), start_posture (None = home; the
    ///     plant's own start, used with start="plant"), start_noise (0.01 rad), min_start_margin
    ///     (0 m), dt (1/240), substeps (12), solver_iterations (1), pgs_iterations (4), kp (8),
    ///     kd (0.1), max_force
    ///     (1.2 N·m); learner: alpha (0.8), gamma (0.99), initial_weight (0), beta (20),
    ///     step_fraction (0.2), max_steps (200), centres_per_dim (20), rbf_width (1),
    ///     rbf_cutoff (3), variance_threshold (None), start ("uniform" | "plant"),
    ///     max_start_draws (1000). Unknown keys raise InvalidInputError.
    ///
    /// Returns the dict of run_bimanual_trials ("passed" always False), trajectories rows of
    /// 32 columns: hands (x_L, y_L, z_L, x_R, y_R, z_R), base position (3), base orientation
    /// quaternion (x, y, z, w), the 19 joint angles; and "config" with every key above.
    run_lift_trials,
    LiftPlant,
    "for the humanoid"
}
