//! Measured behaviour of rapier3d / rapier3d-urdf 0.36.1 that `sim` works around.
//! If one of these fails after an upgrade, revisit the workaround named in the test.
mod common;

use rapier3d::prelude::{JointAxis, PhysicsWorld};
use rapier3d_urdf::{UrdfLoaderOptions, UrdfMultibodyOptions, UrdfRobot};

/// The two arms as a bare rapier world with a shoulder motor aimed at 0.5 rad.
fn arms_world() -> (PhysicsWorld, rapier3d::prelude::MultibodyJointHandle) {
    let options = UrdfLoaderOptions {
        make_roots_fixed: true,
        ..UrdfLoaderOptions::default()
    };
    let (robot, _) = UrdfRobot::from_file(common::TWO_ARMS, options, None).unwrap();
    let mut world = PhysicsWorld::new();
    let handles = robot.insert_using_multibody_joints(
        &mut world.bodies,
        &mut world.colliders,
        &mut world.multibody_joints,
        UrdfMultibodyOptions::DISABLE_SELF_CONTACTS,
    );
    let shoulder = handles.joints[0].joint.unwrap();
    let (mb, link) = world.multibody_joints.get_mut(shoulder).unwrap();
    let data = &mut mb.link_mut(link).unwrap().joint.data;
    data.set_motor_position(JointAxis::AngX, 0.5, 1e3, 50.0);
    (world, shoulder)
}

fn shoulder_angle(world: &PhysicsWorld, h: rapier3d::prelude::MultibodyJointHandle) -> f32 {
    let (mb, link) = world.multibody_joints.get(h).unwrap();
    mb.link(link).unwrap().joint().coords()[3]
}

#[test]
fn detect_collisions_before_the_first_step_freezes_the_robot() {
    // Workaround: `World` never calls `detect_collisions`; contact queries are
    // exact shape distances at the current poses (obstacles.rs).
    let (mut world, h) = arms_world();
    for _ in 0..60 {
        world.step();
    }
    assert!(shoulder_angle(&world, h) > 0.4, "a plain world tracks the motor");

    let (mut world, h) = arms_world();
    world.detect_collisions(&(), &());
    for _ in 0..60 {
        world.step();
    }
    assert_eq!(shoulder_angle(&world, h), 0.0, "the trap: the robot never moves");
}

#[test]
fn multibody_root_dofs_settle_only_after_forward_kinematics() {
    // Workaround: `UrdfModel::insert` runs forward kinematics before reading DoF indices.
    let (mut world, h) = arms_world();
    assert_eq!(
        world.multibody_joints.get(h).unwrap().0.ndofs(),
        6 + 4,
        "free root first"
    );
    let (mb, _) = world.multibody_joints.get_mut(h).unwrap();
    mb.forward_kinematics(&world.bodies, true);
    assert_eq!(mb.ndofs(), 4, "fixed root after forward kinematics");
}
