"""The same sweeps of Exp 1 (2 cells) on the local backend (rayon, in this process) and on a
local Ray instance (one task per trial), and what the Ray backend costs per trial.

Per-trial cost: the slope of wall time over the number of trials, from a sweep of trials of a
few steps at two sizes (4 and 48 trials per cell), so that the fixed costs (the driver's GPLVM
fits, figures, summary; Ray running two cells at once) cancel. For Ray that is the task round
trip, the result transfer and one results save per trial (the local backend saves once per
rayon chunk). End to end: a sweep of trials of ~0.1-0.4 s. On Ray a first run, in which each
worker process rebuilds the cell's setup (GPLVM fit) once, is timed apart; the runs compared
find it cached. Times are the best of 3 (2 end to end); Ray's start-up and the round trip of
an empty task are timed apart; both backends must write the same bits.

    .venv/bin/python benches/bench_sweep.py [--out benches/results/bench_sweep.json]
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import tempfile
import time
from pathlib import Path
from typing import Any

import numpy as np

from latentrl.experiments.ray_backend import RayBackend
from latentrl.results import environment, write_json
from latentrl.machine import worker_threads
from latentrl.experiments.sweep import Sweep, run_sweep


def timed_sweep(sweep: Sweep, out: Path, backend: object) -> float:
    started = time.perf_counter()
    run_sweep(sweep, out, backend=backend, progress=False)  # type: ignore[arg-type]
    return time.perf_counter() - started


def same_bits(sweep: Sweep, a: Path, b: Path) -> bool:
    for cell in sweep.expand():
        with np.load(a / cell.id / "returns.npz") as x, np.load(b / cell.id / "returns.npz") as y:
            if x.files != y.files or not all(np.array_equal(x[k], y[k], equal_nan=True) for k in x.files):
                return False
    return True


def measure(sweep: Sweep, root: Path, repeats: int) -> dict[str, object]:
    """Local (after a warm-up run) and on Ray (the instance must be up; after a first run that
    fits the workers' setups), each the best of `repeats` runs: wall times."""
    trials = sum(c.preset.trials for c in sweep.expand()) * 2  # two learners per cell
    name = f"{sweep.trials}x{sweep.base['episodes']}x{sweep.base['steps']}"
    timed_sweep(sweep, root / f"{name}_warmup", "local")  # imports, caches
    local = min(timed_sweep(sweep, root / f"{name}_local{i}", "local") for i in range(repeats))
    first = timed_sweep(sweep, root / f"{name}_ray_first", RayBackend())
    ray = min(timed_sweep(sweep, root / f"{name}_ray{i}", RayBackend()) for i in range(repeats))
    identical = all(same_bits(sweep, root / f"{name}_local0", root / f"{name}_ray{i}") for i in range(repeats))
    return {
        "sweep": sweep.describe(),
        "trials": trials,
        "local_wall_s": local,
        "ray_first_wall_s": first,
        "ray_wall_s": ray,
        "bit_identical": identical and same_bits(sweep, root / f"{name}_local0", root / f"{name}_ray_first"),
    }


def noop_task_ms(ray: Any, tasks: int = 200) -> float:
    """Round trip of an empty Ray task, submitted `tasks` at a time (after a warm-up)."""

    @ray.remote(num_cpus=1)  # type: ignore[untyped-decorator]
    def noop() -> None:
        return None

    ray.get([noop.remote() for _ in range(20)])
    started = time.perf_counter()
    ray.get([noop.remote() for _ in range(tasks)])
    return 1e3 * (time.perf_counter() - started) / tasks


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("benches/results/bench_sweep.json"))
    args = parser.parse_args()
    # A local instance on 127.0.0.1 only (Ray's single-machine mode); set before ray is imported.
    os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")
    import ray

    def sweep(trials: int, episodes: int, steps: int) -> Sweep:
        return Sweep("exp1", quick=True, trials=trials, base={"episodes": episodes, "steps": steps},
                     grid={"beta": [5.0, 10.0]})

    figures: dict[str, object] = {}
    with tempfile.TemporaryDirectory() as tmp:
        started = time.perf_counter()
        ray.init(address="local", num_cpus=worker_threads(), include_dashboard=False, log_to_driver=False,
                 logging_level=logging.WARNING)
        figures["ray_start_s"] = time.perf_counter() - started
        try:
            figures["ray_noop_task_ms"] = noop_task_ms(ray)
            few, many = measure(sweep(4, 2, 10), Path(tmp), 3), measure(sweep(48, 2, 10), Path(tmp), 3)
            small = measure(sweep(4, 100, 200), Path(tmp), 2)
        finally:
            started = time.perf_counter()
            ray.shutdown()
            figures["ray_shutdown_s"] = time.perf_counter() - started
    extra = int(many["trials"]) - int(few["trials"])  # type: ignore[call-overload]
    per_trial = {
        backend: 1e3 * (float(many[key]) - float(few[key])) / extra  # type: ignore[arg-type]
        for backend, key in (("local", "local_wall_s"), ("ray", "ray_wall_s"))
    }
    figures["per_trial_ms"] = {**per_trial, "ray_overhead": per_trial["ray"] - per_trial["local"]}
    figures["tiny_trials"] = {"few": few, "many": many}
    figures["small_trials"] = {
        **small,
        "local_per_trial_ms": 1e3 * float(small["local_wall_s"]) / int(small["trials"]),  # type: ignore[arg-type,call-overload]
        "ray_per_trial_ms": 1e3 * float(small["ray_wall_s"]) / int(small["trials"]),  # type: ignore[arg-type,call-overload]
    }
    figures["bit_identical"] = all(bool(m["bit_identical"]) for m in (few, many, small))
    figures.update(threads=worker_threads(), load_average_1min=os.getloadavg()[0], ray_version=ray.__version__,
                   environment=environment())
    print(json.dumps(without(figures, ("sweep", "environment")), indent=2))
    write_json(args.out, figures)


def without(value: object, keys: tuple[str, ...]) -> object:
    """`value` without the entries named `keys`, at any depth (for the printout)."""
    if isinstance(value, dict):
        return {k: without(v, keys) for k, v in value.items() if k not in keys}
    return value


if __name__ == "__main__":
    main()
