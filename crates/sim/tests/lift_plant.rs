//! The Experiment 3 plant (SPEC §4.3): the humanoid holds a demo pose without falling, a
//! path into the obstacle ends on a contact, spreading the arms drops the object, starts
//! are refused where they must be, an episode does not depend on the one before, and whole
//! trials repeat bitwise on 1 and 2 threads.
use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::episode::{EndReason, LearnerConfig, Plant, StartMode};
use latent_core::trials::{TrialOptions, TrialResult};
use latent_core::{GpMap, SeKernel};
use nalgebra::DMatrix;
use sim::Latent2d;
use sim::UrdfModel;
use sim::latent::run_latent_trials;
use sim::lift::{LiftConfig, LiftPlant, TASK_HEAD};

const KHR1HV: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/khr1hv.urdf");

fn model() -> UrdfModel {
    UrdfModel::from_file(KHR1HV).expect("khr1hv.urdf loads")
}

/// The 7 centred lift demos (rows 0–3 straight-arm hip hinge, 4–6 knee squat).
fn demos() -> Vec<Vec<f64>> {
    let path = format!(
        "{}/../../python/latentrl/data/khr1hv_lift_demos.csv",
        env!("CARGO_MANIFEST_DIR")
    );
    let text = std::fs::read_to_string(path).expect("demo file");
    text.lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect()
}

fn plant() -> LiftPlant {
    LiftPlant::new(model(), LiftConfig::default()).expect("lift plant builds")
}

/// Steps `n` RL steps along the joint-space line `from → to`; returns the outcomes until
/// the first end.
fn walk(p: &mut LiftPlant, from: &[f64], to: &[f64], n: usize) -> Vec<(f64, Option<EndReason>)> {
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
    let mut p = plant();
    let d = demos();
    let ends: Vec<Option<EndReason>> = d.iter().map(|q| p.reset(q)).collect();
    let obstacle = Some(EndReason::Obstacle);
    assert_eq!(
        ends,
        vec![obstacle, obstacle, obstacle, None, None, None, None],
        "demos 0-2 touch the box"
    );
    p.reset(&d[6]);
    let h = p.hands();
    for (a, b) in h.iter().zip(&p.config().target) {
        assert!((a - b).abs() < 2e-3, "{h:?} vs the default target");
    }
    assert!(p.reached_target() && p.config().grip_error(&h) < 1e-3);
    let mut q = d[6].clone();
    q[0] = 10.0;
    assert_eq!(p.reset(&q), Some(EndReason::BoxExit), "outside the joint limits");
    let mut row = vec![0.0; p.task_dim()];
    p.reset(&d[4]);
    p.task_position(&mut row);
    assert_eq!(row.len(), TASK_HEAD + 19);
    assert_eq!(&row[TASK_HEAD..], &p.sim().joint_positions()[..]);
    assert!(
        (row[9..13].iter().map(|x| x * x).sum::<f64>() - 1.0).abs() < 1e-6,
        "unit quaternion"
    );
}

#[test]
fn a_held_squat_pose_neither_falls_nor_drops() {
    let mut p = plant();
    let d = demos();
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
    let mut p = plant();
    let d = demos();
    assert_eq!(p.reset(&d[3]), None);
    let out = walk(&mut p, &d[3], &d[1], 30);
    let (reward, end) = *out.last().unwrap();
    assert_eq!(end, Some(EndReason::Obstacle), "{out:?}");
    assert!(reward < 0.0, "penalty added: {reward}");
}

#[test]
fn spreading_the_arms_drops_the_object() {
    let mut p = plant();
    let d = demos();
    assert_eq!(p.reset(&d[6]), None);
    let mut open = d[6].clone();
    for (i, name) in p.sim().model().joint_names().iter().enumerate() {
        if name.ends_with("shoulder_roll") {
            open[i] = 0.0;
        }
    }
    let out = walk(&mut p, &d[6], &open, 20);
    assert_eq!(out.last().unwrap().1, Some(EndReason::Drop), "{out:?}");
}

#[test]
fn an_episode_does_not_depend_on_the_one_before() {
    let d = demos();
    let mut p = plant();
    p.reset(&d[5]);
    let first = walk(&mut p, &d[5], &d[6], 10);
    // Another episode in between, then the first again on the same plant.
    p.reset(&d[4]);
    walk(&mut p, &d[4], &d[3], 10);
    p.reset(&d[5]);
    let again = walk(&mut p, &d[5], &d[6], 10);
    assert_eq!(first, again);
}

/// GP maps through the 7 demos on a hand-made latent layout: z0 = style (−1 hinge, 1 squat),
/// z1 = progress of the lift in [0, 1].
fn demo_maps() -> (GpMap, GpMap) {
    let d = demos();
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
    let kernel = SeKernel::new([1.0, 1.0, 1e-6]).unwrap();
    (
        GpMap::new(z.clone(), x.clone(), kernel).unwrap(),
        GpMap::new(x, z, SeKernel::new([1.0, 0.5, 1e-4]).unwrap()).unwrap(),
    )
}

fn run(threads: usize, decoder: &GpMap, encoder: &GpMap) -> Vec<TrialResult> {
    let config = LearnerConfig {
        max_steps: 8,
        step_fraction: 0.5,
        beta: 20.0,
        start: StartMode::UniformInBox,
        ..LearnerConfig::default()
    };
    let latent = Latent2d {
        decoder,
        encoder,
        low: &[-1.2, -0.1],
        high: &[1.2, 1.1],
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
    let results = pool
        .install(|| {
            let cancel = AtomicBool::new(false);
            run_latent_trials(
                |_| LiftPlant::new(model(), LiftConfig::default()),
                &config,
                &latent,
                &options,
                &cancel,
                &done,
            )
        })
        .unwrap();
    assert_eq!(done.into_inner(), 2 * 3);
    results
}

#[test]
fn trials_repeat_bitwise_on_one_and_two_threads() {
    let (decoder, encoder) = demo_maps();
    let one = run(1, &decoder, &encoder);
    assert_eq!(one, run(2, &decoder, &encoder), "1 vs 2 threads");
    assert_ne!(one[0].episodes, one[1].episodes, "trials draw different starts");
    for r in &one {
        assert!(r.episodes.iter().all(|e| e.ret.is_finite() && e.steps >= 1));
        assert_eq!(r.trajectories[0].len() % (TASK_HEAD + 19), 0);
    }
}
