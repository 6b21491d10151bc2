"""The sparse GPLVM (issue #40 item 3): the DTC bound through inducing inputs
(latent_core::sparse_gplvm) and its estimator, `GPLVM(inducing=m)`."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

from latentrl import GPLVM, _native
from latentrl._nll_fit import minimise_nll


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


def test_gradient_holds_where_the_inducing_inputs_are_close() -> None:
    """At the start of a 1000-posture fit (64 inducing inputs by farthest-point sampling of the
    PCA start, K_mm's condition number ~1e12) the gradient's slope along itself is the bound's
    central difference. With A = L⁻¹ K_mn from an explicit L⁻¹ in the native kernel it was off by
    3e-4 (∂L/∂U 0.03 where it is 1e-5) and L-BFGS stopped after 4 iterations."""
    from latentrl._nll_fit import initial_log_theta
    from latentrl.pca import PCA
    from latentrl.recorded.sampling import farthest_points

    X = _arms(1000, 0)
    pca = PCA(2).fit(X)
    start, centred = pca.transform(X) / np.sqrt(pca.explained_variance_[0]), X - pca.mean_
    log_theta = initial_log_theta(start, centred)
    params = np.concatenate([start.ravel(), start[farthest_points(start, 64)].ravel(), log_theta])

    def bound(p: np.ndarray) -> tuple[float, np.ndarray]:
        nll, grad, grad_theta, _ = _native.gplvm_nll_grad(p[:2000].reshape(1000, 2), centred, p[-3:],
                                                          inducing=p[2000:-3].reshape(64, 2))
        return nll, np.concatenate([grad.ravel(), grad_theta])

    grad = bound(params)[1]
    step = -1e-4 * grad / np.linalg.norm(grad)
    central = (bound(params + step)[0] - bound(params - step)[0]) / 2
    assert central == pytest.approx(grad @ step, rel=2e-5)


def _arms(n: int, seed: int) -> np.ndarray:
    from latentrl.datasets import arm_postures

    return arm_postures(n, np.random.default_rng(seed))


def _held_out_rmse(model: GPLVM, held_out: np.ndarray) -> float:
    """Held-out reconstruction: decode the GP encoder's latent points of postures not fitted."""
    decoded = model.inverse_transform(model.transform(held_out, method="gp"))
    return float(np.sqrt(np.mean((decoded - held_out) ** 2)))


def test_m_equal_n_is_the_exact_gplvm() -> None:
    """At the exact fit's Z and θ, the bound with the inducing inputs at Z is its NLL (30 postures:
    K_mm, noise-free, factorises without jitter; with many close points it needs ~1e-10 θ1,
    which over θ3 = 1e-6 moves the bound by ~1e-5 relative)."""
    X = _arms(30, 0)
    exact = GPLVM(random_state=0).fit(X)
    centred = X - exact.mean_
    log_theta = np.log(exact.theta_)
    nll, _, _, jitter = _native.gplvm_nll_grad(exact.Z_, centred, log_theta, inducing=exact.Z_)
    assert jitter == 0.0 and nll == pytest.approx(exact.nll_, rel=1e-8)
    sparse = GPLVM(random_state=0, inducing=len(X)).fit(X)
    assert len(sparse.inducing_) == len(X) and sparse.inducing_index_.tolist() == list(range(len(X)))
    assert sparse.nll_ == pytest.approx(exact.nll_, rel=1e-2)
    assert exact.inducing_.shape == (0, 2) and exact.get_params()["inducing"] is None


@pytest.fixture(scope="module")
def fitted() -> tuple[np.ndarray, np.ndarray, GPLVM, GPLVM]:
    """150 postures and 200 held out; the exact GPLVM and the sparse one with m = 32."""
    X, held_out = _arms(150, 0), _arms(200, 1)
    return X, held_out, GPLVM(random_state=0).fit(X), GPLVM(random_state=0, inducing=32).fit(X)


def test_sparse_reconstructs_held_out_postures_about_as_well(fitted: tuple[np.ndarray, np.ndarray, GPLVM, GPLVM]) -> None:
    """The held-out error within 1.5× the exact GPLVM's (measured: 1.7e-3 against 2.0e-3; m = 24
    gives 2.3×). The 2000-posture, m = 64 comparison is the slow test below."""
    _, held_out, exact, sparse = fitted
    assert _held_out_rmse(sparse, held_out) <= 1.5 * _held_out_rmse(exact, held_out)
    assert sparse.decoder_.input_dim == 2 and sparse.inducing_.shape == (32, 2)
    assert sparse.inducing_index_.shape == (32,) and sparse.get_params()["inducing"] == 32


@pytest.mark.slow
@pytest.mark.timeout(7200)
def test_sparse_on_2000_postures_within_1_5x_of_exact() -> None:
    """The issue's criterion (docs/method.md §Sparse GPLVM has the measured errors and times;
    `pytest -s` prints them). The exact fit of 2000 postures alone outlasts the default 600 s
    timeout on a shared machine (it did: 111 s of CPU in 600 s at load 9; 1233 s measured)."""
    X, held_out = _arms(2000, 0), _arms(500, 1)
    exact = _held_out_rmse(GPLVM(random_state=0, tol=1e-4).fit(X), held_out)
    sparse = _held_out_rmse(GPLVM(random_state=0, tol=1e-4, inducing=64).fit(X), held_out)
    print(f"held-out RMSE: sparse (m = 64) {sparse:.3g}, exact {exact:.3g}")
    assert sparse <= 1.5 * exact, (sparse, exact)


def test_save_load_and_pickle_round_trip(tmp_path: Path, fitted: tuple[np.ndarray, np.ndarray, GPLVM, GPLVM]) -> None:
    X, _, _, model = fitted
    path = tmp_path / "sparse.npz"
    model.save(path)
    Z = model.transform(X[:20])
    for loaded in (GPLVM.load(path), pickle.loads(pickle.dumps(model))):
        assert loaded.get_params() == model.get_params() and loaded.inducing == 32
        np.testing.assert_array_equal(loaded.inducing_, model.inducing_)
        np.testing.assert_array_equal(loaded.inducing_index_, model.inducing_index_)
        np.testing.assert_array_equal(loaded.transform(X[:20]), Z)
        np.testing.assert_array_equal(loaded.transform(X[:5], method="projection"), model.transform(X[:5], method="projection"))
        np.testing.assert_array_equal(loaded.inverse_transform(Z, return_variance=True)[1],
                                      model.inverse_transform(Z, return_variance=True)[1])
        assert loaded.set_params(encoder="tracking").loop_encoder_ is not None


@pytest.mark.parametrize("bad", [0, -3, 151, 2.5, True, "8"])
def test_bad_inducing_is_refused(bad: object) -> None:
    with pytest.raises(ValueError, match="inducing must be None .* 1 <= m <= the number of postures \\(150\\)"):
        GPLVM(inducing=bad).fit(_arms(150, 0))  # type: ignore[arg-type]


def test_back_constraint_is_exact_only() -> None:
    with pytest.raises(ValueError, match="inducing: the back-constrained GPLVM is fitted exactly"):
        GPLVM(inducing=8, encoder="back_constrained").fit(_arms(40, 0))


def test_too_many_postures_name_the_ways_out() -> None:
    X = np.random.default_rng(0).standard_normal((_native.MAX_GP_POINTS + 1, 3))
    with pytest.raises(ValueError, match="inducing=M .*--max-postures"):
        GPLVM().fit(X)


@pytest.mark.parametrize("postures", ["arms", "trajectories"])
def test_second_stage_starts_from_the_lower_bound(postures: str) -> None:
    """The second stage's start keeps the first stage's points and is the lower of two starts:
    the first stage's GP encoder (on postures of a smooth 2-D manifold) or each posture's nearest
    first-stage posture (on recorded trajectories, docs/demos.md)."""
    from latentrl._nll_fit import initial_log_theta
    from latentrl.gplvm import second_stage_start
    from latentrl.inverse import fit_gp_encoder
    from latentrl.pca import PCA
    from recorded_writers import arm_episodes

    X = _arms(600, 0) if postures == "arms" else np.concatenate(arm_episodes(600, per_episode=100))
    pca = PCA(2).fit(X)
    start, centred = pca.transform(X) / np.sqrt(pca.explained_variance_[0]), X - pca.mean_
    rows, chosen = np.arange(0, 600, 3), np.arange(0, 600, 30)
    options = {"noise_floor": 1e-6, "max_iter": 50, "tol": 1e-6}
    first = minimise_nll(start[rows], centred[rows], initial_log_theta(start, centred), fit_latent=True,
                         latent_prior=False, inducing=start[chosen], **options)
    latent = second_stage_start(first, centred, rows, chosen, options)
    np.testing.assert_array_equal(latent[rows], first.latent)
    encoded = fit_gp_encoder(centred[rows], first.latent, inducing=centred[chosen], **options).predict_mean(centred)
    encoded[rows] = first.latent

    def bound(z: np.ndarray) -> float:
        return float(_native.gplvm_nll_grad(z, centred, first.log_theta, inducing=first.inducing)[0])

    assert bound(latent) <= bound(encoded)


def test_a_sparse_fit_stops_on_the_decrease_per_term() -> None:
    """With `terms`, L-BFGS-B stops once an iteration decreases the objective by at most
    tol × terms, where scipy's relative test (near an optimum at 0) asks almost nothing; up to
    that iteration its iterates are scipy's own (docs/method.md §Sparse GPLVM)."""
    from latentrl._nll_fit import lbfgs

    def objective(x: np.ndarray) -> tuple[float, np.ndarray]:
        return float(np.sum(np.cosh(x) - 1.0)), np.sinh(x)  # its minimum, 0, at x = 0

    x0, bounds = np.linspace(1.0, 3.0, 50), [(None, None)] * 50
    plain = lbfgs(objective, x0, bounds, max_iter=1000, tol=1e-6)
    per_term = lbfgs(objective, x0, bounds, max_iter=1000, tol=1e-6, terms=100_000)
    assert per_term.success and per_term.status == 0 and "TERMS" in per_term.message
    assert per_term.nit < plain.nit and per_term.fun > plain.fun
    capped = lbfgs(objective, x0, bounds, max_iter=per_term.nit, tol=1e-6)
    np.testing.assert_array_equal(capped.x, per_term.x)
