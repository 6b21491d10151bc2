//! `latent_core`: the numerical core of latentrl — GP decode/encode and the GPLVM
//! objective (paper Sec. III-A/B), and the reinforcement-learning pieces that run at
//! every step in latent space. Pure Rust: no Python needed to use or test it.
#![warn(missing_docs)]

pub mod back_constraint;
pub mod config;
pub mod encode;
pub mod episode;
pub mod error;
pub mod gp;
pub mod gplvm;
pub mod kernel;
pub mod latent_policy;
pub mod lbfgs;
pub mod learner;
pub mod panic;
pub mod params;
pub mod plant;
pub mod policy;
pub mod projection;
pub mod rbf;
pub mod results;
pub mod run;
pub mod space;
pub mod sparse_gplvm;
pub mod stopping;
pub mod td;
pub mod trials;

pub use config::{ActionSet, LearnerConfig};
pub use encode::{Encode, EncodeScratch};
pub use episode::{Bounds, EpisodeRecord, EpisodeScratch, StepResult, TransitionScratch, refused, transition};
pub use error::{CoreError, Result};
pub use gp::{GpMap, PredictScratch};
pub use gplvm::{NllGrad, nll_grad};
pub use kernel::{Factor, SeKernel, factorize};
pub use latent_policy::{Action, LatentPolicy};
pub use learner::{ActionRule, EpisodeRules, Learner, Phase, StartMode};
pub use params::{Check, FieldInfo, Kind, ParamError, Params, Rule};
pub use plant::{EndReason, Plant, StepOutcome};
pub use policy::SoftmaxPolicy;
pub use projection::{Projection, ProjectionConfig, ProjectionScratch};
pub use rbf::{RbfConfig, RbfGrid, SparseFeatures};
pub use results::{ResultArray, trial_arrays};
pub use run::{Encoder, RunConfig};
pub use space::StateSpace;
pub use sparse_gplvm::{SparseNllGrad, gplvm_objective, sparse_nll_grad};
pub use stopping::{Plateau, StopRule};
pub use td::TdLearner;
pub use trials::{LatentArgs, LatentSpace, RunArgs, TrialOptions, TrialResult, run_trials, trial_rng};
