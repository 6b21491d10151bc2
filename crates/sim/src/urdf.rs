//! Reading a URDF robot description and checking it before rapier3d-urdf builds it.
//!
//! [`UrdfModel`] parses a file or a string (with the `urdf-rs` version that
//! rapier3d-urdf 0.36.1 re-exports), rejects what the physics plant cannot simulate,
//! and lists the actuated joints in URDF order. [`crate::world::World`] then inserts
//! it into a rapier world as one multibody (reduced coordinates).
//!
//! What rapier3d-urdf 0.36.1 ignores, and what we do about it:
//! - `<dynamics damping friction>`: read here ([`JointInfo::damping`], [`JointInfo::friction`])
//!   and written into the multibody's per-DoF damping / dry friction by the plant.
//! - `limit.effort`: read here ([`JointInfo::effort`]) and used as the PD torque cap
//!   (see [`crate::world::ServoConfig::use_urdf_effort`]).
//! - `limit.velocity`: read ([`JointInfo::velocity`]) but **not enforced**.
//! - `<mimic>`, `<safety_controller>`: rejected (mimic) or ignored (safety controller).
//! - `<visual>`: ignored; only `<collision>` shapes become colliders. Meshes need cargo
//!   features we do not enable, so a mesh collision shape is rejected.
//!
//! Supported joint types: `revolute`, `continuous`, `prismatic` (actuated, one DoF each)
//! and `fixed`. `floating`, `planar` and `spherical` joints are rejected; a free-floating
//! robot gets its 6 root DoF from [`RootMode::Floating`] instead.

use std::path::Path;

use latent_core::choice;
use rapier3d_urdf::urdf_rs;

use crate::error::{Result, SimError};

mod check;
mod insert;
pub use check::{MAX_URDF_DEPTH, MAX_URDF_LINKS};
use check::{check_joint_types, check_robot, check_size};
pub(crate) use insert::JointSlot;

choice! {
    /// How the root link of the robot is attached to the world.
    pub enum RootMode {
        /// The root link is welded to the world (arms on a fixed base).
        Fixed = "fixed",
        /// The root link floats freely with 6 DoF (a humanoid standing on a floor).
        Floating = "floating",
    }
}

// `choice!` declares the enum; its variants take no `#[default]`.
#[allow(clippy::derivable_impls)]
impl Default for RootMode {
    fn default() -> Self {
        Self::Fixed
    }
}

/// Kind of an actuated (one-DoF) joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum JointKind {
    /// Hinge with position limits; the coordinate is an angle in radians.
    Revolute,
    /// Hinge without limits; the coordinate is an angle in radians.
    Continuous,
    /// Slider with position limits; the coordinate is a length in metres.
    Prismatic,
}

/// One actuated joint as written in the URDF.
#[derive(Debug, Clone, PartialEq)]
pub struct JointInfo {
    /// Joint name.
    pub name: String,
    /// Joint kind.
    pub kind: JointKind,
    /// Name of the link the joint moves.
    pub child_link: String,
    /// Lower position limit (−∞ for continuous joints).
    pub lower: f64,
    /// Upper position limit (+∞ for continuous joints).
    pub upper: f64,
    /// `limit.effort` (N·m or N) if given and positive: the torque cap.
    pub effort: Option<f64>,
    /// `limit.velocity` (rad/s or m/s) if given and positive; recorded, not enforced.
    pub velocity: Option<f64>,
    /// `<dynamics damping>` if given (N·m·s/rad).
    pub damping: Option<f64>,
    /// `<dynamics friction>` if given (N·m), applied as dry joint friction.
    pub friction: Option<f64>,
}

/// One collision shape of a link, as the URDF gives it (for drawing; the physics builds its
/// colliders from the same elements).
#[derive(Debug, Clone, PartialEq)]
pub struct ShapeInfo {
    /// Index of the link (URDF order).
    pub link: usize,
    /// "box", "sphere", "cylinder" or "capsule" (axis z), or "mesh".
    pub kind: &'static str,
    /// box: the 3 side lengths; sphere: the radius; cylinder, capsule: radius and length; mesh:
    /// the scale.
    pub size: Vec<f64>,
    /// Pose of the shape in its link's frame.
    pub origin: nalgebra::Isometry3<f64>,
}

/// A parsed and checked URDF robot.
#[derive(Debug, Clone)]
pub struct UrdfModel {
    pub(crate) robot: urdf_rs::Robot,
    pub(crate) origin: String,
    joints: Vec<JointInfo>,
}

impl UrdfModel {
    /// Reads and checks a URDF file.
    ///
    /// Fails with [`SimError::MissingFile`] if it cannot be read, and otherwise as
    /// [`UrdfModel::parse_named`].
    pub fn from_file(path: impl AsRef<Path>) -> Result<Self> {
        let path = path.as_ref();
        let origin = path.display().to_string();
        let xml = std::fs::read_to_string(path).map_err(|e| SimError::MissingFile {
            path: origin.clone(),
            reason: e.to_string(),
        })?;
        Self::parse_named(&xml, &origin)
    }

    /// Parses and checks a URDF document held in a string.
    pub fn parse(xml: &str) -> Result<Self> {
        Self::parse_named(xml, "<string>")
    }

    /// Parses and checks a URDF document; `origin` names it in error messages.
    ///
    /// Errors: [`SimError::UnsupportedJointType`] for a joint type other than revolute,
    /// continuous, prismatic or fixed (including unknown type strings) or a mimic joint;
    /// [`SimError::MalformedUrdf`] for bad XML, duplicate names, joints naming missing links,
    /// a link with two parents, empty or non-finite limits, a moving link without mass, a
    /// link with mass whose inertia tensor is not positive definite, breaks the triangle
    /// inequality or has a radius of gyration outside [1 µm, 1 km], non-finite inertial or
    /// collision poses, negative or non-finite collision sizes, a zero axis, a length or joint
    /// limit beyond ±1000 (m or rad), or a number too large for rapier's f32 (|value| > 3.4e38);
    /// [`SimError::UnsupportedGeometry`] for mesh collision shapes. A document nested deeper
    /// than [`MAX_URDF_DEPTH`] or with more than [`MAX_URDF_LINKS`] links is refused as
    /// malformed before it is parsed.
    pub fn parse_named(xml: &str, origin: &str) -> Result<Self> {
        check_size(xml, origin)?;
        check_joint_types(xml, origin)?;
        let robot = urdf_rs::read_from_string(xml).map_err(|e| SimError::MalformedUrdf {
            origin: origin.to_string(),
            reason: e.to_string(),
        })?;
        let joints = check_robot(&robot, origin)?;
        Ok(Self {
            robot,
            origin: origin.to_string(),
            joints,
        })
    }

    /// The robot's name attribute.
    pub fn name(&self) -> &str {
        &self.robot.name
    }

    /// The actuated joints, in URDF order (the order of postures and targets).
    pub fn joints(&self) -> &[JointInfo] {
        &self.joints
    }

    /// Names of the actuated joints, in URDF order.
    pub fn joint_names(&self) -> Vec<&str> {
        self.joints.iter().map(|j| j.name.as_str()).collect()
    }

    /// Index of the actuated joint called `name`, or [`SimError::UnknownJoint`].
    pub fn joint_index(&self, name: &str) -> Result<usize> {
        self.joints
            .iter()
            .position(|j| j.name == name)
            .ok_or_else(|| SimError::UnknownJoint {
                name: name.to_string(),
                known: self.joint_names().join(", "),
            })
    }

    /// Names of every URDF link (including body-less frames such as hands), in URDF order.
    pub fn link_names(&self) -> Vec<&str> {
        self.robot.links.iter().map(|l| l.name.as_str()).collect()
    }

    /// Every collision shape, link by link in URDF order.
    pub fn collision_shapes(&self) -> Vec<ShapeInfo> {
        let mut out = Vec::new();
        for (link, l) in self.robot.links.iter().enumerate() {
            for c in &l.collision {
                let (kind, size) = match &c.geometry {
                    urdf_rs::Geometry::Box { size } => ("box", size.0.to_vec()),
                    urdf_rs::Geometry::Sphere { radius } => ("sphere", vec![*radius]),
                    urdf_rs::Geometry::Cylinder { radius, length } => ("cylinder", vec![*radius, *length]),
                    urdf_rs::Geometry::Capsule { radius, length } => ("capsule", vec![*radius, *length]),
                    urdf_rs::Geometry::Mesh { scale, .. } => ("mesh", scale.map_or(vec![1.0; 3], |s| s.0.to_vec())),
                };
                out.push(ShapeInfo {
                    link,
                    kind,
                    size,
                    origin: crate::pose::origin_pose(&c.origin),
                });
            }
        }
        out
    }

    /// `(parent link, child link)` of every URDF joint, fixed ones included: the kinematic
    /// tree, e.g. to draw it.
    pub fn edges(&self) -> Vec<(&str, &str)> {
        self.robot
            .joints
            .iter()
            .map(|j| (j.parent.link.as_str(), j.child.link.as_str()))
            .collect()
    }

    /// Index of the URDF link called `name`, or [`SimError::UnknownLink`].
    pub fn link_index(&self, name: &str) -> Result<usize> {
        self.robot
            .links
            .iter()
            .position(|l| l.name == name)
            .ok_or_else(|| SimError::UnknownLink {
                name: name.to_string(),
                known: self.link_names().join(", "),
            })
    }
}
