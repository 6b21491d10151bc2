"""Figures of Experiment 3 (paper Fig. 7b–e, 8) from a run's arrays, PNG + PDF; needs matplotlib (the
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

from latentrl.experiments.exp3 import Exp3Preset, fit, task_of
from latentrl.experiments.latent_runs import Fitted, recorded_episodes
from latentrl.plots import (
    latent_run_figures,
    latent_value_panel,
    link_positions,
    save_figure,
    shown_paths,
    side_view_stick,
)
from latentrl.task import Task


def figures(preset: Exp3Preset, arrays: Mapping[str, np.ndarray], out: Path) -> None:
    """Fig. 7b, 7c, 7d, 7e and 8 into `out` (PNG + PDF)."""
    fitted = fit(preset)
    task = task_of(preset)
    config = task.to_dict()
    maps: dict[str, Any] = {}
    latent_run_figures(
        preset, arrays, out, names=("fig7e", "fig7b", "fig7c"), title="Exp 3: humanoid lift, mean ± s.d. over trials",
        learner=config["learner"], panel=lambda ax, w: _latent_panel(ax, preset, task, fitted, w, maps),
    )
    paths, label, returns_key = shown_paths(arrays)
    fig, ax = plt.subplots(figsize=(5, 5))
    _side_view(ax, config)
    if paths is not None:
        for k, path in enumerate(paths[0]):
            path = path[np.isfinite(path).all(axis=1)]
            if path.size == 0:
                continue
            shade = plt.cm.viridis(k / max(len(paths[0]) - 1, 1))
            ax.plot(path[:, 0], path[:, 2], color=shade, lw=1)
            ax.plot(path[:, 3], path[:, 5], color=shade, lw=1, ls="--")
            ax.plot(path[0, 0], path[0, 2], "o", color=shade, ms=3)
    h_star = np.asarray(config["target"]["position"]).ravel()
    ax.plot([h_star[0]], [h_star[2]], "r*", ms=10, label="target")
    ax.set(xlim=(-0.05, 0.32), ylim=(-0.01, 0.36), xlabel="x (m, forward)", ylabel="z (m, up)")
    ax.set_aspect("equal")
    ax.set_title(f"hand paths, {label} (trial 1)\nside view; dashed: right hand")
    save_figure(fig, out, "fig7d")
    _fig8(arrays, paths, returns_key, out, task, fitted.demos)


def _side_view(ax: Axes, config: Mapping[str, Any], dx: float = 0.0) -> None:
    """The floor and the task's obstacles in the x–z plane."""
    for box in config["obstacles"]:
        (cx, _, cz), (hx, _, hz) = box["center"], box["half_extents"]
        ax.add_patch(Rectangle((dx + cx - hx, cz - hz), 2 * hx, 2 * hz, color="0.5", alpha=0.5))
    ax.axhline(0.0, color="0.3", lw=1.5)


def _latent_panel(
    ax: Axes, preset: Exp3Preset, task: Task, fitted: Fitted, weights: NDArray[np.float64], maps: dict[str, Any]
) -> None:
    """`plots.latent_value_panel` on a `map_grid` grid with the decoded postures (clipped to the
    joint limits) that, standing at rest, break a rule of the task (the native plant's
    `classify`): touch the obstacle (black), fall (grey) or break the grip (red); and the target
    region (dashed white: RMS per-hand distance to h* ≤ 2 reach radii, standing). `maps` caches
    the classification between the panels."""
    config = task.to_dict()
    h_star = np.asarray(config["target"]["position"]).ravel()

    def regions(ax: Axes, g0: NDArray[np.float64], g1: NDArray[np.float64], postures: NDArray[np.float64]) -> None:
        if "rest" not in maps:
            plant = task.plant(fitted.demos)
            maps["rest"], maps["hands"] = plant.classify(np.clip(postures, task.lower, task.upper))
        rest, hands = maps["rest"].reshape(g0.shape), maps["hands"]
        for code, colour in ((1, "k"), (4, "0.6"), (3, "tab:red")):
            if (rest == code).any():
                ax.contourf(g0, g1, (rest == code).astype(float), levels=[0.5, 1.5], colors=colour, alpha=0.8)
        rms = np.sqrt(((hands - h_star) ** 2).sum(axis=1) / 2).reshape(g0.shape)
        reach = config["target"]["reach_radius"]
        ax.contour(g0, g1, rms, levels=[2 * reach], colors="w", linestyles="--", linewidths=1)

    latent_value_panel(ax, weights, fitted.low, fitted.high, fitted.model, learner=config["learner"], regions=regions,
                       grid=preset.map_grid)
    for i, (z0, z1) in enumerate(fitted.model.Z_):
        ax.annotate(str(i), (z0, z1), color="w", fontsize=7, xytext=(3, 3), textcoords="offset points")


def _fig8(arrays: Mapping[str, np.ndarray], paths: np.ndarray | None, returns_key: str, out: Path,
          task: Task, demos: NDArray[np.float64], frames: int = 6) -> None:
    """Frames of a learnt lift: of trial 1's recorded episodes that reached h* (all, if none
    did), the one whose hands rose most; frames from its start to where the hands are 95 % of
    the way up, and its last step. Side view, drawn from the recorded base poses and joint
    angles by the native kinematics (`TaskPlant.pose_links`)."""
    fig, ax = plt.subplots(figsize=(10, 3))
    if paths is not None and paths.shape[1] > 0:
        returns = np.asarray(arrays[returns_key])[0]
        reached = np.asarray(arrays[returns_key + "_reached"])[0]
        recorded = np.arange(paths.shape[1])
        if returns_key == "latent":
            # Training paths are recorded for `recorded_episodes`.
            recorded = np.array(recorded_episodes(returns.shape[0]))[: paths.shape[1]]
        heights = [_hand_height(paths[0, k]) for k in range(len(recorded))]
        rise = np.array([z.max() - z[0] for z in heights])
        candidates = np.flatnonzero(reached[recorded]) if reached[recorded].any() else np.arange(len(recorded))
        best = int(candidates[np.argmax(rise[candidates])])
        path = paths[0, best]
        path = path[np.isfinite(path).all(axis=1)]
        z = heights[best]
        top = int(np.argmax(z >= z[0] + 0.95 * rise[best]))
        picks = np.unique(np.r_[np.linspace(0, top, frames - 1).round().astype(int), len(path) - 1])
        plant, rows, config = task.plant(demos), task.row_slices(), task.to_dict()
        base = np.r_[rows["base_position"], rows["base_quaternion"]]
        for k, step in enumerate(picks):
            dx = 0.35 * k
            poses = plant.pose_links(path[step, base], path[step, rows["joints"]])
            _side_view(ax, config, dx)
            side_view_stick(ax, task.edges, link_positions(task.link_names, poses), "C0", dx)
            ax.text(dx + 0.05, 0.33, f"step {step}", fontsize=8, ha="center")
        ax.set_title(f"a learnt lift: recorded episode {int(recorded[best])} of trial 1 (return "
                     f"{returns[recorded[best]]:.1f}, hands {1e3 * rise[best]:.0f} mm up)")
    ax.axhline(0.0, color="0.3", lw=1.5)
    ax.set_aspect("equal")
    ax.set(xlabel="x (m; frames 0.35 m apart)", ylabel="z (m)", ylim=(-0.01, 0.36))
    save_figure(fig, out, "fig8")


def _hand_height(path: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mean height of both hands at every recorded step of a trajectory (NaN rows dropped)."""
    path = path[np.isfinite(path).all(axis=1)]
    return (path[:, 2] + path[:, 5]) / 2
