"""The experiments by the name `latentrl run` gives them: each one's preset and runner, and for
the RL experiments what a sweep, a resume or a re-plot needs."""

from __future__ import annotations

import importlib
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

from latentrl.experiments.runner import Setup, run_rl


class RlExperiment(NamedTuple):
    """What the runner, a sweep and `latentrl plot` need of an RL experiment, whose runs
    results.json keeps trial by trial."""

    preset: type
    """Its frozen preset dataclass."""
    setup: Callable[[Any, Path | None], Setup]
    """`setup(preset, run_dir)`: the learners and the facts results.json records (with a run
    directory, in the model saved there)."""
    figures_module: str
    """The module whose `figures(preset, arrays, run_dir, out_dir)` draws the run's figures,
    imported only to draw (matplotlib, the `[plot]` extra)."""
    learners: tuple[str, ...]
    """The learners `setup` builds, by name."""
    task: Callable[[Any], dict[str, Any]]
    """`task(preset)`: the effective task keys of a preset (nested tables), e.g. for `--help`."""

    def figures(self, preset: Any, arrays: Mapping[str, np.ndarray], run_dir: Path, out_dir: Path) -> None:
        """Draws the figures of the run of `preset` in `run_dir` from its `arrays` into `out_dir`."""
        importlib.import_module(self.figures_module).figures(preset, arrays, run_dir, out_dir)

    def run(self, preset: Any, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
        """Runs (or continues) `preset` into `out_dir` with the one runner, figures included; without
        matplotlib it fails (ModuleNotFoundError) before any work."""
        draw = importlib.import_module(self.figures_module).figures
        return run_rl(preset, out_dir, setup=self.setup, figures=draw, progress=progress)


class Experiment(NamedTuple):
    """One `latentrl run` experiment."""

    preset: type
    """Its frozen preset dataclass; every scalar field becomes a `--flag`."""
    table: Callable[..., Any] | None
    """Table I's `run(preset, out_dir, progress=...)`; None for the RL experiments (`rl.run`)."""
    rl: RlExperiment | None
    """Set for the RL experiments (resumable, re-plottable, sweepable); None for Table I."""

    def run(self, preset: Any, out_dir: Path | str, *, progress: bool = True) -> Any:
        """Runs `preset` into `out_dir`."""
        if self.rl is not None:
            return self.rl.run(preset, out_dir, progress=progress)
        assert self.table is not None
        return self.table(preset, out_dir, progress=progress)


def experiments() -> dict[str, Experiment]:
    """Every experiment, by name."""
    from latentrl.experiments import exp1, exp2, exp3, table1

    return {
        "table1": Experiment(table1.Table1Preset, table1.run_table1, None),
        "exp1": Experiment(
            exp1.Exp1Preset, None,
            RlExperiment(exp1.Exp1Preset, exp1.setup, "latentrl.experiments.exp1_figures", ("latent", "full"),
                         lambda p: dict(zip(("plant", "learner"), exp1.configs(p)))),
        ),
        "exp2": Experiment(
            exp2.Exp2Preset, None,
            RlExperiment(exp2.Exp2Preset, exp2.setup, "latentrl.experiments.exp2_figures", ("latent",),
                         lambda p: exp2.task_of(p).to_dict()),
        ),
        "exp3": Experiment(
            exp3.Exp3Preset, None,
            RlExperiment(exp3.Exp3Preset, exp3.setup, "latentrl.experiments.exp3_figures", ("latent",),
                         lambda p: exp3.task_of(p).to_dict()),
        ),
    }


def task_schema(experiment: str) -> tuple[dict[str, Any], ...]:
    """The task keys an RL experiment takes (`--table.key` flags, sweep keys): Experiment 1's
    toy (`plant.*`, `learner.*`) or a task file's, from the native definitions."""
    from latentrl import _native

    return tuple(_native.bimanual_schema() if experiment == "exp1" else _native.task_schema())


def run_experiment(name: str, preset: Any, out_dir: Path | str, *, progress: bool = True) -> Any:
    """Runs (or continues) experiment `name` (`table1`, `exp1`, `exp2`, `exp3`) with `preset` into
    `out_dir`: results.json, returns.npz and the figures (the `[plot]` extra)."""
    return experiments()[name].run(preset, out_dir, progress=progress)


def rl_experiments() -> dict[str, RlExperiment]:
    """The RL experiments, by name."""
    return {name: exp.rl for name, exp in experiments().items() if exp.rl is not None}
