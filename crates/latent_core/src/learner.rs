//! The TD(0) learner of RL in a latent space (paper Sec. III-D/E; docs/method.md §TD(0)): an RBF
//! grid over the state box, the value weights, the soft-max policy and the scaled action set.
//!
//! The step displacement is `Δ_i = step · h ⊙ u_i`: each action's unit direction `u_i`
//! scaled per dimension by the RBF grid spacing `h` (ours: 0.2 × spacing, docs/method.md §Policy).

use crate::config::LearnerConfig;
use crate::error::Result;
use crate::params::Params;
use crate::policy::{SoftmaxPolicy, check_actions};
use crate::rbf::{RbfConfig, RbfGrid, RbfScratch, SparseFeatures};
use crate::space::StateSpace;
use crate::td::TdLearner;

/// Where an episode starts.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum StartMode {
    /// The plant draws a posture ([`crate::Plant::sample_start`]); the learner encodes it.
    #[default]
    Plant,
    /// Uniform over the learner's box, decoded; redrawn while the plant refuses the decoded
    /// posture (or variance gating does). The latent state is the drawn point.
    Uniform,
}

/// How the episodes of a learner run. A task's configuration holds these values and their
/// rules; `Default` is the paper's Experiment 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EpisodeRules {
    /// Steps per episode before a time-out (paper Exp. 1: 500).
    pub max_steps: usize,
    /// Penalty R_p of a box exit or a gated target, as of the plant's endings (paper: −1).
    pub penalty: f64,
    /// Where episodes start.
    pub start: StartMode,
    /// Draws allowed to find an admissible start before [`crate::CoreError::NoValidStart`].
    pub max_start_draws: usize,
    /// Stop a training trial once it has stopped improving ([`crate::stopping`]); `None`: run
    /// every episode (the paper's).
    pub stop: Option<crate::StopRule>,
}

impl Default for EpisodeRules {
    fn default() -> Self {
        Self {
            max_steps: 500,
            penalty: -1.0,
            start: StartMode::Plant,
            max_start_draws: 1000,
            stop: None,
        }
    }
}

crate::choice! {
    /// How a frozen learner picks each action.
    pub enum ActionRule {
        /// The action of the largest look-ahead value, the first of equals.
        Greedy = "greedy",
        /// A draw from the soft-max on the look-ahead values (Eq. 10), as in training.
        SoftMax = "softmax",
        /// One of the actions uniformly at random, whatever the weights: a control that cannot
        /// learn by construction (the untrained learner's soft-max is the same draw only where
        /// V is flat, and a greedy one on near-equal weights resolves rounding noise).
        Random = "random",
    }
}

/// Whether a learner is training, running frozen test episodes, or rolling out its policy.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Phase {
    /// TD(0) updates after every step (Eq. 7–9); soft-max actions (Eq. 10).
    #[default]
    Train,
    /// No updates: the soft-max policy acts on the learnt value function as it is, and
    /// starts must also pass [`crate::Plant::admits_test_start`] (Experiment 2's frozen tests,
    /// docs/method.md §Experiment 2).
    Test,
    /// No updates, actions by `action`; starts as the frozen tests' (`test_starts`) or as
    /// training's. What a saved policy does when it is run, and its control.
    Rollout {
        /// How each action is chosen.
        action: ActionRule,
        /// Whether starts must also pass [`crate::Plant::admits_test_start`].
        test_starts: bool,
    },
}

impl Phase {
    /// Whether TD(0) updates the weights.
    pub fn learns(self) -> bool {
        self == Phase::Train
    }

    /// Whether a start must also pass [`crate::Plant::admits_test_start`].
    pub fn test_starts(self) -> bool {
        matches!(self, Phase::Test | Phase::Rollout { test_starts: true, .. })
    }

    /// How actions are chosen.
    pub fn action(self) -> ActionRule {
        match self {
            Phase::Train | Phase::Test => ActionRule::SoftMax,
            Phase::Rollout { action, .. } => action,
        }
    }
}

/// A TD(0) learner with its RBF grid, soft-max policy and scaled action set.
#[derive(Debug, Clone)]
pub struct Learner {
    pub(crate) grid: RbfGrid,
    pub(crate) td: TdLearner,
    pub(crate) policy: SoftmaxPolicy,
    pub(crate) displacements: Vec<f64>,
    pub(crate) n_actions: usize,
    pub(crate) config: LearnerConfig,
    pub(crate) rules: EpisodeRules,
    pub(crate) phase: Phase,
}

impl Learner {
    /// A learner over the box `[low, high]` with the actions of `config.actions`; validates
    /// `config` (its one rule set).
    pub fn new(config: &LearnerConfig, rules: EpisodeRules, low: &[f64], high: &[f64]) -> Result<Self> {
        let actions = config.actions.directions(low.len());
        Self::with_actions(config, rules, low, high, &actions)
    }

    /// [`Learner::new`] with the unit action directions given (a flat `n_actions × dim`
    /// array, e.g. Experiment 1's 12 full-space actions); `config.actions` is not used.
    pub fn with_actions(
        config: &LearnerConfig,
        rules: EpisodeRules,
        low: &[f64],
        high: &[f64],
        actions: &[f64],
    ) -> Result<Self> {
        config.validate()?;
        let rbf = RbfConfig {
            centres_per_dim: config.rbf_per_dim,
            width: config.rbf_width,
            cutoff: config.rbf_cutoff,
        };
        let grid = RbfGrid::new(low, high, &rbf)?;
        let dim = grid.dim();
        let n_actions = check_actions(actions, dim)?;
        let displacements = actions
            .chunks_exact(dim)
            .flat_map(|u| u.iter().zip(grid.spacing()).map(|(u, h)| config.step * h * u))
            .collect();
        let corrections = if config.move_correction { n_actions } else { 0 };
        let td = TdLearner::new(
            grid.len(),
            corrections,
            config.alpha,
            config.gamma,
            config.initial_weight,
        )?;
        let policy = SoftmaxPolicy::new(config.beta)?;
        Ok(Self {
            grid,
            td,
            policy,
            displacements,
            n_actions,
            config: config.clone(),
            rules,
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

    /// The RBF grid.
    pub fn grid(&self) -> &RbfGrid {
        &self.grid
    }

    /// The value-function weights `w`, then the move corrections' blocks if any.
    pub fn weights(&self) -> &[f64] {
        self.td.weights()
    }

    /// Replaces the weights (e.g. those of a saved policy); `weights.len()` must be the grid's.
    pub fn set_weights(&mut self, weights: &[f64]) -> Result<()> {
        self.td.set_weights(weights)
    }

    /// Consumes the learner, returning `w`.
    pub fn into_weights(self) -> Vec<f64> {
        self.td.into_weights()
    }

    /// Its configuration.
    pub fn config(&self) -> &LearnerConfig {
        &self.config
    }

    /// How its episodes run.
    pub fn rules(&self) -> &EpisodeRules {
        &self.rules
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
        space.check(self.grid.dim(), posture_dim)
    }

    /// The look-ahead values `Q(z, u_i) = V(z + Δ_i)` (Eq. 11), plus the move corrections
    /// `C_i(z)` if learnt, into `q`, one per action; `b_z` are the features of `z` and
    /// `candidate` is a `dim`-long buffer.
    #[inline]
    pub(crate) fn look_ahead(
        &self,
        z: &[f64],
        b_z: &SparseFeatures,
        candidate: &mut [f64],
        q: &mut [f64],
        rbf: &mut RbfScratch,
    ) {
        let dim = self.grid.dim();
        for (a, (q, d)) in q.iter_mut().zip(self.displacements.chunks_exact(dim)).enumerate() {
            for ((c, z), d) in candidate.iter_mut().zip(z).zip(d) {
                *c = z + d;
            }
            *q = self.grid.value(self.td.value_weights(), candidate, rbf) + self.td.correction(b_z, a);
        }
    }

    /// The greedy policy's next latent target from `z`: `z + Δ_a` for the action `a` of the
    /// largest look-ahead value (the first of equals), clamped into the box.
    pub fn greedy_target(&self, z: &[f64]) -> Result<Vec<f64>> {
        self.grid.check_point("latent state", z)?;
        let dim = self.grid.dim();
        let mut q = vec![0.0; self.n_actions];
        let mut target = vec![0.0; dim];
        let mut rbf = self.grid.scratch();
        let mut b_z = self.grid.features();
        self.grid.eval_into(z, &mut rbf, &mut b_z);
        self.look_ahead(z, &b_z, &mut target, &mut q, &mut rbf);
        let a = greedy(&q);
        for (k, t) in target.iter_mut().enumerate() {
            *t = (z[k] + self.displacements[a * dim + k]).clamp(self.grid.low()[k], self.grid.high()[k]);
        }
        Ok(target)
    }

    /// `V(z) = wᵀ b(z)` (Eq. 7) at each row of `points` (flat, `dim` values per row), with the
    /// learner's own sparse features: what the policy looks ahead with.
    pub fn values(&self, points: &[f64]) -> Result<Vec<f64>> {
        let dim = self.grid.dim();
        let mut scratch: RbfScratch = self.grid.scratch();
        points
            .chunks(dim)
            .map(|z| {
                self.grid.check_point("latent point", z)?;
                Ok(self.grid.value(self.td.value_weights(), z, &mut scratch))
            })
            .collect()
    }
}

/// The index of the largest value, the first of equals.
#[inline]
pub(crate) fn greedy(q: &[f64]) -> usize {
    let mut best = 0;
    for (i, &v) in q.iter().enumerate() {
        if v > q[best] {
            best = i;
        }
    }
    best
}
