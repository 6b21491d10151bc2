//! One RL step of the zoo's floating-base biped (`examples/zoo/biped_pick`, issue #37): the
//! latent learner's whole step (look-ahead, decode, the plant's 12 physics steps of 1/240 s with
//! floor contacts and its rules, encode, TD(0)), episodes restarted as `train` does (a fresh world
//! per episode). The latent space is the demos' own two parameters (squat depth, arm raise)
//! with GP maps through the 100 demos; the learner's step is 0.05 of them.
//!
//! `rl_step`: the learner's step, restarts amortised; `plant_step`: only [`TaskPlant`]'s step
//! (same targets); `reset`: one episode start. Times are the bench thread's CPU time (Linux's
//! `/proc/thread-self/schedstat`), not wall time: on a shared, loaded machine wall time also
//! counts the other processes' turns.
//! Run: `cargo bench -p sim --bench biped_step`.
use std::hint::black_box;
use std::sync::Arc;
use std::time::Duration;

use criterion::measurement::{Measurement, ValueFormatter, WallTime};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use latent_core::trials::LatentSpace;
use latent_core::{EpisodeScratch, GpMap, Learner, LearnerConfig, Plant, SeKernel, trial_rng};
use nalgebra::DMatrix;
use sim::{Task, TaskPlant};

const ZOO: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../examples/zoo/biped_pick");

/// The demos, one posture (10 joints) per row.
fn demos() -> Vec<Vec<f64>> {
    let text = std::fs::read_to_string(format!("{ZOO}/demos.csv")).expect("demo file");
    let rows = text.lines().skip(1);
    rows.map(|r| r.split(',').map(|v| v.parse().expect("a number")).collect())
        .collect()
}

/// Decoder and encoder through the demos at their generator's parameters: z = (−q_l_hip,
/// −q_l_shoulder), the squat depth and the arm raise.
fn maps(demos: &[Vec<f64>]) -> (GpMap, GpMap) {
    let n = demos.len();
    let z = DMatrix::from_fn(2, n, |i, j| -demos[j][if i == 0 { 0 } else { 6 }]);
    let x = DMatrix::from_fn(10, n, |i, j| demos[j][i]);
    (
        GpMap::new(z.clone(), x.clone(), SeKernel::new([1.0, 0.5, 1e-6]).unwrap()).unwrap(),
        GpMap::new(x, z, SeKernel::new([1.0, 0.5, 1e-4]).unwrap()).unwrap(),
    )
}

/// The bench thread's CPU time.
struct CpuTime;

/// Nanoseconds the calling thread has run on a CPU.
fn cpu_ns() -> u64 {
    let stat = std::fs::read_to_string("/proc/thread-self/schedstat").expect("Linux's schedstat");
    stat.split_whitespace()
        .next()
        .and_then(|ns| ns.parse().ok())
        .expect("a count of ns")
}

/// Durations are printed as wall time's are.
static DURATIONS: WallTime = WallTime;

impl Measurement for CpuTime {
    type Intermediate = u64;
    type Value = Duration;

    fn start(&self) -> u64 {
        cpu_ns()
    }

    fn end(&self, start: u64) -> Duration {
        Duration::from_nanos(cpu_ns() - start)
    }

    fn add(&self, a: &Duration, b: &Duration) -> Duration {
        *a + *b
    }

    fn zero(&self) -> Duration {
        Duration::ZERO
    }

    fn to_f64(&self, value: &Duration) -> f64 {
        value.as_nanos() as f64
    }

    fn formatter(&self) -> &dyn ValueFormatter {
        DURATIONS.formatter()
    }
}

fn steps(c: &mut Criterion<CpuTime>) {
    let task = Arc::new(Task::load(format!("{ZOO}/task.toml")).expect("biped_pick task loads"));
    let demos = demos();
    let (decoder, encoder) = maps(&demos);
    let latent = LatentSpace {
        decoder: &decoder,
        encoder: &encoder,
        low: vec![0.0, 0.0],
        high: vec![1.0, 1.6],
    };
    let space = latent.space();
    let config = LearnerConfig {
        step: 0.05,
        ..task.config().learner.clone()
    };
    let mut learner = Learner::new(&config, task.episode_rules(), &latent.low, &latent.high).unwrap();
    let mut plant = TaskPlant::new(Arc::clone(&task), Some(&demos)).unwrap();
    let mut rng = trial_rng(1, 0);
    let mut scratch: EpisodeScratch = learner.scratch(&space, plant.posture_dim());
    let max_steps = task.config().episode.max_steps;
    let mut group = c.benchmark_group("biped_pick");
    group.throughput(Throughput::Elements(1));
    group.sample_size(30);
    learner.start(&mut plant, &space, &mut rng, &mut scratch).unwrap();
    let mut taken = 0;
    let mut targets = Vec::new();
    group.bench_function("rl_step", |b| {
        b.iter(|| {
            let r = learner.step(&mut plant, &space, &mut rng, &mut scratch);
            taken += 1;
            if targets.len() < 20_000 {
                targets.push(scratch.posture().to_vec());
            }
            if r.end.is_some() || taken == max_steps {
                learner.start(&mut plant, &space, &mut rng, &mut scratch).unwrap();
                taken = 0;
            }
            r.reward
        })
    });
    let mut reached = vec![0.0; plant.posture_dim()];
    let mut next = 0;
    plant.reset(&demos[0]);
    group.bench_function("plant_step", |b| {
        b.iter(|| {
            let outcome = plant.step(&targets[next % targets.len()], &mut reached);
            next += 1;
            if outcome.end.is_some() || next % max_steps == 0 {
                plant.reset(&demos[next % demos.len()]);
            }
            outcome.reward
        })
    });
    group.bench_function("reset", |b| {
        b.iter(|| {
            next += 1;
            black_box(plant.reset(&demos[next % demos.len()]))
        })
    });
    group.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(CpuTime);
    targets = steps
}
criterion_main!(benches);
