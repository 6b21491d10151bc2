//! How a world is built and stepped: the physics, the servos and the root, each parameter
//! declared once ([`latent_core::params!`]).

use std::collections::BTreeMap;

use latent_core::params;
use latent_core::params::{ParamError, Rule, join};

use crate::pd::PdGains;
use crate::urdf::RootMode;

/// The rule of a servo gain or a damping: ≥ 0 and within f32 (rapier stores them as f32, where a
/// larger value would become infinite).
const GAIN: Rule = Rule::closed(0.0, f32::MAX as f64);

params! {
    /// The physics world: time step, sub-steps, solver, gravity, contacts.
    pub struct PhysicsConfig {
        /// Physics time step (s); ≤ 1/240 keeps PD tracking within 1 mrad.
        dt: f64 = 1.0 / 240.0 => Rule::open_closed(0.0, 0.05),
        /// Physics steps per RL step: one RL step lasts dt × substeps (default 0.05 s, paper's δt).
        substeps: usize = 12 => Rule::count(1, 10_000),
        /// rapier solver iterations per physics step (rapier's default 4); each refreshes every
        /// multibody's mass matrix, most of a step's cost.
        solver_iterations: usize = 4 => Rule::count(1, 1_000),
        /// Projected Gauss-Seidel passes over the constraints in each solver iteration (rapier's
        /// default 1): tighter contacts and limits without the mass-matrix refresh.
        pgs_iterations: usize = 1 => Rule::count(1, 1_000),
        /// Gravity (m/s²); the default points along −z.
        gravity: [f64; 3] = [0.0, 0.0, -9.81] => Rule::closed(-1000.0, 1000.0),
        /// Viscous joint damping (N·m·s/rad) where the URDF has no `<dynamics damping>`; 0
        /// replaces rapier's implicit 0.1, so all damping comes from the servos' kd.
        joint_damping: f64 = 0.0 => GAIN,
        /// Let links of the robot collide with each other (adjacent links never do).
        self_collisions: bool = false => Rule::Any,
        /// With self_collisions: pairs of links that still never collide, e.g.
        /// [["link3", "link5"]] (a task may list what a robot's meshes make overlap).
        ignore_collisions: Vec<[String; 2]> = Vec::new() => Rule::Any,
        /// Shapes closer than this (m) touch, for the obstacle and floor queries.
        contact_margin: f64 = 1e-3 => Rule::closed(0.0, 1.0),
        /// The largest effector (and floating-base) distance (m) from a fine-step reference
        /// that these settings were chosen for; `latentrl.physics_check` tests it. None: not
        /// declared. The world does not use it.
        tolerance: Option<f64> = None => Rule::Positive,
    }
}

params! {
    /// Overrides of one joint's servo.
    pub struct JointServo {
        /// Stiffness kp (N·m/rad or N/m).
        kp: Option<f64> = None => GAIN,
        /// Damping kd (N·m·s/rad or N·s/m).
        kd: Option<f64> = None => GAIN,
        /// Torque (force) cap (N·m or N); inf for none.
        max_force: Option<f64> = None => Rule::AtLeast(0.0),
    }
}

params! {
    /// The PD servos of the actuated joints (force-based: τ = kp (q* − q) − kd q̇, capped).
    pub struct ServoConfig {
        /// Stiffness kp of every joint (N·m/rad); kp 5000 / kd 50 track a 0.1 rad step of the
        /// 0.5 kg arms to < 1 mrad in 0.05 s.
        kp: f64 = 5000.0 => GAIN,
        /// Damping kd of every joint (N·m·s/rad).
        kd: f64 = 50.0 => GAIN,
        /// Torque cap of every joint (N·m); inf for none.
        max_force: f64 = f64::INFINITY => Rule::AtLeast(0.0),
        /// Cap each servo's torque at its URDF `limit.effort` too, where given.
        use_urdf_effort: bool = true => Rule::Any,
        /// Per-joint overrides by joint name: a table `[servo.joints.NAME]` of kp, kd, max_force.
        joints: BTreeMap<String, JointServo> = BTreeMap::new() => Rule::Nested,
    }
}

impl ServoConfig {
    /// The gains of joint `name`, with its URDF effort `effort` (if used) capping the torque.
    pub fn gains(&self, name: &str, effort: Option<f64>) -> PdGains {
        let own = self.joints.get(name);
        let gains = PdGains {
            kp: own.and_then(|j| j.kp).unwrap_or(self.kp),
            kd: own.and_then(|j| j.kd).unwrap_or(self.kd),
            max_force: own.and_then(|j| j.max_force).unwrap_or(self.max_force),
        };
        match (self.use_urdf_effort, effort) {
            (true, Some(effort)) => gains.capped(effort),
            _ => gains,
        }
    }
}

/// What a world is built from: the root, an optional floor, the physics and the servos.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct WorldConfig {
    /// Fixed base (arms) or free-floating root (humanoid).
    pub root: RootMode,
    /// Height of a floor half-space (normal +z), or none.
    pub floor: Option<f64>,
    /// The physics.
    pub physics: PhysicsConfig,
    /// The servos.
    pub servo: ServoConfig,
}

impl WorldConfig {
    /// Checks every rule (names as in a task file: `physics.dt`, `servo.joints.knee.kp`, `floor`).
    pub fn validate(&self) -> Result<(), ParamError> {
        use latent_core::Params;
        self.physics.check_fields("physics")?;
        self.servo.check_fields("servo")?;
        if let Some(h) = self.floor
            && !(h.is_finite() && h.abs() <= 1000.0)
        {
            return Err(ParamError::new(
                &join("", "floor"),
                format!("must be a finite height within ±1000 m, got {h}"),
            ));
        }
        Ok(())
    }

    /// Duration of one RL step, `dt · substeps` (s).
    pub fn rl_dt(&self) -> f64 {
        self.physics.dt * self.physics.substeps as f64
    }
}
