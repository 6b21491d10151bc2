"""Figures of Experiment 1 (paper Fig. 4a–c) from a run's arrays, PNG + PDF; needs matplotlib (the
`[plot]` extra)."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

from latentrl.experiments.exp1 import Exp1Preset, configs
from latentrl.experiments.latent_runs import recorded_episodes
from latentrl.plots import hand_paths, learning_curves, save_figure


def figures(preset: Exp1Preset, arrays: Mapping[str, np.ndarray], run: Path, out: Path) -> None:
    """Fig. 4a (learning curves), 4b (hand paths during learning), 4c (after learning) of a run
    into `out` (they need nothing of the run's directory `run` beyond `arrays`)."""
    fig, ax = plt.subplots(figsize=(6, 4))
    learning_curves(ax, {name: arrays[name] for name in ("latent", "full") if name in arrays})
    ax.set_title("Exp 1: bimanual reaching, mean ± s.d. over trials")
    save_figure(fig, out, "fig4a")
    record = recorded_episodes(preset.episodes)
    plant, _ = configs(preset)
    disc = ((*plant["obstacle_centre"], plant["obstacle_radius"]),)
    target = np.asarray(plant["target"])
    for name, episodes in (("fig4b", record[:3]), ("fig4c", record[-3:])):
        fig, axes = plt.subplots(1, 2, figsize=(9, 4.5), sharex=True, sharey=True)
        for ax, learner in zip(axes, ("latent", "full")):
            paths = arrays.get(f"{learner}_paths")
            if paths is None:
                continue
            hand_paths(ax, paths[0, [record.index(e) for e in episodes]], target=target, discs=disc)
            ax.set_title(f"{learner}: episodes {', '.join(str(e + 1) for e in episodes)} (trial 1)")
        save_figure(fig, out, name)
