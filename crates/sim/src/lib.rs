//! `sim`: the plants latentrl learns to control — any URDF robot in a rapier3d world as a
//! [`task::Task`] ([`task::TaskPlant`]), and Experiment 1's kinematic toy ([`bimanual`]).
#![warn(missing_docs)]

pub mod bimanual;
pub mod error;
pub mod fall;
pub mod fallcheck;
pub mod files;
pub mod kinematics;
pub mod obstacles;
pub mod pd;
mod pose;
pub mod shapes;
pub mod task;
pub mod urdf;
pub mod world;

pub use bimanual::{BimanualConfig, BimanualLearner, BimanualPlant};
pub use error::SimError;
pub use fall::{FallCriteria, FallStatus};
pub use kinematics::{ArmsPose, PlanarArms};
pub use pd::PdGains;
pub use shapes::{Contact, Obstacle, ObstacleId, ObstacleShape};
pub use task::{RuleCheck, Task, TaskConfig, TaskPlant};
pub use urdf::{JointInfo, JointKind, MAX_URDF_BYTES, MAX_URDF_DEPTH, MAX_URDF_LINKS, MimicInfo, RootMode, UrdfModel};
pub use world::{Frame, PhysicsConfig, ServoConfig, World, WorldConfig};
