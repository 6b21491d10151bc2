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
