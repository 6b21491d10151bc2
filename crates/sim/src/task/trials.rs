//! The one trial runner of a task (Exp 2, Exp 3, `latentrl train`, a saved policy's rollouts):
//! trials of the task's latent learner (`task.learner`, `task.episode`) in parallel, one
//! [`TaskPlant`] per trial (a fresh world per episode for a floating robot). Python and the
//! Rust tests run this same assembly.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize};

use rayon::prelude::*;

use latent_core::trials::LatentSpace;
use latent_core::{CoreError, Learner, ResultArray, TrialOptions, TrialResult, run_trials, trial_arrays};

use super::{Task, TaskPlant};
use crate::error::Result;

/// A task's trials, checked before any runs: the task, demos and maps build a plant and the
/// learner, the weights fit it, the recorded paths fit in memory.
#[derive(Debug)]
pub struct TaskTrials<'a> {
    task: Arc<Task>,
    demos: Option<&'a [Vec<f64>]>,
    latent: &'a LatentSpace<'a>,
    /// The learner every trial starts from (its grid, actions and weights).
    pub template: Learner,
    /// One learner per trial where each starts from its own weights (a saved policy's trials);
    /// empty where every trial starts from `template`.
    per_trial: Vec<Learner>,
    /// What is run.
    pub options: TrialOptions,
}

impl<'a> TaskTrials<'a> {
    /// The trials of `task` in `latent` with `options`, starting from `weights`: none (w₀
    /// everywhere), one row for every trial, or one row per trial (a saved policy's trials, each
    /// from its own); `demos` as for [`TaskPlant::new`].
    pub fn new(
        task: Arc<Task>,
        demos: Option<&'a [Vec<f64>]>,
        latent: &'a LatentSpace<'a>,
        weights: &[Vec<f64>],
        options: TrialOptions,
    ) -> Result<Self> {
        // One plant and the learner up front: a bad task, demos or maps fail before any trial.
        let probe = TaskPlant::new(Arc::clone(&task), demos)?;
        let mut template = Learner::new(&task.config().learner, task.episode_rules(), &latent.low, &latent.high)?;
        template.check_space(&latent.space(), latent_core::Plant::posture_dim(&probe))?;
        drop(probe);
        let per_trial = match weights {
            [] => Vec::new(),
            [w] => {
                template.set_weights(w)?;
                Vec::new()
            }
            rows if rows.len() == options.n_trials => rows
                .iter()
                .map(|w| {
                    let mut learner = template.clone();
                    learner.set_weights(w).map(|()| learner)
                })
                .collect::<latent_core::Result<_>>()?,
            rows => {
                return Err(CoreError::Shape {
                    what: "weights",
                    expected: format!("one row, or one per trial ({})", options.n_trials),
                    got: format!("{} rows", rows.len()),
                }
                .into());
            }
        };
        options.check_recording(task.episode_rules().max_steps, task.row_len())?;
        #[rustfmt::skip]
        return Ok(Self { task, demos, latent, template, per_trial, options });
    }

    /// The task.
    pub fn task(&self) -> &Task {
        &self.task
    }

    /// Runs the trials: see [`run_trials`] for seeding, cancellation, progress and test episodes.
    /// Trials with weights of their own run side by side too, each seeded as its index says.
    pub fn run(&self, cancel: &AtomicBool, done: &AtomicUsize) -> Result<Vec<TrialResult>> {
        let make = |_| {
            TaskPlant::new(Arc::clone(&self.task), self.demos).map_err(|e| CoreError::Plant { reason: e.to_string() })
        };
        let space = self.latent.space();
        if self.per_trial.is_empty() {
            return Ok(run_trials(&self.template, &space, make, &self.options, cancel, done)?);
        }
        let one = |(i, learner): (usize, &Learner)| {
            let options = TrialOptions {
                n_trials: 1,
                first_trial: self.options.first_trial + i,
                ..self.options.clone()
            };
            run_trials(learner, &space, make, &options, cancel, done)
        };
        let runs: Vec<Vec<TrialResult>> = self
            .per_trial
            .par_iter()
            .enumerate()
            .map(one)
            .collect::<latent_core::Result<_>>()?;
        Ok(runs.into_iter().flatten().collect())
    }

    /// The arrays of `results` by name ([`trial_arrays`]), paths of the task's rows.
    pub fn arrays(&self, results: &[TrialResult]) -> Vec<(String, ResultArray)> {
        trial_arrays(results, &self.template, &self.options, self.task.row_len())
    }
}
