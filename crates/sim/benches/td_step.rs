//! One RL step of Experiment 1 (docs/method.md §RL loop, §Experiment 1): soft-max look-ahead over
//! all actions, (decode,) plant step, (encode,) features and the TD(0) update. The full-space
//! learner uses the sparse 20⁴ grid and 12 actions; the latent learner a 20² grid, 4 actions and GP
//! maps fitted to 50 constraint-satisfying postures. Peer figures (benches/README.md): NumPy 201 µs
//! (latent), 660–1200 µs (full); target ≈ 20 µs.
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use latent_core::{EpisodeScratch, GpMap, Learner, LearnerConfig, SeKernel, StateSpace, trial_rng};
use nalgebra::DMatrix;
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use sim::bimanual::{BimanualConfig, BimanualLearner, BimanualPlant};

/// Decoder and encoder fitted to 50 random latent points in [0, 1]² and postures
/// `(z0, z1, z0 + 0.1, z1)` spread over the hands' box.
fn maps() -> (GpMap, GpMap) {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let z = DMatrix::from_fn(2, 50, |_, _| rng.random_range(0.0..1.0));
    let x = DMatrix::from_fn(4, 50, |i, j| match i {
        0 => 1.8 * z[(0, j)] - 0.35,
        1 => 1.8 * z[(1, j)] - 0.35,
        2 => 1.8 * z[(0, j)] - 0.25,
        _ => 1.8 * z[(1, j)] - 0.35,
    });
    let decoder = GpMap::new(z.clone(), x.clone(), SeKernel::new([1.0, 0.1, 1e-4]).unwrap()).unwrap();
    let encoder = GpMap::new(x, z, SeKernel::new([1.0, 0.3, 1e-4]).unwrap()).unwrap();
    (decoder, encoder)
}

fn bench_learner(c: &mut Criterion, name: &str, learner: BimanualLearner<'_>) {
    let plant_config = BimanualConfig::default();
    let (mut learner, space): (Learner, StateSpace<'_>) =
        learner.build(&plant_config, &LearnerConfig::default()).unwrap();
    let mut plant = BimanualPlant::new(plant_config).unwrap();
    let mut rng = trial_rng(1, 0);
    let mut scratch: EpisodeScratch = learner.scratch(&space, 4);
    learner.start(&mut plant, &space, &mut rng, &mut scratch).unwrap();
    let mut group = c.benchmark_group("td_step");
    group.throughput(Throughput::Elements(1));
    group.bench_function(name, |b| {
        b.iter(|| {
            let r = learner.step(&mut plant, &space, &mut rng, &mut scratch);
            if r.end.is_some() {
                learner.start(&mut plant, &space, &mut rng, &mut scratch).unwrap();
            }
            r.reward
        })
    });
    group.finish();
}

fn steps(c: &mut Criterion) {
    bench_learner(c, "full_4d_20^4_12_actions", BimanualLearner::Full);
    let (decoder, encoder) = maps();
    let latent = BimanualLearner::Latent {
        decoder: &decoder,
        encoder: &encoder,
        low: &[-0.05, -0.05],
        high: &[1.05, 1.05],
    };
    bench_learner(c, "latent_2d_20^2_4_actions_N50", latent);
}

criterion_group!(benches, steps);
criterion_main!(benches);
