//! The episode loop of RL in latent space (paper Sec. III-E, Fig. 3; docs/method.md §RL loop),
//! entirely in Rust. One step from state `z_t`:
//!
//! 1. look-ahead `Q(z_t, u_i) = V(z_t + Δ_i)` (Eq. 11) and a soft-max draw (Eq. 10);
//! 2. `z' = z_t + Δ_a`; outside the learner's box ⇒ penalty, terminal, no plant call
//!    ([`EndReason::BoxExit`]);
//! 3. decode `x̂ = μ(z')`; with variance gating on (docs/method.md §Variance gating, off by
//!    default) a variance above the threshold ⇒ penalty, terminal, no plant call
//!    ([`EndReason::VarianceGate`]);
//! 4. the plant tracks `x̂` for one RL step and reports the reached posture `x̃`, the reward
//!    (its own penalty included) and whether the episode ended;
//! 5. encode `z_{t+1} = g(x̃)`;
//! 6. TD(0) on `(z_t, r_t, z_{t+1})` (Eq. 7–9), terminal if the plant ended the episode
//!    (skipped in [`Phase::Test`] and [`Phase::Rollout`]: they act on the learnt V unchanged;
//!    a rollout takes its action by its [`ActionRule`] in step 1).
//!
//! Steps 2–5 are [`transition`], which an environment stepping a latent point by any delta
//! (Gymnasium's latent-space wrapper) shares. Reaching `max_steps` is a time-out, not a
//! terminal state: the last update bootstraps; so does a plant's success
//! ([`EndReason::is_terminal`]).

use std::sync::atomic::{AtomicBool, Ordering};

use rand::{Rng, RngExt};

use crate::error::{CoreError, Result};
use crate::learner::{ActionRule, Learner, StartMode, greedy};
use crate::plant::{EndReason, Plant};
use crate::rbf::{RbfScratch, SparseFeatures};
use crate::space::{SpaceScratch, StateSpace};

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

/// Result of one [`Learner::step`] or [`transition`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StepResult {
    /// Reward of this transition, penalty included.
    pub reward: f64,
    /// `Some(reason)` if the episode ended (terminal transition).
    pub end: Option<EndReason>,
    /// True if the plant was called (false for box exits and gated targets).
    pub moved: bool,
}

/// The latent box, the gate and the penalty of [`transition`].
#[derive(Debug, Clone, Copy)]
pub struct Bounds<'a> {
    /// Lower corner of the learner's box.
    pub low: &'a [f64],
    /// Upper corner of the learner's box.
    pub high: &'a [f64],
    /// Variance gating threshold (docs/method.md §Variance gating), `None` for off.
    pub variance_threshold: Option<f64>,
    /// Penalty of a box exit or a gated target.
    pub penalty: f64,
}

/// Buffers of one state space and plant for [`transition`]: nothing is allocated per step.
#[derive(Debug, Clone)]
pub struct TransitionScratch {
    /// The decoded target posture `x̂`.
    pub target: Vec<f64>,
    /// The reached posture `x̃`.
    pub reached: Vec<f64>,
    /// The encoded next state `z_{t+1}`.
    pub next: Vec<f64>,
    maps: SpaceScratch,
}

impl TransitionScratch {
    /// Buffers for `space` (learner dimension `dim`) and a plant of `posture_dim` coordinates.
    pub fn new(space: &StateSpace<'_>, dim: usize, posture_dim: usize) -> Self {
        Self {
            target: vec![0.0; posture_dim],
            reached: vec![0.0; posture_dim],
            next: vec![0.0; dim],
            maps: space.scratch(),
        }
    }
}

/// Steps 2 and 3's refusals of a latent target: outside the box ([`EndReason::BoxExit`]), or —
/// with gating on and the target's decoded variance given — above the threshold
/// ([`EndReason::VarianceGate`]). `None`: the plant may track it.
pub fn refused(z_target: &[f64], bounds: &Bounds<'_>, variance: Option<f64>) -> Option<EndReason> {
    let inside = z_target
        .iter()
        .zip(bounds.low)
        .zip(bounds.high)
        .all(|((x, lo), hi)| x >= lo && x <= hi);
    if !inside {
        return Some(EndReason::BoxExit);
    }
    match (bounds.variance_threshold, variance) {
        (Some(t), Some(v)) if v > t => Some(EndReason::VarianceGate),
        _ => None,
    }
}

/// [`refused`] for a caller's arrays: `z` inside `[low, high]` (one length each), and with
/// `variance` and `threshold` given, the variance gate.
pub fn refusal(
    z: &[f64],
    low: &[f64],
    high: &[f64],
    variance: Option<f64>,
    threshold: Option<f64>,
) -> crate::Result<Option<EndReason>> {
    if z.len() != low.len() || high.len() != low.len() {
        return Err(crate::CoreError::Argument(format!(
            "z, low, high: expected one length, got {}, {}, {}",
            z.len(),
            low.len(),
            high.len()
        )));
    }
    let bounds = Bounds {
        low,
        high,
        variance_threshold: threshold,
        penalty: 0.0,
    };
    Ok(refused(z, &bounds, variance))
}

/// Steps 2–5 of the module docs towards the latent target `z_target`: box check, decode (and
/// gate), one plant step, and — unless the plant ended the episode in a terminal state —
/// encode the reached posture into `s.next`.
#[inline]
pub fn transition<P: Plant>(
    plant: &mut P,
    space: &StateSpace<'_>,
    bounds: &Bounds<'_>,
    z_target: &[f64],
    s: &mut TransitionScratch,
) -> StepResult {
    let refusal = |end| StepResult {
        reward: bounds.penalty,
        end: Some(end),
        moved: false,
    };
    if let Some(end) = refused(z_target, bounds, None) {
        return refusal(end);
    }
    let gated = bounds.variance_threshold.is_some();
    let var = space.decode(z_target, &mut s.target, &mut s.maps, gated);
    if let Some(end) = refused(z_target, bounds, space.is_latent().then_some(var)) {
        return refusal(end);
    }
    let outcome = plant.step(&s.target, &mut s.reached);
    if outcome.end.is_none_or(|e| !e.is_terminal()) {
        space.encode_near(&s.reached, z_target, &mut s.next, &mut s.maps);
    }
    StepResult {
        reward: outcome.reward,
        end: outcome.end,
        moved: true,
    }
}

/// Buffers for one trial's episodes: nothing is allocated per step.
#[derive(Debug, Clone)]
pub struct EpisodeScratch {
    z: Vec<f64>,
    mean_z: Vec<f64>,
    candidate: Vec<f64>,
    q: Vec<f64>,
    q_buffer: Vec<f64>,
    current: SparseFeatures,
    next: SparseFeatures,
    rbf: RbfScratch,
    step: TransitionScratch,
}

impl EpisodeScratch {
    /// The learner's current state `z_t`.
    pub fn state(&self) -> &[f64] {
        &self.z
    }

    /// The mean of the learner's state over the last episode: its start and every state a
    /// non-terminal step reached (where in the state space the episode went).
    pub fn mean_state(&self) -> &[f64] {
        &self.mean_z
    }

    /// The last posture the plant reached (or was reset to).
    pub fn posture(&self) -> &[f64] {
        &self.step.reached
    }
}

impl Learner {
    /// Buffers for episodes in `space` on a plant with `posture_dim` coordinates.
    pub fn scratch(&self, space: &StateSpace<'_>, posture_dim: usize) -> EpisodeScratch {
        let dim = self.grid.dim();
        EpisodeScratch {
            z: vec![0.0; dim],
            mean_z: vec![0.0; dim],
            candidate: vec![0.0; dim],
            q: vec![0.0; self.n_actions],
            q_buffer: vec![0.0; self.n_actions],
            current: self.grid.features(),
            next: self.grid.features(),
            rbf: self.grid.scratch(),
            step: TransitionScratch::new(space, dim, posture_dim),
        }
    }

    /// The box, gate and penalty of this learner's transitions.
    pub fn bounds(&self) -> Bounds<'_> {
        Bounds {
            low: self.grid.low(),
            high: self.grid.high(),
            variance_threshold: self.config.variance_threshold,
            penalty: self.rules.penalty,
        }
    }

    /// TD(0) update (Eq. 7–9) of the features `b` after `action`, whose look-ahead was `q`,
    /// and of that action's move correction if learnt, unless the learner is frozen.
    #[inline]
    fn learn(&mut self, b: &SparseFeatures, action: usize, q: f64, reward: f64, v_next: Option<f64>) {
        if self.phase.learns() {
            let target = reward + self.td.gamma() * v_next.unwrap_or(0.0);
            self.td.update(b, reward, v_next);
            self.td.correct(b, action, target - q);
        }
    }

    /// Starts an episode (see [`StartMode`]): resets the plant and sets `z_0` and `b(z_0)`.
    /// In [`Phase::Test`] (and a rollout from test starts) a start must also pass
    /// [`Plant::admits_test_start`].
    pub fn start<P: Plant, R: Rng + ?Sized>(
        &self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        s: &mut EpisodeScratch,
    ) -> Result<()> {
        self.start_unless(plant, space, rng, s, &NEVER)
    }

    /// [`Self::start`], giving up with [`CoreError::Cancelled`] once `cancel` is set (read
    /// before every draw: `max_start_draws` may be 10⁹).
    pub(crate) fn start_unless<P: Plant, R: Rng + ?Sized>(
        &self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        s: &mut EpisodeScratch,
        cancel: &AtomicBool,
    ) -> Result<()> {
        let draws = self.rules.max_start_draws;
        let gate = self.config.variance_threshold;
        let mut admitted = false;
        for _ in 0..draws {
            if cancel.load(Ordering::Relaxed) {
                return Err(CoreError::Cancelled);
            }
            let t = &mut s.step;
            match self.rules.start {
                StartMode::Plant => {
                    plant.sample_start(rng, &mut t.reached);
                    if plant.reset(&t.reached).is_none() {
                        space.encode(&t.reached, &mut s.z, &mut t.maps);
                        admitted = true;
                    }
                }
                StartMode::Uniform => {
                    for (k, z) in s.z.iter_mut().enumerate() {
                        *z = rng.random_range(self.grid.low()[k]..=self.grid.high()[k]);
                    }
                    let var = space.decode(&s.z, &mut t.reached, &mut t.maps, gate.is_some());
                    let gated = space.is_latent() && gate.is_some_and(|g| var > g);
                    admitted = !gated && plant.reset(&t.reached).is_none();
                }
            }
            if admitted && (!self.phase.test_starts() || plant.admits_test_start()) {
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
        self.look_ahead(&s.z, &s.current, &mut s.candidate, &mut s.q, &mut s.rbf);
        let a = match self.phase.action() {
            ActionRule::Greedy => greedy(&s.q),
            ActionRule::SoftMax => self.policy.sample(&s.q, &mut s.q_buffer, rng),
            ActionRule::Random => rng.random_range(0..self.n_actions),
        };
        // 2.–5. z' = z + Δ_a, box, decode, plant, encode.
        shifted(&s.z, &self.displacements[a * dim..(a + 1) * dim], &mut s.candidate);
        let result = transition(plant, space, &self.bounds(), &s.candidate, &mut s.step);
        let q = s.q[a];
        if result.end.is_some_and(EndReason::is_terminal) {
            self.learn(&s.current, a, q, result.reward, None);
            return result;
        }
        // 6. TD(0) with bootstrap (also from a success, which ends the episode).
        self.grid.eval_into(&s.step.next, &mut s.rbf, &mut s.next);
        let v_next = self.td.value(&s.next);
        self.learn(&s.current, a, q, result.reward, Some(v_next));
        std::mem::swap(&mut s.current, &mut s.next);
        std::mem::swap(&mut s.z, &mut s.step.next);
        result
    }

    /// Runs one episode: [`Self::start`], then [`Self::step`] until a terminal transition
    /// or `max_steps`. If `trajectory` is given, the plant's task-space row after the reset
    /// and after every plant step is appended to it (`task_dim()` values per row).
    pub fn run_episode<P: Plant, R: Rng + ?Sized>(
        &mut self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        s: &mut EpisodeScratch,
        trajectory: Option<&mut Vec<f64>>,
    ) -> Result<EpisodeRecord> {
        self.run_episode_with(plant, space, rng, None::<&mut R>, s, trajectory, &NEVER)
    }

    /// [`Self::run_episode`] with the start drawn from `rng` and, if given, the actions from
    /// `actions` (a rollout: so policies that draw differently meet the same starts). Once
    /// `cancel` is set (read before every start draw and every step) it stops with
    /// [`CoreError::Cancelled`], the learner holding the updates of the steps it ran.
    #[allow(clippy::too_many_arguments)]
    pub fn run_episode_with<P: Plant, R: Rng + ?Sized, A: Rng + ?Sized>(
        &mut self,
        plant: &mut P,
        space: &StateSpace<'_>,
        rng: &mut R,
        mut actions: Option<&mut A>,
        s: &mut EpisodeScratch,
        mut trajectory: Option<&mut Vec<f64>>,
        cancel: &AtomicBool,
    ) -> Result<EpisodeRecord> {
        self.start_unless(plant, space, rng, s, cancel)?;
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
        s.mean_z.copy_from_slice(&s.z);
        let mut states = 1.0;
        while record.steps < self.rules.max_steps {
            if cancel.load(Ordering::Relaxed) {
                return Err(CoreError::Cancelled);
            }
            let r = match actions.as_deref_mut() {
                Some(a) => self.step(plant, space, a, s),
                None => self.step(plant, space, rng, s),
            };
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
            s.mean_z.iter_mut().zip(&s.z).for_each(|(m, z)| *m += z);
            states += 1.0;
        }
        s.mean_z.iter_mut().for_each(|m| *m /= states);
        Ok(record)
    }
}

/// A cancel flag nobody sets.
static NEVER: AtomicBool = AtomicBool::new(false);

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
    use crate::config::LearnerConfig;
    use crate::learner::{EpisodeRules, Phase};
    use crate::plant::StepOutcome;
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

    fn rules(max_steps: usize, start: StartMode) -> EpisodeRules {
        EpisodeRules {
            max_steps,
            start,
            ..EpisodeRules::default()
        }
    }

    fn learner(max_steps: usize) -> Learner {
        let config = LearnerConfig {
            rbf_per_dim: 11,
            step: 1.0,
            ..LearnerConfig::default()
        };
        Learner::new(&config, rules(max_steps, StartMode::Plant), &[0.0], &[1.0]).unwrap()
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
            rbf_per_dim: 11,
            alpha: 0.5,
            initial_weight: 20.0,
            step: 0.5,
            ..LearnerConfig::default()
        };
        let mut l = Learner::new(&config, rules(60, StartMode::Plant), &[0.0], &[1.0]).unwrap();
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

    /// [`Corridor`] with a thin wall at 0.5 instead: a move that crosses it ends on it
    /// (reward −1), whatever its target; starts just left of it or at 0.7, right of it.
    struct Wall {
        x: f64,
    }

    impl Plant for Wall {
        fn posture_dim(&self) -> usize {
            1
        }
        fn task_dim(&self) -> usize {
            1
        }
        fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
            posture[0] = if rng.random_bool(0.5) { 0.49 } else { 0.7 };
        }
        fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
            self.x = posture[0];
            None
        }
        fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
            let crossed = (self.x < 0.5) != (target[0] < 0.5);
            self.x = target[0];
            reached[0] = self.x;
            StepOutcome {
                reward: if crossed { -1.0 } else { self.x },
                end: crossed.then_some(EndReason::Obstacle),
            }
        }
        fn task_position(&self, out: &mut [f64]) {
            out[0] = self.x;
        }
    }

    #[test]
    fn move_corrections_learn_a_move_that_v_cannot() {
        // Beyond the wall V learns the larger rewards from the starts there, so V alone keeps
        // looking right from 0.49; the correction of "right" learns that the move ends on the
        // wall.
        let hits = |move_correction: bool| {
            let config = LearnerConfig {
                rbf_per_dim: 11,
                alpha: 0.5,
                step: 0.2,
                move_correction,
                ..LearnerConfig::default()
            };
            let mut l = Learner::new(&config, rules(20, StartMode::Plant), &[0.0], &[1.0]).unwrap();
            assert_eq!(l.weights().len(), if move_correction { 3 * 11 } else { 11 });
            let mut plant = Wall { x: 0.0 };
            let mut rng = ChaCha8Rng::seed_from_u64(3);
            let mut s = l.scratch(&StateSpace::Full, 1);
            let ends: Vec<EndReason> = (0..300)
                .map(|_| {
                    l.run_episode(&mut plant, &StateSpace::Full, &mut rng, &mut s, None)
                        .unwrap()
                        .end
                })
                .collect();
            let greedy = l.greedy_target(&[0.49]).unwrap()[0];
            (
                ends[200..].iter().filter(|&&e| e == EndReason::Obstacle).count(),
                greedy,
            )
        };
        let (plain, plain_greedy) = hits(false);
        let (corrected, corrected_greedy) = hits(true);
        assert!(
            plain > 30 && plain_greedy > 0.5,
            "V alone: {plain} hits, greedy to {plain_greedy}"
        );
        assert!(
            corrected < 5 && corrected_greedy < 0.49,
            "with corrections: {corrected} hits, greedy to {corrected_greedy}"
        );
    }

    /// A 1-D line from 0.3: reward 0.1 per step below 0.8, 1 at or above it, where the
    /// episode ends as `end`.
    struct Goal {
        x: f64,
        end: EndReason,
    }

    impl Plant for Goal {
        fn posture_dim(&self) -> usize {
            1
        }
        fn task_dim(&self) -> usize {
            1
        }
        fn sample_start<R: Rng + ?Sized>(&mut self, _rng: &mut R, posture: &mut [f64]) {
            posture[0] = 0.3;
        }
        fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
            self.x = posture[0];
            None
        }
        fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
            self.x = target[0];
            reached[0] = self.x;
            let at_goal = self.x >= 0.8;
            StepOutcome {
                reward: if at_goal { 1.0 } else { 0.1 },
                end: at_goal.then_some(self.end),
            }
        }
        fn task_position(&self, out: &mut [f64]) {
            out[0] = self.x;
        }
    }

    #[test]
    fn a_success_bootstraps_so_the_learner_seeks_it() {
        // Ended as a terminal state the goal is worth its one reward (1) against 0.1 / (1 − γ)
        // = 2 for staying away, so the learner learns to avoid it; a success bootstraps
        // (optimistic w₀ = 1 / (1 − γ) for exploration, as in the quick presets). Measured:
        // 100 of the last 100 episodes end at the goal as a success, 1 as a terminal end.
        let goals = |end| {
            let config = LearnerConfig {
                rbf_per_dim: 11,
                alpha: 0.5,
                step: 1.0,
                initial_weight: 20.0,
                ..LearnerConfig::default()
            };
            let mut l = Learner::new(&config, rules(40, StartMode::Plant), &[0.0], &[1.0]).unwrap();
            let mut plant = Goal { x: 0.0, end };
            let mut rng = ChaCha8Rng::seed_from_u64(2);
            let mut s = l.scratch(&StateSpace::Full, 1);
            let ends: Vec<EndReason> = (0..400)
                .map(|_| {
                    l.run_episode(&mut plant, &StateSpace::Full, &mut rng, &mut s, None)
                        .unwrap()
                        .end
                })
                .collect();
            ends[300..].iter().filter(|&&e| e == end).count()
        };
        let (success, terminal) = (goals(EndReason::Success), goals(EndReason::Obstacle));
        assert!(
            success > 80 && terminal < 50,
            "goal reached in the last 100 episodes: {success} as a success, {terminal} as a terminal end"
        );
    }

    #[test]
    fn frozen_learner_keeps_its_weights_and_filters_test_starts() {
        let config = LearnerConfig {
            rbf_per_dim: 11,
            step: 1.0,
            ..LearnerConfig::default()
        };
        let mut l = Learner::new(&config, rules(30, StartMode::Uniform), &[0.0], &[1.0]).unwrap();
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
            // The mean state: over the start and every non-terminal step's state (the full
            // space's state is the reached x, the recorded row).
            let states = 1 + rec.steps - usize::from(rec.end != EndReason::TimeOut);
            let mean = traj[..states].iter().sum::<f64>() / states as f64;
            assert!(
                (s.mean_state()[0] - mean).abs() < 1e-12,
                "{:?} vs {mean}",
                s.mean_state()
            );
            passes += usize::from(rec.passed);
        }
        assert!(passes > 0);
        assert_eq!(l.weights(), &trained[..], "a frozen learner changed its weights");
    }

    #[test]
    fn values_are_the_look_ahead_values() {
        let mut l = learner(10);
        let weights: Vec<f64> = (0..11).map(|i| i as f64).collect();
        l.set_weights(&weights).unwrap();
        let mut scratch = l.grid().scratch();
        let v = l.values(&[0.0, 0.35, 1.0]).unwrap();
        for (z, v) in [0.0, 0.35, 1.0].iter().zip(&v) {
            assert_eq!(*v, l.grid().value(&weights, &[*z], &mut scratch));
        }
        assert!(l.values(&[f64::NAN]).is_err());
        assert!(l.set_weights(&[1.0]).is_err());
    }

    /// A decoder folded onto itself (z and −z decode to the same posture z²): after a move to
    /// 0.6 the plain projection starts from the first nearest demo (−0.6), the tracking one keeps
    /// the commanded point.
    #[test]
    fn a_tracking_encoder_keeps_the_commanded_point() {
        use crate::{GpMap, Projection, ProjectionConfig, SeKernel};
        use nalgebra::DMatrix;
        let latent = DMatrix::from_fn(1, 21, |_, j| -1.0 + 0.1 * j as f64);
        let postures = latent.map(|z| z * z);
        let decoder = GpMap::new(latent, postures.clone(), SeKernel::new([1.0, 0.1, 1e-6]).unwrap()).unwrap();
        let tracking = ProjectionConfig {
            tracking: true,
            ..ProjectionConfig::default()
        };
        let encoder = Projection::new(&decoder, postures, tracking).unwrap();
        let space = StateSpace::Latent {
            decoder: &decoder,
            encoder: &encoder,
        };
        let bounds = Bounds {
            low: &[-1.0],
            high: &[1.0],
            variance_threshold: None,
            penalty: -1.0,
        };
        let mut plant = Corridor { x: 0.0 };
        let mut s = TransitionScratch::new(&space, 1, 1);
        for z in [0.6, -0.6, 0.25] {
            let step = transition(&mut plant, &space, &bounds, &[z], &mut s);
            assert!(step.moved && step.end.is_none());
            assert!((s.next[0] - z).abs() < 1e-6, "commanded {z}, encoded {}", s.next[0]);
        }
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
            variance_threshold: Some(-1.0),
            ..LearnerConfig::default()
        };
        assert!(Learner::new(&bad, EpisodeRules::default(), &[0.0], &[1.0]).is_err());
    }
}
