//! The KHR-1HV-like humanoid (`python/latentrl/data/khr1hv.urdf`, docs/method.md §Experiment 3)
//! stands under servo-like PD at its home posture, and the shipped lift demos hold still.
use std::time::Instant;

mod common;

use common::humanoid_world as sim_options;
use sim::fall::{reset_on_ground, support_margin};
use sim::fallcheck::{FallCheckConfig, run_fall_check, run_fall_check_observed};
use sim::{PhysicsConfig, UrdfModel, World, WorldConfig};

const KHR1HV: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/khr1hv.urdf");

/// The humanoid with the world of the humanoid lift task (`sim_options`), or other iterations.
fn humanoid(options: WorldConfig) -> World {
    World::new(UrdfModel::from_file(KHR1HV).expect("khr1hv.urdf loads"), options).expect("builds")
}

/// rapier's default solver (4 iterations of 1 PGS pass) with the humanoid's servos.
fn rapier_default() -> WorldConfig {
    WorldConfig {
        physics: PhysicsConfig {
            solver_iterations: 4,
            pgs_iterations: 1,
            ..sim_options().physics
        },
        ..sim_options()
    }
}

/// Postures of a shipped demo CSV (header of joint names in URDF order, one row each).
fn demos(file: &str) -> Vec<Vec<f64>> {
    let path = format!("{}/../../python/latentrl/data/{file}", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(path).expect("demo file");
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let sim = humanoid(sim_options());
    let names = sim.model().joint_names();
    assert_eq!(header, names, "columns in URDF joint order");
    lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

#[test]
fn model_has_the_documented_size_and_mass() {
    let mut sim = humanoid(sim_options());
    assert_eq!(sim.num_joints(), 19);
    let home = vec![0.0; 19];
    reset_on_ground(&mut sim, &home, "l_foot", 0.0, 0.0, None).unwrap();
    let head = sim.link_pose("head").unwrap().translation.z + 0.06;
    assert!((0.339..=0.40).contains(&head), "height {head}");
    let l = sim.link_pose("l_foot").unwrap().translation;
    assert!(l.z > 0.029 && l.z < 0.031, "ankle 3 cm above the sole: {l:?}");
}

#[test]
fn every_demo_pose_holds_for_two_seconds() {
    for (file, heel) in [("khr1hv_lift_demos.csv", 0.045), ("khr1hv_lift_demos_heel.csv", 0.016)] {
        for (i, pose) in demos(file).iter().enumerate() {
            let mut sim = humanoid(sim_options());
            let config = FallCheckConfig::for_task(&common::task("humanoid_lift"), 2.0).unwrap();
            reset_on_ground(&mut sim, pose, "l_foot", 0.0, 0.0, None).unwrap();
            let kinematic = support_margin(&sim, &config.soles).unwrap();
            let r = &run_fall_check(&mut sim, pose, std::slice::from_ref(pose), &config).unwrap()[0];
            eprintln!(
                "{file} pose {i}: kinematic margin {kinematic:.4}, sim min {:.4} final {:.4}, grip {:+.4}, base {:.3}, tilt {:.3}, fell {}",
                r.min_margin, r.final_margin, r.grip_error, r.status.base_height, r.status.sole_tilt, r.fell
            );
            assert!((kinematic - heel).abs() < 2e-3, "{file} pose {i}: margin {kinematic}");
            assert!(!r.fell && r.min_margin > 0.005, "{file} pose {i}: {r:?}");
        }
    }
}

/// The requirement: 10 s of standing at the home posture under the servo PD, with
/// the task's physics (dt 1/120 s, 2 solver iterations of 4 PGS passes since 2026-12-03) and
/// rapier's default (4 iterations of 1 pass) at the same dt. Also prints the physics cost per
/// step; the task's must hold the base within 3 mm (measured 2.0 mm; 4 × 1: 6.1 mm; at the
/// dt 1/240 with 1 × 4 shipped before: 0.9 mm, 4 × 1: 2.3 mm, 1 × 1: 19 mm).
#[test]
fn stands_for_ten_seconds_at_home_posture() {
    for options in [sim_options(), rapier_default()] {
        let physics = (options.physics.solver_iterations, options.physics.pgs_iterations);
        let mut sim = humanoid(options.clone());
        let home = vec![0.0; 19];
        reset_on_ground(&mut sim, &home, "l_foot", 0.0, 5e-4, None).unwrap();
        let start = sim.base_pose().translation;
        let config = FallCheckConfig::for_task(&common::task("humanoid_lift"), 10.0).unwrap();
        let report = run_fall_check(&mut sim, &home, std::slice::from_ref(&home), &config).unwrap();
        let end = sim.base_pose().translation;
        let drift = (end.x - start.x).hypot(end.y - start.y);
        let t = Instant::now();
        sim.step(240);
        let per_step = t.elapsed().as_secs_f64() / 240.0;
        eprintln!(
            "iterations × PGS passes {physics:?}: {:.0} µs per physics step; after 10 s: {:?}, base drift {:.1} mm",
            per_step * 1e6,
            report[0],
            1e3 * drift,
        );
        assert!(!report[0].fell, "{report:?}");
        assert!(report[0].min_margin > 0.03, "{report:?}");
        assert!(report[0].status.sole_tilt < 0.02, "{report:?}");
        if options == sim_options() {
            assert!(drift < 3e-3, "base drifted {drift} m");
        }
    }
}

/// The observer sees the reset and every check, at increasing times, and observing does not
/// change what the check reports.
#[test]
fn observed_fall_check_reports_what_the_plain_one_does() {
    let home = vec![0.0; 19];
    let config = FallCheckConfig::for_task(&common::task("humanoid_lift"), 0.5).unwrap();
    let plain = run_fall_check(
        &mut humanoid(sim_options()),
        &home,
        &[home.clone(), home.clone()],
        &config,
    )
    .unwrap();
    let mut seen = Vec::new();
    let mut sim = humanoid(sim_options());
    let observed = run_fall_check_observed(&mut sim, &home, &[home.clone(), home.clone()], &config, |sim, fell| {
        seen.push((sim.time(), fell, sim.base_pose().translation.z))
    })
    .unwrap();
    assert_eq!(plain, observed);
    let per_segment = (0.5 / common::humanoid_world().physics.dt).round() as usize / config.check_every;
    assert_eq!(seen.len(), 1 + 2 * per_segment);
    assert_eq!(seen[0].0, 0.0);
    assert!(seen.windows(2).all(|w| w[1].0 > w[0].0));
    assert!((seen.last().unwrap().0 - 1.0).abs() < 1e-9, "{:?}", seen.last());
    assert!(seen.iter().all(|&(_, fell, _)| !fell) && observed[1].fall_time.is_none());
    assert_eq!(seen.last().unwrap().2, observed[1].status.base_height);
}
