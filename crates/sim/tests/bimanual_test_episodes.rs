//! Frozen test episodes after training (`TrialOptions::test_episodes`): they run with the
//! trial's own generator after its training episodes, change no weight and do not perturb
//! training; a cancelled trial runs none.

mod common;

use std::sync::atomic::{AtomicBool, AtomicUsize};

use latent_core::{LearnerConfig, TrialOptions, TrialResult};
use sim::bimanual::{BimanualConfig, run_bimanual_trials};

fn run(options: &TrialOptions, cancel: bool) -> Vec<TrialResult> {
    let (decoder, encoder) = common::synthetic_maps();
    let learner = common::latent_learner(&decoder, &encoder);
    let config = LearnerConfig {
        step: 0.5,
        ..LearnerConfig::default()
    };
    let plant = BimanualConfig {
        max_steps: 60,
        ..BimanualConfig::default()
    };
    let done = AtomicUsize::new(0);
    let r = run_bimanual_trials(&plant, &config, &learner, options, &AtomicBool::new(cancel), &done).unwrap();
    if !cancel {
        assert_eq!(
            done.into_inner(),
            options.n_trials * (options.episodes + options.test_episodes)
        );
    }
    r
}

#[test]
fn test_episodes_follow_training_without_changing_it() {
    let base = TrialOptions {
        n_trials: 2,
        episodes: 30,
        base_seed: 7,
        keep_weights: true,
        ..Default::default()
    };
    let with_tests = TrialOptions {
        test_episodes: 5,
        record_test_episodes: vec![4, 0],
        ..base.clone()
    };
    let plain = run(&base, false);
    let tested = run(&with_tests, false);
    for (p, t) in plain.iter().zip(&tested) {
        assert_eq!(p.episodes, t.episodes, "test episodes perturbed training");
        assert_eq!(p.weights, t.weights, "test episodes changed the weights");
        assert!(p.tests.is_empty() && t.tests.len() == 5 && t.finished);
        assert_eq!(t.test_trajectories.len(), 2);
        for (slot, e) in [4, 0].into_iter().enumerate() {
            // One row per plant call after the start row.
            let rows = t.test_trajectories[slot].len() / 4;
            assert!(rows >= 1 && rows <= t.tests[e].steps + 1);
        }
    }
    assert_ne!(
        tested[0].tests, tested[1].tests,
        "each trial tests with its own generator"
    );
}

#[test]
fn a_cancelled_trial_runs_no_test_episodes() {
    let options = TrialOptions {
        n_trials: 1,
        episodes: 10,
        test_episodes: 5,
        ..Default::default()
    };
    let r = run(&options, true);
    assert!(!r[0].finished && r[0].episodes.is_empty() && r[0].tests.is_empty());
}
