"""The settings every latent RL run shares (`LatentRun`: trials, episodes, seed, the GPLVM fit,
the latent box's margin, overrides of the task by key path), `TrainPreset` (a training run on a
task of your own: `train_latent_policy`, `latentrl train`, `latentrl check`'s costing), the
latent box and how overrides (a CLI flag, a sweep cell, a keyword) apply. The experiments'
presets extend `LatentRun` (`latentrl.experiments`).

The run settings (trials, episodes, seed, test episodes, GPLVM iterations, encoder, latent
margin, latent spacing) are the `[run]` table's keys (docs/tasks.md): their docs, defaults and
rules are the native `RunConfig`'s, a preset states only the values it chooses, a task file's
`[run]` replaces those (`with_task_run`) and flags replace that. The other fields are Python-side
choices (demos, what the figures draw); every task, learner and physics parameter is a key of
the experiment's task file, overridden by key path (``task={"learner.alpha": 0.5}``,
``--learner.alpha 0.5``) and checked by the native side's rules."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from latentrl._validation import int_at_least
from latentrl.task import Task, check_run, run_default, run_settings


def check_run_fields(preset: Any, names: tuple[str, ...]) -> None:
    """ValueError naming `run.<name>` and its rule unless the preset's run settings `names` keep
    the `[run]` table's rules (the one check of run settings: `latentrl.task.check_run`)."""
    check_run({name: getattr(preset, name) for name in names})


def latent_box(latent: np.ndarray, margin: float) -> tuple[np.ndarray, np.ndarray]:
    """The bounding box of the latent points, widened by `margin` of its width per side; a
    ValueError naming the margin if that box overflows (1e308: the run failed naming only
    `latent_low` holding -inf)."""
    low, high = latent.min(axis=0), latent.max(axis=0)
    with np.errstate(over="ignore", invalid="ignore"):
        pad = margin * (high - low)
        box = low - pad, high + pad
    if np.isfinite(latent).all() and not (np.isfinite(box[0]).all() and np.isfinite(box[1]).all()):
        raise ValueError(f"run.latent_margin = {margin:g} widens the latent box beyond the largest float; a margin "
                         "is a share of the box's width per side (ours: 0.1)")
    return box


def check_ints(preset: Any, names: tuple[str, ...], minimum: int = 1) -> None:
    """ValueError naming the first of `names` that is not an int >= `minimum`."""
    for name in names:
        int_at_least(name, getattr(preset, name), minimum)


def check_floats(preset: Any, names: tuple[str, ...], *, positive: bool) -> None:
    """ValueError naming the first of `names` that is not finite and > 0 (or >= 0)."""
    for name in names:
        value = getattr(preset, name)
        ok = isinstance(value, (int, float, np.integer, np.floating)) and np.isfinite(value)
        if not ok or value < 0 or (positive and value == 0):
            bound = "> 0" if positive else ">= 0"
            raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")


class Overrides(dict[str, Any]):
    """Task keys by path → values: a dict that hashes by its items, so that presets holding one
    stay hashable (caches, sweep cells)."""

    def __hash__(self) -> int:  # type: ignore[override]
        return hash(repr(sorted(self.items(), key=lambda kv: kv[0])))


@dataclass(frozen=True)
class LatentRun:
    """What every latent-space RL experiment's preset holds: the trials, the GPLVM fit, and
    overrides of the experiment's task by key path."""

    # The run settings: each one's doc, default and rule are the `[run]` table's (docs/tasks.md).
    trials: int = run_default("trials")
    episodes: int = run_default("episodes")
    seed: int = run_default("seed")
    test_episodes: int = run_default("test_episodes")
    gplvm_max_iter: int = run_default("gplvm_max_iter")
    encoder: str = run_default("encoder")
    latent_margin: float = run_default("latent_margin")
    latent_spacing: str = run_default("latent_spacing")
    task: Mapping[str, Any] = field(default_factory=dict)
    """Overrides of the experiment's task by key path, e.g. {"learner.alpha": 0.5} (flags: --learner.alpha)."""

    def __post_init__(self) -> None:
        if isinstance(self.task, Mapping) and not isinstance(self.task, Overrides):
            object.__setattr__(self, "task", Overrides(self.task))

    def check_run(self) -> None:
        """ValueError naming the first impossible shared field (a run setting: `run.<name>`)."""
        check_run_fields(self, tuple(run_settings()))
        if not isinstance(self.task, Mapping) or not all(isinstance(k, str) and "." in k for k in self.task):
            raise ValueError(f"task: expected overrides by key path such as {{'learner.alpha': 0.5}}, got {self.task!r}")
        run = sorted(k for k in self.task if k.startswith("run."))
        if run:
            raise ValueError(f"task: {', '.join(run)}: run settings are the preset's fields "
                             f"({', '.join(k.removeprefix('run.') for k in run)}), not task overrides")


def with_task_run(preset: Any, task: Task) -> Any:
    """`preset` with the run settings `task` sets (its file's `[run]`, `Task.run_given`) where the
    preset holds its class's default: a quick preset's own values win over the file, and fields
    given later (`with_overrides`: flags, API arguments) over both."""
    default = type(preset)()
    given = {k: v for k, v in task.run_given().items() if getattr(preset, k) == getattr(default, k)}
    return dataclasses.replace(preset, **given) if given else preset


def with_overrides(preset: Any, overrides: Mapping[str, Any]) -> Any:
    """`preset` with `overrides` applied: a preset field by its name (a run setting also as
    ``run.trials``), a task key by its path (``learner.alpha``: added to the preset's `task`).
    An unknown field is a ValueError listing the valid ones; task keys are checked by the task
    (`validate`)."""
    fields = {f.name for f in dataclasses.fields(preset)}
    run = {f"run.{name}" for name in run_settings() if name in fields}
    overrides = {k.removeprefix("run.") if k in run else k: v for k, v in overrides.items()}
    plain = {k: v for k, v in overrides.items() if "." not in k}
    unknown = sorted(set(plain) - fields - {"task"})
    if unknown:
        raise ValueError(
            f"unknown preset fields {unknown}; {type(preset).__name__} has {sorted(fields - {'task'})}, "
            "and task keys are given by path (learner.alpha, episode.max_steps, …)"
        )
    task = {**getattr(preset, "task", {}), **plain.pop("task", {}), **{k: v for k, v in overrides.items() if "." in k}}
    if task and "task" not in fields:
        raise ValueError(f"{type(preset).__name__} takes no task keys, got {sorted(task)}")
    return dataclasses.replace(preset, **plain, **({"task": task} if "task" in fields else {}))


@dataclass(frozen=True)
class TrainPreset(LatentRun):
    """Training a latent policy on a task of your own (`latentrl train`)."""

    trials: int = 2
    """Independent RL trials; the policy keeps each trial's weights and acts with trial 0's (ours: 2,
    which run side by side on 2 cores: 4 took the zoo's biped two rounds, ≈ 14 minutes, for the
    same trial 0, bit for bit; `examples/zoo/README.md`, "Session 9")."""
    episodes: int = 2000
    """Training episodes per trial (ours: 2000)."""
    test_episodes: int = 20
    """Frozen test episodes per trial after training (no TD updates, the task's test starts; ours: 20)."""
    gplvm_max_iter: int = 10000
    """Iterations of the GPLVM fit, a guard, not a budget: the robot zoo's fits converge within it
    (the 7-DoF arms' in 1486 and 4355 iterations, 11 and 24 s CPU), where the experiments' 1000
    stopped them unconverged."""
    encoder: str = "tracking"
    """Posture → latent map of the RL loop (the `[run]` table's `encoder`): "tracking" for a task of your own
    (on the robot zoo at the default budget it matched the paper's "gp" on one robot and raised the
    greedy reach rate on two, 52 → 90 % and 22 → 46 %; docs/encoders.md)."""

    def validate(self) -> None:
        """ValueError naming the first impossible field."""
        self.check_run()

    @classmethod
    def quick(cls) -> TrainPreset:
        """A short run to see that it learns: 2 trials × 300 episodes, 10 test episodes (the
        learner's step and w₀ are derived where the task is silent: `latentrl.derive`)."""
        return dataclasses.replace(cls(), episodes=300, test_episodes=10)
