//! `latent_core`: the numerical core of latentrl — GP decode/encode and the GPLVM
//! objective (paper Sec. III-A/B), and the reinforcement-learning pieces that run at
//! every step in latent space. Pure Rust: no Python needed to use or test it.
#![warn(missing_docs)]

pub mod episode;
pub mod error;
pub mod gp;
pub mod gplvm;
pub mod kernel;
pub mod policy;
pub mod rbf;
pub mod td;
pub mod trials;

pub use episode::{
    EndReason, EpisodeRecord, EpisodeScratch, Learner, LearnerConfig, Phase, Plant, StartMode, StateSpace, StepOutcome,
    StepResult,
};
pub use error::{CoreError, Result};
pub use gp::{GpMap, PredictScratch};
pub use gplvm::{NllGrad, nll_grad};
pub use kernel::{Factor, SeKernel, factorize};
pub use policy::{SoftmaxPolicy, orthogonal_actions};
pub use rbf::{RbfConfig, RbfGrid, SparseFeatures};
pub use td::{TdConfig, TdLearner};
pub use trials::{TrialOptions, TrialResult, run_trials, trial_rng};
