import numpy as np
import pytest

from latentrl import GPLVM
from latentrl.inverse import Projection, fit_gp_encoder


def manifold(t):
    return np.column_stack(
        [t[:, 0], t[:, 1], np.sin(2 * t[:, 0]), np.cos(2 * t[:, 1]), t[:, 0] * t[:, 1]]
    )


@pytest.fixture(scope="module")
def model():
    rng = np.random.default_rng(0)
    X = manifold(rng.uniform(-1, 1, size=(40, 2))) + 0.01 * rng.normal(size=(40, 5))
    return GPLVM().fit(X)


def test_gp_encoder_maps_training_postures_to_their_latent_points(model):
    encoder = fit_gp_encoder(model.X_train_, model.Z_)
    assert (encoder.input_dim, encoder.output_dim) == (5, 2) and encoder.theta[2] >= 1e-6
    np.testing.assert_allclose(encoder.theta, model.encoder_.theta, rtol=1e-12)
    assert np.abs(encoder.predict(model.X_train_)[0] - model.Z_).max() < 0.05 * model.Z_.std()


def test_projection_decoder_matches_the_native_decoder(model):
    z = np.random.default_rng(1).normal(size=(6, 2)) * model.Z_.std(axis=0)
    means, variances = model.decoder_.predict(z)
    for point, mean, variance in zip(z, means, variances):
        p_mean, _, p_variance, _ = model.projection_.decode_with_gradient(point)
        np.testing.assert_allclose(p_mean, mean, rtol=1e-9, atol=1e-10)
        assert p_variance == pytest.approx(variance, rel=1e-7, abs=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_projection_gradients_match_finite_differences(model, seed):
    rng = np.random.default_rng(seed)
    z = model.Z_[seed] + 0.3 * rng.normal(size=2)
    x = model.X_train_[seed + 5]
    projection = model.projection_
    _, d_mean, _, d_variance = projection.decode_with_gradient(z)
    _, grad = projection.neg_log_density(z, x)
    # h = 1e-4: the mean sums k*·α with |α| ~ 400, so rounding swamps smaller steps
    # (measured error 6e-9 at h = 1e-4, 5e-7 at h = 1e-6).
    h = 1e-4
    for i in range(2):
        step = np.eye(2)[i] * h
        plus, minus = (
            projection.decode_with_gradient(z + step),
            projection.decode_with_gradient(z - step),
        )
        np.testing.assert_allclose(
            d_mean[:, i], (plus[0] - minus[0]) / (2 * h), rtol=1e-6, atol=1e-7
        )
        assert d_variance[i] == pytest.approx((plus[2] - minus[2]) / (2 * h), rel=1e-6, abs=1e-10)
        fd = (
            projection.neg_log_density(z + step, x)[0] - projection.neg_log_density(z - step, x)[0]
        ) / (2 * h)
        assert grad[i] == pytest.approx(fd, rel=1e-6, abs=1e-6)


def test_both_encoders_agree_and_projection_reconstructs_at_least_as_well(model):
    rng = np.random.default_rng(2)
    new = manifold(rng.uniform(-0.9, 0.9, size=(30, 2))) + 0.01 * rng.normal(size=(30, 5))
    z_gp, z_proj = model.transform(new, method="gp"), model.transform(new, method="projection")
    assert np.abs(z_gp - z_proj).max() < 0.1 * model.Z_.std()
    error_gp = np.linalg.norm(model.inverse_transform(z_gp) - new, axis=1)
    error_proj = np.linalg.norm(model.inverse_transform(z_proj) - new, axis=1)
    assert error_proj.mean() <= error_gp.mean()


def test_projection_of_a_decoded_point_recovers_it(model):
    z = model.Z_[:5] + 0.05
    recovered = model.projection_.encode(model.inverse_transform(z))
    np.testing.assert_allclose(recovered, z, atol=1e-3 * model.Z_.std())


def test_projection_from_arrays_equals_the_models(model):
    projection = Projection(model.Z_, model.X_train_, model.theta_, max_iter=200)
    np.testing.assert_array_equal(
        projection.encode(model.X_train_[:3]), model.projection_.encode(model.X_train_[:3])
    )


def test_projection_is_at_least_as_accurate_as_the_gp_encoder_on_arm_postures():
    # Regression: started on the density, L-BFGS left the data and decoded 1.3 rad off.
    from latentrl.datasets import arm_postures

    model = GPLVM(random_state=0).fit(arm_postures(123, np.random.default_rng(0)))
    fresh = arm_postures(40, np.random.default_rng(1))
    errors = {
        method: np.sqrt(np.mean((model.inverse_transform(model.transform(fresh, method)) - fresh) ** 2))
        for method in ("gp", "projection")
    }
    assert errors["gp"] < 0.01
    assert errors["projection"] <= errors["gp"]
