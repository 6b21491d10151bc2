"""`latentrl.keyframes`: interpolated keyframes and postures recorded from the sim."""

from __future__ import annotations

import numpy as np
import pytest
from latentrl import Demonstrations, Task, load_demos, save_demos
from latentrl._native import Sim
from latentrl.datasets import arm_postures
from latentrl.experiments.exp3 import demos_path
from latentrl.keyframes import interpolate_keyframes, record_postures

ARMS = Task.shipped("two_arms")
JOINT_NAMES = ARMS.joint_names


def test_interpolation_joins_consecutive_keyframes_within_each_sequence():
    keys = load_demos(demos_path(), expected_joints=Task.shipped("humanoid_lift").joint_names)
    dense = interpolate_keyframes(keys, 4, breaks=(4,))
    X, Y = keys.postures, dense.postures
    assert Y.shape == (4 * 3 + 1 + 4 * 2 + 1, 19) and dense.joint_names == keys.joint_names
    np.testing.assert_array_equal(Y[[0, 4, 8, 12, 13, 17, 21]], X)  # every keyframe, in order
    np.testing.assert_allclose(Y[2], (X[0] + X[1]) / 2)
    np.testing.assert_allclose(Y[15], (X[4] + X[5]) / 2)
    # no posture between the two styles: each row lies on a segment of its own sequence
    assert not np.any(np.all(np.isclose(Y, (X[3] + X[4]) / 2), axis=1))
    assert interpolate_keyframes(keys, 1).postures.shape == (7, 19)


def test_interpolation_rejects_bad_arguments():
    keys = Demonstrations(np.zeros((3, 2)), ("a", "b"))
    with pytest.raises(ValueError, match="per_segment must be an int >= 1"):
        interpolate_keyframes(keys, 0)
    with pytest.raises(ValueError, match=r"breaks must be rows 1..2"):
        interpolate_keyframes(keys, 2, breaks=(3,))


def test_recorded_postures_reach_each_held_target_and_save(tmp_path):
    sim = Sim(ARMS.urdf_path, physics={"solver_iterations": 2})
    targets = arm_postures(3, np.random.default_rng(2))
    sim.reset(targets[0])
    demos = record_postures(sim, targets, hold_steps=60, every=6)
    assert demos.joint_names == JOINT_NAMES and demos.postures.shape == (30, 4)
    # the last posture recorded under each target is within 1 mrad of it (PD tracking)
    np.testing.assert_allclose(demos.postures[9::10], targets, atol=1e-3)
    assert np.abs(demos.postures[10] - targets[1]).max() > 1e-3, "the first sample is mid-move"
    save_demos(demos, tmp_path / "recorded.csv")
    again = load_demos(tmp_path / "recorded.csv", expected_joints=JOINT_NAMES)
    np.testing.assert_allclose(again.postures, demos.postures)


@pytest.mark.parametrize(
    ("targets", "kwargs", "message"),
    [
        (np.zeros((2, 3)), {"hold_steps": 5}, r"targets must have shape \(M >= 1, 4\)"),
        (np.full((1, 4), np.nan), {"hold_steps": 5}, "targets must be finite"),
        (np.zeros((1, 4)), {"hold_steps": 0}, "hold_steps must be an int >= 1"),
        (np.zeros((1, 4)), {"hold_steps": 5, "every": 6}, r"every \(6\) must be at most hold_steps \(5\)"),
    ],
)
def test_record_rejects_bad_arguments(targets, kwargs, message):
    with pytest.raises(ValueError, match=message):
        record_postures(Sim(ARMS.urdf_path), targets, **kwargs)
