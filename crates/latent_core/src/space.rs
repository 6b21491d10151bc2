//! The learner's state space relative to the plant's posture space: the postures
//! themselves, or a latent space with a GP decoder and an encoder (paper Sec. III-B/E).

use crate::encode::{Encode, EncodeScratch};
use crate::error::{CoreError, Result};
use crate::gp::{GpMap, PredictScratch};
/// The learner's state space relative to the plant's posture space.
#[derive(Debug, Clone, Copy)]
pub enum StateSpace<'a> {
    /// The posture space itself: decode and encode are the identity.
    Full,
    /// A latent space: `decoder` maps latent → posture (GPLVM mean, Eq. 4), `encoder`
    /// posture → latent (out-of-sample GP, back-constraint or iterative projection, Sec. III-B).
    Latent {
        /// Latent → posture GP map.
        decoder: &'a GpMap,
        /// Posture → latent map.
        encoder: &'a dyn Encode,
    },
}

/// Buffers of a space's maps: none in the full space.
#[derive(Debug, Clone)]
pub struct SpaceScratch {
    decode: Option<PredictScratch>,
    encode: Option<EncodeScratch>,
}

impl<'a> StateSpace<'a> {
    /// Checks that this space connects a learner of dimension `dim` to a plant with
    /// `posture_dim` coordinates.
    pub fn check(&self, dim: usize, posture_dim: usize) -> Result<()> {
        let mismatch = |what: &'static str, expected: usize, got: usize| {
            Err(CoreError::Shape {
                what,
                expected: format!("dimension {expected}"),
                got: format!("dimension {got}"),
            })
        };
        match self {
            StateSpace::Full if posture_dim != dim => {
                mismatch("plant posture (full-space learner box)", dim, posture_dim)
            }
            StateSpace::Full => Ok(()),
            StateSpace::Latent { decoder, encoder } => {
                if decoder.input_dim() != dim {
                    mismatch("decoder input (latent box)", dim, decoder.input_dim())
                } else if decoder.output_dim() != posture_dim {
                    mismatch("decoder output (plant posture)", posture_dim, decoder.output_dim())
                } else if encoder.input_dim() != posture_dim {
                    mismatch("encoder input (plant posture)", posture_dim, encoder.input_dim())
                } else if encoder.output_dim() != dim {
                    mismatch("encoder output (latent box)", dim, encoder.output_dim())
                } else {
                    Ok(())
                }
            }
        }
    }

    /// Whether decoded targets have a variance (the latent space).
    pub fn is_latent(&self) -> bool {
        matches!(self, StateSpace::Latent { .. })
    }

    /// Fresh buffers for [`Self::decode`] and [`Self::encode`].
    pub fn scratch(&self) -> SpaceScratch {
        match self {
            StateSpace::Full => SpaceScratch {
                decode: None,
                encode: None,
            },
            StateSpace::Latent { decoder, encoder } => SpaceScratch {
                decode: Some(decoder.scratch()),
                encode: Some(encoder.encode_scratch()),
            },
        }
    }

    /// Decodes `z` into `posture` (identity in the full space). Returns the GPLVM variance
    /// when `with_variance` (for variance gating), else 0: the `O(N²)` solve is skipped.
    #[inline]
    pub fn decode(&self, z: &[f64], posture: &mut [f64], s: &mut SpaceScratch, with_variance: bool) -> f64 {
        match (self, s.decode.as_mut()) {
            (StateSpace::Latent { decoder, .. }, Some(s)) if with_variance => decoder.predict_into(z, posture, s),
            (StateSpace::Latent { decoder, .. }, Some(s)) => {
                decoder.mean_into(z, posture, s);
                0.0
            }
            _ => {
                posture.copy_from_slice(z);
                0.0
            }
        }
    }

    /// Encodes `posture` into `z` (identity in the full space).
    #[inline]
    pub fn encode(&self, posture: &[f64], z: &mut [f64], s: &mut SpaceScratch) {
        match (self, s.encode.as_mut()) {
            (StateSpace::Latent { encoder, .. }, Some(s)) => encoder.encode_into(posture, z, s),
            _ => z.copy_from_slice(posture),
        }
    }

    /// Encodes `posture`, reached after commanding `near`, into `z` ([`Encode::encode_near_into`];
    /// identity in the full space).
    #[inline]
    pub fn encode_near(&self, posture: &[f64], near: &[f64], z: &mut [f64], s: &mut SpaceScratch) {
        match (self, s.encode.as_mut()) {
            (StateSpace::Latent { encoder, .. }, Some(s)) => encoder.encode_near_into(posture, near, z, s),
            _ => z.copy_from_slice(posture),
        }
    }
}
