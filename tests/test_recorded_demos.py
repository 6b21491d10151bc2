"""Demonstrations as recorders write them (issue #40, items 1, 2 and 4): LeRobot datasets, robomimic
HDF5 and ROS 1/2 bags, each written here by the format's own library (pyarrow, h5py, rosbags),
read through `load_demos` and every `--demos`; joint matching, units, episodes, farthest-point
selection, the size cap, and a clear one-line error for each bad file."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from latentrl import Demonstrations, Task, cli, load_demos, save_demos
from latentrl.recorded import frames as frames_module
from latentrl.recorded.options import joint_map
from latentrl.recorded.sampling import farthest_points

from recorded_writers import NAMES, episodes_of, write_bag, write_episode, write_hdf5, write_lerobot, write_lerobot_v3

ROOT = Path(__file__).resolve().parents[1]
RNG = np.random.default_rng(0)


def bag_path(tmp_path: Path, ros: int) -> Path:
    return tmp_path / ("demo.bag" if ros == 1 else "demo_bag")


# --- reading ---------------------------------------------------------------------------------

def test_a_lerobot_dataset_loads_with_its_episodes(tmp_path):
    episodes = episodes_of()
    write_lerobot(tmp_path / "ds", episodes, value_type=pa.float64())
    demos = load_demos(tmp_path / "ds")
    np.testing.assert_array_equal(demos.postures, np.concatenate(episodes))
    assert demos.joint_names == NAMES
    assert demos.episodes.tolist() == [0] * 5 + [1] * 7 + [2] * 4
    assert demos.frames.tolist() == [*range(5), *range(7), *range(4)]
    assert not demos.episodes.flags.writeable


def test_lerobot_float32_names_as_v2_0_dict_and_another_state_column(tmp_path):
    episodes = episodes_of()
    write_lerobot(tmp_path / "ds", episodes, names={"motors": list(NAMES)}, key="observation.joints")
    demos = load_demos(tmp_path / "ds", key="observation.joints")
    np.testing.assert_allclose(demos.postures, np.concatenate(episodes), atol=1e-6)
    with pytest.raises(ValueError, match=r"info.json: no feature 'observation.state'; its float features are "
                                         r"\['action', 'observation.joints', 'timestamp'\]"):
        load_demos(tmp_path / "ds")


def test_a_lerobot_v3_dataset_loads_each_episode_from_the_file_its_table_names(tmp_path):
    """v3.0 packs several episodes into one data file; the episode table says which file holds
    each and how many frames it has: the same postures, episodes and frames as v2.1's layout."""
    episodes = episodes_of((5, 7, 4, 6, 3))
    write_lerobot_v3(tmp_path / "v3", episodes, per_file=2)
    write_lerobot(tmp_path / "v2", episodes)
    v3, v2 = load_demos(tmp_path / "v3"), load_demos(tmp_path / "v2")
    np.testing.assert_array_equal(v3.postures, np.concatenate(episodes).astype(np.float32))
    np.testing.assert_array_equal(v3.postures, v2.postures)
    assert v3.joint_names == NAMES and v3.episodes.tolist() == v2.episodes.tolist()
    assert v3.frames.tolist() == v2.frames.tolist()
    sampled = load_demos(tmp_path / "v3", max_postures=10)
    assert len(sampled.postures) == 10 and set(sampled.episodes.tolist()) <= set(range(5))


def test_a_broken_lerobot_v3_dataset_is_named(tmp_path):
    episodes = episodes_of((5, 7, 4))
    root = write_lerobot_v3(tmp_path / "short", episodes)
    table = root / "meta" / "episodes" / "chunk-000" / "file-000.parquet"
    rows = pq.read_table(table).to_pylist()
    rows[1]["dataset_to_index"] += 2  # the table claims 9 frames for episode 1
    pq.write_table(pa.Table.from_pylist(rows), table)
    with pytest.raises(ValueError, match=r"file-000\.parquet: 7 rows of episode_index 1, where the episode table gives 9"):
        load_demos(root)
    root = write_lerobot_v3(tmp_path / "nocol", episodes)
    pq.write_table(pa.Table.from_pylist([{"episode_index": 0}]), root / "meta" / "episodes" / "chunk-000" / "file-000.parquet")
    with pytest.raises(ValueError, match=r"file-000\.parquet: no columns \['data/chunk_index'"):
        load_demos(root)
    root = write_lerobot_v3(tmp_path / "escape", episodes)
    info = json.loads((root / "meta" / "info.json").read_text())
    (root / "meta" / "info.json").write_text(json.dumps({**info, "data_path": "../../x/file-{file_index:03d}.parquet"}))
    with pytest.raises(ValueError, match=r"data_path '\.\./\.\./x/file-\{file_index:03d\}\.parquet' leads out of the dataset"):
        load_demos(root)
    (root / "meta" / "info.json").write_text(json.dumps({**info, "data_path": "data/{episode_chunk}.parquet"}))
    with pytest.raises(ValueError, match=r"data_path 'data/\{episode_chunk\}\.parquet' is no v3 data file template"):
        load_demos(root)
    for name, change, said in (
            ("null", {"dataset_from_index": None}, r"\['dataset_from_index'\] must be integers >= 0"),
            ("twice", {"episode_index": 0}, r"the episode table lists episodes \[0\] more than once"),
            ("nofile", {"data/file_index": 7}, r"episode 1's data file .*file-007\.parquet is missing")):
        root = write_lerobot_v3(tmp_path / name, episodes)
        table = root / "meta" / "episodes" / "chunk-000" / "file-000.parquet"
        rows = pq.read_table(table).to_pylist()
        rows[1].update(change)
        pq.write_table(pa.Table.from_pylist(rows), table)
        with pytest.raises(ValueError, match=said):
            load_demos(root)
    # The Hugging Face cache: every file of the snapshot a link to a blob outside its folder.
    built, snapshot, blobs = write_lerobot_v3(tmp_path / "built", episodes), tmp_path / "snapshot", tmp_path / "blobs"
    blobs.mkdir()
    for n, file in enumerate(sorted(p for p in built.rglob("*") if p.is_file())):
        file.rename(blobs / str(n))
        link = snapshot / file.relative_to(built)
        link.parent.mkdir(parents=True, exist_ok=True)
        link.symlink_to(blobs / str(n))
    np.testing.assert_array_equal(load_demos(snapshot).postures, np.concatenate(episodes).astype(np.float32))
    root = write_lerobot_v3(tmp_path / "key", episodes)
    with pytest.raises(ValueError, match=r"no feature 'observation\.effort'; its float features are \['observation\.state'\]"):
        load_demos(root, key="observation.effort")


def test_recorded_joint_names_empty_or_twice_are_refused_as_such(tmp_path):
    """An empty recorded name read as a column a joint map leaves out (dropped without a word);
    a name twice blamed a joint map nobody gave."""
    write_lerobot(tmp_path / "empty", episodes_of(), ["shoulder", "", "wrist"])
    with pytest.raises(ValueError, match=r"recorded joints \[1\] \(counting from 0\) have an empty name"):
        load_demos(tmp_path / "empty")
    write_lerobot(tmp_path / "twice", episodes_of(), ["joint", "joint", "wrist"])
    with pytest.raises(ValueError, match=r"\(observation.state\): joints \['joint'\] name two columns each"):
        load_demos(tmp_path / "twice")


def test_a_one_joint_lerobot_feature_stored_as_a_plain_column_loads(tmp_path):
    """LeRobot writes a feature of shape (1,) as a scalar column, not a list (helper-32's sweep:
    refused as "holds float")."""
    episodes = episodes_of((4, 6), width=1)
    write_lerobot(tmp_path / "ds", episodes, ("gripper",))
    for index, frames in enumerate(episodes):
        path = tmp_path / "ds" / "data" / "chunk-000" / f"episode_{index:06d}.parquet"
        pq.write_table(pq.read_table(path).set_column(0, "observation.state", pa.array(frames[:, 0], pa.float32())), path)
    np.testing.assert_array_equal(load_demos(tmp_path / "ds").postures, np.concatenate(episodes).astype(np.float32))


def test_an_hdf5_demo_naming_its_joints_in_another_order_is_read_in_the_first_ones(tmp_path):
    """Each demo's dataset may carry its own joint names: a demo in another order was read by
    position, its joints swapped without a word (helper-32's sweep); other names are refused,
    and two groups of one episode index (demo_1, demo_01) too."""
    episodes = episodes_of((4, 5))
    path = write_hdf5(tmp_path / "d.hdf5", episodes)
    with h5py.File(path, "r+") as f:
        dataset = f["data/demo_1/obs/robot0_joint_pos"]
        dataset[...] = episodes[1][:, ::-1]
        dataset.attrs["joint_names"] = list(NAMES[::-1])
    np.testing.assert_array_equal(load_demos(path).postures, np.concatenate(episodes))
    with h5py.File(path, "r+") as f:
        f["data/demo_1/obs/robot0_joint_pos"].attrs["joint_names"] = ["wrist", "elbow", "knee"]
    with pytest.raises(ValueError, match=r"/data/demo_1/obs/robot0_joint_pos names its joints \['wrist', 'elbow', "
                                         r"'knee'\], not the recording's \['shoulder', 'elbow', 'wrist'\]"):
        load_demos(path)
    path = write_hdf5(tmp_path / "twice.hdf5", episodes_of((4, 5, 6)))
    with h5py.File(path, "r+") as f:
        f.move("data/demo_2", "data/demo_01")
    with pytest.raises(ValueError, match=r"data/demo_01 and data/demo_1 are both episode 1: rename one"):
        load_demos(path)


@pytest.mark.parametrize("names_on", ["dataset", "data", "given"])
def test_a_robomimic_hdf5_loads_its_names_from_an_attribute_or_the_caller(tmp_path, names_on):
    episodes = episodes_of()
    path = write_hdf5(tmp_path / "demos.hdf5", episodes, None if names_on == "given" else NAMES, names_on=names_on)
    demos = load_demos(path, joint_names=NAMES if names_on == "given" else None)
    np.testing.assert_array_equal(demos.postures, np.concatenate(episodes))
    assert demos.joint_names == NAMES and demos.episodes.tolist() == [0] * 5 + [1] * 7 + [2] * 4


@pytest.mark.parametrize("ros", [1, 2, "2-mcap"])
def test_a_ros_bag_of_joint_states_loads_each_message_by_its_names(tmp_path, ros):
    frames = episodes_of((40,))[0]
    mcap = ros == "2-mcap"
    path = write_bag(bag_path(tmp_path, 2 if mcap else ros), frames, ros=2 if mcap else ros, shuffle=True, mcap=mcap)
    assert not mcap or (path / "demo_bag.mcap").is_file()
    demos = load_demos(path, expected_joints=NAMES)
    np.testing.assert_array_equal(demos.postures, frames)
    assert demos.episodes.tolist() == [0] * 40 and demos.frames.tolist() == list(range(40))
    with pytest.raises(ValueError, match=r"a bag's JointState messages name their joints; rename them with a joint map"):
        load_demos(path, joint_names=NAMES)


@pytest.mark.filterwarnings("ignore:.*messages come before joint 'gripper' is first named")
@pytest.mark.parametrize("ros", [1, 2])
def test_two_publishers_on_one_topic_are_merged_into_frames_of_the_latest_positions(tmp_path, ros, monkeypatch):
    """An arm driver (NAMES) and a gripper driver (one joint, every third message) on
    /joint_states: each frame holds every joint's latest position, from the first message at
    which both have spoken; a message naming part of one publisher's joints is refused."""
    frames = episodes_of((30,), width=4)[0]
    arm, grip = list(NAMES), ["gripper"]

    def publisher(i, names, positions):
        return (grip, positions[3:]) if i % 3 == 2 else (names[:3], positions[:3])

    path = write_bag(bag_path(tmp_path, ros), frames, [*NAMES, "gripper"], ros=ros, message=publisher)
    latest, expected = np.full(4, np.nan), []
    for i, row in enumerate(frames):
        part = slice(3, 4) if i % 3 == 2 else slice(0, 3)
        latest[part] = row[part]
        if i >= 2:
            expected.append(latest.copy())
    demos = load_demos(path, expected_joints=[*arm, *grip])
    np.testing.assert_array_equal(demos.postures, np.array(expected))
    assert demos.frames.tolist() == list(range(28))
    monkeypatch.setattr(frames_module, "MAX_RECORDED_VALUES", 60)  # past the cap: every 2nd merged frame
    every_other = load_demos(path, expected_joints=[*arm, *grip], max_postures=14)
    np.testing.assert_array_equal(every_other.postures, np.array(expected)[::2])
    assert every_other.frames.tolist() == list(range(0, 28, 2))
    monkeypatch.undo()

    def dropping(i, names, positions):  # a message without the wrist: it holds its last position
        names, positions = publisher(i, names, positions)
        return (names[:2], positions[:2]) if i == 19 else (names, positions)

    path = write_bag(tmp_path / ("drop.bag" if ros == 1 else "drop_bag"), frames, [*NAMES, "gripper"], ros=ros,
                     message=dropping)
    held = np.array(expected)
    held[17:19, 2] = held[16, 2]  # frames 17 and 18 are messages 19 and 20 (the gripper's)
    np.testing.assert_array_equal(load_demos(path).postures, held)


def test_two_publishers_naming_the_same_joints_are_warned_of(tmp_path, recwarn):
    """A stray publisher of zeros beside the driver (two ROS 1 callers, the same joints): their
    messages interleave, which no reading rule undoes (helper-32's sweep: read without a word)."""
    from rosbags.rosbag1 import Writer
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC)
    state, header, time = (store.types[t] for t in
                           ("sensor_msgs/msg/JointState", "std_msgs/msg/Header", "builtin_interfaces/msg/Time"))

    def write(path, callers):
        with Writer(path) as writer:
            connections = {c: writer.add_connection("/joint_states", state.__msgtype__, typestore=store, callerid=c)
                           for c, _ in callers}
            for i in range(20):
                caller, names = callers[i % len(callers)]
                msg = state(header=header(seq=i, stamp=time(sec=i, nanosec=0), frame_id=""), name=names,
                            position=np.full(len(names), i / 10), velocity=np.zeros(0), effort=np.zeros(0))
                writer.write(connections[caller], 1_000_000 * (i + 1), store.serialize_ros1(msg, state.__msgtype__))
        return path

    load_demos(write(tmp_path / "same.bag", [("/ur_driver", list(NAMES)), ("/joint_state_publisher", list(NAMES))]))
    said = [str(w.message) for w in recwarn]
    assert any("publishers /joint_state_publisher and /ur_driver both name joints ['elbow', 'shoulder', 'wrist']"
               in m for m in said), said
    recwarn.clear()
    load_demos(write(tmp_path / "apart.bag", [("/ur_driver", list(NAMES)), ("/gripper", ["finger"])]))
    assert not any("both name joints" in str(w.message) for w in recwarn)


@pytest.mark.parametrize("ros", [1, 2])
def test_a_bag_is_read_as_a_subscriber_sees_it(tmp_path, ros, recwarn):
    """Publishers that start late, publish velocities only, or republish every joint beside a
    driver of some (helper-32's sweep: each was refused before, with no option to read it)."""
    frames = episodes_of((30,), width=4)[0]
    def late(i, n, p):
        return (n[:3], p[:3]) if i < 10 else (n, p)  # the gripper's first message is message 10
    path = write_bag(bag_path(tmp_path, ros), frames, [*NAMES, "gripper"], ros=ros, message=late)
    demos = load_demos(path)
    np.testing.assert_array_equal(demos.postures, frames[10:])
    assert demos.frames.tolist() == list(range(20))
    assert any("its first 10 messages come before joint 'gripper' is first named (message 10)" in str(w.message)
               for w in recwarn)
    def velocity(i, n, p):
        return (["wheel"], np.zeros(0)) if i % 4 == 3 else (n, p)  # names, no positions
    path = write_bag(tmp_path / ("v.bag" if ros == 1 else "v_bag"), frames[:, :3], ros=ros, message=velocity)
    np.testing.assert_array_equal(load_demos(path).postures, frames[[i for i in range(30) if i % 4 != 3], :3])
    def empty_first(i, n, p):
        return ([], np.zeros(0)) if i == 0 else (n, p)
    path = write_bag(tmp_path / ("e.bag" if ros == 1 else "e_bag"), frames[:, :3], ros=ros, message=empty_first)
    np.testing.assert_array_equal(load_demos(path).postures, frames[1:, :3])


def test_joints_are_matched_by_name_extras_dropped_missing_refused(tmp_path):
    episodes = episodes_of(width=4)
    names = ["l_shoulder", "elbow", "gripper", "wrist"]
    write_lerobot(tmp_path / "ds", episodes, names, value_type=pa.float64())
    demos = load_demos(tmp_path / "ds", expected_joints=["wrist", "shoulder", "elbow"],
                       joint_map={"l_shoulder": "shoulder"})
    np.testing.assert_array_equal(demos.postures, np.concatenate(episodes)[:, [3, 0, 1]])
    with pytest.raises(ValueError, match=r"ds \(observation.state\): joints \['shoulder'\] are not in the recording, "
                                         r"which has \['l_shoulder', 'elbow', 'gripper', 'wrist'\]"):
        load_demos(tmp_path / "ds", expected_joints=["shoulder", "elbow", "wrist"])
    with pytest.raises(ValueError, match=r"the joint map renames \['hip'\], which are not among the joints"):
        load_demos(tmp_path / "ds", joint_map={"hip": "knee"})
    with pytest.raises(ValueError, match=r"after the joint map, joints \['elbow'\] name two columns each"):
        load_demos(tmp_path / "ds", joint_map={"wrist": "elbow"})


def test_a_joint_map_renames_the_columns_of_a_csv_too(tmp_path):
    save_demos(Demonstrations(np.zeros((2, 2)), ("a", "b")), tmp_path / "d.csv")
    assert load_demos(tmp_path / "d.csv", joint_map={"a": "x"}, expected_joints=["b", "x"]).joint_names == ("b", "x")
    with pytest.raises(ValueError, match=r"d.csv: a file of postures names its joints; key and joint names"):
        load_demos(tmp_path / "d.csv", key="observation.state")


def test_a_joint_map_leaves_out_the_columns_it_maps_to_nothing(tmp_path):
    """A recorder's CSV with a time stamp and a gripper: `--joint-map time=,gripper=` keeps the
    joints; in a recording (fit, no task) the column is left out too."""
    values = np.arange(12.0).reshape(3, 4)
    save_demos(Demonstrations(values, ("time", "b", "gripper", "a")), tmp_path / "d.csv")
    drop = joint_map("time=, gripper=")
    assert drop == {"time": "", "gripper": ""}
    demos = load_demos(tmp_path / "d.csv", joint_map=drop, expected_joints=["a", "b"])
    assert demos.joint_names == ("a", "b")
    np.testing.assert_array_equal(demos.postures, values[:, [3, 1]])
    assert load_demos(tmp_path / "d.csv", joint_map={"time": "", "a": "x"}).joint_names == ("b", "gripper", "x")
    with pytest.raises(ValueError, match=r"d.csv: joint names do not match the expected ones: missing \[\], "
                                         r"unknown \['time', 'gripper'\]"):
        load_demos(tmp_path / "d.csv", expected_joints=["a", "b"])
    with pytest.raises(ValueError, match=r"the joint map renames \['stamp'\], which are not among the joints"):
        load_demos(tmp_path / "d.csv", joint_map={"stamp": ""})
    with pytest.raises(ValueError, match=r"d.csv: demo columns: the joint map leaves out every column$"):
        load_demos(tmp_path / "d.csv", joint_map=dict.fromkeys(("time", "b", "gripper", "a"), ""))
    episodes = episodes_of(width=4)
    write_lerobot(tmp_path / "ds", episodes, ["shoulder", "elbow", "gripper", "wrist"], value_type=pa.float64())
    demos = load_demos(tmp_path / "ds", joint_map={"gripper": ""})
    assert demos.joint_names == ("shoulder", "elbow", "wrist")
    with pytest.raises(ValueError, match=r"ds \(observation.state\): the joint map leaves out every column$"):
        load_demos(tmp_path / "ds", joint_map=dict.fromkeys(("shoulder", "elbow", "gripper", "wrist"), ""))
    np.testing.assert_array_equal(demos.postures, np.concatenate(episodes)[:, [0, 1, 3]])


def test_degrees_are_refused_and_converted_on_request(tmp_path):
    episodes = [np.degrees(e) for e in episodes_of()]
    path = write_hdf5(tmp_path / "deg.h5", episodes)
    with pytest.raises(ValueError, match=r"deg.h5 \(robot0_joint_pos\): joint '\w+' is -?\d+\.?\d* at episode \d, "
                                         r"frame \d, beyond ±2π: the recording looks like degrees; give --degrees"):
        load_demos(path)
    demos = load_demos(path, degrees=True)
    np.testing.assert_allclose(demos.postures, np.concatenate(episodes_of()))
    # Only the kept joints count: a gripper in millimetres, dropped, is no reason to refuse.
    wide = [np.column_stack([e, np.full(len(e), 40.0)]) for e in episodes_of()]
    path = write_hdf5(tmp_path / "mm.h5", wide, (*NAMES, "gripper_mm"))
    assert load_demos(path, expected_joints=NAMES).postures.shape == (16, 3)


def test_a_tasks_demos_convert_only_its_angular_joints_and_drop_a_mimic_column(tmp_path):
    """`--degrees` converted a prismatic finger's metres too (0.02 m became 0.00035) without a word,
    and `load_demos(..., expected_joints=task.joint_names)` refused a mimic column the CLI drops."""
    task = Task.from_dict({"name": "arm7", "urdf": str(ROOT / "tests/robots/arm7_description/urdf/arm7_primitives.urdf"),
                           "root": "fixed", "effectors": ["tcp"], "target": {"position": [[0.4, 0.0, 0.6]]}})
    radians = np.array([[0.0, 0.3, 0.0, -1.8, 0.0, 2.0, 0.8, 0.02], [0.5, 0.6, -0.2, -1.5, 0.3, 2.2, 0.0, 0.04],
                        [-0.4, 0.2, 0.3, -2.2, -0.3, 1.8, -0.8, 0.0]])
    recorded = np.column_stack([np.degrees(radians[:, :7]), radians[:, 7:], radians[:, 7]])  # the mimic finger last
    names = (*task.joint_names, "finger_joint2")
    save_demos(Demonstrations(recorded, names), tmp_path / "d.csv")
    write_hdf5(tmp_path / "d.h5", [recorded[:2], recorded[2:]], names)
    for path in (tmp_path / "d.csv", tmp_path / "d.h5"):
        demos = task.demos(path, degrees=True)
        assert demos.joint_names == task.joint_names
        np.testing.assert_allclose(demos.postures, radians, atol=1e-12)
    assert task.demos(tmp_path / "d.h5", degrees=True).episodes.tolist() == [0, 0, 1]
    with pytest.raises(ValueError, match=r"d.csv: joint names do not match the expected ones: missing \[\], unknown "
                                         r"\['finger_joint2'\] \(a task's demonstrations, a mimic joint's column checked "
                                         r"against its leader and dropped: Task.demos\(path\); a column to leave out: "
                                         r"joint_map=\{'finger_joint2': ''\}\)"):
        load_demos(tmp_path / "d.csv", expected_joints=task.joint_names)
    millimetres = radians.copy()
    millimetres[:, 7] *= 1000  # the finger's 0.02–0.04 m as 20–40 mm
    save_demos(Demonstrations(millimetres, task.joint_names), tmp_path / "mm.csv")
    with pytest.raises(ValueError, match=r"finger_joint1 = 20, beyond ±2π .* finger_joint1 is prismatic, its positions "
                                         r"metres; these look like millimetres or centimetres"):
        task.demos(tmp_path / "mm.csv")


def test_the_save_of_npz_keeps_the_episodes(tmp_path):
    write_lerobot(tmp_path / "ds", episodes_of())
    demos = load_demos(tmp_path / "ds", max_postures=6)
    save_demos(demos, tmp_path / "kept.npz")
    again = load_demos(tmp_path / "kept.npz")
    assert again.episodes.tolist() == demos.episodes.tolist() and again.frames.tolist() == demos.frames.tolist()
    assert load_demos(tmp_path / "kept.npz", max_postures=3).postures.shape == (3, 3)


# --- frames to postures ----------------------------------------------------------------------

def brute_force_fps(X: np.ndarray, m: int) -> list[int]:
    chosen = [0]
    while len(chosen) < m:
        d = np.array([min(np.linalg.norm(x - X[c]) for c in chosen) for x in X])
        if d.max() == 0:
            break
        chosen.append(int(np.argmax(d)))
    return sorted(chosen)


def test_farthest_point_sampling_is_the_documented_rule():
    X = RNG.normal(size=(300, 4))
    for m in (1, 2, 17, 60):
        assert farthest_points(X, m).tolist() == brute_force_fps(X, m)
    assert farthest_points(X, 500).tolist() == list(range(300))
    # A recorder dwelling at rest: the copies count once, and sampling stops when all are taken.
    rest = np.repeat(np.eye(3), 50, axis=0)
    assert farthest_points(rest, 10).tolist() == [0, 50, 100]


def test_max_postures_picks_the_spread_and_keeps_the_recorded_order(tmp_path):
    # 1000 frames dwelling near 0, then a sweep to 1.2 rad: the sweep's extremes are kept.
    dwell = RNG.normal(scale=1e-3, size=(1000, 3))
    sweep = np.linspace(0, 1.2, 50)[:, None] * np.ones(3)
    write_lerobot(tmp_path / "ds", [dwell, sweep], value_type=pa.float64())
    demos = load_demos(tmp_path / "ds", max_postures=10)
    assert len(demos.postures) == 10 and demos.frames[0] == 0 and demos.episodes[0] == 0
    assert (np.diff(demos.episodes * 10_000 + demos.frames) > 0).all(), "recorded order"
    assert demos.episodes.tolist().count(1) >= 8 and 49 in demos.frames[demos.episodes == 1]
    assert load_demos(tmp_path / "ds", max_postures=10).frames.tolist() == demos.frames.tolist()
    with pytest.raises(ValueError, match="max_postures must be an int >= 1 or None, got 0"):
        load_demos(tmp_path / "ds", max_postures=0)


def test_past_the_cap_nothing_is_read_without_max_postures_and_every_kth_frame_with_it(tmp_path, monkeypatch):
    from latentrl.recorded.lerobot import LeRobotDataset

    write_lerobot(tmp_path / "ds", episodes_of((30, 30)), value_type=pa.float64())
    monkeypatch.setattr(frames_module, "MAX_RECORDED_VALUES", 60)
    reads = []
    original = LeRobotDataset.read
    monkeypatch.setattr(LeRobotDataset, "read", lambda self, e, step: reads.append(step) or original(self, e, step))
    with pytest.raises(ValueError, match=r"ds: 60 frames of 3 values \(180 values\) are more than the 60 a recording "
                                         r"may bring into memory .*; give --max-postures N"):
        load_demos(tmp_path / "ds")
    assert reads == [], "refused from metadata, before any frame is read"
    demos = load_demos(tmp_path / "ds", max_postures=12)
    assert reads == [3, 3] and len(demos.postures) == 12 and set(demos.frames.tolist()) <= set(range(0, 30, 3))


# --- bad files: one clear error each, naming file and field ------------------------------------

def bad_lerobot(tmp_path: Path, case: str) -> tuple[Path, dict]:
    ds, eps = tmp_path / "ds", episodes_of()
    kwargs: dict = {}
    if case == "no names":
        write_lerobot(ds, eps, names=None)
    elif case == "NaN frame":
        eps[1][3, 2] = np.nan
        write_lerobot(ds, eps)
    elif case == "empty episode":
        eps[2] = np.zeros((0, 3))
        write_lerobot(ds, eps)
    elif case == "mixed shapes":
        write_lerobot(ds, eps[:2], total_episodes=3)
        write_episode(ds, 2, [[0.1, 0.2, 0.3], [0.1, 0.2]])
    elif case == "truncated":
        write_lerobot(ds, eps)
        file = ds / "data" / "chunk-000" / "episode_000001.parquet"
        file.write_bytes(file.read_bytes()[:-100])
    elif case == "missing episode file":
        write_lerobot(ds, eps)
        (ds / "data" / "chunk-000" / "episode_000001.parquet").unlink()
    elif case == "missing column":
        write_lerobot(ds, eps)
        kwargs = {"key": "observation.effort"}
        info = json.loads((ds / "meta" / "info.json").read_text())
        info["features"]["observation.effort"] = dict(info["features"]["observation.state"])
        (ds / "meta" / "info.json").write_text(json.dumps(info))
    elif case == "wrong joint names":
        write_lerobot(ds, eps, names=["a", "b", "c"])
        kwargs = {"expected_joints": NAMES}
    return ds, kwargs


def bad_hdf5(tmp_path: Path, case: str) -> tuple[Path, dict]:
    path, eps = tmp_path / "demos.hdf5", episodes_of()
    kwargs: dict = {}
    if case == "no names":
        write_hdf5(path, eps, None)
    elif case == "NaN frame":
        eps[2][1, 0] = np.nan
        write_hdf5(path, eps)
    elif case == "empty episode":
        eps[0] = np.zeros((0, 3))
        write_hdf5(path, eps)
    elif case == "mixed shapes":
        eps[1] = np.zeros((7, 4))
        write_hdf5(path, eps, names=None)
        kwargs = {"joint_names": NAMES}
    elif case == "truncated":
        write_hdf5(path, eps)
        path.write_bytes(path.read_bytes()[:1500])
    elif case == "missing key":
        write_hdf5(path, eps)
        kwargs = {"key": "robot0_eef_pos"}
    elif case == "wrong joint names":
        write_hdf5(path, eps, ("a", "b", "c"))
        kwargs = {"expected_joints": NAMES}
    elif case == "moved external demo":  # a demo kept in a file of its own that was not copied along
        write_hdf5(path, eps)
        with h5py.File(path, "r+") as f:
            del f["data/demo_1"]
            f["data/demo_1"] = h5py.ExternalLink("demo_1.hdf5", "/data/demo_1")
    elif case == "broken soft link":
        write_hdf5(path, eps)
        with h5py.File(path, "r+") as f:
            f["data/demo_2/obs/robot0_joint_pos"].parent.move("robot0_joint_pos", "old")
            f["data/demo_2/obs/robot0_joint_pos"] = h5py.SoftLink("/data/demo_2/obs/gone")
    elif case == "not robomimic":
        with h5py.File(path, "w") as f:
            f.create_dataset("postures", data=np.zeros((3, 3)))
    return path, kwargs


def bad_bag(tmp_path: Path, case: str, ros: int) -> tuple[Path, dict]:
    path, frames = bag_path(tmp_path, ros), episodes_of((12,))[0]
    kwargs: dict = {}
    if case == "NaN frame":
        frames[4, 1] = np.nan
        write_bag(path, frames, ros=ros)
    elif case == "empty topic":
        write_bag(path, frames[:0], ros=ros)
    elif case == "mixed shapes":
        write_bag(path, frames, ros=ros, message=lambda i, n, p: (n, p[:2] if i == 5 else p))
    elif case == "empty joint name":
        write_bag(path, frames, ros=ros, message=lambda i, n, p: ([*n[:2], ""], p) if i == 6 else (n, p))
    elif case == "truncated":
        write_bag(path, frames, ros=ros)
        file = path if ros == 1 else next(path.glob("*.db3"))
        file.write_bytes(file.read_bytes()[: len(file.read_bytes()) // 2])
    elif case == "missing topic":
        write_bag(path, frames, ros=ros, topic="/robot/joint_states")
    elif case == "wrong joint names":
        write_bag(path, frames, ("a", "b", "c"), ros=ros)
        kwargs = {"expected_joints": NAMES}
    elif case == "not joint states":
        write_bag(path, frames, ros=ros)
        kwargs = {"key": "/tf_like"}
    return path, kwargs


ERRORS = {  # (format, bad file) → what its error says
    ("lerobot", "no names"): r"info.json: features.observation.state has no names; give the joint names \(--joint-names",
    ("lerobot", "NaN frame"): r"episode_000001.parquet: episode 1, frame 3, joint 'wrist': nan",
    ("lerobot", "empty episode"): r"episode_000002.parquet: episode 2 has no frames",
    ("lerobot", "mixed shapes"): r"episode_000002.parquet: column 'observation.state': frame 1 has 2 values, expected 3",
    ("lerobot", "truncated"): r"episode_000001.parquet: not a readable parquet file \(cut short\?\)",
    ("lerobot", "missing episode file"): r"info.json: total_episodes is 3, but .*ds/data holds 2 episode files",
    ("lerobot", "missing column"): r"episode_000000.parquet: no column 'observation.effort'; it has \['observation.state'",
    ("lerobot", "wrong joint names"): r"ds \(observation.state\): joints \['shoulder', 'elbow', 'wrist'\] are not in the recording, "
                                      r"which has \['a', 'b', 'c'\]",
    ("hdf5", "no names"): r"demos.hdf5: no 'joint_names' attribute on data/demo_\*/obs/robot0_joint_pos or data; give the joint",
    ("hdf5", "NaN frame"): r"demos.hdf5: data/demo_2/obs/robot0_joint_pos: episode 2, frame 1, joint 'shoulder': nan",
    ("hdf5", "empty episode"): r"demos.hdf5: data/demo_0/obs/robot0_joint_pos: episode 0 has no frames",
    ("hdf5", "mixed shapes"): r"demos.hdf5: data/demo_1/obs/robot0_joint_pos has 4 values per frame, the episodes before it 3",
    ("hdf5", "truncated"): r"demos.hdf5: not a readable HDF5 file \(cut short\?\)",
    ("hdf5", "missing key"): r"demos.hdf5: no dataset data/demo_0/obs/robot0_eef_pos; data/demo_0/obs has \['object', "
                              r"'robot0_joint_pos'\]",
    ("hdf5", "wrong joint names"): r"demos.hdf5 \(robot0_joint_pos\): joints \['shoulder', 'elbow', 'wrist'\] are not in",
    ("hdf5", "moved external demo"): r"demos.hdf5: data/demo_1 links to /data/demo_1 in demo_1.hdf5, which cannot be "
                                      r"opened \(moved or not copied\?\)",
    ("hdf5", "broken soft link"): r"demos.hdf5: data/demo_2/obs/robot0_joint_pos links to /data/demo_2/obs/gone, "
                                   r"which is not in the file",
    ("hdf5", "not robomimic"): r"demos.hdf5: no group 'data' \(the robomimic layout",
    ("ros", "NaN frame"): r"topic /joint_states: episode 0, frame 4, joint 'elbow': nan",
    ("ros", "empty topic"): r"topic /joint_states: episode 0 has no frames",
    ("ros", "mixed shapes"): r"topic /joint_states: message 5: 2 positions for 3 joint names \(\['shoulder', 'elbow', 'wrist'\]\)",
    ("ros", "empty joint name"): r"topic /joint_states: message 6 names a joint with an empty name \(\['shoulder', 'elbow', ''\]\)",
    ("ros", "truncated"): r"not a readable ROS bag \(cut short\?\)",
    ("ros", "missing topic"): r"no topic '/joint_states'; its JointState topics are \['/robot/joint_states'\]",
    ("ros", "wrong joint names"): r"\(/joint_states\): joints \['shoulder', 'elbow', 'wrist'\] are not in the recording",
    ("ros", "not joint states"): r"topic /tf_like carries \['std_msgs/msg/String'\], not sensor_msgs/JointState",
}
MAKERS = {"lerobot": bad_lerobot, "hdf5": bad_hdf5, "ros1": lambda p, c: bad_bag(p, c, 1),
          "ros2": lambda p, c: bad_bag(p, c, 2)}
BAD = [(kind, case) for kind in MAKERS for fmt, case in ERRORS if fmt == kind.rstrip("12")]


@pytest.mark.parametrize(("kind", "case"), BAD)
def test_a_bad_recording_is_named(tmp_path, kind, case):
    path, kwargs = MAKERS[kind](tmp_path, case)
    with pytest.raises(ValueError, match=ERRORS[kind.rstrip("12"), case]) as caught:
        load_demos(path, **kwargs)
    assert str(path) in str(caught.value)


def test_folders_that_are_no_recording_are_named(tmp_path):
    (tmp_path / "empty").mkdir()
    with pytest.raises(ValueError, match=r"empty: a folder, but neither a LeRobot dataset \(no meta/info.json\) nor"):
        load_demos(tmp_path / "empty")
    (tmp_path / "bag").mkdir()
    (tmp_path / "bag" / "bag_0.db3").write_bytes(b"x")
    with pytest.raises(ValueError, match=r"a ROS 2 bag is read as its folder \(with metadata.yaml\): give .*bag$"):
        load_demos(tmp_path / "bag" / "bag_0.db3")
    (tmp_path / "bag" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    with pytest.raises(ValueError, match=r"metadata.yaml: a ROS 2 bag is read as its folder .*: give .*bag$"):
        load_demos(tmp_path / "bag" / "metadata.yaml")
    write_lerobot(tmp_path / "ds", episodes_of())
    with pytest.raises(ValueError, match=r"info.json: a LeRobot dataset is read as its folder .*: give .*ds$"):
        load_demos(tmp_path / "ds" / "meta" / "info.json")
    with pytest.raises(FileNotFoundError):
        load_demos(tmp_path / "absent.hdf5")


# --- the command line, the optional libraries -------------------------------------------------

def test_cli_errors_are_one_line_naming_file_and_field(tmp_path, capsys):
    path, _ = bad_hdf5(tmp_path, "NaN frame")
    assert cli.main(["fit", str(path), "--out", str(tmp_path / "m.npz")]) == 1
    err = capsys.readouterr().err
    assert err.startswith("latentrl: error: ") and "Traceback" not in err and err.count("\n") == 1
    assert "data/demo_2/obs/robot0_joint_pos: episode 2, frame 1, joint 'shoulder': nan" in err
    assert cli.main(["fit", str(path), "--joint-map", "shoulder", "--out", str(tmp_path / "m.npz")]) == 1
    assert "joint_map: expected old=new[,old=new…] (old= leaves a column out), got 'shoulder'" in capsys.readouterr().err


def test_cli_fit_reads_a_recording_with_its_flags(tmp_path, capsys):
    episodes = [np.degrees(e) for e in episodes_of((40, 40), width=4)]
    write_lerobot(tmp_path / "ds", episodes, ["a", "b", "c", "d"])
    assert cli.main(["fit", str(tmp_path / "ds"), "--model", "pca", "--degrees", "--max-postures", "20",
                     "--joint-map", "a=x,b=y", "--out", str(tmp_path / "m.npz")]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary["postures"] == 20 and summary["episodes"] == 2 and summary["joint_names"] == ["x", "y", "c", "d"]


def test_importing_latentrl_imports_no_format_library():
    code = ("import sys, latentrl, latentrl.cli, latentrl.recorded, latentrl.experiments.training; "
            "print(sorted(m for m in ('pyarrow', 'h5py', 'rosbags') if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=True)
    assert done.stdout.strip() == "[]"


@pytest.mark.parametrize(("library", "extra", "make"), [
    ("pyarrow", "lerobot", lambda p: write_lerobot(p / "ds", episodes_of())),
    ("h5py", "hdf5", lambda p: write_hdf5(p / "d.h5", episodes_of())),
    ("rosbags", "rosbag", lambda p: write_bag(p / "d.bag", episodes_of((3,))[0])),
])
def test_a_missing_library_names_its_extra(tmp_path, monkeypatch, capsys, library, extra, make):
    path = make(tmp_path)
    for name in [m for m in sys.modules if m == library or m.startswith(library + ".")]:
        monkeypatch.setitem(sys.modules, name, None)  # import of it fails as if not installed
    monkeypatch.setitem(sys.modules, library, None)
    with pytest.raises(ModuleNotFoundError, match=rf"needs {library}: pip install 'latentrl\[{extra}\]'"):
        load_demos(path)
    assert cli.main(["fit", str(path), "--out", str(tmp_path / "m.npz")]) == 1
    assert capsys.readouterr().err == f"latentrl: error: reading {'a LeRobot dataset' if extra == 'lerobot' else 'HDF5' if extra == 'hdf5' else 'a ROS bag'} needs {library}: pip install 'latentrl[{extra}]'\n"


# --- training from a recording of a shipped robot --------------------------------------------

TRAIN = ["--quick", "--trials", "1", "--episodes", "12", "--test-episodes", "2", "--gplvm-max-iter", "40",
         "--episode.max-steps", "40", "--no-progress"]


def test_train_from_a_recorded_dataset_is_train_from_the_csv(tmp_path, capsys):
    """Experiment 2's arms: its 123 demo postures as a LeRobot recording of 3 episodes with a
    gripper joint and one joint under another name train exactly as the CSV does."""
    task = Task.shipped("two_arms")
    task_file = ROOT / "python" / "latentrl" / "tasks" / "two_arms.toml"
    postures = load_demos(ROOT / "python" / "latentrl" / "data" / "two_arms_demos.csv",
                          expected_joints=task.joint_names).postures
    recorded = np.column_stack([postures, np.linspace(0, 0.04, len(postures))])
    names = ["L_shoulder", *task.joint_names[1:], "gripper"]
    write_lerobot(tmp_path / "arms", np.array_split(recorded, 3), names, value_type=pa.float64())
    save_demos(Demonstrations(postures, task.joint_names), tmp_path / "arms.csv")
    runs = {}
    for name, demos, extra in (("csv", tmp_path / "arms.csv", []),
                               ("lerobot", tmp_path / "arms", ["--joint-map", f"L_shoulder={task.joint_names[0]}"])):
        out = tmp_path / f"run_{name}"
        assert cli.main(["train", str(task_file), "--demos", str(demos), "--out", str(out), *TRAIN, *extra]) == 0
        with np.load(out / "returns.npz") as npz:
            runs[name] = {k: npz[k] for k in npz.files}
        runs[name]["digest"] = json.loads((out / "results.json").read_text())["setup"]["inputs"]["demos"]
    capsys.readouterr()
    assert runs["csv"]["digest"] == runs["lerobot"]["digest"], "the learner gets the same postures"
    presets = [json.loads(str(runs[name].pop("preset_json"))) for name in ("csv", "lerobot")]
    assert {k for k in presets[0] if presets[0][k] != presets[1][k]} == {"demos", "joint_map"}
    assert runs["csv"].keys() == runs["lerobot"].keys()
    for key in runs["csv"]:
        np.testing.assert_array_equal(runs["csv"][key], runs["lerobot"][key], err_msg=key)
    # check reads the same way, and refuses the recording without the rename, naming the joint.
    assert cli.main(["check", str(task_file), "--demos", str(tmp_path / "arms"), "--quick", "--no-progress",
                     "--gplvm-max-iter", "40", "--joint-map", f"L_shoulder={task.joint_names[0]}"]) in (0, 3)
    capsys.readouterr()
    assert cli.main(["train", str(task_file), "--demos", str(tmp_path / "arms"), "--out", str(tmp_path / "bad"),
                     *TRAIN]) == 1
    err = capsys.readouterr().err
    assert f"joints ['{task.joint_names[0]}'] are not in the recording" in err and not (tmp_path / "bad").exists()


# --- 100 000 frames in each format -----------------------------------------------------------

def test_100k_frames_in_each_format_load_with_max_postures(tmp_path_factory):
    """The measurement of docs/demos.md, smaller selection: each recording of 100 000 frames is
    read whole (under the cap) and thinned to 300 postures by `latentrl fit` in a fresh process."""
    out = tmp_path_factory.mktemp("rec100k")
    writer = subprocess.run([sys.executable, str(ROOT / "tests" / "recorded_writers.py"), str(out)],
                            capture_output=True, text=True, timeout=300)
    assert writer.returncode == 0, writer.stderr
    for name in ("lerobot", "robomimic.hdf5", "joint_states.bag", "joint_states_ros2"):
        done = subprocess.run([sys.executable, "-m", "latentrl", "fit", str(out / name), "--model", "pca",
                               "--max-postures", "300", "--out", str(out / f"{name}.npz")],
                              capture_output=True, text=True, timeout=300)
        assert done.returncode == 0, done.stderr
        summary = json.loads(done.stdout)
        assert summary["postures"] == 300 and len(summary["joint_names"]) == 8, summary
        assert summary["episodes"] == (100 if name in ("lerobot", "robomimic.hdf5") else 1)
