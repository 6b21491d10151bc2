"""The sparse GPLVM (issue #40 item 3): the DTC bound through inducing inputs
(latent_core::sparse_gplvm) and its estimator, `GPLVM(inducing=m)`."""

from __future__ import annotations

import numpy as np
import pytest

from latentrl import _native


def _problem(n: int = 40) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rng = np.random.default_rng(0)
    latent = rng.standard_normal((n, 2))
    data = np.column_stack([np.sin(latent[:, 0]), latent[:, 1] ** 2, latent.sum(axis=1)])
    return latent, data - data.mean(axis=0), np.log([1.0, 1.5, 0.05])


def test_binding_at_the_latent_points_is_the_exact_objective() -> None:
    latent, data, log_theta = _problem()
    nll, grad, grad_theta, jitter = _native.gplvm_nll_grad(latent, data, log_theta, inducing=latent)
    exact, exact_z, exact_theta, _ = _native.gplvm_nll_grad(latent, data, log_theta)
    assert jitter == 0.0 and grad.shape == (2 * len(latent), 2)
    assert nll == pytest.approx(exact, rel=1e-8)
    # Latent points and inducing inputs moved together move the bound as the exact NLL.
    np.testing.assert_allclose(grad[: len(latent)] + grad[len(latent) :], exact_z, atol=1e-6)
    np.testing.assert_allclose(grad_theta, exact_theta, rtol=1e-6, atol=1e-8)


def test_binding_refuses_bad_inducing_inputs() -> None:
    latent, data, log_theta = _problem()
    with pytest.raises(_native.InvalidInputError, match="inducing inputs"):
        _native.gplvm_nll_grad(latent, data, log_theta, inducing=latent[:, :1])
    with pytest.raises(_native.InvalidInputError, match="inducing inputs"):
        _native.gplvm_nll_grad(latent, data, log_theta, inducing=np.full((3, 2), np.nan))
    with pytest.raises(_native.InvalidInputError, match="inducing is empty"):
        _native.GpMap(latent, data, np.exp(log_theta), inducing=np.zeros((0, 2)))
