//! Two planar arms on rapier3d 0.36.1: physics steps/s and RL steps/s (SPEC §4.2).
//!
//! Peers (PEERS.md): MuJoCo 4.1 µs per step (dt 2 ms), rapier's PyPI wheel 2.4 µs.
//! Run: `cargo bench -p sim --bench arms_step`.
use std::hint::black_box;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::Isometry3;
use sim::{Obstacle, ObstacleShape, PhysicsSim, SimOptions};

const TWO_ARMS: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../python/latentrl/data/two_arms.urdf"
);
const START: [f64; 4] = [0.6, -1.2, 2.5, 1.2];

fn arms(options: SimOptions) -> PhysicsSim {
    let mut sim = PhysicsSim::from_urdf_file(TWO_ARMS, options).expect("two_arms.urdf loads");
    // The SPEC §4.2 corridor: two boxes, y ∈ [0.30, 0.37].
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
fn wiggle(sim: &mut PhysicsSim, k: usize) {
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
        let mut sim = arms(SimOptions {
            dt,
            solver_iterations: iterations,
            ..SimOptions::default()
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
    let options = SimOptions::default();
    let label = format!("substeps{}_dt1/240", options.substeps);
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

criterion_group!(benches, physics_steps, rl_steps);
criterion_main!(benches);
