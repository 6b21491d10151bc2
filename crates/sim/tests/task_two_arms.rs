//! The two-arms task (`tasks/two_arms.toml`, docs/method.md §Experiment 2) on the generic task
//! plant: walls tested on the hands, drops, rewards, "passed", and whole trials (test episodes,
//! determinism).
mod common;

use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::trials::{LatentSpace, TrialOptions, TrialResult};
use latent_core::{EndReason, GpMap, LearnerConfig, Plant, SeKernel, StartMode};
use nalgebra::DMatrix;
use sim::task::TaskTrials;
use sim::{PlanarArms, RuleCheck, Task, TaskPlant};

/// The posture (elbows outward) with the left hand at `(x, y)` and the right hand 0.1 m to its right.
fn holding(x: f64, y: f64) -> [f64; 4] {
    PlanarArms::default()
        .inverse(&[x, y, x + 0.1, y], 0)
        .expect("reachable")
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// The hands `(x_L, y_L, x_R, y_R)` of the plant (the effectors lie in z = 0).
fn hands(p: &TaskPlant) -> [f64; 4] {
    let e = p.effectors();
    assert_eq!((e[2], e[5]), (0.0, 0.0), "planar arms");
    [e[0], e[1], e[3], e[4]]
}

/// Steps towards hands `(x, y)` along a straight line of `n` steps; returns every outcome
/// and the largest joint tracking error |reached − target| seen.
fn walk(p: &mut TaskPlant, from: (f64, f64), to: (f64, f64), n: usize) -> (Vec<(f64, Option<EndReason>)>, f64) {
    let mut reached = [0.0; 4];
    let mut outcomes = Vec::new();
    let mut worst: f64 = 0.0;
    for k in 1..=n {
        let t = k as f64 / n as f64;
        let target = holding(from.0 + t * (to.0 - from.0), from.1 + t * (to.1 - from.1));
        let out = p.step(&target, &mut reached);
        worst = target
            .iter()
            .zip(&reached)
            .map(|(a, b)| (a - b).abs())
            .fold(worst, f64::max);
        outcomes.push((out.reward, out.end));
        if out.end.is_some() {
            break;
        }
    }
    (outcomes, worst)
}

#[test]
fn a_held_posture_stays_put_and_pays_the_formula() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut p = TaskPlant::new(task.clone(), None).unwrap();
    let q = holding(-0.2, 0.2);
    assert_eq!(p.reset(&q), None);
    let expected_hands = PlanarArms::default().hands(&q);
    let mut reached = [0.0; 4];
    for _ in 0..40 {
        let out = p.step(&q, &mut reached);
        assert_eq!(out.end, None);
        let h = hands(&p);
        assert!(close(&reached, &q, 1e-4), "{reached:?} vs {q:?}");
        assert!(close(&h, &expected_hands, 1e-4), "{h:?} vs {expected_hands:?}");
        // Reward (docs/method.md §Experiment 2): exp(−0.35 ‖(h − h*)/0.3‖²) of the sim's hand
        // frames.
        let d2: f64 = h
            .iter()
            .zip([-0.05, 0.47, 0.05, 0.47])
            .map(|(a, b)| (a - b) * (a - b))
            .sum();
        assert!(
            (out.reward - (-0.35 * d2 / 0.09).exp()).abs() < 1e-12,
            "{} vs formula",
            out.reward
        );
    }
    let mut row = vec![0.0; p.task_dim()];
    p.task_position(&mut row);
    assert_eq!(row.len(), 6 + 7 + 4);
    assert_eq!(&row[..6], p.effectors());
    assert_eq!(
        &row[6..13],
        &[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0],
        "the fixed base at the origin"
    );
    assert!(close(&row[13..], &reached, 0.0));
    assert!(!p.reached_target() && !p.passed() && p.admits_test_start());
}

#[test]
fn hands_match_the_kinematics_of_the_reached_posture() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut p = TaskPlant::new(task.clone(), None).unwrap();
    assert_eq!(p.reset(&holding(-0.2, 0.15)), None);
    let (outcomes, _) = walk(&mut p, (-0.2, 0.15), (-0.05, 0.25), 10);
    assert!(outcomes.iter().all(|(_, end)| end.is_none()));
    let mut q = [0.0; 4];
    p.world().joint_positions_into(&mut q);
    assert!(
        close(&hands(&p), &PlanarArms::default().hands(&q), 1e-5),
        "f32 world vs f64 FK"
    );
}

#[test]
fn passing_the_gap_reaches_the_target_and_counts_as_passed() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut p = TaskPlant::new(task.clone(), None).unwrap();
    assert_eq!(p.reset(&holding(-0.25, 0.2)), None);
    assert!(p.admits_test_start(), "both hands below the wall");
    // Straight up through the gap x ∈ (−0.36, −0.06): 1 cm per 0.05 s step.
    let (up, worst) = walk(&mut p, (-0.25, 0.2), (-0.25, 0.45), 25);
    assert!(up.iter().all(|(_, end)| end.is_none()), "{up:?}");
    assert!(worst < 1e-3, "tracking error {worst} rad with 2 solver iterations");
    assert!(p.passed());
    let (over, _) = walk(&mut p, (-0.25, 0.45), (-0.05, 0.47), 20);
    assert!(over.iter().all(|(_, end)| end.is_none()));
    assert!(p.reached_target() && p.passed());
    let best = over.last().unwrap().0;
    assert!(best > 0.99, "reward at the target {best}");
    // A reset clears "passed"; a start above the wall admits no test episode.
    assert_eq!(p.reset(&holding(-0.05, 0.47)), None);
    assert!(!p.passed() && !p.admits_test_start());
}

#[test]
fn a_target_inside_the_corridor_wall_ends_with_obstacle() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut p = TaskPlant::new(task.clone(), None).unwrap();
    assert_eq!(p.reset(&holding(-0.4, 0.2)), None);
    let (outcomes, _) = walk(&mut p, (-0.4, 0.2), (-0.4, 0.34), 14);
    let (reward, end) = *outcomes.last().unwrap();
    assert_eq!(end, Some(EndReason::Obstacle), "{outcomes:?}");
    let h = hands(&p);
    assert!(
        (0.30..=0.37).contains(&h[1]) && h[0] <= -0.36,
        "left hand in the left wall: {h:?}"
    );
    assert!((reward - (p.reward() - 1.0)).abs() < 1e-12, "reward + penalty");
    assert!(!p.passed());
}

#[test]
fn a_broken_grip_ends_with_drop() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut p = TaskPlant::new(task.clone(), None).unwrap();
    let q = holding(-0.2, 0.2);
    assert_eq!(p.reset(&q), None);
    // Right hand 1 cm further right: the grip is off by 0.01 > 0.005.
    let target = PlanarArms::default().inverse(&[-0.2, 0.2, -0.09, 0.2], 0).unwrap();
    let mut reached = [0.0; 4];
    let out = p.step(&target, &mut reached);
    assert_eq!(out.end, Some(EndReason::Drop));
    assert!((out.reward - (p.reward() - 1.0)).abs() < 1e-12);
    // 3 mm is within the tolerance.
    assert_eq!(p.reset(&q), None);
    let target = PlanarArms::default().inverse(&[-0.2, 0.2, -0.097, 0.2], 0).unwrap();
    assert_eq!(p.step(&target, &mut reached).end, None);
}

#[test]
fn inadmissible_starts_are_refused() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut p = TaskPlant::new(task.clone(), None).unwrap();
    assert_eq!(p.reset(&holding(-0.4, 0.33)), Some(EndReason::Obstacle));
    let loose = PlanarArms::default().inverse(&[-0.2, 0.2, -0.05, 0.2], 0).unwrap();
    assert_eq!(p.reset(&loose), Some(EndReason::Drop));
    assert_eq!(
        p.reset(&[9.0, 0.0, 0.0, 0.0]),
        Some(EndReason::BoxExit),
        "outside the joint limits"
    );
    assert_eq!(p.reset(&holding(-0.2, 0.2)), None);
}

#[test]
fn a_reset_does_not_depend_on_the_posture_before() {
    let task = std::sync::Arc::new(common::task("two_arms"));
    let mut a = TaskPlant::new(task.clone(), None).unwrap();
    let mut b = TaskPlant::new(task.clone(), None).unwrap();
    let q = holding(-0.2, 0.2);
    let mut reached = [0.0; 4];
    a.reset(&holding(-0.1, 0.1));
    a.step(&holding(-0.12, 0.12), &mut reached);
    a.reset(&q);
    b.reset(&q);
    let (ra, rb) = (a.world().joint_positions(), b.world().joint_positions());
    assert_eq!(
        ra.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
        rb.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
    );
    let (sa, sb) = (a.step(&q, &mut reached), b.step(&q, &mut reached));
    assert_eq!(sa.reward.to_bits(), sb.reward.to_bits());
}

/// GP maps over a 9×9 latent grid on [0, 1]²: the left hand at
/// (−0.3 + 0.2 z0, 0.12 + 0.33 z1), right hand 0.1 m to its right, through the gap.
fn gap_maps() -> (GpMap, GpMap) {
    let side = 9;
    let n = side * side;
    let z = DMatrix::from_fn(2, n, |i, j| {
        (if i == 0 { j % side } else { j / side }) as f64 / (side - 1) as f64
    });
    let mut x = DMatrix::zeros(4, n);
    for j in 0..n {
        let q = holding(-0.3 + 0.2 * z[(0, j)], 0.12 + 0.33 * z[(1, j)]);
        x.column_mut(j).copy_from_slice(&q);
    }
    let kernel = SeKernel::new([1.0, 0.1, 1e-6]).unwrap();
    (
        GpMap::new(z.clone(), x.clone(), kernel).unwrap(),
        GpMap::new(x, z, kernel).unwrap(),
    )
}

fn run(threads: usize, task: &std::sync::Arc<Task>, decoder: &GpMap, encoder: &GpMap) -> Vec<TrialResult> {
    // The learner's step and the episode length of this test, through the task's own keys.
    let mut config = task.config().clone();
    config.learner = LearnerConfig {
        step: 0.5,
        ..config.learner
    };
    config.episode.max_steps = 60;
    let task =
        std::sync::Arc::new(Task::from_config(config, std::path::Path::new(common::TASKS), task.origin()).unwrap());
    assert_eq!(task.episode_rules().start, StartMode::Uniform);
    let latent = LatentSpace {
        decoder,
        encoder,
        low: vec![0.0, 0.0],
        high: vec![1.0, 1.0],
    };
    let options = TrialOptions {
        n_trials: 2,
        episodes: 6,
        base_seed: 5,
        test_episodes: 4,
        record_test_episodes: vec![0, 3],
        keep_weights: true,
        ..TrialOptions::default()
    };
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let done = AtomicUsize::new(0);
    let trials = TaskTrials::new(task, None, &latent, &[], options).unwrap();
    let results = pool.install(|| trials.run(&AtomicBool::new(false), &done)).unwrap();
    assert_eq!(done.into_inner(), 2 * (6 + 4));
    results
}

#[test]
fn trials_run_test_episodes_from_below_the_wall_and_repeat_bitwise() {
    let mut config = common::task("two_arms").config().clone();
    config.constraints[0].tolerance = Some(0.02);
    let task = std::sync::Arc::new(
        Task::from_config(config, std::path::Path::new(common::TASKS), "two_arms, grip 0.02").unwrap(),
    );
    let (decoder, encoder) = gap_maps();
    let one = run(1, &task, &decoder, &encoder);
    let two = run(2, &task, &decoder, &encoder);
    assert_eq!(one, two, "1 vs 2 threads");
    let row = task.row_len();
    for r in &one {
        assert!(r.finished);
        assert_eq!((r.episodes.len(), r.tests.len(), r.test_trajectories.len()), (6, 4, 2));
        for path in &r.test_trajectories {
            assert!(
                path[1] < 0.30 && path[4] < 0.30,
                "test start above the wall band: {:?}",
                &path[..6]
            );
        }
        for rec in r.tests.iter().chain(&r.episodes) {
            assert!(rec.steps >= 1 && rec.steps <= 60);
        }
        // Recorded test paths and flags agree.
        for (slot, e) in [0, 3].into_iter().enumerate() {
            let path = &r.test_trajectories[slot];
            let above = path.chunks_exact(row).skip(1).any(|h| h[1] > 0.37 && h[4] > 0.37);
            assert_eq!(r.tests[e].passed, above);
        }
    }
}

/// One RL step that carries both hands through the right wall (y 0.30–0.37) and beyond it.
fn jump_the_wall(check: RuleCheck) -> (Option<EndReason>, [f64; 4]) {
    let mut config = common::task("two_arms").config().clone();
    config.episode.check_rules = check;
    let task = Task::from_config(config, std::path::Path::new(common::TASKS), "two_arms.toml").unwrap();
    let mut p = TaskPlant::new(std::sync::Arc::new(task), None).unwrap();
    assert_eq!(p.reset(&holding(0.0, 0.26)), None);
    let mut reached = [0.0; 4];
    let out = p.step(&holding(0.0, 0.41), &mut reached);
    (out.end, hands(&p))
}

#[test]
fn a_wall_crossed_within_one_rl_step_ends_only_when_every_physics_step_is_checked() {
    let (end, h) = jump_the_wall(RuleCheck::RlStep);
    assert!(h[1] > 0.37, "the hands end beyond the wall: {h:?}");
    assert_eq!(end, None, "once per RL step: the end state is clear");
    let (end, h2) = jump_the_wall(RuleCheck::PhysicsStep);
    assert_eq!(end, Some(EndReason::Obstacle), "the wall was crossed in between");
    assert_eq!(h, h2, "the check does not change the motion");
}

#[test]
fn a_checked_step_refuses_a_target_of_the_wrong_length() {
    let mut p = TaskPlant::new(std::sync::Arc::new(common::task("two_arms")), None).unwrap();
    let err = p.step_checked(&[0.0; 3]).unwrap_err().to_string();
    assert_eq!(err, "target: expected shape (4,), got (3,)");
    let q = holding(-0.2, 0.2);
    assert_eq!(p.reset(&q), None);
    let (outcome, reached) = p.step_checked(&q).unwrap();
    assert!(outcome.end.is_none() && close(&reached, &q, 1e-2));
}

#[test]
fn classify_gives_one_posture_per_column() {
    let mut p = TaskPlant::new(std::sync::Arc::new(common::task("two_arms")), None).unwrap();
    let (a, b) = (holding(-0.2, 0.2), holding(0.0, 0.3));
    let c = p
        .classify(&DMatrix::from_iterator(4, 2, a.iter().chain(&b).copied()))
        .unwrap();
    assert_eq!((c.codes.len(), c.effectors.shape()), (2, (p.effectors().len(), 2)));
    assert_eq!(c.targets.shape(), c.effectors.shape());
    p.reset(&b);
    assert_eq!(c.effectors.column(1).as_slice(), p.effectors());
}

#[test]
fn a_home_posture_the_robot_cannot_take_is_named_by_its_demo_row() {
    let shipped = common::task("two_arms");
    let joints = shipped.model().joints();
    let good: Vec<f64> = joints.iter().map(|j| 0.5 * (j.lower + j.upper)).collect();
    let mut bad = good.clone();
    bad[1] = joints[1].upper + 1.0;
    let task = |start, start_demo| {
        let mut config = shipped.config().clone();
        config.episode.start = start;
        config.episode.start_demo = start_demo;
        std::sync::Arc::new(Task::new(config, shipped.model().clone(), "test").unwrap())
    };
    let demos = [bad.clone(), good.clone()];
    match TaskPlant::new(task(sim::task::StartRule::Demo, 0), Some(&demos)) {
        Err(sim::SimError::HomePosture { row: 0, source }) => {
            assert!(source.to_string().contains("position"), "{source}")
        }
        other => panic!("expected the home posture named, got {:?}", other.err()),
    }
    // Another start demo is the home posture; a bad row elsewhere is the survey's to find.
    assert!(TaskPlant::new(task(sim::task::StartRule::Demo, 1), Some(&demos)).is_ok());
    // No episode starts at the home posture: the robot stands at a neutral one instead.
    let plant = TaskPlant::new(task(sim::task::StartRule::Uniform, 0), Some(&demos)).unwrap();
    assert!(
        plant
            .home()
            .iter()
            .zip(joints)
            .all(|(q, j)| *q == 0.0_f64.clamp(j.lower, j.upper))
    );
}
