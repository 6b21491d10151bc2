//! PD servo tracking on the two-arm plant (docs/pitfalls.md §rapier3d: force-based kp 5000 / kd 50
//! track a 0.1 rad step to < 1 mrad within 0.05 s at dt ≤ 1/240).
mod common;

use sim::{PdGains, PhysicsConfig, ServoConfig, WorldConfig};

const START: [f64; 4] = [0.6, -1.2, 2.5, 1.2];

/// Largest |q − target| after `seconds` of tracking a 0.1 rad step on every joint.
fn step_error(options: WorldConfig, seconds: f64) -> f64 {
    let dt = options.physics.dt;
    let mut sim = common::arms(options);
    sim.reset(&START).unwrap();
    let target: Vec<f64> = START.iter().map(|q| q + 0.1).collect();
    sim.set_targets(&target).unwrap();
    sim.step((seconds / dt).round() as usize);
    sim.joint_positions()
        .iter()
        .zip(&target)
        .map(|(q, t)| (q - t).abs())
        .fold(0.0, f64::max)
}

#[test]
fn step_of_a_tenth_radian_settles_below_one_milliradian_in_50_ms() {
    // (dt, solver iterations): the default, a finer step, and the cheaper 2 iterations.
    for (dt, iterations) in [(1.0 / 240.0, 4), (1.0 / 500.0, 4), (1.0 / 240.0, 2)] {
        let options = WorldConfig {
            physics: PhysicsConfig {
                dt,
                solver_iterations: iterations,
                ..PhysicsConfig::default()
            },
            ..WorldConfig::default()
        };
        let err = step_error(options, 0.05);
        println!(
            "dt = 1/{:.0}, {iterations} iterations: max error after 0.05 s = {err:.3e} rad",
            1.0 / dt
        );
        assert!(err < 1e-3, "dt {dt}, {iterations} iterations: error {err} rad");
    }
}

#[test]
fn one_rl_step_is_fifty_milliseconds_and_tracks() {
    let mut sim = common::arms(WorldConfig::default());
    assert!((sim.rl_dt() - 0.05).abs() < 1e-12);
    sim.reset(&START).unwrap();
    let target = [0.7, -1.1, 2.6, 1.3];
    sim.set_targets(&target).unwrap();
    sim.step_rl();
    assert!((sim.time() - 0.05).abs() < 1e-12);
    for (q, t) in sim.joint_positions().iter().zip(target) {
        assert!((q - t).abs() < 1e-3, "{q} vs {t}");
    }
}

#[test]
fn holding_a_posture_keeps_it() {
    let mut sim = common::arms(WorldConfig::default());
    sim.reset(&START).unwrap();
    sim.step(240);
    for (q, t) in sim.joint_positions().iter().zip(START) {
        assert!((q - t).abs() < 1e-4, "{q} vs {t}");
    }
    assert!(sim.joint_velocities().iter().all(|v| v.abs() < 1e-3));
}

#[test]
fn weak_gains_and_torque_caps_slow_the_servo() {
    let weak = WorldConfig {
        servo: ServoConfig {
            kp: 1000.0,
            kd: 30.0,
            max_force: f64::INFINITY,
            ..ServoConfig::default()
        },
        ..WorldConfig::default()
    };
    let err_weak = step_error(weak, 0.05);
    let capped = WorldConfig {
        servo: ServoConfig {
            max_force: 1.0,
            ..ServoConfig::default()
        },
        ..WorldConfig::default()
    };
    let err_capped = step_error(capped, 0.05);
    println!("kp 1000 / kd 30: {err_weak:.3e} rad; kp 5000 capped at 1 N·m: {err_capped:.3e} rad");
    assert!(err_weak > 1e-3);
    assert!(err_capped > 1e-2);
}

#[test]
fn targets_are_clamped_to_the_joint_limits() {
    let mut sim = common::arms(WorldConfig::default());
    sim.set_targets(&[0.0, 5.0, 0.0, -5.0]).unwrap();
    assert_eq!(sim.targets(), [0.0, 0.3, 0.0, -0.3]);
}

#[test]
fn passive_joint_swings_freely_under_in_plane_gravity() {
    // Gravity along −y acts in the arm plane; a passive shoulder lets the arm fall.
    let options = WorldConfig {
        physics: PhysicsConfig {
            gravity: [0.0, -9.81, 0.0],
            ..PhysicsConfig::default()
        },
        ..WorldConfig::default()
    };
    let mut sim = common::arms(options);
    sim.reset(&[0.0, 0.0, 0.0, 0.0]).unwrap();
    sim.set_gains("left_shoulder", PdGains::passive()).unwrap();
    sim.step(48);
    let q = sim.joint_positions();
    assert!(q[0] < -0.1, "passive shoulder should fall, q = {q:?}");
    assert!(q[2].abs() < 1e-2, "servoed right shoulder holds, q = {q:?}");
}

#[test]
fn rapier_trap_zero_gains_with_a_torque_budget_still_lock_the_joint() {
    // rapier 0.36.1: a motor with kp = kd = 0 but an uncapped force still holds its
    // joint in place, which is why `PdGains::passive` caps the force at 0 instead.
    let options = WorldConfig {
        physics: PhysicsConfig {
            gravity: [0.0, -9.81, 0.0],
            ..PhysicsConfig::default()
        },
        ..WorldConfig::default()
    };
    let mut sim = common::arms(options);
    sim.reset(&[0.0, 0.0, 0.0, 0.0]).unwrap();
    let zero = PdGains {
        kp: 0.0,
        kd: 0.0,
        max_force: f64::INFINITY,
    };
    sim.set_gains("left_shoulder", zero).unwrap();
    sim.step(48);
    let q = sim.joint_positions();
    assert!(
        q[0].abs() < 1e-2,
        "the zero-gain motor locked the joint (the trap), q = {q:?}"
    );
}

#[test]
fn hands_follow_a_moving_target_within_a_millimetre() {
    // RL-like use: a new target every 0.05 s, each up to 0.05 rad per joint away.
    let arms = sim::PlanarArms::default();
    let mut sim = common::arms(WorldConfig::default());
    let mut rng = common::Rng(5);
    let mut target = START;
    sim.reset(&target).unwrap();
    let mut worst: f64 = 0.0;
    for _ in 0..200 {
        for t in &mut target {
            *t += rng.range(-0.05, 0.05);
        }
        sim.set_targets(&target).unwrap();
        sim.step_rl();
        let q: [f64; 4] = sim.joint_positions().try_into().unwrap();
        let (want, got) = (arms.hands(&target), arms.hands(&q));
        let per_hand = |h: &[f64; 4], i: usize| ((h[i] - want[i]).powi(2) + (h[i + 1] - want[i + 1]).powi(2)).sqrt();
        worst = worst.max(per_hand(&got, 0)).max(per_hand(&got, 2));
    }
    println!("largest hand position error after an RL step: {:.3e} m", worst);
    assert!(worst < 1e-3, "{worst}");
}
