//! `sim`: the plants latentrl learns to control.
#![warn(missing_docs)]

pub mod arms;
pub mod bimanual;
pub mod error;
pub mod humanoid;
pub mod kinematics;
pub mod latent;
pub mod lift;
pub mod obstacles;
pub mod pd;
pub mod plant;
pub mod urdf;

pub use arms::{ArmsConfig, ArmsLatent, ArmsPlant, Wall};
pub use bimanual::{BimanualConfig, BimanualLearner, BimanualPlant};
pub use error::SimError;
pub use kinematics::{ArmsPose, PlanarArms};
pub use latent::Latent2d;
pub use lift::{LiftConfig, LiftPlant};
pub use obstacles::{Contact, FallCriteria, FallStatus, Obstacle, ObstacleId, ObstacleShape};
pub use pd::PdGains;
pub use plant::{Frame, PhysicsSim, SimOptions};
pub use urdf::{JointInfo, JointKind, RootMode, UrdfModel};
