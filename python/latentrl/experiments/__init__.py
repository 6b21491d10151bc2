"""The paper's experiments: one frozen preset per experiment, run by one runner; here, the
experiments by the name `latentrl run` gives them: each one's preset and runner, and for the RL
experiments what a sweep, a resume or a re-plot needs. The experiments' modules (and the runner)
are imported when `experiments()` is first called, not with the package."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

if TYPE_CHECKING:
    import numpy as np

    from latentrl.experiments.runner import Setup


class RlExperiment(NamedTuple):
    """What the runner, a sweep and `latentrl plot` need of an RL experiment, whose runs
    results.json keeps trial by trial."""

    preset: type
    """Its frozen preset dataclass."""
    setup: Callable[[Any, Path | None], Setup]
    """`setup(preset, run_dir)`: the learners and the facts results.json records (with a run
    directory, in the model saved there)."""
    draw: Callable[[Any, Mapping[str, np.ndarray], Path, Path], None]
    """`draw(preset, arrays, run_dir, out_dir)`: the experiment module's `figures`, which imports
    matplotlib (the `[plot]` extra) when it draws."""
    learners: tuple[str, ...]
    """The learners `setup` builds, by name."""
    task: Callable[[Any], dict[str, Any]]
    """`task(preset)`: the effective task keys of a preset (nested tables), e.g. for `--help`."""

    def figures(self, preset: Any, arrays: Mapping[str, np.ndarray], run_dir: Path, out_dir: Path) -> None:
        """Draws the figures of the run of `preset` in `run_dir` from its `arrays` into `out_dir`."""
        self.draw(preset, arrays, run_dir, out_dir)

    def run(self, preset: Any, out_dir: Path | str, *, progress: bool = True) -> dict[str, Any]:
        """Runs (or continues) `preset` into `out_dir` with the one runner, figures included; without
        matplotlib it fails (ModuleNotFoundError) before any work."""
        import matplotlib.pyplot  # noqa: F401  (the figures' extra, checked before the trials run)

        from latentrl.experiments.runner import run_rl

        return run_rl(preset, out_dir, setup=self.setup, figures=self.draw, progress=progress)


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
            RlExperiment(exp1.Exp1Preset, exp1.setup, exp1.figures, ("latent", "full"),
                         lambda p: dict(zip(("plant", "learner"), exp1.configs(p)))),
        ),
        "exp2": Experiment(
            exp2.Exp2Preset, None,
            RlExperiment(exp2.Exp2Preset, exp2.setup, exp2.figures, ("latent",),
                         lambda p: exp2.task_of(p).to_dict()),
        ),
        "exp3": Experiment(
            exp3.Exp3Preset, None,
            RlExperiment(exp3.Exp3Preset, exp3.setup, exp3.figures, ("latent",),
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
