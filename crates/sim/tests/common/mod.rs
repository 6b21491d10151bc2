//! Shared helpers of the `sim` integration tests.
#![allow(dead_code)]

use latent_core::{GpMap, SeKernel};
use nalgebra::DMatrix;
use sim::bimanual::BimanualLearner;
use sim::{Task, UrdfModel, World, WorldConfig};

/// Path of the shipped two-arm URDF (package data of the Python package).
pub const TWO_ARMS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/two_arms.urdf");

/// Folder of the shipped task files.
pub const TASKS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/tasks");

/// The shipped task `name` (`two_arms`, `humanoid_lift`).
pub fn task(name: &str) -> Task {
    Task::load(format!("{TASKS}/{name}.toml")).expect("shipped task loads")
}

/// The world of the humanoid lift task (its servos and physics, the floor).
pub fn humanoid_world() -> WorldConfig {
    task("humanoid_lift").world_config()
}

/// The 7 centred humanoid lift demos (rows 0–3 straight-arm hip hinge, 4–6 knee squat).
pub fn lift_demos() -> Vec<Vec<f64>> {
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

/// The two-arm model.
pub fn arms_model() -> UrdfModel {
    UrdfModel::from_file(TWO_ARMS).expect("two_arms.urdf loads")
}

/// The two-arm plant with `options`.
pub fn arms(options: WorldConfig) -> World {
    World::new(arms_model(), options).expect("two-arm plant builds")
}

/// SplitMix64: a tiny deterministic generator for test inputs.
pub struct Rng(pub u64);

impl Rng {
    /// Uniform in [0, 1).
    pub fn uniform(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in [lo, hi).
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.uniform()
    }

    /// A posture in the demonstrated style: hands in front, elbows outward.
    pub fn arms_posture(&mut self) -> [f64; 4] {
        [
            self.range(-0.5, 3.0),
            self.range(-2.8, 0.0),
            self.range(0.1, 3.6),
            self.range(0.0, 2.8),
        ]
    }
}

/// Latent box of [`synthetic_maps`]: the bounding box of the training latents.
pub const LATENT_LOW: [f64; 2] = [-0.4, -0.4];
/// Upper corner of the latent box.
pub const LATENT_HIGH: [f64; 2] = [1.3, 1.3];

/// A decoder (latent → posture) and encoder (posture → latent) fitted to a 7×7 latent
/// grid `z` over the latent box with postures `x = (z0, z1, z0 + 0.1, z1)`: every decoded
/// posture holds the object exactly (the GP mean is the same linear smoother in every
/// output), so a latent learner on these maps never drops.
pub fn synthetic_maps() -> (GpMap, GpMap) {
    let side = 7;
    let n = side * side;
    let z = DMatrix::from_fn(2, n, |i, j| {
        let k = if i == 0 { j % side } else { j / side };
        LATENT_LOW[i] + (LATENT_HIGH[i] - LATENT_LOW[i]) * k as f64 / (side - 1) as f64
    });
    let x = DMatrix::from_fn(4, n, |i, j| match i {
        0 => z[(0, j)],
        1 => z[(1, j)],
        2 => z[(0, j)] + 0.1,
        _ => z[(1, j)],
    });
    let kernel = SeKernel::new([1.0, 0.25, 1e-6]).unwrap();
    let decoder = GpMap::new(z.clone(), x.clone(), kernel).unwrap();
    let encoder = GpMap::new(x, z, kernel).unwrap();
    (decoder, encoder)
}

/// The latent learner of Experiment 1 over [`synthetic_maps`] and their latent box.
pub fn latent_learner<'a>(decoder: &'a GpMap, encoder: &'a GpMap) -> BimanualLearner<'a> {
    BimanualLearner::Latent {
        decoder,
        encoder,
        low: &LATENT_LOW,
        high: &LATENT_HIGH,
    }
}
