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


def held_out(model, n=40, seed=5):
    """Postures off the training set: the manifold at new latent points, with noise."""
    rng = np.random.default_rng(seed)
    return manifold(rng.uniform(-1, 1, size=(n, 2))) + 0.01 * rng.normal(size=(n, 5))


def test_native_projection_agrees_with_the_scipy_reference(model):
    """The Rust projection (own bounded L-BFGS) against `Projection` (SciPy L-BFGS-B): the same
    start, stages, box and best-of rule, different minimisers. Measured on these 40 held-out
    postures: largest latent distance 4.5e-7 of the latent span, native's −log density at most
    4.1e-9 above the reference's (tolerances 1e-4 and 1e-6)."""
    X = held_out(model)
    native, reference = model.native_projection_.encode(X), model.projection_.encode(X)
    span = np.ptp(model.Z_, axis=0).max()
    assert np.linalg.norm(native - reference, axis=1).max() <= 1e-4 * span
    density = [np.array([model.projection_.neg_log_density(z, x)[0] for z, x in zip(Z, X)]) for Z in (native, reference)]
    assert np.all(density[0] <= density[1] + 1e-6)


def test_native_projection_encodes_one_posture_as_the_batch(model):
    X = held_out(model, n=3)
    batch = model.native_projection_.encode(X)
    for x, z in zip(X, batch):
        np.testing.assert_array_equal(model.native_projection_.encode_one(x), z)
    assert model.loop_encoder_ is model.encoder_
    projected = GPLVM(encoder="projection").fit(model.X_train_)
    assert projected.loop_encoder_ is projected.native_projection_


def test_the_tracking_encoder_fits_the_gp_model_and_projects_without_a_command(model):
    tracking = GPLVM(encoder="tracking").fit(model.X_train_)
    np.testing.assert_array_equal(tracking.Z_, model.Z_)
    assert tracking.fitted_encoder_ == "gp"
    X = held_out(model, n=3)
    np.testing.assert_array_equal(tracking.loop_encoder_.encode(X), model.native_projection_.encode(X))
    np.testing.assert_array_equal(tracking.transform(X), model.transform(X, method="projection"))


@pytest.mark.parametrize(
    "call, match",
    [
        (lambda p: p.encode_one(np.zeros(4)), r"posture: expected shape \(5,\), got \(4,\)"),
        (lambda p: p.encode_one(np.array([0.0, np.nan, 0.0, 0.0, 0.0])), "posture contains a non-finite value"),
        (lambda p: p.encode(np.zeros((2, 3))), r"postures: expected shape \(M, 5\)"),
        (lambda p: p.encode(np.full((1, 5), np.inf)), "postures contains a non-finite value"),
    ],
)
def test_bad_postures_to_the_native_projection_are_named_errors(model, call, match):
    with pytest.raises(ValueError, match=match):
        call(model.native_projection_)


def test_bad_native_projection_settings_are_named_errors(model):
    from latentrl._native import Projection as NativeProjection

    with pytest.raises(ValueError, match=r"postures \(the decoder's training outputs\)"):
        NativeProjection(model.decoder_, model.X_train_[:-1])
    with pytest.raises(ValueError, match="margin"):
        NativeProjection(model.decoder_, model.X_train_, margin=-1.0)
    with pytest.raises(ValueError, match="max_iter"):
        NativeProjection(model.decoder_, model.X_train_, max_iter=0)
