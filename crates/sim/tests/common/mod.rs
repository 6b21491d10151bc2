//! Shared helpers of the `sim` integration tests.
#![allow(dead_code)]

use sim::{PhysicsSim, SimOptions, UrdfModel};

/// Path of the shipped two-arm URDF (package data of the Python package).
pub const TWO_ARMS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../python/latentrl/data/two_arms.urdf");

/// The two-arm model.
pub fn arms_model() -> UrdfModel {
    UrdfModel::from_file(TWO_ARMS).expect("two_arms.urdf loads")
}

/// The two-arm plant with `options`.
pub fn arms(options: SimOptions) -> PhysicsSim {
    PhysicsSim::new(arms_model(), options).expect("two-arm plant builds")
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
