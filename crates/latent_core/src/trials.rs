//! Independent trials in parallel (the paper's "25 trials", docs/method.md §Experiments),
//! deterministic whatever the thread count.
//!
//! Trial `i` draws every random number (start states, soft-max draws) from its own
//! generator [`trial_rng`]`(base_seed, i)`: a ChaCha8 generator keyed by `base_seed` on
//! stream `i`. Trials share nothing mutable, rayon maps over the trial indices and the
//! results are collected in index order, so the output is bitwise the same on 1 or N
//! threads, and trial `i` gives the same result whether it runs alone or in a sweep
//! (`first_trial` lets an interrupted sweep resume with the missing indices).
//!
//! After its training episodes a trial may run `test_episodes` frozen test episodes
//! ([`Phase::Test`]: no TD updates, starts filtered by [`crate::Plant::admits_test_start`])
//! with the same generator, e.g. Experiment 2's 50 frozen test episodes from starts below
//! the wall (docs/method.md §Experiment 2).

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::encode::Encode;
use crate::episode::{EpisodeRecord, EpisodeScratch};
use crate::error::{CoreError, Result};
use crate::gp::GpMap;
use crate::learner::{ActionRule, Learner, Phase};
use crate::plant::Plant;
use crate::run::{MAX_EPISODES, RunConfig, records_over_limit};
use crate::space::StateSpace;

/// The generator of trial `trial`: ChaCha8 seeded from `base_seed`, stream `trial`
/// (2⁶⁴ independent streams per seed).
pub fn trial_rng(base_seed: u64, trial: usize) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(base_seed);
    rng.set_stream(trial as u64);
    rng
}

/// The generator of the actions of rollout episode `episode` of trial `trial`: ChaCha8 seeded
/// from the three indices. A rollout draws its starts from the trial's generator and its actions
/// from these, so every policy rolled out with the same seed (greedy, soft-max, the random
/// control) meets the same starts, and a greedy rollout draws as it did before it had them.
pub fn episode_rng(base_seed: u64, trial: usize, episode: usize) -> ChaCha8Rng {
    let mut seed = [0u8; 32];
    seed[..8].copy_from_slice(&base_seed.to_le_bytes());
    seed[8..16].copy_from_slice(&(trial as u64).to_le_bytes());
    seed[16..24].copy_from_slice(&(episode as u64).to_le_bytes());
    seed[24..].copy_from_slice(b"actions\0");
    ChaCha8Rng::from_seed(seed)
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
    /// Frozen test episodes run after the training episodes ([`Phase::Test`]); 0 = none.
    pub test_episodes: usize,
    /// Test-episode indices (0-based) whose task-space trajectory is recorded.
    pub record_test_episodes: Vec<usize>,
    /// The phase of the `episodes` ([`Phase::Train`]; [`Phase::Rollout`] runs a trained
    /// template's policy frozen, each episode's actions from its [`episode_rng`]).
    pub phase: Phase,
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
            test_episodes: 0,
            record_test_episodes: Vec::new(),
            phase: Phase::Train,
        }
    }
}

/// Most values of recorded paths one call may return (2 GiB of float64).
pub const MAX_PATH_VALUES: usize = 1 << 28;

/// The run arguments of a trial runner as a caller gave them: integers of any size, `None`
/// for left out. [`TrialOptions::from_args`] checks them.
#[derive(Debug, Clone, Default)]
pub struct RunArgs {
    /// Number of trials.
    pub n_trials: i128,
    /// Episodes per trial.
    pub episodes: i128,
    /// Base seed.
    pub base_seed: i128,
    /// Index of the first trial (0).
    pub first_trial: Option<i128>,
    /// Episode indices to record.
    pub record_episodes: Vec<i128>,
    /// Frozen test episodes (0).
    pub test_episodes: Option<i128>,
    /// Test-episode indices to record.
    pub record_test_episodes: Vec<i128>,
    /// Keep each trial's final weights.
    pub keep_weights: bool,
    /// Roll the episodes out frozen with this action rule's name ("greedy", "softmax",
    /// "random"), starts as the frozen tests' if the flag is set.
    pub rollout: Option<(String, bool)>,
}

/// `value` if it lies in `[min, max]`, else the error naming `name`.
fn int_in(name: &str, value: i128, min: i128, max: i128) -> Result<i128> {
    if value < min || value > max {
        return argument(format!("{name} must lie in [{min}, {max}], got {value}"));
    }
    Ok(value)
}

/// `value` if it lies within the bounds of the `[run]` count `key` (its rule in [`RunConfig`],
/// where they are defined once), else the error naming the runner's argument `name`.
fn run_count(name: &str, key: &str, value: i128) -> Result<usize> {
    let (min, max) =
        RunConfig::count_bounds(key).ok_or_else(|| CoreError::Argument(format!("run.{key} is no count")))?;
    Ok(int_in(name, value, min.into(), max.into())? as usize)
}

impl TrialOptions {
    /// The options of `args`, every argument checked against its limit (the messages name
    /// the argument; `n_trials`, `episodes` and `test_episodes` obey the `[run]` rules of
    /// [`RunConfig`]), and at most [`MAX_EPISODES`] episode records in all.
    pub fn from_args(args: &RunArgs) -> Result<Self> {
        let n_trials = run_count("n_trials", "trials", args.n_trials)?;
        let episodes = run_count("episodes", "episodes", args.episodes)?;
        let base_seed = int_in("base_seed", args.base_seed, 0, u64::MAX as i128)? as u64;
        let first_trial = match args.first_trial {
            Some(v) => int_in("first_trial", v, 0, 1 << 40)? as usize,
            None => 0,
        };
        let test_episodes = match args.test_episodes {
            Some(v) => run_count("test_episodes", "test_episodes", v)?,
            None => 0,
        };
        check_records(n_trials, episodes, test_episodes)?;
        let indices = |name: &str, list: &[i128], n: usize| -> Result<Vec<usize>> {
            let name = format!("{name}[i]");
            list.iter()
                .map(|&e| Ok(int_in(&name, e, 0, n as i128 - 1)? as usize))
                .collect()
        };
        let phase = match &args.rollout {
            None => Phase::Train,
            Some((name, test_starts)) => Phase::Rollout {
                action: ActionRule::parse("rollout", name)?,
                test_starts: *test_starts,
            },
        };
        let options = TrialOptions {
            n_trials,
            first_trial,
            episodes,
            base_seed,
            record_episodes: indices("record_episodes", &args.record_episodes, episodes)?,
            keep_weights: args.keep_weights,
            test_episodes,
            record_test_episodes: indices("record_test_episodes", &args.record_test_episodes, test_episodes)?,
            phase,
        };
        options.validate()?;
        Ok(options)
    }

    /// The units of progress: `n_trials × (episodes + test_episodes)` episodes.
    pub fn total_episodes(&self) -> usize {
        self.n_trials * (self.episodes + self.test_episodes)
    }

    /// Refuses recorded paths too large to return ([`MAX_PATH_VALUES`]): `trials × recorded
    /// episodes × (max_steps + 1) × row` values.
    pub fn check_recording(&self, max_steps: usize, row: usize) -> Result<()> {
        let records = self.record_episodes.len() + self.record_test_episodes.len();
        let values = self.n_trials as u128 * records as u128 * (max_steps as u128 + 1) * row as u128;
        if values > MAX_PATH_VALUES as u128 {
            return argument(format!(
                "recording {records} episodes of up to {max_steps} steps × {row} values in each of {} trials needs \
                 {values} values, more than {MAX_PATH_VALUES} (2 GiB); record fewer episodes or run fewer trials at a time",
                self.n_trials
            ));
        }
        Ok(())
    }

    /// Checks `n_trials`, `episodes` and `test_episodes` by the `[run]` rules, the episode
    /// records in all, and that every recorded (test) episode exists.
    pub fn validate(&self) -> Result<()> {
        run_count("n_trials", "trials", self.n_trials as i128)?;
        run_count("episodes", "episodes", self.episodes as i128)?;
        run_count("test_episodes", "test_episodes", self.test_episodes as i128)?;
        check_records(self.n_trials, self.episodes, self.test_episodes)?;
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
        if let Some(&e) = self.record_test_episodes.iter().find(|&&e| e >= self.test_episodes) {
            return Err(CoreError::InvalidParameter {
                name: "record_test_episodes",
                value: e as f64,
                reason: "every recorded test episode index must be < test_episodes",
            });
        }
        Ok(())
    }
}

/// Refuses more than [`MAX_EPISODES`] episode records in one call ([`records_over_limit`]).
fn check_records(n_trials: usize, episodes: usize, test_episodes: usize) -> Result<()> {
    match records_over_limit(n_trials, episodes, test_episodes) {
        Some(total) => argument(format!(
            "n_trials × (episodes + test_episodes) = {total} episode records in one call, more than {MAX_EPISODES}; \
             run fewer trials at a time (the runners save trial by trial)"
        )),
        None => Ok(()),
    }
}

/// One trial's results.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialResult {
    /// The trial index (the generator's stream).
    pub trial: usize,
    /// One record per episode run, in order (fewer than `episodes` if cancelled, or stopped by
    /// the learner's [`crate::EpisodeRules::stop`] rule: then `finished` all the same).
    pub episodes: Vec<EpisodeRecord>,
    /// One task-space trajectory per entry of `record_episodes` (rows of `task_dim`
    /// values: the start, then one per plant step); empty if that episode was not run.
    pub trajectories: Vec<Vec<f64>>,
    /// False if the cancel flag stopped the trial early.
    pub finished: bool,
    /// The final weights, if `keep_weights`.
    pub weights: Option<Vec<f64>>,
    /// One record per frozen test episode run (empty if cancelled before them).
    pub tests: Vec<EpisodeRecord>,
    /// One task-space trajectory per entry of `record_test_episodes`, as `trajectories`.
    pub test_trajectories: Vec<Vec<f64>>,
    /// The task-space row at the start of every test episode run, concatenated (`task_dim`
    /// values each): where each frozen test started (e.g. the hands at floor level or not).
    pub test_starts: Vec<f64>,
    /// The learner's mean state over every training episode run (`EpisodeScratch::mean_state`),
    /// concatenated (the learner's dimension each): where each episode went.
    pub mean_states: Vec<f64>,
}

/// Runs `options.n_trials` trials in parallel (rayon's current pool). Each trial clones its
/// template — the one of `templates` for every trial, or one per trial in order (a saved
/// policy's trials, each from its own weights) — weights included, so pre-trained weights carry
/// over; builds its plant with `make_plant(trial_index)` and runs `options.episodes` episodes
/// in `space`.
///
/// `cancel` is read before every step and start draw: once set, every trial stops and reports
/// `finished = false`. `done` is incremented after every episode, test episodes included
/// (progress: `n_trials × (episodes + test_episodes)` in all).
/// Inputs are checked once, up front, with one test episode's start when there are test
/// episodes ([`CoreError::NoTestStart`]); the only error past that point is
/// [`CoreError::NoValidStart`].
pub fn run_trials<P, F>(
    templates: &[Learner],
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
    if templates.len() != 1 && templates.len() != options.n_trials {
        return Err(CoreError::Shape {
            what: "weights",
            expected: format!("one row, or one per trial ({})", options.n_trials),
            got: format!("{} rows", templates.len()),
        });
    }
    let mut probe = make_plant(options.first_trial)?;
    for template in templates {
        template.check_space(space, probe.posture_dim())?;
    }
    let template = |trial: usize| {
        &templates[if templates.len() == 1 {
            0
        } else {
            trial - options.first_trial
        }]
    };
    if options.phase == Phase::Train && options.test_episodes > 0 {
        // A test-start rule no start meets fails here, not after the training it would lose.
        let mut tester = template(options.first_trial).clone();
        tester.set_phase(Phase::Test);
        let mut scratch = tester.scratch(space, probe.posture_dim());
        let mut rng = trial_rng(options.base_seed, options.first_trial);
        // Polls Ctrl-C (10⁹ draws may be allowed); cancelled, the trials below return unfinished.
        match tester.start_unless(&mut probe, space, &mut rng, &mut scratch, cancel) {
            Ok(()) | Err(CoreError::Cancelled) => {}
            Err(CoreError::NoValidStart { draws }) => return Err(CoreError::NoTestStart { draws }),
            Err(e) => return Err(e),
        }
    }
    drop(probe);
    let trials = options.first_trial..options.first_trial + options.n_trials;
    trials
        .into_par_iter()
        .map(|trial| run_one(template(trial), space, &make_plant, options, trial, cancel, done))
        .collect()
}

/// A start posture of `plant` drawn by [`Plant::sample_start`] from stream 0 of `seed`
/// ([`trial_rng`]): the start of a caller stepping the plant itself.
pub fn seeded_start<P: Plant>(plant: &mut P, seed: u64) -> Vec<f64> {
    let mut posture = vec![0.0; plant.posture_dim()];
    plant.sample_start(&mut trial_rng(seed, 0), &mut posture);
    posture
}

/// A latent space: the GPLVM maps and the latent box, checked by [`LatentArgs::check`].
#[derive(Debug, Clone)]
pub struct LatentSpace<'a> {
    /// Latent → posture GP map (GPLVM mean, Eq. 4).
    pub decoder: &'a GpMap,
    /// Posture → latent map (out-of-sample GP, back-constraint or iterative projection).
    pub encoder: &'a dyn Encode,
    /// Lower corner of the latent box.
    pub low: Vec<f64>,
    /// Upper corner of the latent box.
    pub high: Vec<f64>,
}

impl<'a> LatentSpace<'a> {
    /// The state space of these maps.
    pub fn space(&self) -> StateSpace<'a> {
        StateSpace::Latent {
            decoder: self.decoder,
            encoder: self.encoder,
        }
    }
}

/// A corner of the latent box as a caller gave it: its numbers, or (`Err`) the name of the
/// type that was not a 1-D array of numbers.
pub type Corner = std::result::Result<Vec<f64>, String>;

/// A latent space's parts as a caller gave them, each possibly left out.
#[derive(Debug, Default)]
pub struct LatentArgs<'a> {
    /// Latent → posture.
    pub decoder: Option<&'a GpMap>,
    /// Posture → latent.
    pub encoder: Option<&'a dyn Encode>,
    /// Lower corner of the latent box.
    pub low: Option<Corner>,
    /// Upper corner of the latent box.
    pub high: Option<Corner>,
}

fn argument<T>(message: String) -> Result<T> {
    Err(CoreError::Argument(message))
}

impl<'a> LatentArgs<'a> {
    /// Whether any part is given (Exp 1 runs its full-space learner when none is).
    pub fn given(&self) -> bool {
        self.decoder.is_some() || self.encoder.is_some() || self.low.is_some() || self.high.is_some()
    }

    /// The latent space: decoder and encoder given, corners of the decoder's input dimension,
    /// finite, `high > low`. `context` ends the "is required" messages.
    pub fn check(self, context: &str) -> Result<LatentSpace<'a>> {
        let decoder = self.decoder(context)?;
        let Some(encoder) = self.encoder else {
            return argument(format!("encoder (posture → latent) is required {context}"));
        };
        let (low, high) = latent_box(decoder, self.low, self.high, context)?;
        Ok(LatentSpace {
            decoder,
            encoder,
            low,
            high,
        })
    }
}

impl<'a> LatentArgs<'a> {
    /// The decoder, required.
    fn decoder(&self, context: &str) -> Result<&'a GpMap> {
        self.decoder
            .ok_or_else(|| CoreError::Argument(format!("decoder (a GpMap latent → posture) is required {context}")))
    }

    /// The latent space as [`LatentArgs::check`] if any part is given; none if no part is
    /// (Exp 1 then runs its full-space learner).
    pub fn check_given(self, context: &str) -> Result<Option<LatentSpace<'a>>> {
        if self.given() {
            self.check(context).map(Some)
        } else {
            Ok(None)
        }
    }

    /// The decoder and the latent box, without an encoder (what a survey of the space needs).
    pub fn check_box(self, context: &str) -> Result<(&'a GpMap, Vec<f64>, Vec<f64>)> {
        let decoder = self.decoder(context)?;
        let (low, high) = latent_box(decoder, self.low, self.high, context)?;
        Ok((decoder, low, high))
    }
}

/// The latent box `(low, high)` of `decoder`: both corners given, of its input dimension,
/// finite, `high > low`. `context` ends the "is required" messages.
fn latent_box(
    decoder: &GpMap,
    low: Option<Corner>,
    high: Option<Corner>,
    context: &str,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let dim = decoder.input_dim();
    let corner = |name: &'static str, value: Option<Corner>| -> Result<Vec<f64>> {
        let v = match value {
            None => return argument(format!("{name} is required {context}")),
            Some(Err(type_name)) => {
                return argument(format!(
                    "{name}: expected a 1-D array of {dim} numbers, got {type_name}"
                ));
            }
            Some(Ok(v)) => v,
        };
        if v.len() != dim {
            return argument(format!(
                "{name}: expected shape ({dim},) (the decoder's input dimension), got ({},)",
                v.len()
            ));
        }
        crate::error::check_finite(name, &v)?;
        Ok(v)
    };
    let low = corner("latent_low", low)?;
    let high = corner("latent_high", high)?;
    if let Some(k) = (0..dim).find(|&k| high[k] <= low[k]) {
        return argument(format!(
            "latent_high[{k}] = {} must exceed latent_low[{k}] = {}",
            high[k], low[k]
        ));
    }
    Ok((low, high))
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
    let plant = make_plant(trial)?;
    let mut learner = template.clone();
    learner.set_phase(options.phase);
    let scratch = learner.scratch(space, plant.posture_dim());
    let rng = trial_rng(options.base_seed, trial);
    let mut run = TrialRun {
        plant,
        learner,
        rng,
        episode_seed: (options.base_seed, trial),
        scratch,
        space,
        cancel,
        done,
    };
    let mut mean_states = Vec::new();
    let (episodes, trajectories, mut finished) =
        run.block(options.episodes, &options.record_episodes, None, Some(&mut mean_states))?;
    let (mut tests, mut test_trajectories) = (Vec::new(), vec![Vec::new(); options.record_test_episodes.len()]);
    let mut test_starts = Vec::new();
    if finished && options.test_episodes > 0 {
        run.learner.set_phase(Phase::Test);
        (tests, test_trajectories, finished) = run.block(
            options.test_episodes,
            &options.record_test_episodes,
            Some(&mut test_starts),
            None,
        )?;
    }
    let weights = options.keep_weights.then(|| run.learner.into_weights());
    Ok(TrialResult {
        trial,
        episodes,
        trajectories,
        finished,
        weights,
        tests,
        test_trajectories,
        test_starts,
        mean_states,
    })
}

/// One trial's plant, learner and generator, run block by block (training, then tests).
struct TrialRun<'a, P> {
    plant: P,
    learner: Learner,
    rng: ChaCha8Rng,
    /// The base seed and the trial: a rollout episode draws its actions from its own
    /// [`episode_rng`].
    episode_seed: (u64, usize),
    scratch: EpisodeScratch,
    space: &'a StateSpace<'a>,
    cancel: &'a AtomicBool,
    done: &'a AtomicUsize,
}

impl<P: Plant> TrialRun<'_, P> {
    /// Runs `n` episodes in the learner's current phase, recording the trajectories of the
    /// episodes listed in `record` (and, with `starts`, the first row of every episode; with
    /// `means`, every episode's mean state); returns the records, the trajectories and whether
    /// the block finished (false if cancelled).
    fn block(
        &mut self,
        n: usize,
        record: &[usize],
        mut starts: Option<&mut Vec<f64>>,
        mut means: Option<&mut Vec<f64>>,
    ) -> Result<(Vec<EpisodeRecord>, Vec<Vec<f64>>, bool)> {
        let mut episodes = Vec::with_capacity(n);
        let mut trajectories = vec![Vec::new(); record.len()];
        let mut buffer = Vec::new();
        let task_dim = self.plant.task_dim();
        let stop = self
            .learner
            .rules()
            .stop
            .filter(|_| self.learner.phase() == Phase::Train);
        let mut plateau = stop.map(crate::Plateau::new);
        for e in 0..n {
            if self.cancel.load(Ordering::Relaxed) {
                return Ok((episodes, trajectories, false));
            }
            let (plant, rng, space, scratch) = (&mut self.plant, &mut self.rng, self.space, &mut self.scratch);
            let rollout = matches!(self.learner.phase(), Phase::Rollout { .. });
            let (seed, trial) = self.episode_seed;
            let mut actions = rollout.then(|| episode_rng(seed, trial, e));
            let path = (starts.is_some() || record.contains(&e)).then(|| {
                buffer.clear();
                &mut buffer
            });
            let rec =
                match self
                    .learner
                    .run_episode_with(plant, space, rng, actions.as_mut(), scratch, path, self.cancel)
                {
                    Err(CoreError::Cancelled) => return Ok((episodes, trajectories, false)),
                    other => other?,
                };
            if let Some(starts) = starts.as_deref_mut() {
                starts.extend_from_slice(&buffer[..task_dim]);
            }
            if let Some(means) = means.as_deref_mut() {
                means.extend_from_slice(self.scratch.mean_state());
            }
            // The same episode may be listed twice: every listed slot gets the trajectory.
            for (slot, r) in trajectories.iter_mut().zip(record) {
                if *r == e {
                    slot.clone_from(&buffer);
                }
            }
            let stopped = plateau.as_mut().is_some_and(|p| p.record(&rec));
            episodes.push(rec);
            self.done.fetch_add(1, Ordering::Relaxed);
            if stopped {
                self.done.fetch_add(n - e - 1, Ordering::Relaxed); // progress counts the skipped ones
                break;
            }
        }
        Ok((episodes, trajectories, true))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;

    #[test]
    fn a_seeded_start_follows_its_seed() {
        let mut line = line();
        let start = seeded_start(&mut line, 3);
        assert_eq!((start.len(), start.clone()), (1, seeded_start(&mut line, 3)));
        assert_ne!(start, seeded_start(&mut line, 4));
    }

    #[test]
    fn latent_args_are_checked_only_when_any_part_is_given() {
        assert!(LatentArgs::default().check_given("here").unwrap().is_none());
        let low_only = LatentArgs {
            low: Some(Ok(vec![0.0])),
            ..LatentArgs::default()
        };
        let err = low_only.check_given("here").unwrap_err().to_string();
        assert_eq!(err, "decoder (a GpMap latent → posture) is required here");
    }

    #[test]
    fn streams_differ_and_repeat() {
        let a: Vec<u64> = (0..4).map(|_| trial_rng(1, 0).next_u64()).collect();
        assert!(a.windows(2).all(|w| w[0] == w[1]));
        assert_ne!(trial_rng(1, 0).next_u64(), trial_rng(1, 1).next_u64());
        assert_ne!(trial_rng(1, 0).next_u64(), trial_rng(2, 0).next_u64());
    }

    /// A 1-D line: starts uniform in [0, 1], a test start below `test_below` (0.5); the reward is x.
    struct Line {
        x: f64,
        test_below: f64,
    }

    fn line() -> Line {
        Line {
            x: 0.0,
            test_below: 0.5,
        }
    }

    impl Plant for Line {
        fn posture_dim(&self) -> usize {
            1
        }
        fn task_dim(&self) -> usize {
            1
        }
        fn sample_start<R: rand::Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
            posture[0] = rand::RngExt::random_range(rng, 0.0..1.0);
        }
        fn reset(&mut self, posture: &[f64]) -> Option<crate::EndReason> {
            self.x = posture[0];
            None
        }
        fn step(&mut self, target: &[f64], reached: &mut [f64]) -> crate::StepOutcome {
            self.x = target[0];
            reached[0] = self.x;
            crate::StepOutcome {
                reward: self.x,
                end: None,
            }
        }
        fn task_position(&self, out: &mut [f64]) {
            out[0] = self.x;
        }
        fn admits_test_start(&self) -> bool {
            self.x < self.test_below
        }
    }

    /// A test-start rule that no start meets failed after the whole training, which it lost.
    #[test]
    fn a_test_start_rule_no_start_meets_fails_before_training() {
        let config = crate::LearnerConfig {
            rbf_per_dim: 11,
            ..Default::default()
        };
        let rules = crate::EpisodeRules {
            max_steps: 5,
            max_start_draws: 50,
            ..Default::default()
        };
        let template = Learner::new(&config, rules, &[0.0], &[1.0]).unwrap();
        let options = TrialOptions {
            episodes: 100,
            test_episodes: 3,
            ..Default::default()
        };
        let (cancel, done) = (AtomicBool::new(false), AtomicUsize::new(0));
        let plant = |_| {
            Ok(Line {
                x: 0.0,
                test_below: -1.0,
            })
        };
        let one = std::slice::from_ref(&template);
        let err = run_trials(one, &StateSpace::Full, plant, &options, &cancel, &done).unwrap_err();
        assert!(matches!(err, CoreError::NoTestStart { draws: 50 }), "{err}");
        assert_eq!(done.load(Ordering::Relaxed), 0, "no training episode ran");
    }

    #[test]
    fn rollouts_of_every_action_rule_meet_the_same_starts() {
        let config = crate::LearnerConfig {
            rbf_per_dim: 11,
            step: 1.0,
            ..Default::default()
        };
        let rules = crate::EpisodeRules {
            max_steps: 5,
            ..Default::default()
        };
        let mut template = Learner::new(&config, rules, &[0.0], &[1.0]).unwrap();
        // V rises to the right: greedy always moves right.
        template
            .set_weights(&(0..11).map(f64::from).collect::<Vec<_>>())
            .unwrap();
        let run = |action, test_starts, seed| {
            let options = TrialOptions {
                episodes: 30,
                base_seed: seed,
                record_episodes: (0..30).collect(),
                phase: Phase::Rollout { action, test_starts },
                ..Default::default()
            };
            let (cancel, done) = (AtomicBool::new(false), AtomicUsize::new(0));
            let plant = |_| Ok(line());
            let one = std::slice::from_ref(&template);
            let trial = run_trials(one, &StateSpace::Full, plant, &options, &cancel, &done).unwrap();
            assert_eq!(template.weights(), &(0..11).map(f64::from).collect::<Vec<_>>()[..]);
            trial.into_iter().next().unwrap().trajectories
        };
        let starts = |paths: &[Vec<f64>]| paths.iter().map(|p| p[0]).collect::<Vec<_>>();
        let greedy = run(ActionRule::Greedy, false, 4);
        let softmax = run(ActionRule::SoftMax, false, 4);
        let random = run(ActionRule::Random, false, 4);
        assert_eq!(starts(&greedy), starts(&softmax));
        assert_eq!(starts(&greedy), starts(&random));
        assert_ne!(starts(&greedy), starts(&run(ActionRule::Greedy, false, 5)));
        assert!(
            greedy.iter().all(|p| p.windows(2).all(|w| w[1] >= w[0])),
            "greedy moves right"
        );
        let lefts = |paths: &[Vec<f64>]| paths.iter().flat_map(|p| p.windows(2)).filter(|w| w[1] < w[0]).count();
        assert!(
            lefts(&random) > 40,
            "the random control ignores V: {} moves left",
            lefts(&random)
        );
        let tested = run(ActionRule::Random, true, 4);
        assert!(starts(&tested).iter().all(|&x| x < 0.5));
        assert!(starts(&greedy).iter().any(|&x| x >= 0.5));
    }

    /// A trial under a stopping rule ends early, finished, its test episodes run, and progress
    /// counts the skipped episodes; without the rule it runs every episode.
    #[test]
    fn a_stopping_rule_ends_a_flat_trial_early() {
        let config = crate::LearnerConfig {
            rbf_per_dim: 11,
            step: 1.0,
            ..Default::default()
        };
        let run = |stop| {
            let rules = crate::EpisodeRules {
                max_steps: 5,
                stop,
                ..Default::default()
            };
            let template = Learner::new(&config, rules, &[0.0], &[1.0]).unwrap();
            let options = TrialOptions {
                episodes: 2000,
                test_episodes: 3,
                ..Default::default()
            };
            let (cancel, done) = (AtomicBool::new(false), AtomicUsize::new(0));
            let plant = |_| Ok(line());
            let one = std::slice::from_ref(&template);
            let trial = run_trials(one, &StateSpace::Full, plant, &options, &cancel, &done).unwrap();
            assert_eq!(done.load(Ordering::Relaxed), 2003);
            trial.into_iter().next().unwrap()
        };
        let full = run(None);
        assert_eq!((full.episodes.len(), full.finished), (2000, true));
        let stopped = run(Some(crate::StopRule {
            window: 20,
            patience: 2,
        }));
        assert!(stopped.finished && stopped.tests.len() == 3);
        assert!(stopped.episodes.len() < 2000 && stopped.episodes.len() % 20 == 0);
        assert_eq!(stopped.episodes[..], full.episodes[..stopped.episodes.len()]);
    }

    /// A line whose 10th step (or, refusing every start, its 10th start draw) sets the
    /// caller's cancel flag, as Ctrl-C would.
    struct Interrupting<'a> {
        line: Line,
        calls: &'a AtomicUsize,
        refuse: bool,
        cancel: &'a AtomicBool,
    }

    impl Interrupting<'_> {
        fn tick(&mut self) {
            if self.calls.fetch_add(1, Ordering::Relaxed) + 1 == 10 {
                self.cancel.store(true, Ordering::Relaxed);
            }
        }
    }

    impl Plant for Interrupting<'_> {
        fn posture_dim(&self) -> usize {
            1
        }
        fn task_dim(&self) -> usize {
            1
        }
        fn sample_start<R: rand::Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
            self.line.sample_start(rng, posture);
        }
        fn reset(&mut self, posture: &[f64]) -> Option<crate::EndReason> {
            if self.refuse {
                self.tick();
                return Some(crate::EndReason::Obstacle);
            }
            self.line.reset(posture)
        }
        fn step(&mut self, target: &[f64], reached: &mut [f64]) -> crate::StepOutcome {
            self.tick();
            self.line.step(target, reached)
        }
        fn task_position(&self, out: &mut [f64]) {
            self.line.task_position(out);
        }
    }

    /// Cancelling inside an episode of 10⁶ steps, or inside 10⁹ start draws, stops the
    /// trial there (unfinished, no episode recorded), not at the episode's end.
    #[test]
    fn cancel_stops_a_trial_inside_an_episode_and_its_start_draws() {
        let config = crate::LearnerConfig {
            rbf_per_dim: 11,
            step: 0.1,
            ..Default::default()
        };
        for refuse in [false, true] {
            let rules = crate::EpisodeRules {
                max_steps: 1_000_000,
                max_start_draws: 1_000_000_000,
                ..Default::default()
            };
            let template = Learner::new(&config, rules, &[0.0], &[1.0]).unwrap();
            let (cancel, done) = (AtomicBool::new(false), AtomicUsize::new(0));
            let calls = AtomicUsize::new(0);
            let plant = |_| {
                Ok(Interrupting {
                    line: line(),
                    calls: &calls,
                    refuse,
                    cancel: &cancel,
                })
            };
            let options = TrialOptions {
                episodes: 3,
                ..Default::default()
            };
            let one = std::slice::from_ref(&template);
            let trial = run_trials(one, &StateSpace::Full, plant, &options, &cancel, &done).unwrap();
            let trial = trial.into_iter().next().unwrap();
            assert!(!trial.finished, "refuse = {refuse}");
            assert_eq!(calls.load(Ordering::Relaxed), 10, "refuse = {refuse}");
            assert!(trial.episodes.is_empty() && done.load(Ordering::Relaxed) == 0);
        }
    }

    #[test]
    fn runner_limits_are_the_run_tables() {
        let args = |n_trials, episodes| RunArgs {
            n_trials,
            episodes,
            ..RunArgs::default()
        };
        let message = |a: RunArgs| TrialOptions::from_args(&a).unwrap_err().to_string();
        assert_eq!(message(args(0, 5)), "n_trials must lie in [1, 1000000], got 0");
        assert_eq!(message(args(1, -3)), "episodes must lie in [1, 100000000], got -3");
        assert!(message(args(1000, 100_000)).contains("= 100000000 episode records in one call, more than 10000000"));
        assert_eq!(RunConfig::count_bounds("test_episodes"), Some((0, 100_000_000)));
        assert_eq!(RunConfig::count_bounds("seed"), None);
    }

    #[test]
    fn options_are_checked() {
        assert!(
            TrialOptions {
                n_trials: 0,
                ..Default::default()
            }
            .validate()
            .is_err()
        );
        assert!(
            TrialOptions {
                episodes: 0,
                ..Default::default()
            }
            .validate()
            .is_err()
        );
        let o = TrialOptions {
            episodes: 10,
            record_episodes: vec![3, 10],
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(CoreError::InvalidParameter {
                name: "record_episodes",
                ..
            })
        ));
        let o = TrialOptions {
            test_episodes: 2,
            record_test_episodes: vec![2],
            ..Default::default()
        };
        assert!(matches!(
            o.validate(),
            Err(CoreError::InvalidParameter {
                name: "record_test_episodes",
                ..
            })
        ));
    }
}
