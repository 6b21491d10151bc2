//! The Experiment 2 plant (SPEC §4.2): two simulated arms holding an object, walls tested on
//! the hands, drops, rewards, "passed", and whole trials (test episodes, determinism).
mod common;

use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::episode::{EndReason, LearnerConfig, Plant, StartMode};
use latent_core::trials::{TrialOptions, TrialResult};
use latent_core::{GpMap, SeKernel};
use nalgebra::DMatrix;
use sim::PlanarArms;
use sim::arms::{ArmsConfig, ArmsLatent, ArmsPlant};
use sim::latent::run_latent_trials;

fn plant(config: ArmsConfig) -> ArmsPlant {
    ArmsPlant::new(common::arms_model(), config).expect("arms plant builds")
}

/// The posture (elbows outward) with the left hand at `(x, y)` and the right hand 0.1 m to its right.
fn holding(x: f64, y: f64) -> [f64; 4] {
    PlanarArms::default()
        .inverse(&[x, y, x + 0.1, y], 0)
        .expect("reachable")
}

fn close(a: &[f64], b: &[f64], tol: f64) -> bool {
    a.iter().zip(b).all(|(x, y)| (x - y).abs() <= tol)
}

/// Steps towards hands `(x, y)` along a straight line of `n` steps; returns every outcome
/// and the largest joint tracking error |reached − target| seen.
fn walk(p: &mut ArmsPlant, from: (f64, f64), to: (f64, f64), n: usize) -> (Vec<(f64, Option<EndReason>)>, f64) {
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
    let mut p = plant(ArmsConfig::default());
    let q = holding(-0.2, 0.2);
    assert_eq!(p.reset(&q), None);
    let expected_hands = PlanarArms::default().hands(&q);
    let mut reached = [0.0; 4];
    for _ in 0..40 {
        let out = p.step(&q, &mut reached);
        assert_eq!(out.end, None);
        let h = p.hands();
        assert!(close(&reached, &q, 1e-4), "{reached:?} vs {q:?}");
        assert!(close(&h, &expected_hands, 1e-4), "{h:?} vs {expected_hands:?}");
        // Reward (SPEC §4.2): exp(−0.35 ‖(h − h*)/0.3‖²) of the sim's hand frames.
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
    let mut task = [0.0; 4];
    p.task_position(&mut task);
    assert_eq!(task, p.hands());
    assert!(!p.reached_target() && !p.passed() && p.admits_test_start());
}

#[test]
fn hands_match_the_kinematics_of_the_reached_posture() {
    let mut p = plant(ArmsConfig::default());
    assert_eq!(p.reset(&holding(-0.2, 0.15)), None);
    let (outcomes, _) = walk(&mut p, (-0.2, 0.15), (-0.05, 0.25), 10);
    assert!(outcomes.iter().all(|(_, end)| end.is_none()));
    let mut q = [0.0; 4];
    p.sim().joint_positions_into(&mut q);
    assert!(
        close(&p.hands(), &PlanarArms::default().hands(&q), 1e-5),
        "f32 world vs f64 FK"
    );
}

#[test]
fn passing_the_gap_reaches_the_target_and_counts_as_passed() {
    let mut p = plant(ArmsConfig::default());
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
    let mut p = plant(ArmsConfig::default());
    assert_eq!(p.reset(&holding(-0.4, 0.2)), None);
    let (outcomes, _) = walk(&mut p, (-0.4, 0.2), (-0.4, 0.34), 14);
    let (reward, end) = *outcomes.last().unwrap();
    assert_eq!(end, Some(EndReason::Obstacle), "{outcomes:?}");
    let h = p.hands();
    assert!(
        (0.30..=0.37).contains(&h[1]) && h[0] <= -0.36,
        "left hand in the left wall: {h:?}"
    );
    assert!(
        (reward - (p.config().reward(&h) - 1.0)).abs() < 1e-12,
        "reward + penalty"
    );
    assert!(!p.passed());
}

#[test]
fn a_broken_grip_ends_with_drop() {
    let mut p = plant(ArmsConfig::default());
    let q = holding(-0.2, 0.2);
    assert_eq!(p.reset(&q), None);
    // Right hand 1 cm further right: the grip is off by 0.01 > 0.005.
    let target = PlanarArms::default().inverse(&[-0.2, 0.2, -0.09, 0.2], 0).unwrap();
    let mut reached = [0.0; 4];
    let out = p.step(&target, &mut reached);
    assert_eq!(out.end, Some(EndReason::Drop));
    assert!((out.reward - (p.config().reward(&p.hands()) - 1.0)).abs() < 1e-12);
    // 3 mm is within the tolerance.
    assert_eq!(p.reset(&q), None);
    let target = PlanarArms::default().inverse(&[-0.2, 0.2, -0.097, 0.2], 0).unwrap();
    assert_eq!(p.step(&target, &mut reached).end, None);
}

#[test]
fn inadmissible_starts_are_refused() {
    let mut p = plant(ArmsConfig::default());
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
fn bad_hand_links_and_configs_fail_to_build() {
    let bad = ArmsConfig {
        left_hand: "left_paw".to_string(),
        ..ArmsConfig::default()
    };
    assert!(ArmsPlant::new(common::arms_model(), bad).is_err());
    let bad = ArmsConfig {
        start_posture: [9.0, 0.0, 0.0, 0.0],
        ..ArmsConfig::default()
    };
    assert!(ArmsPlant::new(common::arms_model(), bad).is_err());
    let bad = ArmsConfig {
        theta: -1.0,
        ..ArmsConfig::default()
    };
    assert!(ArmsPlant::new(common::arms_model(), bad).is_err());
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

fn run(threads: usize, decoder: &GpMap, encoder: &GpMap) -> Vec<TrialResult> {
    let plant = ArmsConfig {
        drop_tolerance: 0.02,
        ..ArmsConfig::default()
    };
    let config = LearnerConfig {
        max_steps: 60,
        step_fraction: 0.5,
        beta: 20.0,
        start: StartMode::UniformInBox,
        ..LearnerConfig::default()
    };
    let latent = ArmsLatent {
        decoder,
        encoder,
        low: &[0.0, 0.0],
        high: &[1.0, 1.0],
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
    let model = common::arms_model();
    let results = pool
        .install(|| {
            run_latent_trials(
                |_| ArmsPlant::new(model.clone(), plant.clone()),
                &config,
                &latent,
                &options,
                &AtomicBool::new(false),
                &done,
            )
        })
        .unwrap();
    assert_eq!(done.into_inner(), 2 * (6 + 4));
    results
}

#[test]
fn trials_run_test_episodes_from_below_the_wall_and_repeat_bitwise() {
    let (decoder, encoder) = gap_maps();
    let one = run(1, &decoder, &encoder);
    let two = run(2, &decoder, &encoder);
    assert_eq!(one, two, "1 vs 2 threads");
    for r in &one {
        assert!(r.finished);
        assert_eq!((r.episodes.len(), r.tests.len(), r.test_trajectories.len()), (6, 4, 2));
        for path in &r.test_trajectories {
            assert!(
                path[1] < 0.30 && path[3] < 0.30,
                "test start above the wall band: {:?}",
                &path[..4]
            );
        }
        for rec in r.tests.iter().chain(&r.episodes) {
            assert!(rec.steps >= 1 && rec.steps <= 60);
        }
    }
    // Recorded test paths and flags agree.
    for r in &one {
        for (slot, e) in [0, 3].into_iter().enumerate() {
            let path = &r.test_trajectories[slot];
            let above = path.chunks_exact(4).skip(1).any(|h| h[1] > 0.37 && h[3] > 0.37);
            assert_eq!(r.tests[e].passed, above);
        }
    }
}
