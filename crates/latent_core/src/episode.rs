//! The plant interface and the episode loop of RL in latent space (paper Sec. III-E,
//! Fig. 3; SPEC §3.1), entirely in Rust.
//!
//! The learner's state space is either the plant's posture space itself
//! ([`StateSpace::Full`]: decode and encode are the identity) or a latent space
//! ([`StateSpace::Latent`]) with a GP decoder (latent → posture, Eq. 4) and an
//! out-of-sample GP encoder (posture → latent, Sec. III-B). One step from state `z_t`:
//!
//! 1. look-ahead `Q(z_t, u_i) = V(z_t + Δ_i)` (Eq. 11) and a soft-max draw (Eq. 10);
//! 2. `z' = z_t + Δ_a`; outside the learner's box ⇒ penalty, terminal, no plant call
//!    ([`EndReason::BoxExit`]);
//! 3. decode `x̂ = μ(z')`; with variance gating on (SPEC §3.2, off by default) a variance
//!    above the threshold ⇒ penalty, terminal, no plant call ([`EndReason::Uncertain`]);
//! 4. the plant tracks `x̂` for one RL step and reports the reached posture `x̃`, the reward
//!    (its own penalty included) and whether the episode ended;
//! 5. encode `z_{t+1} = g(x̃)`;
//! 6. TD(0) on `(z_t, r_t, z_{t+1})` (Eq. 7–9), terminal if the plant ended the episode
//!    (skipped in [`Phase::Test`]: frozen test episodes act on the learnt V unchanged).
//!
//! The step displacement is `Δ_i = step_fraction · h ⊙ u_i`: each action's unit direction
//! `u_i` scaled per dimension by the RBF grid spacing `h` (SPEC: 0.2 × spacing).
//! Reaching `max_steps` is a time-out, not a terminal state: the last update bootstraps.

use rand::{Rng, RngExt};

use crate::error::{CoreError, Result, check_finite, check_positive};
use crate::gp::{GpMap, PredictScratch};
use crate::policy::{SoftmaxPolicy, check_actions};
use crate::rbf::{RbfConfig, RbfGrid, RbfScratch, SparseFeatures};
use crate::td::{TdConfig, TdLearner};

/// How an episode ended; the codes are those of `returns.npz` (SPEC §5).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u8)]
pub enum EndReason {
    /// 0: ran for `max_steps` without a penalty (also "not ended" inside a step).
    TimeOut = 0,
    /// 1: the hands (or links) hit an obstacle.
    Obstacle = 1,
    /// 2: the learner's state left its box, or the plant left its own state box.
    BoxExit = 2,
    /// 3: the held object was dropped (constraint broken).
    Drop = 3,
    /// 4: the robot fell.
    Fall = 4,
    /// 5: variance gating (SPEC §3.2) refused a decoded target; ours, beyond SPEC §5.
    Uncertain = 5,
}

impl EndReason {
    /// The numeric code (0 time-out, 1 obstacle, 2 box exit, 3 drop, 4 fall, 5 uncertain).
    pub fn code(self) -> u8 {
        self as u8
    }

    /// The reason for a code, if it is one.
    pub fn from_code(code: u8) -> Option<Self> {
        [
            Self::TimeOut,
            Self::Obstacle,
            Self::BoxExit,
            Self::Drop,
            Self::Fall,
            Self::Uncertain,
        ]
        .get(code as usize)
        .copied()
    }
}

/// What one plant step reports.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepOutcome {
    /// Reward of the reached state (Eq. 12), the plant's penalty already added if it ended.
    pub reward: f64,
    /// `Some(reason)` if this step ended the episode (a terminal transition).
    pub end: Option<EndReason>,
}

/// A system to control: a kinematic toy, simulated arms, a humanoid.
pub trait Plant {
    /// Posture dimension D (joint angles, or hand coordinates for the toy).
    fn posture_dim(&self) -> usize;

    /// Dimension of the task-space position recorded in trajectories (e.g. 4 for two
    /// planar hands).
    fn task_dim(&self) -> usize;

    /// Draws a start posture from the plant's own start distribution into `posture`.
    fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]);

    /// Puts the plant at `posture`. Returns `Some(reason)` if that posture is not an
    /// admissible start (e.g. inside an obstacle or with the object dropped).
    fn reset(&mut self, posture: &[f64]) -> Option<EndReason>;

    /// Tracks `target` for one RL time step, writes the reached posture into `reached`
    /// and reports the reward and whether the episode ended.
    fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome;

    /// The current task-space position (e.g. both hands) into `out` (`task_dim()` long).
    fn task_position(&self, out: &mut [f64]);

    /// True if the current state counts as "reached the target" (the experiment's one
    /// definition); plants without one keep the default `false`.
    fn reached_target(&self) -> bool {
        false
    }

    /// True if the episode has, since the last reset, passed the plant's waypoint (e.g.
    /// started below a wall and got above it through a corridor); plants without one keep
    /// the default `false`.
    fn passed(&self) -> bool {
        false
    }

    /// Checked after an admitted [`Plant::reset`] when the learner is in [`Phase::Test`]:
    /// whether the current state may also start a frozen test episode (e.g. the hands below
    /// the wall they must pass). Default: every admissible start.
    fn admits_test_start(&self) -> bool {
        true
    }
}

/// Whether a learner is training or running frozen test episodes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Phase {
    /// TD(0) updates after every step (Eq. 7–9).
    #[default]
    Train,
    /// No updates: the soft-max policy acts on the learnt value function as it is, and
    /// starts must also pass [`Plant::admits_test_start`].
    Test,
}

/// The learner's state space relative to the plant's posture space.
#[derive(Debug, Clone, Copy)]
pub enum StateSpace<'a> {
    /// The posture space itself: decode and encode are the identity.
    Full,
    /// A latent space: `decoder` maps latent → posture (GPLVM mean, Eq. 4), `encoder`
    /// posture → latent (out-of-sample GP, Sec. III-B).
    Latent {
        /// Latent → posture GP map.
        decoder: &'a GpMap,
        /// Posture → latent GP map.
        encoder: &'a GpMap,
    },
}

/// Where an episode starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StartMode {
    /// The plant draws a posture ([`Plant::sample_start`]); the learner encodes it.
    #[default]
    FromPlant,
    /// Uniform over the learner's box, decoded; redrawn while the plant refuses the
    /// decoded posture (or variance gating does). The latent state is the drawn point.
    UniformInBox,
}

/// Everything about a learner except its state box and action set; `Default` is the
/// paper's Experiment 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LearnerConfig {
    /// RBF grid of the value function (paper: 20 per dimension, σ = spacing).
    pub rbf: RbfConfig,
    /// α, γ and the initial weights (paper Exp. 1: 0.9, 0.95, 0).
    pub td: TdConfig,
    /// Soft-max inverse temperature β of Eq. 10 (paper Exp. 1: 10).
    pub beta: f64,
    /// Step length δt·|u| as a fraction of the RBF spacing, per dimension (ours: 0.2).
    pub step_fraction: f64,
    /// Steps per episode before a time-out (paper Exp. 1: 500).
    pub max_steps: usize,
    /// Penalty R_p for leaving the learner's box or failing the variance gate (paper: −1).
    pub penalty: f64,
    /// Variance gating (SPEC §3.2): decoded variance above this ⇒ penalty and terminal.
    /// `None` (default) turns it off; ignored in the full space (nothing is decoded).
    pub variance_threshold: Option<f64>,
    /// Where episodes start.
    pub start: StartMode,
    /// Draws allowed to find an admissible start before [`CoreError::NoValidStart`].
    pub max_start_draws: usize,
}

impl Default for LearnerConfig {
    fn default() -> Self {
        Self {
            rbf: RbfConfig::default(),
            td: TdConfig::default(),
            beta: 10.0,
            step_fraction: 0.2,
            max_steps: 500,
            penalty: -1.0,
            variance_threshold: None,
            start: StartMode::FromPlant,
            max_start_draws: 1000,
        }
    }
}

impl LearnerConfig {
    /// Checks every field (the grid's and TD's included when the learner is built).
    pub fn validate(&self) -> Result<()> {
        self.td.validate()?;
        check_positive("beta (soft-max inverse temperature)", self.beta)?;
        check_positive("step_fraction", self.step_fraction)?;
        check_finite("penalty", &[self.penalty])?;
        if let Some(t) = self.variance_threshold {
            check_positive("variance_threshold", t)?;
        }
        if self.max_steps == 0 {
            return Err(CoreError::InvalidParameter {
                name: "max_steps",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        if self.max_start_draws == 0 {
            return Err(CoreError::InvalidParameter {
                name: "max_start_draws",
                value: 0.0,
                reason: "must be at least 1",
            });
        }
        Ok(())
    }
}

/// What is recorded of one episode.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeRecord {
    /// Cumulative reward, penalties included.
    pub ret: f64,
    /// How it ended.
    pub end: EndReason,
    /// Steps taken (transitions, the terminating one included).
    pub steps: usize,
    /// True if [`Plant::reached_target`] held after some plant step.
    pub reached: bool,
    /// True if [`Plant::passed`] held after some plant step.
    pub passed: bool,
}

/// Result of one [`Learner::step`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepResult {
    /// Reward of this transition, penalty included.
    pub reward: f64,
    /// `Some(reason)` if the episode ended (terminal transition).
    pub end: Option<EndReason>,
    /// True if the plant was called (false for box exits and gated targets).
    pub moved: bool,
}

/// Buffers for one trial's episodes: nothing is allocated per step.
#[derive(Debug, Clone)]
pub struct EpisodeScratch {
    z: Vec<f64>,
    z_next: Vec<f64>,
    candidate: Vec<f64>,
    q: Vec<f64>,
    q_buffer: Vec<f64>,
    current: SparseFeatures,
    next: SparseFeatures,
    rbf: RbfScratch,
    target: Vec<f64>,
    reached: Vec<f64>,
    decode: Option<PredictScratch>,
    encode: Option<PredictScratch>,
}

impl EpisodeScratch {
    /// The learner's current state `z_t`.
    pub fn state(&self) -> &[f64] {
        &self.z
    }

    /// The last posture the plant reached (or was reset to).
    pub fn posture(&self) -> &[f64] {
        &self.reached
    }
}

/// A TD(0) learner with its RBF grid, soft-max policy and scaled action set.
#[derive(Debug, Clone)]
pub struct Learner {
    grid: RbfGrid,
    td: TdLearner,
    policy: SoftmaxPolicy,
    displacements: Vec<f64>,
    n_actions: usize,
    config: LearnerConfig,
    phase: Phase,
}

impl Learner {
    /// A learner over the box `[low, high]` with unit action directions `actions` (a flat
    /// `n_actions × dim` array, e.g. [`crate::policy::orthogonal_actions`]).
    pub fn new(config: &LearnerConfig, low: &[f64], high: &[f64], actions: &[f64]) -> Result<Self> {
        config.validate()?;
        let grid = RbfGrid::new(low, high, &config.rbf)?;
        let dim = grid.dim();
        let n_actions = check_actions(actions, dim)?;
        let displacements = actions
            .chunks_exact(dim)
            .flat_map(|u| u.iter().zip(grid.spacing()).map(|(u, h)| config.step_fraction * h * u))
            .collect();
        let td = TdLearner::new(grid.len(), &config.td)?;
        let policy = SoftmaxPolicy::new(config.beta)?;
        Ok(Self {
            grid,
            td,
            policy,
            displacements,
            n_actions,
            config: *config,
            phase: Phase::Train,
        })
    }

    /// Switches between training (TD updates) and frozen test episodes (none).
    pub fn set_phase(&mut self, phase: Phase) {
        self.phase = phase;
    }

    /// The current phase ([`Phase::Train`] when built).
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// TD(0) update (Eq. 7–9) of the features `b`, unless the learner is frozen.
    #[inline]
    fn learn(&mut self, b: &SparseFeatures, reward: f64, v_next: Option<f64>) {
        if self.phase == Phase::Train {
            self.td.update(b, reward, v_next);
        }
    }

    /// The RBF grid.
    pub fn grid(&self) -> &RbfGrid {
        &self.grid
    }

    /// The value-function weights `w`.
    pub fn weights(&self) -> &[f64] {
        self.td.weights()
    }

    /// Consumes the learner, returning `w`.
    pub fn into_weights(self) -> Vec<f64> {
        self.td.into_weights()
    }

    /// Its configuration.
    pub fn config(&self) -> &LearnerConfig {
        &self.config
    }

    /// Number of actions.
    pub fn n_actions(&self) -> usize {
        self.n_actions
    }

    /// The step displacements `Δ_i` (flat `n_actions × dim`).
    pub fn displacements(&self) -> &[f64] {
        &self.displacements
    }

    /// Checks that `space` connects this learner to a plant with `posture_dim` coordinates.
    pub fn check_space(&self, space: &StateSpace<'_>, posture_dim: usize) -> Result<()> {
        let dim = self.grid.dim();
        let mismatch = |what: &'static str, expected: usize, got: usize| {
            Err(CoreError::Shape {
                what,
                expected: format!("dimension {expected}"),
                got: format!("dimension {got}"),
            })
        };
        match space {
            StateSpace::Full if posture_dim != dim => {
                mismatch("plant posture (full-space learner box)", dim, posture_dim)
            }
            StateSpace::Full => Ok(()),
            StateSpace::Latent { decoder, encoder } => {
                if decoder.input_dim() != dim {
                    mismatch("decoder input (latent box)", dim, decoder.input_dim())
                } else if decoder.output_dim() != posture_dim {
                    mismatch("decoder output (plant posture)", posture_dim, decoder.output_dim())
                } else if encoder.input_dim() != posture_dim {
                    mismatch("encoder input (plant posture)", posture_dim, encoder.input_dim())
                } else if encoder.output_dim() != dim {
                    mismatch("encoder output (latent box)", dim, encoder.output_dim())
                } else {
                    Ok(())
                }
            }
        }
    }

    /// Buffers for episodes in `space` on a plant with `posture_dim` coordinates.
    pub fn scratch(&self, space: &StateSpace<'_>, posture_dim: usize) -> EpisodeScratch {
        let dim = self.grid.dim();
        let (decode, encode) = match space {
            StateSpace::Full => (None, None),
            StateSpace::Latent { decoder, encoder } => (Some(decoder.scratch()), Some(encoder.scratch())),
        };
        EpisodeScratch {
            z: vec![0.0; dim],
            z_next: vec![0.0; dim],
            candidate: vec![0.0; dim],
            q: vec![0.0; self.n_actions],
            q_buffer: vec![0.0; self.n_actions],
            current: self.grid.features(),
            next: self.grid.features(),
            rbf: self.grid.scratch(),
            target: vec![0.0; posture_dim],
            reached: vec![0.0; posture_dim],
            decode,
            encode,
        }
    }

    /// Decodes `z` into `posture` (identity in the full space). Returns the GPLVM variance
    /// when `with_variance` (for variance gating), else 0: the `O(N²)` solve is skipped.
    #[inline]
    fn decode(
        space: &StateSpace<'_>,
        z: &[f64],
        posture: &mut [f64],
        scratch: Option<&mut PredictScratch>,
        with_variance: bool,
    ) -> f64 {
        match (space, scratch) {
            (StateSpace::Latent { decoder, .. }, Some(s)) if with_variance => decoder.predict_into(z, posture, s),
            (StateSpace::Latent { decoder, .. }, Some(s)) => {
                decoder.mean_into(z, posture, s);
                0.0
            }
            _ => {
                posture.copy_from_slice(z);
                0.0
            }
        }
    }

    /// Encodes `posture` into `z` (identity in the full space).
    #[inline]
    fn encode(space: &StateSpace<'_>, posture: &[f64], z: &mut [f64], scratch: Option<&mut PredictScratch>) {
        match (space, scratch) {
            (StateSpace::Latent { encoder, .. }, Some(s)) => {
                encoder.mean_into(posture, z, s);
            }
            _ => z.copy_from_slice(posture),
        }
    }

    /// Starts an episode (see [`StartMode`]): resets the plant and sets `z_0` and `b(z_0)`.
    /// In [`Phase::Test`] a start must also pass [`Plant::admits_test_start`].
    pub fn start<P: Plant, R: Rng + ?Sized>(
        &self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        s: &mut EpisodeScratch,
    ) -> Result<()> {
        let draws = self.config.max_start_draws;
        let mut admitted = false;
        for _ in 0..draws {
            match self.config.start {
                StartMode::FromPlant => {
                    plant.sample_start(rng, &mut s.reached);
                    if plant.reset(&s.reached).is_none() {
                        Self::encode(space, &s.reached, &mut s.z, s.encode.as_mut());
                        admitted = true;
                    }
                }
                StartMode::UniformInBox => {
                    for (k, z) in s.z.iter_mut().enumerate() {
                        *z = rng.random_range(self.grid.low()[k]..=self.grid.high()[k]);
                    }
                    let gated = self.config.variance_threshold.is_some();
                    let var = Self::decode(space, &s.z, &mut s.reached, s.decode.as_mut(), gated);
                    let gated = matches!(space, StateSpace::Latent { .. })
                        && self.config.variance_threshold.is_some_and(|t| var > t);
                    admitted = !gated && plant.reset(&s.reached).is_none();
                }
            }
            if admitted && (self.phase == Phase::Train || plant.admits_test_start()) {
                break;
            }
            admitted = false;
        }
        if !admitted {
            return Err(CoreError::NoValidStart { draws });
        }
        self.grid.eval_into(&s.z, &mut s.rbf, &mut s.current);
        Ok(())
    }

    /// One step from the current state (module doc, steps 1–6), TD update included in
    /// [`Phase::Train`].
    #[inline]
    pub fn step<P: Plant, R: Rng + ?Sized>(
        &mut self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        s: &mut EpisodeScratch,
    ) -> StepResult {
        let dim = self.grid.dim();
        // 1. Look-ahead Q(z, u_i) = V(z + Δ_i) (Eq. 11) and soft-max draw (Eq. 10).
        for (q, d) in s.q.iter_mut().zip(self.displacements.chunks_exact(dim)) {
            shifted(&s.z, d, &mut s.candidate);
            *q = self.grid.value(self.td.weights(), &s.candidate, &mut s.rbf);
        }
        let a = self.policy.sample(&s.q, &mut s.q_buffer, rng);
        // 2. z' = z + Δ_a, which must stay in the learner's box.
        shifted(&s.z, &self.displacements[a * dim..(a + 1) * dim], &mut s.candidate);
        let penalty = self.config.penalty;
        if !self.grid.contains(&s.candidate) {
            self.learn(&s.current, penalty, None);
            return StepResult {
                reward: penalty,
                end: Some(EndReason::BoxExit),
                moved: false,
            };
        }
        // 3. Decode (and gate on the variance).
        let gated = self.config.variance_threshold.is_some();
        let var = Self::decode(space, &s.candidate, &mut s.target, s.decode.as_mut(), gated);
        if matches!(space, StateSpace::Latent { .. }) && self.config.variance_threshold.is_some_and(|t| var > t) {
            self.learn(&s.current, penalty, None);
            return StepResult {
                reward: penalty,
                end: Some(EndReason::Uncertain),
                moved: false,
            };
        }
        // 4. The plant tracks the target.
        let outcome = plant.step(&s.target, &mut s.reached);
        if let Some(end) = outcome.end {
            self.learn(&s.current, outcome.reward, None);
            return StepResult {
                reward: outcome.reward,
                end: Some(end),
                moved: true,
            };
        }
        // 5. Encode, 6. TD(0) with bootstrap.
        Self::encode(space, &s.reached, &mut s.z_next, s.encode.as_mut());
        self.grid.eval_into(&s.z_next, &mut s.rbf, &mut s.next);
        let v_next = self.td.value(&s.next);
        self.learn(&s.current, outcome.reward, Some(v_next));
        std::mem::swap(&mut s.current, &mut s.next);
        std::mem::swap(&mut s.z, &mut s.z_next);
        StepResult {
            reward: outcome.reward,
            end: None,
            moved: true,
        }
    }

    /// Runs one episode: [`Self::start`], then [`Self::step`] until a terminal transition
    /// or `max_steps`. If `trajectory` is given, the plant's task-space position after the
    /// reset and after every plant step is appended to it (`task_dim()` values per row).
    pub fn run_episode<P: Plant, R: Rng + ?Sized>(
        &mut self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        s: &mut EpisodeScratch,
        mut trajectory: Option<&mut Vec<f64>>,
    ) -> Result<EpisodeRecord> {
        self.start(plant, space, rng, s)?;
        let task_dim = plant.task_dim();
        let record_row = |plant: &P, traj: &mut Option<&mut Vec<f64>>| {
            if let Some(t) = traj.as_deref_mut() {
                let start = t.len();
                t.resize(start + task_dim, 0.0);
                plant.task_position(&mut t[start..]);
            }
        };
        record_row(plant, &mut trajectory);
        let mut record = EpisodeRecord {
            ret: 0.0,
            end: EndReason::TimeOut,
            steps: 0,
            reached: false,
            passed: false,
        };
        while record.steps < self.config.max_steps {
            let r = self.step(plant, space, rng, s);
            record.steps += 1;
            record.ret += r.reward;
            if r.moved {
                record_row(plant, &mut trajectory);
                record.reached |= plant.reached_target();
                record.passed |= plant.passed();
            }
            if let Some(end) = r.end {
                record.end = end;
                break;
            }
        }
        Ok(record)
    }
}

/// `out = z + d`.
#[inline]
fn shifted(z: &[f64], d: &[f64], out: &mut [f64]) {
    for ((o, z), d) in out.iter_mut().zip(z).zip(d) {
        *o = z + d;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::policy::orthogonal_actions;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// A 1-D corridor on [0, 1]: reward x per step (more to the right), obstacle
    /// (terminal, reward x − 1) beyond 0.85.
    struct Corridor {
        x: f64,
    }

    impl Plant for Corridor {
        fn posture_dim(&self) -> usize {
            1
        }
        fn task_dim(&self) -> usize {
            1
        }
        fn sample_start<R: Rng + ?Sized>(&mut self, _rng: &mut R, posture: &mut [f64]) {
            posture[0] = 0.5;
        }
        fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
            self.x = posture[0];
            None
        }
        fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
            self.x = target[0];
            reached[0] = self.x;
            if self.x > 0.85 {
                StepOutcome {
                    reward: self.x - 1.0,
                    end: Some(EndReason::Obstacle),
                }
            } else {
                StepOutcome {
                    reward: self.x,
                    end: None,
                }
            }
        }
        fn task_position(&self, out: &mut [f64]) {
            out[0] = self.x;
        }
        fn passed(&self) -> bool {
            self.x > 0.7
        }
        fn admits_test_start(&self) -> bool {
            self.x < 0.3
        }
    }

    fn learner(max_steps: usize) -> Learner {
        let config = LearnerConfig {
            rbf: RbfConfig {
                centres_per_dim: 11,
                ..RbfConfig::default()
            },
            step_fraction: 1.0,
            max_steps,
            ..LearnerConfig::default()
        };
        Learner::new(&config, &[0.0], &[1.0], &orthogonal_actions(1)).unwrap()
    }

    #[test]
    fn episode_accounting_and_trajectory() {
        let mut l = learner(50);
        let mut plant = Corridor { x: 0.0 };
        let mut rng = ChaCha8Rng::seed_from_u64(0);
        let mut s = l.scratch(&StateSpace::Full, 1);
        let mut traj = Vec::new();
        let rec = l
            .run_episode(&mut plant, &StateSpace::Full, &mut rng, &mut s, Some(&mut traj))
            .unwrap();
        assert!(rec.steps >= 1 && rec.steps <= 50);
        let rows = traj.len();
        // The reward of every plant step is the reached x; penalties come on top.
        let visited: f64 = traj[1..].iter().sum();
        match rec.end {
            EndReason::Obstacle => {
                assert!((rec.ret - (visited - 1.0)).abs() < 1e-12);
                assert_eq!(rows, rec.steps + 1);
            }
            // A box exit (below 0) pays −1 with no plant call.
            EndReason::BoxExit => {
                assert!((rec.ret - (visited - 1.0)).abs() < 1e-12);
                assert_eq!(rows, rec.steps);
            }
            EndReason::TimeOut => {
                assert!((rec.ret - visited).abs() < 1e-12);
                assert_eq!(rows, 51);
            }
            other => panic!("unexpected end {other:?}"),
        }
        assert_eq!(traj[0], 0.5);
        // Steps move by exactly one spacing (0.1).
        for w in traj.windows(2) {
            assert!(((w[1] - w[0]).abs() - 0.1).abs() < 1e-12);
        }
    }

    #[test]
    fn learns_to_avoid_the_obstacle() {
        // Optimistic weights (1/(1 − γ)): with positive rewards and w₀ = 0 the first
        // visited states look best and the soft-max never leaves them.
        let config = LearnerConfig {
            rbf: RbfConfig {
                centres_per_dim: 11,
                ..RbfConfig::default()
            },
            td: TdConfig {
                alpha: 0.5,
                initial_weight: 20.0,
                ..TdConfig::default()
            },
            step_fraction: 0.5,
            max_steps: 60,
            ..LearnerConfig::default()
        };
        let mut l = Learner::new(&config, &[0.0], &[1.0], &orthogonal_actions(1)).unwrap();
        let mut plant = Corridor { x: 0.0 };
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let mut s = l.scratch(&StateSpace::Full, 1);
        let records: Vec<EpisodeRecord> = (0..600)
            .map(|_| {
                l.run_episode(&mut plant, &StateSpace::Full, &mut rng, &mut s, None)
                    .unwrap()
            })
            .collect();
        let stats = |r: &[EpisodeRecord]| {
            let mean = r.iter().map(|e| e.ret).sum::<f64>() / r.len() as f64;
            let hits = r.iter().filter(|e| e.end == EndReason::Obstacle).count();
            (mean, hits)
        };
        let (first, first_hits) = stats(&records[..100]);
        let (last, last_hits) = stats(&records[500..]);
        assert!(last > 1.1 * first, "mean return: first {first}, last {last}");
        assert!(
            last_hits < first_hits,
            "obstacle endings: first {first_hits}, last {last_hits}"
        );
    }

    #[test]
    fn frozen_learner_keeps_its_weights_and_filters_test_starts() {
        let config = LearnerConfig {
            rbf: RbfConfig {
                centres_per_dim: 11,
                ..RbfConfig::default()
            },
            step_fraction: 1.0,
            max_steps: 30,
            start: StartMode::UniformInBox,
            ..LearnerConfig::default()
        };
        let mut l = Learner::new(&config, &[0.0], &[1.0], &orthogonal_actions(1)).unwrap();
        let mut plant = Corridor { x: 0.0 };
        let mut rng = ChaCha8Rng::seed_from_u64(9);
        let mut s = l.scratch(&StateSpace::Full, 1);
        let mut starts_above = 0;
        for _ in 0..300 {
            let mut traj = Vec::new();
            l.run_episode(&mut plant, &StateSpace::Full, &mut rng, &mut s, Some(&mut traj))
                .unwrap();
            starts_above += usize::from(traj[0] >= 0.3);
        }
        assert!(starts_above > 0, "training starts are not filtered");
        let trained = l.weights().to_vec();
        assert!(trained.iter().any(|&w| w != 0.0));
        l.set_phase(Phase::Test);
        assert_eq!(l.phase(), Phase::Test);
        let mut passes = 0;
        for _ in 0..40 {
            let mut traj = Vec::new();
            let rec = l
                .run_episode(&mut plant, &StateSpace::Full, &mut rng, &mut s, Some(&mut traj))
                .unwrap();
            assert!(traj[0] < 0.3, "test start {} not admitted by the plant", traj[0]);
            assert_eq!(rec.passed, traj[1..].iter().any(|&x| x > 0.7));
            passes += usize::from(rec.passed);
        }
        assert!(passes > 0);
        assert_eq!(l.weights(), &trained[..], "a frozen learner changed its weights");
    }

    #[test]
    fn end_codes_round_trip() {
        for code in 0..6u8 {
            assert_eq!(EndReason::from_code(code).unwrap().code(), code);
        }
        assert!(EndReason::from_code(6).is_none());
    }

    #[test]
    fn mismatched_spaces_are_errors() {
        let l = learner(10);
        assert!(l.check_space(&StateSpace::Full, 1).is_ok());
        assert!(matches!(
            l.check_space(&StateSpace::Full, 4),
            Err(CoreError::Shape { .. })
        ));
        let bad = LearnerConfig {
            max_steps: 0,
            ..LearnerConfig::default()
        };
        assert!(Learner::new(&bad, &[0.0], &[1.0], &[1.0, -1.0]).is_err());
        let bad = LearnerConfig {
            variance_threshold: Some(-1.0),
            ..LearnerConfig::default()
        };
        assert!(Learner::new(&bad, &[0.0], &[1.0], &[1.0, -1.0]).is_err());
    }
}
