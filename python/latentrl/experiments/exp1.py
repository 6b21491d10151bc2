"""Experiment 1 (paper Sec. IV-A, Fig. 4): bimanual reaching in end-effector space.

A full-space learner (4-D hand positions, 12 actions, 20⁴ RBFs) against a latent learner
(GPLVM d = 2 on demonstrated constraint-satisfying hand pairs, 4 actions, 20² RBFs).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from latentrl import _native
from latentrl.datasets import bimanual_pairs
from latentrl.experiments.latent_runs import gplvm_info, recorded_episodes
from latentrl.experiments.presets import check_floats, check_ints, latent_box
from latentrl.experiments.runner import RunTrials, Setup, run_rl
from latentrl.gplvm import GPLVM

TARGET = np.array([0.0, 0.0, 0.1, 0.0])
"""x* of the reward (paper): left hand at the origin, right hand 0.1 to its right."""
OBSTACLE_CENTRE = (0.5, 0.5)
"""Centre of the obstacle disc (ours: the paper only draws it)."""


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

    def validate(self) -> None:
        """ValueError naming the first field with an impossible value."""
        check_ints(self, ("trials", "episodes", "steps", "n_demos", "gplvm_max_iter", "rbf_per_dim"))
        check_ints(self, ("seed",), minimum=0)
        check_floats(
            self,
            ("drop_tolerance", "reward_theta", "start_std", "rbf_cutoff", "beta", "alpha",
             "step_fraction", "reach_radius"),
            positive=True,
        )
        check_floats(self, ("latent_margin", "obstacle_radius", "variance_threshold"), positive=False)
        if not np.isfinite(self.initial_weight):
            raise ValueError(f"initial_weight must be finite, got {self.initial_weight!r}")
        if not 0 <= self.gamma < 1:
            raise ValueError(f"gamma must lie in [0, 1), got {self.gamma!r}")

    @classmethod
    def quick(cls) -> Exp1Preset:
        """The CI smoke test: step 0.5 × spacing, 500 episodes × 500 steps, 3 trials."""
        return dataclasses.replace(cls(), trials=3, episodes=500, step_fraction=0.5)


def native_config(preset: Exp1Preset) -> dict[str, Any]:
    """The preset in the native call's configuration keys."""
    return {
        "drop_tolerance": preset.drop_tolerance,
        "theta": preset.reward_theta,
        "obstacle_centre": list(OBSTACLE_CENTRE),
        "obstacle_radius": preset.obstacle_radius,
        "target": TARGET.tolist(),
        "start_sd": preset.start_std,
        "reached_rms": preset.reach_radius,
        "alpha": preset.alpha,
        "gamma": preset.gamma,
        "initial_weight": preset.initial_weight,
        "beta": preset.beta,
        "step_fraction": preset.step_fraction,
        "max_steps": preset.steps,
        "centres_per_dim": preset.rbf_per_dim,
        "rbf_cutoff": preset.rbf_cutoff,
        "variance_threshold": preset.variance_threshold or None,
    }


def setup(preset: Exp1Preset) -> Setup:
    """Demonstrations, the GPLVM and its latent box, and both learners' trial runners."""
    demos = bimanual_pairs(preset.n_demos, np.random.default_rng(preset.seed))
    model = GPLVM(n_components=2, max_iter=preset.gplvm_max_iter, random_state=preset.seed).fit(demos)
    low, high = latent_box(model.Z_, preset.latent_margin)
    run = partial(
        _native.run_bimanual_trials,
        episodes=preset.episodes,
        base_seed=preset.seed,
        config=native_config(preset),
        record_episodes=recorded_episodes(preset.episodes),
    )
    learners: dict[str, RunTrials] = {
        "latent": partial(
            run, "latent", decoder=model.decoder_, encoder=model.encoder_, latent_low=low, latent_high=high
        ),
        "full": partial(run, "full"),
    }
    info = {
        "gplvm": gplvm_info(model),
        "latent_box": {"low": low, "high": high},
        "recorded_episodes": recorded_episodes(preset.episodes),
    }
    return Setup(learners=learners, info=info)


def run_exp1(preset: Exp1Preset, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
    """Runs (or continues) Experiment 1 into `out_dir` (results.json, returns.npz, fig4*)."""
    from latentrl.experiments.exp1_figures import figures  # matplotlib: the [plot] extra

    return run_rl(preset, out_dir, setup=setup, figures=figures, progress=progress)
