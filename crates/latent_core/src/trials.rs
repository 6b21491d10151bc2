//! Independent trials in parallel (SPEC §4: "25 trials"), deterministic whatever the
//! thread count.
//!
//! Trial `i` draws every random number (start states, soft-max draws) from its own
//! generator [`trial_rng`]`(base_seed, i)`: a ChaCha8 generator keyed by `base_seed` on
//! stream `i`. Trials share nothing mutable, rayon maps over the trial indices and the
//! results are collected in index order, so the output is bitwise the same on 1 or N
//! threads, and trial `i` gives the same result whether it runs alone or in a sweep
//! (`first_trial` lets an interrupted sweep resume with the missing indices).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::episode::{EpisodeRecord, Learner, Plant, StateSpace};
use crate::error::{CoreError, Result};

/// The generator of trial `trial`: ChaCha8 seeded from `base_seed`, stream `trial`
/// (2⁶⁴ independent streams per seed).
pub fn trial_rng(base_seed: u64, trial: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(base_seed);
    rng.set_stream(trial as u64);
    rng
}

/// What to run; `Default` is one trial of 5000 episodes (paper Exp. 1 length) from seed 0.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TrialOptions {
    /// Number of trials T.
    pub n_trials: usize,
    /// Index of the first trial: trials `first_trial .. first_trial + n_trials` are run,
    /// each with the generator of its own index.
    pub first_trial: usize,
    /// Episodes per trial E.
    pub episodes: usize,
    /// Base seed of every trial's generator.
    pub base_seed: u64,
    /// Episode indices (0-based) whose task-space trajectory is recorded in every trial.
    pub record_episodes: Vec<usize>,
    /// Keep each trial's final value-function weights.
    pub keep_weights: bool,
}

impl Default for TrialOptions {
    fn default() -> Self {
        Self {
            n_trials: 1,
            first_trial: 0,
            episodes: 5000,
            base_seed: 0,
            record_episodes: Vec::new(),
            keep_weights: false,
        }
    }
}

impl TrialOptions {
    /// Checks `n_trials, episodes ≥ 1` and that every recorded episode exists.
    pub fn validate(&self) -> Result<()> {
        if self.n_trials == 0 {
            return Err(CoreError::InvalidParameter { name: "n_trials", value: 0.0, reason: "must be at least 1" });
        }
        if self.episodes == 0 {
            return Err(CoreError::InvalidParameter { name: "episodes", value: 0.0, reason: "must be at least 1" });
        }
        if self.first_trial.checked_add(self.n_trials).is_none() {
            return Err(CoreError::InvalidParameter {
                name: "first_trial",
                value: self.first_trial as f64,
                reason: "first_trial + n_trials overflows",
            });
        }
        if let Some(&e) = self.record_episodes.iter().find(|&&e| e >= self.episodes) {
            return Err(CoreError::InvalidParameter {
                name: "record_episodes",
                value: e as f64,
                reason: "every recorded episode index must be < episodes",
            });
        }
        Ok(())
    }
}

/// One trial's results.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialResult {
    /// The trial index (the generator's stream).
    pub trial: usize,
    /// One record per episode run, in order (fewer than `episodes` if cancelled).
    pub episodes: Vec<EpisodeRecord>,
    /// One task-space trajectory per entry of `record_episodes` (rows of `task_dim`
    /// values: the start, then one per plant step); empty if that episode was not run.
    pub trajectories: Vec<Vec<f64>>,
    /// False if the cancel flag stopped the trial early.
    pub finished: bool,
    /// The final weights, if `keep_weights`.
    pub weights: Option<Vec<f64>>,
}

/// Runs `options.n_trials` trials in parallel (rayon's current pool). Each trial clones
/// `template` (weights included, so pre-trained weights carry over), builds its plant with
/// `make_plant(trial_index)` and runs `options.episodes` episodes in `space`.
///
/// `cancel` is read between episodes: once set, every trial stops and reports
/// `finished = false`. `done` is incremented after every episode (progress).
/// Inputs are checked once, up front; the only error past that point is
/// [`CoreError::NoValidStart`].
pub fn run_trials<P, F>(
    template: &Learner,
    space: &StateSpace<'_>,
    make_plant: F,
    options: &TrialOptions,
    cancel: &AtomicBool,
    done: &AtomicUsize,
) -> Result<Vec<TrialResult>>
where
    P: Plant,
    F: Fn(usize) -> Result<P> + Sync,
{
    options.validate()?;
    let probe = make_plant(options.first_trial)?;
    template.check_space(space, probe.posture_dim())?;
    drop(probe);
    let trials = options.first_trial..options.first_trial + options.n_trials;
    trials.into_par_iter().map(|trial| run_one(template, space, &make_plant, options, trial, cancel, done)).collect()
}

fn run_one<P: Plant, F: Fn(usize) -> Result<P>>(
    template: &Learner,
    space: &StateSpace<'_>,
    make_plant: &F,
    options: &TrialOptions,
    trial: usize,
    cancel: &AtomicBool,
    done: &AtomicUsize,
) -> Result<TrialResult> {
    let mut plant = make_plant(trial)?;
    let mut learner = template.clone();
    let mut rng = trial_rng(options.base_seed, trial);
    let mut scratch = learner.scratch(space, plant.posture_dim());
    let mut episodes = Vec::with_capacity(options.episodes);
    let mut trajectories = vec![Vec::new(); options.record_episodes.len()];
    let mut finished = true;
    let mut buffer = Vec::new();
    for e in 0..options.episodes {
        if cancel.load(Ordering::Relaxed) {
            finished = false;
            break;
        }
        let slot = options.record_episodes.iter().position(|&r| r == e);
        let record = if slot.is_some() {
            buffer.clear();
            learner.run_episode(&mut plant, space, &mut rng, &mut scratch, Some(&mut buffer))?
        } else {
            learner.run_episode(&mut plant, space, &mut rng, &mut scratch, None)?
        };
        // The same episode may be listed twice: every listed slot gets the trajectory.
        for (slot, r) in trajectories.iter_mut().zip(&options.record_episodes) {
            if *r == e {
                slot.clone_from(&buffer);
            }
        }
        episodes.push(record);
        done.fetch_add(1, Ordering::Relaxed);
    }
    let weights = options.keep_weights.then(|| learner.into_weights());
    Ok(TrialResult { trial, episodes, trajectories, finished, weights })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u64> = (0..4).map(|_| trial_rng(1, 0).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(trial_rng(1, 0).next_u64(), trial_rng(1, 1).next_u64());
        assert_ne!(trial_rng(1, 0).next_u64(), trial_rng(2, 0).next_u64());
    }

    #[test]
    fn options_are_checked() {
        assert!(TrialOptions { n_trials: 0, ..Default::default() }.validate().is_err());
        assert!(TrialOptions { episodes: 0, ..Default::default() }.validate().is_err());
        let o = TrialOptions { episodes: 10, record_episodes: vec![3, 10], ..Default::default() };
        assert!(matches!(o.validate(), Err(CoreError::InvalidParameter { name: "record_episodes", .. })));
    }
}
