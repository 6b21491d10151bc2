"""The back-constrained GPLVM (issue #19): `Z_ = K_b W`, so training postures encode exactly
to their latent points and a new posture with one kernel evaluation; the objective against an
independent NumPy composition; save/load; refusals."""

import numpy as np
import pytest
from scipy.spatial.distance import cdist

from latentrl import GPLVM
from latentrl._native import gplvm_back_constrained_nll_grad, gplvm_nll_grad
from latentrl.datasets import arm_postures


@pytest.fixture(scope="module")
def X():
    return arm_postures(60, np.random.default_rng(3))


@pytest.fixture(scope="module")
def model(X):
    return GPLVM(encoder="back_constrained", max_iter=300, random_state=0).fit(X)


def k_b(a, b, beta):
    """The back-constraint kernel in NumPy: exp(-|a - b|^2 / (2 beta))."""
    return np.exp(-0.5 * cdist(a, b, "sqeuclidean") / beta)


def test_training_postures_encode_exactly_to_their_latent_points(X, model):
    assert np.array_equal(model.transform(X), model.Z_)
    assert np.array_equal(model.fit_transform(X), model.transform(X))


def test_a_new_posture_encodes_with_one_kernel_evaluation(X, model):
    new = X[:5] + 0.01
    beta = model.encoder_theta_[1]
    expected = k_b(new, model.X_train_, beta) @ model.encoder_weights_
    assert np.allclose(model.transform(new), expected, rtol=0, atol=1e-9)  # measured 7e-12


def test_objective_is_the_gplvm_nll_at_the_kernel_regression_points(X):
    rng = np.random.default_rng(1)
    centred = X - X.mean(axis=0)
    weights = 0.1 * rng.standard_normal((len(X), 2))
    log_theta, log_beta = np.log([0.5, 1.2, 0.01]), np.log(0.7)
    nll, grad_w, _, grad_lb, latent, _ = gplvm_back_constrained_nll_grad(weights, centred, log_theta, log_beta)
    z = k_b(centred, centred, 0.7) @ weights
    assert np.allclose(latent, z, atol=1e-12)
    nll_z, grad_z, _, _ = gplvm_nll_grad(z, centred, log_theta)
    assert nll == pytest.approx(nll_z, rel=1e-12)
    assert np.allclose(grad_w, k_b(centred, centred, 0.7) @ grad_z, atol=1e-9)
    h = 1e-6
    up = gplvm_back_constrained_nll_grad(weights, centred, log_theta, log_beta + h)[0]
    down = gplvm_back_constrained_nll_grad(weights, centred, log_theta, log_beta - h)[0]
    assert grad_lb == pytest.approx((up - down) / (2 * h), rel=1e-5)


def test_fit_reconstructs_and_scales_the_latent_space_like_the_pca_start(X, model):
    assert np.abs(model.inverse_transform(model.Z_) - X).max() < 0.01
    assert np.max(np.std(model.Z_, axis=0)) == pytest.approx(1.0)
    assert model.nll_ == pytest.approx(gplvm_nll_grad(model.Z_, X - model.mean_, np.log(model.theta_))[0], abs=1e-6)


def test_save_load_keeps_the_encoder_bit_for_bit(tmp_path, X, model):
    model.save(tmp_path / "bc.npz")
    loaded = GPLVM.load(tmp_path / "bc.npz")
    assert np.array_equal(loaded.transform(X), model.transform(X))
    assert np.array_equal(loaded.encoder_weights_, model.encoder_weights_)


def test_refusals_name_the_setting(X, model):
    with pytest.raises(ValueError, match="latent_prior"):
        GPLVM(encoder="back_constrained", latent_prior=True).fit(X)
    with pytest.raises(ValueError, match="fitted with the 'back_constrained' encoder"):
        model.transform(X, method="gp")
    assert np.isfinite(model.transform(X, method="projection")).all()
    gp = GPLVM(max_iter=20).fit(X)
    assert not gp.encoder_weights_.any()
    with pytest.raises(ValueError, match="fitted with the 'gp' encoder"):
        gp.transform(X, method="back_constrained")


def test_the_experiments_take_the_encoder_as_a_checked_preset_field(model):
    from latentrl.experiments.exp2 import Exp2Preset
    from latentrl.results import gplvm_info

    assert Exp2Preset().encoder == "gp"
    with pytest.raises(ValueError, match="run: encoder: unknown variant `pca`, expected one of `gp`, `projection`, `back_constrained`, `tracking`"):
        Exp2Preset(encoder="pca").validate()
    Exp2Preset(encoder="projection").validate()
    from latentrl.experiments.exp1 import Exp1Preset

    Exp1Preset(encoder="projection").validate()
    assert gplvm_info(model)["encoder"] == "back_constrained"


def test_bad_inputs_to_the_native_back_constraint_are_named_errors(X):
    from latentrl import InvalidInputError
    from latentrl._native import GpMap

    centred = X - X.mean(axis=0)
    with pytest.raises(InvalidInputError, match="back-constraint weights"):
        gplvm_back_constrained_nll_grad(np.zeros((5, 2)), centred, np.zeros(3), 0.0)
    with pytest.raises(InvalidInputError, match="log beta"):
        gplvm_back_constrained_nll_grad(np.zeros((len(X), 2)), centred, np.zeros(3), float("nan"))
    with pytest.raises(InvalidInputError, match="theta2"):
        gplvm_back_constrained_nll_grad(np.zeros((len(X), 2)), centred, np.zeros(3), 800.0)  # exp overflows
    with pytest.raises(InvalidInputError, match="weights"):
        GpMap.back_constraint(X, np.zeros((3, 2)), 0.0)
