//! Inserting a checked [`UrdfModel`] into a rapier world with rapier3d-urdf, as
//! multibodies (reduced coordinates), and mapping URDF joints and links to rapier.

use std::path::Path;

use nalgebra::Isometry3;
use rapier3d::prelude::{
    ColliderHandle, JointAxis, MultibodyJointHandle, PhysicsWorld, RigidBodyBuilder, RigidBodyHandle,
};
use rapier3d_urdf::{UrdfCollider, UrdfLoaderOptions, UrdfMultibodyOptions, UrdfRobot, urdf_rs};

use super::{JointInfo, JointKind, RootMode, UrdfModel};
use crate::error::{Result, SimError};
use crate::pose::{origin_pose, to_pose};

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
    /// One slot per mimic joint, in the order of [`UrdfModel::mimics`].
    pub mimic_slots: Vec<JointSlot>,
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
        let mut robot = UrdfRobot::from_robot(&self.without_meshes(), options.clone(), Path::new("."));
        self.add_hull_colliders(&mut robot, &options)?;
        self.anchor_squeezed_root(&mut robot);
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

        let mut slot = |info: &JointInfo| -> Result<JointSlot> {
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
            Ok(JointSlot {
                handle,
                link_id,
                dof,
                axis,
            })
        };
        let slots = self.joints.iter().map(&mut slot).collect::<Result<Vec<_>>>()?;
        let mimic_slots = self.mimics.iter().map(|m| slot(&m.joint)).collect::<Result<Vec<_>>>()?;
        let root = self
            .root_link()
            .and_then(|i| frames[i])
            .map(|(body, _)| body)
            .ok_or_else(|| bad("the robot has no root link".to_string()))?;
        Ok(InsertedRobot {
            slots,
            mimic_slots,
            frames,
            colliders,
            root,
        })
    }

    /// The robot with every mesh collision shape replaced by an empty box, which the loader
    /// skips: the meshes become colliders from their hulls ([`Self::add_hull_colliders`]),
    /// while each link keeps its `<collision>` elements (so none is dropped as empty).
    fn without_meshes(&self) -> urdf_rs::Robot {
        let mut robot = self.robot.clone();
        for collision in robot.links.iter_mut().flat_map(|l| l.collision.iter_mut()) {
            if matches!(collision.geometry, urdf_rs::Geometry::Mesh { .. }) {
                collision.geometry = urdf_rs::Geometry::Box {
                    size: urdf_rs::Vec3([0.0; 3]),
                };
            }
        }
        robot
    }

    /// Adds a collider for each mesh hull to the loaded link that carries its URDF link.
    fn add_hull_colliders(&self, robot: &mut UrdfRobot, options: &UrdfLoaderOptions) -> Result<()> {
        for ((l, c), hull) in &self.hulls {
            let link = &self.robot.links[*l];
            let body = robot
                .links
                .iter_mut()
                .find(|b| b.urdf_link_index == *l)
                .ok_or_else(|| SimError::Mesh {
                    link: link.name.clone(),
                    path: hull.path.display().to_string(),
                    reason: "its link was not made a body".to_string(),
                    origin: self.origin.clone(),
                })?;
            let mut builder = options.collider_blueprint.clone();
            builder.shape = hull.shape.clone();
            let collider = builder
                .position(to_pose(&origin_pose(&link.collision[*c].origin)))
                .build();
            body.colliders.push(UrdfCollider { collider, visual: None });
        }
        Ok(())
    }

    /// Puts back the pose of the links an empty root link was fixed to: rapier3d-urdf 0.36.1
    /// drops such a root (a `world` or `base` frame) and anchors its fixed children at the
    /// world origin, losing the fixed joint's `<origin>` (a Kinova arm's base yaw of 90° turned
    /// the whole arm). Each such child's subtree is moved by that origin, so the URDF root stays
    /// at the world origin as the URDF says.
    fn anchor_squeezed_root(&self, robot: &mut UrdfRobot) {
        let Some(root) = self.root_link() else { return };
        if robot.links.iter().any(|l| l.urdf_link_index == root) {
            return;
        }
        let root_name = &self.robot.links[root].name;
        for joint in self.robot.joints.iter().filter(|j| &j.parent.link == root_name) {
            let origin = origin_pose(&joint.origin);
            let child = self.robot.links.iter().position(|l| l.name == joint.child.link);
            let start = robot.links.iter().position(|l| Some(l.urdf_link_index) == child);
            let (Some(start), false) = (start, origin == Isometry3::identity()) else {
                continue;
            };
            let mut subtree = vec![start];
            let mut k = 0;
            while k < subtree.len() {
                let parent = subtree[k];
                subtree.extend(robot.joints.iter().filter(|j| j.link1 == parent).map(|j| j.link2));
                k += 1;
            }
            let shift = to_pose(&origin);
            for i in subtree {
                let body = &mut robot.links[i].body;
                let moved = shift * body.position();
                body.set_position(moved, true);
            }
        }
    }

    /// The URDF link no joint moves (the first one, if the description has several).
    fn root_link(&self) -> Option<usize> {
        (0..self.robot.links.len()).find(|&i| {
            !self
                .robot
                .joints
                .iter()
                .any(|j| j.child.link == self.robot.links[i].name)
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
