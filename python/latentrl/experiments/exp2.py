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
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path

import numpy as np

from latentrl.datasets import arm_postures
from latentrl.experiments.latent_runs import Fitted, latent_setup, run_fit
from latentrl.experiments.presets import LatentRun, check_ints
from latentrl.experiments.runner import Setup
from latentrl.task import Task

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
        preset.n_demos, preset.seed, preset.gplvm_max_iter, preset.latent_margin, preset.encoder))


@lru_cache(maxsize=4)
def _fit(n_demos: int, seed: int, max_iter: int, margin: float, encoder: str) -> Fitted:
    demos = arm_postures(n_demos, np.random.default_rng(seed))
    return Fitted.of(demos, seed=seed, max_iter=max_iter, margin=margin, encoder=encoder)


def setup(preset: Exp2Preset, run: Path | None = None) -> Setup:
    """The two-arms task, the GPLVM on `arm_postures(n_demos)` (the run's in directory `run`),
    its latent box and the learner."""
    task = task_of(preset)
    fitted = fit(preset, run)
    return latent_setup(preset, task, fitted.model, (fitted.low, fitted.high), fitted.demos)
