"""The `Sim` binding (rapier3d world with PD servos): holding, tracking, FK, obstacles, errors."""

from pathlib import Path

import numpy as np
import pytest

from latentrl import InvalidInputError, Task
from latentrl._native import Sim, arms_ik
from latentrl.datasets import arms_forward
from urdf_reference import task_robot

START = arms_ik(np.array([[-0.25, 0.15, -0.15, 0.15]]))[0]
ARMS = Task.shipped("two_arms")
LIFT = Task.shipped("humanoid_lift")


def urdf(task: Task) -> str:
    """Path of the task's URDF."""
    return str(task.urdf_path)


def world(task: Task, **kwargs) -> dict:
    """The `Sim` keywords of the task's world: root, floor, physics and servos."""
    config = task.to_dict()
    floor = config["floor"]["height"] if config["floor"] is not None else None
    return {"root": config["root"], "floor": floor, "physics": config["physics"], "servo": config["servo"], **kwargs}


@pytest.fixture
def sim() -> Sim:
    s = Sim(urdf(ARMS), **world(ARMS))
    s.reset(START)
    return s


def hands(s: Sim) -> np.ndarray:
    return np.concatenate([s.frame_position("left_hand")[:2], s.frame_position("right_hand")[:2]])


def test_builds_from_path_or_xml():
    from_path = Sim(Path(urdf(ARMS)))
    from_xml = Sim(Path(urdf(ARMS)).read_text(), physics={"dt": 1 / 480, "substeps": 24})
    assert from_path.joint_names == ["left_shoulder", "left_elbow", "right_shoulder", "right_elbow"]
    assert from_xml.joint_names == from_path.joint_names
    assert from_path.dt == pytest.approx(0.05) and from_xml.dt == pytest.approx(0.05)
    assert "two_arms" in repr(from_path)


def test_holds_a_posture(sim):
    for _ in range(20):
        sim.step()
    assert sim.time == pytest.approx(1.0)
    np.testing.assert_allclose(sim.joint_positions(), START, atol=1e-3)
    np.testing.assert_allclose(sim.joint_velocities(), 0.0, atol=1e-2)


def test_tracks_a_target(sim):
    target = START + np.array([0.1, -0.05, -0.08, 0.05])
    sim.set_targets(target)
    np.testing.assert_array_equal(sim.targets(), target)
    sim.step()  # one RL step (0.05 s)
    np.testing.assert_allclose(sim.joint_positions(), target, atol=2e-3)
    sim.step(60)  # 60 physics steps
    np.testing.assert_allclose(sim.joint_positions(), target, atol=1e-3)


def test_hand_frames_match_the_numpy_kinematics(sim):
    rng = np.random.default_rng(0)
    postures = START + rng.uniform(-0.3, 0.3, (5, 4))
    for q in postures:
        sim.reset(q)
        np.testing.assert_allclose(hands(sim), arms_forward(q[None])[0], atol=1e-5)
        assert sim.frame_position("left_hand")[2] == pytest.approx(0.0, abs=1e-5)


def test_box_obstacle_contacts(sim):
    h = hands(sim)
    assert sim.contacts() == []
    far = sim.add_box_obstacle(np.array([0.0, -0.5, 0.0]), np.array([0.05, 0.05, 0.05]))
    near = sim.add_box_obstacle(np.array([h[0], h[1], 0.0]), np.array([0.02, 0.02, 0.1]))
    assert (far, near) == (0, 1)
    found = sim.contacts()
    assert found and all(obstacle == near for _, obstacle in found)
    assert "left_forearm" in {link for link, _ in found}


def test_bad_inputs_raise_clear_errors(sim):
    with pytest.raises(InvalidInputError, match=r"posture.*\(4,\)"):
        sim.reset(np.zeros(3))
    with pytest.raises(InvalidInputError, match="outside the joint limits"):
        sim.reset(np.array([0.0, 1.0, 0.0, 0.0]))
    with pytest.raises(InvalidInputError, match="non-finite|NaN|finite"):
        sim.set_targets(np.array([np.nan, 0.0, 0.0, 0.0]))
    with pytest.raises(InvalidInputError, match="nowhere"):
        sim.frame_position("nowhere")
    with pytest.raises(InvalidInputError, match="half_extents"):
        sim.add_box_obstacle(np.zeros(3), np.array([0.1, -1.0, 0.1]))
    with pytest.raises(InvalidInputError, match=r"center: expected shape \(3,\)"):
        sim.add_box_obstacle(np.zeros(2), np.ones(3))
    with pytest.raises(InvalidInputError, match="n: expected an int >= 0"):
        sim.step(-1)
    with pytest.raises(InvalidInputError, match="root"):
        Sim(urdf(ARMS), root="loose")  # type: ignore[arg-type]
    with pytest.raises(InvalidInputError, match=r"physics.substeps must be an integer in \[1, 10000\], got 0"):
        Sim(urdf(ARMS), physics={"substeps": 0})
    with pytest.raises(InvalidInputError, match=r"physics.pgs_iterations must be an integer in \[1, 1000\], got 0"):
        Sim(urdf(ARMS), physics={"pgs_iterations": 0})
    with pytest.raises(InvalidInputError, match=r"physics.dt must lie in \(0, 0.05\], got -1"):
        Sim(urdf(ARMS), physics={"dt": -1.0})
    with pytest.raises(InvalidInputError, match=r"servo.kp must lie in \[0, 3.4028234663852886e38\], got -5"):
        Sim(urdf(ARMS), servo={"kp": -5.0})
    with pytest.raises(InvalidInputError, match="physics: gravity: invalid length 2, expected an array of length 3"):
        Sim(urdf(ARMS), physics={"gravity": [0.0, 0.0]})
    with pytest.raises(InvalidInputError, match="unknown field `dtt`"):
        Sim(urdf(ARMS), physics={"dtt": 0.01})
    with pytest.raises(InvalidInputError, match="unknown field `gain`"):
        Sim(urdf(ARMS), servo={"gain": 1.0})
    with pytest.raises(TypeError, match="dt"):  # the world's keys are in physics= and servo=
        Sim(urdf(ARMS), dt=0.01)  # type: ignore[call-arg]
    with pytest.raises(InvalidInputError, match="cannot read URDF file /no/such/robot.urdf: No such file"):
        Sim("/no/such/robot.urdf")
    with pytest.raises(InvalidInputError, match=r"malformed URDF \(<string>\)"):
        Sim("<robot name='broken'>")


def test_floating_humanoid_stands_on_the_ground_and_falls_without_it():
    kin = task_robot(LIFT)  # the NumPy reference kinematics of the URDF
    home = np.zeros(len(kin.joint_names))
    poses = kin.link_poses(home)  # Sim.reset leaves the floating base at the identity
    sole = min(kin.box_corners(poses, s)[:, 2].min() for s in ("l_foot", "r_foot"))
    heights = {}
    for ground in (sole - 5e-4, None):
        config = world(LIFT, floor=ground)
        s = Sim(urdf(LIFT), **{**config, "physics": {**config["physics"], "substeps": 24}})
        s.reset(home)
        start = s.frame_position("torso")[2]
        for _ in range(10):  # 1 s
            s.step()
        heights[ground is not None] = (start, s.frame_position("torso")[2])
    start, end = heights[True]
    assert end == pytest.approx(start, abs=3e-3)  # standing: the servos sag by ~1 mm
    start, end = heights[False]
    assert end < start - 1.0  # free fall for 1 s: ~4.9 m


def test_floor_must_be_finite():
    with pytest.raises(InvalidInputError, match="floor must be a finite height"):
        Sim(urdf(ARMS), floor=float("nan"))


def test_reset_on_ground_and_fall_status_check_their_inputs():
    floating = Sim(urdf(LIFT), root="floating", floor=0.0)
    home = np.zeros(len(floating.joint_names))
    floating.reset_on_ground(home, "l_foot")
    fell, height, tilt, contact = floating.fall_status(["l_foot", "r_foot"], min_base_height=0.05)
    assert not fell and height == pytest.approx(floating.base_position()[2]) and tilt < 1e-6 and contact is None
    assert floating.fall_status(["l_foot", "r_foot"], min_base_height=1.0)[0]  # base below 1 m: fallen
    with pytest.raises(InvalidInputError, match="no floor"):
        Sim(urdf(LIFT), root="floating").reset_on_ground(home, "l_foot")
    with pytest.raises(ValueError, match="l_paw"):
        floating.reset_on_ground(home, "l_paw")
    with pytest.raises(ValueError, match="clearance"):
        floating.reset_on_ground(home, "l_foot", clearance=float("nan"))
    with pytest.raises(ValueError, match="fall criteria"):
        floating.fall_status(["l_foot"], min_base_height=float("inf"))
    with pytest.raises(ValueError, match="r_paw"):
        floating.fall_status(["r_paw"], min_base_height=0.05)
