"""The Rust planar-arm kinematics (`_native.arms_fk` / `arms_ik`) and grip rule (`grip_error`)
against the NumPy reference."""

import numpy as np
import pytest

from latentrl import InvalidInputError
from latentrl._native import arms_elbows, arms_fk, arms_ik, grip_error
from latentrl._reference import arms_forward
from latentrl._reference import grip_error as numpy_grip_error
from latentrl.datasets import SHOULDERS, arm_hands


def random_postures(n=500, seed=0):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2 * np.pi, 2 * np.pi, size=(n, 4))


def test_fk_matches_numpy():
    q = random_postures()
    np.testing.assert_allclose(arms_fk(q), arms_forward(q), atol=1e-14)
    np.testing.assert_allclose(arms_elbows(q), arms_forward(q, elbows=True), atol=1e-14)


@pytest.mark.parametrize("test", ["distance", "vector"])
def test_grip_error_matches_numpy_bit_for_bit(test):
    """Same sum order as NumPy (no `hypot`): Table I and Exp 2's counts stay the same bits."""
    rng = np.random.default_rng(1)
    near = np.hstack([left := rng.uniform(-1, 1, (500, 2)), left + [0.1, 0.0] + rng.normal(0, 0.01, (500, 2))])
    for hands in (near, rng.uniform(-2, 2, (500, 4)), arms_fk(random_postures())):
        np.testing.assert_array_equal(grip_error(hands, test), numpy_grip_error(hands, test))


def test_known_poses():
    straight_up = np.array([[np.pi / 2, 0.0, np.pi / 2, 0.0]])
    np.testing.assert_allclose(arms_fk(straight_up), [[-0.15, 0.6, 0.15, 0.6]], atol=1e-15)
    bent = np.array([[np.pi, -np.pi / 2, 0.0, np.pi / 2]])  # upper arms sideways, forearms up
    np.testing.assert_allclose(arms_fk(bent), [[-0.45, 0.3, 0.45, 0.3]], atol=1e-15)
    np.testing.assert_allclose(arms_elbows(bent), [[-0.45, 0.0, 0.45, 0.0]], atol=1e-15)
    np.testing.assert_allclose(arms_ik(arms_fk(bent)), bent, atol=1e-12)


def test_ik_round_trip_elbows_outward():
    hands = arm_hands(2000, np.random.default_rng(1))
    q = arms_ik(hands)
    np.testing.assert_allclose(arms_forward(q), hands, atol=1e-12)
    assert np.all(q[:, 1] <= 0) and np.all(q[:, 3] >= 0)  # left elbow out left, right out right
    elbows = arms_forward(q, elbows=True)
    for arm, side in ((0, 1.0), (1, -1.0)):  # elbow left (right) of the shoulder→hand line
        d = hands[:, 2 * arm : 2 * arm + 2] - SHOULDERS[arm]
        e = elbows[:, 2 * arm : 2 * arm + 2] - SHOULDERS[arm]
        assert np.all(side * (d[:, 0] * e[:, 1] - d[:, 1] * e[:, 0]) > 0)


def test_ik_of_fk_recovers_outward_postures():
    rng = np.random.default_rng(2)
    n = 300
    q = np.column_stack(
        [
            rng.uniform(0.6, 2.4, n),
            rng.uniform(-2.8, -0.2, n),
            rng.uniform(0.8, 2.2, n),
            rng.uniform(0.2, 2.8, n),
        ]
    )
    np.testing.assert_allclose(arms_ik(arms_fk(q)), q, atol=1e-9)


def test_ik_angles_continuous_over_a_sweep():
    # Hands swept across shoulder height on the left: atan2 crosses ±π there.
    y = np.linspace(0.25, -0.25, 501)
    hands = np.column_stack([np.full_like(y, -0.45), y, np.full_like(y, -0.35), y])
    q = arms_ik(hands)
    assert np.max(np.abs(np.diff(q, axis=0))) < 0.02


@pytest.mark.parametrize(
    ("call", "arg", "message"),
    [
        (arms_fk, np.zeros((3, 3)), r"postures: expected shape \(N, 4\)"),
        (arms_fk, np.array([[0.0, np.nan, 0.0, 0.0]]), "non-finite"),
        (arms_ik, np.zeros((2, 5)), r"hands: expected shape \(N, 4\)"),
        (arms_ik, np.array([[-0.15, 0.7, 0.0, 0.3]]), "left hand target of row 0 is unreachable"),
        (
            arms_ik,
            np.array([[0.0, 0.3, 0.1, 0.3], [0.0, 0.3, 0.9, 0.0]]),
            "right hand target of row 1",
        ),
        (arms_ik, np.zeros((0, 4)), "empty"),
        (grip_error, np.zeros((2, 8)), r"hands: expected shape \(N, 4\)"),
        (grip_error, np.array([[0.0, np.inf, 0.0, 0.0]]), "non-finite"),
    ],
)
def test_bad_input_raises_value_error(call, arg, message):
    with pytest.raises(ValueError, match=message) as info:
        call(arg)
    assert isinstance(info.value, InvalidInputError)


def test_wrong_rank_or_dtype_raises():
    with pytest.raises((TypeError, ValueError)):
        arms_fk(np.zeros(4))
    with pytest.raises((TypeError, ValueError)):
        arms_fk(np.zeros((2, 4), dtype=np.int64))
