//! A trained latent policy: the learner's grid and weights over the latent box, acting with the
//! GPLVM's maps. What a saved policy does one step at a time (the Gymnasium wrapper, a replay)
//! and where its value function is read.

use nalgebra::DMatrix;

use crate::LearnerConfig;
use crate::encode::Encode;
use crate::error::{CoreError, Result, check_vector};
use crate::gp::GpMap;
use crate::learner::Learner;
use crate::space::StateSpace;

/// One greedy step of a [`LatentPolicy`].
#[derive(Debug, Clone, PartialEq)]
pub struct Action {
    /// The next servo target (D,): the decoded `next`.
    pub target: Vec<f64>,
    /// The latent point of the reached posture (d,).
    pub z: Vec<f64>,
    /// The greedy latent step from `z`, clamped into the box (d,).
    pub next: Vec<f64>,
}

/// The learner of a trained policy, without episode rules: it acts greedily (the action of the
/// largest look-ahead value) and reads its own value function.
#[derive(Debug, Clone)]
pub struct LatentPolicy {
    learner: Learner,
}

impl LatentPolicy {
    /// The learner of `config` over `[low, high]` with `weights`, acting with `decoder` and
    /// `encoder` (checked to connect it to a robot).
    pub fn new(
        config: &LearnerConfig,
        low: &[f64],
        high: &[f64],
        weights: &[f64],
        decoder: &GpMap,
        encoder: &dyn Encode,
    ) -> Result<Self> {
        let policy = Self::without_maps(config, low, high, Some(weights))?;
        let space = StateSpace::Latent { decoder, encoder };
        policy.learner.check_space(&space, decoder.output_dim())?;
        Ok(policy)
    }

    /// `V(z)` ([`LatentPolicy::values`]) at `points` of the learner of `config` over
    /// `[low, high]` with `weights` (w₀ everywhere if none), no maps needed.
    pub fn learner_values(
        config: &LearnerConfig,
        low: &[f64],
        high: &[f64],
        weights: Option<&[f64]>,
        points: &DMatrix<f64>,
    ) -> Result<Vec<f64>> {
        Self::without_maps(config, low, high, weights)?.values(points)
    }

    fn without_maps(config: &LearnerConfig, low: &[f64], high: &[f64], weights: Option<&[f64]>) -> Result<Self> {
        let mut learner = Learner::new(config, Default::default(), low, high)?;
        if let Some(w) = weights {
            learner.set_weights(w)?;
        }
        Ok(Self { learner })
    }

    /// The next servo target for the reached `posture` (D,): encode it, take the greedy latent
    /// step (clamped into the box), decode.
    pub fn act(&self, decoder: &GpMap, encoder: &dyn Encode, posture: &[f64]) -> Result<Action> {
        check_vector("posture", posture, encoder.input_dim())?;
        let mut z = vec![0.0; encoder.output_dim()];
        encoder.encode_into(posture, &mut z, &mut encoder.encode_scratch());
        let next = self.learner.greedy_target(&z)?;
        let mut target = vec![0.0; decoder.output_dim()];
        decoder.mean_into(&next, &mut target, &mut decoder.scratch());
        Ok(Action { target, z, next })
    }

    /// `V(z) = wᵀ b(z)` (Eq. 7) at the columns of `points` (d × M): the learner's own sparse
    /// features, as its look-ahead sees them.
    pub fn values(&self, points: &DMatrix<f64>) -> Result<Vec<f64>> {
        let dim = self.learner.grid().dim();
        if points.nrows() != dim {
            return Err(CoreError::Shape {
                what: "points",
                expected: format!("(M, {dim})"),
                got: format!("({}, {})", points.ncols(), points.nrows()),
            });
        }
        self.learner.values(points.as_slice())
    }
}
