//! PD joint servos on rapier multibody motors (docs/method.md §RL loop, step 4: the plant tracks
//! the decoded targets with PD control).
//!
//! Each actuated joint gets a rapier position motor with the **force-based** model, so
//! the torque is `τ = kp·(q* − q) + kd·(0 − q̇)`, clamped to `±max_force`, in N·m/rad and
//! N·m·s/rad (N/m and N·s/m for sliders), independent of the link masses. rapier's
//! default acceleration-based model scales the gains by the mass and behaves oddly on
//! chains (docs/pitfalls.md §rapier3d). rapier integrates the motor implicitly, so large gains stay
//! stable (measured stable to kp 1e5 at dt 1/240).
//!
//! A motor with zero stiffness and damping still locks its joint in rapier 0.36.1; a
//! passive joint must have its torque cap set to zero instead: [`PdGains::passive`].

use rapier3d::prelude::{GenericJoint, JointAxis, MotorModel, Real};

use crate::error::{Result, SimError};

/// Gains and torque cap of one joint servo.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PdGains {
    /// Stiffness `kp` (N·m/rad), ≥ 0.
    pub kp: f64,
    /// Damping `kd` (N·m·s/rad), ≥ 0.
    pub kd: f64,
    /// Largest torque the servo applies (N·m), ≥ 0; `f64::INFINITY` for no cap.
    pub max_force: f64,
}

impl Default for PdGains {
    /// kp 5000, kd 50, no cap: tracks a 0.1 rad step on the 0.5 kg arms to < 1 mrad
    /// within 0.05 s at dt ≤ 1/240 (docs/pitfalls.md §rapier3d; measured in
    /// `tests/pd_tracking.rs`).
    fn default() -> Self {
        Self {
            kp: 5000.0,
            kd: 50.0,
            max_force: f64::INFINITY,
        }
    }
}

impl PdGains {
    /// Checked constructor: every value finite and ≥ 0 (`max_force` may be +∞).
    pub fn new(kp: f64, kd: f64, max_force: f64) -> Result<Self> {
        let gains = Self { kp, kd, max_force };
        gains.validate("<any>")?;
        Ok(gains)
    }

    /// A servo that applies no torque: the joint swings freely (cap 0, see module docs).
    pub fn passive() -> Self {
        Self {
            kp: 0.0,
            kd: 0.0,
            max_force: 0.0,
        }
    }

    /// The same gains with the torque cap lowered to `cap` if `cap` is smaller.
    pub fn capped(self, cap: f64) -> Self {
        Self {
            max_force: self.max_force.min(cap),
            ..self
        }
    }

    /// Fails with [`SimError::InvalidJointParameter`] naming `joint` unless kp and kd are
    /// finite and ≥ 0 and max_force is ≥ 0 (and not NaN).
    pub fn validate(&self, joint: &str) -> Result<()> {
        let checks = [
            ("kp", self.kp, self.kp.is_finite() && self.kp >= 0.0),
            ("kd", self.kd, self.kd.is_finite() && self.kd >= 0.0),
            ("max_force", self.max_force, self.max_force >= 0.0),
        ];
        for (name, value, ok) in checks {
            if !ok {
                return Err(SimError::InvalidJointParameter {
                    joint: joint.to_string(),
                    name,
                    value,
                    reason: "must be ≥ 0 (kp and kd also finite)".to_string(),
                });
            }
        }
        Ok(())
    }
}

/// Points the servo of `axis` at `target` with `gains` (force-based model).
pub(crate) fn drive(joint: &mut GenericJoint, axis: JointAxis, target: f64, gains: &PdGains) {
    let cap = if gains.max_force.is_finite() {
        gains.max_force as Real
    } else {
        Real::MAX
    };
    joint
        .set_motor_model(axis, MotorModel::ForceBased)
        .set_motor_position(axis, target as Real, gains.kp as Real, gains.kd as Real)
        .set_motor_max_force(axis, cap);
}

/// Moves only the target of an already configured servo (the per-RL-step hot path).
pub(crate) fn retarget(joint: &mut GenericJoint, axis: JointAxis, target: f64) {
    if let Some(motor) = joint.motor(axis).copied() {
        joint.set_motor_position(axis, target as Real, motor.stiffness, motor.damping);
    }
}
