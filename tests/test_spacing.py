"""GPLVM(spacing="even"): latent points evenly spaced along each axis, θ refitted (latentrl.spacing)."""

import numpy as np
import pytest
from scipy.spatial import cKDTree

from latentrl import GPLVM
from latentrl._native import gplvm_nll_grad
from latentrl.spacing import even_ranks
from latentrl.run_settings import TrainPreset


def clustered(seed: int = 0) -> np.ndarray:
    """Postures of a 1-D curve in 4-D, 30 of 40 of them packed in a tenth of its length."""
    rng = np.random.default_rng(seed)
    t = np.concatenate([rng.uniform(0.0, 0.1, 30), rng.uniform(0.1, 1.0, 10)])
    return np.column_stack([np.cos(3 * t), np.sin(3 * t), t, t**2]) + 0.001 * rng.normal(size=(40, 4))


def spread(Z: np.ndarray) -> float:
    """95th over 5th percentile of the nearest-neighbour distances."""
    d = cKDTree(Z).query(Z, k=2)[0][:, 1]
    return float(np.percentile(d, 95) / np.percentile(d, 5))


def test_even_ranks_keeps_order_and_range_and_spaces_evenly():
    rng = np.random.default_rng(1)
    Z = rng.standard_normal((50, 2)) ** 3  # heavy tails: far from evenly spaced
    moved = even_ranks(Z, Z)
    for j in range(2):
        order = np.argsort(Z[:, j])
        assert np.array_equal(np.argsort(moved[:, j]), order)
        assert moved[:, j].min() == Z[:, j].min() and moved[:, j].max() == Z[:, j].max()
        gaps = np.diff(moved[order, j])
        np.testing.assert_allclose(gaps, np.ptp(Z[:, j]) / 49, rtol=1e-9)
    # Other points move by the same increasing map: between two latent points, between their images.
    first = np.argsort(Z[:, 0])
    mid = (Z[first[10]] + Z[first[11]]) / 2
    inside = even_ranks(Z, mid[None, :])[0, 0]
    assert moved[first[10], 0] < inside < moved[first[11], 0]


def test_even_spacing_undoes_the_fits_cluster_and_refits_theta():
    X = clustered()
    fit = GPLVM(n_components=1, random_state=0, max_iter=3000).fit(X)
    even = GPLVM(n_components=1, random_state=0, max_iter=3000, spacing="even").fit(X)
    assert even.converged_ and even.n_iter_ > fit.n_iter_
    assert spread(even.Z_) < spread(fit.Z_) / 3
    np.testing.assert_allclose(np.sort(even.Z_[:, 0]), np.linspace(fit.Z_.min(), fit.Z_.max(), 40), atol=1e-12)
    # θ is a stationary point of the NLL with the moved points fixed (θ3 above its floor).
    centred = X - X.mean(axis=0)
    grad_theta = gplvm_nll_grad(even.Z_, centred, np.log(even.theta_))[2]
    assert np.abs(grad_theta).max() < 1e-3 * abs(even.nll_)
    # A smoother map through the same demonstrations, not another map: it passes near each
    # (the sparse end of the curve, compressed, costs most; measured 9 % of the spread here).
    assert np.sqrt(np.mean((even.inverse_transform(even.Z_) - X) ** 2)) < 0.15 * X.std()


def test_even_spacing_saves_and_loads(tmp_path):
    model = GPLVM(n_components=1, random_state=0, spacing="even").fit(clustered())
    model.save(tmp_path / "m.npz")
    back = GPLVM.load(tmp_path / "m.npz")
    assert back.spacing == "even" and np.array_equal(back.Z_, model.Z_)


def test_sparse_even_spacing_moves_inducing_inputs_by_the_same_map():
    X = clustered()
    fit = GPLVM(n_components=1, random_state=0, inducing=8).fit(X)
    even = GPLVM(n_components=1, random_state=0, inducing=8, spacing="even").fit(X)
    np.testing.assert_allclose(even.Z_, even_ranks(fit.Z_, fit.Z_))
    np.testing.assert_allclose(even.inducing_, even_ranks(fit.Z_, fit.inducing_))


@pytest.mark.parametrize("inducing", [None, 8])
def test_spacing_a_fit_evenly_equals_fitting_it_evenly(inducing):
    """`evenly_spaced` reuses this process's fit of the latent points: the same bits as a fresh
    `spacing="even"` fit, and as one from a model whose fit it cannot reuse (loaded, re-parametrised)."""
    X = clustered()
    params = {"n_components": 1, "random_state": 0, "inducing": inducing}
    fresh = GPLVM(**params, spacing="even").fit(X)
    fit = GPLVM(**params).fit(X)
    stale = GPLVM(**params, max_iter=5).fit(X).set_params(max_iter=fit.max_iter)  # its fit is not this one's
    for model in (fit.evenly_spaced(), stale.evenly_spaced()):
        assert model.spacing == "even" and model.n_iter_ == fresh.n_iter_
        for name in ("Z_", "theta_", "inducing_", "encoder_theta_", "nll_"):
            assert np.array_equal(getattr(model, name), getattr(fresh, name)), name
    assert fit.spacing == "fit"  # the fit itself is kept
    with pytest.raises(ValueError, match="spacing is already 'even'"):
        fresh.evenly_spaced()


@pytest.mark.parametrize(("params", "message"), [
    ({"spacing": "uniform"}, "spacing must be one of 'fit', 'even', got 'uniform'"),
    ({"spacing": "even", "encoder": "back_constrained"}, "back-constrained latent points are a function of X"),
])
def test_bad_spacing_is_refused_before_the_fit(params, message):
    with pytest.raises(ValueError, match=message):
        GPLVM(n_components=1, **params).fit(clustered())


def test_the_run_setting_refuses_even_spacing_with_the_back_constraint():
    TrainPreset().validate()
    TrainPreset(encoder="back_constrained").validate()  # "auto" keeps the back-constrained points
    with pytest.raises(ValueError, match='run.latent_spacing "even" moves the latent points'):
        TrainPreset(encoder="back_constrained", latent_spacing="even").validate()
    with pytest.raises(ValueError, match="latent_spacing: unknown variant `ranks`"):
        TrainPreset(latent_spacing="ranks").validate()


def test_the_check_names_an_evenly_spaced_fit_without_claiming_why():
    from types import SimpleNamespace

    from latentrl.check import fit_finding

    even = fit_finding(SimpleNamespace(converged_=True, n_iter_=7, spacing="even"))
    assert even.verdict == "ok" and even.message.endswith("evenly spaced along each axis (spacing='even')")
    assert "evenly" not in fit_finding(SimpleNamespace(converged_=True, n_iter_=7, spacing="fit")).message
