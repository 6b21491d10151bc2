import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from latentrl import PCA, NotFittedError


def data(seed=0, n=30, dims=5):
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, dims)) @ rng.normal(size=(dims, dims)) + rng.normal(size=dims)


def test_matches_covariance_eigendecomposition():
    X = data()
    pca = PCA(n_components=3).fit(X)
    eigvals, eigvecs = np.linalg.eigh(np.cov(X, rowvar=False))
    order = np.argsort(eigvals)[::-1][:3]
    np.testing.assert_allclose(pca.explained_variance_, eigvals[order], rtol=1e-10)
    np.testing.assert_allclose(np.abs(pca.components_ @ eigvecs[:, order]), np.eye(3), atol=1e-8)
    np.testing.assert_allclose(pca.components_ @ pca.components_.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(pca.mean_, X.mean(axis=0))
    assert pca.explained_variance_ratio_.sum() < 1 and pca.n_features_in_ == 5
    largest = np.abs(pca.components_).argmax(axis=1)
    assert np.all(pca.components_[np.arange(3), largest] > 0)


@given(st.integers(0, 2**32 - 1), st.integers(3, 20), st.integers(2, 6))
def test_round_trip_is_the_orthogonal_projection(seed, n, dims):
    X = data(seed, n, dims)
    pca = PCA(n_components=2).fit(X)
    Z = pca.transform(X)
    np.testing.assert_allclose(Z, pca.fit_transform(X), atol=1e-12)
    residual = X - pca.inverse_transform(Z)
    np.testing.assert_allclose(residual @ pca.components_.T, 0.0, atol=1e-9 * (1 + np.abs(X).max()))


def test_exact_on_rank_two_data():
    rng = np.random.default_rng(1)
    X = rng.normal(size=(20, 2)) @ rng.normal(size=(2, 4)) + 3.0
    pca = PCA().fit(X)
    np.testing.assert_allclose(pca.inverse_transform(pca.transform(X)), X, atol=1e-12)
    np.testing.assert_allclose(pca.explained_variance_ratio_.sum(), 1.0)


def test_constant_data_fits():
    pca = PCA().fit(np.ones((5, 3)))
    np.testing.assert_array_equal(pca.explained_variance_ratio_, [0.0, 0.0])
    np.testing.assert_allclose(pca.transform(np.ones((2, 3))), 0.0)


@pytest.mark.parametrize(
    ("X", "params", "match"),
    [
        (np.ones((2, 3)), {}, "n_samples=2 must be greater than n_components=2"),
        (np.ones((5, 1)), {}, "n_features=1 must be at least n_components=2"),
        (np.ones((5, 3)), {"n_components": 0}, "n_components must be an int"),
        (np.ones((5, 3)), {"n_components": 1.5}, "n_components must be an int"),
        (np.array([[0.0, np.nan, 1.0]] * 4), {}, r"X: non-finite value NaN at index \(0, 1\)"),
        (np.array([[0.0, np.inf, 1.0]] * 4), {}, "X: non-finite value inf"),
        (np.ones(5), {}, "X: expected a 2-D array"),
    ],
)
def test_bad_fit_input(X, params, match):
    with pytest.raises(ValueError, match=match):
        PCA(**params).fit(X)


def test_bad_transform_input():
    pca = PCA().fit(data())
    with pytest.raises(ValueError, match="X has 4 features, but PCA is expecting 5 features"):
        pca.transform(np.ones((2, 4)))
    with pytest.raises(ValueError, match="Z: expected 2 columns"):
        pca.inverse_transform(np.ones((2, 3)))
    with pytest.raises(NotFittedError, match="not fitted"):
        PCA().transform(np.ones((2, 5)))
    assert issubclass(NotFittedError, ValueError) and issubclass(NotFittedError, AttributeError)


def test_params_repr_and_pickle():
    pca = PCA(n_components=3)
    assert pca.get_params() == {"n_components": 3} and repr(pca) == "PCA(n_components=3)"
    assert repr(PCA()) == "PCA()"
    assert pca.set_params(n_components=2) is pca and pca.n_components == 2
    with pytest.raises(ValueError, match="invalid parameter 'bogus'"):
        pca.set_params(bogus=1)
    fitted = pca.fit(data())
    clone = pickle.loads(pickle.dumps(fitted))
    np.testing.assert_array_equal(clone.transform(data(1)), fitted.transform(data(1)))


def test_save_load_round_trip(tmp_path):
    pca = PCA(n_components=3).fit(data())
    pca.save(tmp_path / "pca.npz")
    loaded = PCA.load(tmp_path / "pca.npz")
    assert loaded.get_params() == pca.get_params() and loaded.n_features_in_ == 5
    np.testing.assert_array_equal(loaded.transform(data(2)), pca.transform(data(2)))
    np.testing.assert_array_equal(
        loaded.inverse_transform(np.ones((2, 3))), pca.inverse_transform(np.ones((2, 3)))
    )
    with pytest.raises(NotFittedError):
        PCA().save(tmp_path / "unfitted.npz")
