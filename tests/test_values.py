"""V across languages (issue #22): the value function the figures and `LatentPolicy.value` show is
the Rust learner's own (its sparse RBF features, its grid order), checked against the plain-NumPy
reference at random latent points after real training, in 1-D, 2-D and 3-D latent spaces."""

import numpy as np
import pytest

from latentrl import GPLVM, _native, _reference
from latentrl.datasets import arm_postures
from latentrl import train_latent_policy


@pytest.fixture(scope="module", params=[1, 2, 3], ids=["d1", "d2", "d3"])
def trained(request):
    model = GPLVM(n_components=request.param, max_iter=40, random_state=0).fit(arm_postures(40, np.random.default_rng(2)))
    overrides = {"episode.max_steps": 40, "learner.rbf_per_dim": 8}
    return train_latent_policy(model, trials=1, episodes=12, test_episodes=0, overrides=overrides)


def test_trained_values_match_the_reference_at_random_points(trained):
    w, low, high = trained.weights[0], trained.latent_low, trained.latent_high
    assert np.ptp(w) > 0, "training moved the weights"
    points = np.random.default_rng(0).uniform(low, high, size=(200, len(low)))
    learner = trained.task.to_dict()["learner"]
    reference = _reference.value_function(w, low, high, points, width=learner["rbf_width"], cutoff=learner["rbf_cutoff"])
    np.testing.assert_allclose(trained.value(points), reference, rtol=1e-12, atol=1e-12)
    # The figures' path: the learner's values from its configuration and weights alone.
    figure = _native.learner_values(learner, list(low), list(high), w, points)
    np.testing.assert_array_equal(figure, trained.value(points))


def test_one_weight_peaks_at_its_centre_in_the_grid_order():
    """Weight 1 on flat index 3 + 5·8 of an 8×8 grid (dimension 0 fastest): V is largest at the
    centre (3, 5), not at (5, 3) — a changed Rust grid order fails here."""
    low, high = np.zeros(2), np.array([1.0, 2.0])
    w = np.zeros(64)
    w[3 + 5 * 8] = 1.0
    spacing = (high - low) / 7
    at = np.array([[3 * spacing[0], 5 * spacing[1]], [5 * spacing[0], 3 * spacing[1]]])
    v = _native.learner_values({"rbf_per_dim": 8}, list(low), list(high), w, at)
    assert v[0] > 0.1 and v[1] < 0.01, v
    np.testing.assert_allclose(v, _reference.value_function(w, low, high, at), rtol=1e-12)
