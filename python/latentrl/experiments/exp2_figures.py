"""Figures of Experiment 2 (paper Fig. 5, 6a–d) from a run's arrays, PNG + PDF; needs matplotlib (the
`[plot]` extra)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from matplotlib.patches import Rectangle
from numpy.typing import NDArray

from latentrl.datasets import arms_forward, grip_error
from latentrl.experiments.exp2 import GRIP_TEST_TOLERANCE, Exp2Preset, fit, task_of
from latentrl.experiments.latent_runs import Fitted, recorded_episodes
from latentrl.experiments.presets import latent_box
from latentrl.pca import PCA
from latentrl.plots import hand_paths, latent_run_figures, latent_value_panel, save_figure, shown_paths
from latentrl.task import Task

PLANAR_HANDS = [0, 1, 3, 4]
"""Columns (x_L, y_L, x_R, y_R) of a recorded row of the planar arms (effectors x, y, z each)."""


def figures(preset: Exp2Preset, arrays: Mapping[str, np.ndarray], run: Path, out: Path) -> None:
    """Fig. 5, 6a, 6b, 6c, 6d of the run in directory `run` into `out` (PNG + PDF)."""
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
    for wall in config["obstacles"]:
        (x0, y0, _), (x1, y1, _) = wall["min"], wall["max"]
        ax.add_patch(Rectangle((x0, y0), x1 - x0, y1 - y0, color="k"))


def _latent_panel(
    ax: Axes, task: Task, fitted: Fitted, weights: NDArray[np.float64] | None, learner: Mapping[str, Any], grid: int = 120
) -> None:
    """`plots.latent_value_panel` with the task's rules mapped into latent space by the native
    plant: black where the decoded hands are in a wall, red lines around the postures that break
    the grip, dashed white around the target region."""
    plant = task.plant(fitted.demos)
    reach = task.to_dict()["target"]["reach_radius"]

    def regions(ax: Axes, g0: NDArray[np.float64], g1: NDArray[np.float64], postures: NDArray[np.float64]) -> None:
        codes, effectors, targets = plant.classify(np.clip(postures, task.lower, task.upper))
        codes = codes.reshape(g0.shape)
        ax.contourf(g0, g1, (codes == 1).astype(float), levels=[0.5, 1.5], colors="k")
        ax.contour(g0, g1, (codes == 3).astype(float), levels=[0.5], colors="r", linewidths=1)
        rms = np.sqrt(((effectors - targets) ** 2).sum(axis=1) / 2).reshape(g0.shape)
        ax.contour(g0, g1, rms, levels=[reach], colors="w", linestyles="--", linewidths=1)

    latent_value_panel(ax, weights, fitted.low, fitted.high, fitted.model, learner=learner, regions=regions, grid=grid)


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
