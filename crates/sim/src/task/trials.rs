//! The one trial runner of a task (Exp 2, Exp 3, `latentrl train`, a saved policy's rollouts):
//! trials of the task's latent learner (`task.learner`, `task.episode`) in parallel, one
//! [`TaskPlant`] per trial (a fresh world per episode for a floating robot). Python and the
//! Rust tests run this same assembly.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicUsize};

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
    /// The learner every trial starts from (its grid, actions and weights), or one per trial
    /// (a saved policy's trials, each from its own weights).
    pub templates: Vec<Learner>,
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
        let template = Learner::new(&task.config().learner, task.episode_rules(), &latent.low, &latent.high)?;
        template.check_space(&latent.space(), latent_core::Plant::posture_dim(&probe))?;
        drop(probe);
        let templates = match weights {
            [] => vec![template],
            rows => rows
                .iter()
                .map(|w| {
                    let mut learner = template.clone();
                    learner.set_weights(w).map(|()| learner)
                })
                .collect::<latent_core::Result<_>>()?,
        };
        options.check_recording(task.episode_rules().max_steps, task.row_len())?;
        #[rustfmt::skip]
        return Ok(Self { task, demos, latent, templates, options });
    }

    /// The task.
    pub fn task(&self) -> &Task {
        &self.task
    }

    /// Runs the trials: see [`run_trials`] for seeding, cancellation, progress and test episodes.
    pub fn run(&self, cancel: &AtomicBool, done: &AtomicUsize) -> Result<Vec<TrialResult>> {
        let make = |_| {
            TaskPlant::new(Arc::clone(&self.task), self.demos).map_err(|e| CoreError::Plant { reason: e.to_string() })
        };
        Ok(run_trials(
            &self.templates,
            &self.latent.space(),
            make,
            &self.options,
            cancel,
            done,
        )?)
    }

    /// The arrays of `results` by name ([`trial_arrays`]), paths of the task's rows.
    pub fn arrays(&self, results: &[TrialResult]) -> Vec<(String, ResultArray)> {
        trial_arrays(results, &self.templates[0], &self.options, self.task.row_len())
    }
}
