//! The humanoid lift task (`tasks/humanoid_lift.toml`, docs/method.md §Experiment 3) on the generic
//! task plant: the humanoid holds a demo pose without falling, a path into the obstacle ends on a
//! contact, spreading the arms drops the object, starts are refused where they must be, an episode
//! does not depend on the one before, and whole trials repeat bitwise on 1 and 2 threads.
mod common;

use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::trials::{LatentSpace, TrialOptions, TrialResult};
use latent_core::{EndReason, GpMap, LearnerConfig, Plant, SeKernel};
use nalgebra::DMatrix;
use rand::SeedableRng;
use sim::task::TaskTrials;
use sim::{Task, TaskPlant};

/// Steps `n` RL steps along the joint-space line `from → to`; returns the outcomes until
/// the first end.
fn walk(p: &mut TaskPlant, from: &[f64], to: &[f64], n: usize) -> Vec<(f64, Option<EndReason>)> {
    let mut reached = vec![0.0; from.len()];
    let mut out = Vec::new();
    for k in 1..=n {
        let t = k as f64 / n as f64;
        let target: Vec<f64> = from.iter().zip(to).map(|(a, b)| a + t * (b - a)).collect();
        let o = p.step(&target, &mut reached);
        out.push((o.reward, o.end));
        if o.end.is_some() {
            break;
        }
    }
    out
}

#[test]
fn starts_are_refused_in_the_obstacle_and_the_target_is_the_top_demo() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    let ends: Vec<Option<EndReason>> = d.iter().map(|q| p.reset(q)).collect();
    let obstacle = Some(EndReason::Obstacle);
    assert_eq!(
        ends,
        vec![obstacle, obstacle, obstacle, None, None, None, None],
        "demos 0-2 touch the box"
    );
    p.reset(&d[6]);
    // h* from the left sole (`target.relative_to`): demo 6's hands stand on it.
    for (a, b) in p.effectors().iter().zip(&p.target_position()) {
        assert!((a - b).abs() < 1e-6, "{:?} vs the task's target", p.effectors());
    }
    assert!(p.reached_target());
    let mut q = d[6].clone();
    q[0] = 10.0;
    assert_eq!(p.reset(&q), Some(EndReason::BoxExit), "outside the joint limits");
    let mut row = vec![0.0; p.task_dim()];
    p.reset(&d[4]);
    p.task_position(&mut row);
    assert_eq!(row.len(), 6 + 7 + 19);
    assert_eq!(&row[13..], &p.world().joint_positions()[..]);
    assert!(
        (row[9..13].iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-6,
        "unit quaternion"
    );
}

#[test]
fn a_demo_start_is_the_start_demo_plus_noise() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    assert_eq!(p.home(), &d[4][..], "episode.start_demo = 4");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut q = vec![0.0; 19];
    p.sample_start(&mut rng, &mut q);
    assert!(q.iter().zip(&d[4]).all(|(a, b)| (a - b).abs() <= 0.01 + 1e-12));
    assert!(q.iter().zip(&d[4]).any(|(a, b)| a != b));
    assert!(
        TaskPlant::new(task.clone(), Some(&d[..3])).is_err(),
        "no demo 4 among 3"
    );
}

#[test]
fn a_held_squat_pose_neither_falls_nor_drops() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    for i in [4, 6] {
        assert_eq!(p.reset(&d[i]), None);
        let out = walk(&mut p, &d[i], &d[i], 40);
        assert_eq!(out.len(), 40, "demo {i} ended early: {:?}", out.last());
        assert!(out.iter().all(|(r, _)| (0.0..=1.0).contains(r)));
        if i == 6 {
            assert!(
                out.last().unwrap().0 > 0.9,
                "holding the top pose: reward {:?}",
                out.last()
            );
        }
    }
}

#[test]
fn a_path_into_the_obstacle_ends_on_contact() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    assert_eq!(p.reset(&d[3]), None);
    let out = walk(&mut p, &d[3], &d[1], 30);
    let (reward, end) = *out.last().unwrap();
    assert_eq!(end, Some(EndReason::Obstacle), "{out:?}");
    assert!(reward < 0.0, "penalty added: {reward}");
}

#[test]
fn spreading_the_arms_drops_the_object() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    assert_eq!(p.reset(&d[6]), None);
    let mut open = d[6].clone();
    for (i, name) in task.model().joint_names().iter().enumerate() {
        if name.ends_with("shoulder_roll") {
            open[i] = 0.0;
        }
    }
    let out = walk(&mut p, &d[6], &open, 20);
    assert_eq!(out.last().unwrap().1, Some(EndReason::Drop), "{out:?}");
}

#[test]
fn an_episode_does_not_depend_on_the_one_before() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    p.reset(&d[5]);
    let first = walk(&mut p, &d[5], &d[6], 10);
    // Another episode in between, then the first again on the same plant.
    p.reset(&d[4]);
    walk(&mut p, &d[4], &d[3], 10);
    p.reset(&d[5]);
    let again = walk(&mut p, &d[5], &d[6], 10);
    assert_eq!(first, again);
    // The reset restores a snapshot of the world as built: a new plant, its world just built,
    // gives the same bits (Exp 3 quick's arrays are also unchanged against rebuilding per episode).
    let mut fresh = TaskPlant::new(task.clone(), Some(&d)).unwrap();
    fresh.reset(&d[5]);
    assert_eq!(
        walk(&mut fresh, &d[5], &d[6], 10),
        first,
        "a new plant vs episodes on a restored world"
    );
}

/// GP maps through the 7 demos on a hand-made latent layout: z0 = style (−1 hinge, 1 squat),
/// z1 = progress of the lift in [0, 1].
fn demo_maps() -> (GpMap, GpMap) {
    let d = common::lift_demos();
    let latent = [
        (-1.0, 0.0),
        (-1.0, 1.0 / 3.0),
        (-1.0, 2.0 / 3.0),
        (-1.0, 1.0),
        (1.0, 0.0),
        (1.0, 0.5),
        (1.0, 1.0),
    ];
    let z = DMatrix::from_fn(2, 7, |i, j| if i == 0 { latent[j].0 } else { latent[j].1 });
    let x = DMatrix::from_fn(19, 7, |i, j| d[j][i]);
    (
        GpMap::new(z.clone(), x.clone(), SeKernel::new([1.0, 1.0, 1e-6]).unwrap()).unwrap(),
        GpMap::new(x, z, SeKernel::new([1.0, 0.5, 1e-4]).unwrap()).unwrap(),
    )
}

fn run(threads: usize, task: &std::sync::Arc<Task>, decoder: &GpMap, encoder: &GpMap) -> Vec<TrialResult> {
    // The learner's step and the episode length of this test, through the task's own keys.
    let mut config = task.config().clone();
    config.learner = LearnerConfig {
        step: 0.5,
        ..config.learner
    };
    config.episode.max_steps = 8;
    let task =
        std::sync::Arc::new(Task::from_config(config, std::path::Path::new(common::TASKS), task.origin()).unwrap());
    let latent = LatentSpace {
        decoder,
        encoder,
        low: vec![-1.2, -0.1],
        high: vec![1.2, 1.1],
    };
    let options = TrialOptions {
        n_trials: 2,
        episodes: 3,
        base_seed: 3,
        record_episodes: vec![2],
        ..TrialOptions::default()
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let done = AtomicUsize::new(0);
    let demos = common::lift_demos();
    let trials = TaskTrials::new(task, Some(&demos), &latent, &[], options).unwrap();
    let results = pool.install(|| trials.run(&AtomicBool::new(false), &done)).unwrap();
    assert_eq!(done.into_inner(), 2 * 3);
    results
}

#[test]
fn trials_repeat_bitwise_on_one_and_two_threads() {
    let task = std::sync::Arc::new(common::task("humanoid_lift"));
    let (decoder, encoder) = demo_maps();
    let one = run(1, &task, &decoder, &encoder);
    assert_eq!(one, run(2, &task, &decoder, &encoder), "1 vs 2 threads");
    assert_ne!(one[0].episodes, one[1].episodes, "trials draw different starts");
    for r in &one {
        assert!(r.episodes.iter().all(|e| e.ret.is_finite() && e.steps >= 1));
        assert_eq!(r.trajectories[0].len() % task.row_len(), 0);
    }
}

/// A floating robot without a fall rule (a quadruped whose feet are spheres cannot name box
/// soles) rests its lowest point on the floor at a reset: with the base at the origin, the
/// Go1's feet had started 30 cm inside the floor, and the robot popped out upside down.
#[test]
fn a_floating_robot_without_a_fall_rule_starts_on_the_floor() {
    let shipped = common::task("humanoid_lift");
    let mut config = shipped.config().clone();
    config.fall = None;
    let task = std::sync::Arc::new(Task::new(config, shipped.model().clone(), "no fall").unwrap());
    let d = common::lift_demos();
    let mut p = TaskPlant::new(task, Some(&d)).unwrap();
    for q in &d[3..] {
        assert_eq!(p.reset(q), None);
        // Its box feet keep their 8 corners and nothing else (Exp 3's support polygon as before).
        assert_eq!(sim::fall::sole_points(p.world(), "l_foot").unwrap().len(), 8);
        let lowest = p.world().lowest_point().unwrap();
        assert!(
            (lowest - sim::fall::GROUND_CLEARANCE).abs() < 1e-6,
            "lowest point at {lowest} m"
        );
    }
}
