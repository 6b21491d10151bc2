"""Real robot descriptions (issue #17) from Python: the test arm `tests/robots/arm7_description`
(STL, OBJ and COLLADA collision meshes, package:// paths, a continuous wrist, prismatic fingers
with a mimic) loads, matches an independent forward kinematics, runs in a task, and
`latentrl urdf-info` describes it."""

import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from latentrl import InvalidInputError, Task
from latentrl._native import Sim, TaskPlant
from urdf_reference import Robot

PACKAGE = Path(__file__).parent / "robots" / "arm7_description"
ARM7 = PACKAGE / "urdf" / "arm7.urdf"


def random_postures(sim: Sim, reference: Robot, n: int, seed: int) -> np.ndarray:
    """`n` postures of the actuated joints within their limits (continuous joints in ±π)."""
    names = list(reference.joint_names)
    index = [names.index(j) for j in sim.joint_names]
    lower = np.where(np.isinf(reference.lower), -np.pi, reference.lower)[index]
    upper = np.where(np.isinf(reference.upper), np.pi, reference.upper)[index]
    return np.random.default_rng(seed).uniform(lower, upper, size=(n, len(index)))


def test_forward_kinematics_matches_the_numpy_reference_with_the_mimic_finger():
    # The NumPy reference treats every moving joint as free: the mimic finger gets
    # multiplier 1 * finger_joint1 + 0, as the URDF says. Measured here: < 1e-6 m (f32).
    sim = Sim(ARM7)
    reference = Robot.parse(ARM7)
    names = list(reference.joint_names)
    worst = 0.0
    for posture in random_postures(sim, reference, 50, seed=0):
        sim.reset(posture)
        full = dict(zip(sim.joint_names, posture))
        full["finger_joint2"] = full["finger_joint1"]
        poses = reference.link_poses(np.array([full[n] for n in names]))
        for link in reference.links:
            worst = max(worst, float(np.linalg.norm(sim.frame_position(link) - poses[link][:3, 3])))
    assert worst < 1e-4, f"largest link position error {worst * 1e3:.4f} mm"


def test_urdf_info_lists_joints_shapes_and_mass():
    out = subprocess.run([sys.executable, "-m", "latentrl", "urdf-info", str(ARM7)], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "robot arm7: 12 links, total mass 22.74 kg" in out.stdout
    assert "joint7                   continuous  unlimited" in out.stdout
    assert "= 1 * finger_joint1 + 0" in out.stdout
    assert out.stdout.count("convex hull of 48 vertices from 96 triangles") == 8
    info = json.loads(subprocess.run([sys.executable, "-m", "latentrl", "urdf-info", str(ARM7), "--json"],
                                     capture_output=True, text=True, check=True).stdout)
    assert [j["type"] for j in info["joints"]].count("prismatic") == 2
    assert info["joints"][-1]["mimic"] == {"leader": "finger_joint1", "multiplier": 1.0, "offset": 0.0}
    assert {Path(s["file"]).suffix for s in info["collision"]} == {".stl", ".obj", ".dae"}


def test_urdf_info_on_a_missing_mesh_names_link_and_path_without_traceback(tmp_path):
    copy = tmp_path / "arm7_description"
    shutil.copytree(PACKAGE, copy)
    (copy / "meshes" / "collision" / "link4.obj").unlink()
    out = subprocess.run([sys.executable, "-m", "latentrl", "urdf-info", str(copy / "urdf" / "arm7.urdf")],
                         capture_output=True, text=True)
    assert out.returncode == 1
    assert "Traceback" not in out.stderr
    assert 'collision mesh of link "link4"' in out.stderr and "link4.obj: cannot read it" in out.stderr


def test_a_task_on_the_mesh_arm_steps_and_gives_the_mimic_its_own_gains():
    task = Task.from_dict({
        "name": "arm7_reach", "urdf": str(ARM7), "root": "fixed", "effectors": ["tcp"],
        "target": {"position": [[0.4, 0.0, 0.6]], "width": 0.1},
        "servo": {"kp": 20000.0, "kd": 200.0, "joints": {"finger_joint2": {"kp": 500.0}}},
        "physics": {"self_collisions": True, "ignore_collisions": [["link5", "link7"]]},
    })
    assert len(task.joint_names) == 8
    demos = np.array([[0.0, 0.3, 0.0, -1.8, 0.0, 2.0, 0.8, 0.02], [0.5, 0.6, -0.2, -1.5, 0.3, 2.2, 0.0, 0.04],
                      [-0.4, 0.2, 0.3, -2.2, -0.3, 1.8, -0.8, 0.0]])
    plant = TaskPlant(task._native, demos)
    assert plant.reset(demos[0]) is None
    for _ in range(20):  # 1 s towards the last demo
        _, end, _ = plant.step(demos[2])
    assert np.isfinite(plant.link_poses()).all()
    assert np.abs(plant.joint_positions() - demos[2]).max() < 0.05


def test_an_unknown_link_in_ignore_collisions_is_refused_by_name():
    with pytest.raises(InvalidInputError, match=r"physics.ignore_collisions\[0\]\[1\]"):
        Task.from_dict({"name": "t", "urdf": str(ARM7), "root": "fixed", "effectors": ["tcp"],
                        "target": {"position": [[0.4, 0.0, 0.6]]},
                        "physics": {"self_collisions": True, "ignore_collisions": [["link5", "link_77"]]}})
