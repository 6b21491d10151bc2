//! Inserting a checked [`UrdfModel`] into a rapier world with rapier3d-urdf, as
//! multibodies (reduced coordinates), and mapping URDF joints and links to rapier.

use std::path::Path;

use nalgebra::Isometry3;
use rapier3d::prelude::{
    ColliderHandle, JointAxis, MultibodyJointHandle, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
};
use rapier3d_urdf::{UrdfLoaderOptions, UrdfMultibodyOptions, UrdfRobot, urdf_rs};

use super::{JointKind, RootMode, UrdfModel};
use crate::error::{Result, SimError};
use crate::pose::origin_pose;

/// Where one actuated joint lives inside the rapier multibody.
#[derive(Debug, Clone, Copy)]
pub(crate) struct JointSlot {
    /// Handle of the multibody joint (also finds the multibody).
    pub handle: MultibodyJointHandle,
    /// Index of the joint's link inside its multibody.
    pub link_id: usize,
    /// Index of the DoF in the multibody's generalized velocity / damping vectors.
    pub dof: usize,
    /// The rapier axis of the DoF (the loader maps the URDF axis onto local X).
    pub axis: JointAxis,
}

/// The rapier objects made from a [`UrdfModel`].
pub(crate) struct InsertedRobot {
    /// One slot per actuated joint, in URDF order.
    pub slots: Vec<JointSlot>,
    /// Per URDF link: the rigid body carrying it and the link frame in that body's frame
    /// (identity unless the loader folded a body-less link into its neighbour).
    pub frames: Vec<Option<(RigidBodyHandle, Isometry3<f64>)>>,
    /// `(URDF link index, collider)` for every collision shape.
    pub colliders: Vec<(usize, ColliderHandle)>,
    /// The root link's rigid body.
    pub root: RigidBodyHandle,
}

impl UrdfModel {
    /// Inserts the robot into `world` as multibodies and maps joints and links to rapier.
    ///
    /// Bodies never sleep (a sleeping robot ignores new motor targets). The multibodies'
    /// root DoFs are settled here with one forward-kinematics pass, so DoF indices are
    /// final before the first step.
    pub(crate) fn insert(
        &self,
        world: &mut PhysicsWorld,
        root: RootMode,
        self_collisions: bool,
    ) -> Result<InsertedRobot> {
        let bad = |reason: String| SimError::MalformedUrdf {
            origin: self.origin.clone(),
            reason,
        };
        let options = UrdfLoaderOptions {
            make_roots_fixed: root == RootMode::Fixed,
            rigid_body_blueprint: RigidBodyBuilder::dynamic().can_sleep(false),
            ..UrdfLoaderOptions::default()
        };
        let robot = UrdfRobot::from_robot(&self.robot, options, Path::new("."));
        let link_ids: Vec<usize> = robot.links.iter().map(|l| l.urdf_link_index).collect();
        let joint_ids: Vec<(usize, Vec<usize>)> = robot
            .joints
            .iter()
            .map(|j| (j.urdf_joint_index, j.merged_urdf_joint_indices.clone()))
            .collect();
        let flags = if self_collisions {
            UrdfMultibodyOptions::empty()
        } else {
            UrdfMultibodyOptions::DISABLE_SELF_CONTACTS
        };
        let handles = robot.insert_using_multibody_joints(
            &mut world.bodies,
            &mut world.colliders,
            &mut world.multibody_joints,
            flags,
        );

        let n_links = self.robot.links.len();
        let mut frames: Vec<Option<(RigidBodyHandle, Isometry3<f64>)>> = vec![None; n_links];
        let mut colliders = Vec::new();
        for (link, urdf_index) in handles.links.iter().zip(&link_ids) {
            frames[*urdf_index] = Some((link.body, Isometry3::identity()));
            colliders.extend(link.colliders.iter().map(|c| (*urdf_index, c.handle)));
        }
        self.resolve_folded_frames(&mut frames);

        let mut slots = Vec::with_capacity(self.joints.len());
        for info in &self.joints {
            let urdf_joint = self.robot.joints.iter().position(|j| j.name == info.name);
            let k = joint_ids
                .iter()
                .position(|(id, merged)| Some(*id) == urdf_joint || merged.iter().any(|m| Some(*m) == urdf_joint));
            let handle = k
                .and_then(|k| handles.joints[k].joint)
                .ok_or_else(|| bad(format!("joint {:?} could not be inserted (kinematic loop?)", info.name)))?;
            let (mb, link_id) = world
                .multibody_joints
                .get_mut(handle)
                .ok_or_else(|| bad(format!("joint {:?} has no multibody", info.name)))?;
            mb.forward_kinematics(&world.bodies, true);
            mb.update_rigid_bodies(&mut world.bodies, true);
            let axis = match info.kind {
                JointKind::Prismatic => JointAxis::LinX,
                _ => JointAxis::AngX,
            };
            let dof = mb.link(link_id).map_or(0, |l| l.assembly_id());
            slots.push(JointSlot {
                handle,
                link_id,
                dof,
                axis,
            });
        }
        let parentless = (0..n_links).find(|&i| {
            !self
                .robot
                .joints
                .iter()
                .any(|j| j.child.link == self.robot.links[i].name)
        });
        let root = parentless
            .and_then(|i| frames[i])
            .map(|(body, _)| body)
            .ok_or_else(|| bad("the robot has no root link".to_string()))?;
        Ok(InsertedRobot {
            slots,
            frames,
            colliders,
            root,
        })
    }

    /// Places body-less links (folded away by the loader) relative to a neighbour body
    /// through the fixed joints that attached them.
    fn resolve_folded_frames(&self, frames: &mut [Option<(RigidBodyHandle, Isometry3<f64>)>]) {
        let index = |name: &str| self.robot.links.iter().position(|l| l.name == name);
        let mut progress = true;
        while progress {
            progress = false;
            for joint in self
                .robot
                .joints
                .iter()
                .filter(|j| j.joint_type == urdf_rs::JointType::Fixed)
            {
                let (Some(parent), Some(child)) = (index(&joint.parent.link), index(&joint.child.link)) else {
                    continue;
                };
                let origin = origin_pose(&joint.origin);
                match (frames[parent], frames[child]) {
                    (Some((body, pose)), None) => frames[child] = Some((body, pose * origin)),
                    (None, Some((body, pose))) => frames[parent] = Some((body, pose * origin.inverse())),
                    _ => continue,
                }
                progress = true;
            }
        }
    }
}
