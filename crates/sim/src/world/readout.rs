//! Reading the plant's state: joint positions and velocities, link poses and the world
//! positions of frames such as the hands. Everything is widened from rapier's f32.

use nalgebra::{Isometry3, Point3};
use rapier3d::prelude::RigidBodyHandle;

use super::World;
use crate::error::{Result, SimError};
use crate::pose::to_isometry;
use crate::urdf::JointSlot;

/// Values per position row: x, y, z (m).
pub const POSITION_WIDTH: usize = 3;

/// Values per pose row ([`World::link_pose_rows`]): position x, y, z (m) and quaternion x, y,
/// z, w.
pub const POSE_WIDTH: usize = 7;

/// A point fixed on a link: where to read a hand position. Made by [`World::frame`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub(crate) body: RigidBodyHandle,
    pub(crate) offset: Isometry3<f64>,
}

impl World {
    /// Writes the joint positions (URDF order) into `out` (length `num_joints`).
    pub fn joint_positions_into(&self, out: &mut [f64]) {
        for (o, slot) in out.iter_mut().zip(&self.slots) {
            *o = self.coordinate(slot);
        }
    }

    /// The joint positions (rad or m), URDF order: the reached posture.
    pub fn joint_positions(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.slots.len()];
        self.joint_positions_into(&mut out);
        out
    }

    /// The mimic joints' positions, in the order of [`crate::UrdfModel::mimics`].
    pub fn mimic_positions(&self) -> Vec<f64> {
        self.mimic_slots.iter().map(|slot| self.coordinate(slot)).collect()
    }

    /// The coordinate of one joint slot (NaN if rapier lost it).
    pub(crate) fn coordinate(&self, slot: &JointSlot) -> f64 {
        self.world
            .multibody_joints
            .get(slot.handle)
            .and_then(|(mb, _)| mb.link(slot.link_id))
            .map_or(f64::NAN, |l| l.joint().coords()[slot.axis as usize] as f64)
    }

    /// The joint velocities (rad/s or m/s), URDF order.
    pub fn joint_velocities(&self) -> Vec<f64> {
        let vel = |slot: &JointSlot| {
            let mb = self.world.multibody_joints.get(slot.handle).map(|(mb, _)| mb);
            mb.map_or(f64::NAN, |mb| mb.generalized_velocity()[slot.dof] as f64)
        };
        self.slots.iter().map(vel).collect()
    }

    /// A frame on link `link` (any URDF link, body-less hand frames included) shifted
    /// by `offset` (metres, in the link frame).
    pub fn frame(&self, link: &str, offset: [f64; 3]) -> Result<Frame> {
        let i = self.model.link_index(link)?;
        let (body, pose) = self.frames[i].ok_or_else(|| SimError::UnknownLink {
            name: link.to_string(),
            known: "links with a body or fixed to one".to_string(),
        })?;
        let shift = Isometry3::translation(offset[0], offset[1], offset[2]);
        Ok(Frame {
            body,
            offset: pose * shift,
        })
    }

    /// World pose of `frame`.
    pub fn frame_pose(&self, frame: &Frame) -> Isometry3<f64> {
        self.world
            .bodies
            .get(frame.body)
            .map_or_else(Isometry3::identity, |rb| to_isometry(rb.position()) * frame.offset)
    }

    /// World position of `frame` (e.g. a hand).
    pub fn frame_position(&self, frame: &Frame) -> [f64; 3] {
        let p = self.frame_pose(frame) * Point3::origin();
        [p.x, p.y, p.z]
    }

    /// World pose of link `link` (its URDF link frame).
    pub fn link_pose(&self, link: &str) -> Result<Isometry3<f64>> {
        Ok(self.frame_pose(&self.frame(link, [0.0; 3])?))
    }

    /// World position of link `link`'s origin (its URDF link frame).
    pub fn link_position(&self, link: &str) -> Result<[f64; 3]> {
        Ok(self.frame_position(&self.frame(link, [0.0; 3])?))
    }

    /// Each collision shape of the robot with its URDF link index and its world pose, from the
    /// bodies' poses as they are (after a reset, before a step).
    fn placed_shapes(&self) -> impl Iterator<Item = (usize, &dyn rapier3d::parry::shape::Shape, rapier3d::math::Pose)> {
        self.link_colliders.iter().filter_map(|(link, handle)| {
            let collider = self.world.colliders.get(*handle)?;
            let body = self.world.bodies.get(collider.parent()?)?;
            let pose = *body.position() * collider.position_wrt_parent().copied().unwrap_or_default();
            Some((*link, collider.shape(), pose))
        })
    }

    /// The height (m) of the robot's lowest collision point, from its bodies' poses as they are
    /// (after a reset, before a step); `None` for a robot without collision shapes.
    pub fn lowest_point(&self) -> Option<f64> {
        self.placed_shapes()
            .map(|(_, shape, pose)| f64::from(shape.compute_aabb(&pose).mins.z))
            .reduce(f64::min)
    }

    /// The lowest world point of each collision shape of link `link` that `keep` accepts (by its
    /// parry shape), from the bodies' poses as they are.
    pub fn lowest_points_of(
        &self,
        link: &str,
        keep: impl Fn(&dyn rapier3d::parry::shape::Shape) -> bool,
    ) -> Result<Vec<Point3<f64>>> {
        let index = self.model.link_index(link)?;
        let down = rapier3d::prelude::Vector::new(0.0, 0.0, -1.0);
        Ok(self
            .placed_shapes()
            .filter(|(l, shape, _)| *l == index && keep(*shape))
            .filter_map(|(_, shape, pose)| {
                let p = shape.as_support_map()?.support_point(&pose, down);
                Some(Point3::new(f64::from(p.x), f64::from(p.y), f64::from(p.z)))
            })
            .collect())
    }

    /// World poses of every URDF link, in URDF link order (`None` for a link neither with a
    /// body nor fixed to one).
    pub fn link_poses(&self) -> Vec<Option<Isometry3<f64>>> {
        self.frames
            .iter()
            .map(|f| {
                f.and_then(|(body, offset)| {
                    self.world
                        .bodies
                        .get(body)
                        .map(|rb| to_isometry(rb.position()) * offset)
                })
            })
            .collect()
    }

    /// [`World::link_poses`] as rows of [`POSE_WIDTH`] values (position, quaternion x, y, z,
    /// w), NaN for a link without a pose.
    pub fn link_pose_rows(&self) -> Vec<f64> {
        let poses = self.link_poses();
        let mut out = Vec::with_capacity(POSE_WIDTH * poses.len());
        for pose in &poses {
            match pose {
                Some(p) => {
                    out.extend(p.translation.vector.iter());
                    out.extend(p.rotation.coords.iter());
                }
                None => out.extend([f64::NAN; POSE_WIDTH]),
            }
        }
        out
    }

    /// World pose of the root link.
    pub fn base_pose(&self) -> Isometry3<f64> {
        self.world
            .bodies
            .get(self.root)
            .map_or_else(Isometry3::identity, |rb| to_isometry(rb.position()))
    }
}
