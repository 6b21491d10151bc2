"""Tasks (issue #15): the shipped task files load and keep Experiment 2's and 3's rules, every bad
key, value, name or shape is refused by the one native rule with the file and the key path,
overrides apply by path, the schema lists every key, and the native plant applies the rules."""

import math
from pathlib import Path

import numpy as np
import pytest

from latentrl import Task
from latentrl.envs import shipped_demos
from latentrl.task import SHIPPED, end_reasons, schema, shipped_path

ARMS_TOML = shipped_path("two_arms").read_text()


def write(tmp_path: Path, text: str, name: str = "task.toml") -> Path:
    path = tmp_path / name
    path.write_text(text.replace('urdf = "../data/', f'urdf = "{shipped_path("two_arms").parent.parent}/data/'))
    return path


def test_shipped_tasks_load_with_their_robots():
    for name in SHIPPED:
        task = Task.shipped(name)
        assert task.name == name and task.origin.endswith(f"{name}.toml")
        config = task.to_dict()
        assert len(config["target"]["position"]) == len(task.effectors) == 2
        assert task.row_len == 3 * 2 + 7 + len(task.joint_names)
    arms = Task.shipped("two_arms")
    assert arms.joint_names == ("left_shoulder", "left_elbow", "right_shoulder", "right_elbow")
    lift = Task.shipped("humanoid_lift").to_dict()
    assert lift["root"] == "floating" and lift["floor"] == {"height": 0.0}
    assert lift["fall"]["max_tilt"] == math.radians(20) and lift["servo"]["max_force"] == 1.2
    assert end_reasons() == ("timeout", "obstacle", "box_exit", "drop", "fall", "variance_gate", "success")


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("[learner]", "[learner]\ngammma = 0.5"), r"task.toml: learner.gammma \(line 5\d\): unknown field `gammma`, expected one of"),
        (("gamma = 0.99", "gamma = 1.0"), r"task.toml: learner.gamma must lie in \[0, 1\), got 1"),
        (("gamma = 0.99", 'gamma = "high"'), r"task.toml: learner.gamma \(line 5\d\): invalid type: string \"high\", expected a number"),
        (("rbf_per_dim = 20", "rbf_per_dim = 1"), r"learner.rbf_per_dim must be an integer in \[2, 10000\], got 1"),
        (("tolerance = 0.005", "tolerance = -1.0"), r"constraints\[0\].tolerance must be a finite number > 0, got -1"),
        (("offset = [0.1, 0.0, 0.0]", "offset = [0.1, 0.0]"), r"constraints\[0\].offset \(line \d+\): invalid length 2, expected an array of length 3"),
        (("max = [-0.36, 0.37, 1.0]", "max = [-2.0, 0.37, 1.0]"), r"obstacles\[0\].max\[0\] must exceed min\[0\] = -1, got -2"),
        (('effectors = ["left_hand", "right_hand"]', 'effectors = ["left_hand", "right_hnd"]'),
         r'effectors\[1\]: unknown link "right_hnd"; links are: .*left_hand'),
        (('position = [[-0.05, 0.47, 0.0], [0.05, 0.47, 0.0]]', "position = [[-0.05, 0.47, 0.0]]"),
         r"target.position needs one \[x, y, z\] row per effector \(2 effectors: left_hand, right_hand\), got 1 rows"),
        (("dt = 0.008333333333333333", "dt = 1e10"), r"physics.dt must lie in \(0, 0.05\], got 10000000000"),
        (('kind = "offset"', 'kind = "glue"'), r"constraints\[0\].kind \(line \d+\): unknown variant `glue`, expected one of"),
        (('links = ["left_hand", "right_hand"]\noffset', 'link = "left_hand"\noffset'),
         r"constraints\[0\].links is required for kind = \"offset\""),
        (("position = [[-0.05, 0.47, 0.0], [0.05, 0.47, 0.0]]",
          'relative_to = "left_hnd"\nposition = [[-0.05, 0.47, 0.0], [0.05, 0.47, 0.0]]'),
         r'target.relative_to: unknown link "left_hnd"; links are: .*left_hand'),
        (("max_steps = 1000", "max_steps = 0"), r"episode.max_steps must be an integer in \[1, 1000000\], got 0"),
        (('root = "fixed"', 'root = "floating"'), r"floor is required with root = \"floating\""),
        (('urdf = "../data/two_arms.urdf"', 'urdf = "../data/no_such.urdf"'), r"urdf: cannot read URDF file .*no_such.urdf"),
        (("[learner]", "[run]\ntrials = 0\n\n[learner]"), r"task.toml: run.trials must be an integer in \[1, 1000000\], got 0"),
        (("[learner]", '[run]\nencoder = "pca"\n\n[learner]'), r"task.toml: run.encoder \(line \d+\): unknown variant `pca`"),
        (('links = ["left_hand", "right_hand"]', 'links = ["left_hand", "left_hand"]'),
         r'constraints\[0\].links must name two different links, got "left_hand" twice'),
    ],
)
def test_bad_task_files_name_the_file_the_key_and_the_rule(tmp_path, edit, message):
    old, new = edit
    assert old in ARMS_TOML
    path = write(tmp_path, ARMS_TOML.replace(old, new, 1))
    with pytest.raises(ValueError, match=message):
        Task.load(path)


def test_a_file_that_is_not_toml_is_refused(tmp_path):
    path = write(tmp_path, "name = \n[[")
    with pytest.raises(ValueError, match=r"task.toml: not valid TOML \(line 1\)"):
        Task.load(path)
    with pytest.raises(ValueError, match="cannot read it"):
        Task.load(tmp_path / "missing.toml")


def test_overrides_apply_by_path_and_are_checked():
    arms = Task.shipped("two_arms")
    quick = arms.replace({"learner.initial_weight": 100.0, "episode.max_steps": 40})
    config = quick.to_dict()
    assert config["learner"]["initial_weight"] == 100.0 and config["episode"]["max_steps"] == 40
    assert arms.to_dict()["learner"]["initial_weight"] == 0.0, "the original is unchanged"
    with pytest.raises(ValueError, match=r"learner.alpha must lie in \(0, 1\], got 0"):
        arms.replace({"learner.alpha": 0.0})
    with pytest.raises(ValueError, match="unknown field `alpah`"):
        arms.replace({"learner.alpah": 0.5})
    with pytest.raises(ValueError, match="unknown field `gravty`"):
        arms.replace({"physics.gravty": [0, 0, 0]})
    assert arms.replace({}) is arms


def test_a_task_from_a_dict_round_trips_and_its_digest_sees_changes():
    arms = Task.shipped("two_arms")
    again = Task.from_dict(arms.to_dict(), arms.base_dir)
    assert again.to_dict() == arms.to_dict() and again.digest() == arms.digest()
    assert arms.replace({"learner.beta": 5.0}).digest() != arms.digest()


def test_the_schema_lists_every_key_with_doc_rule_kind_and_default():
    keys = {entry["key"]: entry for entry in schema()}
    for key in ("urdf", "learner.gamma", "physics.dt", "episode.start", "constraints[].kind", "obstacles[].test",
                "fall.max_tilt", "servo.joints.NAME.kp", "target.width", "waypoint.axis", "run.trials", "run.encoder"):
        assert key in keys, key
        assert keys[key]["doc"], key
    assert keys["learner.gamma"]["rule"] == "must lie in [0, 1)" and keys["learner.gamma"]["default"] == 0.95
    assert keys["episode.start"]["kind"] == "uniform | demo"
    assert keys["run.encoder"]["kind"] == "gp | projection | back_constrained | tracking"
    assert keys["run.gplvm_max_iter"]["default"] == 1000 and keys["run.latent_margin"]["default"] == 0.1
    assert keys["physics.substeps"]["default"] == 12 and keys["physics.substeps"]["kind"] == "int"


def test_the_plant_classifies_postures_by_the_task_rules():
    arms = Task.shipped("two_arms")
    plant = arms.plant()
    demos = shipped_demos("two_arms")
    codes, effectors, targets = plant.classify(demos[:10])
    assert codes.shape == (10,) and effectors.shape == targets.shape == (10, 6)
    np.testing.assert_array_equal(targets, np.tile(np.ravel(arms.to_dict()["target"]["position"]), (10, 1)))
    assert set(codes) <= {0, 1, 3}, "demos hold the object; some touch the walls"
    assert np.allclose(effectors[:, 3] - effectors[:, 0], 0.1, atol=0.005) or (codes != 0).any()
    bad = demos[:1].copy()
    bad[0, 0] = 100.0
    assert plant.classify(bad)[0][0] == 2, "outside the joint limits"
    lift = Task.shipped("humanoid_lift")
    d = shipped_demos("humanoid_lift")
    codes, _, _ = lift.plant(d).classify(d)
    np.testing.assert_array_equal(codes, [1, 1, 1] + [0] * 11)
    with pytest.raises(ValueError, match=r"postures: expected shape \(M, 19\)"):
        lift.plant(d).classify(np.zeros((2, 4)))


def test_a_demo_start_needs_demonstrations():
    lift = Task.shipped("humanoid_lift").replace({"episode.start": "demo"})
    with pytest.raises(ValueError, match='episode.start = "demo" needs the demonstrations'):
        lift.plant()
    with pytest.raises(ValueError, match="demonstration 0 has 4 values, the robot 19 actuated joints"):
        lift.plant(np.zeros((7, 4)))


def test_check_joints_names_the_file_and_the_columns():
    arms = Task.shipped("two_arms")
    arms.check_joints(arms.joint_names, "demos.csv")
    with pytest.raises(ValueError, match=r"demos.csv: the columns must be the actuated joints .*missing \['right_elbow'\]"):
        arms.check_joints(("left_shoulder", "left_elbow", "right_shoulder"), "demos.csv")
    with pytest.raises(ValueError, match="in another order"):
        arms.check_joints(tuple(reversed(arms.joint_names)), "demos.csv")


def test_a_recorded_posture_past_a_joint_stop_can_be_drawn_but_not_started_from():
    """Driven into its stop, a joint ends a few mrad past its limit (Exp 3 recorded l_knee at
    lower − 2.97 mrad); `pose_links` draws such a row, a reset refuses it as no posture of the
    robot (a box exit)."""
    task = Task.shipped("humanoid_lift")
    plant = task.plant(shipped_demos("humanoid_lift"))
    posture = shipped_demos("humanoid_lift")[4].copy()
    knee = task.joint_names.index("l_knee")
    base = np.array([0.0, 0.0, 0.3, 0.0, 0.0, 0.0, 1.0])
    posture[knee] = task.lower[knee]
    at_stop = plant.pose_links(base, posture)
    posture[knee] = task.lower[knee] - 3e-3
    past = plant.pose_links(base, posture)
    foot = task.link_names.index("l_foot")
    moved = np.linalg.norm(past[foot, :3] - at_stop[foot, :3])
    assert 0 < moved < 3e-3, moved  # 3 mrad on a shin of < 0.1 m
    code = plant.reset(posture)
    assert code is not None and end_reasons()[code] == "box_exit"


def test_a_task_file_with_a_byte_order_mark_loads(tmp_path):
    """A UTF-8 byte-order mark (Windows editors write one): the native reader skipped it, the
    Python reader of the file's keys failed with "Invalid statement (at line 1, column 1)", naming
    no file."""
    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    (tmp_path / "glass_arm.urdf").write_bytes((example / "glass_arm.urdf").read_bytes())
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + (example / "glass_arm.toml").read_bytes())
    task = Task.load(path)
    assert task.given == Task.load(example / "glass_arm.toml").given
    assert task.to_dict() == Task.load(example / "glass_arm.toml").to_dict()


def test_a_robot_that_cannot_move_or_a_sole_without_a_box_is_refused_at_load(tmp_path):
    """Both loaded: the first then failed `check` on its demo columns ("missing []"), the second
    on its first reset ("invalid parameter sole = NaN")."""
    glass = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    (tmp_path / "glass_arm.urdf").write_text((glass / "glass_arm.urdf").read_text().replace('type="revolute"', 'type="fixed"'))
    (tmp_path / "task.toml").write_text((glass / "glass_arm.toml").read_text())
    with pytest.raises(ValueError, match=r'urdf: the robot "glass_arm" has no actuated joint'):
        Task.load(tmp_path / "task.toml")
    lift = shipped_path("humanoid_lift")
    text = lift.read_text()
    soles = next(line for line in text.splitlines() if line.startswith("soles"))
    path = write(tmp_path, text.replace(soles, 'soles = ["l_hand"]'), "lift.toml")
    with pytest.raises(ValueError, match=r'fall.soles\[0\]: link "l_hand" has no collision shape'):
        Task.load(path)
