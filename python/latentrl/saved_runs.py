"""A run folder read back as the run it holds: its experiment's name and preset, with the task its
trials ran with (`latentrl run --resume`, `plot`, `replay`)."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

from latentrl.task import by_path, changed_since


def saved_run(out_dir: Path, *, train: bool = False) -> tuple[str, Any]:
    """(experiment name, preset) of the RL run in `out_dir`, from its results.json — with `train`,
    also ("train", its TrainRun) for a `latentrl train` directory; ValueError if the directory
    holds none, or the preset does not fit this version."""
    from latentrl.experiments import experiments
    from latentrl.experiments.run_folder import RunFolder

    folder = RunFolder(out_dir)
    if not folder.results_path.is_file():
        raise ValueError(f"{out_dir}: no results.json there, so no run of an RL experiment")
    fields = folder.preset()
    preset_name = fields.pop("name", None)
    known = [(name, exp.preset) for name, exp in experiments().items() if exp.rl]
    if train:
        from latentrl.experiments.training import TrainRun

        known.append(("train", TrainRun))
    found = [(name, cls) for name, cls in known if cls.__name__ == preset_name]
    if not found:
        raise ValueError(f"{out_dir}: results.json names no RL experiment's preset (found {preset_name!r})")
    name, preset_cls = found[0]
    unknown = sorted(set(fields) - {f.name for f in dataclasses.fields(preset_cls)})
    if unknown:
        raise ValueError(f"{out_dir}: its preset has fields this version does not know: {unknown}")
    preset = preset_cls(**fields)
    recorded = folder.recorded_task()
    if name == "train" or recorded is None:
        return name, preset
    return name, _as_recorded(out_dir, name, preset, recorded)


def _as_recorded(out_dir: Path, name: str, preset: Any, recorded: dict[str, Any]) -> Any:
    """`preset` with a task override for every key it does not set whose recorded value this
    version's task does not give (a shipped task file changed since the run): its figures, replays and resume
    use the task its trials ran with. A key added since the run takes its default, the
    behaviour before it. A key no override can set is a ValueError."""
    from latentrl.experiments import experiments, task_schema

    rl = experiments()[name].rl
    assert rl is not None
    changed = {k: v for k, v in changed_since(recorded, rl.task(preset)).items() if k not in preset.task}
    settable = {e["key"] for e in task_schema(name) if by_path(e)}
    fixed = sorted(set(changed) - settable)
    if fixed:
        raise ValueError(f"{out_dir}: its trials ran with a task this version cannot rebuild ({', '.join(fixed)} "
                         "differ and no override sets them); use the latentrl version that made it")
    return dataclasses.replace(preset, task={**preset.task, **changed}) if changed else preset
