"""Experiment 2 (paper Sec. IV-B, Fig. 5 and 6): two planar 2-link arms holding an object,
learning in a GPLVM latent space through a physics simulation.

The GPLVM (d = 2) is fitted to 123 demonstrated postures with `hand_R − hand_L = (0.1, 0)`.
A TD(0) learner with 8 latent actions (orthogonal + diagonal) and 20 × 20 RBFs over the
latent box steers the two arms (rapier3d, PD servos tracking the decoded postures) so that
both hands pass a corridor in end-effector space and reach the target (SPEC §4.2 table).
After training, optional frozen test episodes (no TD updates) start with both hands below
the wall and count how often the learnt policy reaches the target ("success") and passes
the wall.

Figures: Fig. 5 (uniform latent samples decoded by PCA and by the GPLVM, constraint kept or
not), Fig. 6a (running mean of the return), 6b/6d (value function before/after learning
with the GPLVM variance shaded and the corridor mapped into latent space), 6c (hand paths
in end-effector space with the corridor).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.datasets import arm_postures
from latentrl.experiments.latent_runs import (
    gplvm_info,
    recorded_episodes,
    recorded_tests,
    robot_learner,
)
from latentrl.experiments.presets import check_floats, check_ints, latent_box
from latentrl.experiments.runner import RunTrials, Setup, run_rl
from latentrl.gplvm import GPLVM

TARGET = np.array([-0.05, 0.47, 0.05, 0.47])
"""h* (ours, SPEC §4.2 table): left hand (−0.05, 0.47), right hand (0.05, 0.47)."""
WALLS = ((-1.0, 0.30, -0.36, 0.37), (-0.06, 0.30, 1.0, 0.37))
"""The corridor (ours, SPEC §4.2 table): two walls (x_min, y_min, x_max, y_max) in metres,
tested on the hand positions only; the gap x ∈ (−0.36, −0.06) is left of the target."""
URDF = "two_arms.urdf"
"""The arms (package data): shoulders (±0.15, 0), links 0.3 + 0.3 m, planar in z = 0."""
GRIP_TEST_TOLERANCE = 0.005
"""Fig. 5: a decoded sample keeps the constraint if | ‖h_R − h_L‖ − 0.1 | ≤ this (paper)."""


@dataclass(frozen=True)
class Exp2Preset:
    """Exp 2: two planar 2-link arms, latent-space TD(0) through a physics sim (Fig. 5, 6)."""

    trials: int = 25
    """Independent RL trials (paper: 25)."""
    episodes: int = 5000
    """Training episodes per trial (paper: 5000)."""
    steps: int = 1000
    """Steps per episode before a time-out (paper: 1000)."""
    seed: int = 0
    """Base seed: demonstrations, GPLVM fit and every trial's RNG derive from it."""
    n_demos: int = 123
    """Demonstrated constraint-satisfying postures (paper: 123)."""
    gplvm_max_iter: int = 1000
    """L-BFGS iteration cap of the GPLVM fit."""
    latent_margin: float = 0.1
    """Latent box = bounding box of the fitted latent points, widened by this share per side
    (ours: 10 %)."""
    drop_tolerance: float = 0.005
    """Dropped when ‖(h_R − h_L) − (0.1, 0)‖ exceeds this, metres (ours, SPEC §4.2: ≥ 3× the
    PD tracking error)."""
    reward_theta: float = 0.35
    """θ of the reward exp(−θ ‖(h − h*)/ℓ‖²) (paper)."""
    reward_length: float = 0.3
    """Length unit ℓ of the reward, metres (ours: with metres alone θ = 0.35 is nearly flat)."""
    reach_radius: float = 0.05
    """'Reached the target': RMS per-hand distance to h* at most this, metres (ours, SPEC §4.2)."""
    rbf_per_dim: int = 20
    """RBF centres per latent dimension (paper: 20)."""
    rbf_cutoff: float = 3.0
    """Sparse RBFs: centres farther than this many σ contribute nothing (ours)."""
    beta: float = 20.0
    """Soft-max inverse temperature β (paper)."""
    alpha: float = 0.8
    """TD(0) learning rate α (paper)."""
    gamma: float = 0.99
    """Discount γ (paper)."""
    step_fraction: float = 0.2
    """Latent step length as a share of the RBF spacing per dimension, diagonals √2 longer (ours)."""
    initial_weight: float = 0.0
    """Initial value weights (0 paper-like; 1/(1−γ) = 100 is optimistic and much faster)."""
    variance_threshold: float = 0.0
    """Latent targets with GPLVM variance above this are infeasible (−1, end); 0 = off (SPEC §3.2)."""
    test_episodes: int = 0
    """Frozen test episodes per trial after training (no TD updates, hands start below the
    wall); 0 = none (ours)."""
    physics_dt: float = 1.0 / 240.0
    """Physics time step, s; δt = physics_dt × substeps = 0.05 s (paper's δt)."""
    substeps: int = 12
    """Physics steps per RL step."""
    solver_iterations: int = 2
    """rapier solver iterations per physics step (ours: 2 keeps PD tracking < 1 mrad at ~55 %
    of the cost of 4)."""
    kp: float = 5000.0
    """PD stiffness of every joint servo, N·m/rad (ours: force-based, tracks a 0.1 rad step to
    < 1 mrad in 0.05 s)."""
    kd: float = 50.0
    """PD damping of every joint servo, N·m·s/rad (ours)."""
    curve_window: int = 500
    """Running-mean window of Fig. 6a (paper: 500; at most episodes // 5 for short runs)."""
    fig5_samples: int = 2000
    """Uniform latent samples per method in Fig. 5 (ours)."""

    def validate(self) -> None:
        """ValueError naming the first field with an impossible value."""
        check_ints(
            self,
            ("trials", "episodes", "steps", "n_demos", "gplvm_max_iter", "rbf_per_dim", "substeps",
             "solver_iterations", "curve_window", "fig5_samples"),
        )
        check_ints(self, ("seed", "test_episodes"), minimum=0)
        if self.n_demos < 3:
            raise ValueError(f"n_demos must be at least 3 for a 2-D GPLVM, got {self.n_demos!r}")
        check_floats(
            self,
            ("drop_tolerance", "reward_theta", "reward_length", "reach_radius", "rbf_cutoff", "beta",
             "alpha", "step_fraction", "physics_dt", "kp"),
            positive=True,
        )
        check_floats(self, ("latent_margin", "variance_threshold", "kd"), positive=False)
        if not np.isfinite(self.initial_weight):
            raise ValueError(f"initial_weight must be finite, got {self.initial_weight!r}")
        if not 0 <= self.gamma < 1:
            raise ValueError(f"gamma must lie in [0, 1), got {self.gamma!r}")

    @classmethod
    def quick(cls) -> Exp2Preset:
        """The CI smoke test (SPEC §4.2): w₀ = 100, step 0.5 × spacing, 300 episodes × 1000
        steps, 3 trials, then 50 frozen test episodes from starts below the wall."""
        return dataclasses.replace(
            cls(), trials=3, episodes=300, initial_weight=100.0, step_fraction=0.5, test_episodes=50
        )


def native_config(preset: Exp2Preset) -> dict[str, Any]:
    """The preset in the configuration keys of `_native.run_arms_trials`."""
    return {
        "target": TARGET.tolist(),
        "theta": preset.reward_theta,
        "length_scale": preset.reward_length,
        "walls": [list(w) for w in WALLS],
        "drop_tolerance": preset.drop_tolerance,
        "reached_rms": preset.reach_radius,
        "dt": preset.physics_dt,
        "substeps": preset.substeps,
        "solver_iterations": preset.solver_iterations,
        "kp": preset.kp,
        "kd": preset.kd,
        "alpha": preset.alpha,
        "gamma": preset.gamma,
        "initial_weight": preset.initial_weight,
        "beta": preset.beta,
        "step_fraction": preset.step_fraction,
        "max_steps": preset.steps,
        "centres_per_dim": preset.rbf_per_dim,
        "rbf_cutoff": preset.rbf_cutoff,
        "variance_threshold": preset.variance_threshold or None,
        "start": "uniform",
    }


@dataclass(frozen=True)
class Fitted:
    """The demonstrations, the GPLVM fitted to them and the latent box of the learner."""

    demos: NDArray[np.float64]
    model: GPLVM
    low: NDArray[np.float64]
    high: NDArray[np.float64]


def fit(preset: Exp2Preset) -> Fitted:
    """Demonstrations (seeded by `preset.seed`), GPLVM and latent box; cached on the fields
    they depend on, so `setup` and `figures` (and presets that differ elsewhere) share a fit."""
    return _fit(preset.n_demos, preset.seed, preset.gplvm_max_iter, preset.latent_margin)


@lru_cache(maxsize=4)
def _fit(n_demos: int, seed: int, max_iter: int, margin: float) -> Fitted:
    demos = arm_postures(n_demos, np.random.default_rng(seed))
    model = GPLVM(n_components=2, max_iter=max_iter, random_state=seed).fit(demos)
    low, high = latent_box(model.Z_, margin)
    return Fitted(demos, model, low, high)


JOINT_NAMES = ("left_shoulder", "left_elbow", "right_shoulder", "right_elbow")
"""The arms' joints in the URDF, the column order of their postures (q1_L, q2_L, q1_R, q2_R)."""


def urdf_path() -> str:
    """Path of the shipped two-arm URDF."""
    return str(resources.files("latentrl") / "data" / URDF)


def learner(preset: Exp2Preset, model: GPLVM, low: NDArray[np.float64], high: NDArray[np.float64]) -> RunTrials:
    """The latent learner of `preset` on the two arms, in the latent box (`low`, `high`) of a
    fitted GPLVM of arm postures (columns `JOINT_NAMES`)."""
    return robot_learner(_native.run_arms_trials, urdf_path(), preset, model, (low, high), native_config(preset))


def setup(preset: Exp2Preset) -> Setup:
    """The GPLVM on `arm_postures(n_demos)`, its latent box and the latent learner's runner."""
    fitted = fit(preset)
    model = fitted.model
    info = {
        "gplvm": gplvm_info(model),
        "latent_box": {"low": fitted.low, "high": fitted.high},
        "recorded_episodes": recorded_episodes(preset.episodes),
        "recorded_test_episodes": recorded_tests(preset.test_episodes),
        "walls": [list(w) for w in WALLS],
        "target": TARGET.tolist(),
    }
    return Setup(learners={"latent": learner(preset, model, fitted.low, fitted.high)}, info=info)


def in_walls(hands: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether either hand of each row `(x_L, y_L, x_R, y_R)` lies in a corridor wall."""
    inside = np.zeros(len(hands), dtype=bool)
    for x0, y0, x1, y1 in WALLS:
        for hx, hy in ((hands[:, 0], hands[:, 1]), (hands[:, 2], hands[:, 3])):
            inside |= (hx >= x0) & (hx <= x1) & (hy >= y0) & (hy <= y1)
    return inside


def run_exp2(preset: Exp2Preset, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
    """Runs (or continues) Experiment 2 into `out_dir` (results.json, returns.npz, fig5, fig6*)."""
    from latentrl.experiments.exp2_figures import figures  # matplotlib: the [plot] extra

    return run_rl(preset, out_dir, setup=setup, figures=figures, progress=progress)
