//! Obstacles and contact queries on the two-arm plant.
mod common;

use latent_core::CoreError;
use std::f64::consts::FRAC_PI_2;

use nalgebra::Isometry3;
use sim::{Contact, Obstacle, ObstacleShape, SimError, WorldConfig};

/// Both arms straight up (+y): the left arm lies on x = −0.15, y ∈ [0, 0.6].
const UP: [f64; 4] = [FRAC_PI_2, 0.0, FRAC_PI_2, 0.0];

fn block(x: f64, y: f64, sensor: bool) -> Obstacle {
    Obstacle {
        name: "block".to_string(),
        shape: ObstacleShape::Box {
            half_extents: [0.05, 0.05, 0.1],
        },
        pose: Isometry3::translation(x, y, 0.0),
        sensor,
    }
}

#[test]
fn arm_driven_into_a_box_touches_it_and_a_far_box_is_untouched() {
    let mut sim = common::arms(WorldConfig::default());
    let near = sim.add_obstacle(block(-0.35, 0.45, false)).unwrap();
    let far = sim.add_obstacle(block(1.0, 1.0, false)).unwrap();
    sim.reset(&UP).unwrap();
    assert!(!sim.touching("left_forearm", near).unwrap());
    assert!(!sim.any_obstacle_contact());
    sim.set_target("left_shoulder", FRAC_PI_2 + 0.5).unwrap();
    for _ in 0..10 {
        sim.step_rl();
    }
    assert!(sim.touching("left_forearm", near).unwrap());
    assert!(!sim.touching("left_forearm", far).unwrap());
    assert!(!sim.touching("right_forearm", near).unwrap());
    assert!(sim.contacts().contains(&Contact {
        link: "left_forearm".to_string(),
        obstacle: near
    }));
    assert!(
        sim.contacts()
            .iter()
            .all(|c| c.obstacle == near && c.link.starts_with("left"))
    );
    // The solid box stops the arm short of its target.
    assert!(
        sim.joint_positions()[0] < FRAC_PI_2 + 0.45,
        "{:?}",
        sim.joint_positions()
    );
}

#[test]
fn sensor_obstacle_reports_overlap_without_blocking() {
    let mut sim = common::arms(WorldConfig::default());
    let id = sim.add_obstacle(block(-0.35, 0.45, true)).unwrap();
    sim.reset(&UP).unwrap();
    assert!(!sim.touching("left_forearm", id).unwrap());
    sim.set_target("left_shoulder", FRAC_PI_2 + 0.5).unwrap();
    for _ in 0..4 {
        sim.step_rl();
    }
    assert!((sim.joint_positions()[0] - (FRAC_PI_2 + 0.5)).abs() < 1e-3);
    assert!(sim.touching("left_forearm", id).unwrap());
    assert_eq!(sim.obstacle_distance("left_forearm", id).unwrap(), 0.0);
    assert!(!sim.touching("right_forearm", id).unwrap());
}

#[test]
fn contacts_follow_a_reset_at_once() {
    let mut sim = common::arms(WorldConfig::default());
    let id = sim.add_obstacle(block(-0.15, 0.3, true)).unwrap();
    sim.reset(&UP).unwrap();
    assert!(sim.touching("left_upper_arm", id).unwrap());
    sim.step_rl();
    assert!(sim.touching("left_upper_arm", id).unwrap());
    // Arms pointing down (−y): far from the block, no stale contact from before.
    sim.reset(&[-FRAC_PI_2, 0.0, -FRAC_PI_2, 0.0]).unwrap();
    assert!(!sim.any_obstacle_contact());
    let d = sim.obstacle_distance("left_hand", id);
    assert!(
        matches!(d, Ok(x) if x == f64::INFINITY),
        "a body-less frame has no shape: {d:?}"
    );
    let gap = sim.obstacle_distance("left_upper_arm", id).unwrap();
    // The capsule ends at y = 0, the block starts at y = 0.25. parry's capsule–box
    // distance (GJK) reads ≈ 0.4 mm long on 0.36.1 / parry 0.31.
    assert!(
        (gap - 0.25).abs() < 2e-3,
        "gap from y = 0 to the block at y = 0.25: {gap}"
    );
}

#[test]
fn ground_contact_and_bad_obstacles() {
    let options = WorldConfig {
        floor: Some(-0.01),
        ..WorldConfig::default()
    };
    let mut sim = common::arms(options);
    sim.step(2);
    assert!(sim.touching_ground("left_forearm").unwrap());
    assert!(
        !common::arms(WorldConfig::default())
            .touching_ground("left_forearm")
            .unwrap()
    );
    let bad = Obstacle {
        shape: ObstacleShape::Sphere { radius: -1.0 },
        ..block(0.0, 0.0, false)
    };
    assert!(matches!(
        sim.add_obstacle(bad),
        Err(SimError::Input(CoreError::InvalidParameter { name: "radius", .. }))
    ));
    assert!(matches!(
        sim.touching("left_forearm", 7),
        Err(SimError::UnknownObstacle { id: 7, count: 0 })
    ));
    assert!(matches!(
        sim.touching("nose", 0),
        Err(SimError::UnknownObstacle { .. } | SimError::UnknownLink { .. })
    ));
}
