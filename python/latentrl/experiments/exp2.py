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
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache, partial
from importlib import resources
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Rectangle
from numpy.typing import NDArray

from latentrl import _native
from latentrl.datasets import arm_postures, arms_forward, grip_error
from latentrl.experiments.exp1 import recorded_episodes
from latentrl.experiments.presets import check_floats, check_ints, latent_box
from latentrl.experiments.runner import Setup, run_rl
from latentrl.gplvm import GPLVM
from latentrl.pca import PCA
from latentrl.plots import hand_paths, latent_value_panel, learning_curves, save_figure, value_function

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


def urdf_path() -> str:
    """Path of the shipped two-arm URDF."""
    return str(resources.files("latentrl") / "data" / URDF)


def recorded_tests(test_episodes: int) -> list[int]:
    """Test episodes whose hand paths are kept (Fig. 6c): the first ten."""
    return list(range(min(10, test_episodes)))


def setup(preset: Exp2Preset) -> Setup:
    """The GPLVM on `arm_postures(n_demos)`, its latent box and the latent learner's runner."""
    fitted = fit(preset)
    learner = partial(
        _native.run_arms_trials,
        urdf_path(),
        decoder=fitted.model.decoder_,
        encoder=fitted.model.encoder_,
        latent_low=fitted.low,
        latent_high=fitted.high,
        episodes=preset.episodes,
        base_seed=preset.seed,
        config=native_config(preset),
        record_episodes=recorded_episodes(preset.episodes),
        test_episodes=preset.test_episodes,
        record_test_episodes=recorded_tests(preset.test_episodes),
        return_weights=True,
    )
    model = fitted.model
    info = {
        "gplvm": {
            "nll": model.nll_,
            "theta": model.theta_,
            "converged": model.converged_,
            "n_iter": model.n_iter_,
            "encoder_theta": model.encoder_theta_,
        },
        "latent_box": {"low": fitted.low, "high": fitted.high},
        "recorded_episodes": recorded_episodes(preset.episodes),
        "recorded_test_episodes": recorded_tests(preset.test_episodes),
        "walls": [list(w) for w in WALLS],
        "target": TARGET.tolist(),
    }
    return Setup(learners={"latent": learner}, info=info)


def in_walls(hands: NDArray[np.float64]) -> NDArray[np.bool_]:
    """Whether either hand of each row `(x_L, y_L, x_R, y_R)` lies in a corridor wall."""
    inside = np.zeros(len(hands), dtype=bool)
    for x0, y0, x1, y1 in WALLS:
        for hx, hy in ((hands[:, 0], hands[:, 1]), (hands[:, 2], hands[:, 3])):
            inside |= (hx >= x0) & (hx <= x1) & (hy >= y0) & (hy <= y1)
    return inside


def figures(preset: Exp2Preset, arrays: Mapping[str, np.ndarray], out: Path) -> None:
    """Fig. 5, 6a, 6b, 6c, 6d into `out` (PNG + PDF)."""
    fitted = fit(preset)
    _fig5(preset, fitted, out)
    fig, ax = plt.subplots(figsize=(6, 4))
    window = max(1, min(preset.curve_window, preset.episodes // 5))
    learning_curves(ax, {"latent": arrays["latent"]}, window=window)
    ax.set_title("Exp 2: two planar arms, mean ± s.d. over trials")
    save_figure(fig, out, "fig6a")
    weights = arrays.get("latent_weights")
    before = np.full(preset.rbf_per_dim**2, preset.initial_weight)
    panels = (("fig6b", before, "before learning"), ("fig6d", weights, "after learning (trial 1)"))
    for name, w, when in panels:
        if w is None:
            continue
        fig, ax = plt.subplots(figsize=(6, 5))
        _latent_panel(ax, fitted, np.asarray(w)[0] if w.ndim == 2 else w)
        ax.set_title(f"value function {when}")
        save_figure(fig, out, name)
    fig, ax = plt.subplots(figsize=(6, 4.5))
    _walls(ax)
    tests = arrays.get("latent_test_paths")
    paths = tests if tests is not None else arrays.get("latent_paths")
    if paths is not None:
        hand_paths(ax, paths[0], target=TARGET)
    label = "frozen test episodes" if tests is not None else "recorded training episodes"
    ax.set_title(f"hand paths, {label} (trial 1); dashed: right hand")
    ax.set_xlim(-0.65, 0.6)
    ax.set_ylim(-0.05, 0.65)
    save_figure(fig, out, "fig6c")


def _walls(ax: Axes) -> None:
    for x0, y0, x1, y1 in WALLS:
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="k"))


def _latent_panel(ax: Axes, fitted: Fitted, weights: NDArray[np.float64], grid: int = 120) -> None:
    """`plots.latent_value_panel` with the corridor mapped into latent space (black: decoded
    hands in a wall), grip broken > 5 mm (red line) and the target region (dashed white)."""

    def regions(ax: Axes, g0: NDArray[np.float64], g1: NDArray[np.float64], postures: NDArray[np.float64]) -> None:
        hands = arms_forward(postures)
        walls = in_walls(hands).reshape(g0.shape)
        ax.contourf(g0, g1, walls.astype(float), levels=[0.5, 1.5], colors="k")
        drop = grip_error(hands, test="vector").reshape(g0.shape)
        ax.contour(g0, g1, drop, levels=[GRIP_TEST_TOLERANCE], colors="r", linewidths=1)
        rms = np.sqrt(((hands - TARGET) ** 2).sum(axis=1) / 2).reshape(g0.shape)
        ax.contour(g0, g1, rms, levels=[0.05], colors="w", linestyles="--", linewidths=1)

    latent_value_panel(ax, weights, fitted.low, fitted.high, fitted.model, regions=regions, grid=grid)


def _fig5(preset: Exp2Preset, fitted: Fitted, out: Path) -> None:
    """Uniform samples of each method's latent box (bounding box + `latent_margin`), decoded:
    green keeps the constraint (| ‖h_R − h_L‖ − 0.1 | ≤ 5 mm), red breaks it."""
    rng = np.random.default_rng(preset.seed)
    pca = PCA(n_components=2).fit(fitted.demos)
    methods = (("PCA", pca, pca.transform(fitted.demos)), ("GPLVM", fitted.model, fitted.model.Z_))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    for ax, (name, model, latent) in zip(axes, methods):
        low, high = latent_box(latent, preset.latent_margin)
        samples = rng.uniform(low, high, size=(preset.fig5_samples, 2))
        ok = grip_error(arms_forward(model.inverse_transform(samples))) <= GRIP_TEST_TOLERANCE
        ax.plot(*samples[~ok].T, ".", color="tab:red", ms=3, label="constraint broken")
        ax.plot(*samples[ok].T, ".", color="tab:green", ms=3, label="constraint kept")
        ax.plot(*latent.T, "k.", ms=4, label="demonstrations")
        ax.set_title(f"{name}: {100 * ok.mean():.1f} % of latent samples keep the grip")
        ax.set_xlabel("z1")
        ax.set_ylabel("z2")
    axes[0].legend(loc="best", fontsize=8)
    save_figure(fig, out, "fig5")


def run_exp2(preset: Exp2Preset, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
    """Runs (or continues) Experiment 2 into `out_dir` (results.json, returns.npz, fig5, fig6*)."""
    return run_rl(preset, out_dir, setup=setup, figures=figures, progress=progress)
