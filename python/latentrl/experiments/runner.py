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
from typing import Any, Protocol

import numpy as np

from latentrl._base import read_npz
from latentrl.run_lock import run_lock
from latentrl.task import changed_since, end_reasons, ran_with
from latentrl.experiments.presets import describe
from latentrl.experiments.results import (
    as_saved,
    environment,
    peak_rss_mib,
    read_results,
    remove_stale_temporaries,
    worker_threads,
    write_json,
    write_npz,
)

END_CODES = dict(enumerate(end_reasons()))
"""How an episode ended, as stored in `<learner>_end` (−1: not run): the native names."""

PER_EPISODE = {
    "returns": "",
    "ends": "_end",
    "steps": "_steps",
    "reached": "_reached",
    "passed": "_passed",
}
"""Per-episode arrays of the native call, each (trials, episodes), and the suffix of their
key in returns.npz after the learner's name (docs/method.md §Results layout: `latent`, `latent_end`,
…)."""

PER_TRIAL = {
    "test_returns": "_test",
    "test_ends": "_test_end",
    "test_steps": "_test_steps",
    "test_reached": "_test_reached",
    "test_passed": "_test_passed",
    "trajectories": "_paths",
    "test_trajectories": "_test_paths",
    "test_start_hands": "_test_start_hands",
    "mean_states": "_mean_state",
    "weights": "_weights",
}
"""Further per-trial arrays of the native call (frozen test episodes (trials, K), recorded
paths, the effectors' (x, y, z) at the start of every test episode (trials, K, 3E), the
learner's mean state over every training episode (trials, episodes, d), final weights) and
their suffix in returns.npz; stored when the call returns them with a non-empty per-trial
part."""


def array_key(learner: str, what: str) -> str:
    """Key in returns.npz of a learner's array `what` (see PER_EPISODE and PER_TRIAL)."""
    return learner + {**PER_EPISODE, **PER_TRIAL}[what]

#: A learner: runs trials `first .. first + n` and returns the native call's dict.
RunTrials = Callable[..., dict[str, Any]]


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
    """The fitted model the learners work in (a GPLVM), saved beside the results as `MODEL_FILE`."""


MODEL_FILE = "gplvm.npz"
"""A run's GPLVM in its results directory (`GPLVM.save`): what its figures, replays and resumes
decode with, since a refit on another CPU or BLAS can give another latent space."""


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

    meta_path, arrays_path = out / "results.json", out / "returns.npz"
    plan = describe(preset)
    arrays, meta = _previous(meta_path, arrays_path, plan)
    started = time.perf_counter()
    built = setup(preset, out)
    if meta is not None:
        _check_continued(meta, built, arrays, out)
    arrays[PRESET_KEY] = np.array(json.dumps(as_saved(plan), sort_keys=True))
    chunk = chunk or worker_threads()
    if built.model is not None and (meta is None or not (out / MODEL_FILE).exists()):
        out.mkdir(parents=True, exist_ok=True)
        built.model.save(out / MODEL_FILE)
    if meta is None:
        meta = {"preset": plan, "environment": environment(), "setup": built.info, "wall_time_s": 0.0}
    for name in built.learners:
        for key in PER_EPISODE:
            arrays.setdefault(array_key(name, key), _empty(key, preset.trials, preset.episodes))
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
                        arrays.setdefault(array_key(name, key), _unset(value, preset.trials))[t] = value[i]
                meta["trials"].setdefault(name, {})[str(t)] = summarise_trial(arrays, name, t)
            meta["wall_time_s"] += time.perf_counter() - started
            meta["peak_rss_mib"] = max(meta.get("peak_rss_mib", 0.0), peak_rss_mib())
            started = time.perf_counter()
            _save(meta_path, arrays_path, meta, arrays)
    finally:
        bar.close()
    figures(preset, arrays, out, out)
    return meta


def summarise_trial(arrays: Mapping[str, np.ndarray], name: str, trial: int) -> dict[str, Any]:
    """Per-trial figures for results.json: early/late mean return, end counts, reach and pass
    rates; with frozen test episodes also `test_success` (share that reached the target),
    `test_passed`, their mean return and end counts."""
    returns = arrays[array_key(name, "returns")][trial]
    ends = arrays[array_key(name, "ends")][trial]
    reached = arrays[array_key(name, "reached")][trial]
    passed = arrays[array_key(name, "passed")][trial]
    window = max(1, len(returns) // 10)
    summary: dict[str, Any] = {
        "mean_return_first": float(returns[:window].mean()),
        "mean_return_last": float(returns[-window:].mean()),
        "reached_last": float(reached[-window:].mean()),
        "passed_last": float(passed[-window:].mean()),
        "window": window,
        "ends": end_counts(ends),
    }
    if array_key(name, "test_ends") in arrays:
        test_ends = arrays[array_key(name, "test_ends")][trial]
        summary.update(
            test_success=float(arrays[array_key(name, "test_reached")][trial].mean()),
            test_passed=float(arrays[array_key(name, "test_passed")][trial].mean()),
            test_mean_return=float(arrays[array_key(name, "test_returns")][trial].mean()),
            test_ends=end_counts(test_ends),
        )
    return summary


def end_counts(ends: np.ndarray) -> dict[str, int]:
    """How many of `ends` (end codes) ended each way, by name, every ending listed."""
    return {label: int((ends == code).sum()) for code, label in END_CODES.items()}


def _empty(key: str, trials: int, episodes: int) -> np.ndarray:
    if key == "returns":
        return np.full((trials, episodes), np.nan)
    if key == "ends":
        return np.full((trials, episodes), -1, dtype=np.int8)
    if key == "reached":
        return np.zeros((trials, episodes), dtype=bool)
    return np.zeros((trials, episodes), dtype=np.int64)


def _unset(value: np.ndarray, trials: int) -> np.ndarray:
    """A (trials, …) array for per-trial rows like `value[i]`, every entry 'not run':
    NaN (floats), −1 (ints), False (bools)."""
    shape = (trials, *value.shape[1:])
    if value.dtype == bool:
        return np.zeros(shape, dtype=bool)
    if np.issubdtype(value.dtype, np.integer):
        return np.full(shape, -1, dtype=value.dtype)
    return np.full(shape, np.nan, dtype=value.dtype)


def _chunks(todo: list[tuple[str, int]], size: int) -> list[tuple[str, int, int]]:
    """Consecutive runs of the same learner, at most `size` trials each: (name, first, count)."""
    out: list[tuple[str, int, int]] = []
    for name, t in todo:
        if out and out[-1][0] == name and out[-1][1] + out[-1][2] == t and out[-1][2] < size:
            out[-1] = (name, out[-1][1], out[-1][2] + 1)
        else:
            out.append((name, t, 1))
    return out


def _previous(
    meta_path: Path, arrays_path: Path, plan: dict[str, Any]
) -> tuple[dict[str, np.ndarray], dict[str, Any] | None]:
    """Arrays and metadata of an earlier run of the same preset in this directory, if any."""
    for path in (meta_path, arrays_path):
        remove_stale_temporaries(path)
    if not meta_path.exists():
        return {}, None
    meta = read_results(meta_path)
    recorded = meta.get("setup", {}).get("task")
    ran = ran_with(recorded) if recorded is not None else {}
    if _edited(meta.get("preset") or {}, as_saved(plan), ran):
        raise ValueError(
            f"{meta_path.parent} holds a run of a different preset; choose another --out "
            "or delete it (only a run of the same preset is continued)"
        )
    if not arrays_path.exists():
        return {}, None
    arrays = load_arrays(arrays_path.parent)
    _check_saved_run(meta_path.parent, plan, arrays, ran)
    return arrays, meta


PRESET_KEY = "preset_json"
"""Key in returns.npz of the preset the arrays were computed with (JSON): `--resume` refuses a
results.json whose preset was edited since."""


def _edited(saved: Mapping[str, Any], now: Mapping[str, Any], ran: Mapping[str, Any]) -> list[str]:
    """The preset fields that differ between `saved` and `now`. A task override that only
    restores what the trials ran with (`ran`: `task.ran_with` of the recorded task, empty if none
    was recorded) is not an edit: `cli.saved_run` adds those when a shipped task changed since."""
    edited = [k for k in set(saved) | set(now) if k != "task" and saved.get(k) != now.get(k)]
    before, after = saved.get("task") or {}, now.get("task") or {}
    restored = {k for k in set(after) - set(before) if k in ran and ran[k] == after[k]}
    if {k for k in set(before) | set(after) if before.get(k) != after.get(k)} - restored:
        edited.append("task")
    return sorted(edited)


def _check_saved_run(out: Path, plan: dict[str, Any], arrays: Mapping[str, np.ndarray], ran: Mapping[str, Any]) -> None:
    """The arrays of a run being continued were computed with `plan`; a ValueError naming the
    edited fields otherwise (mixing would be silently wrong)."""
    if PRESET_KEY in arrays:
        saved, now = json.loads(str(arrays[PRESET_KEY])), as_saved(plan)
        edited = _edited(saved, now, ran)
        if edited:
            changes = ", ".join(f"{k}: {saved.get(k)!r} in returns.npz, {now.get(k)!r} in results.json" for k in edited)
            raise ValueError(f"{out}/results.json was edited after its trials ran ({changes}); resume refuses to mix "
                             "the two: restore the file, or start a new run with --out")


def _check_continued(meta: Mapping[str, Any], built: Setup, arrays: Mapping[str, np.ndarray], out: Path) -> None:
    """A continued run's trials ran with the task the setup builds and its per-episode arrays
    have the preset's shapes (its model fit is checked where the setup reads it back:
    `latent_runs.run_fit`) and with the inputs it recorded (`check_inputs`: first, since a
    changed input can change settings derived from it)."""
    check_inputs(meta.get("setup", {}).get("inputs") or {}, built.info.get("inputs") or {}, out)
    recorded = meta.get("setup", {}).get("task")
    keys = sorted(changed_since(recorded, as_saved(built.info.get("task")) or {})) if recorded is not None else []
    if keys:
        raise ValueError(f"{out}: its trials ran with another task ({', '.join(keys)} differ); resume refuses to "
                         "mix the two: start a new run with --out")
    want = (meta["preset"]["trials"], meta["preset"]["episodes"])
    for name in built.learners:
        for what in PER_EPISODE:
            key = array_key(name, what)
            if key not in arrays:
                raise ValueError(f"{out}/returns.npz: {key} is missing; restore the file, or start a new run with --out")
            if arrays[key].shape != want:
                raise ValueError(f"{out}/returns.npz: {key} has shape {arrays[key].shape}, the preset asks for "
                                 f"{want} (trials, episodes); it belongs to another run")


def check_inputs(recorded: Mapping[str, str], now: Mapping[str, str], out: Path) -> None:
    """ValueError naming the first input (task file, URDF, demos, model) whose SHA-256 the run
    recorded and that now differs: a run is continued, replayed, rolled out or plotted only with
    what it was made from."""
    for name, digest in recorded.items():
        if name in now and now[name] != digest:
            raise ValueError(f"{out}: its {name} changed since the run (sha256 {digest[:12]}… ≠ {now[name][:12]}…); "
                             "the run is refused rather than mixed with it: restore it, or start a new run with --out")


def load_arrays(out_dir: Path | str) -> dict[str, np.ndarray]:
    """Every array of a results directory's returns.npz: a ValueError naming the file if it is not
    readable or an array (but the preset's JSON) holds anything but numbers."""
    path = Path(out_dir) / "returns.npz"
    try:
        arrays = read_npz(path)
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None
    for key, value in arrays.items():
        if key != PRESET_KEY and value.dtype.kind not in "biuf":
            raise ValueError(f"{path}: {key} holds {value.dtype} values, expected numbers")
    return arrays


def finished_trials(arrays: Mapping[str, np.ndarray]) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """The rows of finished trials only, learner by learner (a partial run's unrun trials are
    NaN or −1), and how many each learner has. Learners with none are left out."""
    learners = [key for key in arrays if array_key(key, "ends") in arrays]
    done = {name: arrays[array_key(name, "ends")][:, 0] >= 0 for name in learners}
    kept: dict[str, np.ndarray] = {}
    for key, value in arrays.items():
        owner = max((n for n in learners if key == n or key.startswith(n + "_")), key=len, default=None)
        if owner is not None and done[owner].any():
            kept[key] = value[done[owner]]
    return kept, {name: int(mask.sum()) for name, mask in done.items() if mask.any()}


def _save(meta_path: Path, arrays_path: Path, meta: dict[str, Any], arrays: dict[str, np.ndarray]) -> None:
    # Arrays first: a crash between the two leaves metadata that under-reports, never over-reports.
    write_npz(arrays_path, arrays)
    write_json(meta_path, meta)
