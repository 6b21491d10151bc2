import pickle

import numpy as np
import pytest

from latentrl import GPLVM, PCA, NotFittedError
from latentrl._nll_fit import initial_log_theta, minimise_nll
from latentrl._persistence import FORMAT_VERSION
from latentrl._native import gplvm_nll_grad


def manifold(n=40, noise=0.01, seed=0):
    """Postures on a curved 2-D manifold in 5-D, plus Gaussian noise."""
    rng = np.random.default_rng(seed)
    t = rng.uniform(-1, 1, size=(n, 2))
    X = np.column_stack(
        [t[:, 0], t[:, 1], np.sin(2 * t[:, 0]), np.cos(2 * t[:, 1]), t[:, 0] * t[:, 1]]
    )
    return X + noise * rng.normal(size=X.shape)


@pytest.fixture(scope="module")
def X():
    return manifold()


@pytest.fixture(scope="module")
def model(X):
    return GPLVM().fit(X)


def test_fit_lowers_the_nll_from_the_pca_start(X, model):
    pca = PCA().fit(X)
    start = pca.transform(X) / np.sqrt(pca.explained_variance_[0])
    centred = X - X.mean(axis=0)
    log_theta = initial_log_theta(start, centred)
    at_start = gplvm_nll_grad(start, centred, log_theta)[0]
    # Best θ for the PCA latent points: moving Z as well must do better still.
    theta_only = minimise_nll(
        start,
        centred,
        log_theta,
        fit_latent=False,
        latent_prior=False,
        noise_floor=1e-6,
        max_iter=1000,
        tol=1e-9,
    )
    assert model.nll_ < theta_only.nll - 10 < at_start - 10
    assert model.converged_ and model.n_iter_ > 0 and "CONVERGENCE" in model.stop_reason_
    assert model.log_likelihood_ == -model.nll_


def test_fitted_state_is_consistent(X, model):
    np.testing.assert_array_equal(model.mean_, X.mean(axis=0))
    assert model.Z_.shape == (40, 2) and model.theta_.shape == (3,) and model.n_features_in_ == 5
    nll = gplvm_nll_grad(model.Z_, X - model.mean_, np.log(model.theta_))[0]
    assert model.nll_ == pytest.approx(nll, rel=1e-12)
    assert model.theta_[2] >= 1e-6 and model.jitter_ == model.decoder_.jitter == 0.0
    assert model.decoder_.theta == pytest.approx(list(model.theta_), rel=1e-15)


def test_reconstructs_training_postures(X, model):
    error = np.abs(model.inverse_transform(model.Z_) - X)
    # noise s.d. 0.01 on data of s.d. ~0.6: the GP mean smooths a little of the noise away
    assert error.max() < 0.05 and np.sqrt(np.mean(error**2)) < 0.015


def test_variance_low_near_data_high_far_away(model):
    prior = model.theta_[0] + model.theta_[2]
    at_data = model.predict_variance(model.Z_)
    lengthscale = np.sqrt(model.theta_[1])
    far = model.predict_variance(
        model.Z_.max(axis=0) + lengthscale * np.array([[3.0, 0.0], [0.0, 3.0], [30.0, 30.0]])
    )
    assert at_data.max() < 1e-3 * prior
    assert at_data.max() < far[0] < far[2] and at_data.max() < far[1]
    assert far[:2].min() > 0.1 * prior
    np.testing.assert_allclose(far[2], prior, rtol=1e-12)


def test_exact_data_stops_at_the_noise_floor_or_the_cap():
    X = manifold(noise=0.0)
    model = GPLVM(noise_floor=1e-5).fit(X)
    assert model.theta_[2] == pytest.approx(1e-5, rel=1e-9)
    assert np.abs(model.inverse_transform(model.Z_) - X).max() < 1e-2
    capped = GPLVM(max_iter=5).fit(X)
    assert not capped.converged_ and capped.n_iter_ == 5 and "ITERATIONS" in capped.stop_reason_


def test_duplicate_postures_still_fit():
    X = np.repeat(manifold(n=15), 3, axis=0)
    model = GPLVM().fit(X)
    assert np.isfinite(model.nll_) and model.theta_[2] >= 1e-6 and model.jitter_ >= 0
    decoded = model.inverse_transform(model.Z_)
    np.testing.assert_allclose(decoded[0::3], decoded[1::3], atol=1e-3)
    assert np.abs(decoded - X).max() < 0.05


def test_restarts_are_deterministic_and_keep_the_best(X, model):
    a = GPLVM(n_restarts=2, random_state=3).fit(X)
    b = GPLVM(n_restarts=2, random_state=3).fit(X)
    np.testing.assert_array_equal(a.Z_, b.Z_)
    assert a.nll_ == b.nll_ <= model.nll_  # the unperturbed PCA start is among the restarts


def test_latent_prior_adds_half_squared_norm(X):
    model = GPLVM(latent_prior=True).fit(X)
    nll = gplvm_nll_grad(model.Z_, X - model.mean_, np.log(model.theta_))[0]
    assert model.nll_ == pytest.approx(nll + 0.5 * np.sum(model.Z_**2), rel=1e-12)
    # The prior pulls the latent points towards the origin.
    assert np.sum(model.Z_**2) < np.sum(GPLVM().fit(X).Z_ ** 2)


def test_transform_encodes_training_postures_near_their_latent_points(X, model):
    scale = model.Z_.std()
    for method in ("gp", "projection"):
        assert np.abs(model.transform(X, method=method) - model.Z_).max() < 0.05 * scale
    np.testing.assert_array_equal(model.transform(X), model.transform(X, method="gp"))
    np.testing.assert_array_equal(
        GPLVM(encoder="projection").fit(X).transform(X[:3]),
        model.transform(X[:3], method="projection"),
    )
    np.testing.assert_array_equal(GPLVM().fit_transform(X), model.Z_)


def test_save_load_round_trip(tmp_path, X, model):
    model.save(tmp_path / "model.npz")
    loaded = GPLVM.load(tmp_path / "model.npz")
    assert loaded.get_params() == model.get_params()
    for name in GPLVM._saved:
        np.testing.assert_array_equal(getattr(loaded, name), getattr(model, name))
    Z = np.random.default_rng(0).normal(size=(7, 2))
    np.testing.assert_array_equal(loaded.inverse_transform(Z), model.inverse_transform(Z))
    np.testing.assert_array_equal(loaded.predict_variance(Z), model.predict_variance(Z))
    for method in ("gp", "projection"):
        np.testing.assert_array_equal(
            loaded.transform(X[:5], method=method), model.transform(X[:5], method=method)
        )
    clone = pickle.loads(pickle.dumps(model))
    np.testing.assert_array_equal(clone.inverse_transform(Z), model.inverse_transform(Z))


def _rewrite(path, **changes):
    with np.load(path) as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays.update(changes)
    for key, value in changes.items():
        if value is None:
            del arrays[key]
    np.savez(path, **arrays)


def test_load_rejects_bad_files(tmp_path, model):
    good = tmp_path / "good.npz"
    model.save(good)
    raw = good.read_bytes()
    cases = {
        "truncated.npz": (raw[: len(raw) // 2], "not a readable NPZ file"),
        "text.npz": (b"hello, world\n", "not a readable NPZ file"),
        "flipped.npz": (
            raw[:200] + bytes(b ^ 0xFF for b in raw[200:260]) + raw[260:],
            "not a readable NPZ file",
        ),
    }
    for name, (content, match) in cases.items():
        (tmp_path / name).write_bytes(content)
        with pytest.raises(ValueError, match=match):
            GPLVM.load(tmp_path / name)
    np.save(tmp_path / "single.npy", np.ones(3))
    with pytest.raises(ValueError, match="single array"):
        GPLVM.load(tmp_path / "single.npy")
    PCA().fit(manifold()).save(tmp_path / "pca.npz")
    with pytest.raises(ValueError, match=r"holds latentrl\.PCA, expected latentrl\.GPLVM"):
        GPLVM.load(tmp_path / "pca.npz")
    mutations = [
        ({"format_version": np.array(FORMAT_VERSION + 1)}, "format_version 2 \\(int64\\) is not supported"),
        ({"Z_": None}, "missing fitted attribute 'Z_'"),
        ({"Z_": model.Z_[:-1]}, "Z_: axis N has size 39, expected 40"),
        ({"theta_": np.ones(4)}, "theta_: axis 3 has size 4"),
        ({"mean_": model.mean_[:3]}, "mean_: axis D has size 3, expected 5"),
        ({"converged_": np.array(1.0)}, "converged_: expected a 0-D array of kind 'b'"),
        ({"params": np.array('{"bogus": 1}')}, "unexpected keyword argument 'bogus'"),
    ]
    for changes, match in mutations:
        path = tmp_path / "mutated.npz"
        path.write_bytes(raw)
        _rewrite(path, **changes)
        with pytest.raises(ValueError, match=match):
            GPLVM.load(path)
    with pytest.raises(FileNotFoundError):
        GPLVM.load(tmp_path / "absent.npz")


@pytest.mark.parametrize(
    ("X", "params", "match"),
    [
        (np.ones((2, 3)), {}, "n_samples=2 must be greater than n_components=2"),
        (np.ones((5, 1)), {}, "n_features=1 must be at least n_components=2"),
        (np.array([[0.0, np.nan, 1.0]] * 4), {}, r"X: non-finite value NaN at index \(0, 1\)"),
        (np.array([[0.0, 1.0, -np.inf]] * 4), {}, "X: non-finite value -inf"),
        (manifold(), {"max_iter": 0}, "max_iter must be an int >= 1"),
        (manifold(), {"n_restarts": -1}, "n_restarts must be an int >= 0"),
        (manifold(), {"noise_floor": 0.0}, "noise_floor must be a finite number > 0"),
        (manifold(), {"tol": float("nan")}, "tol must be a finite number > 0"),
        (manifold(), {"encoder": "nearest"}, "encoder method must be one of"),
    ],
)
def test_bad_fit_input(X, params, match):
    with pytest.raises(ValueError, match=match):
        GPLVM(**params).fit(X)


def test_bad_use_after_fit(model):
    with pytest.raises(ValueError, match="X has 4 features, but GPLVM is expecting 5 features"):
        model.transform(np.ones((2, 4)))
    with pytest.raises(ValueError, match="Z: expected 2 columns"):
        model.inverse_transform(np.ones((2, 3)))
    with pytest.raises(ValueError, match=r"Z: non-finite value NaN at index \(1, 0\)"):
        model.predict_variance(np.array([[0.0, 0.0], [np.nan, 0.0]]))
    with pytest.raises(ValueError, match="encoder method must be one of"):
        model.transform(np.ones((2, 5)), method="pca")
    with pytest.raises(NotFittedError, match="GPLVM is not fitted"):
        GPLVM().inverse_transform(np.ones((1, 2)))


def test_params_and_repr():
    model = GPLVM(max_iter=50, random_state=1)
    assert repr(model) == "GPLVM(max_iter=50, random_state=1)"
    assert set(model.get_params()) == {
        "n_components",
        "max_iter",
        "noise_floor",
        "latent_prior",
        "n_restarts",
        "random_state",
        "encoder",
        "tol",
        "max_components",
        "relevance_threshold",
        "inducing",
        "spacing",
    }


def test_inverse_transform_returns_the_variance_from_the_same_call(X, model):
    Z = model.Z_[:5] + 0.1
    mean, variance = model.inverse_transform(Z, return_variance=True)
    np.testing.assert_array_equal(mean, model.inverse_transform(Z))
    np.testing.assert_array_equal(variance, model.predict_variance(Z))
    assert variance.shape == (5,) and np.all(variance > model.theta_[2] * 0.999)  # ≥ the noise θ3
