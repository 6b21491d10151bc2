"""Stock robot descriptions (issue #41): each defect class of the 22 pybullet_data URDFs on a small
synthetic robot, through `latentrl urdf-info` and the Python API; demo columns in any order and
with mimic joints. The 22 files themselves: the `slow` test at the end, when pybullet_data is
found (`$PYBULLET_DATA`, or /tmp/pybullet_data; docs/robots.md says how to get it)."""

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from latentrl import InvalidInputError, Task
from latentrl._native import Sim
from latentrl.robot_info import urdf_info

ARM7 = Path(__file__).parent / "robots" / "arm7_description" / "urdf" / "arm7.urdf"

LINK = ('<link name="{name}"><inertial><mass value="{mass}"/><inertia ixx="{ixx}" ixy="0" ixz="0" iyy="{iyy}" '
        'iyz="0" izz="{izz}"/></inertial><collision><geometry><box size="0.1 0.2 0.3"/></geometry></collision></link>')


def robot(tmp_path: Path, body: str, name: str = "r.urdf") -> Path:
    base = LINK.format(name="base", mass=1, ixx=0.01, iyy=0.01, izz=0.01)
    path = tmp_path / name
    path.write_text(f'<?xml version="1.0"?>\n<robot name="r">\n{base}\n{body}\n</robot>\n')
    return path


def hinge(name: str, child: str) -> str:
    return (f'<joint name="{name}" type="revolute"><parent link="base"/><child link="{child}"/><axis xyz="0 0 1"/>'
            '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>')


def urdf_info_cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "latentrl", "urdf-info", *args], capture_output=True, text=True)


def test_balance_inertia_names_every_link_at_once_then_repairs_each(tmp_path):
    # Two links breaking the triangle inequality (the xArm6's link3, the mini cheetah's thighs)
    # and one all-zero inertia (laikago): one error names all three.
    bad = LINK.format(name="a", mass=0.6, ixx=4e-4, iyy=1.8e-3, izz=2.3e-3)
    worse = LINK.format(name="b", mass=0.6, ixx=4e-4, iyy=1.8e-3, izz=2.3e-3)
    zero = LINK.format(name="c", mass=2.0, ixx=0, iyy=0, izz=0)
    path = robot(tmp_path, bad + worse + zero + hinge("ja", "a") + hinge("jb", "b") + hinge("jc", "c"))
    refused = urdf_info_cli(str(path))
    assert refused.returncode == 1 and "Traceback" not in refused.stderr
    assert "3 link(s)" in refused.stderr and all(f'link "{n}"' in refused.stderr for n in "abc")
    assert "--balance-inertia" in refused.stderr
    loaded = urdf_info_cli(str(path), "--balance-inertia")
    assert loaded.returncode == 0, loaded.stderr
    assert "repaired while loading:" in loaded.stdout
    assert "replaced by their mean" in loaded.stdout and "replaced by a solid box of 2 kg" in loaded.stdout
    info = urdf_info(path, balance_inertia=True)
    assert [w.split(":")[0] for w in info["warnings"]] == ['link "a"', 'link "b"', 'link "c"']
    as_json = urdf_info_cli(str(path), "--balance-inertia", "--json")
    assert json.loads(as_json.stdout)["warnings"] == info["warnings"]
    assert as_json.stderr.count("latentrl: warning: link") == 3


def test_sim_takes_balance_inertia_and_steps_the_repaired_robot(tmp_path):
    zero = LINK.format(name="a", mass=12.0, ixx=0, iyy=0, izz=0)
    path = robot(tmp_path, zero + hinge("j", "a"))
    with pytest.raises(InvalidInputError, match='link "a" has mass 12 but its <inertia> is not positive definite'):
        Sim(path)
    sim = Sim(path, balance_inertia=True)
    sim.set_targets(np.array([0.5]))
    sim.step(480)
    assert abs(sim.joint_positions()[0] - 0.5) < 0.05


@pytest.mark.parametrize("text, message", [
    ("<?xml version='1.0'?>\n<sdf version='1.6'><model name='m'/></sdf>", "an SDF file (root <sdf>), not URDF"),
    ("<mujoco model='m'/>", "an MJCF file (root <mujoco>), not URDF"),
    ("<robot xmlns:xacro='x'>\n  <xacro:property name='l' value='1'/>\n</robot>",
     "line 2, <xacro:property name='l' value='1'/>: a xacro file, not URDF: run xacro first"),
])
def test_other_formats_are_named_not_read_as_empty_robots(tmp_path, text, message):
    path = tmp_path / "robot.sdf"
    path.write_text(text)
    out = urdf_info_cli(str(path))
    assert out.returncode == 1 and message in out.stderr, out.stderr


def test_parser_errors_name_line_and_element(tmp_path):
    body = LINK.format(name="a", mass=1, ixx=0.01, iyy=0.01, izz=0.01) + "\n" + hinge("j", "a").replace('"-1"', '"-1.57."')
    out = urdf_info_cli(str(robot(tmp_path, body)))
    assert out.returncode == 1
    assert 'line 5, <limit lower="-1.57." upper="1" effort="10" velocity="1"/>: lower: "-1.57." is not a number' in out.stderr


def test_xacro_leftovers_spherical_and_rangeless_joints_load_with_warnings(tmp_path):
    a = LINK.format(name="a", mass=1, ixx=0.01, iyy=0.01, izz=0.01)
    b = LINK.format(name="b", mass=1, ixx=0.01, iyy=0.01, izz=0.01)
    c = LINK.format(name="c", mass=1, ixx=0.01, iyy=0.01, izz=0.01)
    body = (a + b + c
            + '<joint name="imu" type="fixed"><origin xyz="$(optenv IMU_XYZ 0.19 0 0.149)"/>'
              '<parent link="base"/><child link="a"/></joint>'
            + '<joint name="ball" type="spherical"><parent link="base"/><child link="b"/></joint>'
            + '<joint name="knee" type="revolute"><parent link="base"/><child link="c"/><limit effort="1" velocity="1"/></joint>')
    info = urdf_info(robot(tmp_path, body))
    assert [j["name"] for j in info["joints"]] == ["ball_x", "ball_y", "ball_z", "knee"]
    assert all(j["type"] == "continuous" for j in info["joints"])
    warnings = "\n".join(info["warnings"])
    assert 'read as its default "0.19 0 0.149"' in warnings
    assert 'joint "ball": spherical, loaded as three continuous joints' in warnings
    assert 'joint "knee": revolute without <limit lower upper>, loaded as continuous' in warnings


def arm7_task() -> Task:
    return Task.from_dict({"name": "arm7", "urdf": str(ARM7), "root": "fixed", "effectors": ["tcp"],
                           "target": {"position": [[0.4, 0.0, 0.6]], "width": 0.1}})


def test_demo_columns_in_any_order_with_a_mimic_column_checked_against_its_leader():
    task = arm7_task()
    names = list(task.joint_names)
    assert names[-1] == "finger_joint1"
    rng = np.random.default_rng(0)
    postures = rng.uniform(0.0, 0.04, size=(5, len(names)))
    columns = ["finger_joint2", *reversed(names)]
    table = np.column_stack([postures[:, -1], postures[:, ::-1]])  # the mimic follows 1 * finger_joint1 + 0
    np.testing.assert_array_equal(task.demo_postures(columns, table, "demos.csv"), postures)
    table[3, 0] += 0.01
    with pytest.raises(InvalidInputError, match=r'demos.csv: demo columns: row 3: mimic joint "finger_joint2" is'):
        task.demo_postures(columns, table, "demos.csv")
    with pytest.raises(ValueError, match=r"demos.csv: demo columns: missing \['joint1'\], not joints of the robot \['knee'\]"):
        task.demo_postures(["knee", *names[1:]], postures, "demos.csv")


STOCK = ["a1/a1", "aliengo/aliengo", "biped/biped2d_pybullet", "franka_panda/panda",
         "gripper/wsg50_one_motor_gripper_left_finger", "humanoid/humanoid", "husky/husky", "kuka_iiwa/model",
         "kuka_iiwa/model_free_base", "laikago/laikago", "laikago/laikago_toes_zup", "mini_cheetah/mini_cheetah",
         "cartpole", "pendulum5", "pr2_gripper", "r2d2", "quadruped/microtaur/microtaur", "quadruped/minitaur",
         "quadruped/spirit40", "racecar/racecar", "xarm/xarm6_robot", "xarm/xarm6_with_gripper"]
"""The 22 URDFs of pybullet 3.2.7's pybullet_data named in issue #41."""

REFUSED = {"biped/biped2d_pybullet": 'line 115, <limit effort="0.0" lower="-1.57."',
           "quadruped/microtaur/microtaur": 'line 300, <origin rpy="-3.14159 1.57079 0 0"'}


@pytest.mark.slow
def test_stock_pybullet_urdfs_load_or_are_refused_saying_where():
    data = Path(os.environ.get("PYBULLET_DATA", "/tmp/pybullet_data"))
    if not (data / "r2d2.urdf").is_file():
        pytest.skip("pybullet_data not found: pip download --no-deps pybullet==3.2.7 and unzip its pybullet_data/")
    loaded = 0
    for name in STOCK:
        out = urdf_info_cli(str(data / f"{name}.urdf"), "--balance-inertia")
        if name in REFUSED:
            assert out.returncode == 1 and REFUSED[name] in out.stderr, (name, out.stderr)
        else:
            assert out.returncode == 0, (name, out.stderr)
            loaded += 1
    assert loaded == 20
    sdf = urdf_info_cli(str(data / "kuka_iiwa" / "kuka_with_gripper.sdf"))
    assert sdf.returncode == 1 and "an SDF file" in sdf.stderr


def test_a_task_takes_balance_inertia_and_names_each_repair(tmp_path):
    """The task key `balance_inertia = true` loads a robot `urdf-info` repairs, its warnings on the
    Task (what `latentrl train` and `check` print); without it the task is refused."""
    zero = LINK.format(name="c", mass=2.0, ixx=0, iyy=0, izz=0)
    robot(tmp_path, zero + hinge("jc", "c"))
    text = 'name = "t"\nurdf = "r.urdf"\neffectors = ["c"]\n[target]\nposition = [[0.0, 0.0, 0.0]]\n'
    (tmp_path / "t.toml").write_text(text)
    with pytest.raises(ValueError, match="--balance-inertia"):
        Task.load(tmp_path / "t.toml")
    (tmp_path / "t.toml").write_text("balance_inertia = true\n" + text)
    task = Task.load(tmp_path / "t.toml")
    assert [w.split(":")[0] for w in task.warnings] == ['link "c"'] and "balance_inertia" in task.given
