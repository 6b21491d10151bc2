//! Static obstacles: their shapes and placement (the queries live in [`crate::obstacles`]).

use latent_core::CoreError;
use nalgebra::Isometry3;
use rapier3d::prelude::{Real, SharedShape};

use crate::error::{Result, SimError, check_finite};
use crate::pose::to_vector;

/// Shape of a static obstacle, in its own frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ObstacleShape {
    /// Box with these half-extents along x, y, z (m).
    Box {
        /// Half-extents (m), all > 0.
        half_extents: [f64; 3],
    },
    /// Sphere (m).
    Sphere {
        /// Radius (m), > 0.
        radius: f64,
    },
    /// Capsule: the segment `a`–`b` swept by a sphere of `radius` (m).
    Capsule {
        /// First end of the segment.
        a: [f64; 3],
        /// Second end of the segment.
        b: [f64; 3],
        /// Radius (m), > 0.
        radius: f64,
    },
}

/// A static obstacle: a shape placed in the world.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    /// Name for reports (need not be unique).
    pub name: String,
    /// The shape.
    pub shape: ObstacleShape,
    /// Pose of the shape's frame in the world.
    pub pose: Isometry3<f64>,
    /// `true`: a sensor the robot passes through (still reported by the queries);
    /// `false`: a solid wall the robot collides with.
    pub sensor: bool,
}

impl Obstacle {
    /// An axis-aligned box named `name` at `center` with `half_extents` (m).
    pub fn aligned_box(name: &str, center: [f64; 3], half_extents: [f64; 3], sensor: bool) -> Self {
        let [x, y, z] = center;
        Self {
            name: name.to_string(),
            shape: ObstacleShape::Box { half_extents },
            pose: Isometry3::translation(x, y, z),
            sensor,
        }
    }
}

/// Index of an obstacle, in the order of [`crate::World::add_obstacle`] calls.
pub type ObstacleId = usize;

/// One link touching one obstacle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Contact {
    /// URDF name of the link.
    pub link: String,
    /// The obstacle.
    pub obstacle: ObstacleId,
}

impl ObstacleShape {
    pub(crate) fn build(&self) -> Result<SharedShape> {
        let bad = |name, value| {
            SimError::Input(CoreError::InvalidParameter {
                name,
                value,
                reason: "must be finite and > 0",
            })
        };
        let positive = |name, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(v as Real)
            } else {
                Err(bad(name, v))
            }
        };
        Ok(match *self {
            ObstacleShape::Box {
                half_extents: [x, y, z],
            } => SharedShape::cuboid(
                positive("half_extents.x", x)?,
                positive("half_extents.y", y)?,
                positive("half_extents.z", z)?,
            ),
            ObstacleShape::Sphere { radius } => SharedShape::ball(positive("radius", radius)?),
            ObstacleShape::Capsule { a, b, radius } => {
                check_finite("capsule end a", &a)?;
                check_finite("capsule end b", &b)?;
                SharedShape::capsule(to_vector(a), to_vector(b), positive("radius", radius)?)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_aligned_box_sits_unrotated_at_its_centre() {
        let b = Obstacle::aligned_box("b", [1.0, 2.0, 3.0], [0.1, 0.2, 0.3], true);
        assert_eq!(b.pose, Isometry3::translation(1.0, 2.0, 3.0));
        let half_extents = [0.1, 0.2, 0.3];
        assert_eq!(
            (b.name.as_str(), b.shape, b.sensor),
            ("b", ObstacleShape::Box { half_extents }, true)
        );
    }
}
