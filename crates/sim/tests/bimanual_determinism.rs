//! Trials give bitwise the same results on 1 and 2 threads, and for the same seed
//! (STYLE: "a test compares 1 and N threads bitwise").

mod common;

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use latent_core::{LearnerConfig, TrialOptions, TrialResult};
use sim::bimanual::{BimanualConfig, BimanualLearner, run_bimanual_trials};

fn options() -> TrialOptions {
    TrialOptions {
        n_trials: 4,
        episodes: 25,
        base_seed: 42,
        record_episodes: vec![0, 24],
        keep_weights: true,
        ..Default::default()
    }
}

fn config() -> LearnerConfig {
    LearnerConfig {
        step: 0.5,
        ..LearnerConfig::default()
    }
}

fn plant() -> BimanualConfig {
    BimanualConfig {
        max_steps: 80,
        ..BimanualConfig::default()
    }
}

fn run_on(threads: usize, learner: &BimanualLearner<'_>, options: &TrialOptions) -> Vec<TrialResult> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    let done = AtomicUsize::new(0);
    let results = pool
        .install(|| run_bimanual_trials(&plant(), &config(), learner, options, &AtomicBool::new(false), &done))
        .unwrap();
    assert_eq!(done.load(Ordering::Relaxed), options.n_trials * options.episodes);
    results
}

/// Bitwise equality, f64 by bit pattern.
fn assert_bitwise_equal(a: &[TrialResult], b: &[TrialResult]) {
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(b) {
        assert_eq!(x.trial, y.trial);
        assert_eq!(x.finished, y.finished);
        assert_eq!(x.episodes.len(), y.episodes.len());
        for (e, f) in x.episodes.iter().zip(&y.episodes) {
            assert_eq!(e.ret.to_bits(), f.ret.to_bits());
            assert_eq!((e.end, e.steps, e.reached), (f.end, f.steps, f.reached));
        }
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for (t, u) in x.trajectories.iter().zip(&y.trajectories) {
            assert_eq!(bits(t), bits(u));
        }
        assert_eq!(bits(x.weights.as_ref().unwrap()), bits(y.weights.as_ref().unwrap()));
    }
}

#[test]
fn full_space_one_vs_two_threads() {
    let a = run_on(1, &BimanualLearner::Full, &options());
    let b = run_on(2, &BimanualLearner::Full, &options());
    assert_bitwise_equal(&a, &b);
    // Trials differ from each other (own streams).
    assert_ne!(a[0].episodes, a[1].episodes);
}

#[test]
fn latent_one_vs_two_threads() {
    let (decoder, encoder) = common::synthetic_maps();
    let learner = common::latent_learner(&decoder, &encoder);
    let a = run_on(1, &learner, &options());
    let b = run_on(2, &learner, &options());
    assert_bitwise_equal(&a, &b);
    assert!(
        a.iter()
            .flat_map(|t| &t.episodes)
            .all(|e| e.end != latent_core::EndReason::Drop)
    );
}

#[test]
fn a_trial_is_the_same_alone_or_in_a_sweep() {
    let all = run_on(2, &BimanualLearner::Full, &options());
    let third = TrialOptions {
        n_trials: 1,
        first_trial: 2,
        ..options()
    };
    let alone = run_on(1, &BimanualLearner::Full, &third);
    assert_bitwise_equal(&all[2..3], &alone);
}

#[test]
fn cancel_stops_every_trial_unfinished() {
    let cancel = AtomicBool::new(true);
    let done = AtomicUsize::new(0);
    let r = run_bimanual_trials(&plant(), &config(), &BimanualLearner::Full, &options(), &cancel, &done).unwrap();
    assert!(r.iter().all(|t| !t.finished && t.episodes.is_empty()));
    assert_eq!(done.load(Ordering::Relaxed), 0);
}
