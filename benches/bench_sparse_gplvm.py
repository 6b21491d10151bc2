"""The sparse GPLVM (`GPLVM(inducing=m)`, docs/method.md §Sparse GPLVM) on many frames: fit time
and peak memory, and the cost of decoding with its DTC map. Writes
benches/results/bench_sparse_gplvm.json.

    .venv/bin/python benches/bench_sparse_gplvm.py [--quick] [--inducing 64] [--max-iter 200]

Data: `arm_postures(N)` (two planar 2-link arms holding an object, D = 4, seed 0) for N = 10k and
100k frames (--quick: 2k and 10k). Each fit runs in its own child process, so its peak RSS
(`ru_maxrss`) is its own: d = 2, m inducing inputs, random_state 0, L-BFGS capped at --max-iter
iterations (reported with whether it converged); the fit includes the DTC GP encoder's. Then:

- fit: wall and CPU seconds (user + sys of the child, all its threads: the number to compare on
  a shared machine), the 1-minute load average before it;
- held out: RMS of decode(encode(x)) − x over 1000 postures not fitted, rad, with the GP encoder
  (`held_out_rmse`) and the iterative projection (`held_out_rmse_projection`);
- decode batch: points per wall second and per CPU second (all threads) of
  `decoder_.predict_mean` (mean only) and `decoder_.predict` (mean and variance) over 100k latent
  points drawn in the fitted points' bounding box;
- decode one: µs per call of `decoder_.predict_one` from Python, median of 2000 calls.

GPy's `SparseGPLVM` (same data, m, kernel RBF and its Gaussian noise, the same iteration cap) runs
beside it when GPy imports (`pip install GPy gymnasium` in a venv of its own, `python/` on
PYTHONPATH, `--gpy-python` that venv's python); its rows are skipped otherwise. GPy runs its
default VarDTC inference (Titsias' bound, the same O(N m²)): its `DTC` class takes one output
column only (D = 4 fails in `dtc.py` on a (4m, 4m) + (m, m) sum). GPy's time includes no encoder.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

RESULTS = Path(__file__).parent / "results" / "bench_sparse_gplvm.json"

CHILD = r"""
import json, os, resource, statistics, sys, time
import numpy as np
from latentrl.datasets import arm_postures

n, m, max_iter, peer = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
X = arm_postures(n, np.random.default_rng(0))
held_out = arm_postures(1000, np.random.default_rng(1))
rss0 = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
out = {"frames": n, "inducing": m, "max_iter": max_iter, "rss_before_fit_mib": rss0, "load_before": os.getloadavg()[0]}


def cpu():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime

if peer == "latentrl":
    from latentrl import GPLVM

    start, cpu0 = time.perf_counter(), cpu()
    model = GPLVM(random_state=0, inducing=m, max_iter=max_iter).fit(X)
    out.update(fit_s=time.perf_counter() - start, fit_cpu_s=cpu() - cpu0, n_iter=model.n_iter_,
               converged=model.converged_, nll=model.nll_, theta=model.theta_.tolist())
    out["peak_rss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    for method, key in (("gp", "held_out_rmse"), ("projection", "held_out_rmse_projection")):
        decoded = model.inverse_transform(model.transform(held_out, method=method))
        out[key] = float(np.sqrt(np.mean((decoded - held_out) ** 2)))
    low, high = model.Z_.min(axis=0), model.Z_.max(axis=0)
    Z = np.random.default_rng(2).uniform(low, high, (100_000, 2))
    for name, call in (("mean", model.decoder_.predict_mean), ("mean_variance", model.decoder_.predict)):
        start, cpu0 = time.perf_counter(), cpu()
        call(Z)
        out[f"decode_batch_{name}_points_per_s"] = len(Z) / (time.perf_counter() - start)
        out[f"decode_batch_{name}_points_per_cpu_s"] = len(Z) / (cpu() - cpu0)
    times = []
    for z in Z[:2000]:
        start = time.perf_counter()
        model.decoder_.predict_one(z)
        times.append(time.perf_counter() - start)
    out["decode_one_us"] = 1e6 * statistics.median(times)
else:
    import GPy

    Y = X - X.mean(axis=0)
    start, cpu0 = time.perf_counter(), cpu()
    gpy = GPy.models.SparseGPLVM(Y, 2, kernel=GPy.kern.RBF(2), num_inducing=m)
    gpy.optimize(max_iters=max_iter)
    out.update(fit_s=time.perf_counter() - start, fit_cpu_s=cpu() - cpu0, nll=-float(np.ravel(gpy.log_likelihood())[0]), gpy=GPy.__version__)
    out["peak_rss_mib"] = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    Z = np.random.default_rng(2).uniform(gpy.X.values.min(axis=0), gpy.X.values.max(axis=0), (100_000, 2))
    start = time.perf_counter()
    gpy.predict(Z)
    out["decode_batch_mean_variance_points_per_s"] = len(Z) / (time.perf_counter() - start)
    times = []
    for z in Z[:200]:
        start = time.perf_counter()
        gpy.predict(z[None, :])
        times.append(time.perf_counter() - start)
    out["decode_one_us"] = 1e6 * statistics.median(times)
print(json.dumps(out))
"""


def run(n: int, m: int, max_iter: int, peer: str, python: str) -> dict[str, Any] | None:
    """One fit in a child process; None if the peer cannot run (GPy not installed)."""
    done = subprocess.run([python, "-c", CHILD, str(n), str(m), str(max_iter), peer],
                          capture_output=True, text=True, check=False)
    if done.returncode != 0:
        print(f"{peer} N={n}: skipped ({done.stderr.strip().splitlines()[-1] if done.stderr else done.returncode})")
        return None
    row: dict[str, Any] = json.loads(done.stdout.strip().splitlines()[-1])
    print(peer, json.dumps(row))
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--quick", action="store_true", help="2k and 10k frames instead of 10k and 100k")
    parser.add_argument("--inducing", type=int, default=64, help="m (default: 64)")
    parser.add_argument("--max-iter", type=int, default=200, help="L-BFGS iteration cap (default: 200)")
    parser.add_argument("--gpy-python", default=sys.executable,
                        help="the Python that runs GPy's rows (default: this one)")
    parser.add_argument("--sizes", default=None, help="frames, comma-separated (default: 10000,100000)")
    parser.add_argument("--out", type=Path, default=RESULTS)
    args = parser.parse_args()
    sizes = [int(n) for n in args.sizes.split(",")] if args.sizes else (2_000, 10_000) if args.quick else (10_000, 100_000)
    rows: dict[str, list[dict[str, Any]]] = {"latentrl": [], "gpy": []}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    for n in sizes:
        for peer, python in (("latentrl", sys.executable), ("gpy", args.gpy_python)):
            row = run(n, args.inducing, args.max_iter, peer, python)
            if row is not None:
                rows[peer].append(row)
            # Written after every row: a long run interrupted keeps what it measured.
            result = {"command": " ".join(sys.argv), "date": time.strftime("%Y-%m-%d"), **rows}
            args.out.write_text(json.dumps(result, indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
