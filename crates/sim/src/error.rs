//! The one error type of `sim`: every variant says what was wrong and where.

use latent_core::CoreError;
use latent_core::error::ErrorKind;

/// Errors raised by the plants when their inputs are unusable.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A wrong shape, a non-finite value or an impossible parameter: the core's input errors.
    #[error(transparent)]
    Input(#[from] CoreError),
    /// A hand target lies outside the annulus an arm can reach.
    #[error(
        "{arm} hand target of row {row} is unreachable: {distance:.6} m from the shoulder, \
         the arm reaches from {min:.6} m to {max:.6} m"
    )]
    Unreachable {
        /// `"left"` or `"right"`.
        arm: &'static str,
        /// Row (point index) of the batch, 0 for a single target.
        row: usize,
        /// Distance from the shoulder to the target.
        distance: f64,
        /// Smallest reachable distance, `|l1 − l2|`.
        min: f64,
        /// Largest reachable distance, `l1 + l2`.
        max: f64,
    },
    /// A URDF file could not be read (missing, unreadable, not UTF-8).
    #[error("cannot read URDF file {path}: {reason}")]
    MissingFile {
        /// The path as given.
        path: String,
        /// The operating-system error.
        reason: String,
    },
    /// A URDF document is not well-formed XML or breaks the URDF schema.
    #[error("malformed URDF ({origin}): {reason}")]
    MalformedUrdf {
        /// Where the document came from: a file path or `"<string>"`.
        origin: String,
        /// What was wrong, with the element's name where known.
        reason: String,
    },
    /// A URDF joint has a type the physics plant does not support.
    #[error(
        "unsupported joint type {kind:?} for joint {joint:?} in {origin} \
         (supported: revolute, continuous, prismatic, fixed, and spherical as three continuous joints; \
         a free-floating robot: root = \"floating\")"
    )]
    UnsupportedJointType {
        /// The joint's name.
        joint: String,
        /// The `type` attribute as written.
        kind: String,
        /// Where the document came from.
        origin: String,
    },
    /// A collision mesh could not be used: missing, unreadable, malformed or flat.
    #[error("collision mesh of link {link:?} in {origin}: {path}: {reason}")]
    Mesh {
        /// The link's name.
        link: String,
        /// The file tried (after resolving `package://` and relative paths), or the
        /// filename as written when it could not be resolved.
        path: String,
        /// What was wrong.
        reason: String,
        /// Where the URDF came from.
        origin: String,
    },
    /// A joint name that the robot does not have.
    #[error("unknown joint {name:?}; actuated joints are: {known}")]
    UnknownJoint {
        /// The name asked for.
        name: String,
        /// Comma-separated list of the actuated joints, in URDF order.
        known: String,
    },
    /// A link (or frame) name that the robot does not have.
    #[error("unknown link {name:?}; links are: {known}")]
    UnknownLink {
        /// The name asked for.
        name: String,
        /// Comma-separated list of the links.
        known: String,
    },
    /// A per-joint parameter was unusable (gain, torque cap, posture outside the limits).
    #[error("invalid {name} = {value} for joint {joint:?}: {reason}")]
    InvalidJointParameter {
        /// The joint's name.
        joint: String,
        /// Parameter name (`"kp"`, `"kd"`, `"max_force"`, `"position"`, …).
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        reason: String,
    },
    /// A configuration value broke its rule, named by its key path (`physics.dt`).
    #[error(transparent)]
    Param(#[from] latent_core::ParamError),
    /// A task (file or dict) is unusable: a key, a value, or a name the robot lacks.
    #[error("{origin}: {reason}")]
    Task {
        /// Where the task came from: its file, or what the caller named it.
        origin: String,
        /// What was wrong, starting with the key path.
        reason: String,
    },
    /// An obstacle id that was never returned by `add_obstacle`.
    #[error("unknown obstacle id {id}; the world has {count} obstacles")]
    UnknownObstacle {
        /// The id asked for.
        id: usize,
        /// Number of obstacles in the world.
        count: usize,
    },
    /// The home posture, demonstration `episode.start_demo`, that the robot cannot take (a
    /// joint outside its limits, …), where the robot stands at a neutral posture.
    #[error("demos row {row} (the home posture, episode.start_demo): {source}")]
    HomePosture {
        /// The demonstration's row (from 0).
        row: usize,
        /// Why the robot cannot take it.
        source: Box<SimError>,
    },
    /// Demonstration columns that do not fit the robot's joints.
    #[error("demo columns: {reason}")]
    DemoColumns {
        /// What does not fit, naming the joint (and the row).
        reason: String,
    },
}

impl SimError {
    /// The kind of this error: the core's own for its errors, bad input for every other.
    pub fn kind(&self) -> ErrorKind {
        match self {
            Self::Input(core) => core.kind(),
            Self::HomePosture { source, .. } => source.kind(),
            _ => ErrorKind::Input,
        }
    }
}

/// Result alias for the plants.
pub type Result<T> = std::result::Result<T, SimError>;

/// Fails with [`CoreError::NonFinite`] at the first NaN or infinity in `values`.
pub fn check_finite(what: &'static str, values: &[f64]) -> Result<()> {
    Ok(latent_core::error::check_finite(what, values)?)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_core_error_keeps_its_kind_and_every_other_is_input() {
        let numerical = SimError::Input(CoreError::NotPositiveDefinite { n: 2, jitter: 1e-6 });
        assert_eq!(numerical.kind(), ErrorKind::Numerical);
        assert_eq!(SimError::Input(CoreError::Cancelled).kind(), ErrorKind::Cancelled);
        let columns = SimError::DemoColumns { reason: "x".into() };
        assert_eq!(columns.kind(), ErrorKind::Input);
    }
}
