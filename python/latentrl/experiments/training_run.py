"""A training run of `latentrl train` with its figures: the return curve and, for a 2-D latent
space, the value function before and after learning; needs matplotlib (the `[plot]` extra)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np

from latentrl.experiments.presets import latent_box
from latentrl.experiments.runner import run_rl
from latentrl.experiments.training import TrainRun, fitted, save_policy, setup
from latentrl.plots import latent_value_panel, learning_curves, save_figure
from latentrl.task import end_reasons


def run_training(run: TrainRun, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
    """Runs (or continues) the training into `out_dir` with the one runner, draws its figures and
    writes its policy (`policy.npz`)."""
    meta = run_rl(run, out_dir, setup=setup, figures=figures, progress=progress)
    save_policy(run, Path(out_dir))
    return meta


def figures(run: TrainRun, arrays: Mapping[str, np.ndarray], run_dir: Path, out: Path) -> None:
    """`returns.png` (mean ± s.d. over trials, running mean) and, with d = 2, `value_before.png`,
    `value_after.png` (trial 1), PNG + PDF."""
    task, _, model = fitted(run, run_dir)
    learner = task.to_dict()["learner"]
    fig, ax = plt.subplots(figsize=(6, 4))
    learning_curves(ax, {"latent": arrays["latent"]}, window=max(1, min(100, run.episodes // 5)))
    ax.set_title(f"{task.name}: return per episode, mean ± s.d. over trials")
    save_figure(fig, out, "returns")
    if model.n_components_ != 2 or "latent_weights" not in arrays:
        return
    low, high = latent_box(model.Z_, run.latent_margin)
    for name, weights in (("value_before", None), ("value_after", np.asarray(arrays["latent_weights"])[0])):
        fig, ax = plt.subplots(figsize=(6, 5))
        latent_value_panel(ax, weights, low, high, model, learner=learner)
        ax.set_title(f"{task.name}: value function {name.split('_')[1]} learning")
        save_figure(fig, out, name)
    if "latent_mean_state" in arrays:
        failures(arrays, task.name, low, high, model, learner, out)


def failures(arrays: Mapping[str, np.ndarray], name: str, low: np.ndarray, high: np.ndarray, model: Any,
             learner: Mapping[str, Any], out: Path) -> None:
    """`failures.png`: trial 0's V after learning with, for each episode of the last fifth of the
    episodes it ran that never came within the reach radius, its mean latent state, coloured by how it
    ended (where in the latent space episodes fail)."""
    trial = 0
    ran = int((np.asarray(arrays["latent_end"])[trial] >= 0).sum())  # a stopped trial ran fewer than its budget
    fifth = max(1, ran // 5)
    last = slice(ran - fifth, ran)
    means = np.asarray(arrays["latent_mean_state"])[trial, last]
    ends = np.asarray(arrays["latent_end"])[trial, last]
    failed = ~np.asarray(arrays["latent_reached"], dtype=bool)[trial, last] & np.isfinite(means).all(axis=1)
    fig, ax = plt.subplots(figsize=(6, 5))
    latent_value_panel(ax, np.asarray(arrays["latent_weights"])[trial], low, high, model, learner=learner)
    for code, reason in enumerate(end_reasons()):
        mine = failed & (ends == code)
        if mine.any():
            ax.plot(means[mine, 0], means[mine, 1], "x", ms=5, color=f"C{code}", label=f"{reason} ({mine.sum()})")
    if failed.any():
        ax.legend(fontsize=7, loc="upper right", title="failed, by ending", title_fontsize=7)
    ax.set_title(f"{name}: where the last {fifth} episodes of trial {trial} failed ({failed.sum()})")
    save_figure(fig, out, "failures")
