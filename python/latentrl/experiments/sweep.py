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
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from dataclasses import dataclass
from typing import Any, ClassVar, Protocol

from latentrl.progress import progress_bar
from latentrl.run_lock import run_lock

from latentrl.experiments.presets import describe
from latentrl.experiments.ray_backend import RayBackend
from latentrl.experiments.registry import RlExperiment, rl_experiments
from latentrl.experiments.results import environment, read_json, read_results, worker_threads, write_json
from latentrl.experiments.runner import Setup, load_arrays, run_in_process, run_rl
from latentrl.experiments.sweep_types import Cell, Job, Sweep, SweepError, load_sweep

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
                run_rl(job.cell.preset, job.out, setup=kind.setup, figures=kind.figures, progress=False,
                       execute=execute)
            except Exception as err:  # noqa: BLE001 - reported per cell; Ctrl-C passes through
                failures[job.cell.id] = err
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
    jobs = [
        Job(sweep.experiment, cell, out / cell.id)
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
        entries[job.cell.id]["figures"] = True
        save_state([job.cell])

    save_state()
    started = time.perf_counter()
    bar = progress_bar(total=sum(wanted.values()), initial=sum(done.values()), unit="trial",
               desc=f"sweep {sweep.experiment} ({runner.name})", disable=not progress)
    try:
        failures.update(runner.run(jobs, bar.update, finished))
    finally:
        bar.close()
        run_info["wall_time_s"] = time.perf_counter() - started
        save_state([job.cell for job in jobs])
    from latentrl.experiments.sweep_summary import write_summary  # matplotlib: the [plot] extra

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
    meta_path = out / "results.json"
    if not (meta_path.exists() and (out / "returns.npz").exists()):
        return 0
    try:
        if read_results(meta_path).get("preset") != json.loads(json.dumps(describe(cell.preset))):
            return 0
        arrays = load_arrays(out)
    except ValueError:
        return 0
    ends = [arrays.get(f"{learner}_end") for learner in kind.learners]
    return sum(int((e[:, 0] >= 0).sum()) for e in ends if e is not None)
