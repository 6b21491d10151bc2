//! Experiment 1 (docs/method.md §Experiment 1, paper Sec. IV-A, Fig. 4): two planar hands carrying
//! an object in end-effector space, as a kinematic [`Plant`], and the runner for its two learners.
//!
//! State (= posture) `x = (x_L, y_L, x_R, y_R)`; linear dynamics `x_{t+1} = x_t + δt·u`, so
//! a step reaches its target exactly. The object is held while `‖(x_R − x_L) − g‖ ≤ tol`
//! (`g = (0.1, 0)`); the hands must stay out of a disc obstacle and inside a box. The reward
//! is `exp(−θ ‖x − x*‖²)` (Eq. 12); a step that ends the episode (obstacle, box exit, drop)
//! earns that reward **plus** the penalty −1 (the paper adds the penalty to the reward; with this
//! reading a full-space learner that drops after ≈ 1.5 steps returns ≈ −0.92, the figure
//! of docs/method.md §Experiment 1).
//!
//! Learners: the full-space one ([`BimanualLearner::Full`]) has 12 actions
//! ([`full_space_actions`]) and a 20⁴ RBF grid over the plant's box; the latent one
//! ([`BimanualLearner::Latent`]) has `2d` orthogonal actions and a 20^d grid over a latent
//! box given by the caller (e.g. the bounding box of the fitted latent points plus a margin).

use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::error::{Result, check_vector};
use latent_core::params::{ParamError, Params, Rule};
use latent_core::trials::{LatentSpace, TrialOptions, TrialResult, run_trials};
use latent_core::{
    CoreError, Encode, EndReason, EpisodeRules, GpMap, Learner, LearnerConfig, Plant, ResultArray, StateSpace,
    StepOutcome, params, trial_arrays,
};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

/// The held object's offset `hand_R − hand_L` in metres (paper: (0.1, 0), no rotation): the
/// plant's default `grip` and the grip rule of [`crate::kinematics::grip_error`].
pub const GRIP: [f64; 2] = [0.1, 0.0];

params! {
    /// Everything about the Experiment 1 plant and its episodes; `Default` is
    /// docs/method.md §Experiment 1.
    pub struct BimanualConfig {
        /// Drop tolerance on ‖(x_R − x_L) − grip‖ (for RL 0.1, about one RBF spacing,
        /// docs/method.md §Experiment 1; Table I and the paper-strict variant: 0.005).
        drop_tolerance: f64 = 0.1 => Rule::Positive,
        /// The held object's offset x_R − x_L (paper: (0.1, 0), no rotation).
        grip: [f64; 2] = GRIP => Rule::Finite,
        /// Centre of the disc obstacle neither hand may enter (ours: (0.5, 0.5)).
        obstacle_centre: [f64; 2] = [0.5, 0.5] => Rule::Finite,
        /// Radius of the disc obstacle (ours: 0.2); 0 removes it.
        obstacle_radius: f64 = 0.2 => Rule::NonNegative,
        /// Lower bound of each hand coordinate (state box [low, high]² per hand; ours: −0.5).
        box_low: f64 = -0.5 => Rule::Finite,
        /// Upper bound of each hand coordinate (ours: 1.5).
        box_high: f64 = 1.5 => Rule::Finite,
        /// Target x* = (x_L, y_L, x_R, y_R) of the reward (paper: (0, 0, 0.1, 0)).
        target: [f64; 4] = [0.0, 0.0, 0.1, 0.0] => Rule::Finite,
        /// θ of the reward exp(−θ ‖x − x*‖²) (Eq. 12; paper: 0.75).
        theta: f64 = 0.75 => Rule::Positive,
        /// Mean of the left hand's start position (paper: (1, 1)).
        start_mean: [f64; 2] = [1.0, 1.0] => Rule::Finite,
        /// Standard deviation of the left hand's start position per coordinate (paper: 0.1);
        /// the right hand starts at left + grip.
        start_sd: f64 = 0.1 => Rule::NonNegative,
        /// Penalty R_p added when a step hits the obstacle, leaves the box or drops (paper: −1).
        penalty: f64 = -1.0 => Rule::closed(-1e6, 1e6),
        /// "Reached the target": RMS per-hand distance to x* at most this (ours: 0.1).
        reach_radius: f64 = 0.1 => Rule::Positive,
        /// Steps per episode before a time-out (paper: 500).
        max_steps: usize = 500 => Rule::count(1, 1_000_000),
    }
    check = box_order;
}

fn box_order(c: &BimanualConfig, path: &str) -> std::result::Result<(), ParamError> {
    if c.box_high <= c.box_low {
        return Err(ParamError::new(
            &latent_core::params::join(path, "box_high"),
            format!("must exceed box_low = {}, got {}", c.box_low, c.box_high),
        ));
    }
    Ok(())
}

impl BimanualConfig {
    /// The learner's episode rules: the plant's own (Gaussian) start, length and penalty.
    pub fn episode_rules(&self) -> EpisodeRules {
        EpisodeRules {
            max_steps: self.max_steps,
            penalty: self.penalty,
            ..EpisodeRules::default()
        }
    }

    /// The state box as `(low, high)` corners in posture space (4-D).
    pub fn posture_box(&self) -> ([f64; 4], [f64; 4]) {
        ([self.box_low; 4], [self.box_high; 4])
    }

    /// Why the posture `x` would end an episode, if it would: box exit, obstacle or drop
    /// (checked in that order).
    pub fn violation(&self, x: &[f64]) -> Option<EndReason> {
        if x.iter().any(|&v| v < self.box_low || v > self.box_high) {
            return Some(EndReason::BoxExit);
        }
        let [cx, cy] = self.obstacle_centre;
        let r2 = self.obstacle_radius * self.obstacle_radius;
        let inside = |hx: f64, hy: f64| (hx - cx) * (hx - cx) + (hy - cy) * (hy - cy) < r2;
        if inside(x[0], x[1]) || inside(x[2], x[3]) {
            return Some(EndReason::Obstacle);
        }
        let dx = x[2] - x[0] - self.grip[0];
        let dy = x[3] - x[1] - self.grip[1];
        if dx * dx + dy * dy > self.drop_tolerance * self.drop_tolerance {
            return Some(EndReason::Drop);
        }
        None
    }

    /// `R(x) = exp(−θ ‖x − x*‖²)` (paper Eq. 12).
    pub fn reward(&self, x: &[f64]) -> f64 {
        let d2: f64 = x.iter().zip(&self.target).map(|(a, b)| (a - b) * (a - b)).sum();
        (-self.theta * d2).exp()
    }

    /// RMS per-hand distance to the target, `sqrt(‖x − x*‖² / 2)`.
    pub fn rms_hand_distance(&self, x: &[f64]) -> f64 {
        let d2: f64 = x.iter().zip(&self.target).map(|(a, b)| (a - b) * (a - b)).sum();
        (d2 / 2.0).sqrt()
    }
}

/// The kinematic two-hand plant of Experiment 1.
#[derive(Debug, Clone)]
pub struct BimanualPlant {
    config: BimanualConfig,
    state: [f64; 4],
}

impl BimanualPlant {
    /// A plant with a checked configuration, both hands at the start mean.
    pub fn new(config: BimanualConfig) -> Result<Self> {
        config.validate()?;
        let [x, y] = config.start_mean;
        let state = [x, y, x + config.grip[0], y + config.grip[1]];
        Ok(Self { config, state })
    }

    /// Its configuration.
    pub fn config(&self) -> &BimanualConfig {
        &self.config
    }

    /// The current state `(x_L, y_L, x_R, y_R)`.
    pub fn state(&self) -> [f64; 4] {
        self.state
    }

    /// [`Plant::reset`] to a caller's `posture`, checked: 4 finite values.
    pub fn reset_checked(&mut self, posture: &[f64]) -> Result<Option<EndReason>> {
        check_vector("posture", posture, 4)?;
        Ok(self.reset(posture))
    }

    /// [`Plant::step`] towards a caller's `target`, checked: 4 finite values.
    pub fn step_checked(&mut self, target: &[f64]) -> Result<StepOutcome> {
        check_vector("target", target, 4)?;
        Ok(self.step(target, &mut [0.0; 4]))
    }
}

impl Plant for BimanualPlant {
    fn posture_dim(&self) -> usize {
        4
    }

    fn task_dim(&self) -> usize {
        4
    }

    /// Left hand ~ N(start_mean, start_sd²·I), right hand = left + grip
    /// (docs/method.md §Experiment 1).
    fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
        let nx: f64 = StandardNormal.sample(rng);
        let ny: f64 = StandardNormal.sample(rng);
        posture[0] = self.config.start_mean[0] + self.config.start_sd * nx;
        posture[1] = self.config.start_mean[1] + self.config.start_sd * ny;
        posture[2] = posture[0] + self.config.grip[0];
        posture[3] = posture[1] + self.config.grip[1];
    }

    fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
        self.state.copy_from_slice(posture);
        self.config.violation(posture)
    }

    /// Kinematic: the hands reach the target exactly.
    fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
        self.state.copy_from_slice(target);
        reached.copy_from_slice(target);
        let end = self.config.violation(target);
        let reward = self.config.reward(target) + if end.is_some() { self.config.penalty } else { 0.0 };
        StepOutcome { reward, end }
    }

    fn task_position(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.state);
    }

    fn reached_target(&self) -> bool {
        self.config.rms_hand_distance(&self.state) <= self.config.reach_radius
    }
}

/// The 12 full-space actions (docs/method.md §Experiment 1): the 4 directions +x, −x, +y, −y
/// applied to the left hand, the right hand, and both hands, as unit rows of a flat 12 × 4 array.
pub fn full_space_actions() -> Vec<f64> {
    let dirs = [[1.0, 0.0], [-1.0, 0.0], [0.0, 1.0], [0.0, -1.0]];
    let mut actions = Vec::with_capacity(48);
    for (left, right) in [(1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
        for [dx, dy] in dirs {
            actions.extend_from_slice(&[left * dx, left * dy, right * dx, right * dy]);
        }
    }
    actions
}

/// Which learner controls the plant.
#[derive(Debug, Clone, Copy)]
pub enum BimanualLearner<'a> {
    /// Full 4-D space: 12 actions, RBF grid over the plant's state box.
    Full,
    /// Latent space: the actions of the learner's config (Exp. 1: the 2d axes), RBF grid over
    /// `[low, high]` (d-D).
    Latent {
        /// Latent → posture GP map (GPLVM mean, Eq. 4).
        decoder: &'a GpMap,
        /// Posture → latent map (the out-of-sample GP, the back-constraint or a projection).
        encoder: &'a dyn Encode,
        /// Lower corner of the latent box.
        low: &'a [f64],
        /// Upper corner of the latent box.
        high: &'a [f64],
    },
}

impl<'a> BimanualLearner<'a> {
    /// The latent learner in `latent`, or the full-space learner without one.
    pub fn new(latent: Option<&'a LatentSpace<'a>>) -> Self {
        match latent {
            Some(l) => Self::Latent {
                decoder: l.decoder,
                encoder: l.encoder,
                low: &l.low,
                high: &l.high,
            },
            None => Self::Full,
        }
    }

    /// The learner (box, actions, fresh weights) and its state space for `plant`.
    pub fn build(&self, plant: &BimanualConfig, config: &LearnerConfig) -> Result<(Learner, StateSpace<'a>)> {
        plant.validate()?;
        match *self {
            Self::Full => {
                let (low, high) = plant.posture_box();
                let learner = Learner::with_actions(config, plant.episode_rules(), &low, &high, &full_space_actions())?;
                Ok((learner, StateSpace::Full))
            }
            Self::Latent {
                decoder,
                encoder,
                low,
                high,
            } => {
                let learner = Learner::new(config, plant.episode_rules(), low, high)?;
                let space = StateSpace::Latent { decoder, encoder };
                learner.check_space(&space, 4)?;
                Ok((learner, space))
            }
        }
    }
}

/// Runs Experiment 1 trials (docs/method.md §Experiment 1) in parallel: see
/// [`latent_core::trials::run_trials`] for seeding, cancellation and progress.
pub fn run_bimanual_trials(
    plant: &BimanualConfig,
    config: &LearnerConfig,
    learner: &BimanualLearner<'_>,
    options: &TrialOptions,
    cancel: &AtomicBool,
    done: &AtomicUsize,
) -> Result<Vec<TrialResult>> {
    let (template, space) = learner.build(plant, config)?;
    run_trials(
        std::slice::from_ref(&template),
        &space,
        |_| BimanualPlant::new(plant.clone()),
        options,
        cancel,
        done,
    )
}

/// Experiment 1's trials, checked before any runs: both configurations (their errors named
/// `plant.*` and `learner.*`), the learner's grid and maps, the recorded paths' memory.
#[derive(Debug)]
pub struct BimanualTrials<'a> {
    /// The toy's configuration.
    pub plant: BimanualConfig,
    /// The learner's configuration.
    pub config: LearnerConfig,
    learner: BimanualLearner<'a>,
    /// The learner every trial starts from.
    pub template: Learner,
    /// What is run.
    pub options: TrialOptions,
}

impl<'a> BimanualTrials<'a> {
    /// The trials of `learner` (`config`) on the toy `plant` with `options`.
    pub fn new(
        plant: BimanualConfig,
        config: LearnerConfig,
        learner: BimanualLearner<'a>,
        options: TrialOptions,
    ) -> Result<Self> {
        check_tables(&plant, &config)?;
        let (template, _) = learner.build(&plant, &config)?;
        options.check_recording(plant.max_steps, 4)?;
        #[rustfmt::skip]
        return Ok(Self { plant, config, learner, template, options });
    }

    /// Runs the trials ([`run_bimanual_trials`]).
    pub fn run(&self, cancel: &AtomicBool, done: &AtomicUsize) -> Result<Vec<TrialResult>> {
        run_bimanual_trials(&self.plant, &self.config, &self.learner, &self.options, cancel, done)
    }

    /// The arrays of `results` by name ([`trial_arrays`]), paths of the hands (4 values a row).
    pub fn arrays(&self, results: &[TrialResult]) -> Vec<(String, ResultArray)> {
        trial_arrays(results, &self.template, &self.options, 4)
    }
}

/// Both of Experiment 1's configurations checked, a broken rule named `plant.*` or `learner.*`.
pub fn check_tables(plant: &BimanualConfig, learner: &LearnerConfig) -> Result<()> {
    plant.check_fields("plant").map_err(CoreError::from)?;
    learner.check_fields("learner").map_err(CoreError::from)
}

/// The keys of Experiment 1's configuration (`plant.*`: the toy, `learner.*`) with their docs,
/// rules, types and defaults.
pub fn schema_tables() -> Vec<crate::task::SchemaTable> {
    use crate::task::SchemaTable;
    vec![
        SchemaTable::of("plant", &BimanualConfig::default()),
        SchemaTable::of("learner", &LearnerConfig::default()),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn violations_and_reward() {
        let c = BimanualConfig::default();
        assert_eq!(c.violation(&[1.0, 1.0, 1.1, 1.0]), None);
        assert_eq!(c.violation(&[0.5, 0.45, 0.6, 0.45]), Some(EndReason::Obstacle));
        assert_eq!(
            c.violation(&[0.2, 0.5, 0.3, 0.5]),
            None,
            "left hand 0.3 from the centre, right 0.2: on the rim"
        );
        assert_eq!(c.violation(&[1.45, 1.0, 1.55, 1.0]), Some(EndReason::BoxExit));
        assert_eq!(c.violation(&[1.0, 1.0, 1.25, 1.0]), Some(EndReason::Drop));
        assert_eq!(c.violation(&[1.0, 1.0, 1.19, 1.0]), None, "within the 0.1 tolerance");
        let strict = BimanualConfig {
            drop_tolerance: 0.005,
            ..c.clone()
        };
        assert_eq!(strict.violation(&[1.0, 1.0, 1.11, 1.0]), Some(EndReason::Drop));
        assert_eq!(c.reward(&c.target), 1.0);
        assert!((c.reward(&[1.0, 1.0, 1.1, 1.0]) - (-3.0f64).exp()).abs() < 1e-15);
        assert!((c.rms_hand_distance(&[0.1, 0.0, 0.2, 0.0]) - 0.1).abs() < 1e-15);
    }

    #[test]
    fn checked_reset_and_step_refuse_a_wrong_length_or_a_nan() {
        let mut p = BimanualPlant::new(BimanualConfig::default()).unwrap();
        let wrong = p.reset_checked(&[0.0; 3]).unwrap_err().to_string();
        assert_eq!(wrong, "posture: expected shape (4,), got (3,)");
        assert!(
            p.step_checked(&[0.0, f64::NAN, 0.0, 0.0])
                .unwrap_err()
                .to_string()
                .contains("non-finite")
        );
        assert_eq!(p.reset_checked(&[1.0, 1.0, 1.1, 1.0]).unwrap(), None);
        assert_eq!(p.state(), [1.0, 1.0, 1.1, 1.0]);
    }

    #[test]
    fn step_adds_the_penalty_and_reports_the_end() {
        let mut p = BimanualPlant::new(BimanualConfig::default()).unwrap();
        let mut reached = [0.0; 4];
        let ok = p.step(&[1.0, 1.0, 1.1, 1.0], &mut reached);
        assert_eq!(reached, [1.0, 1.0, 1.1, 1.0]);
        assert_eq!(ok.end, None);
        let dropped = p.step(&[1.0, 1.0, 1.3, 1.0], &mut reached);
        assert_eq!(dropped.end, Some(EndReason::Drop));
        assert!((dropped.reward - (p.config().reward(&[1.0, 1.0, 1.3, 1.0]) - 1.0)).abs() < 1e-15);
        assert!(!p.reached_target());
        p.step(&[0.05, 0.0, 0.15, 0.0], &mut reached);
        assert!(p.reached_target());
    }

    #[test]
    fn starts_hold_the_object_around_1_1() {
        let mut p = BimanualPlant::new(BimanualConfig::default()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        let mut x = [0.0; 4];
        let mut mean = [0.0; 2];
        for _ in 0..2000 {
            p.sample_start(&mut rng, &mut x);
            assert_eq!(p.reset(&x), None);
            assert!(((x[2] - x[0]) - 0.1).abs() < 1e-12 && (x[3] - x[1]).abs() < 1e-12);
            mean[0] += x[0] / 2000.0;
            mean[1] += x[1] / 2000.0;
        }
        assert!((mean[0] - 1.0).abs() < 0.01 && (mean[1] - 1.0).abs() < 0.01, "{mean:?}");
    }

    #[test]
    fn twelve_distinct_unit_actions() {
        let a = full_space_actions();
        assert_eq!(a.len(), 48);
        let rows: Vec<&[f64]> = a.chunks_exact(4).collect();
        for (i, r) in rows.iter().enumerate() {
            assert!(r.iter().any(|&v| v != 0.0));
            assert!(rows[..i].iter().all(|o| o != r));
        }
        // "Both hands" moves keep the grip.
        for r in &rows[8..] {
            assert_eq!(r[0], r[2]);
            assert_eq!(r[1], r[3]);
        }
    }

    #[test]
    fn full_learner_step_is_0_021() {
        let (learner, _) = BimanualLearner::Full
            .build(&BimanualConfig::default(), &LearnerConfig::default())
            .unwrap();
        assert_eq!(learner.grid().len(), 160_000);
        let d = learner.displacements();
        assert!((d[0] - 0.2 * 2.0 / 19.0).abs() < 1e-15);
    }

    #[test]
    fn bad_config_is_an_error() {
        for c in [
            BimanualConfig {
                drop_tolerance: 0.0,
                ..Default::default()
            },
            BimanualConfig {
                box_high: -1.0,
                ..Default::default()
            },
            BimanualConfig {
                start_sd: -0.1,
                ..Default::default()
            },
            BimanualConfig {
                target: [f64::NAN, 0.0, 0.0, 0.0],
                ..Default::default()
            },
        ] {
            assert!(BimanualPlant::new(c).is_err());
        }
    }
}
