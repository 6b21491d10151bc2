//! The posture → latent maps the RL loop can encode with (step 6 of docs/method.md §RL loop),
//! behind one trait: a [`GpMap`]'s mean (the out-of-sample GP or the back-constraint) or a
//! [`Projection`].

use crate::gp::{GpMap, PredictScratch};
use crate::projection::{Projection, ProjectionScratch};

/// A posture → latent map the RL loop encodes with (step 6 of docs/method.md §RL loop): a [`GpMap`]
/// (the out-of-sample GP or the back-constraint: its mean) or a [`Projection`].
pub trait Encode: std::fmt::Debug + Send + Sync {
    /// Posture dimension D.
    fn input_dim(&self) -> usize;
    /// Latent dimension d.
    fn output_dim(&self) -> usize;
    /// Fresh buffers for [`Encode::encode_into`].
    fn encode_scratch(&self) -> EncodeScratch;
    /// Encodes `posture` (length D) into `z` (length d), allocation-free with buffers of this
    /// map (others are replaced once); lengths and finiteness are the caller's contract.
    fn encode_into(&self, posture: &[f64], z: &mut [f64], scratch: &mut EncodeScratch);
    /// Encodes `posture`, reached after commanding the latent point `near`, into `z`: maps
    /// that can use where the move was aimed (a tracking [`Projection`]) search from there;
    /// the others ignore it ([`Encode::encode_into`]).
    fn encode_near_into(&self, posture: &[f64], near: &[f64], z: &mut [f64], scratch: &mut EncodeScratch) {
        let _ = near;
        self.encode_into(posture, z, scratch);
    }
}

/// Buffers of an [`Encode`] map.
#[derive(Debug, Clone)]
pub enum EncodeScratch {
    /// Of a [`GpMap`].
    Map(PredictScratch),
    /// Of a [`Projection`].
    Projection(Box<ProjectionScratch>),
}

impl Encode for GpMap {
    fn input_dim(&self) -> usize {
        self.inputs.nrows()
    }

    fn output_dim(&self) -> usize {
        self.alpha_t.nrows()
    }

    fn encode_scratch(&self) -> EncodeScratch {
        EncodeScratch::Map(self.scratch())
    }

    fn encode_into(&self, posture: &[f64], z: &mut [f64], scratch: &mut EncodeScratch) {
        if !matches!(scratch, EncodeScratch::Map(_)) {
            *scratch = self.encode_scratch();
        }
        if let EncodeScratch::Map(s) = scratch {
            self.mean_into(posture, z, s);
        }
    }
}

impl Encode for Projection {
    fn input_dim(&self) -> usize {
        self.posture_dim()
    }

    fn output_dim(&self) -> usize {
        self.latent_dim()
    }

    fn encode_scratch(&self) -> EncodeScratch {
        EncodeScratch::Projection(Box::new(self.scratch()))
    }

    fn encode_into(&self, posture: &[f64], z: &mut [f64], scratch: &mut EncodeScratch) {
        if !matches!(scratch, EncodeScratch::Projection(_)) {
            *scratch = self.encode_scratch();
        }
        if let EncodeScratch::Projection(s) = scratch {
            Projection::encode_into(self, posture, z, s);
        }
    }

    fn encode_near_into(&self, posture: &[f64], near: &[f64], z: &mut [f64], scratch: &mut EncodeScratch) {
        if !matches!(scratch, EncodeScratch::Projection(_)) {
            *scratch = self.encode_scratch();
        }
        if let EncodeScratch::Projection(s) = scratch {
            Projection::encode_near_into(self, posture, near, z, s);
        }
    }
}
