"""Demonstration generators: constraint satisfied, seeded, continuous angles, valid arguments."""

import numpy as np
import pytest

from latentrl.datasets import (
    ARM_REACH,
    ARM_Y_MIN,
    EE_LEFT_BOX,
    OFFSET,
    SHOULDERS,
    arm_hands,
    arm_postures,
    bimanual_pairs,
    grip_error,
)
from latentrl._reference import arms_forward


def test_bimanual_pairs_satisfy_the_constraint_in_the_box():
    pairs = bimanual_pairs(500, np.random.default_rng(0))
    assert pairs.shape == (500, 4)
    np.testing.assert_allclose(pairs[:, 2:] - pairs[:, :2], np.tile(OFFSET, (500, 1)), atol=1e-15)
    (x0, y0), (x1, y1) = EE_LEFT_BOX
    assert np.all(
        (pairs[:, 0] >= x0) & (pairs[:, 0] <= x1) & (pairs[:, 1] >= y0) & (pairs[:, 1] <= y1)
    )
    assert np.all(pairs[:, 2] <= 1.5)  # right hand still inside the Exp 1 state box


def test_bimanual_pairs_seeded_and_noisy():
    a = bimanual_pairs(50, np.random.default_rng(7))
    np.testing.assert_array_equal(a, bimanual_pairs(50, np.random.default_rng(7)))
    noisy = bimanual_pairs(50, np.random.default_rng(7), noise=0.003)
    np.testing.assert_allclose(noisy, a, atol=0.02)  # same hands, plus noise
    assert 0.001 < np.std(noisy - a) < 0.005


def test_arm_postures_hold_the_object():
    q = arm_postures(300, np.random.default_rng(1))
    hands = arms_forward(q)
    np.testing.assert_allclose(hands[:, 2:] - hands[:, :2], np.tile(OFFSET, (300, 1)), atol=1e-12)
    assert np.all(hands[:, [1, 3]] >= ARM_Y_MIN - 1e-12)
    for arm in (0, 1):
        reach = np.linalg.norm(hands[:, 2 * arm : 2 * arm + 2] - SHOULDERS[arm], axis=1)
        assert np.all((reach >= ARM_REACH[0] - 1e-12) & (reach <= ARM_REACH[1] + 1e-12))
    assert np.all(q[:, 1] <= 0) and np.all(q[:, 3] >= 0)  # elbows outward


def test_arm_postures_angles_are_continuous():
    # No 2π jumps: over a dense sample, nearby hand targets have nearby postures, and each
    # shoulder angle spans one interval shorter than 2π.
    q = arm_postures(5000, np.random.default_rng(2))
    assert np.all(np.ptp(q, axis=0) < 2 * np.pi - 1)
    hands = arms_forward(q)
    order = np.lexsort((hands[:, 1].round(2), hands[:, 0].round(2)))
    left, angles = hands[order, :2], q[order]
    near = np.linalg.norm(np.diff(left, axis=0), axis=1) < 0.005
    assert near.sum() > 100
    assert np.max(np.abs(np.diff(angles, axis=0))[near]) < 0.5


def test_arm_postures_seeded_and_noisy():
    a = arm_postures(40, np.random.default_rng(3))
    np.testing.assert_array_equal(a, arm_postures(40, np.random.default_rng(3)))
    noisy = arm_postures(40, np.random.default_rng(3), noise=0.01)
    assert 0.005 < np.std(noisy - a) < 0.02
    assert np.max(grip_error(arms_forward(noisy))) > 1e-4


def test_arm_hands_region_can_be_changed():
    hands = arm_hands(200, np.random.default_rng(4), reach=(0.3, 0.5), y_min=0.2)
    assert np.all(hands[:, 1] >= 0.2)
    assert np.all(np.linalg.norm(hands[:, :2] - SHOULDERS[0], axis=1) >= 0.3 - 1e-12)


def test_grip_error_tests():
    hands = np.array([[0.0, 0.0, 0.1, 0.0], [0.0, 0.0, 0.0, 0.1], [0.0, 0.0, 0.103, 0.004]])
    np.testing.assert_allclose(
        grip_error(hands, test="vector"), [0.0, np.sqrt(0.02), 0.005], atol=1e-12
    )
    np.testing.assert_allclose(
        grip_error(hands, test="distance"), [0.0, 0.0, np.hypot(0.103, 0.004) - 0.1], atol=1e-12
    )
    with pytest.raises(ValueError, match="test must be"):
        grip_error(hands, test="angle")


@pytest.mark.parametrize("n", [0, -1, 2.5, True])
def test_bad_n(n):
    with pytest.raises(ValueError, match="n must be"):
        bimanual_pairs(n, np.random.default_rng(0))
    with pytest.raises(ValueError, match="n must be"):
        arm_postures(n, np.random.default_rng(0))


def test_bad_noise_and_region():
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="noise"):
        bimanual_pairs(3, rng, noise=-1.0)
    with pytest.raises(ValueError, match="noise"):
        arm_postures(3, rng, noise=float("nan"))
    with pytest.raises(ValueError, match="left_box"):
        bimanual_pairs(3, rng, left_box=((0, 0), (0, 1)))
    with pytest.raises(ValueError, match="reach"):
        arm_hands(3, rng, reach=(0.2, 0.7))
    with pytest.raises(ValueError, match="postures"):
        arms_forward(np.zeros((3, 2)))
