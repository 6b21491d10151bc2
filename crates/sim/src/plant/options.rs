//! [`SimOptions`]: how the physics world is built and stepped.

use crate::error::{Result, SimError, check_finite};
use crate::pd::PdGains;
use crate::urdf::RootMode;
use latent_core::CoreError;

/// How the world is built and stepped.
#[derive(Debug, Clone, PartialEq)]
pub struct SimOptions {
    /// Fixed base (arms) or free-floating root (humanoid).
    pub root: RootMode,
    /// Gravity (m/s²). Default `(0, 0, −9.81)`: along −z, normal to the arms' x–y plane.
    pub gravity: [f64; 3],
    /// Physics time step (s). Default 1/240 (≤ 1/240 keeps PD tracking within 1 mrad).
    pub dt: f64,
    /// Physics steps per RL step. Default 12, i.e. an RL step of 0.05 s (paper's δt).
    pub substeps: usize,
    /// rapier solver iterations per physics step. Default 4 (rapier's default). Each is a
    /// small step that also refreshes every multibody's kinematics and mass matrix, which
    /// dominates the humanoid's cost.
    pub solver_iterations: usize,
    /// Projected Gauss-Seidel passes over the constraints inside each solver iteration.
    /// Default 1 (rapier's default); more tightens contacts and limits without the mass
    /// matrix refresh of more `solver_iterations`.
    pub pgs_iterations: usize,
    /// Height of a ground half-space (normal +z), or `None` for no ground. Default `None`.
    pub ground: Option<f64>,
    /// Servo gains of every joint at start (change per joint with `set_gains`).
    pub gains: PdGains,
    /// Cap each servo's torque at the URDF `limit.effort` when given. Default true.
    pub use_urdf_effort: bool,
    /// Viscous joint damping (N·m·s/rad) where the URDF has no `<dynamics damping>`.
    /// Default 0: replaces rapier's implicit 0.1 so all damping comes from the PD `kd`.
    pub joint_damping: f64,
    /// Let links of the same robot collide. Default false: the two arms may cross in
    /// the plane (the kinematic plant ignores it too).
    pub self_collisions: bool,
    /// Shapes closer than this (m) count as touching in the contact queries
    /// (`obstacles.rs`). Default 1 mm.
    pub contact_margin: f64,
}

impl Default for SimOptions {
    fn default() -> Self {
        Self {
            root: RootMode::Fixed,
            gravity: [0.0, 0.0, -9.81],
            dt: 1.0 / 240.0,
            substeps: 12,
            solver_iterations: 4,
            pgs_iterations: 1,
            ground: None,
            gains: PdGains::default(),
            use_urdf_effort: true,
            joint_damping: 0.0,
            self_collisions: false,
            contact_margin: 1e-3,
        }
    }
}

impl SimOptions {
    /// Fails with [`SimError::InvalidParameter`] on a non-positive step, sub-step or
    /// iteration count, non-finite gravity or ground, or negative damping or margin.
    pub(crate) fn validate(&self) -> Result<()> {
        let positive = [
            ("dt", self.dt),
            ("substeps", self.substeps as f64),
            ("solver_iterations", self.solver_iterations as f64),
            ("pgs_iterations", self.pgs_iterations as f64),
        ];
        for (name, value) in positive {
            if !(value.is_finite() && value > 0.0) {
                return Err(SimError::Input(CoreError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and > 0",
                }));
            }
        }
        check_finite("gravity", &self.gravity)?;
        check_finite("ground", self.ground.as_slice())?;
        for (name, value) in [
            ("joint_damping", self.joint_damping),
            ("contact_margin", self.contact_margin),
        ] {
            if !(value.is_finite() && value >= 0.0) {
                return Err(SimError::Input(CoreError::InvalidParameter {
                    name,
                    value,
                    reason: "must be finite and ≥ 0",
                }));
            }
        }
        self.gains.validate("<all joints>")
    }
}
