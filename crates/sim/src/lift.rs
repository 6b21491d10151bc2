//! Experiment 3 (SPEC §4.3, paper Fig. 7b–e, 8): the KHR-1HV-like humanoid lifts an object
//! with both hands, standing on the floor under gravity, as a [`Plant`] for RL in the GPLVM
//! latent space of its lift demonstrations; and the runner of its trials.
//!
//! One plant step (SPEC §3.1 step 4–5): the decoded posture becomes the servo targets
//! (clamped to the joint limits), the world advances one RL step (`substeps × dt`, 0.05 s),
//! the joint positions are read back (the reached posture) and the hands come from the
//! sim's hand frames. Then, on the reached hands `h = (x_L, y_L, z_L, x_R, y_R, z_R)`:
//!
//! - reward `exp(−θ ‖(h − h*)/ℓ‖²)` (Eq. 12 with a length unit ℓ = 0.1 m at the robot's
//!   scale; the task of `latentrl.envs.HumanoidLiftEnv`);
//! - any robot link within the contact margin of an obstacle ⇒ reward + penalty,
//!   [`EndReason::Obstacle`] (obstacles are static sensors: the robot passes through them,
//!   the contact query sees it);
//! - a fall ([`FallCriteria`]: a sole tilting > 20°, a non-sole link on the floor, or the
//!   base below half its height at the reset) ⇒ reward + penalty, [`EndReason::Fall`];
//! - `| ‖h_R − h_L‖ − grip width | > drop_tolerance` ⇒ reward + penalty, [`EndReason::Drop`].
//!
//! The tests run in that order, once per RL step (after the sub-steps).
//!
//! **A fresh world per episode.** [`Plant::reset`] rebuilds the physics world from the
//! model, then stands the robot at the posture with the left sole flat on the floor
//! ([`reset_on_ground`]). Resetting a world in place would make an episode depend on the
//! one before it (rapier keeps contact warm-start impulses, and joint coordinates are set
//! by an f32 displacement from the previous ones); a rebuild costs ≈ 1–2 ms, under one RL
//! step. A start is refused (and redrawn by the learner) when the posture lies outside the
//! joint limits ([`EndReason::BoxExit`]), touches an obstacle, breaks the grip, has a
//! non-sole link on the floor or a tilted sole, or stands with its centre of mass less
//! than `min_start_margin` inside the support polygon ([`EndReason::Fall`]).

use latent_core::episode::{EndReason, LearnerConfig, Plant, StartMode, StepOutcome};
use latent_core::error::CoreError;
use latent_core::td::TdConfig;
use nalgebra::Isometry3;
use rand::{Rng, RngExt};

use crate::error::{Result, SimError, check_finite};
use crate::humanoid::{self, reset_on_ground, support_margin};
use crate::obstacles::{FallCriteria, Obstacle, ObstacleShape};
use crate::plant::{Frame, PhysicsSim, SimOptions};
use crate::urdf::{RootMode, UrdfModel};

/// Columns of [`Plant::task_position`]: hands (6), base position (3), base orientation
/// quaternion `(x, y, z, w)` (4), then the joint angles (URDF order).
pub const TASK_HEAD: usize = 13;

/// Height (m) above the floor of the lowest sole corner at a reset.
const CLEARANCE: f64 = 5e-4;

/// An axis-aligned static box obstacle (a sensor): centre and half-extents (m).
pub fn box_obstacle(name: &str, centre: [f64; 3], half_extents: [f64; 3]) -> Obstacle {
    Obstacle {
        name: name.to_string(),
        shape: ObstacleShape::Box { half_extents },
        pose: Isometry3::translation(centre[0], centre[1], centre[2]),
        sensor: true,
    }
}

/// Everything about the Experiment 3 plant; `Default` is our setup (docs/exp3.md).
#[derive(Debug, Clone, PartialEq)]
pub struct LiftConfig {
    /// Target hands `h* = (x_L, y_L, z_L, x_R, y_R, z_R)` (m). Default: the hands of the
    /// demo that holds them highest (row 6 of `khr1hv_lift_demos.csv`, knee squat, standing).
    pub target: [f64; 6],
    /// θ of the reward `exp(−θ ‖(h − h*)/ℓ‖²)` (paper: 0.35).
    pub theta: f64,
    /// Length unit ℓ of the reward (ours: 0.1 m, the robot's scale).
    pub length_scale: f64,
    /// Width of the held object (m): the demonstrated hand distance, 0.10.
    pub grip_width: f64,
    /// Dropped when `| ‖h_R − h_L‖ − grip_width |` exceeds this (ours: 0.02 m).
    pub drop_tolerance: f64,
    /// Penalty R_p added when a step ends the episode (paper: −1).
    pub penalty: f64,
    /// "Reached the target": RMS per-hand distance to `h*` at most this (ours: 0.02 m).
    pub reached_rms: f64,
    /// Hand frames (left, right).
    pub hands: [String; 2],
    /// Sole links (left, right); the robot stands with the first flat on the floor.
    pub soles: [String; 2],
    /// Fall: a sole leaning more than this from the vertical (rad; SPEC: 20°).
    pub max_sole_tilt: f64,
    /// Fall: the base below this share of its height at the reset (SPEC: half).
    pub base_height_fraction: f64,
    /// Static obstacles (default: one box, [`LiftConfig::default`]).
    pub obstacles: Vec<Obstacle>,
    /// The plant's own start (`StartMode::FromPlant`): this posture plus uniform noise of
    /// ±`start_noise` rad per joint. `None`: the zero (home) posture.
    pub start_posture: Option<Vec<f64>>,
    /// Noise of the plant's own start (rad per joint).
    pub start_noise: f64,
    /// A start is refused unless the static support margin (centre of mass inside the
    /// support polygon) is at least this (m). Default 0.
    pub min_start_margin: f64,
    /// The physics world. Default: floating root, floor at z = 0, dt 1/240 s × 12 sub-steps,
    /// 1 solver iteration of 4 PGS passes, servos kp 8 N·m/rad, kd 0.1 N·m·s/rad, capped at 1.2 N·m
    /// (`latentrl.humanoid.SERVO`, `PHYSICS`).
    pub sim: SimOptions,
}

impl Default for LiftConfig {
    /// The obstacle: a box 10 cm deep (x ∈ [0.165, 0.265] m), 24 cm wide (|y| ≤ 0.12) and
    /// 25 cm tall (z ∈ [0.05, 0.30]) in front of the robot (x forward from the left sole's
    /// frame). The straight-arm hip-hinge demos 0–2 (hands 18–19 cm forward, the upper body
    /// bent over) touch it; demo 3 (hands 15 cm forward) and the knee-squat demos 4–6
    /// (hands ≤ 12 cm forward) keep clear.
    fn default() -> Self {
        Self {
            target: [0.101, 0.05, 0.2655, 0.101, -0.05, 0.2655],
            theta: 0.35,
            length_scale: 0.1,
            grip_width: 0.10,
            drop_tolerance: 0.02,
            penalty: -1.0,
            reached_rms: 0.02,
            hands: ["l_hand".to_string(), "r_hand".to_string()],
            soles: ["l_foot".to_string(), "r_foot".to_string()],
            max_sole_tilt: 20f64.to_radians(),
            base_height_fraction: 0.5,
            obstacles: vec![box_obstacle("wall", [0.215, 0.0, 0.175], [0.05, 0.12, 0.125])],
            start_posture: None,
            start_noise: 0.01,
            min_start_margin: 0.0,
            sim: humanoid::sim_options(),
        }
    }
}

fn positive(name: &'static str, value: f64) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(SimError::Input(CoreError::InvalidParameter {
            name,
            value,
            reason: "must be finite and > 0",
        }))
    }
}

impl LiftConfig {
    /// Checks every field: finite values, positive widths and tolerances, a floating root
    /// with a floor, a base fraction in (0, 1).
    pub fn validate(&self) -> Result<()> {
        check_finite("target", &self.target)?;
        check_finite("penalty", &[self.penalty, self.min_start_margin])?;
        for (name, value) in [
            ("theta (reward width)", self.theta),
            ("length_scale", self.length_scale),
            ("grip_width", self.grip_width),
            ("drop_tolerance", self.drop_tolerance),
            ("reached_rms", self.reached_rms),
            ("max_sole_tilt", self.max_sole_tilt),
        ] {
            positive(name, value)?;
        }
        if !(self.start_noise.is_finite() && self.start_noise >= 0.0) {
            return Err(SimError::Input(CoreError::InvalidParameter {
                name: "start_noise",
                value: self.start_noise,
                reason: "must be finite and ≥ 0",
            }));
        }
        if !(self.base_height_fraction > 0.0 && self.base_height_fraction < 1.0) {
            return Err(SimError::Input(CoreError::InvalidParameter {
                name: "base_height_fraction",
                value: self.base_height_fraction,
                reason: "must lie in (0, 1)",
            }));
        }
        if let Some(q) = &self.start_posture {
            check_finite("start_posture", q)?;
        }
        if self.sim.root != RootMode::Floating || self.sim.ground.is_none() {
            return Err(SimError::Input(CoreError::InvalidParameter {
                name: "sim (root, ground)",
                value: f64::NAN,
                reason: "the humanoid needs a floating root and a floor",
            }));
        }
        Ok(())
    }

    /// `R(h) = exp(−θ ‖(h − h*)/ℓ‖²)` (paper Eq. 12) of hands `h`.
    pub fn reward(&self, hands: &[f64; 6]) -> f64 {
        (-self.theta * self.squared_distance(hands) / (self.length_scale * self.length_scale)).exp()
    }

    /// RMS per-hand distance to the target, `sqrt(‖h − h*‖² / 2)`.
    pub fn rms_hand_distance(&self, hands: &[f64; 6]) -> f64 {
        (self.squared_distance(hands) / 2.0).sqrt()
    }

    fn squared_distance(&self, hands: &[f64; 6]) -> f64 {
        hands.iter().zip(&self.target).map(|(a, b)| (a - b) * (a - b)).sum()
    }

    /// `| ‖h_R − h_L‖ − grip_width |` (m).
    pub fn grip_error(&self, hands: &[f64; 6]) -> f64 {
        let d = (0..3).map(|k| (hands[k + 3] - hands[k]).powi(2)).sum::<f64>().sqrt();
        (d - self.grip_width).abs()
    }
}

/// The simulated humanoid of Experiment 3 (module docs).
pub struct LiftPlant {
    model: UrdfModel,
    config: LiftConfig,
    sim: PhysicsSim,
    frames: [Frame; 2],
    fall: FallCriteria,
    hands: [f64; 6],
    home: Vec<f64>,
}

impl LiftPlant {
    /// Builds the world from `model` (e.g. `khr1hv.urdf`) and stands the robot at the start
    /// posture. Fails on a bad configuration, unknown hand or sole links, a start posture of
    /// the wrong length or outside the joint limits.
    pub fn new(model: UrdfModel, config: LiftConfig) -> Result<Self> {
        config.validate()?;
        let (sim, frames) = Self::world(&model, &config)?;
        let home = match &config.start_posture {
            Some(q) => q.clone(),
            None => vec![0.0; sim.num_joints()],
        };
        let fall = FallCriteria {
            min_base_height: 0.0,
            max_sole_tilt: config.max_sole_tilt,
            soles: config.soles.to_vec(),
        };
        let mut plant = Self {
            model,
            config,
            sim,
            frames,
            fall,
            hands: [0.0; 6],
            home,
        };
        plant.sim.fall_status(&plant.fall)?;
        let home = plant.home.clone();
        plant.stand(&home)?;
        Ok(plant)
    }

    /// A fresh world with the obstacles and the hand frames.
    fn world(model: &UrdfModel, config: &LiftConfig) -> Result<(PhysicsSim, [Frame; 2])> {
        let mut sim = PhysicsSim::new(model.clone(), config.sim.clone())?;
        for obstacle in &config.obstacles {
            sim.add_obstacle(obstacle.clone())?;
        }
        let frames = [
            sim.frame(&config.hands[0], [0.0; 3])?,
            sim.frame(&config.hands[1], [0.0; 3])?,
        ];
        Ok((sim, frames))
    }

    /// Rebuilds the world and stands the robot at `posture`; sets the fall test's base height.
    fn stand(&mut self, posture: &[f64]) -> Result<()> {
        let (sim, frames) = Self::world(&self.model, &self.config)?;
        self.sim = sim;
        self.frames = frames;
        let ground = self.config.sim.ground.unwrap_or(0.0);
        reset_on_ground(&mut self.sim, posture, &self.config.soles[0], ground, CLEARANCE)?;
        let base = self.sim.base_pose().translation.z;
        self.fall.min_base_height = ground + self.config.base_height_fraction * (base - ground);
        self.read_hands();
        Ok(())
    }

    /// Its configuration.
    pub fn config(&self) -> &LiftConfig {
        &self.config
    }

    /// The physics world of the current episode (read-only).
    pub fn sim(&self) -> &PhysicsSim {
        &self.sim
    }

    /// The current hand positions `(x_L, y_L, z_L, x_R, y_R, z_R)`.
    pub fn hands(&self) -> [f64; 6] {
        self.hands
    }

    fn read_hands(&mut self) {
        let [a, b, c] = self.sim.frame_position(&self.frames[0]);
        let [d, e, f] = self.sim.frame_position(&self.frames[1]);
        self.hands = [a, b, c, d, e, f];
    }

    /// Why the current state ends an episode, if it does: an obstacle contact, a fall, then
    /// a drop (module docs).
    pub fn violation(&self) -> Option<EndReason> {
        if self.sim.any_obstacle_contact() {
            return Some(EndReason::Obstacle);
        }
        // The sole links were checked when the plant was built.
        if self.sim.fall_status(&self.fall).is_ok_and(|s| s.fell) {
            return Some(EndReason::Fall);
        }
        (self.config.grip_error(&self.hands) > self.config.drop_tolerance).then_some(EndReason::Drop)
    }
}

impl Plant for LiftPlant {
    fn posture_dim(&self) -> usize {
        self.sim.num_joints()
    }

    fn task_dim(&self) -> usize {
        TASK_HEAD + self.sim.num_joints()
    }

    /// The start posture plus uniform noise of ±`start_noise` per joint, clamped to the limits.
    fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
        let noise = self.config.start_noise;
        for ((q, home), info) in posture.iter_mut().zip(&self.home).zip(self.model.joints()) {
            let dq = if noise > 0.0 {
                rng.random_range(-noise..=noise)
            } else {
                0.0
            };
            *q = (home + dq).clamp(info.lower, info.upper);
        }
    }

    fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
        if self.stand(posture).is_err() {
            // Outside the joint limits (or not finite): not a posture of this robot.
            return Some(EndReason::BoxExit);
        }
        if let Some(end) = self.violation() {
            return Some(end);
        }
        let margin = support_margin(&self.sim, &self.config.soles).unwrap_or(f64::NEG_INFINITY);
        (margin < self.config.min_start_margin).then_some(EndReason::Fall)
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
        let end = self.violation();
        let reward = self.config.reward(&self.hands) + if end.is_some() { self.config.penalty } else { 0.0 };
        StepOutcome { reward, end }
    }

    fn task_position(&self, out: &mut [f64]) {
        out[..6].copy_from_slice(&self.hands);
        let base = self.sim.base_pose();
        let t = base.translation.vector;
        let q = base.rotation.quaternion();
        out[6..TASK_HEAD].copy_from_slice(&[t.x, t.y, t.z, q.i, q.j, q.k, q.w]);
        self.sim.joint_positions_into(&mut out[TASK_HEAD..]);
    }

    fn reached_target(&self) -> bool {
        self.config.rms_hand_distance(&self.hands) <= self.config.reached_rms
    }
}

/// The learner of Experiment 3 (ours, the paper gives Exp. 2's values): α 0.8, γ 0.99, β 20,
/// 200 steps per episode (paper), w₀ = 0, step 0.2 × RBF spacing, 20 × 20 RBFs, starts
/// uniform over the latent box (redrawn while the plant refuses them).
pub fn learner_config() -> LearnerConfig {
    LearnerConfig {
        td: TdConfig {
            alpha: 0.8,
            gamma: 0.99,
            initial_weight: 0.0,
        },
        beta: 20.0,
        max_steps: 200,
        start: StartMode::UniformInBox,
        ..LearnerConfig::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reward_grip_and_validation() {
        let c = LiftConfig::default();
        assert_eq!(c.reward(&c.target), 1.0);
        let mut h = c.target;
        h[2] -= 0.1;
        h[5] -= 0.1;
        assert!(
            (c.reward(&h) - (-0.35f64 * 2.0).exp()).abs() < 1e-12,
            "0.1 m per hand = ℓ"
        );
        assert!((c.rms_hand_distance(&h) - 0.1).abs() < 1e-12);
        assert!(c.grip_error(&c.target) < 1e-12, "the target holds the object");
        h[4] = -0.08;
        assert!((c.grip_error(&h) - 0.03).abs() < 1e-12);
        for bad in [
            LiftConfig {
                drop_tolerance: 0.0,
                ..LiftConfig::default()
            },
            LiftConfig {
                base_height_fraction: 1.0,
                ..LiftConfig::default()
            },
            LiftConfig {
                target: [0.0, f64::NAN, 0.0, 0.0, 0.0, 0.0],
                ..LiftConfig::default()
            },
            LiftConfig {
                sim: SimOptions::default(),
                ..LiftConfig::default()
            },
        ] {
            assert!(bad.validate().is_err(), "{bad:?}");
        }
    }
}
