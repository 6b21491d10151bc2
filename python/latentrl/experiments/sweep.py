"""Sweeps: one RL experiment over a grid or a list of preset overrides, every cell a full preset
run into its own results directory, on this machine or on a Ray cluster.

    sweep = Sweep("exp1", quick=True, trials=4, grid={"learner.beta": [5.0, 10.0]})   # or load_sweep(FILE)
    run_sweep(sweep, "results/beta", backend="local")       # or "ray", ray_backend.RayBackend(…)

Layout of the sweep directory:

    sweep.json           the description, its cells (id, overrides, trials done, status), the runs
    <cell>/              the runner's layout for that cell's preset: results.json, returns.npz and
                         the experiment's figures (`latentrl plot DIR/<cell>` works)
    summary.{md,json}    per cell and learner: final return mean ± s.d., episodes to the threshold
    sweep.{png,pdf}      learning curves and final returns of every cell

Backends: `local` runs the cells one after the other in this process, rayon running each
chunk of trials in parallel (as `latentrl run`); `ray` (`ray_backend.py`) runs one Ray task
per trial, or per `batch` trials, of every cell. Either way the runner stores each chunk in
its cell's results as it arrives (`run_rl(execute=…)`), atomically; a trial's RNG depends on
the cell's base seed and the trial index alone, so both backends write the same bits, and
`resume` skips the finished trials whichever backend ran them.

The module has three parts: the description (`Sweep`, `Cell`, `load_sweep`: every value checked
on construction), running it (`run_sweep`, the local backend) and the summary (`write_summary`,
its figure drawn with matplotlib, the `[plot]` extra, imported when it is drawn).
"""

from __future__ import annotations

import dataclasses
import difflib
import importlib
import itertools
import json
import math
import re
import time
import tomllib
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Protocol

import numpy as np
from numpy.typing import NDArray

from latentrl._files import MAX_SWEEP_FILE_BYTES, read_text
from latentrl.experiments import RlExperiment, rl_experiments, task_schema
from latentrl.experiments.presets import check_type, describe
from latentrl.run_settings import with_overrides
from latentrl.experiments.ray_backend import RayBackend
from latentrl.results import environment, read_json, write_json
from latentrl.experiments.run_folder import RunFolder
from latentrl.machine import worker_threads
from latentrl.experiments.runner import Job, Setup, run_in_process, run_rl
from latentrl.progress import progress_bar
from latentrl.run_lock import run_lock
from latentrl.task import by_path, check_run, key_paths, run_settings

__all__ = ["Cell", "Sweep", "SweepError", "load_sweep", "run_sweep"]


# --- the description of a sweep ----------------------------------------------------------------


SWEEP_KEYS = ("experiment", "quick", "trials", "seed", "threshold", "base", "grid", "cells")
"""The keys of a sweep file, as the fields of `Sweep`."""


class SweepError(RuntimeError):
    """Some cells of a sweep failed; the others and every finished trial are saved."""


MAX_CELLS = 10_000
"""The most cells of one sweep: counted before the grid is expanded."""

@dataclass(frozen=True)
class Cell:
    """One point of a sweep: a full preset and where its results go."""

    id: str
    """Directory name: index and the overridden values that vary across the sweep."""
    overrides: dict[str, Any]
    """The grid point and/or explicit overrides of this cell (on top of `Sweep.base`)."""
    preset: Any
    """The experiment's preset for this cell."""


@dataclass(frozen=True)
class Sweep:
    """A sweep of one RL experiment: a grid (cartesian product) and/or a list of explicit
    overrides, on top of base overrides, with the trials per cell and the base seed. Every
    value is checked against the preset's fields on construction (ValueError naming it)."""

    experiment: str
    """`exp1` or `exp2`."""
    grid: Mapping[str, Sequence[Any]] = field(default_factory=dict)
    """Preset field → values; the cells are their cartesian product (the last field fastest)."""
    cells: Sequence[Mapping[str, Any]] = ()
    """Explicit overrides, one mapping per cell; with a grid, each is crossed with every point."""
    base: Mapping[str, Any] = field(default_factory=dict)
    """Overrides every cell starts from (the grid and the cells override these)."""
    quick: bool = False
    """Start from the experiment's quick preset instead of the paper's."""
    trials: int | None = None
    """Trials per cell (None: the preset's)."""
    seed: int | None = None
    """Base seed of every cell; trial i of a cell draws from (seed, i) (None: the preset's).
    To repeat the sweep over seeds, put `seed` in the grid."""
    threshold: float | None = None
    """Return that counts as learnt, for 'episodes to threshold' (running mean over the last
    10 % of a cell's episodes); None: half the best final return of the whole sweep."""

    def __post_init__(self) -> None:
        if not isinstance(self.experiment, str) or self.experiment not in rl_experiments():
            known = ", ".join(rl_experiments())
            raise ValueError(f"experiment: unknown experiment {self.experiment!r}; sweeps run {known}")
        check_type("quick", self.quick, bool)
        check_run({name: getattr(self, name) for name in ("trials", "seed") if getattr(self, name) is not None})
        if self.threshold is not None:
            threshold = check_type("threshold", self.threshold, float)
            if not math.isfinite(threshold):
                raise ValueError(f"threshold: must be finite, got {self.threshold!r}")
            object.__setattr__(self, "threshold", threshold)
        kinds = _field_kinds(rl_experiments()[self.experiment].preset)
        kinds.update(_task_kinds(self.experiment))
        base = _check_overrides("base", key_paths(self.base), kinds)
        for name in ("trials", "seed"):
            for key in (name, f"run.{name}"):
                if getattr(self, name) is not None and key in base:
                    raise ValueError(f"base.{key}: {name} is already set at the top level of the sweep")
        if not isinstance(self.grid, Mapping):
            raise ValueError(f"grid: expected a table of field = [values], got {self.grid!r}")
        grid: dict[str, list[Any]] = {}
        for name, values in key_paths(self.grid).items():
            _check_name(f"grid.{name}", name, kinds)
            if isinstance(values, (str, bytes)) or not isinstance(values, Sequence):
                raise ValueError(f"grid.{name}: expected a list of values, got {values!r}")
            if not values:
                raise ValueError(f"grid.{name}: empty list (give at least one value or leave the field out)")
            checked = [_check_field(f"grid.{name}[{i}]", name, v, kinds) for i, v in enumerate(values)]
            for i, value in enumerate(checked):
                if value in checked[:i]:
                    raise ValueError(f"grid.{name}: {value!r} appears twice")
            grid[name] = checked
        if isinstance(self.cells, (str, bytes, Mapping)) or not isinstance(self.cells, Sequence):
            raise ValueError(f"cells: expected a list of tables of overrides, got {self.cells!r}")
        cells = [_check_overrides(f"cells[{i}]", key_paths(c), kinds) for i, c in enumerate(self.cells)]
        for i, cell in enumerate(cells):
            both = sorted(set(cell) & set(grid))
            if both:
                raise ValueError(f"cells[{i}]: {', '.join(both)} also in the grid (set each field in one place)")
        count = math.prod(len(v) for v in grid.values()) * max(1, len(cells))
        if count > MAX_CELLS:
            sizes = " × ".join([*(str(len(v)) for v in grid.values()), *([str(len(cells))] if cells else [])])
            raise ValueError(f"grid: {sizes} = {count} cells, more than the {MAX_CELLS} a sweep may have "
                             "(each is a full run); split it into several sweeps")
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "grid", grid)
        object.__setattr__(self, "cells", cells)
        self.expand()  # every cell's preset validates and no two are the same

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], source: str = "") -> Sweep:
        """A sweep from parsed TOML/YAML (keys as the fields); errors are prefixed by `source`."""
        prefix = f"{source}: " if source else ""
        try:
            if not isinstance(data, Mapping):
                raise ValueError(f"expected a table at the top level, got {type(data).__name__}")
            unknown = sorted(set(data) - set(SWEEP_KEYS))
            if unknown:
                raise ValueError(f"unknown key {unknown[0]!r} (a sweep has {', '.join(SWEEP_KEYS)})")
            if "experiment" not in data:
                raise ValueError("no experiment = \"exp1\" or \"exp2\"")
            return cls(**data)
        except ValueError as err:
            raise ValueError(f"{prefix}{err}") from None

    def expand(self) -> list[Cell]:
        """The cells, in order: each explicit cell (or the base alone) crossed with the grid."""
        kind = rl_experiments()[self.experiment]
        start = kind.preset.quick() if self.quick else kind.preset()  # type: ignore[attr-defined]
        top = {name: getattr(self, name) for name in ("trials", "seed") if getattr(self, name) is not None}
        start = with_overrides(start, {**self.base, **top})
        points = [dict(zip(self.grid, values)) for values in itertools.product(*self.grid.values())]
        overrides = [{**cell, **point} for cell in (self.cells or [{}]) for point in points]
        varying = list(dict.fromkeys([*self.grid, *(k for c in self.cells for k in c)]))  # in the ids
        width = max(2, len(str(len(overrides) - 1)))
        cells: list[Cell] = []
        seen: dict[str, str] = {}
        for index, values in enumerate(overrides):
            label = "".join(f"_{k}={_format(values[k])}" for k in varying if k in values)
            cell_id = (f"{index:0{width}d}" + re.sub(r"[^A-Za-z0-9._=+-]", "-", label))[:100]
            try:
                preset = with_overrides(start, values)
                preset.validate()
            except ValueError as err:
                raise ValueError(f"cell {cell_id}: {err}") from None
            key = json.dumps(describe(preset), sort_keys=True, default=str)
            if key in seen:
                raise ValueError(f"cells {seen[key]} and {cell_id} are the same preset")
            seen[key] = cell_id
            cells.append(Cell(cell_id, values, preset))
        return cells

    def describe(self) -> dict[str, Any]:
        """The description as plain JSON values (what sweep.json keeps and `resume` compares)."""
        return json.loads(json.dumps(dataclasses.asdict(self)))  # type: ignore[no-any-return]


def load_sweep(path: Path | str) -> Sweep:
    """A sweep from a TOML file (or YAML, `.yaml`/`.yml`, if PyYAML is installed); a file that
    is not one, or holds a bad value, is a ValueError naming the file and the value."""
    path = Path(path)
    try:
        text = read_text(path, MAX_SWEEP_FILE_BYTES, "a sweep file")
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None
    if path.suffix.lower() in (".yaml", ".yml"):
        try:
            yaml: Any = importlib.import_module("yaml")
        except ModuleNotFoundError:
            raise ValueError(f"{path}: YAML sweep files need PyYAML (pip install pyyaml), or use TOML") from None
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as err:
            raise ValueError(f"{path}: not valid YAML ({err})") from None
    else:
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as err:
            raise ValueError(f"{path}: not valid TOML ({err})") from None
    return Sweep.from_mapping(data, source=str(path))


def _field_kinds(preset_cls: type) -> dict[str, type]:
    """Scalar preset fields (the ones a sweep may set) → their type, from the defaults; a run
    setting also by its path (`run.trials`)."""
    fields = dataclasses.fields(preset_cls)
    kinds = {f.name: type(f.default) for f in fields if type(f.default) in (bool, int, float, str)}
    return {**kinds, **{f"run.{name}": kind for name, kind in kinds.items() if name in run_settings()}}


def _task_kinds(experiment: str) -> dict[str, type]:
    """Scalar task keys of `experiment` (by path) → the type a sweep value must have; choices
    and optional values are strings or numbers checked by the task itself (`object`)."""
    types = {"float": float, "int": int, "bool": bool, "str": str}
    return {e["key"]: types.get(e["kind"], object) for e in task_schema(experiment) if by_path(e)}


def _check_name(where: str, name: str, kinds: Mapping[str, type]) -> None:
    if name not in kinds:
        close = difflib.get_close_matches(name, kinds, n=1)
        fields = [k for k in kinds if "." not in k]
        hint = f"; did you mean {close[0]!r}?" if close else f" (fields: {', '.join(fields)}; task keys by path, e.g. learner.beta)"
        raise ValueError(f"{where}: {name!r} is not a field of the preset or a task key{hint}")


def _check_field(where: str, name: str, value: Any, kinds: Mapping[str, type]) -> Any:
    _check_name(where, name, kinds)
    return value if kinds[name] is object else check_type(where, value, kinds[name])


def _check_overrides(where: str, overrides: Any, kinds: Mapping[str, type]) -> dict[str, Any]:
    if not isinstance(overrides, Mapping):
        raise ValueError(f"{where}: expected a table of field = value, got {overrides!r}")
    return {name: _check_field(f"{where}.{name}", name, v, kinds) for name, v in overrides.items()}


def _format(value: Any) -> str:
    return repr(value) if isinstance(value, float) else str(value)


__all__ = ["Cell", "Sweep", "SweepError", "load_sweep", "run_sweep"]


# --- running a sweep ---------------------------------------------------------------------------


class Backend(Protocol):
    """Runs the jobs' trials and stores them with the runner; returns the failed cells."""

    @property
    def name(self) -> str:
        """The backend's name ("local", "ray")."""

    def describe(self) -> dict[str, Any]:
        """The backend and its settings, for sweep.json's record of each run."""

    def run(
        self, jobs: list[Job], advance: Callable[[int], object], finished: Callable[[Job], None]
    ) -> dict[str, BaseException]:
        """Runs every job; `advance(n)` after n trials are saved, `finished(job)` after a cell
        is complete (figures drawn). Returns cell id → error for the cells that failed."""


@dataclass
class LocalBackend:
    """The cells one after the other in this process; each cell's trials in chunks of one
    per rayon thread, run in parallel in Rust (as `latentrl run`)."""

    name: ClassVar[str] = "local"

    def describe(self) -> dict[str, Any]:
        """See `Backend.describe`."""
        return {"backend": self.name, "rayon_threads": worker_threads()}

    def run(
        self, jobs: list[Job], advance: Callable[[int], object], finished: Callable[[Job], None]
    ) -> dict[str, BaseException]:
        """See `Backend.run`."""
        failures: dict[str, BaseException] = {}
        for job in jobs:
            kind = rl_experiments()[job.experiment]

            def execute(
                built: Setup, chunks: list[tuple[str, int, int]], episodes: Callable[[int], object]
            ) -> Iterator[tuple[str, int, int, dict[str, Any]]]:
                for chunk in run_in_process(built, chunks, episodes):
                    yield chunk
                    advance(chunk[2])  # after the runner saved it

            try:
                run_rl(job.preset, job.out, setup=kind.setup, figures=kind.figures, progress=False,
                       execute=execute)
            except Exception as err:  # noqa: BLE001 - reported per cell; Ctrl-C passes through
                failures[job.id] = err
                continue
            finished(job)
        return failures


def run_sweep(
    sweep: Sweep,
    out_dir: Path | str,
    *,
    backend: str | Backend = "local",
    resume: bool = False,
    progress: bool = True,
) -> dict[str, Any]:
    """Runs `sweep` into `out_dir` on `backend` ("local", "ray" or a backend object) and writes
    the summary; returns what sweep.json holds, with the summary under "summary". A directory
    that holds a sweep is refused unless `resume`, which continues the same sweep (finished
    trials are kept, whichever backend ran them; a cell counts as done once its figures are
    drawn). Failed cells raise a SweepError after the others finished; Ctrl-C (a
    KeyboardInterrupt) keeps finished trials. One writer at a time (`run_lock`)."""
    runner = _backend(backend)
    with run_lock(out_dir):
        return _run_sweep(sweep, Path(out_dir), runner, resume, progress)


def _run_sweep(sweep: Sweep, out: Path, runner: Backend, resume: bool, progress: bool) -> dict[str, Any]:
    cells = sweep.expand()
    state = _open(out, sweep, cells, resume)
    kind = rl_experiments()[sweep.experiment]
    done = {cell.id: _trials_done(kind, cell, out / cell.id) for cell in cells}
    wanted = {cell.id: cell.preset.trials * len(kind.learners) for cell in cells}
    run_info = {**runner.describe(), "started": time.strftime("%Y-%m-%dT%H:%M:%S%z")}
    state["runs"].append(run_info)
    entries = {entry["id"]: entry for entry in state["cells"]}
    by_id = {cell.id: cell for cell in cells}
    jobs = [
        Job(sweep.experiment, cell.id, cell.preset, out / cell.id)
        for cell in cells
        if done[cell.id] < wanted[cell.id] or not entries[cell.id]["figures"]
    ]
    failures: dict[str, BaseException] = {}

    def save_state(changed: Sequence[Cell] = ()) -> None:
        for cell in changed:
            done[cell.id] = _trials_done(kind, cell, out / cell.id)
        for entry, cell in zip(state["cells"], cells):
            entry["trials_done"], entry["trials_of"] = done[cell.id], wanted[cell.id]
            entry["status"] = (
                "failed" if cell.id in failures
                else "done" if done[cell.id] == wanted[cell.id] and entry["figures"]
                else "partial" if done[cell.id] else "pending"
            )
            entry["error"] = str(failures[cell.id]) if cell.id in failures else None
        write_json(out / "sweep.json", state)

    def finished(job: Job) -> None:
        entries[job.id]["figures"] = True
        save_state([by_id[job.id]])

    save_state()
    started = time.perf_counter()
    bar = progress_bar(total=sum(wanted.values()), initial=sum(done.values()), unit="trial",
               desc=f"sweep {sweep.experiment} ({runner.name})", disable=not progress)
    try:
        failures.update(runner.run(jobs, bar.update, finished))
    finally:
        bar.close()
        run_info["wall_time_s"] = time.perf_counter() - started
        save_state([by_id[job.id] for job in jobs])
    state["summary"] = write_summary(sweep, cells, out)
    if failures:
        listed = "; ".join(f"{cell_id}: {err}" for cell_id, err in failures.items())
        raise SweepError(
            f"{len(failures)} of {len(cells)} cells failed ({listed}); finished trials are kept "
            f"in {out}, resume runs the rest"
        )
    return state


def _backend(backend: str | Backend) -> Backend:
    if backend == "local":
        return LocalBackend()
    if backend == "ray":
        return RayBackend()
    if isinstance(backend, str):
        raise ValueError(f"unknown backend {backend!r}; choose local or ray")
    return backend


def _open(out: Path, sweep: Sweep, cells: list[Cell], resume: bool) -> dict[str, Any]:
    """sweep.json's content: a fresh one, or the saved one of the same sweep when resuming."""
    path = out / "sweep.json"
    state: dict[str, Any] = {
        "sweep": sweep.describe(),
        "cells": [
            {"id": c.id, "overrides": c.overrides, "preset": describe(c.preset), "figures": False} for c in cells
        ],
        "environment": environment(),
        "runs": [],
    }
    if path.exists():
        saved = read_json(path)
        if not resume:
            raise ValueError(f"{out} already holds a sweep; resume it (--resume) or choose another --out")
        if saved.get("sweep") != state["sweep"]:
            raise ValueError(f"{out} holds a different sweep; only the same description is resumed")
        state["runs"] = list(saved.get("runs") or [])
        drawn = {entry.get("id"): bool(entry.get("figures")) for entry in saved.get("cells") or []}
        for entry in state["cells"]:
            entry["figures"] = drawn.get(entry["id"], False)
    return state


def _trials_done(kind: RlExperiment, cell: Cell, out: Path) -> int:
    """Finished trials (over all learners) in a cell's directory, if it holds its preset."""
    folder = RunFolder(out)
    if not (folder.results_path.exists() and folder.arrays_path.exists()):
        return 0
    try:
        if folder.preset() != json.loads(json.dumps(describe(cell.preset))):
            return 0
        arrays = folder.arrays()
    except ValueError:
        return 0
    ends = [arrays.get(f"{learner}_end") for learner in kind.learners]
    return sum(int((e[:, 0] >= 0).sum()) for e in ends if e is not None)


# --- the summary ------------------------------------------------------------------------------


FINAL_SHARE = 0.1
"""Share of a trial's last episodes whose mean return is its 'final return' (as results.json's
`mean_return_last`); also the running-mean window of 'episodes to threshold'."""


def final_window(episodes: int) -> int:
    """Episodes averaged for the final return and the threshold test."""
    return max(1, int(episodes * FINAL_SHARE))


def episodes_to_threshold(returns: NDArray[np.float64], threshold: float, window: int) -> NDArray[np.int64]:
    """Per trial (row of `returns`, (trials, episodes)), the first episode count at which the
    mean return of the last `window` episodes is ≥ `threshold`; −1 where it never is."""
    if returns.shape[1] < window:
        return np.full(len(returns), -1, dtype=np.int64)
    sums = np.cumsum(np.pad(returns, ((0, 0), (1, 0))), axis=1)
    running = (sums[:, window:] - sums[:, :-window]) / window
    hit = running >= threshold
    first = np.where(hit.any(axis=1), hit.argmax(axis=1) + window, -1)
    return first.astype(np.int64)


def write_summary(sweep: Sweep, cells: list[Cell], out: Path) -> dict[str, Any]:
    """Computes the summary of the finished trials in `out`, writes summary.json, summary.md
    and sweep.png/pdf, and returns the summary."""
    learners = rl_experiments()[sweep.experiment].learners
    curves: list[tuple[Cell, str, NDArray[np.float64]]] = []
    for cell in cells:
        try:
            arrays = RunFolder(out / cell.id).arrays()
        except (OSError, ValueError):
            continue
        for learner in learners:
            if learner in arrays and f"{learner}_end" in arrays:
                curves.append((cell, learner, arrays[learner][arrays[f"{learner}_end"][:, 0] >= 0]))
    finals = {(c.id, name): r[:, -final_window(r.shape[1]):].mean(axis=1) for c, name, r in curves if len(r)}
    threshold, source = sweep.threshold, "given"
    if threshold is None:
        best = max((float(f.mean()) for f in finals.values()), default=None)
        threshold, source = (None if best is None else 0.5 * best), "half the best final return"
    rows = []
    for cell, learner, returns in curves:
        row: dict[str, Any] = {"cell": cell.id, "overrides": cell.overrides, "learner": learner,
                               "trials": len(returns), "of": cell.preset.trials}
        if len(returns):
            final = finals[(cell.id, learner)]
            row.update(final_return_mean=float(final.mean()), final_return_sd=float(final.std()))
            if threshold is not None:
                reached = episodes_to_threshold(returns, threshold, final_window(returns.shape[1]))
                reached = reached[reached >= 0]
                row["reached_threshold"] = len(reached)
                if len(reached):
                    row.update(episodes_to_threshold_mean=float(reached.mean()),
                               episodes_to_threshold_sd=float(reached.std()))
        rows.append(row)
    summary = {
        "threshold": threshold,
        "threshold_source": source,
        "final_share": FINAL_SHARE,
        "sd": "over trials, ddof 0 (as the figures)",
        "rows": rows,
    }
    write_json(out / "summary.json", summary)
    (out / "summary.md").write_text(_table(sweep, cells, rows, threshold, source))
    if curves:
        _figure(curves, threshold, out)
    return summary


def _table(sweep: Sweep, cells: list[Cell], rows: list[dict[str, Any]], threshold: float | None,
           source: str) -> str:
    fields = list(dict.fromkeys(k for c in cells for k in c.overrides))
    when = f"≥ {threshold:.4g} ({source})" if threshold is not None else "(no finished trial)"
    head = ["cell", *fields, "learner", "trials", "final return", f"episodes to {when}"]
    lines = [
        f"# Sweep of {sweep.experiment}: {len(cells)} cells",
        "",
        f"Final return: each trial's mean return over its last {FINAL_SHARE:.0%} of episodes, mean ± s.d.",
        "over the finished trials; episodes to the threshold: until that running mean first reached it",
        "(mean ± s.d. over the trials that did, and how many did).",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    overrides = {c.id: c.overrides for c in cells}
    for row in rows:
        values = [str(overrides[row["cell"]].get(k, "")) for k in fields]
        final = "—"
        if "final_return_mean" in row:
            final = f"{row['final_return_mean']:.1f} ± {row['final_return_sd']:.1f}"
        reach = "—"
        if "episodes_to_threshold_mean" in row:
            reach = f"{row['episodes_to_threshold_mean']:.0f} ± {row['episodes_to_threshold_sd']:.0f}"
        if "reached_threshold" in row:
            reach += f" ({row['reached_threshold']}/{row['trials']})"
        lines.append("| " + " | ".join([row["cell"], *values, row["learner"], f"{row['trials']}/{row['of']}",
                                        final, reach]) + " |")
    return "\n".join(lines) + "\n"


def _figure(curves: list[tuple[Cell, str, NDArray[np.float64]]], threshold: float | None, out: Path) -> None:
    """Left: mean learning curve (running mean over the final window) of every cell (colour)
    and learner (line style); right: final return mean ± s.d. per cell, by its number."""
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    from latentrl.plots import running_mean, save_figure

    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    ids = list(dict.fromkeys(cell.id for cell, _, _ in curves))
    learners = list(dict.fromkeys(name for _, name, _ in curves))
    colours = {cell_id: plt.cm.viridis(i / max(len(ids) - 1, 1)) for i, cell_id in enumerate(ids)}
    styles = dict(zip(learners, ("-", "--", ":", "-.")))
    for cell, learner, returns in curves:
        if not len(returns):
            continue
        window = final_window(returns.shape[1])
        mean = running_mean(returns, window).mean(axis=0)
        left.plot(np.arange(1, mean.size + 1), mean, color=colours[cell.id], ls=styles.get(learner, "-"))
        final = returns[:, -window:].mean(axis=1)
        x = ids.index(cell.id) + 0.15 * (learners.index(learner) - (len(learners) - 1) / 2)
        right.errorbar(x, final.mean(), yerr=final.std(), fmt="o", color=colours[cell.id], capsize=3,
                       mfc="white" if learners.index(learner) else None)
    handles = [Line2D([], [], color=colours[cell_id], label=cell_id) for cell_id in ids]
    handles += [Line2D([], [], color="grey", ls=styles[name], label=name) for name in learners]
    if threshold is not None:
        left.axhline(threshold, color="k", lw=0.8, ls=":")
        handles.append(Line2D([], [], color="k", lw=0.8, ls=":", label=f"threshold {threshold:.4g}"))
    left.set_xlabel("episode")
    left.set_ylabel("return (running mean)")
    right.set_xticks(range(len(ids)), [cell_id.split("_")[0] for cell_id in ids])
    right.set_xlabel("cell")
    filled = f" (filled: {learners[0]}, open: {', '.join(learners[1:])})" if len(learners) > 1 else ""
    right.set_ylabel("final return, mean ± s.d." + filled)
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=min(3, len(handles)),
               fontsize=8, frameon=False)
    fig.suptitle("sweep: learning curves and final returns per cell")
    save_figure(fig, out, "sweep")
