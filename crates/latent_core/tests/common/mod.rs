//! Shared fixtures: GP maps fitted to synthetic, constraint-satisfying Experiment 1 data.
#![allow(dead_code)]

use latent_core::{GpMap, SeKernel};
use nalgebra::DMatrix;
use sim::bimanual::BimanualLearner;

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
