//! GP decode (single point and batch) and GPLVM NLL + gradient.
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use latent_core::{GpMap, SeKernel, nll_grad};
use nalgebra::DMatrix;
use std::hint::black_box;

/// Deterministic pseudo-data: N latent points in [-1, 1]², D outputs.
fn data(n: usize, d_out: usize) -> (DMatrix<f64>, DMatrix<f64>) {
    let latent = DMatrix::from_fn(2, n, |i, j| (((j * 7919 + i * 104_729) % 1000) as f64 / 500.0) - 1.0);
    let mut y = DMatrix::from_fn(d_out, n, |i, j| {
        (latent[(0, j)] * (i + 1) as f64).sin() + latent[(1, j)].cos()
    });
    let mean = y.column_mean();
    for mut c in y.column_iter_mut() {
        c -= &mean;
    }
    (latent, y)
}

fn decode(c: &mut Criterion) {
    let mut group = c.benchmark_group("gp_decode");
    for &(n, d_out) in &[(123usize, 4usize), (123, 19), (1000, 4)] {
        let (latent, y) = data(n, d_out);
        let gp = GpMap::new(latent, y, SeKernel::new([1.0, 0.3, 1e-3]).unwrap()).unwrap();
        let mut scratch = gp.scratch();
        let mut mean = vec![0.0; d_out];
        group.throughput(Throughput::Elements(1));
        group.bench_function(BenchmarkId::new("single_mean_var", format!("N{n}_D{d_out}")), |b| {
            b.iter(|| gp.predict_into(black_box(&[0.1, -0.2]), &mut mean, &mut scratch))
        });
        let queries = DMatrix::from_fn(2, 10_000, |i, j| ((j * 31 + i * 17) % 200) as f64 / 100.0 - 1.0);
        group.throughput(Throughput::Elements(10_000));
        group.bench_function(BenchmarkId::new("batch_10k", format!("N{n}_D{d_out}")), |b| {
            b.iter(|| gp.predict(black_box(&queries)).unwrap())
        });
    }
    group.finish();
}

fn gplvm_objective(c: &mut Criterion) {
    let mut group = c.benchmark_group("gplvm_nll_grad");
    group.sample_size(10);
    for &n in &[123usize, 1000] {
        let (latent, y) = data(n, 4);
        group.bench_function(BenchmarkId::from_parameter(format!("N{n}_D4")), |b| {
            b.iter(|| nll_grad(black_box(&latent), &y, [0.0, (0.3f64).ln(), (1e-3f64).ln()]).unwrap())
        });
    }
    group.finish();
}

criterion_group!(benches, decode, gplvm_objective);
criterion_main!(benches);
