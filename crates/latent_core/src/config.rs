//! The learner's parameters (paper Sec. III-D/E; docs/method.md §TD(0)), each declared once with
//! its doc, default and rule ([`crate::params!`]); `Default` is the paper's Experiment 1.

use crate::params::Rule;
use crate::{choice, params};

choice! {
    /// The latent actions: unit steps along each axis, optionally with the diagonals.
    pub enum ActionSet {
        /// ±1 along each axis: 2d actions (paper Exp. 1: 4 in 2-D).
        Axes = "axes",
        /// The axes, then for every pair of axes the four diagonals (±1, ±1), √2 longer:
        /// 2d + 2d(d − 1) actions (paper Exp. 2: 8 in 2-D).
        AxesAndDiagonals = "axes_and_diagonals",
    }
}

params! {
    /// The TD(0) learner of V over an RBF grid on the latent box and its soft-max policy.
    pub struct LearnerConfig {
        /// RBF centres per latent dimension, box corners included (paper: 20).
        rbf_per_dim: usize = 20 => Rule::count(2, 10_000),
        /// RBF width σ as a multiple of the grid spacing (ours: 1, "σ ≈ spacing").
        rbf_width: f64 = 1.0 => Rule::Positive,
        /// Sparse RBFs: centres farther than this many σ contribute nothing (ours: 3).
        rbf_cutoff: f64 = 3.0 => Rule::Positive,
        /// TD(0) learning rate α (paper: 0.9 in Exp. 1, 0.8 in Exp. 2).
        alpha: f64 = 0.9 => Rule::open_closed(0.0, 1.0),
        /// Discount γ; below 1, since a time-out bootstraps (paper: 0.95 in Exp. 1, 0.99 in Exp. 2).
        gamma: f64 = 0.95 => Rule::closed_open(0.0, 1.0),
        /// Initial value weight w₀ of every RBF (0 paper-like; 1/(1 − γ) is optimistic).
        initial_weight: f64 = 0.0 => Rule::Finite,
        /// Soft-max inverse temperature β (paper: 10 in Exp. 1, 20 in Exp. 2).
        beta: f64 = 10.0 => Rule::Positive,
        /// Latent step length as a share of the RBF spacing, per dimension (ours: 0.2).
        step: f64 = 0.2 => Rule::open_closed(0.0, 100.0),
        /// The latent actions (paper: axes in Exp. 1, axes and diagonals in Exp. 2 and 3).
        actions: ActionSet = ActionSet::Axes => Rule::Any,
        /// A latent target whose GPLVM variance exceeds this ends the episode with the penalty
        /// and no plant step (docs/method.md §Variance gating); none (default) turns it off.
        variance_threshold: Option<f64> = None => Rule::Positive,
        /// Ours, not the paper's: also learn for every action a correction `C_a(z) = c_aᵀ b(z)`
        /// of its look-ahead, `Q(z, a) = V(z + Δ_a) + C_a(z)`, from each move's own outcome
        /// (`c_a ← c_a + α (r + γ V(s') − Q(z, a)) b(z)`): what V cannot hold, such as a move
        /// that meets an obstacle on the way to a clear target. The weights then hold
        /// 1 + actions blocks (V's first). Off (default): Eq. 11, `Q(z, a) = V(z + Δ_a)`.
        move_correction: bool = false => Rule::Any,
    }
}

impl ActionSet {
    /// The unit action directions in `dim` dimensions, a flat `n_actions × dim` array: `+e_0,
    /// −e_0, +e_1, −e_1, …`, then (with diagonals) for each pair `i < j` the rows with
    /// `(u_i, u_j)` = (1, 1), (1, −1), (−1, 1), (−1, −1).
    pub fn directions(self, dim: usize) -> Vec<f64> {
        let mut actions = Vec::new();
        for k in 0..dim {
            for sign in [1.0, -1.0] {
                let mut row = vec![0.0; dim];
                row[k] = sign;
                actions.extend(row);
            }
        }
        if self == ActionSet::AxesAndDiagonals {
            for i in 0..dim {
                for j in i + 1..dim {
                    for (a, b) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
                        let mut row = vec![0.0; dim];
                        row[i] = a;
                        row[j] = b;
                        actions.extend(row);
                    }
                }
            }
        }
        actions
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::Params;

    #[test]
    fn action_sets_in_any_dimension() {
        assert_eq!(
            ActionSet::Axes.directions(2),
            [1.0, 0.0, -1.0, 0.0, 0.0, 1.0, 0.0, -1.0]
        );
        let eight = ActionSet::AxesAndDiagonals.directions(2);
        assert_eq!(&eight[8..], [1.0, 1.0, 1.0, -1.0, -1.0, 1.0, -1.0, -1.0]);
        assert_eq!(ActionSet::Axes.directions(1), [1.0, -1.0]);
        assert_eq!(ActionSet::AxesAndDiagonals.directions(3).len(), (6 + 12) * 3);
    }

    #[test]
    fn the_defaults_pass_their_rules_and_gamma_one_does_not() {
        LearnerConfig::default().validate().unwrap();
        let bad = LearnerConfig {
            gamma: 1.0,
            ..LearnerConfig::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "gamma must lie in [0, 1), got 1"
        );
        let bad = LearnerConfig {
            rbf_per_dim: 1,
            ..LearnerConfig::default()
        };
        assert_eq!(
            bad.validate().unwrap_err().to_string(),
            "rbf_per_dim must be an integer in [2, 10000], got 1"
        );
    }
}
