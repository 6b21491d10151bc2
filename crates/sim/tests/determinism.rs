//! Same inputs, same machine, same thread count ⇒ bitwise-equal joint states.
mod common;

use nalgebra::Isometry3;
use sim::{Obstacle, ObstacleShape, World, WorldConfig};

fn run(seed: u64) -> Vec<u64> {
    let mut sim: World = common::arms(WorldConfig::default());
    let obstacle = Obstacle {
        name: "wall".to_string(),
        shape: ObstacleShape::Box {
            half_extents: [0.3, 0.035, 0.1],
        },
        pose: Isometry3::translation(-0.5, 0.335, 0.0),
        sensor: false,
    };
    sim.add_obstacle(obstacle).unwrap();
    let mut rng = common::Rng(seed);
    let mut trace = Vec::new();
    for episode in 0..3 {
        sim.reset(&rng.arms_posture()).unwrap();
        for _ in 0..20 {
            let mut target = sim.joint_positions();
            for t in &mut target {
                *t += rng.range(-0.05, 0.05);
            }
            sim.set_targets(&target).unwrap();
            sim.step_rl();
            let state = sim.joint_positions().into_iter().chain(sim.joint_velocities());
            trace.extend(state.map(f64::to_bits));
        }
        trace.push(episode);
    }
    trace
}

#[test]
fn same_sequence_twice_gives_bitwise_equal_states() {
    assert_eq!(run(3), run(3));
    assert_ne!(run(3), run(4));
}

#[test]
fn reset_to_a_posture_gives_that_posture() {
    let mut sim = common::arms(WorldConfig::default());
    let posture = [1.0, -0.8, 2.0, 0.9];
    sim.step_rl();
    sim.reset(&posture).unwrap();
    assert_eq!(sim.time(), 0.0);
    assert_eq!(sim.targets(), posture);
    for (q, p) in sim.joint_positions().iter().zip(posture) {
        assert!((q - p).abs() < 1e-6);
    }
    assert!(sim.joint_velocities().iter().all(|v| *v == 0.0));
    // Shoulder angles past π and below −π/2 (inside the limits) are kept as given.
    sim.reset(&[6.0, -3.0, -3.0, 3.0]).unwrap();
    let q = sim.joint_positions();
    assert!((q[0] - 6.0).abs() < 1e-6 && (q[2] + 3.0).abs() < 1e-6, "{q:?}");
}

#[test]
fn a_plant_can_move_to_a_worker_thread() {
    // Trials run in parallel (rayon): each builds its own plant and owns it.
    fn assert_send<T: Send>() {}
    assert_send::<World>();
    let handle = std::thread::spawn(|| {
        let mut sim = common::arms(WorldConfig::default());
        sim.step_rl();
        sim.joint_positions()
    });
    assert_eq!(handle.join().unwrap().len(), 4);
}
