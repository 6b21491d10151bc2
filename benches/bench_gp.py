"""latentrl's GP decode / encode / GPLVM objective and fit against GPy and plain NumPy, in one
process, on the same data, parameters and starting point.

Run it in the bench venv (GPy is never a dependency of latentrl itself):

    bash benches/setup_bench_env.sh
    benches/.venv-bench/bin/python benches/bench_gp.py [--quick] [--out benches/results/bench_gp.json]

Without GPy installed the GPy rows are skipped (the NumPy and latentrl rows still run).

Cases: N = 123 arm postures (D = 4, exact, the Table I joint-space data) and a synthetic
D = 19 set (N = 123 points of a smooth 2-D manifold plus noise, humanoid-sized). Each case
fits latentrl's GPLVM once and hands the same Z and θ to GPy and NumPy, so every row computes
the same numbers (checked and reported as `agreement`).

GPy model: `GPy.models.GPLVM(Y − mean, 2, X=Z, kernel=RBF(2))` with its Gaussian likelihood
variance playing θ3. That is latentrl's "SE + white noise" kernel (paper Eq. 2) exactly: GPy's
likelihood noise cannot be switched off, so `RBF + White` in GPy would add a second noise term.
GPy's exact inference adds a constant 1e-8 to K's diagonal, so its likelihood variance holds
θ3 − 1e-8, and the white-noise floor (θ3 ≥ 1e-6) is `constrain_bounded(1e-6 − 1e-8, 1e6)` on it.

GPy's back-constrained model: `GPy.models.BCGPLVM(Y − mean, 2, kernel=RBF(2), mapping=Kernel(D,
2, Z=Y − mean, RBF(D)))`, the mapping's RBF variance fixed at 1 and its lengthscale² playing β:
the latent points are `K_b A`, our `K_b W`. Both start from our start: W₀ the ridge solve of the
PCA start, β₀ the median squared distance between postures, θ₀ with θ3 at least the floor, and
the same noise floor as the plain GPLVM.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
from scipy.linalg import cho_factor, solve_triangular
from scipy.optimize import fmin_l_bfgs_b
from scipy.spatial.distance import pdist

import latentrl
import latentrl._nll_fit
import latentrl.gplvm
from latentrl import GPLVM
from latentrl._nll_fit import initial_log_theta
from latentrl._native import GpMap, gplvm_back_constrained_nll_grad, gplvm_nll_grad
from latentrl.back_constraint import start_weights
from latentrl._reference import gplvm_nll_grad as numpy_nll_grad
from latentrl._reference import se_kernel
from latentrl.datasets import arm_postures
from latentrl.results import write_json
from latentrl.pca import PCA

try:
    import GPy
except ImportError:  # the NumPy/latentrl rows still run
    GPy = None

try:
    from threadpoolctl import threadpool_info, threadpool_limits
except ImportError:
    threadpool_info = threadpool_limits = None

NOISE_FLOOR = 1e-6
FIT_ITERS = 1000
GPY_JITTER = 1e-8
"""GPy's exact inference adds this constant to K's diagonal (exact_gaussian_inference.py); the
GPy models here hold θ3 − GPY_JITTER so that both compute with the same K."""


# ---------------------------------------------------------------------------------------------
# Timing


def per_call(
    fn: Callable[[], Any], *, min_time: float = 0.25, repeats: int = 5, warmup: int = 3
) -> dict[str, float]:
    """Median and best seconds per call of `fn` over `repeats` timed loops of ≥ min_time/repeats."""
    for _ in range(warmup):
        fn()
    loops, budget = 1, min_time / repeats
    while True:
        t0 = time.perf_counter()
        for _ in range(loops):
            fn()
        elapsed = time.perf_counter() - t0
        if elapsed >= budget or loops >= 1 << 20:
            break
        loops *= 2 if elapsed == 0 else max(2, min(10, int(budget / elapsed) + 1))
    samples = [elapsed / loops]
    for _ in range(repeats - 1):
        t0 = time.perf_counter()
        for _ in range(loops):
            fn()
        samples.append((time.perf_counter() - t0) / loops)
    return {
        "median_s": statistics.median(samples),
        "best_s": min(samples),
        "loops": loops,
        "repeats": repeats,
    }


def once(fn: Callable[[], Any], repeats: int) -> tuple[dict[str, float], Any]:
    """Best and median wall time of `repeats` full runs of a long call, and its last result."""
    times, result = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return {"median_s": statistics.median(times), "best_s": min(times), "repeats": repeats}, result


# ---------------------------------------------------------------------------------------------
# Data and baselines


def synthetic19_case(rng: np.random.Generator) -> np.ndarray:
    """N = 123 points of a smooth 2-D manifold in 19-D (random sinusoids) plus 0.01 noise."""
    z = rng.uniform(-1, 1, size=(123, 2))
    w = rng.normal(scale=1.5, size=(2, 19))
    phase = rng.uniform(0, 2 * np.pi, size=19)
    amplitude = rng.uniform(0.2, 0.8, size=19)
    return amplitude * np.sin(z @ w + phase) + rng.normal(scale=0.01, size=(123, 19))


class NumpyGp:
    """The honest plain-NumPy predictor: Cholesky factor and K⁻¹Y pre-computed once."""

    def __init__(self, inputs: np.ndarray, outputs: np.ndarray, theta: np.ndarray):
        self.inputs, self.theta = inputs, theta
        self.mean = outputs.mean(axis=0)
        k = se_kernel(inputs, inputs, theta) + theta[2] * np.eye(len(inputs))
        self.lower = cho_factor(k, lower=True)[0]
        self.lower = np.tril(self.lower)
        self.alpha = np.linalg.solve(k, outputs - self.mean)

    def kstar(self, queries: np.ndarray) -> np.ndarray:
        r2 = (
            np.sum(queries**2, axis=1)[:, None]
            + np.sum(self.inputs**2, axis=1)[None, :]
            - 2.0 * queries @ self.inputs.T
        )
        return self.theta[0] * np.exp(-0.5 * np.maximum(r2, 0.0) / self.theta[1])

    def predict_one(self, x: np.ndarray) -> tuple[np.ndarray, float]:
        diff = self.inputs - x
        k = self.theta[0] * np.exp(-0.5 * np.einsum("ij,ij->i", diff, diff) / self.theta[1])
        v = solve_triangular(self.lower, k, lower=True, check_finite=False)
        return k @ self.alpha + self.mean, float(self.theta[0] + self.theta[2] - v @ v)

    def predict_mean(self, queries: np.ndarray) -> np.ndarray:
        return self.kstar(queries) @ self.alpha + self.mean


def gpy_gplvm(centred: np.ndarray, latent: np.ndarray, theta: np.ndarray) -> Any:
    """GPy's GPLVM with latentrl's kernel and parameters (see the module docstring)."""
    kernel = GPy.kern.RBF(latent.shape[1], variance=theta[0], lengthscale=np.sqrt(theta[1]))
    return floored(GPy.models.GPLVM(centred, latent.shape[1], X=latent.copy(), kernel=kernel), theta)


def floored(model: Any, theta: np.ndarray) -> Any:
    """`model` with its likelihood variance θ3 − GPY_JITTER, bounded below by our noise floor."""
    # The bound sits a hair (1e-6 relative) below the floor: a value exactly on a logistic
    # bound is not representable, and at θ3 = floor K's condition number is ~1e8.
    model.Gaussian_noise.variance.constrain_bounded(
        (NOISE_FLOOR - GPY_JITTER) * (1 - 1e-6), 1e6, warning=False
    )
    model.Gaussian_noise.variance[:] = theta[2] - GPY_JITTER
    return model


def gpy_bcgplvm(centred: np.ndarray, weights: np.ndarray, theta: np.ndarray, log_beta: float) -> Any:
    """GPy's BCGPLVM with latentrl's kernel, back-constraint and parameters (module docstring)."""
    d = weights.shape[1]
    back = GPy.kern.RBF(centred.shape[1], variance=1.0, lengthscale=np.exp(0.5 * log_beta))
    mapping = GPy.mappings.Kernel(centred.shape[1], d, centred.copy(), back)
    mapping.A[:] = weights
    mapping.kern.variance.fix(warning=False)
    kernel = GPy.kern.RBF(d, variance=theta[0], lengthscale=np.sqrt(theta[1]))
    return floored(GPy.models.BCGPLVM(centred, d, kernel=kernel, mapping=mapping), theta)


def gpy_regression(inputs: np.ndarray, centred: np.ndarray, theta: np.ndarray) -> Any:
    kernel = GPy.kern.RBF(inputs.shape[1], variance=theta[0], lengthscale=np.sqrt(theta[1]))
    model = GPy.models.GPRegression(inputs, centred, kernel=kernel, noise_var=theta[2] - GPY_JITTER)
    return model


def latentrl_fit_same_budget(
    start: np.ndarray, centred: np.ndarray, log_theta: np.ndarray
) -> dict[str, Any]:
    """latentrl's NLL + gradient under GPy's exact optimiser call (fmin_l_bfgs_b with
    maxfun = maxiter = FIT_ITERS and scipy's default tolerances), log θ with the same floor."""
    n, d = start.shape

    def f_fp(params: np.ndarray) -> tuple[float, np.ndarray]:
        nll, gz, gt, _ = gplvm_nll_grad(params[:-3].reshape(n, d), centred, params[-3:])
        return nll, np.concatenate([gz.ravel(), gt])

    x0 = np.concatenate([start.ravel(), log_theta])
    bounds = [(None, None)] * (x0.size - 1) + [(np.log(NOISE_FLOOR), None)]
    _, nll, info = fmin_l_bfgs_b(f_fp, x0, bounds=bounds, maxfun=FIT_ITERS, maxiter=FIT_ITERS)
    return {
        "nll": float(nll),
        "evaluations": int(info["funcalls"]),
        "iterations": int(info["nit"]),
        "stop": info["task"] if isinstance(info["task"], str) else info["task"].decode(),
    }


# ---------------------------------------------------------------------------------------------
# One case


def run_case(name: str, X: np.ndarray, *, quick: bool) -> dict[str, Any]:
    print(f"\n== {name}: N = {X.shape[0]}, D = {X.shape[1]}, d = 2")
    rows: dict[str, Any] = {}
    agreement: dict[str, float] = {}
    fit_repeats = 1 if quick else 2

    model = GPLVM(2, max_iter=FIT_ITERS, noise_floor=NOISE_FLOOR).fit(X)
    Z, theta, mean = model.Z_, model.theta_, model.mean_
    centred = X - mean
    rng = np.random.default_rng(1)
    lo, hi = Z.min(axis=0), Z.max(axis=0)
    z1 = lo + rng.uniform(size=2) * (hi - lo)
    batch = lo + rng.uniform(size=(10_000, 2)) * (hi - lo)
    x1 = X[7] + 0.01 * rng.standard_normal(X.shape[1])

    decoder: GpMap = model.decoder_
    numpy_decoder = NumpyGp(Z, X, theta)
    gpy_model = gpy_gplvm(centred, Z, theta) if GPy else None

    # --- decode one point, mean + variance
    rows["decode_one_latentrl_predict_one"] = per_call(lambda: decoder.predict_one(z1))
    rows["decode_one_latentrl_inverse_transform"] = per_call(
        lambda: model.inverse_transform(z1[None, :])
    )
    rows["decode_one_latentrl_inverse_transform_variance"] = per_call(
        lambda: model.inverse_transform(z1[None, :], return_variance=True)
    )
    rows["decode_one_numpy"] = per_call(lambda: numpy_decoder.predict_one(z1))
    mean_rs, var_rs = decoder.predict_one(z1)
    mean_np, var_np = numpy_decoder.predict_one(z1)
    agreement["decode_one_numpy_mean"] = float(np.max(np.abs(mean_rs - mean_np)))
    agreement["decode_one_numpy_var"] = abs(var_rs - var_np)
    if gpy_model is not None:
        rows["decode_one_gpy_predict"] = per_call(lambda: gpy_model.predict(z1[None, :]))
        mean_gp, var_gp = gpy_model.predict(z1[None, :])
        agreement["decode_one_gpy_mean"] = float(np.max(np.abs(mean_rs - (mean_gp[0] + mean))))
        agreement["decode_one_gpy_var"] = float(abs(var_rs - var_gp[0, 0]))

    # --- decode a 10k batch (throughput in points/s)
    rows["decode_10k_latentrl_predict"] = per_call(lambda: decoder.predict(batch), min_time=0.5)
    rows["decode_10k_latentrl_inverse_transform"] = per_call(
        lambda: model.inverse_transform(batch), min_time=0.5
    )
    rows["decode_10k_numpy_mean"] = per_call(
        lambda: numpy_decoder.predict_mean(batch), min_time=0.5
    )
    agreement["decode_10k_numpy_mean"] = float(
        np.max(np.abs(decoder.predict(batch)[0] - numpy_decoder.predict_mean(batch)))
    )
    if gpy_model is not None:
        rows["decode_10k_gpy_predict"] = per_call(lambda: gpy_model.predict(batch), min_time=0.5)
    for key in [k for k in rows if k.startswith("decode_10k")]:
        rows[key]["points_per_s"] = 10_000 / rows[key]["median_s"]

    # --- GPLVM NLL + gradient, one evaluation at the fitted point
    log_theta = np.log(theta)
    rows["nll_grad_latentrl"] = per_call(lambda: gplvm_nll_grad(Z, centred, log_theta))
    rows["nll_grad_numpy"] = per_call(lambda: numpy_nll_grad(Z, centred, log_theta))
    nll_rs = gplvm_nll_grad(Z, centred, log_theta)[0]
    agreement["nll_numpy"] = abs(nll_rs - numpy_nll_grad(Z, centred, log_theta)[0])
    if gpy_model is not None:
        agreement["nll_gpy"] = abs(nll_rs - float(gpy_model.objective_function()))
        # Timing goes through the optimiser's (transformed) parameters; their round trip moves a
        # θ3 that sits on its logistic bound, so the model is rebuilt afterwards.
        params = gpy_model.optimizer_array.copy()
        rows["nll_grad_gpy"] = per_call(lambda: gpy_model._objective_grads(params))
        gpy_model = gpy_gplvm(centred, Z, theta)

    # --- GPLVM fit from the same PCA start
    pca = PCA(2).fit(X)
    start = pca.transform(X) / np.sqrt(pca.explained_variance_[0])
    theta0 = initial_log_theta(start, centred)
    timing, fitted = once(
        lambda: GPLVM(2, max_iter=FIT_ITERS, noise_floor=NOISE_FLOOR).fit(X), fit_repeats
    )
    rows["fit_latentrl_GPLVM"] = {
        **timing,
        "nll": fitted.nll_,
        "iterations": fitted.n_iter_,
        "converged": bool(fitted.converged_),
        "stop": fitted.stop_reason_,
        "theta": fitted.theta_.tolist(),
        "note": "GPLVM.fit incl. the GP encoder fit",
    }
    timing, result = once(lambda: latentrl_fit_same_budget(start, centred, theta0), fit_repeats)
    rows["fit_latentrl_core_gpy_budget"] = {**timing, **result}
    if gpy_model is not None:

        row, m = gpy_fit(lambda: gpy_gplvm(centred, start, np.exp(theta0)), fit_repeats)
        rows["fit_gpy"] = {
            **row,
            "theta": [
                float(m.rbf.variance[0]),
                float(m.rbf.lengthscale[0]) ** 2,
                float(m.Gaussian_noise.variance[0]) + GPY_JITTER,
            ],
        }

    # --- encode one point: out-of-sample GP, and the iterative projection
    encoder: GpMap = model.encoder_
    numpy_encoder = NumpyGp(X, Z, model.encoder_theta_)
    rows["encode_one_latentrl_predict_one"] = per_call(lambda: encoder.predict_one(x1))
    rows["encode_one_latentrl_transform"] = per_call(lambda: model.transform(x1[None, :]))
    rows["encode_one_numpy"] = per_call(lambda: numpy_encoder.predict_one(x1))
    agreement["encode_one_numpy"] = float(
        np.max(np.abs(encoder.predict_one(x1)[0] - numpy_encoder.predict_one(x1)[0]))
    )
    rows["encode_one_latentrl_projection"] = per_call(
        lambda: model.transform(x1[None, :], method="projection"), min_time=0.5, repeats=3, warmup=1
    )
    if GPy is not None:
        z_mean = Z.mean(axis=0)
        gpy_encoder = gpy_regression(X, Z - z_mean, model.encoder_theta_)
        rows["encode_one_gpy_predict"] = per_call(lambda: gpy_encoder.predict(x1[None, :]))
        agreement["encode_one_gpy"] = float(
            np.max(
                np.abs(
                    encoder.predict_one(x1)[0] - (gpy_encoder.predict(x1[None, :])[0][0] + z_mean)
                )
            )
        )
        y1 = x1[None, :] - mean
        rows["encode_one_gpy_infer_newX"] = per_call(
            lambda: gpy_model.infer_newX(y1), min_time=0.5, repeats=3, warmup=1
        )

    back_constrained(X, centred, start, theta0, x1, rows, agreement, fit_repeats)
    rows["fit_latentrl_GPLVM_profile"] = profile_fit(X, rows["fit_gpy"]["nll"] if "fit_gpy" in rows else None)

    return {
        "N": int(X.shape[0]),
        "D": int(X.shape[1]),
        "theta": theta.tolist(),
        "rows": rows,
        "agreement": agreement,
    }


def gpy_fit(build: Callable[[], Any], repeats: int) -> tuple[dict[str, Any], Any]:
    """Times building a GPy model with `build` and `optimize("lbfgsb", max_iters=FIT_ITERS)`:
    its row (timing, final NLL, evaluations, stop) and the last fitted model."""

    def fit() -> Any:
        m = build()
        m.optimize("lbfgsb", max_iters=FIT_ITERS)
        return m

    timing, m = once(fit, repeats)
    run = m.optimization_runs[-1]
    row = {**timing, "nll": float(m.objective_function()), "evaluations": int(run.funct_eval), "stop": run.status}
    return row, m


def back_constrained(
    X: np.ndarray,
    centred: np.ndarray,
    start: np.ndarray,
    log_theta: np.ndarray,
    x1: np.ndarray,
    rows: dict[str, Any],
    agreement: dict[str, float],
    repeats: int,
) -> None:
    """The back-constrained rows: our fit and GPy's BCGPLVM from the same start, the NLLs of
    both at that start, and one posture encoded by the back-constraint."""
    timing, bc = once(
        lambda: GPLVM(2, max_iter=FIT_ITERS, noise_floor=NOISE_FLOOR, encoder="back_constrained").fit(X), repeats
    )
    rows["fit_latentrl_back_constrained"] = {
        **timing,
        "nll": bc.nll_,
        "iterations": bc.n_iter_,
        "converged": bool(bc.converged_),
        "stop": bc.stop_reason_,
        "note": "GPLVM(encoder='back_constrained').fit",
    }
    rows["encode_one_latentrl_back_constrained_predict_one"] = per_call(lambda: bc.encoder_.predict_one(x1))
    rows["encode_one_latentrl_back_constrained_transform"] = per_call(lambda: bc.transform(x1[None, :]))
    if GPy is None:
        return
    log_beta = float(np.log(np.median(pdist(centred, "sqeuclidean"))))
    weights = start_weights(start, centred, log_beta)
    theta = np.exp(np.maximum(log_theta, [-np.inf, -np.inf, np.log(NOISE_FLOOR)]))
    ours = gplvm_back_constrained_nll_grad(weights, centred, np.log(theta), log_beta)[0]
    agreement["nll_gpy_back_constrained_at_start"] = abs(
        ours - float(gpy_bcgplvm(centred, weights, theta, log_beta).objective_function())
    )

    rows["fit_gpy_bcgplvm"] = gpy_fit(lambda: gpy_bcgplvm(centred, weights, theta, log_beta), repeats)[0]


def profile_fit(X: np.ndarray, target_nll: float | None) -> dict[str, Any]:
    """Where `GPLVM.fit`'s time goes: the native NLL + gradient of the GPLVM objective and of
    the GP encoder's (both through `latentrl._nll_fit.gplvm_nll_grad`), the encoder fit as a whole,
    and the rest (SciPy's L-BFGS-B, the Python objective wrapper, PCA, the maps); and when the
    GPLVM objective first came to `target_nll` (GPy's final NLL) or below."""
    spent: dict[str, Any] = {"native_s": 0.0, "native_calls": 0, "encoder_fit_s": 0.0, "reached_target_s": None}
    native, encoder_fit = latentrl._nll_fit.gplvm_nll_grad, latentrl.gplvm.fit_gp_encoder
    started = time.perf_counter()

    def timed_native(*args: Any) -> Any:
        t = time.perf_counter()
        out = native(*args)
        spent["native_s"] += time.perf_counter() - t
        spent["native_calls"] += 1
        if spent["reached_target_s"] is None and target_nll is not None and out[0] <= target_nll:
            spent["reached_target_s"] = time.perf_counter() - started
            spent["reached_target_calls"] = spent["native_calls"]
        return out

    def timed_encoder_fit(*args: Any, **kwargs: Any) -> Any:
        t = time.perf_counter()
        out = encoder_fit(*args, **kwargs)
        spent["encoder_fit_s"] += time.perf_counter() - t
        return out

    latentrl._nll_fit.gplvm_nll_grad, latentrl.gplvm.fit_gp_encoder = timed_native, timed_encoder_fit
    try:
        GPLVM(2, max_iter=FIT_ITERS, noise_floor=NOISE_FLOOR).fit(X)
        total = time.perf_counter() - started
    finally:
        latentrl._nll_fit.gplvm_nll_grad, latentrl.gplvm.fit_gp_encoder = native, encoder_fit
    return {"median_s": total, **spent, "rest_s": total - spent["native_s"]}


CASES: dict[str, tuple[str, Callable[[np.random.Generator], np.ndarray]]] = {
    "arms_N123_D4": ("arm postures", lambda rng: arm_postures(123, rng)),
    "synthetic_N123_D19": ("synthetic 19-D", lambda rng: synthetic19_case(rng)),
}


def fit_over_seeds(
    make: Callable[[np.random.Generator], np.ndarray], seeds: range
) -> list[dict[str, Any]]:
    """Final NLL of each fitter from the same PCA start on several data sets: one start can land
    either optimiser in a poorer local optimum, so the comparison is over seeds."""
    out = []
    for seed in seeds:
        X = make(np.random.default_rng(seed))
        pca = PCA(2).fit(X)
        start = pca.transform(X) / np.sqrt(pca.explained_variance_[0])
        centred = X - pca.mean_
        theta0 = initial_log_theta(start, centred)
        row: dict[str, Any] = {"seed": seed}
        t0 = time.perf_counter()
        row["latentrl_core_gpy_budget"] = latentrl_fit_same_budget(start, centred, theta0)["nll"]
        row["latentrl_core_seconds"] = time.perf_counter() - t0
        t0 = time.perf_counter()
        fitted = GPLVM(2, max_iter=FIT_ITERS, noise_floor=NOISE_FLOOR).fit(X)
        row["latentrl_GPLVM_seconds"] = time.perf_counter() - t0
        row["latentrl_GPLVM"] = float(fitted.nll_)
        if GPy is not None:
            m = gpy_gplvm(centred, start, np.exp(theta0))
            t0 = time.perf_counter()
            m.optimize("lbfgsb", max_iters=FIT_ITERS)
            row["gpy_seconds"] = time.perf_counter() - t0
            row["gpy"] = float(m.objective_function())
        out.append(row)
    return out


# ---------------------------------------------------------------------------------------------
# Report


def fmt_time(seconds: float) -> str:
    if seconds < 1e-3:
        return f"{seconds * 1e6:8.1f} µs"
    if seconds < 1:
        return f"{seconds * 1e3:8.2f} ms"
    return f"{seconds:8.2f} s "


def print_case(case: dict[str, Any]) -> None:
    for key, row in case["rows"].items():
        extra = ""
        if "points_per_s" in row:
            extra = f"  {row['points_per_s']:.3g} points/s"
        if "nll" in row:
            evals = row.get("evaluations", row.get("iterations"))
            extra = f"  NLL {row['nll']:.3f}  ({evals} {'evals' if 'evaluations' in row else 'iters'}, {row.get('stop', '')})"
        print(f"  {key:42s} {fmt_time(row['median_s'])}{extra}")
    print(
        "  agreement (max abs diff): "
        + ", ".join(f"{k} {v:.1e}" for k, v in case["agreement"].items())
    )


def ratios(case: dict[str, Any]) -> dict[str, float]:
    rows = case["rows"]
    out: dict[str, float] = {}

    def ratio(name: str, slow: str, fast: str) -> None:
        if slow in rows and fast in rows:
            out[name] = rows[slow]["median_s"] / rows[fast]["median_s"]

    ratio(
        "decode_one_gpy_over_predict_one",
        "decode_one_gpy_predict",
        "decode_one_latentrl_predict_one",
    )
    ratio(
        "decode_one_gpy_over_inverse_transform",
        "decode_one_gpy_predict",
        "decode_one_latentrl_inverse_transform",
    )
    ratio(
        "decode_one_numpy_over_predict_one", "decode_one_numpy", "decode_one_latentrl_predict_one"
    )
    ratio(
        "decode_one_gpy_over_inverse_transform_variance",
        "decode_one_gpy_predict",
        "decode_one_latentrl_inverse_transform_variance",
    )
    ratio("fit_gpy_over_latentrl_GPLVM", "fit_gpy", "fit_latentrl_GPLVM")
    ratio("fit_back_constrained_over_plain", "fit_latentrl_back_constrained", "fit_latentrl_GPLVM")
    ratio("fit_gpy_bcgplvm_over_latentrl", "fit_gpy_bcgplvm", "fit_latentrl_back_constrained")
    ratio("decode_10k_gpy_over_latentrl", "decode_10k_gpy_predict", "decode_10k_latentrl_predict")
    ratio("decode_10k_numpy_over_latentrl", "decode_10k_numpy_mean", "decode_10k_latentrl_predict")
    ratio("nll_grad_gpy_over_latentrl", "nll_grad_gpy", "nll_grad_latentrl")
    ratio("nll_grad_numpy_over_latentrl", "nll_grad_numpy", "nll_grad_latentrl")
    ratio("fit_gpy_over_latentrl_same_budget", "fit_gpy", "fit_latentrl_core_gpy_budget")
    ratio(
        "encode_one_gpy_over_predict_one",
        "encode_one_gpy_predict",
        "encode_one_latentrl_predict_one",
    )
    ratio(
        "encode_one_gpy_over_transform", "encode_one_gpy_predict", "encode_one_latentrl_transform"
    )
    ratio(
        "projection_gpy_over_latentrl",
        "encode_one_gpy_infer_newX",
        "encode_one_latentrl_projection",
    )
    if "fit_gpy" in rows:
        out["fit_nll_latentrl_minus_gpy_same_budget"] = (
            rows["fit_latentrl_core_gpy_budget"]["nll"] - rows["fit_gpy"]["nll"]
        )
        out["fit_nll_latentrl_default_minus_gpy"] = (
            rows["fit_latentrl_GPLVM"]["nll"] - rows["fit_gpy"]["nll"]
        )
    if "fit_gpy_bcgplvm" in rows:
        out["fit_nll_back_constrained_latentrl_minus_gpy"] = (
            rows["fit_latentrl_back_constrained"]["nll"] - rows["fit_gpy_bcgplvm"]["nll"]
        )
    return out


def issue19_goals(name: str, case: dict[str, Any]) -> dict[str, bool]:
    """Issue #19's speed goals, met or not, each named with its measured number."""
    rows, r = case["rows"], case["ratios"]
    goals: dict[str, bool] = {}
    encode = rows["encode_one_latentrl_back_constrained_transform"]["median_s"] * 1e6
    native = rows["encode_one_latentrl_back_constrained_predict_one"]["median_s"] * 1e6
    goals[f"{name}: back-constrained encode of one posture ≤ 5 µs (transform {encode:.1f} µs, "
          f"native predict_one {native:.1f} µs)"] = encode <= 5
    bc_ratio = r["fit_back_constrained_over_plain"]
    goals[f"{name}: back-constrained fit ≤ 2× the plain fit ({bc_ratio:.2f}×)"] = bc_ratio <= 2
    if "decode_one_gpy_over_inverse_transform_variance" in r:
        decode = r["decode_one_gpy_over_inverse_transform_variance"]
        goals[f"{name}: decode mean + variance through inverse_transform ≥ 50× GPy's predict ({decode:.1f}×)"] = (
            decode >= 50
        )
    if "fit_gpy_over_latentrl_GPLVM" in r:
        speed, gap = r["fit_gpy_over_latentrl_GPLVM"], r["fit_nll_latentrl_default_minus_gpy"]
        reached = rows["fit_latentrl_GPLVM_profile"]["reached_target_s"]
        early = "never" if reached is None else f"{rows['fit_gpy']['median_s'] / reached:.1f}× GPy's fit time"
        goals[f"{name}: GPLVM.fit ≥ 3× faster than GPy's fit ({speed:.2f}×) to an NLL no worse "
              f"(ours − GPy's {gap:+.2f}; GPy's final NLL first reached: {early})"] = speed >= 3 and gap <= 0
    return goals


def machine() -> dict[str, Any]:
    info: dict[str, Any] = {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "rayon_threads": os.environ.get("RAYON_NUM_THREADS", "default (one per CPU)"),
        "versions": {
            "latentrl": latentrl.__version__,
            "numpy": np.__version__,
            "scipy": __import__("scipy").__version__,
            "GPy": getattr(GPy, "__version__", None),
        },
    }
    if threadpool_info is not None:
        info["threadpools"] = [
            {k: p.get(k) for k in ("internal_api", "num_threads", "version")}
            for p in threadpool_info()
        ]
    return info


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parent / "results" / "bench_gp.json"
    )
    parser.add_argument("--quick", action="store_true", help="one fit repeat (smoke run)")
    parser.add_argument("--blas-threads", type=int, default=1, help="BLAS threads (peer figures: 1)")
    parser.add_argument(
        "--fit-seeds", type=int, default=5, help="data sets for the fit NLL comparison"
    )
    args = parser.parse_args(argv)

    if threadpool_limits is not None:
        threadpool_limits(args.blas_threads)  # for the whole run
    env = machine()
    print(
        f"latentrl {env['versions']['latentrl']}, NumPy {np.__version__}, GPy {env['versions']['GPy']}; "
        f"{env['cpu_count']} CPUs, rayon threads: {env['rayon_threads']}"
    )
    for pool in env.get("threadpools", []):
        print(
            f"  threadpool {pool['internal_api']} {pool.get('version')}: {pool['num_threads']} thread(s)"
        )
    if GPy is None:
        print(
            "GPy not importable: GPy rows skipped (run benches/setup_bench_env.sh)", file=sys.stderr
        )

    started = time.perf_counter()
    cases = {
        name: run_case(label, make(np.random.default_rng(0)), quick=args.quick)
        for name, (label, make) in CASES.items()
    }
    print("\nResults (median per call)")
    for name, case in cases.items():
        print(f"-- {name}")
        print_case(case)
        case["ratios"] = ratios(case)
        print("  ratios: " + ", ".join(f"{k} {v:.3g}" for k, v in case["ratios"].items()))
    seeds = range(2 if args.quick else args.fit_seeds)
    print(
        f"\nGPLVM fit from the same PCA start, final NLL over seeds {list(seeds)} "
        f"(core: latentrl's NLL under GPy's optimiser call, {FIT_ITERS} evaluations)"
    )
    for name, (_, make) in CASES.items():
        fits = fit_over_seeds(make, seeds)
        cases[name]["fit_over_seeds"] = fits
        for row in fits:
            gpy = f"{row['gpy']:.2f} ({row['gpy_seconds']:.2f} s)" if "gpy" in row else "–"
            print(
                f"  {name} seed {row['seed']}: latentrl core {row['latentrl_core_gpy_budget']:.2f} "
                f"({row['latentrl_core_seconds']:.2f} s), GPLVM.fit {row['latentrl_GPLVM']:.2f} "
                f"({row['latentrl_GPLVM_seconds']:.2f} s), GPy {gpy}"
            )

    targets = {}
    for name, case in cases.items():
        r = case["ratios"]
        if "decode_one_gpy_over_predict_one" in r:
            targets[f"{name}: single-point decode ≥ 20× faster than GPy (predict_one)"] = (
                r["decode_one_gpy_over_predict_one"] >= 20
            )
            diffs = [f["latentrl_core_gpy_budget"] - f["gpy"] for f in case["fit_over_seeds"]]
            wins = sum(
                d <= 1e-6 * max(1.0, abs(f["gpy"])) for d, f in zip(diffs, case["fit_over_seeds"])
            )
            case["ratios"]["fit_nll_no_worse_than_gpy_seeds"] = wins
            case["ratios"]["fit_nll_median_diff_over_seeds"] = float(np.median(diffs))
            targets[
                f"{name}: fit NLL no worse than GPy's, same start and budget (median over {len(diffs)} seeds; "
                f"no worse in {wins})"
            ] = bool(np.median(diffs) <= 0)
    for name, case in cases.items():
        targets.update(issue19_goals(name, case))
    for target, ok in targets.items():
        print(f"{'PASS' if ok else 'MISS'}  {target}")

    payload = {
        "bench": "bench_gp",
        "machine": env,
        "blas_threads": args.blas_threads,
        "wall_time_s": time.perf_counter() - started,
        "cases": cases,
        "targets": targets,
    }
    write_json(args.out, payload)
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
