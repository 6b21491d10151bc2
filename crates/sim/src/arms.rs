//! Experiment 2 (SPEC §4.2, paper Sec. IV-B, Fig. 6): two planar 2-link arms holding an
//! object, simulated with rapier3d ([`PhysicsSim`]) and PD servos, as a [`Plant`] for RL in
//! a GPLVM latent space; and the runner for its trials.
//!
//! One plant step (SPEC §3.1 step 4–5): the decoded posture becomes the servo targets
//! (clamped to the joint limits), the world advances one RL step (`substeps × dt`, 0.05 s),
//! the joint positions are read back (the sensor reading, i.e. the **reached** posture),
//! and the hand positions come from the sim's hand frames (`left_hand`, `right_hand`).
//! Then, on the reached hands `h = (x_L, y_L, x_R, y_R)`:
//!
//! - reward `exp(−θ ‖(h − h*)/ℓ‖²)` (Eq. 12 with a length unit ℓ, SPEC §4.2 table);
//! - a hand inside a corridor wall ⇒ reward + penalty, [`EndReason::Obstacle`];
//! - `‖(h_R − h_L) − grip‖ > drop_tolerance` ⇒ reward + penalty, [`EndReason::Drop`].
//!
//! **The walls are tested on the hand positions only** (points in the arm plane, SPEC §4.2:
//! "the links must cross the wall band"): they are not bodies in the physics world, so
//! neither links nor hands collide with them; a hand counts as touching a wall when it lies
//! in the closed rectangle. The same tests refuse a start ([`Plant::reset`]), as does a
//! posture outside the joint limits ([`EndReason::BoxExit`]).
//!
//! "Passed" ([`Plant::passed`]): both hands below the wall band (`y <` the lowest wall
//! bottom) at the reset and both above it (`y >` the highest wall top) after some step.
//! Frozen test episodes start only below the band ([`Plant::admits_test_start`]).

use latent_core::episode::{EndReason, LearnerConfig, Plant, StartMode, StepOutcome};
use latent_core::error::CoreError;
use latent_core::td::TdConfig;
use rand::Rng;

use crate::error::{Result, SimError, check_finite};
use crate::latent::Latent2d;
use crate::plant::{Frame, PhysicsSim, SimOptions};
use crate::urdf::UrdfModel;

/// An axis-aligned rectangle in the arm plane (metres) that neither hand may enter.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wall {
    /// Lower-left corner `(x_min, y_min)`.
    pub low: [f64; 2],
    /// Upper-right corner `(x_max, y_max)`.
    pub high: [f64; 2],
}

impl Wall {
    /// Whether the point `(x, y)` lies in the closed rectangle.
    pub fn contains(&self, x: f64, y: f64) -> bool {
        (self.low[0]..=self.high[0]).contains(&x) && (self.low[1]..=self.high[1]).contains(&y)
    }
}

/// Everything about the Experiment 2 plant; `Default` is the SPEC §4.2 setup table.
#[derive(Debug, Clone, PartialEq)]
pub struct ArmsConfig {
    /// Target hands `h* = (x_L, y_L, x_R, y_R)` (SPEC: left (−0.05, 0.47), right (0.05, 0.47)).
    pub target: [f64; 4],
    /// θ of the reward `exp(−θ ‖(h − h*)/ℓ‖²)` (paper: 0.35).
    pub theta: f64,
    /// Length unit ℓ of the reward (SPEC: 0.3 m; with distances in metres θ = 0.35 would make
    /// the reward 0.8–1.0 everywhere).
    pub length_scale: f64,
    /// The corridor: walls neither hand may enter (SPEC: y ∈ [0.30, 0.37], x ∈ [−1, −0.36]
    /// and x ∈ [−0.06, 1]). Empty: no obstacle, nothing to pass.
    pub walls: Vec<Wall>,
    /// The held object's offset `h_R − h_L` (paper: (0.1, 0)).
    pub grip: [f64; 2],
    /// Dropped when `‖(h_R − h_L) − grip‖` exceeds this (SPEC: 0.005 m).
    pub drop_tolerance: f64,
    /// Penalty R_p added when a step hits a wall or drops (paper: −1).
    pub penalty: f64,
    /// "Reached the target": RMS per-hand distance to `h*` at most this (SPEC: 0.05 m).
    pub reached_rms: f64,
    /// URDF link (frame) of the left hand.
    pub left_hand: String,
    /// URDF link (frame) of the right hand.
    pub right_hand: String,
    /// The plant's own start posture ([`crate::arms::ArmsPlant`]'s `sample_start`, used with
    /// `StartMode::FromPlant`); Experiment 2 starts uniformly in the latent box instead.
    /// Default: hands at (−0.25, 0.15) and (−0.15, 0.15), elbows outward, below the wall.
    pub start_posture: [f64; 4],
    /// The physics world: step, sub-steps, solver iterations, servo gains. Default: dt 1/240,
    /// 12 sub-steps (0.05 s RL step, paper δt), **2** solver iterations (ours: tracking stays
    /// < 1 mrad, `tests/pd_tracking.rs`, at ≈ 55 % of the cost of rapier's 4), kp 5000, kd 50.
    pub sim: SimOptions,
}

impl Default for ArmsConfig {
    fn default() -> Self {
        Self {
            target: [-0.05, 0.47, 0.05, 0.47],
            theta: 0.35,
            length_scale: 0.3,
            walls: vec![
                Wall {
                    low: [-1.0, 0.30],
                    high: [-0.36, 0.37],
                },
                Wall {
                    low: [-0.06, 0.30],
                    high: [1.0, 0.37],
                },
            ],
            grip: [0.1, 0.0],
            drop_tolerance: 0.005,
            penalty: -1.0,
            reached_rms: 0.05,
            left_hand: "left_hand".to_string(),
            right_hand: "right_hand".to_string(),
            // PlanarArms::default().inverse(&[-0.25, 0.15, -0.15, 0.15]) (tested below).
            start_posture: [
                3.424_417_622_960_777_7,
                -2.531_237_385_236_626_6,
                1.700_348_493_943_719_2,
                1.955_193_101_290_535_7,
            ],
            sim: SimOptions {
                solver_iterations: 2,
                ..SimOptions::default()
            },
        }
    }
}

impl ArmsConfig {
    /// Checks every field: finite values, positive θ, ℓ and tolerances, non-empty walls.
    pub fn validate(&self) -> Result<()> {
        check_finite("target", &self.target)?;
        check_finite("grip", &self.grip)?;
        check_finite("penalty", &[self.penalty])?;
        check_finite("start_posture", &self.start_posture)?;
        for (name, value) in [
            ("theta (reward width)", self.theta),
            ("length_scale", self.length_scale),
            ("drop_tolerance", self.drop_tolerance),
            ("reached_rms", self.reached_rms),
        ] {
            if !(value.is_finite() && value > 0.0) {
                return Err(SimError::Input(CoreError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and > 0",
                }));
            }
        }
        for wall in &self.walls {
            check_finite("wall corners", &[wall.low[0], wall.low[1], wall.high[0], wall.high[1]])?;
            if let Some(k) = (0..2).find(|&k| wall.high[k] <= wall.low[k]) {
                return Err(SimError::Input(CoreError::InvalidParameter {
                    name: "wall high corner",
                    value: wall.high[k],
                    reason: "must exceed the low corner in x and y",
                }));
            }
        }
        Ok(())
    }

    /// `R(h) = exp(−θ ‖(h − h*)/ℓ‖²)` (paper Eq. 12, SPEC §4.2) of hands `h`.
    pub fn reward(&self, hands: &[f64; 4]) -> f64 {
        (-self.theta * self.squared_distance(hands) / (self.length_scale * self.length_scale)).exp()
    }

    /// RMS per-hand distance to the target, `sqrt(‖h − h*‖² / 2)`.
    pub fn rms_hand_distance(&self, hands: &[f64; 4]) -> f64 {
        (self.squared_distance(hands) / 2.0).sqrt()
    }

    fn squared_distance(&self, hands: &[f64; 4]) -> f64 {
        hands.iter().zip(&self.target).map(|(a, b)| (a - b) * (a - b)).sum()
    }

    /// Why hands `h` would end an episode, if they would: a hand in a wall (obstacle), then
    /// the grip broken (drop).
    pub fn violation(&self, hands: &[f64; 4]) -> Option<EndReason> {
        let in_wall = |x: f64, y: f64| self.walls.iter().any(|w| w.contains(x, y));
        if in_wall(hands[0], hands[1]) || in_wall(hands[2], hands[3]) {
            return Some(EndReason::Obstacle);
        }
        let dx = hands[2] - hands[0] - self.grip[0];
        let dy = hands[3] - hands[1] - self.grip[1];
        (dx.hypot(dy) > self.drop_tolerance).then_some(EndReason::Drop)
    }

    /// The wall band `(lowest bottom, highest top)` in y, `None` without walls.
    pub fn wall_band(&self) -> Option<(f64, f64)> {
        let bottom = self.walls.iter().map(|w| w.low[1]).reduce(f64::min)?;
        let top = self.walls.iter().map(|w| w.high[1]).reduce(f64::max)?;
        Some((bottom, top))
    }
}

/// The two simulated arms of Experiment 2 (module docs).
pub struct ArmsPlant {
    sim: PhysicsSim,
    config: ArmsConfig,
    frames: [Frame; 2],
    band: Option<(f64, f64)>,
    hands: [f64; 4],
    started_below: bool,
    went_above: bool,
}

impl ArmsPlant {
    /// Builds the world from `model` (e.g. `two_arms.urdf`) and puts the arms at
    /// `config.start_posture`. Fails on a bad configuration, unknown hand links or a start
    /// posture outside the joint limits.
    pub fn new(model: UrdfModel, config: ArmsConfig) -> Result<Self> {
        config.validate()?;
        let mut sim = PhysicsSim::new(model, config.sim.clone())?;
        let frames = [
            sim.frame(&config.left_hand, [0.0; 3])?,
            sim.frame(&config.right_hand, [0.0; 3])?,
        ];
        sim.reset(&config.start_posture)?;
        let band = config.wall_band();
        let mut plant = Self {
            sim,
            config,
            frames,
            band,
            hands: [0.0; 4],
            started_below: false,
            went_above: false,
        };
        plant.read_hands();
        Ok(plant)
    }

    /// Its configuration.
    pub fn config(&self) -> &ArmsConfig {
        &self.config
    }

    /// The physics world (read-only: joint positions, frames, time).
    pub fn sim(&self) -> &PhysicsSim {
        &self.sim
    }

    /// The current hand positions `(x_L, y_L, x_R, y_R)`.
    pub fn hands(&self) -> [f64; 4] {
        self.hands
    }

    fn read_hands(&mut self) {
        let [lx, ly, _] = self.sim.frame_position(&self.frames[0]);
        let [rx, ry, _] = self.sim.frame_position(&self.frames[1]);
        self.hands = [lx, ly, rx, ry];
    }

    fn both_hands(&self, test: impl Fn(f64) -> bool) -> bool {
        test(self.hands[1]) && test(self.hands[3])
    }
}

impl Plant for ArmsPlant {
    fn posture_dim(&self) -> usize {
        self.sim.num_joints()
    }

    fn task_dim(&self) -> usize {
        4
    }

    /// The fixed `config.start_posture` (the generator is not used).
    fn sample_start<R: Rng + ?Sized>(&mut self, _rng: &mut R, posture: &mut [f64]) {
        posture.copy_from_slice(&self.config.start_posture);
    }

    fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
        if self.sim.reset(posture).is_err() {
            // Outside the joint limits (or not finite): not a posture of this robot.
            return Some(EndReason::BoxExit);
        }
        self.read_hands();
        self.started_below = self.band.is_some_and(|(bottom, _)| self.both_hands(|y| y < bottom));
        self.went_above = false;
        self.config.violation(&self.hands)
    }

    fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
        if self.sim.set_targets(target).is_err() {
            // A non-finite target (the learner never sends one): end as a box exit.
            self.sim.joint_positions_into(reached);
            return StepOutcome {
                reward: self.config.penalty,
                end: Some(EndReason::BoxExit),
            };
        }
        self.sim.step_rl();
        self.sim.joint_positions_into(reached);
        self.read_hands();
        if let Some((_, top)) = self.band {
            self.went_above |= self.both_hands(|y| y > top);
        }
        let end = self.config.violation(&self.hands);
        let reward = self.config.reward(&self.hands) + if end.is_some() { self.config.penalty } else { 0.0 };
        StepOutcome { reward, end }
    }

    fn task_position(&self, out: &mut [f64]) {
        out.copy_from_slice(&self.hands);
    }

    fn reached_target(&self) -> bool {
        self.config.rms_hand_distance(&self.hands) <= self.config.reached_rms
    }

    fn passed(&self) -> bool {
        self.started_below && self.went_above
    }

    fn admits_test_start(&self) -> bool {
        self.started_below
    }
}

/// The learner of Experiment 2 as in the paper (SPEC §4.2): α 0.8, γ 0.99, β 20, 1000 steps
/// per episode, w₀ = 0, step 0.2 × RBF spacing, 20 × 20 RBFs, starts uniform over the latent
/// box (redrawn while the plant refuses them).
pub fn learner_config() -> LearnerConfig {
    LearnerConfig {
        td: TdConfig {
            alpha: 0.8,
            gamma: 0.99,
            initial_weight: 0.0,
        },
        beta: 20.0,
        max_steps: 1000,
        start: StartMode::UniformInBox,
        ..LearnerConfig::default()
    }
}

/// The latent space of an Experiment 2 learner: GPLVM maps and the latent box (d = 2; 8
/// actions, orthogonal + diagonal, paper Exp. 2).
pub type ArmsLatent<'a> = Latent2d<'a>;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kinematics::PlanarArms;

    #[test]
    fn default_start_is_the_ik_of_hands_below_the_wall() {
        let c = ArmsConfig::default();
        let q = PlanarArms::default().inverse(&[-0.25, 0.15, -0.15, 0.15], 0).unwrap();
        for (a, b) in q.iter().zip(&c.start_posture) {
            assert!((a - b).abs() < 1e-12, "{q:?} vs {:?}", c.start_posture);
        }
    }

    #[test]
    fn violations_reward_and_band() {
        let c = ArmsConfig::default();
        assert_eq!(c.violation(&[-0.2, 0.2, -0.1, 0.2]), None);
        assert_eq!(
            c.violation(&[-0.2, 0.33, -0.1, 0.33]),
            None,
            "left hand in the gap, right hand in the gap"
        );
        assert_eq!(
            c.violation(&[-0.4, 0.33, -0.3, 0.33]),
            Some(EndReason::Obstacle),
            "left hand in the left wall"
        );
        assert_eq!(
            c.violation(&[-0.1, 0.30, 0.0, 0.30]),
            Some(EndReason::Obstacle),
            "right hand on the right wall's edge"
        );
        assert_eq!(c.violation(&[-0.2, 0.2, -0.094, 0.2]), Some(EndReason::Drop));
        assert_eq!(c.violation(&[-0.2, 0.2, -0.096, 0.2]), None, "within 5 mm");
        assert_eq!(c.reward(&c.target), 1.0);
        let h = [0.25, 0.47, 0.35, 0.47];
        assert!(
            (c.reward(&h) - (-0.35 * 2.0f64).exp()).abs() < 1e-15,
            "0.3 m per hand = ℓ"
        );
        assert!((c.rms_hand_distance(&h) - 0.3).abs() < 1e-15);
        assert_eq!(c.wall_band(), Some((0.30, 0.37)));
        assert_eq!(
            ArmsConfig {
                walls: vec![],
                ..ArmsConfig::default()
            }
            .wall_band(),
            None
        );
    }

    #[test]
    fn bad_config_is_an_error() {
        let bad = [
            ArmsConfig {
                theta: 0.0,
                ..ArmsConfig::default()
            },
            ArmsConfig {
                length_scale: f64::NAN,
                ..ArmsConfig::default()
            },
            ArmsConfig {
                drop_tolerance: -1.0,
                ..ArmsConfig::default()
            },
            ArmsConfig {
                walls: vec![Wall {
                    low: [0.0, 0.0],
                    high: [1.0, 0.0],
                }],
                ..ArmsConfig::default()
            },
            ArmsConfig {
                target: [0.0, f64::INFINITY, 0.0, 0.0],
                ..ArmsConfig::default()
            },
        ];
        for c in bad {
            assert!(
                matches!(
                    c.validate(),
                    Err(SimError::Input(CoreError::InvalidParameter { .. })
                        | SimError::Input(CoreError::NonFinite { .. }))
                ),
                "{c:?}"
            );
        }
    }
}
