//! Trials give bitwise the same results on 1 and 2 threads, and a trial the same alone or
//! among others (STYLE: "a test compares 1 and N threads bitwise"), on a toy plant: a point
//! on a line that earns its position and ends beyond 0.9; in its own space and in a latent
//! space encoded by the iterative projection.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use latent_core::{
    EndReason, EpisodeRules, GpMap, Learner, LearnerConfig, Plant, Projection, ProjectionConfig, SeKernel, StartMode,
    StateSpace, StepOutcome, TrialOptions, TrialResult, run_trials,
};
use nalgebra::DMatrix;
use rand::{Rng, RngExt};

struct Line {
    x: f64,
}

impl Plant for Line {
    fn posture_dim(&self) -> usize {
        1
    }
    fn task_dim(&self) -> usize {
        1
    }
    fn sample_start<R: Rng + ?Sized>(&mut self, rng: &mut R, posture: &mut [f64]) {
        posture[0] = rng.random_range(0.0..0.5);
    }
    fn reset(&mut self, posture: &[f64]) -> Option<EndReason> {
        self.x = posture[0];
        None
    }
    fn step(&mut self, target: &[f64], reached: &mut [f64]) -> StepOutcome {
        self.x = target[0];
        reached[0] = self.x;
        let end = (self.x > 0.9).then_some(EndReason::Obstacle);
        StepOutcome {
            reward: self.x - if end.is_some() { 1.0 } else { 0.0 },
            end,
        }
    }
    fn task_position(&self, out: &mut [f64]) {
        out[0] = self.x;
    }
}

fn options() -> TrialOptions {
    TrialOptions {
        n_trials: 4,
        episodes: 40,
        base_seed: 42,
        record_episodes: vec![0, 39],
        keep_weights: true,
        ..Default::default()
    }
}

fn run_on(threads: usize, options: &TrialOptions) -> Vec<TrialResult> {
    run_in(threads, options, &StateSpace::Full, [0.0, 1.0])
}

/// Trials in `space`, the learner's box `[low, high]`.
fn run_in(threads: usize, options: &TrialOptions, space: &StateSpace<'_>, [low, high]: [f64; 2]) -> Vec<TrialResult> {
    let config = LearnerConfig {
        rbf_per_dim: 11,
        ..LearnerConfig::default()
    };
    let rules = EpisodeRules {
        max_steps: 50,
        start: StartMode::Plant,
        ..EpisodeRules::default()
    };
    let learner = Learner::new(&config, rules, &[low], &[high]).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let done = AtomicUsize::new(0);
    let results = pool
        .install(|| {
            run_trials(
                std::slice::from_ref(&learner),
                space,
                |_| Ok(Line { x: 0.0 }),
                options,
                &AtomicBool::new(false),
                &done,
            )
        })
        .unwrap();
    assert_eq!(done.load(Ordering::Relaxed), options.n_trials * options.episodes);
    results
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn assert_bitwise_equal(a: &[TrialResult], b: &[TrialResult]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!((x.trial, x.finished), (y.trial, y.finished));
        let returns = |t: &TrialResult| t.episodes.iter().map(|e| e.ret).collect::<Vec<_>>();
        assert_eq!(bits(&returns(x)), bits(&returns(y)));
        assert_eq!(x.episodes, y.episodes);
        for (t, u) in x.trajectories.iter().zip(&y.trajectories) {
            assert_eq!(bits(t), bits(u));
        }
        assert_eq!(bits(x.weights.as_ref().unwrap()), bits(y.weights.as_ref().unwrap()));
    }
}

#[test]
fn one_vs_two_threads() {
    let a = run_on(1, &options());
    let b = run_on(2, &options());
    assert_bitwise_equal(&a, &b);
    assert_ne!(a[0].episodes, a[1].episodes, "trials draw from their own streams");
}

#[test]
fn a_trial_is_the_same_alone_or_among_others() {
    let all = run_on(2, &options());
    let third = TrialOptions {
        n_trials: 1,
        first_trial: 2,
        ..options()
    };
    assert_bitwise_equal(&all[2..3], &run_on(1, &third));
}

#[test]
fn the_projection_encoder_is_the_same_on_one_and_two_threads() {
    // A 1-D latent line z ∈ [−1, 1] decoded to the plant's x = (z + 1) / 2 (a little bent).
    let latent = DMatrix::from_fn(1, 9, |_, j| j as f64 / 4.0 - 1.0);
    let postures = latent.map(|z| 0.5 * (z + 1.0) + 0.05 * z * z);
    let decoder = GpMap::new(latent, postures.clone(), SeKernel::new([0.5, 0.3, 1e-6]).unwrap()).unwrap();
    let projection = Projection::new(&decoder, postures, ProjectionConfig::default()).unwrap();
    let space = StateSpace::Latent {
        decoder: &decoder,
        encoder: &projection,
    };
    let options = TrialOptions {
        episodes: 15,
        record_episodes: vec![0, 14],
        ..options()
    };
    let a = run_in(1, &options, &space, [-1.0, 1.0]);
    assert_bitwise_equal(&a, &run_in(2, &options, &space, [-1.0, 1.0]));
    assert_ne!(a[0].episodes, a[1].episodes, "trials draw from their own streams");
}
