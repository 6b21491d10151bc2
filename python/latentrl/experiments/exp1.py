"""Experiment 1 (paper Sec. IV-A, Fig. 4): bimanual reaching in end-effector space.

A full-space learner (4-D hand positions, 12 actions, 20⁴ RBFs) against a latent learner
(GPLVM d = 2 on demonstrated constraint-satisfying hand pairs, 4 actions, 20² RBFs).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass


@dataclass(frozen=True)
class Exp1Preset:
    """Exp 1: bimanual reaching in end-effector space, full-space vs latent-space TD(0) (Fig. 4)."""

    trials: int = 25
    """Independent RL trials per learner (paper: 25)."""
    episodes: int = 5000
    """Episodes per trial (paper: 5000)."""
    steps: int = 500
    """Steps per episode before a time-out (paper: 500)."""
    seed: int = 0
    """Base seed: demonstrations, GPLVM fit and every trial's RNG derive from it."""
    n_demos: int = 50
    """Demonstrated constraint-satisfying hand pairs (ours: the paper's count is illegible)."""
    gplvm_max_iter: int = 1000
    """L-BFGS iteration cap of the GPLVM fit."""
    latent_margin: float = 0.1
    """Latent box = bounding box of the fitted latent points, widened by this share per side (ours)."""
    drop_tolerance: float = 0.1
    """Constraint broken (object dropped) beyond this offset error (ours for RL; Table I uses 0.005)."""
    reward_theta: float = 0.75
    """θ of the reward exp(−θ‖x − x*‖²) (paper)."""
    obstacle_radius: float = 0.2
    """Radius of the obstacle disc at (0.5, 0.5) that neither hand may enter (ours)."""
    start_std: float = 0.1
    """Standard deviation of the left hand's start around (1, 1) (paper)."""
    rbf_per_dim: int = 20
    """RBF centres per state dimension, both learners (paper: 20)."""
    rbf_cutoff: float = 3.0
    """Sparse RBFs: centres farther than this many σ contribute nothing (ours)."""
    beta: float = 10.0
    """Soft-max inverse temperature β (paper)."""
    alpha: float = 0.9
    """TD(0) learning rate α (paper)."""
    gamma: float = 0.95
    """Discount γ (paper)."""
    step_fraction: float = 0.2
    """Step length δt·|u| as a share of the RBF spacing, in each learner's own space (ours)."""
    initial_weight: float = 0.0
    """Initial value weights (0 paper-like; 1/(1−γ) = 20 is optimistic and ~10× faster)."""
    variance_threshold: float = 0.0
    """Latent targets with GPLVM variance above this are infeasible (−1, end); 0 = off (SPEC §3.2)."""
    reach_radius: float = 0.1
    """'Reached the target': RMS per-hand distance to x* at most this (SPEC §4.1)."""

    @classmethod
    def quick(cls) -> Exp1Preset:
        """The CI smoke test: step 0.5 × spacing, 500 episodes × 500 steps, 3 trials."""
        return dataclasses.replace(cls(), trials=3, episodes=500, step_fraction=0.5)
