//! `latent_core`: the numerical core of latentrl — GP decode/encode and the GPLVM
//! objective (paper Sec. III-A/B), and the reinforcement-learning pieces that run at
//! every step in latent space. Pure Rust: no Python needed to use or test it.
#![warn(missing_docs)]

pub mod error;
pub mod gp;
pub mod gplvm;
pub mod kernel;

pub use error::{CoreError, Result};
pub use gp::{GpMap, PredictScratch};
pub use gplvm::{nll_grad, NllGrad};
pub use kernel::{factorize, Factor, SeKernel};
