//! Two planar arms on rapier3d 0.36.1: physics steps/s and RL steps/s
//! (docs/method.md §Experiment 2), and the two-arms task's plant ([`sim::TaskPlant`],
//! `tasks/two_arms.toml`) alone and inside a latent learner's step.
//!
//! Peers (benches/README.md §Peer figures): MuJoCo 4.1 µs per step (dt 2 ms), rapier's PyPI wheel
//! 2.4 µs; MuJoCo on the same URDF and settings is measured side by side in `benches/bench_sim.py`.
//! Run: `cargo bench -p sim --bench arms_step`.
use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use std::sync::Arc;

use latent_core::trials::LatentSpace;
use latent_core::{GpMap, Learner, Plant, SeKernel};
use nalgebra::{DMatrix, Isometry3};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use sim::{Obstacle, ObstacleShape, PhysicsConfig, PlanarArms, Task, TaskPlant, World, WorldConfig};

const TWO_ARMS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/two_arms.urdf");
const TASK: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/tasks/two_arms.toml");

/// The two-arms task with `iterations` solver iterations and the grip `tolerance`.
fn task(iterations: usize, tolerance: f64) -> Arc<Task> {
    let base = Task::load(TASK).expect("two_arms.toml loads");
    let mut config = base.config().clone();
    config.physics.solver_iterations = iterations;
    config.constraints[0].tolerance = Some(tolerance);
    Arc::new(Task::new(config, base.model().clone(), "two_arms").expect("a valid task"))
}
const START: [f64; 4] = [0.6, -1.2, 2.5, 1.2];

fn arms(options: WorldConfig) -> World {
    let mut sim = World::from_urdf_file(TWO_ARMS, options).expect("two_arms.urdf loads");
    // Experiment 2's corridor (docs/method.md §Experiment 2): two boxes, y ∈ [0.30, 0.37].
    for (x0, x1) in [(-1.0, -0.36), (-0.06, 1.0)] {
        let wall = Obstacle {
            name: "corridor".to_string(),
            shape: ObstacleShape::Box {
                half_extents: [(x1 - x0) / 2.0, 0.035, 0.05],
            },
            pose: Isometry3::translation((x0 + x1) / 2.0, 0.335, 0.0),
            sensor: true,
        };
        sim.add_obstacle(wall).expect("valid wall");
    }
    sim.reset(&START).expect("start posture within limits");
    sim
}

/// Alternating targets so the servos keep working (a still robot is cheaper).
fn wiggle(sim: &mut World, k: usize) {
    let d = if k.is_multiple_of(2) { 0.05 } else { -0.05 };
    let target = [START[0] + d, START[1] - d, START[2] + d, START[3] + d];
    sim.set_targets(&target).expect("finite targets");
}

fn physics_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("arms_physics_step");
    // rapier's solver iterations are TGS sub-steps: cost grows with them, and dt 1/240
    // with 4 iterations tracks like dt 1/960 with 1 (tests/pd_tracking.rs).
    let settings = [
        ("dt1/240_it4", 1.0 / 240.0, 4),
        ("dt1/240_it2", 1.0 / 240.0, 2),
        ("dt1/240_it1", 1.0 / 240.0, 1),
        ("dt1/120_it4", 1.0 / 120.0, 4),
    ];
    for (label, dt, iterations) in settings {
        let mut sim = arms(WorldConfig {
            physics: PhysicsConfig {
                dt,
                solver_iterations: iterations,
                ..PhysicsConfig::default()
            },
            ..WorldConfig::default()
        });
        let mut k = 0;
        group.throughput(Throughput::Elements(100));
        group.bench_function(BenchmarkId::from_parameter(label), |b| {
            b.iter(|| {
                k += 1;
                wiggle(&mut sim, k);
                sim.step(100);
                black_box(sim.joint_positions())
            })
        });
    }
    group.finish();
}

fn rl_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("arms_rl_step");
    let options = WorldConfig::default();
    let label = format!("substeps{}_dt1/240", options.physics.substeps);
    let mut sim = arms(options);
    let left = sim.frame("left_hand", [0.0; 3]).expect("hand frame");
    let right = sim.frame("right_hand", [0.0; 3]).expect("hand frame");
    let mut k = 0;
    group.throughput(Throughput::Elements(1));
    // One full RL-step plant call: targets, 12 sub-steps, posture, hands, contact check.
    group.bench_function(BenchmarkId::from_parameter(label), |b| {
        b.iter(|| {
            k += 1;
            wiggle(&mut sim, k);
            sim.step_rl();
            let q = sim.joint_positions();
            let hands = (sim.frame_position(&left), sim.frame_position(&right));
            black_box((q, hands, sim.any_obstacle_contact()))
        })
    });
    group.bench_function("reset", |b| {
        b.iter(|| sim.reset(black_box(&START)).expect("valid posture"))
    });
    group.finish();
}

/// Posture holding the object with the left hand at `(x, y)`.
fn holding(x: f64, y: f64) -> [f64; 4] {
    PlanarArms::default()
        .inverse(&[x, y, x + 0.1, y], 0)
        .expect("reachable")
}

/// One `Plant::step` of the two-arms task's plant (targets, sub-steps, joints, hands, walls,
/// grip, reward) at 2 (the task's) and 4 solver iterations.
fn arms_plant_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("arms_plant_step");
    group.throughput(Throughput::Elements(1));
    let start = holding(-0.2, 0.2);
    for iterations in [2, 4] {
        let mut plant = TaskPlant::new(task(iterations, 0.005), None).expect("plant builds");
        plant.reset(&start);
        let targets = [holding(-0.19, 0.2), holding(-0.2, 0.2)];
        let mut reached = [0.0; 4];
        let mut k = 0;
        group.bench_function(BenchmarkId::from_parameter(format!("it{iterations}")), |b| {
            b.iter(|| {
                k += 1;
                black_box(plant.step(&targets[k % 2], &mut reached))
            })
        });
    }
    group.finish();
}

/// One full latent RL step (docs/method.md §RL loop: look-ahead over 8 actions, decode, plant,
/// encode, TD update) on GP maps over a 9 × 9 latent grid of gap-crossing postures.
fn arms_learner_step(c: &mut Criterion) {
    let side = 9;
    let n = side * side;
    let z = DMatrix::from_fn(2, n, |i, j| {
        (if i == 0 { j % side } else { j / side }) as f64 / (side - 1) as f64
    });
    let mut x = DMatrix::zeros(4, n);
    for j in 0..n {
        x.column_mut(j)
            .copy_from_slice(&holding(-0.3 + 0.2 * z[(0, j)], 0.12 + 0.33 * z[(1, j)]));
    }
    let kernel = SeKernel::new([1.0, 0.1, 1e-6]).expect("valid kernel");
    let decoder = GpMap::new(z.clone(), x.clone(), kernel).expect("decoder");
    let encoder = GpMap::new(x, z, kernel).expect("encoder");
    let latent = LatentSpace {
        decoder: &decoder,
        encoder: &encoder,
        low: vec![0.0, 0.0],
        high: vec![1.0, 1.0],
    };
    let task = task(2, 0.02);
    let mut plant = TaskPlant::new(Arc::clone(&task), None).expect("plant builds");
    let space = latent.space();
    let mut learner =
        Learner::new(&task.config().learner, task.episode_rules(), &latent.low, &latent.high).expect("learner");
    let mut scratch = learner.scratch(&space, 4);
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    learner
        .start(&mut plant, &space, &mut rng, &mut scratch)
        .expect("a start");
    let mut group = c.benchmark_group("arms_learner_step");
    group.throughput(Throughput::Elements(1));
    group.bench_function("latent_8_actions_it2", |b| {
        b.iter(|| {
            let r = learner.step(&mut plant, &space, &mut rng, &mut scratch);
            if r.end.is_some() {
                learner
                    .start(&mut plant, &space, &mut rng, &mut scratch)
                    .expect("a start");
            }
            black_box(r)
        })
    });
    group.finish();
}

criterion_group!(benches, physics_steps, rl_steps, arms_plant_steps, arms_learner_step);
criterion_main!(benches);
