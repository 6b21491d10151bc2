"""Loading a recorder's CSV of postures: `load_demos` on a plain table of numbers (NumPy's C
reader), the same file read cell by cell as any other CSV is (what names a bad cell's line and
joint), and `np.loadtxt` alone as the peer, in one process; wall seconds, best of runs.

    .venv/bin/python benches/bench_demos.py [--rows 2000000] [--runs 3] [--out benches/results/bench_demos.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import tempfile
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any
from unittest.mock import patch

import numpy as np

import latentrl.demos
from latentrl import load_demos

JOINTS = 7
"""Columns of the table: a 7-DoF arm's joints."""


def best_of(runs: int, load: Callable[[], Any]) -> float:
    """The fastest of `runs` wall times of `load()` (s)."""
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        load()
        times.append(time.perf_counter() - start)
    return min(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", type=int, default=2_000_000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "bench_demos.json")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "demos.csv"
        postures = np.random.default_rng(0).uniform(-np.pi, np.pi, (args.rows, JOINTS))
        with path.open("w") as fh:
            fh.write(",".join(f"joint{j}" for j in range(JOINTS)) + "\n")
            np.savetxt(fh, postures, delimiter=",", fmt="%.10f")
        with patch.object(latentrl.demos, "_numbers_below_header", lambda text: None):
            cells = best_of(args.runs, lambda: load_demos(path))
        rows = {
            "load_demos": best_of(args.runs, lambda: load_demos(path)),
            "load_demos, cell by cell": cells,
            "np.loadtxt (peer)": best_of(args.runs, lambda: np.loadtxt(path, delimiter=",", skiprows=1)),
        }
        size = path.stat().st_size
    for name, seconds in rows.items():
        print(f"{name:26s} {seconds:7.2f} s")
    args.out.write_text(json.dumps({"rows": {k: {"best_s": v} for k, v in rows.items()}, "postures": args.rows,
                                    "joints": JOINTS, "file_bytes": size, "runs": args.runs,
                                    "machine": platform.processor() or platform.machine()}, indent=2) + "\n")


if __name__ == "__main__":
    main()
