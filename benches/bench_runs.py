"""Whole experiment runs: wall time and peak resident memory of `latentrl run EXP` on its
default (paper) preset, the figures the issue tracker asks for (a full Exp 1 run stays under
2 GiB resident; how long the full Exp 2 takes on this machine).

    .venv/bin/python benches/bench_runs.py [exp1 [exp2 …]] [--flag VALUE …] [--out benches/results/bench_runs.json]

Each experiment runs in a child process (`python -m latentrl run EXP --no-progress`) into a
temporary directory; extra arguments after the experiment names go to every run (e.g.
`--trials 2` for a smoke run). The JSON keeps one entry per experiment, merged with what the
file already holds, so experiments can be measured one at a time.
"""

from __future__ import annotations

import argparse
import json
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from latentrl.results import environment, read_json, write_json
from latentrl.machine import worker_threads


def measure(experiment: str, extra: list[str]) -> dict[str, object]:
    """Runs one experiment in a child process; its wall time, peak RSS and a few results."""
    with tempfile.TemporaryDirectory() as out:
        cmd = [sys.executable, "-m", "latentrl", "run", experiment, "--no-progress", "--out", out, *extra]
        started = time.perf_counter()
        subprocess.run(cmd, check=True)
        wall = time.perf_counter() - started
        meta = read_json(Path(out) / "results.json")
    # RUSAGE_CHILDREN: the largest child so far, and the runs are this script's only children.
    child_peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    return {
        "command": " ".join(["latentrl", *cmd[3:5], *extra]),
        "wall_time_s": wall,
        "run_wall_time_s": meta["wall_time_s"],
        "peak_rss_mib": meta["peak_rss_mib"],
        "peak_rss_mib_getrusage_children": child_peak,
        "trials": meta["preset"]["trials"],
        "episodes": meta["preset"]["episodes"],
        "threads": worker_threads(),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("experiments", nargs="*", default=["exp1"], choices=["exp1", "exp2"])
    parser.add_argument("--out", type=Path, default=Path("benches/results/bench_runs.json"))
    args, extra = parser.parse_known_args()
    figures = read_json(args.out) if args.out.exists() else {}
    for experiment in args.experiments:
        figures[experiment] = measure(experiment, extra)
        print(json.dumps({experiment: figures[experiment]}, indent=2))
    figures["environment"] = environment()
    write_json(args.out, figures)


if __name__ == "__main__":
    main()
