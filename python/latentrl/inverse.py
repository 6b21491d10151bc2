"""The two inverse maps posture → latent point (paper Sec. III-B, docs/method.md §Encoding): the
out-of-sample GP encoder (the paper's choice) and the iterative projection that checks it."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.linalg import cho_factor, cho_solve
from scipy.optimize import minimize
from scipy.spatial.distance import cdist

from latentrl._nll_fit import initial_log_theta, minimise_nll
from latentrl._native import GpMap, NumericalError
from latentrl._reference import se_kernel

Array = NDArray[np.float64]


def fit_gp_encoder(
    postures: Array,
    latent: Array,
    *,
    noise_floor: float = 1e-6,
    max_iter: int = 1000,
    tol: float = 1e-6,
    inducing: Array | None = None,
) -> GpMap:
    """GP regression from `postures` (N, D) to their `latent` points (N, d), SE kernel plus
    noise, θ by maximising the marginal likelihood (L-BFGS-B over log θ, θ3 ≥ `noise_floor`).
    Its predictive mean is the encoder. With `inducing` postures (m, D), the sparse (DTC) GP
    through them: its bound gives θ, and the map is the sparse one."""
    centred = latent - latent.mean(axis=0)
    fit = minimise_nll(
        postures,
        centred,
        initial_log_theta(postures, centred),
        fit_latent=False,
        latent_prior=False,
        noise_floor=noise_floor,
        max_iter=max_iter,
        tol=tol,
        inducing=inducing,
    )
    return GpMap(postures, latent, np.exp(fit.log_theta), inducing=inducing)


class Projection:
    """Iterative projection: encodes `x` as `argmax_z log N(x | μ(z), σ²(z) I)` under the
    decoder fitted to (`latent`, `postures`) with `theta`, by L-BFGS started from the latent
    point of the nearest training posture (GPy's `infer_newX`). `jitter` is the decoder's.

    Two stages (ours): first the squared reconstruction error ½‖x − μ(z)‖², then the
    density from there. Started on the density directly, L-BFGS leaves the data at once:
    where σ² is tiny a small residual costs more than moving to where σ² is large. The
    search stays inside the bounding box of the latent points widened by `margin` of its
    extent per side, and the best of start and both stages (by density) is kept.

    `latentrl._native.Projection` is the same algorithm in Rust, the one the RL loop runs
    (`GPLVM.native_projection_`); this SciPy version is its independent reference
    (tests/test_inverse.py, docs/encoders.md)."""

    def __init__(
        self,
        latent: Array,
        postures: Array,
        theta: Array,
        jitter: float = 0.0,
        *,
        max_iter: int = 200,
        margin: float = 0.5,
    ):
        self.latent = latent
        self.postures = postures
        self.theta = theta
        self.max_iter = max_iter
        low, high = latent.min(axis=0), latent.max(axis=0)
        pad = margin * (high - low)
        self._bounds = list(zip(low - pad, high + pad))
        self._mean = postures.mean(axis=0)
        k = se_kernel(latent, latent, theta) + (theta[2] + jitter) * np.eye(len(latent))
        self._factor = cho_factor(k, lower=True)
        self._alpha = cho_solve(self._factor, postures - self._mean)

    def decode_with_gradient(self, z: Array) -> tuple[Array, Array, float, Array]:
        """Eq. 4 at `z` (d,): mean (D,), its Jacobian (D, d), variance, its gradient (d,)."""
        diff = z - self.latent
        k_star = se_kernel(z[None, :], self.latent, self.theta)[0]
        dk_star = -k_star[:, None] * diff / self.theta[1]
        solved = cho_solve(self._factor, k_star)
        mean = self._mean + k_star @ self._alpha
        variance = self.theta[0] + self.theta[2] - k_star @ solved
        return mean, self._alpha.T @ dk_star, np.float64(variance), -2.0 * solved @ dk_star

    def neg_log_density(self, z: Array, x: Array) -> tuple[float, Array]:
        """`−log N(x | μ(z), σ²(z) I)` and its gradient with respect to `z`."""
        mean, d_mean, variance, d_variance = self.decode_with_gradient(z)
        residual = x - mean
        sq = residual @ residual
        value = 0.5 * len(x) * np.log(2 * np.pi * variance) + 0.5 * sq / variance
        # ½D/σ² − ½sq/σ⁴ without forming σ⁴, which overflows a float for σ² > 1e154.
        grad = (0.5 / variance) * (len(x) - sq / variance) * d_variance - residual @ d_mean / variance
        return float(value), grad

    def reconstruction_error(self, z: Array, x: Array) -> tuple[float, Array]:
        """`½‖x − μ(z)‖²` and its gradient with respect to `z`."""
        mean, d_mean, _, _ = self.decode_with_gradient(z)
        residual = x - mean
        return 0.5 * float(residual @ residual), -residual @ d_mean

    def encode(self, X: Array) -> Array:
        """Latent points (M, d) of postures `X` (M, D); NumericalError if the search overflows
        float64 (postures of extreme scale, θ1 ≳ 1e150: found by fuzzing)."""
        starts = self.latent[cdist(X, self.postures, "sqeuclidean").argmin(axis=1)]
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            latent = [self._maximise(x, z0) for x, z0 in zip(X, starts)]
        result = np.array(latent).reshape(len(X), self.latent.shape[1])
        if not np.all(np.isfinite(result)):
            raise NumericalError("X: the projection encoder overflowed float64; rescale the postures")
        return result

    def _maximise(self, x: Array, z0: Array) -> Array:
        candidates = [z0]
        for objective in (self.reconstruction_error, self.neg_log_density):
            res = minimize(
                objective,
                candidates[-1],
                args=(x,),
                jac=True,
                method="L-BFGS-B",
                bounds=self._bounds,
                options={"maxiter": self.max_iter},
            )
            candidates.append(np.asarray(res.x))
        return min(candidates, key=lambda z: self.neg_log_density(z, x)[0])
