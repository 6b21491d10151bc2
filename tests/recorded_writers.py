"""Recordings written by each format's own library, for tests/test_recorded_demos.py and the
measurements of docs/demos.md: a LeRobot v2.1 dataset (pyarrow), robomimic HDF5 (h5py), ROS 1 and
ROS 2 bags of sensor_msgs/JointState (rosbags' writers).

    python tests/recorded_writers.py OUT [--frames 100000]

writes OUT/lerobot/, OUT/robomimic.hdf5, OUT/joint_states.bag and OUT/joint_states_ros2/: the same
frames of a 7-joint arm and its gripper (episodes of 1000 frames; a bag is one episode).
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import h5py
import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
from rosbags.rosbag1 import Writer as Bag1Writer
from rosbags.rosbag2 import StoragePlugin
from rosbags.rosbag2 import Writer as Bag2Writer
from rosbags.typesys import Stores, get_typestore

NAMES = ("shoulder", "elbow", "wrist")
ARM = tuple(f"panda_joint{i}" for i in range(1, 8)) + ("panda_finger_joint1",)


def episodes_of(lengths: tuple[int, ...] = (5, 7, 4), width: int = 3, seed: int = 0) -> list[np.ndarray]:
    rng = np.random.default_rng(seed)
    return [rng.uniform(-1.5, 1.5, size=(n, width)) for n in lengths]


def write_lerobot(folder: Path, episodes: list[np.ndarray], names: tuple[str, ...] | list[str] | dict | None = NAMES, *,
                  key: str = "observation.state", value_type: pa.DataType = pa.float32(),
                  total_episodes: int | None = None) -> Path:
    """A LeRobot v2.1 dataset: meta/info.json and one parquet file per episode."""
    width = episodes[0].shape[1] if episodes and episodes[0].ndim == 2 else 0
    features = {
        key: {"dtype": "float32", "shape": [width], "names": names},
        "action": {"dtype": "float32", "shape": [width], "names": names},
        "timestamp": {"dtype": "float32", "shape": [1], "names": None},
        "frame_index": {"dtype": "int64", "shape": [1], "names": None},
        "episode_index": {"dtype": "int64", "shape": [1], "names": None},
    }
    info = {"codebase_version": "v2.1", "robot_type": "test", "fps": 30, "chunks_size": 1000,
            "total_episodes": len(episodes) if total_episodes is None else total_episodes,
            "total_frames": sum(len(e) for e in episodes),
            "data_path": "data/chunk-{episode_chunk:03d}/episode_{episode_index:06d}.parquet", "features": features}
    (folder / "meta").mkdir(parents=True)
    (folder / "meta" / "info.json").write_text(json.dumps(info))
    for index, frames in enumerate(episodes):
        write_episode(folder, index, frames, key=key, value_type=value_type)
    return folder


def write_lerobot_v3(folder: Path, episodes: list[np.ndarray], names: tuple[str, ...] = NAMES, *,
                     per_file: int = 2, key: str = "observation.state") -> Path:
    """A LeRobot v3.0 dataset: `per_file` episodes to a data file (file-000, file-001, … of
    chunk-000), and the episode table saying which file holds each and its global row range."""
    width = episodes[0].shape[1]
    features = {key: {"dtype": "float32", "shape": [width], "names": list(names)},
                "episode_index": {"dtype": "int64", "shape": [1], "names": None}}
    info = {"codebase_version": "v3.0", "robot_type": "test", "fps": 30, "chunks_size": 1000,
            "total_episodes": len(episodes), "total_frames": sum(len(e) for e in episodes),
            "data_path": "data/chunk-{chunk_index:03d}/file-{file_index:03d}.parquet", "features": features}
    (folder / "meta" / "episodes" / "chunk-000").mkdir(parents=True)
    (folder / "data" / "chunk-000").mkdir(parents=True)
    (folder / "meta" / "info.json").write_text(json.dumps(info))
    rows, start = [], 0
    for file_index in range(0, len(episodes), per_file):
        part = list(enumerate(episodes))[file_index:file_index + per_file]
        frames = np.concatenate([e for _, e in part])
        offsets = pa.array(np.arange(len(frames) + 1, dtype=np.int32) * width)
        table = pa.table({key: pa.ListArray.from_arrays(offsets, pa.array(frames.ravel(), type=pa.float32())),
                          "frame_index": pa.array(np.concatenate([np.arange(len(e)) for _, e in part]), pa.int64()),
                          "episode_index": pa.array(np.concatenate([np.full(len(e), i) for i, e in part]), pa.int64()),
                          "index": pa.array(np.arange(start, start + len(frames)), pa.int64())})
        pq.write_table(table, folder / "data" / "chunk-000" / f"file-{file_index // per_file:03d}.parquet")
        for i, e in part:
            rows.append({"episode_index": i, "tasks": ["reach"], "length": len(e), "data/chunk_index": 0,
                         "data/file_index": file_index // per_file, "dataset_from_index": start,
                         "dataset_to_index": start + len(e)})
            start += len(e)
    pq.write_table(pa.Table.from_pylist(rows), folder / "meta" / "episodes" / "chunk-000" / "file-000.parquet")
    return folder


def write_episode(folder: Path, index: int, frames, *, key: str = "observation.state",
                  value_type: pa.DataType = pa.float32()) -> Path:
    if isinstance(frames, np.ndarray):  # as LeRobot writes it: a list column
        n = len(frames)
        offsets = pa.array(np.arange(n + 1, dtype=np.int32) * frames.shape[1])
        state = pa.ListArray.from_arrays(offsets, pa.array(frames.ravel(), type=value_type))
    else:  # rows of any lengths (a bad file)
        n = len(frames)
        state = pa.array([list(map(float, row)) for row in frames], type=pa.list_(value_type))
    table = pa.table({key: state, "action": state, "timestamp": pa.array(np.arange(n) / 30, pa.float32()),
                      "frame_index": pa.array(np.arange(n), pa.int64()),
                      "episode_index": pa.array(np.full(n, index), pa.int64())})
    path = folder / "data" / f"chunk-{index // 1000:03d}" / f"episode_{index:06d}.parquet"
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(table, path)
    return path


def write_hdf5(path: Path, episodes: list[np.ndarray], names: tuple[str, ...] | None = NAMES, *,
               key: str = "robot0_joint_pos", names_on: str = "dataset") -> Path:
    """The robomimic layout: data/demo_<i>/obs/<key>, joint names as an attribute."""
    with h5py.File(path, "w") as f:
        data = f.create_group("data")
        data.attrs["total"] = sum(len(e) for e in episodes)
        for index, frames in enumerate(episodes):
            demo = data.create_group(f"demo_{index}")
            demo.attrs["num_samples"] = len(frames)
            demo.create_dataset("actions", data=np.zeros((len(frames), 7)))
            dataset = demo.create_dataset(f"obs/{key}", data=frames)
            demo.create_dataset("obs/object", data=np.zeros((len(frames), 10)))
            if names is not None and names_on == "dataset":
                dataset.attrs["joint_names"] = list(names)
        if names is not None and names_on == "data":
            data.attrs["joint_names"] = list(names)
    return path


def write_bag(path: Path, frames: np.ndarray, names=NAMES, *, ros: int = 1, topic: str = "/joint_states",
              shuffle: bool = False, message=None, mcap: bool = False) -> Path:
    """A ROS 1 bag or a ROS 2 bag folder (SQLite, or with `mcap` MCAP) of sensor_msgs/JointState;
    with `shuffle`, each message lists its joints in another order; `message(i, names, positions)`
    may change a message."""
    store = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    joint_state, header, time = (store.types[t] for t in
                                 ("sensor_msgs/msg/JointState", "std_msgs/msg/Header", "builtin_interfaces/msg/Time"))
    serialize = store.serialize_ros1 if ros == 1 else store.serialize_cdr
    writer = Bag1Writer(path) if ros == 1 else \
        Bag2Writer(path, version=9, storage_plugin=StoragePlugin.MCAP if mcap else StoragePlugin.SQLITE3)
    rng = np.random.default_rng(1)
    with writer:
        connection = writer.add_connection(topic, joint_state.__msgtype__, typestore=store)
        other = writer.add_connection("/tf_like", "std_msgs/msg/String", typestore=store)
        for i, row in enumerate(frames):
            order = rng.permutation(len(names)) if shuffle else np.arange(len(names))
            msg_names, positions = [names[k] for k in order], np.asarray(row, dtype=np.float64)[order]
            if message is not None:
                msg_names, positions = message(i, msg_names, positions)
            stamp = {"stamp": time(sec=i, nanosec=0), "frame_id": "", **({"seq": i} if ros == 1 else {})}
            msg = joint_state(header=header(**stamp), name=list(msg_names), position=np.asarray(positions, float),
                              velocity=np.zeros(0), effort=np.zeros(0))
            writer.write(connection, 1_000_000 * (i + 1), serialize(msg, joint_state.__msgtype__))
            if i == 0:
                text = store.types["std_msgs/msg/String"](data="x")
                writer.write(other, 1_000_000, serialize(text, "std_msgs/msg/String"))
    return path


def arm_episodes(frames: int, per_episode: int = 1000, seed: int = 0, offset: float = 0.0) -> list[np.ndarray]:
    """`frames` frames of smooth reaching motions of a 7-joint arm (radians) and its gripper
    (metres), in episodes of `per_episode`; with `offset`, each frame that many steps later in
    time (0.5: halfway between two recorded frames)."""
    rng = np.random.default_rng(seed)
    episodes = []
    for start in range(0, frames, per_episode):
        n = min(per_episode, frames - start)
        t = (np.linspace(0, 1, n) + offset / max(n - 1, 1))[:, None]
        a, b = rng.uniform(-1.5, 1.5, (2, 7))
        arm = a + (b - a) * (3 * t**2 - 2 * t**3) + 0.05 * np.sin(2 * np.pi * rng.uniform(1, 3, 7) * t)
        episodes.append(np.column_stack([arm, 0.04 * (t[:, 0] > 0.5)]))
    return episodes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("out", type=Path)
    parser.add_argument("--frames", type=int, default=100_000)
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    episodes = arm_episodes(args.frames)
    frames = np.concatenate(episodes)
    for what, write in (("lerobot", lambda: write_lerobot(args.out / "lerobot", episodes, list(ARM))),
                        ("lerobot_v3", lambda: write_lerobot_v3(args.out / "lerobot_v3", episodes, ARM, per_file=50)),
                        ("robomimic.hdf5", lambda: write_hdf5(args.out / "robomimic.hdf5", episodes, ARM)),
                        ("joint_states.bag", lambda: write_bag(args.out / "joint_states.bag", frames, ARM, ros=1)),
                        ("joint_states_ros2", lambda: write_bag(args.out / "joint_states_ros2", frames, ARM, ros=2))):
        began = time.perf_counter()
        write()
        print(f"{args.out / what}: {len(frames)} frames in {time.perf_counter() - began:.1f} s")


if __name__ == "__main__":
    main()
