"""Experiment 1 (paper Sec. IV-A, Fig. 4): bimanual reaching in end-effector space.

A full-space learner (4-D hand positions, 12 actions, 20⁴ RBFs) against a latent learner
(GPLVM d = 2 on demonstrated constraint-satisfying hand pairs, 4 actions, 20² RBFs). The plant
is the kinematic toy of `sim::bimanual` (keys `plant.*`), the learner `learner.*`: both
declared, with their defaults and rules, in Rust (`latentrl run exp1 --help` lists them).

Figures (the `[plot]` extra, matplotlib imported when they are drawn): Fig. 4a (learning curves),
4b and 4c (hand paths during and after learning).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from latentrl import _native
from latentrl.datasets import bimanual_pairs
from latentrl.experiments.latent_runs import Fitted, recorded_episodes, run_fit
from latentrl.run_settings import LatentRun, check_ints
from latentrl.results import gplvm_info
from latentrl.experiments.runner import RunTrials, Setup


@dataclass(frozen=True)
class Exp1Preset(LatentRun):
    """Exp 1: bimanual reaching in end-effector space, full-space vs latent-space TD(0) (Fig. 4)."""

    trials: int = 25
    """Independent RL trials per learner (paper: 25)."""
    episodes: int = 5000
    """Episodes per trial (paper: 5000)."""
    n_demos: int = 50
    """Demonstrated constraint-satisfying hand pairs (ours: the paper's count is illegible)."""

    def validate(self) -> None:
        """ValueError naming the first impossible field or key (the native rules for `task`)."""
        self.check_run()
        check_ints(self, ("n_demos",))
        configs(self)

    @classmethod
    def quick(cls) -> Exp1Preset:
        """The CI smoke test: step 0.5 × spacing, 500 episodes × 500 steps, 3 trials."""
        return dataclasses.replace(cls(), trials=3, episodes=500, task={"learner.step": 0.5})


def configs(preset: Exp1Preset) -> tuple[dict[str, Any], dict[str, Any]]:
    """The plant's and the learner's effective configuration (every key), checked natively."""
    tables: dict[str, dict[str, Any]] = {"plant": {}, "learner": {}}
    for key, value in preset.task.items():
        table, _, name = key.partition(".")
        if table not in tables or "." in name:
            raise ValueError(f"task key {key!r}: Experiment 1's keys are plant.* and learner.* (see --help)")
        tables[table][name] = value
    plant, learner = _native.bimanual_config(tables["plant"], tables["learner"])
    return plant, learner


def fit(preset: Exp1Preset, run: Path | None = None) -> Fitted:
    """The demonstrated hand pairs (seeded by `preset.seed`), the GPLVM and its latent box; the
    saved ones of the run in directory `run` (`latent_runs.run_fit`)."""
    def refit() -> Fitted:
        demos = bimanual_pairs(preset.n_demos, np.random.default_rng(preset.seed))
        return Fitted.of(demos, seed=preset.seed, max_iter=preset.gplvm_max_iter, margin=preset.latent_margin,
                         encoder=preset.encoder, spacing=preset.latent_spacing)

    return run_fit(run, preset.latent_margin, refit)


def setup(preset: Exp1Preset, run: Path | None = None) -> Setup:
    """Demonstrations, the GPLVM and its latent box (the run's in directory `run`), and both
    learners' trial runners (the latent learner's final weights are kept: `latentrl replay`
    draws its V)."""
    plant, learner = configs(preset)
    fitted = fit(preset, run)
    model, low, high = fitted.model, fitted.low, fitted.high
    trials = partial(
        _native.run_bimanual_trials,
        episodes=preset.episodes,
        base_seed=preset.seed,
        plant=plant,
        learner=learner,
        record_episodes=recorded_episodes(preset.episodes),
    )
    learners: dict[str, RunTrials] = {
        "latent": partial(trials, decoder=model.decoder_, encoder=model.loop_encoder_, latent_low=low, latent_high=high,
                          return_weights=True),
        "full": trials,
    }
    info = {
        "gplvm": gplvm_info(model),
        "latent_box": {"low": low, "high": high},
        "recorded_episodes": recorded_episodes(preset.episodes),
        "plant": plant,
        "learner": learner,
    }
    return Setup(learners=learners, info=info, model=model)


# --- figures ----------------------------------------------------------------------------------


def figures(preset: Exp1Preset, arrays: Mapping[str, np.ndarray], run: Path, out: Path) -> None:
    """Fig. 4a (learning curves), 4b (hand paths during learning), 4c (after learning) of a run
    into `out` (they need nothing of the run's directory `run` beyond `arrays`)."""
    import matplotlib.pyplot as plt


    from latentrl.plots import hand_paths, learning_curves, save_figure

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
