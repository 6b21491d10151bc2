"""One runner for every RL experiment (docs/method.md §Results layout): seed, build the learners,
run the trials in chunks, save after each chunk, draw the figures.

A results directory that already holds a run of the same preset is continued: finished
trials are kept and only the missing ones run (the trials' seeds depend on the base seed
and the trial index alone, so the result equals an uninterrupted run). A different preset
in the same directory is an error.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple, Protocol

import numpy as np

from latentrl.machine import peak_rss_mib, worker_threads
from latentrl.run_lock import run_lock
from latentrl.experiments.presets import describe
from latentrl.experiments.run_folder import RunFolder
from latentrl.results import (
    PER_EPISODE,
    PER_TRIAL,
    PRESET_KEY,
    array_key,
    as_saved,
    environment,
    not_run,
    not_run_like,
    summarise_trial,
    write_json,
    write_npz,
)


#: A learner: runs trials `first .. first + n` and returns the native call's dict.
RunTrials = Callable[..., dict[str, Any]]


class Job(NamedTuple):
    """A run to make elsewhere than `run_rl`'s caller (a sweep's cell on a backend): an RL
    experiment's preset into its results directory."""

    experiment: str
    """The experiment's name (`latentrl.experiments.rl_experiments`)."""
    id: str
    """What the run is called in messages (a sweep's cell id)."""
    preset: Any
    """The preset to run."""
    out: Path
    """Its results directory."""


class Preset(Protocol):
    """What the runner needs of a preset (a frozen dataclass: read-only fields)."""

    @property
    def trials(self) -> int: ...
    @property
    def episodes(self) -> int: ...
    @property
    def seed(self) -> int: ...

    def validate(self) -> None:
        """ValueError naming the first impossible field."""


@dataclass
class Setup:
    """What an experiment builds before its trials: learners by name, and facts to record."""

    learners: dict[str, RunTrials]
    info: dict[str, Any] = field(default_factory=dict)
    model: Any = None
    """The fitted model the learners work in (a GPLVM), saved beside the results as `results.MODEL_FILE`."""


#: Runs chunks of trials `(learner, first, count)` of a setup and yields each chunk with its
#: native call's dict as it finishes (in any order); `advance(episodes)` moves the progress bar.
Execute = Callable[
    [Setup, list[tuple[str, int, int]], Callable[[int], object]],
    Iterable[tuple[str, int, int, dict[str, Any]]],
]


def episodes_per_trial(preset: Any) -> int:
    """Episodes a trial of `preset` reports progress for: the training and the frozen test
    episodes (the native calls count both)."""
    return int(preset.episodes + getattr(preset, "test_episodes", 0))


def run_in_process(
    built: Setup, chunks: list[tuple[str, int, int]], advance: Callable[[int], object]
) -> Iterator[tuple[str, int, int, dict[str, Any]]]:
    """The default `Execute`: one chunk after the other in this process, rayon running the
    chunk's trials in parallel."""
    for name, first, n in chunks:
        seen = [0]

        def report(done: int, _total: int, seen: list[int] = seen) -> None:
            advance(done - seen[0])
            seen[0] = done

        yield name, first, n, built.learners[name](first_trial=first, n_trials=n, progress=report)


def run_rl(
    preset: Preset,
    out_dir: Path | str,
    *,
    setup: Callable[[Any, Path], Setup],
    figures: Callable[[Any, Mapping[str, np.ndarray], Path, Path], None],
    progress: bool = True,
    chunk: int | None = None,
    execute: Execute = run_in_process,
) -> dict[str, Any]:
    """Runs (or continues) `preset` into `out_dir`; returns the metadata written to results.json.
    `setup(preset, out_dir)` builds the learners (a continued run's in its saved model),
    `figures(preset, arrays, run_dir, figure_dir)` draws them at the end. `execute` runs the
    chunks (elsewhere, e.g. on a Ray cluster: `latentrl.experiments.sweep`); each finished
    chunk is stored and saved here as it arrives. One writer at a time (`run_lock`)."""
    preset.validate()
    with run_lock(out_dir):
        return _run_rl(preset, Path(out_dir), setup, figures, progress, chunk, execute)


def _run_rl(preset: Preset, out: Path, setup: Callable[[Any, Path], Setup],
            figures: Callable[[Any, Mapping[str, np.ndarray], Path, Path], None], progress: bool,
            chunk: int | None, execute: Execute) -> dict[str, Any]:
    from latentrl.progress import progress_bar  # tqdm: loaded by a run, not by `run NAME --help`

    folder = RunFolder(out)
    meta_path, arrays_path = folder.results_path, folder.arrays_path
    plan = describe(preset)
    arrays, meta = folder.previous(preset)
    started = time.perf_counter()
    built = setup(preset, out)
    if meta is not None:
        folder.check_continued(meta, built.learners, built.info, arrays)
    arrays[PRESET_KEY] = np.array(json.dumps(as_saved(plan), sort_keys=True))
    chunk = chunk or worker_threads()
    fresh = meta is None
    try:
        if built.model is not None and (meta is None or not folder.model_path.exists()):
            out.mkdir(parents=True, exist_ok=True)
            built.model.save(folder.model_path)
        if meta is None:
            meta = {"preset": plan, "environment": environment(), "setup": built.info, "wall_time_s": 0.0}
        for name in built.learners:
            for key in PER_EPISODE:
                arrays.setdefault(array_key(name, key), not_run(key, preset.trials, preset.episodes))
        todo = [
            (name, t)
            for name in built.learners
            for t in range(preset.trials)
            if arrays[array_key(name, "ends")][t, 0] < 0
        ]
        bar = progress_bar(total=len(todo) * episodes_per_trial(preset), unit="ep", disable=not progress, desc="episodes")
        meta.setdefault("trials", {})
        try:
            for name, first, n, result in execute(built, _chunks(todo, chunk), bar.update):
                for i, t in enumerate(range(first, first + n)):
                    for key in PER_EPISODE:
                        arrays[array_key(name, key)][t] = result[key][i]
                    for key in PER_TRIAL:
                        value = result.get(key)
                        if value is not None and value[i].size:
                            arrays.setdefault(array_key(name, key), not_run_like(value, preset.trials))[t] = value[i]
                    meta["trials"].setdefault(name, {})[str(t)] = summarise_trial(arrays, name, t)
                meta["wall_time_s"] += time.perf_counter() - started
                meta["peak_rss_mib"] = max(meta.get("peak_rss_mib", 0.0), peak_rss_mib())
                started = time.perf_counter()
                _save(meta_path, arrays_path, meta, arrays)
        finally:
            bar.close()
    except BaseException:  # a full disk, a refused start, Ctrl-C: a new run that saved no trial leaves nothing
        if fresh and not meta_path.exists():
            folder.model_path.unlink(missing_ok=True)
            arrays_path.unlink(missing_ok=True)
        raise
    try:
        figures(preset, arrays, out, out)
    except OSError as err:  # e.g. a full disk: the trials are saved, only figures are missing
        raise type(err)(err.errno, f"{err.strerror or err}; the run's results are saved in {out}: `latentrl plot "
                                   f"{out}` draws its figures again") from err
    return meta


def _chunks(todo: list[tuple[str, int]], size: int) -> list[tuple[str, int, int]]:
    """Consecutive runs of the same learner, at most `size` trials each: (name, first, count)."""
    out: list[tuple[str, int, int]] = []
    for name, t in todo:
        if out and out[-1][0] == name and out[-1][1] + out[-1][2] == t and out[-1][2] < size:
            out[-1] = (name, out[-1][1], out[-1][2] + 1)
        else:
            out.append((name, t, 1))
    return out


def _save(meta_path: Path, arrays_path: Path, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    # Arrays first: a crash between the two leaves metadata that under-reports, never over-reports.
    write_npz(arrays_path, arrays)
    write_json(meta_path, meta)
