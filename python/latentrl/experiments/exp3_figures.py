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

from latentrl.experiments.exp3 import STYLES, Exp3Preset, episode_styles, fit, floor_level_tests, task_of
from latentrl.experiments.latent_runs import Fitted
from latentrl.plots import latent_run_figures, latent_value_panel, link_positions, save_figure, side_view_stick
from latentrl.task import Task


def figures(preset: Exp3Preset, arrays: Mapping[str, np.ndarray], run: Path, out: Path) -> None:
    """Fig. 7b, 7c, 7d, 7e, 7f (ours: the styles) and 8 of the run in directory `run` into `out`
    (PNG + PDF)."""
    fitted = fit(preset, run)
    task = task_of(preset)
    config = task.to_dict()
    maps: dict[str, Any] = {}
    latent_run_figures(
        preset, arrays, out, names=("fig7e", "fig7b", "fig7c"), title="Exp 3: humanoid lift, mean ± s.d. over trials",
        panel=lambda ax, w: _latent_panel(ax, preset, task, fitted, w, maps),
    )
    _style_counts(preset, arrays, fitted, out)
    floor = floor_level_tests(preset, np.asarray(arrays["latent_weights"])[0], run)
    paths = floor["test_trajectories"][0]
    fig, ax = plt.subplots(figsize=(5, 5))
    _side_view(ax, config)
    plant, rows = task.plant(fitted.demos), task.row_slices()
    base = np.r_[rows["base_position"], rows["base_quaternion"]]
    for k, path in enumerate(paths):
        path = path[np.isfinite(path).all(axis=1)]
        shade = plt.cm.viridis(k / max(len(paths) - 1, 1))
        ax.plot(path[:, 0], path[:, 2], color=shade, lw=1)
        ax.plot(path[:, 3], path[:, 5], color=shade, lw=1, ls="--")
        ax.plot(path[0, 0], path[0, 2], "o", color=shade, ms=3)
        # h* where this episode's start stands it (it moves with `target.relative_to`).
        plant.pose_links(path[0, base], path[0, rows["joints"]])
        h_star = plant.target_position()
        ax.plot(h_star[:, 0], h_star[:, 2], "*", color=shade, mec="r", ms=10)
    reached = int(((floor["test_ends"] == 0) & floor["test_reached"]).sum())
    ax.set(xlim=(-0.05, 0.32), ylim=(-0.01, 0.36), xlabel="x (m, forward)", ylabel="z (m, up)")
    ax.set_aspect("equal")
    ax.set_title(f"hand paths of {len(paths)} frozen lifts from floor-level starts\n(trial 1's policy; "
                 f"{reached} reach h*; dashed: right hand; stars: h*)", fontsize=9)
    save_figure(fig, out, "fig7d")
    _fig8(floor, out, task, fitted.demos)


def _style_counts(preset: Exp3Preset, arrays: Mapping[str, np.ndarray], fitted: Fitted, out: Path) -> None:
    """Fig. 7f (ours): successful training episodes (reached h*, ended by the step limit) per
    window of `curve_window` episodes, summed over the trials and split by the style whose
    demos lie nearest the episode's mean latent state (`exp3.episode_styles`)."""
    ok = (np.asarray(arrays["latent_end"]) == 0) & np.asarray(arrays["latent_reached"])
    style = episode_styles(np.asarray(arrays["latent_mean_state"]), fitted.model.Z_)
    window = max(1, min(preset.curve_window, preset.episodes // 5))
    edges = np.arange(0, preset.episodes + window, window)[: preset.episodes // window + 1]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    bottom = np.zeros(len(edges) - 1)
    for k, name in enumerate(STYLES):
        counts = np.array([(ok & (style == k))[:, a:b].sum() for a, b in zip(edges[:-1], edges[1:])])
        ax.bar(edges[:-1], counts, width=window, bottom=bottom, align="edge", label=f"{name} ({counts.sum()})")
        bottom += counts
    ax.set(xlabel="episode", ylabel=f"successful episodes per {window}\n(all trials)")
    ax.set_title("Exp 3: the style of each successful training episode\n(demos nearest its mean latent state)",
                 fontsize=9)
    ax.legend(fontsize=8)
    save_figure(fig, out, "fig7f")


def _side_view(ax: Axes, config: Mapping[str, Any], dx: float = 0.0) -> None:
    """The floor and the task's obstacles in the x–z plane."""
    for box in config["obstacles"]:
        (cx, _, cz), (hx, _, hz) = box["center"], box["half_extents"]
        ax.add_patch(Rectangle((dx + cx - hx, cz - hz), 2 * hx, 2 * hz, color="0.5", alpha=0.5))
    ax.axhline(0.0, color="0.3", lw=1.5)


def _latent_panel(
    ax: Axes, preset: Exp3Preset, task: Task, fitted: Fitted, weights: NDArray[np.float64] | None, maps: dict[str, Any]
) -> None:
    """`plots.latent_value_panel` on a `map_grid` grid with the decoded postures (clipped to the
    joint limits) that, standing at rest, break a rule of the task (the native plant's
    `classify`): touch the obstacle (black), fall (grey) or break the grip (red); and the target
    region (dashed white: RMS per-hand distance to h* ≤ 2 reach radii, standing). `maps` caches
    the classification between the panels."""
    config = task.to_dict()

    def regions(ax: Axes, g0: NDArray[np.float64], g1: NDArray[np.float64], postures: NDArray[np.float64]) -> None:
        if "rest" not in maps:
            plant = task.plant(fitted.demos)
            maps["rest"], maps["hands"], maps["targets"] = plant.classify(np.clip(postures, task.lower, task.upper))
        rest, hands = maps["rest"].reshape(g0.shape), maps["hands"]
        for code, colour in ((1, "k"), (4, "0.6"), (3, "tab:red")):
            if (rest == code).any():
                ax.contourf(g0, g1, (rest == code).astype(float), levels=[0.5, 1.5], colors=colour, alpha=0.8)
        rms = np.sqrt(((hands - maps["targets"]) ** 2).sum(axis=1) / 2).reshape(g0.shape)
        reach = config["target"]["reach_radius"]
        ax.contour(g0, g1, rms, levels=[2 * reach], colors="w", linestyles="--", linewidths=1)

    latent_value_panel(ax, weights, fitted.low, fitted.high, fitted.model, learner=config["learner"], regions=regions,
                       grid=preset.map_grid)
    for i, (z0, z1) in enumerate(fitted.model.Z_):
        ax.annotate(str(i), (z0, z1), color="w", fontsize=7, xytext=(3, 3), textcoords="offset points")


def _fig8(floor: Mapping[str, Any], out: Path, task: Task, demos: NDArray[np.float64], frames: int = 6) -> None:
    """Frames of a learnt lift from the floor: of the floor-level frozen tests (`floor`) that
    reached h* without an ending (all, if none did), the one whose hands rose most; frames from
    its start to where the hands are 95 % of the way up, and its last step. Side view, drawn
    from the recorded base poses and joint angles by the native kinematics
    (`TaskPlant.pose_links`)."""
    fig, ax = plt.subplots(figsize=(10, 3))
    paths = floor["test_trajectories"][0]
    returns, ok = floor["test_returns"][0], (floor["test_ends"][0] == 0) & floor["test_reached"][0]
    heights = [_hand_height(path) for path in paths]
    rise = np.array([z.max() - z[0] for z in heights])
    candidates = np.flatnonzero(ok) if ok.any() else np.arange(len(paths))
    best = int(candidates[np.argmax(rise[candidates])])
    path = paths[best][np.isfinite(paths[best]).all(axis=1)]
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
    outcome = "reached h*" if ok[best] else "did not reach h*"
    ax.set_title(f"a learnt lift from the floor: frozen test {best} of trial 1's policy ({outcome}, return "
                 f"{returns[best]:.1f}, hands {1e3 * z[0]:.0f} → {1e3 * z.max():.0f} mm)")
    ax.axhline(0.0, color="0.3", lw=1.5)
    ax.set_aspect("equal")
    ax.set(xlabel="x (m; frames 0.35 m apart)", ylabel="z (m)", ylim=(-0.01, 0.36))
    save_figure(fig, out, "fig8")


def _hand_height(path: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mean height of both hands at every recorded step of a trajectory (NaN rows dropped)."""
    path = path[np.isfinite(path).all(axis=1)]
    return (path[:, 2] + path[:, 5]) / 2
