"""Experiment 2 (paper Sec. IV-B, Fig. 5 and 6): two planar 2-link arms holding an object,
learning in a GPLVM latent space through a physics simulation.

The task is the shipped task file `latentrl/tasks/two_arms.toml` (walls, grip, target, physics,
servos, the paper's learner); the GPLVM (d = 2) is fitted to 123 demonstrated postures with
`hand_R − hand_L = (0.1, 0)`. After training, optional frozen test episodes (no TD updates) start
with both hands below the wall and count how often the learnt policy reaches the target
("success") and passes the wall.

Figures: Fig. 5 (uniform latent samples decoded by PCA and by the GPLVM, constraint kept or
not), Fig. 6a (running mean of the return), 6b/6d (value function before/after learning
with the GPLVM variance shaded and the corridor mapped into latent space), 6c (hand paths
in end-effector space with the corridor).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from latentrl._native import arms_fk
from latentrl.datasets import arm_postures, grip_error
from latentrl.experiments.latent_runs import Fitted, latent_setup, recorded_episodes, run_fit
from latentrl.run_settings import LatentRun, check_ints, latent_box
from latentrl.pca import PCA
from latentrl.experiments.runner import Setup
from latentrl.task import Task

if TYPE_CHECKING:  # matplotlib (the [plot] extra) is imported when a figure is drawn
    from matplotlib.axes import Axes

GRIP_TEST_TOLERANCE = 0.005
"""Fig. 5: a decoded sample keeps the constraint if | ‖h_R − h_L‖ − 0.1 | ≤ this (paper)."""


@dataclass(frozen=True)
class Exp2Preset(LatentRun):
    """Exp 2: two planar 2-link arms, latent-space TD(0) through a physics sim (Fig. 5, 6)."""

    trials: int = 25
    """Independent RL trials (paper: 25)."""
    episodes: int = 5000
    """Training episodes per trial (paper: 5000)."""
    n_demos: int = 123
    """Demonstrated constraint-satisfying postures (paper: 123)."""
    curve_window: int = 500
    """Running-mean window of Fig. 6a (paper: 500; at most episodes // 5 for short runs)."""
    fig5_samples: int = 2000
    """Uniform latent samples per method in Fig. 5 (ours)."""

    def validate(self) -> None:
        """ValueError naming the first impossible field or task key (the task's own rules)."""
        self.check_run()
        check_ints(self, ("n_demos", "curve_window", "fig5_samples"))
        if self.n_demos < 3:
            raise ValueError(f"n_demos must be at least 3 for a 2-D GPLVM, got {self.n_demos!r}")
        task_of(self)

    @classmethod
    def quick(cls) -> Exp2Preset:
        """The CI smoke test (docs/method.md §Experiment 2): w₀ = 100, step 0.5 × spacing, 300
        episodes × 1000 steps, 3 trials, then 50 frozen test episodes from starts below the wall."""
        return dataclasses.replace(
            cls(), trials=3, episodes=300, test_episodes=50,
            task={"learner.initial_weight": 100.0, "learner.step": 0.5},
        )


def task_of(preset: Exp2Preset) -> Task:
    """The shipped two-arms task with the preset's overrides (checked by the task's rules)."""
    return Task.shipped("two_arms").replace(preset.task)


def fit(preset: Exp2Preset, run: Path | None = None) -> Fitted:
    """Demonstrations (seeded by `preset.seed`), GPLVM and latent box; the saved ones of the
    run in directory `run` (`latent_runs.run_fit`). Fits are cached on the fields they depend
    on, so `setup` and `figures` (and presets that differ elsewhere) share one."""
    return run_fit(run, preset.latent_margin, lambda: _fit(
        preset.n_demos, preset.seed, preset.gplvm_max_iter, preset.latent_margin, preset.encoder, preset.latent_spacing))


@lru_cache(maxsize=4)
def _fit(n_demos: int, seed: int, max_iter: int, margin: float, encoder: str, spacing: str) -> Fitted:
    demos = arm_postures(n_demos, np.random.default_rng(seed))
    return Fitted.of(demos, seed=seed, max_iter=max_iter, margin=margin, encoder=encoder, spacing=spacing)


def setup(preset: Exp2Preset, run: Path | None = None) -> Setup:
    """The two-arms task, the GPLVM on `arm_postures(n_demos)` (the run's in directory `run`),
    its latent box and the learner."""
    task = task_of(preset)
    fitted = fit(preset, run)
    return latent_setup(preset, task, fitted.model, (fitted.low, fitted.high), fitted.demos)


# --- figures ----------------------------------------------------------------------------------


PLANAR_HANDS = [0, 1, 3, 4]
"""Columns (x_L, y_L, x_R, y_R) of a recorded row of the planar arms (effectors x, y, z each)."""


def figures(preset: Exp2Preset, arrays: Mapping[str, np.ndarray], run: Path, out: Path) -> None:
    """Fig. 5, 6a, 6b, 6c, 6d of the run in directory `run` into `out` (PNG + PDF)."""
    import matplotlib.pyplot as plt


    from latentrl.plots import hand_paths, latent_run_figures, save_figure, shown_paths

    fitted = fit(preset, run)
    task = task_of(preset)
    config = task.to_dict()
    _fig5(preset, fitted, out)
    latent_run_figures(
        preset, arrays, out, names=("fig6a", "fig6b", "fig6d"), title="Exp 2: two planar arms, mean ± s.d. over trials",
        panel=lambda ax, w: _latent_panel(ax, task, fitted, w, config["learner"]),
    )
    fig, ax = plt.subplots(figsize=(6, 4.5))
    _walls(ax, config)
    paths, label, key = shown_paths(arrays)
    target = np.asarray(config["target"]["position"])[:, :2].ravel()
    if paths is not None:
        episodes = recorded_episodes(preset.episodes) if key == "latent" else []
        hand_paths(ax, paths[0][..., PLANAR_HANDS], target=target, labels=[f"episode {e + 1}" for e in episodes])
    ax.set_title(f"hand paths, {label} (trial 1); dashed: right hand")
    ax.set_xlim(-0.65, 0.6)
    ax.set_ylim(-0.05, 0.65)
    save_figure(fig, out, "fig6c")


def _walls(ax: Axes, config: Mapping[str, Any]) -> None:
    """The task's effector-tested boxes in the arm plane."""
    from matplotlib.patches import Rectangle

    for wall in config["obstacles"]:
        (x0, y0, _), (x1, y1, _) = wall["min"], wall["max"]
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="k"))


def _latent_panel(
    ax: Axes, task: Task, fitted: Fitted, weights: NDArray[np.float64] | None, learner: Mapping[str, Any], grid: int = 120
) -> None:
    """`plots.latent_value_panel` with the task's rules mapped into latent space by the native
    plant: black where the decoded hands are in a wall, red lines around the postures that break
    the grip, dashed white around the target region (the points `latentrl check`'s survey finds
    reached at rest)."""
    from latentrl.derive import survey_at_step
    from latentrl.plots import latent_value_panel

    plant = task.plant(fitted.demos)

    def regions(ax: Axes, g0: NDArray[np.float64], g1: NDArray[np.float64], postures: NDArray[np.float64]) -> None:
        codes = plant.classify(np.clip(postures, task.lower, task.upper))[0].reshape(g0.shape)
        ax.contourf(g0, g1, (codes == 1).astype(float), levels=[0.5, 1.5], colors="k")
        ax.contour(g0, g1, (codes == 3).astype(float), levels=[0.5], colors="r", linewidths=1)
        survey = survey_at_step(task, fitted.model, fitted.low, fitted.high, fitted.demos)
        if survey["reached"].any():
            z0, z1 = survey["points"].T
            ax.tricontour(z0, z1, survey["reached"].astype(float), levels=[0.5], colors="w", linestyles="--",
                          linewidths=1)

    latent_value_panel(ax, weights, fitted.low, fitted.high, fitted.model, learner=learner, regions=regions, grid=grid)


def _fig5(preset: Exp2Preset, fitted: Fitted, out: Path) -> None:
    """Uniform samples of each method's latent box (bounding box + `latent_margin`), decoded:
    green keeps the constraint (| ‖h_R − h_L‖ − 0.1 | ≤ 5 mm), red breaks it."""
    import matplotlib.pyplot as plt


    from latentrl.plots import save_figure

    rng = np.random.default_rng(preset.seed)
    pca = PCA(n_components=2).fit(fitted.demos)
    methods = (("PCA", pca, pca._encode(fitted.demos)), ("GPLVM", fitted.model, fitted.model.Z_))
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    for ax, (name, model, latent) in zip(axes, methods):
        low, high = latent_box(latent, preset.latent_margin)
        samples = rng.uniform(low, high, size=(preset.fig5_samples, 2))
        ok = grip_error(arms_fk(model.inverse_transform(samples))) <= GRIP_TEST_TOLERANCE
        ax.plot(*samples[~ok].T, ".", color="tab:red", ms=3, label="constraint broken")
        ax.plot(*samples[ok].T, ".", color="tab:green", ms=3, label="constraint kept")
        ax.plot(*latent.T, "k.", ms=4, label="demonstrations")
        ax.set_title(f"{name}: {100 * ok.mean():.1f} % of latent samples keep the grip")
        ax.set_xlabel("z1")
        ax.set_ylabel("z2")
    axes[0].legend(loc="best", fontsize=8)
    save_figure(fig, out, "fig5")
