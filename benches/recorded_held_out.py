"""Held-out reconstruction of a GPLVM fitted to the recordings of tests/recorded_writers.py
(docs/demos.md §Measured), as `latentrl fit RECORDING --out MODEL.npz` saved it:

    .venv/bin/python benches/recorded_held_out.py MODEL.npz [--frames 100000] [--held-out 1000]

Held out: `--held-out` frames evenly spaced among the frames halfway in time between two recorded
frames of the same episode (`arm_episodes`' motions at t + ½ step, `--frames` as recorded).
Prints, as JSON, the RMS of decode(encode(x)) − x (rad) through the GP encoder and the iterative
projection, and over the training frames the RMS of decode(`Z_`) − X.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parents[1] / "tests"))
from recorded_writers import arm_episodes  # noqa: E402

from latentrl import GPLVM  # noqa: E402


def rmse(decoded: np.ndarray, postures: np.ndarray) -> float:
    return float(np.sqrt(np.mean((decoded - postures) ** 2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("model", type=Path)
    parser.add_argument("--frames", type=int, default=100_000, help="frames recorded (default: 100000)")
    parser.add_argument("--held-out", type=int, default=1000, help="frames held out (default: 1000)")
    args = parser.parse_args()
    model = GPLVM.load(args.model)
    between = np.concatenate([episode[:-1] for episode in arm_episodes(args.frames, offset=0.5)])
    held_out = between[np.linspace(0, len(between) - 1, args.held_out).round().astype(np.intp)]
    result = {f"held_out_{method}": rmse(model.inverse_transform(model.transform(held_out, method=method)), held_out)
              for method in ("gp", "projection")}
    result["training"] = rmse(model.inverse_transform(model.Z_), model.X_train_)
    print(json.dumps({"model": str(args.model), "nll": model.nll_, "n_iter": model.n_iter_, **result}))


if __name__ == "__main__":
    main()
