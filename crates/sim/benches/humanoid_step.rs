//! The KHR-1HV-like humanoid on rapier3d 0.36.1: physics steps/s of the free-floating robot
//! standing on the ground under servo PD (docs/method.md §Experiment 3; kp 8 N·m/rad, kd 0.1
//! N·m·s/rad, ±1.2 N·m, dt 1/240), at its home posture and at the first lift demo, with the
//! humanoid's physics (1 solver iteration of 4 PGS passes, `tasks/humanoid_lift.toml`) and rapier's
//! default (4 iterations of 1 pass).
//!
//! Peer: MuJoCo on the same URDF, measured side by side in `benches/bench_sim.py`.
//! Run: `cargo bench -p sim --bench humanoid_step`.
use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use sim::fall::reset_on_ground;
use sim::{PhysicsConfig, Task, UrdfModel, World, WorldConfig};

const KHR1HV: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/khr1hv.urdf");
const TASK: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../python/latentrl/tasks/humanoid_lift.toml"
);
const DEMOS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../python/latentrl/data/khr1hv_lift_demos.csv"
);
/// Physics steps per timed iteration.
const STEPS: usize = 10;
/// Simulated time after which the robot is put back at its start (s): the tests show it
/// standing 10 s, so every timed step is of a standing robot.
const RESTART_AFTER: f64 = 10.0;

/// The humanoid in the world of the lift task with `(solver iterations, PGS passes)`.
fn humanoid((solver_iterations, pgs_iterations): (usize, usize)) -> World {
    let world = Task::load(TASK).expect("humanoid_lift.toml loads").world_config();
    let options = WorldConfig {
        physics: PhysicsConfig {
            solver_iterations,
            pgs_iterations,
            ..world.physics.clone()
        },
        ..world
    };
    World::new(UrdfModel::from_file(KHR1HV).expect("khr1hv.urdf loads"), options).expect("builds")
}

/// The first pose of the shipped (centred) lift demos: hip-hinge, straight arms.
fn lift_demo() -> Vec<f64> {
    let text = std::fs::read_to_string(DEMOS).expect("demo file");
    let row = text.lines().nth(1).expect("a pose row");
    row.split(',').map(|v| v.parse().expect("a number")).collect()
}

fn physics_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("humanoid_physics_step");
    group.throughput(Throughput::Elements(STEPS as u64));
    let home = vec![0.0; 19];
    let demo = lift_demo();
    let settings = [
        ("home_it1_pgs4", &home, (1, 4)),
        ("home_it4", &home, (4, 1)),
        ("lift_demo0_it1_pgs4", &demo, (1, 4)),
    ];
    for (label, posture, iterations) in settings {
        let mut sim = humanoid(iterations);
        let start = |sim: &mut World| {
            reset_on_ground(sim, posture, "l_foot", 0.0, 5e-4, None).expect("start posture within limits")
        };
        start(&mut sim);
        group.bench_function(BenchmarkId::from_parameter(label), |b| {
            b.iter(|| {
                if sim.time() > RESTART_AFTER {
                    start(&mut sim);
                }
                sim.step(STEPS);
                black_box(sim.base_pose())
            })
        });
        let height = sim.base_pose().translation.z;
        assert!(
            height > 0.09,
            "{label}: the robot fell during the bench (base {height} m)"
        );
    }
    group.finish();
}

criterion_group!(benches, physics_steps);
criterion_main!(benches);
