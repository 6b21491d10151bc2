"""The experiments by the name `latentrl run` gives them: each one's preset and runner, and for
the RL experiments what a sweep, a resume or a re-plot needs."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from latentrl.experiments.runner import Setup


class RlExperiment(NamedTuple):
    """What the runner, a sweep and `latentrl plot` need of an RL experiment, whose runs
    results.json keeps trial by trial."""

    preset: type
    """Its frozen preset dataclass."""
    setup: Callable[[Any], Setup]
    """`setup(preset)`: the learners and the facts results.json records."""
    figures_module: str
    """The module whose `figures(preset, arrays, out_dir)` draws the run's figures, imported
    only to draw (matplotlib, the `[plot]` extra)."""
    learners: tuple[str, ...]
    """The learners `setup` builds, by name."""

    def figures(self, preset: Any, arrays: Mapping[str, np.ndarray], out_dir: Path) -> None:
        """Draws the figures of a run of `preset` from its `arrays` into `out_dir`."""
        importlib.import_module(self.figures_module).figures(preset, arrays, out_dir)


class Experiment(NamedTuple):
    """One `latentrl run` experiment."""

    preset: type
    """Its frozen preset dataclass; every scalar field becomes a `--flag`."""
    run: Callable[..., Any]
    """`run(preset, out_dir, progress=...)`."""
    rl: RlExperiment | None
    """Set for the RL experiments (resumable, re-plottable, sweepable); None for Table I."""


def experiments() -> dict[str, Experiment]:
    """Every experiment, by name."""
    from latentrl.experiments import exp1, exp2, exp3, table1

    return {
        "table1": Experiment(table1.Table1Preset, table1.run_table1, None),
        "exp1": Experiment(
            exp1.Exp1Preset, exp1.run_exp1, RlExperiment(exp1.Exp1Preset, exp1.setup, "latentrl.experiments.exp1_figures", ("latent", "full"))
        ),
        "exp2": Experiment(
            exp2.Exp2Preset, exp2.run_exp2, RlExperiment(exp2.Exp2Preset, exp2.setup, "latentrl.experiments.exp2_figures", ("latent",))
        ),
        "exp3": Experiment(
            exp3.Exp3Preset, exp3.run_exp3, RlExperiment(exp3.Exp3Preset, exp3.setup, "latentrl.experiments.exp3_figures", ("latent",))
        ),
    }


def rl_experiments() -> dict[str, RlExperiment]:
    """The RL experiments, by name."""
    return {name: exp.rl for name, exp in experiments().items() if exp.rl is not None}
