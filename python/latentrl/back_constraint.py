"""Fitting the back-constrained GPLVM (Lawrence & Quiñonero-Candela 2006): the latent points
are `Z = K_b W`, an RBF kernel regression on the postures, and L-BFGS-B minimises the GPLVM
NLL over the weights W, log θ and the back-constraint's squared length-scale log β together,
with the analytic gradient of the Rust core (`latent_core::back_constraint`)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.distance import pdist, squareform

from latentrl._nll_fit import lbfgs
from latentrl._native import gplvm_back_constrained_nll_grad

#: Ridge on K_b when the starting weights are solved from the starting latent points.
START_RIDGE = 1e-6

#: log β stays within this many e-folds of its start (the median squared distance between
#: postures): far below, K_b is the identity in float64; far above, all ones.
LOG_BETA_RANGE = 12.0


@dataclass(frozen=True)
class BackConstrainedFit:
    """Result of `minimise_back_constrained`."""

    weights: NDArray[np.float64]
    log_beta: float
    latent: NDArray[np.float64]
    log_theta: NDArray[np.float64]
    nll: float
    n_iter: int
    converged: bool
    message: str
    jitter: float


def start_weights(start: NDArray[np.float64], centred: NDArray[np.float64], log_beta: float) -> NDArray[np.float64]:
    """Weights W (N, d) whose latent points K_b W come closest to `start` (a ridge solve)."""
    kb = np.exp(-0.5 * squareform(pdist(centred, "sqeuclidean")) / np.exp(log_beta))
    return np.linalg.solve(kb + START_RIDGE * np.eye(len(kb)), start)


def minimise_back_constrained(
    start: NDArray[np.float64],
    centred: NDArray[np.float64],
    log_theta: NDArray[np.float64],
    *,
    noise_floor: float,
    max_iter: int,
    tol: float,
) -> BackConstrainedFit:
    """Fits W, log θ and log β to centred postures (N, D) from latent start points (N, d): β
    starts at the median squared distance between postures (and stays within `LOG_BETA_RANGE`
    e-folds of it), W at the ridge solve of `start`. θ3 is bounded below by `noise_floor`; stops
    as `minimise_nll` does."""
    n, d = start.shape
    log_beta = float(np.log(np.median(pdist(centred, "sqeuclidean")) or 1.0))
    weights = start_weights(start, centred, log_beta)

    def objective(params: NDArray[np.float64]) -> tuple[float, NDArray[np.float64]]:
        w, lt, lb = params[: n * d].reshape(n, d), params[n * d: n * d + 3], float(params[-1])
        nll, grad_w, grad_lt, grad_lb, _, _ = gplvm_back_constrained_nll_grad(w, centred, lt, lb)
        return nll, np.concatenate([grad_w.ravel(), grad_lt, [grad_lb]])

    floor = np.log(noise_floor)
    x0 = np.concatenate([weights.ravel(), log_theta[:2], [max(log_theta[2], floor)], [log_beta]])
    bounds = [(None, None)] * (n * d + 2) + [(floor, None), (log_beta - LOG_BETA_RANGE, log_beta + LOG_BETA_RANGE)]
    res = lbfgs(objective, x0, bounds, max_iter=max_iter, tol=tol)
    w, lt, lb = res.x[: n * d].reshape(n, d), res.x[n * d: n * d + 3], float(res.x[-1])
    _, _, _, _, latent, _ = gplvm_back_constrained_nll_grad(w, centred, lt, lb)
    # The NLL depends on Z only through ‖z_i − z_j‖² / θ2: scale Z (by its weights) to unit
    # standard deviation on its widest axis, θ2 with it, as the PCA start is scaled.
    scale = 1.0 / (float(np.max(np.std(latent, axis=0))) or 1.0)
    w, lt = w * scale, lt + np.array([0.0, 2.0 * np.log(scale), 0.0])
    _, _, _, _, latent, jitter = gplvm_back_constrained_nll_grad(w, centred, lt, lb)
    return BackConstrainedFit(np.array(w), lb, latent, np.array(lt), float(res.fun), int(res.nit),
                              res.status == 0, str(res.message), jitter)
