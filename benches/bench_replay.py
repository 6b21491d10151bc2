"""Replay speed (issue #23): frames per second of `latentrl.replay.render_frames` at 640×320 and
960×480 for a recorded Exp 2 arms episode and an Exp 3 humanoid episode, on one core (the
figure is drawn by matplotlib's Agg in this process). Writes benches/results/bench_replay.json.

    .venv/bin/python benches/bench_replay.py EXP2_RUN EXP3_RUN    # results directories with recorded tests
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from latentrl.saved_runs import saved_run
from latentrl.experiments.run_folder import RunFolder
from latentrl.replay import episode_path, recorded, render_frames

ROOT = Path(__file__).resolve().parent.parent


def fps(run: Path, width: int, frames: int) -> dict[str, float]:
    """Frames per second drawing `frames` frames of the run's first recorded test episode: the
    link poses and the latent path of the stored rows, then the frames (reading the run's saved
    GPLVM included)."""
    name, preset = saved_run(run)
    arrays = RunFolder(run).arrays()
    rows, _ = episode_path(arrays, 0, None, 0, preset.episodes)
    rows = rows[np.linspace(0, len(rows) - 1, frames).round().astype(int)]
    start = time.perf_counter()
    episode = recorded(name, preset, run, rows, np.asarray(arrays["latent_weights"])[0], name)
    out = render_frames(episode, size=(width, width // 2), max_frames=frames)
    seconds = time.perf_counter() - start
    return {"frames": len(out), "seconds": seconds, "frames_per_s": len(out) / seconds}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("exp2", type=Path)
    parser.add_argument("exp3", type=Path)
    parser.add_argument("--frames", type=int, default=100)
    parser.add_argument("--out", type=Path, default=ROOT / "benches" / "results" / "bench_replay.json")
    args = parser.parse_args()
    rows = {f"{name}_{width}": fps(run, width, args.frames) for name, run in (("arms", args.exp2), ("humanoid", args.exp3))
            for width in (640, 960)}
    for key, row in rows.items():
        print(key, json.dumps({k: round(v, 3) for k, v in row.items()}))
    args.out.write_text(json.dumps({"rows": rows, "note": "frames include the robot's collision shapes and the V panel"},
                                   indent=2) + "\n")


if __name__ == "__main__":
    main()
