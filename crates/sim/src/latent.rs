//! What the physics-simulated latent experiments share (Experiment 2, the arms, and
//! Experiment 3, the humanoid): a 2-D GPLVM latent space with 8 actions (orthogonal +
//! diagonal, paper Exp. 2) and an RBF grid over its box, and the trials runner that builds
//! one plant per trial.

use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::GpMap;
use latent_core::episode::{Learner, LearnerConfig, Plant, StateSpace};
use latent_core::error::{CoreError, Result as CoreResult};
use latent_core::policy::orthogonal_and_diagonal_actions_2d;
use latent_core::trials::{TrialOptions, TrialResult, run_trials};

/// A 2-D latent space: GPLVM maps and the latent box.
#[derive(Debug, Clone, Copy)]
pub struct Latent2d<'a> {
    /// Latent → posture GP map (GPLVM mean, Eq. 4).
    pub decoder: &'a GpMap,
    /// Posture → latent GP map (out-of-sample GP).
    pub encoder: &'a GpMap,
    /// Lower corner of the latent box.
    pub low: &'a [f64],
    /// Upper corner of the latent box.
    pub high: &'a [f64],
}

impl<'a> Latent2d<'a> {
    /// The latent learner (8 actions: orthogonal + diagonal; RBF grid over the box) and its
    /// state space for a plant with `posture_dim` joints.
    pub fn build(&self, config: &LearnerConfig, posture_dim: usize) -> CoreResult<(Learner, StateSpace<'a>)> {
        if self.low.len() != 2 {
            return Err(CoreError::Shape {
                what: "latent box (the 8 actions of Experiments 2 and 3 are 2-D)",
                expected: "dimension 2".to_string(),
                got: format!("dimension {}", self.low.len()),
            });
        }
        let learner = Learner::new(config, self.low, self.high, &orthogonal_and_diagonal_actions_2d())?;
        let space = StateSpace::Latent {
            decoder: self.decoder,
            encoder: self.encoder,
        };
        learner.check_space(&space, posture_dim)?;
        Ok((learner, space))
    }
}

/// Runs trials in parallel in `latent`, one plant per trial from `make_plant(trial)`: see
/// [`latent_core::trials::run_trials`] for seeding, cancellation, progress and test
/// episodes. One plant is built up front, so a bad model or configuration fails before any
/// trial starts (as [`CoreError::Plant`]).
pub fn run_latent_trials<P, E, F>(
    make_plant: F,
    config: &LearnerConfig,
    latent: &Latent2d<'_>,
    options: &TrialOptions,
    cancel: &AtomicBool,
    done: &AtomicUsize,
) -> CoreResult<Vec<TrialResult>>
where
    P: Plant,
    E: std::fmt::Display,
    F: Fn(usize) -> std::result::Result<P, E> + Sync,
{
    let make_plant = |trial| make_plant(trial).map_err(|e| CoreError::Plant { reason: e.to_string() });
    let probe = make_plant(options.first_trial)?;
    let (template, space) = latent.build(config, probe.posture_dim())?;
    drop(probe);
    run_trials(&template, &space, make_plant, options, cancel, done)
}
