//! Soft-max action selection (paper Eq. 10) over a discrete action set (the usual sets:
//! [`crate::ActionSet`]). The one-step look-ahead `Q(s, u_i) = V(s + δt · u_i)` (Eq. 11) is computed
//! by the caller ([`crate::episode`]) and handed in as the slice `q`.

use rand::{Rng, RngExt};

use crate::error::{CoreError, Result, check_positive};

/// `π(u_i | s) = exp(β Q(s, u_i)) / Σ_j exp(β Q(s, u_j))` (paper Eq. 10).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SoftmaxPolicy {
    beta: f64,
}

impl SoftmaxPolicy {
    /// A policy with inverse temperature `beta` (> 0; paper: 10 for Exp. 1, 20 for Exp. 2).
    pub fn new(beta: f64) -> Result<Self> {
        check_positive("beta (soft-max inverse temperature)", beta)?;
        Ok(Self { beta })
    }

    /// The inverse temperature β.
    pub fn beta(&self) -> f64 {
        self.beta
    }

    /// Writes the unnormalised weights `exp(β (Q_i − max Q))` into `out` and returns their
    /// sum (≥ 1: the largest weight is exactly 1, so nothing overflows or all-underflows).
    #[inline]
    fn weights(&self, q: &[f64], out: &mut [f64]) -> f64 {
        debug_assert_eq!(q.len(), out.len());
        let max = q.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let mut total = 0.0;
        for (w, &qi) in out.iter_mut().zip(q) {
            *w = (self.beta * (qi - max)).exp();
            total += *w;
        }
        total
    }

    /// The probabilities of Eq. 10 for action values `q` (finite, at least one) into `out`.
    pub fn probabilities(&self, q: &[f64], out: &mut [f64]) {
        let total = self.weights(q, out);
        out.iter_mut().for_each(|p| *p /= total);
    }

    /// Draws an action index from Eq. 10 with one uniform number from `rng`. `q` holds the
    /// look-ahead values (finite, at least one); `buffer` (same length) is overwritten.
    #[inline]
    pub fn sample<R: Rng + ?Sized>(&self, q: &[f64], buffer: &mut [f64], rng: &mut R) -> usize {
        let total = self.weights(q, buffer);
        let mut u = rng.random::<f64>() * total;
        for (i, &w) in buffer.iter().enumerate() {
            if u < w {
                return i;
            }
            u -= w;
        }
        // Rounding can leave u a hair above the last weight: take the last non-zero one.
        buffer.iter().rposition(|&w| w > 0.0).unwrap_or(0)
    }
}

/// Checks a flat action array: a non-empty whole number of rows of length `dim`, finite.
pub fn check_actions(actions: &[f64], dim: usize) -> Result<usize> {
    if actions.is_empty() || dim == 0 {
        return Err(CoreError::Empty { what: "action set" });
    }
    if !actions.len().is_multiple_of(dim) {
        return Err(CoreError::Shape {
            what: "action set",
            expected: format!("(n_actions, {dim})"),
            got: format!("{} values", actions.len()),
        });
    }
    crate::error::check_finite("action set", actions)?;
    Ok(actions.len() / dim)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn probabilities_follow_eq_10_and_survive_huge_values() {
        let policy = SoftmaxPolicy::new(2.0).unwrap();
        let q = [0.0, 1.0, -1.0];
        let mut p = [0.0; 3];
        policy.probabilities(&q, &mut p);
        let z: f64 = q.iter().map(|v| (2.0 * v).exp()).sum();
        for i in 0..3 {
            assert!((p[i] - (2.0 * q[i]).exp() / z).abs() < 1e-15);
        }
        // exp(β Q) alone would overflow; subtracting the max keeps it exact.
        let big = [1000.0, 1000.0 + 0.5f64.ln() / 2.0];
        let mut p2 = [0.0; 2];
        policy.probabilities(&big, &mut p2);
        assert!((p2[0] - 2.0 / 3.0).abs() < 1e-12 && (p2[1] - 1.0 / 3.0).abs() < 1e-12);
        let low = [-1e6, -1e6];
        policy.probabilities(&low, &mut p2);
        assert_eq!(p2, [0.5, 0.5]);
    }

    #[test]
    fn sampling_frequencies_match_probabilities() {
        let policy = SoftmaxPolicy::new(10.0).unwrap();
        let q = [0.1, 0.2, 0.0, 0.15];
        let mut p = [0.0; 4];
        policy.probabilities(&q, &mut p);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut counts = [0usize; 4];
        let mut buf = [0.0; 4];
        let n = 200_000;
        for _ in 0..n {
            counts[policy.sample(&q, &mut buf, &mut rng)] += 1;
        }
        for i in 0..4 {
            let f = counts[i] as f64 / n as f64;
            // 5 binomial standard deviations.
            let sd = (p[i] * (1.0 - p[i]) / n as f64).sqrt();
            assert!((f - p[i]).abs() < 5.0 * sd + 1e-12, "action {i}: {f} vs {}", p[i]);
        }
    }

    #[test]
    fn a_dominant_action_is_always_taken() {
        let policy = SoftmaxPolicy::new(10.0).unwrap();
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let mut buf = [0.0; 3];
        for _ in 0..1000 {
            assert_eq!(policy.sample(&[-500.0, 500.0, -500.0], &mut buf, &mut rng), 1);
        }
    }

    #[test]
    fn action_sets() {
        assert_eq!(check_actions(&[1.0, 0.0, 0.0, -1.0], 2).unwrap(), 2);
        assert!(check_actions(&[1.0, 2.0, 3.0], 2).is_err());
        assert!(check_actions(&[], 2).is_err());
        assert!(SoftmaxPolicy::new(0.0).is_err() && SoftmaxPolicy::new(f64::NAN).is_err());
    }
}
