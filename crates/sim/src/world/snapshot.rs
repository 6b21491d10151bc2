//! A world's state saved and restored in place (issue #20): what a fresh build gives, without
//! parsing the URDF and inserting the bodies again. Only rapier's data sets are kept (bodies,
//! colliders, joints, islands, broad and narrow phase: contact warm starts included); its
//! pipelines are workspace that each step refills. `tests/task_humanoid_lift.rs` checks that
//! episodes after a restore are bit-identical to episodes after a fresh build.

use rapier3d::prelude::{
    BroadPhaseBvh, ColliderSet, ImpulseJointSet, IslandManager, MultibodyJointSet, NarrowPhase, RigidBodySet,
    SoftBodySet,
};

use super::World;
use crate::pd::PdGains;

/// The state of a [`World`] at one moment; [`World::restore`] puts it back.
#[derive(Clone)]
pub struct WorldSnapshot {
    islands: IslandManager,
    broad_phase: BroadPhaseBvh,
    narrow_phase: NarrowPhase,
    bodies: RigidBodySet,
    colliders: ColliderSet,
    impulse_joints: ImpulseJointSet,
    multibody_joints: MultibodyJointSet,
    soft_bodies: SoftBodySet,
    gains: Vec<PdGains>,
    targets: Vec<f64>,
    time: f64,
}

impl World {
    /// The world's state now (bodies, joints, contacts, servo gains and targets, time).
    pub fn snapshot(&self) -> WorldSnapshot {
        let w = &self.world;
        WorldSnapshot {
            islands: w.islands.clone(),
            broad_phase: w.broad_phase.clone(),
            narrow_phase: w.narrow_phase.clone(),
            bodies: w.bodies.clone(),
            colliders: w.colliders.clone(),
            impulse_joints: w.impulse_joints.clone(),
            multibody_joints: w.multibody_joints.clone(),
            soft_bodies: w.soft_bodies.clone(),
            gains: self.gains.clone(),
            targets: self.targets.clone(),
            time: self.time,
        }
    }

    /// Puts back a state of this same world taken by [`World::snapshot`] (its handles stay valid:
    /// the sets are the ones it was built with).
    pub fn restore(&mut self, s: &WorldSnapshot) {
        let w = &mut self.world;
        w.islands.clone_from(&s.islands);
        w.broad_phase.clone_from(&s.broad_phase);
        w.narrow_phase.clone_from(&s.narrow_phase);
        w.bodies.clone_from(&s.bodies);
        w.colliders.clone_from(&s.colliders);
        w.impulse_joints.clone_from(&s.impulse_joints);
        w.multibody_joints.clone_from(&s.multibody_joints);
        w.soft_bodies.clone_from(&s.soft_bodies);
        self.gains.clone_from(&s.gains);
        self.targets.clone_from(&s.targets);
        self.time = s.time;
    }
}
