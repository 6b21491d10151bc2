"""Start-up cost (issue #39, item 5: ≤ 0.3 s of CPU each): `import latentrl`, `latentrl --help`
and a bad flag, each in a fresh interpreter, median CPU (user + system) of the child over runs.

    .venv/bin/python benches/bench_startup.py [--runs 7] [--out benches/results/bench_startup.json]
"""

from __future__ import annotations

import argparse
import json
import platform
import resource
import statistics
import subprocess
import sys
from pathlib import Path

COMMANDS = {
    "import latentrl": [sys.executable, "-c", "import latentrl"],
    "latentrl --help": [sys.executable, "-m", "latentrl", "--help"],
    "latentrl train --bad-flag": [sys.executable, "-m", "latentrl", "train", "--bad-flag"],
}
"""What a user starts, by name."""

GOAL_S = 0.3
"""The issue's ceiling on each command's CPU seconds."""


def cpu_seconds(command: list[str]) -> float:
    """CPU seconds (user + system) the child running `command` used."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run(command, capture_output=True, check=False)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "bench_startup.json")
    args = parser.parse_args()
    rows = {}
    for name, command in COMMANDS.items():
        cpu_seconds(command)  # warm the file cache
        times = [cpu_seconds(command) for _ in range(args.runs)]
        rows[name] = {"median_cpu_s": statistics.median(times), "min_cpu_s": min(times),
                      "within_goal": statistics.median(times) <= GOAL_S}
        print(name, json.dumps({k: round(v, 3) if isinstance(v, float) else v for k, v in rows[name].items()}))
    args.out.write_text(json.dumps({"rows": rows, "goal_cpu_s": GOAL_S, "runs": args.runs,
                                    "machine": platform.processor() or platform.machine()}, indent=2) + "\n")


if __name__ == "__main__":
    main()
