"""The L-BFGS fit of a GP's negative log marginal likelihood (paper Eq. 1, 3) on the native
objective and gradient: the GPLVM's, its sparse variant's and the GP encoder's, and the starting
hyper-parameters they share. SciPy loads at the first fit, not at `import latentrl`."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl._native import gplvm_nll_grad

#: The largest |log θ| a sparse fit evaluates: e^±700 is still a finite, non-zero float.
MAX_LOG_THETA = 700.0

#: The most inputs whose pairwise distances `initial_log_theta` takes the median of.
MEDIAN_SAMPLE = 4096


def initial_log_theta(
    inputs: NDArray[np.float64], centred: NDArray[np.float64]
) -> NDArray[np.float64]:
    """Starting log θ for a GP from `inputs` (N, q) to `centred` outputs (N, p): θ1 the mean
    output variance, θ2 the median squared distance between inputs (between `MEDIAN_SAMPLE`
    evenly spaced ones when N is larger: pdist of N points takes N²/2 floats), θ3 = θ1 / 100
    (1 where a scale is zero)."""
    from scipy.spatial.distance import pdist  # SciPy loads at a fit, not at `import latentrl`

    variance = float(np.mean(centred**2)) or 1.0
    sample = inputs[np.linspace(0, len(inputs) - 1, MEDIAN_SAMPLE).astype(np.intp)] if len(inputs) > MEDIAN_SAMPLE else inputs
    lengthscale_sq = float(np.median(pdist(sample, "sqeuclidean"))) or 1.0
    # Clamped at the smallest normal float: data of scale 1e-161 underflows θ3 to 0.
    return np.log(np.maximum([variance, lengthscale_sq, variance / 100], np.finfo(np.float64).tiny))


@dataclass(frozen=True)
class NllFit:
    """Result of `minimise_nll`."""

    latent: NDArray[np.float64]
    log_theta: NDArray[np.float64]
    nll: float
    n_iter: int
    converged: bool
    message: str
    jitter: float
    inducing: NDArray[np.float64] | None = None


def lbfgs(objective: Callable[[NDArray[np.float64]], tuple[float, NDArray[np.float64]]], x0: NDArray[np.float64],
          bounds: Sequence[tuple[float | None, float | None]], *, max_iter: int, tol: float, terms: int = 1) -> Any:
    """scipy's L-BFGS-B on `objective` (value and gradient), stopping when an iteration decreases
    the objective by less than `tol` × max(|objective|, `terms`) or the largest projected gradient
    component falls below `tol`, or after `max_iter` iterations: the one optimiser call of every
    likelihood fit here. `terms`, the number of terms the objective sums, is its scale where its
    value is near 0 (docs/method.md §Sparse GPLVM); scipy's own floor is 1."""
    from scipy.optimize import OptimizeResult, minimize

    last = {"fun": math.inf, "stopped": False}

    def per_term(intermediate_result: OptimizeResult) -> None:
        # Called at each new iterate before scipy's own test of it, so a stop here leaves the
        # iterate scipy's rule would have left, had its floor been `terms`.
        if last["fun"] - intermediate_result.fun <= tol * terms:
            last["stopped"] = True
            raise StopIteration
        last["fun"] = intermediate_result.fun

    res = minimize(objective, x0, jac=True, method="L-BFGS-B", bounds=bounds, callback=per_term if terms > 1 else None,
                   options={"maxiter": max_iter, "ftol": tol, "gtol": tol})
    if last["stopped"]:
        res.status, res.success = 0, True
        res.message = f"CONVERGENCE: REDUCTION_OF_F_<=_TOL*{terms}_TERMS"
    return res


def minimise_nll(
    latent: NDArray[np.float64],
    data: NDArray[np.float64],
    log_theta: NDArray[np.float64],
    *,
    fit_latent: bool,
    latent_prior: bool,
    noise_floor: float,
    max_iter: int,
    tol: float,
    inducing: NDArray[np.float64] | None = None,
) -> NllFit:
    """Minimises the GP negative log marginal likelihood (paper Eq. 1, 3) of centred `data`
    (N, D) given inputs `latent` (N, d) with L-BFGS-B and the analytic gradient: over
    `log θ`, and over the inputs too if `fit_latent` (the GPLVM). θ3 is bounded below by
    `noise_floor`; `latent_prior` adds ½‖Z‖². Stops when the relative decrease of the
    objective or the largest projected gradient falls below `tol`, or after `max_iter`
    iterations (then `converged` is False). With `inducing` (m, d) the objective is the sparse
    (DTC) bound through those inducing inputs (docs/method.md §Sparse GPLVM), optimised with the
    inputs if `fit_latent` (else held fixed), and its decrease is relative to max(|bound|, N·D)."""
    n, d = latent.shape
    # The points L-BFGS moves: the latent points, then the inducing inputs (the native
    # gradient's row order); the data term alone with fixed inputs.
    moved = np.vstack([latent, inducing]) if inducing is not None else latent

    def split(params: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        return (params[:-3].reshape(moved.shape) if fit_latent else moved), params[-3:]

    def evaluate(params: NDArray[np.float64]) -> tuple[float, NDArray[np.float64], NDArray[np.float64], float]:
        points, lt = split(params)
        if inducing is None:
            return gplvm_nll_grad(points, data, lt)
        return gplvm_nll_grad(points[:n], data, lt, inducing=points[n:])

    def objective(params: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        if inducing is not None and np.max(np.abs(params[-3:])) > MAX_LOG_THETA:
            # The sparse bound's gradient grows with N: on 100k frames L-BFGS-B's line search
            # tried log θ2 = −1254 (θ2 underflows to 0). A huge value makes it step back.
            return 1e300, np.zeros_like(params)
        nll, grad_points, grad_lt, _ = evaluate(params)
        grad = np.concatenate([grad_points.ravel(), grad_lt]) if fit_latent else grad_lt
        if latent_prior:
            z = split(params)[0][:n]
            nll += 0.5 * float(np.sum(z * z))
            if fit_latent:
                grad[: n * d] += z.ravel()
        return nll, grad

    floor = np.log(noise_floor)
    x0 = np.concatenate(
        [moved.ravel() if fit_latent else [], log_theta[:2], [max(log_theta[2], floor)]]
    )
    bounds = [(None, None)] * (x0.size - 1) + [(floor, None)]
    if inducing is None:
        res = lbfgs(objective, x0, bounds, max_iter=max_iter, tol=tol)
    else:
        # L-BFGS-B's vector operations call BLAS, which OpenBLAS splits over spinning threads from
        # ~10⁴ variables: on 200k variables (100k postures) and 2 busy cores that cost 30–50× the
        # optimiser's own work (measured), and the split's rounding changes with the thread count.
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            res = lbfgs(objective, x0, bounds, max_iter=max_iter, tol=tol, terms=data.size)
    points, lt = split(res.x)
    return NllFit(
        np.array(points[:n]),
        np.array(lt),
        float(res.fun),
        int(res.nit),
        res.status == 0,
        str(res.message),
        evaluate(res.x)[3],
        None if inducing is None else np.array(points[n:]),
    )
