//! Normalised RBF features (paper Sec. III-D): 2-D (20² latent grid) and sparse 4-D
//! (20⁴ full-space grid, 3σ cut-off), stored features and the value-only fast path.
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use latent_core::{RbfConfig, RbfGrid};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::hint::black_box;

fn features(c: &mut Criterion) {
    let mut group = c.benchmark_group("rbf");
    for dim in [2usize, 4] {
        let grid = RbfGrid::new(&vec![-0.5; dim], &vec![1.5; dim], &RbfConfig::default()).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let points: Vec<Vec<f64>> = (0..1024)
            .map(|_| (0..dim).map(|_| rng.random_range(-0.5..1.5)).collect())
            .collect();
        let weights: Vec<f64> = (0..grid.len()).map(|_| rng.random::<f64>()).collect();
        let mut scratch = grid.scratch();
        let mut out = grid.features();
        group.throughput(Throughput::Elements(points.len() as u64));
        let label = format!("{dim}d_20^{dim}");
        group.bench_function(BenchmarkId::new("features", &label), |b| {
            b.iter(|| {
                for p in &points {
                    grid.eval_into(black_box(p), &mut scratch, &mut out);
                }
                out.len()
            })
        });
        group.bench_function(BenchmarkId::new("value", &label), |b| {
            b.iter(|| {
                points
                    .iter()
                    .map(|p| grid.value(&weights, black_box(p), &mut scratch))
                    .sum::<f64>()
            })
        });
    }
    group.finish();
}

criterion_group!(benches, features);
criterion_main!(benches);
