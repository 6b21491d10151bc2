//! TD(0) V-learning with a linear value function (paper Sec. III-D, Eq. 7–9).
//!
//! `V(s) = wᵀ b(s)` (Eq. 7), TD error `δ_t = r_t + γ V(s_{t+1}) − V(s_t)` (Eq. 8) and the
//! update `w ← w + α δ_t b(s_t)` (Eq. 9). A terminal transition (an episode ended by a
//! penalty) uses `V(s_{t+1}) = 0`. With `LearnerConfig::move_correction` the weights also
//! hold one block `c_a` per action after `w`, each learnt towards the same target.

use crate::error::{CoreError, Result};
use crate::rbf::SparseFeatures;

/// The weights `w` of `V(s) = wᵀ b(s)` and the TD(0) update (Eq. 7–9).
#[derive(Debug, Clone)]
pub struct TdLearner {
    weights: Vec<f64>,
    n_features: usize,
    alpha: f64,
    gamma: f64,
}

impl TdLearner {
    /// `n_features` weights of V set to `initial_weight`, then `corrections` blocks of
    /// `n_features` zeros; learning rate `alpha` and discount `gamma` (their rules are
    /// [`crate::LearnerConfig`]'s).
    pub fn new(n_features: usize, corrections: usize, alpha: f64, gamma: f64, initial_weight: f64) -> Result<Self> {
        if n_features == 0 {
            return Err(CoreError::Empty {
                what: "value-function features",
            });
        }
        let mut weights = vec![initial_weight; n_features];
        weights.resize(n_features * (1 + corrections), 0.0);
        Ok(Self {
            weights,
            n_features,
            alpha,
            gamma,
        })
    }

    /// The weights: `w`, one per feature, then the correction blocks.
    pub fn weights(&self) -> &[f64] {
        &self.weights
    }

    /// V's weights `w` alone, one per feature.
    #[inline]
    pub fn value_weights(&self) -> &[f64] {
        &self.weights[..self.n_features]
    }

    /// Replaces the weights (e.g. with a saved policy's); the length must be `weights()`'s.
    pub fn set_weights(&mut self, weights: &[f64]) -> Result<()> {
        if weights.len() != self.weights.len() {
            return Err(CoreError::Shape {
                what: "value weights",
                expected: format!("({},)", self.weights.len()),
                got: format!("({},)", weights.len()),
            });
        }
        crate::error::check_finite("value weights", weights)?;
        self.weights.copy_from_slice(weights);
        Ok(())
    }

    /// Consumes the learner, returning `w`.
    pub fn into_weights(self) -> Vec<f64> {
        self.weights
    }

    /// Discount factor γ.
    pub fn gamma(&self) -> f64 {
        self.gamma
    }

    /// Learning rate α.
    pub fn alpha(&self) -> f64 {
        self.alpha
    }

    /// `V(s) = wᵀ b(s)` (Eq. 7).
    #[inline]
    pub fn value(&self, features: &SparseFeatures) -> f64 {
        features.dot(&self.weights)
    }

    /// Where in the weights the correction block `c_a` of `action` lies (past their end
    /// without corrections).
    #[inline]
    fn block(&self, action: usize) -> std::ops::Range<usize> {
        let start = self.n_features * (1 + action);
        start..start + self.n_features
    }

    /// The correction `C_a = c_aᵀ b` of block `action` (0 without corrections).
    #[inline]
    pub fn correction(&self, features: &SparseFeatures, action: usize) -> f64 {
        self.weights.get(self.block(action)).map_or(0.0, |c| features.dot(c))
    }

    /// `c_a ← c_a + α · error · b`, `error` being the TD target minus the look-ahead `Q(z, a)`;
    /// nothing without corrections.
    #[inline]
    pub fn correct(&mut self, features: &SparseFeatures, action: usize, error: f64) {
        let block = self.block(action);
        if let Some(c) = self.weights.get_mut(block) {
            let step = self.alpha * error;
            for (&i, &b) in features.indices.iter().zip(&features.values) {
                c[i] += step * b;
            }
        }
    }

    /// One TD(0) update from `b(s_t)`, reward `r_t` and `V(s_{t+1})` — `None` for a terminal
    /// transition, i.e. `V(s_{t+1}) = 0`. Returns `δ_t = r_t + γ V(s_{t+1}) − V(s_t)`
    /// (Eq. 8) after applying `w ← w + α δ_t b(s_t)` (Eq. 9).
    #[inline]
    pub fn update(&mut self, features: &SparseFeatures, reward: f64, next_value: Option<f64>) -> f64 {
        let delta = reward + self.gamma * next_value.unwrap_or(0.0) - self.value(features);
        let step = self.alpha * delta;
        for (&i, &b) in features.indices.iter().zip(&features.values) {
            self.weights[i] += step * b;
        }
        delta
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn features(pairs: &[(usize, f64)]) -> SparseFeatures {
        SparseFeatures {
            indices: pairs.iter().map(|p| p.0).collect(),
            values: pairs.iter().map(|p| p.1).collect(),
        }
    }

    #[test]
    fn update_follows_eq_8_and_9() {
        let mut td = TdLearner::new(4, 0, 0.5, 0.9, 1.0).unwrap();
        let b = features(&[(1, 0.25), (2, 0.75)]);
        assert_eq!(td.value(&b), 1.0);
        // δ = 0.3 + 0.9·2 − 1 = 1.1; w_i += 0.5·1.1·b_i.
        let delta = td.update(&b, 0.3, Some(2.0));
        assert!((delta - 1.1).abs() < 1e-15);
        assert_eq!(td.weights()[0], 1.0);
        assert!((td.weights()[1] - (1.0 + 0.55 * 0.25)).abs() < 1e-15);
        assert!((td.weights()[2] - (1.0 + 0.55 * 0.75)).abs() < 1e-15);
        assert_eq!(td.weights()[3], 1.0);
    }

    #[test]
    fn corrections_are_blocks_after_v_and_leave_it_alone() {
        let mut td = TdLearner::new(3, 2, 0.5, 0.9, 7.0).unwrap();
        assert_eq!(td.weights(), [7.0, 7.0, 7.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let b = features(&[(0, 0.5), (2, 0.5)]);
        // c_1 += 0.5 · (−4) · b: block 1 is weights 6..9.
        td.correct(&b, 1, -4.0);
        assert_eq!(td.weights(), [7.0, 7.0, 7.0, 0.0, 0.0, 0.0, -1.0, 0.0, -1.0]);
        assert_eq!(td.correction(&b, 1), -1.0);
        assert_eq!(td.correction(&b, 0), 0.0);
        assert_eq!(td.value(&b), 7.0);
        let plain = TdLearner::new(3, 0, 0.5, 0.9, 7.0).unwrap();
        assert_eq!(plain.correction(&b, 0), 0.0);
    }

    #[test]
    fn terminal_uses_zero_next_value() {
        let mut td = TdLearner::new(2, 0, 0.9, 0.95, 0.5).unwrap();
        let b = features(&[(0, 1.0)]);
        let delta = td.update(&b, -1.0, None);
        assert!((delta - (-1.5)).abs() < 1e-15);
        assert!((td.weights()[0] - (0.5 - 0.9 * 1.5)).abs() < 1e-15);
    }

    #[test]
    fn converges_to_the_fixed_point_of_a_chain() {
        // Two states, one-hot features: s0 → s1 (r = 0), s1 → terminal (r = 1).
        // Fixed point: V(s1) = 1, V(s0) = γ.
        let mut td = TdLearner::new(2, 0, 0.3, 0.9, 0.0).unwrap();
        let (b0, b1) = (features(&[(0, 1.0)]), features(&[(1, 1.0)]));
        for _ in 0..200 {
            let v1 = td.value(&b1);
            td.update(&b0, 0.0, Some(v1));
            td.update(&b1, 1.0, None);
        }
        assert!((td.weights()[1] - 1.0).abs() < 1e-9);
        assert!((td.weights()[0] - 0.9).abs() < 1e-9);
    }

    #[test]
    fn needs_a_feature() {
        assert!(TdLearner::new(0, 0, 0.9, 0.95, 0.0).is_err());
    }
}
