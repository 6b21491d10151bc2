"""The `ray` backend of sweeps: every trial (or `batch` trials) of every cell as one Ray task.

A task gets the cell's preset, rebuilds the setup from it (demonstrations, GPLVM fit: once per
worker process and preset), checks that it matches the driver's (a digest of the fit and the
latentrl version), runs the trials in Rust and returns their arrays. The driver keeps one
thread per cell in flight that stores the chunks with the runner (`run_rl(execute=…)`) as they
arrive, so a cell's results are written exactly as a local run writes them. Ray is imported
only here, and only when the backend runs (the `ray` extra: `pip install 'latentrl[ray]'`).
"""

from __future__ import annotations

import hashlib
import json
import logging
import os
import threading
from collections.abc import Callable, Iterator, Mapping
from concurrent.futures import FIRST_COMPLETED, Future, ThreadPoolExecutor, wait
from dataclasses import dataclass
from functools import lru_cache
from importlib import metadata
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from latentrl.machine import worker_threads
from latentrl.experiments import rl_experiments
from latentrl.experiments.presets import check_type
from latentrl.results import PER_EPISODE, PER_TRIAL
from latentrl.experiments.run_folder import RunFolder
from latentrl.experiments.runner import Job, Setup, run_rl


def setup_fingerprint(built: Setup) -> str:
    """A digest of a setup's recorded facts (GPLVM fit, latent box, …) and the latentrl
    version: a worker's rebuilt setup must give the driver's."""
    payload = {"latentrl": _version(), "info": built.info}
    text = json.dumps(payload, sort_keys=True, default=lambda v: np.asarray(v).tolist())
    return hashlib.sha256(text.encode()).hexdigest()


def run_chunk(experiment: str, preset: Any, fingerprint: str, learner: str, first: int, n: int) -> dict[str, Any]:
    """One Ray task: trials `first .. first + n` of `learner` of a cell's preset. The setup is
    rebuilt from the preset once per worker process and preset, and must match the driver's
    `fingerprint` (same latentrl, same fit), else a ValueError. Returns the runner's arrays."""
    built = _worker_setup(experiment, preset)
    if setup_fingerprint(built) != fingerprint:
        raise ValueError(
            f"this worker's setup of {type(preset).__name__} differs from the driver's (latentrl "
            f"{_version()} here): install the same latentrl and dependencies on every node"
        )
    result = built.learners[learner](first_trial=first, n_trials=n)
    return {key: value for key, value in result.items() if key in PER_EPISODE or key in PER_TRIAL}


@lru_cache(maxsize=64)
def _worker_setup(experiment: str, preset: Any) -> Setup:
    return rl_experiments()[experiment].setup(preset, None)


@lru_cache(maxsize=1)
def _version() -> str:
    try:
        return metadata.version("latentrl")
    except metadata.PackageNotFoundError:
        return "unknown"


class _Stopped(Exception):
    """The driver was interrupted: stop gathering (raised in the cells' threads)."""


@dataclass
class RayBackend:
    """One Ray task per `batch` trials of every cell, all cells' tasks queued at once (up to
    `cells_in_flight` cells, each gathered by a driver thread that stores its chunks with the
    runner as they arrive). Needs the `ray` extra (`pip install 'latentrl[ray]'`)."""

    address: str | None = None
    """Ray cluster: "auto" joins the cluster `ray start` runs on this machine; "HOST:6379" a
    head node; "ray://HOST:10001" through Ray Client. None: $RAY_ADDRESS if set, else a local
    instance of `num_cpus` CPUs, stopped at the end. If Ray is already initialised, that is used."""
    batch: int = 1
    """Trials per task (each task asks for this many CPUs)."""
    max_retries: int = 3
    """A task whose worker process died is run again up to this many times."""
    num_cpus: int | None = None
    """CPUs of a local instance (None: as many as rayon's threads)."""
    task: Callable[..., dict[str, Any]] = run_chunk
    """What a task runs, with `run_chunk`'s arguments (tests wrap it)."""
    cells_in_flight: int = 16
    """Cells whose trials are queued at the same time."""

    name: ClassVar[str] = "ray"

    def __post_init__(self) -> None:
        for what in ("batch", "max_retries", "cells_in_flight"):
            check_type(what, getattr(self, what), int, minimum=0 if what == "max_retries" else 1)

    def describe(self) -> dict[str, Any]:
        """The backend and its settings, for sweep.json."""
        address = self.address or os.environ.get("RAY_ADDRESS")
        return {"backend": self.name, "address": address, "batch": self.batch, "max_retries": self.max_retries}

    def run(
        self, jobs: list[Job], advance: Callable[[int], object], finished: Callable[[Job], None]
    ) -> dict[str, BaseException]:
        """See `Backend.run`."""
        if not (self.address or os.environ.get("RAY_ADDRESS")):
            # The local instance is for this machine alone: Ray's single-machine mode keeps
            # every server on 127.0.0.1 (else it listens on the machine's network address).
            # Read when ray is imported, so set first.
            os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
        try:
            import ray
        except ModuleNotFoundError:
            raise ValueError("the ray backend needs Ray: pip install 'latentrl[ray]'") from None
        started = self._connect(ray)
        failures: dict[str, BaseException] = {}
        stop = threading.Event()
        lock = threading.Lock()

        def locked_advance(n: int) -> None:
            with lock:
                advance(n)

        try:
            nodes: list[dict[str, Any]] = ray.nodes()  # type: ignore[no-untyped-call]
            largest = max((node["Resources"].get("CPU", 0) for node in nodes if node["Alive"]), default=0)
            if self.batch > largest:
                raise ValueError(f"batch {self.batch} asks for {self.batch} CPUs per task; the largest "
                                 f"node of this Ray cluster has {largest:g}")
            remote = ray.remote(num_cpus=self.batch, max_retries=self.max_retries)(self.task)
            workers = max(1, min(len(jobs), self.cells_in_flight))
            with ThreadPoolExecutor(max_workers=workers, thread_name_prefix="sweep-cell") as pool:
                futures: dict[Future[None], Job] = {
                    pool.submit(self._cell, ray, remote, job, stop, locked_advance): job for job in jobs
                }
                pending = set(futures)
                try:
                    while pending:
                        done, pending = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
                        for future in done:
                            job, error = futures[future], future.exception()
                            if error is not None:
                                failures[job.id] = error
                                continue
                            kind = rl_experiments()[job.experiment]
                            try:  # here, not in the cells' threads: pyplot is not thread-safe
                                kind.figures(job.preset, RunFolder(job.out).arrays(), job.out, job.out)
                            except Exception as err:  # noqa: BLE001 - reported with the cell
                                failures[job.id] = err
                                continue
                            finished(job)
                except BaseException:
                    stop.set()
                    for future in pending:
                        future.cancel()
                    raise
        finally:
            if started:
                ray.shutdown()
        return failures

    def _connect(self, ray: Any) -> bool:
        """Initialises Ray unless it is; whether this call did (and `run` shuts it down again:
        stops the local instance, or disconnects from the cluster)."""
        if ray.is_initialized():
            return False
        quiet = {"logging_level": logging.WARNING, "log_to_driver": False}
        address = self.address or os.environ.get("RAY_ADDRESS")
        if address is None:
            cpus = self.num_cpus or worker_threads()
            ray.init(address="local", num_cpus=cpus, include_dashboard=False, **quiet)
        else:
            ray.init(address=address, **quiet)
        return True

    def _cell(self, ray: Any, remote: Any, job: Job, stop: threading.Event, advance: Callable[[int], None]) -> None:
        """Runs one cell with the runner, its chunks as Ray tasks (in a driver thread)."""
        kind = rl_experiments()[job.experiment]

        def execute(
            built: Setup, chunks: list[tuple[str, int, int]], _episodes: Callable[[int], object]
        ) -> Iterator[tuple[str, int, int, dict[str, Any]]]:
            if stop.is_set():
                raise _Stopped
            fingerprint = setup_fingerprint(built)
            refs = {
                remote.remote(job.experiment, job.preset, fingerprint, name, first, n): (name, first, n)
                for name, first, n in chunks
            }
            errors: list[str] = []
            try:
                while refs:
                    if stop.is_set():
                        raise _Stopped
                    ready, _ = ray.wait(list(refs), num_returns=1, timeout=0.5)
                    for ref in ready:
                        name, first, n = refs.pop(ref)
                        try:
                            result = ray.get(ref)
                        except ray.exceptions.RayError as err:
                            cause = getattr(err, "cause", None) or err
                            errors.append(f"{name} trials {first}..{first + n - 1}: {type(cause).__name__}: {cause}")
                            continue
                        yield name, first, n, result
                        advance(n)  # after the runner saved it
            finally:
                for ref in refs:
                    ray.cancel(ref, force=True)
            if errors:
                more = f" (and {len(errors) - 1} more)" if len(errors) > 1 else ""
                raise RuntimeError(f"{errors[0]}{more}")

        run_rl(job.preset, job.out, setup=kind.setup, figures=_no_figures, progress=False,
               chunk=self.batch, execute=execute)


def _no_figures(_preset: Any, _arrays: Mapping[str, np.ndarray], _run: Path, _out: Path) -> None:
    """The cells' threads draw nothing; the driver's main thread does."""
