"""The three GPLVM encoders compared on the project's demonstration sets (issue #19): round
trips, held-out reconstruction, encode cost and fit time. Writes benches/results/bench_encoders.json;
docs/encoders.md shows the table.

    .venv/bin/python benches/bench_encoders.py [--quick]

Data: the 123 arm postures of Table I's joint-space set and of Exp 2 (`arm_postures`, seed 0:
the same set) and the 7 humanoid lift demos. Encoders: "gp" (the out-of-sample GP
fitted onto Z_ after the fit, the paper's) and "projection" share one fit; "back_constrained"
is its own fit (Z_ = K_b W). Every fit: d = 2, the GPLVM defaults, random_state 0.

- encode∘decode: ‖encode(decode(z)) − z‖ over a 20 × 20 grid of the latent box (the fitted
  points' bounding box widened by 10 % per side, as the experiments use), mean and max.
- demos: ‖encode(x) − z‖ over the training postures (z their fitted latent points), max.
- held out: ‖decode(encode(x)) − x‖ (rad, RMS over joints) of postures left out of the fit:
  5 folds for the arm sets, leave-one-out for the 7 humanoid demos; mean.
- encode µs: one posture per call from Python (`transform`), and the native map alone
  (`encoder_.predict_one`, or `native_projection_.encode_one` for "projection": what the Rust
  RL loop calls per step); median of 2000 calls.
- fit s: wall time of `GPLVM.fit`.
- projection only, native vs SciPy: the largest ‖native − SciPy‖ over the grid's decoded
  postures and the demos, ÷ latent span (JSON only).

The table between the markers of docs/encoders.md is rewritten from the results.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import time
from pathlib import Path

import numpy as np

from latentrl import GPLVM, load_demos
from latentrl.datasets import arm_postures
from latentrl.experiments.exp2 import Exp2Preset
from latentrl.experiments.exp3 import demos_path

ROOT = Path(__file__).resolve().parent.parent
ENCODERS = ("gp", "projection", "back_constrained")


def datasets() -> dict[str, np.ndarray]:
    """The demonstration sets, by name."""
    return {
        "arms_123": arm_postures(Exp2Preset().n_demos, np.random.default_rng(0)),
        "humanoid_lift_7": load_demos(demos_path()).postures,
    }


def fit(X: np.ndarray, encoder: str) -> GPLVM:
    """The GPLVM of `encoder`'s kind ("projection" uses the "gp" fit)."""
    return GPLVM(encoder="back_constrained" if encoder == "back_constrained" else "gp", random_state=0).fit(X)


def grid(model: GPLVM, n: int = 20) -> np.ndarray:
    """An n × n grid of the latent box (10 % margin)."""
    low, high = model.Z_.min(axis=0), model.Z_.max(axis=0)
    low, high = low - 0.1 * (high - low), high + 0.1 * (high - low)
    axes = [np.linspace(a, b, n) for a, b in zip(low, high)]
    return np.stack(np.meshgrid(*axes), axis=-1).reshape(-1, 2)


def held_out(X: np.ndarray, encoder: str) -> float:
    """Mean RMS reconstruction error (over joints) of postures left out of the fit."""
    folds = np.array_split(np.random.default_rng(0).permutation(len(X)), len(X) if len(X) < 10 else 5)
    errors = []
    for fold in folds:
        keep = np.setdiff1d(np.arange(len(X)), fold)
        model = fit(X[keep], encoder)
        back = model.inverse_transform(model.transform(X[fold], method=encoder))
        errors.extend(np.sqrt(np.mean((back - X[fold]) ** 2, axis=1)))
    return float(np.mean(errors))


def encode_cost(model: GPLVM, X: np.ndarray, encoder: str, calls: int) -> tuple[float, float]:
    """Median µs per single-posture encode: from Python, and the native map alone."""
    x = X[:1]
    python, native = [], []
    for _ in range(calls):
        t = time.perf_counter()
        model.transform(x, method=encoder)
        python.append(time.perf_counter() - t)
    encode_one = model.native_projection_.encode_one if encoder == "projection" else model.encoder_.predict_one
    for _ in range(calls):
        t = time.perf_counter()
        encode_one(x[0])
        native.append(time.perf_counter() - t)
    return statistics.median(python) * 1e6, statistics.median(native) * 1e6


def row(X: np.ndarray, encoder: str, calls: int) -> dict[str, float]:
    """Every measure of one encoder on one set."""
    t = time.perf_counter()
    model = fit(X, encoder)
    fit_s = time.perf_counter() - t
    z = grid(model)
    trip = np.linalg.norm(model.transform(model.inverse_transform(z), method=encoder) - z, axis=1)
    demo = np.linalg.norm(model.transform(X, method=encoder) - model.Z_, axis=1)
    python_us, native_us = encode_cost(model, X, encoder, calls)
    span = float(np.ptp(model.Z_, axis=0).max())
    extra = {}
    if encoder == "projection":
        postures = np.vstack([model.inverse_transform(z), X])
        gap = np.linalg.norm(model.native_projection_.encode(postures) - model.transform(postures, method=encoder), axis=1)
        extra = {"native_vs_scipy_max": float(gap.max()) / span}
    return {**extra, "fit_s": fit_s, "encode_decode_mean": float(trip.mean()), "encode_decode_max": float(trip.max()),
            "demos_max": float(demo.max()), "held_out_rms_rad": held_out(X, encoder),
            "encode_us_python": python_us, "encode_us_native": native_us,
            "latent_span": span}


def microseconds(value: float) -> str:
    """A time in µs as the table shows it."""
    return f"{value:.0f}" if value >= 100 else f"{value:.1f}"


def table(sets: dict[str, dict[str, dict[str, float]]]) -> str:
    """The markdown table of docs/encoders.md."""
    lines = ["| set | encoder | fit (s) | encode∘decode over the box, mean / max (÷ latent span) | demos: max ‖encode(x) − z‖ "
             "| held out: decode∘encode RMS (rad) | encode µs: Python / native |", "|---|---|---|---|---|---|---|"]
    for name, rows in sets.items():
        for enc, r in rows.items():
            span = r["latent_span"]
            lines.append(f"| {name} | {enc} | {r['fit_s']:.2f} | {r['encode_decode_mean'] / span:.4f} / "
                         f"{r['encode_decode_max'] / span:.3f} | {r['demos_max']:.1e} | {r['held_out_rms_rad']:.4f} | "
                         f"{microseconds(r['encode_us_python'])} / {microseconds(r['encode_us_native'])} |")
    return "\n".join(lines)


def write_table(sets: dict[str, dict[str, dict[str, float]]], doc: Path) -> None:
    """Replaces the table between the `encoders` markers of `doc`."""
    text = doc.read_text()
    body = f"<!-- encoders:begin -->\n{table(sets)}\n<!-- encoders:end -->"
    doc.write_text(re.sub(r"<!-- encoders:begin -->.*<!-- encoders:end -->", lambda _: body, text, flags=re.S))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="200 timing calls instead of 2000")
    parser.add_argument("--out", type=Path, default=ROOT / "benches" / "results" / "bench_encoders.json")
    args = parser.parse_args()
    calls = 200 if args.quick else 2000
    out = {name: {enc: row(X, enc, calls) for enc in ENCODERS} for name, X in datasets().items()}
    for name, rows in out.items():
        for enc, r in rows.items():
            print(name, enc, json.dumps({k: round(v, 6) for k, v in r.items()}))
    args.out.write_text(json.dumps({"sets": out, "threads": "default"}, indent=2) + "\n")
    write_table(out, ROOT / "docs" / "encoders.md")


if __name__ == "__main__":
    main()
