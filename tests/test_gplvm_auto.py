"""GPLVM(n_components="auto") (issue #19): the latent dimension chosen by automatic relevance
of the principal latent axes of a wider fit; the evidence kept in `relevance_`."""

import numpy as np
import pytest

from latentrl import GPLVM


def manifold(d, seed, n=80, joints=8):
    """`n` uniform points of a d-dimensional cube through a random tanh network into `joints`."""
    rng = np.random.default_rng(seed)
    t = rng.uniform(-1, 1, (n, d))
    hidden = rng.standard_normal((d, 12))
    out = rng.standard_normal((12, joints)) / np.sqrt(12)
    return np.tanh(1.5 * t @ hidden) @ out + 0.01 * rng.standard_normal((n, joints))


@pytest.mark.parametrize("d", [1, 2, 3])
def test_auto_finds_the_dimension_of_a_curve_a_sheet_and_a_solid(d):
    model = GPLVM(n_components="auto", max_components=4, random_state=0).fit(manifold(d, seed=4))
    assert model.n_components_ == d and model.Z_.shape == (80, d)
    rel = model.relevance_ / model.relevance_[0]
    assert rel.shape == (4,) and np.all(np.diff(rel) <= 0)
    assert np.all(rel[:d] >= 0.1) and np.all(rel[d:] < 0.1)


def test_the_chosen_model_is_the_fit_with_that_dimension():
    X = manifold(2, seed=4)
    auto = GPLVM(n_components="auto", max_components=4, random_state=0).fit(X)
    fixed = GPLVM(n_components=2, max_components=4, random_state=0).fit(X)
    np.testing.assert_array_equal(auto.Z_, fixed.Z_)
    np.testing.assert_array_equal(auto.theta_, fixed.theta_)


def test_relevance_is_the_ard_length_scale_of_the_principal_axes():
    """Independent of the latent points' rotation: the eigenvalues of their covariance / θ2."""
    model = GPLVM(n_components=3, random_state=0).fit(manifold(3, seed=5))
    angle = 0.7
    rotation = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
    rotated = model.Z_ @ rotation.T
    expected = np.sort(np.var(rotated @ np.linalg.eigh(np.cov(rotated.T))[1], axis=0, ddof=1))[::-1] / model.theta_[1]
    np.testing.assert_allclose(model.relevance_, expected, rtol=1e-10)


def test_auto_models_save_and_load_with_their_evidence(tmp_path):
    model = GPLVM(n_components="auto", max_components=4, random_state=0).fit(manifold(1, seed=4))
    model.save(tmp_path / "m.npz")
    loaded = GPLVM.load(tmp_path / "m.npz")
    assert loaded.n_components_ == 1
    np.testing.assert_array_equal(loaded.relevance_, model.relevance_)
    np.testing.assert_array_equal(loaded.transform(model.X_train_[:5]), model.transform(model.X_train_[:5]))


@pytest.mark.parametrize("params, n, says", [
    ({"n_components": "auto"}, 2, "n_components='auto' needs at least 3 postures"),
    ({"n_components": "auto", "max_components": 8}, 80, "max_components must be less than the number of joints (8)"),
    ({"n_components": "auto", "max_components": 0}, 80, "max_components must be an int >= 1"),
    ({"n_components": "auto", "relevance_threshold": 2.0}, 80, "relevance_threshold must be in (0, 1]"),
    ({"n_components": "three"}, 80, "n_components must be an int >= 1 or 'auto', got 'three'"),
])
def test_bad_auto_settings_name_the_argument(params, n, says):
    with pytest.raises(ValueError, match=None) as err:
        GPLVM(**params).fit(manifold(2, seed=4, n=n))
    assert says in str(err.value)
