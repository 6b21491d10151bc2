"""Demonstrations as recorders write them: a LeRobot dataset folder, robomimic-style HDF5, a ROS 1
or ROS 2 bag of ``sensor_msgs/JointState``. `latentrl.load_demos` and every ``--demos`` read them
through this package; each format's library is an optional extra, imported only when a file of
that format is read:

- a LeRobot dataset (v2.x or v3.0): a folder with ``meta/info.json`` and ``data/chunk-*/*.parquet``
  (``pip install 'latentrl[lerobot]'``, pyarrow);
- HDF5 in the robomimic layout, ``data/demo_*/obs/<key>`` (``.hdf5`` or ``.h5``;
  ``pip install 'latentrl[hdf5]'``, h5py);
- a ROS 1 bag (``.bag``) or a ROS 2 bag (a folder with ``metadata.yaml``), the
  ``sensor_msgs/JointState`` messages of one topic (``pip install 'latentrl[rosbag]'``, rosbags;
  no ROS install).

What is kept, and how much is read, is the rule of `latentrl.recorded.frames.read_frames`; which
postures a model gets when there are too many, `latentrl.recorded.sampling.farthest_points`.
"""

from __future__ import annotations

from pathlib import Path

from latentrl.recorded.frames import MAX_RECORDED_VALUES, Frames, Recording, read_frames

__all__ = ["MAX_RECORDED_VALUES", "Frames", "Recording", "open_recording", "read_frames", "recording_kind"]

HDF5_SUFFIXES = (".hdf5", ".h5")
KINDS = "a LeRobot dataset folder (meta/info.json), .hdf5/.h5 (robomimic), .bag (ROS 1) or a ROS 2 bag folder (metadata.yaml)"
"""The recordings `load_demos` reads, as its error messages name them."""


def recording_kind(path: Path) -> str | None:
    """ "lerobot", "hdf5", "rosbag" or None (not a recording: a file of postures, by its
    extension). A folder that is neither a LeRobot dataset nor a ROS 2 bag, or a ROS 2 bag's
    storage file given instead of its folder, is a ValueError saying what to give."""
    if path.is_dir():
        if (path / "meta" / "info.json").is_file():
            return "lerobot"
        if (path / "metadata.yaml").is_file():
            return "rosbag"
        raise ValueError(f"{path}: a folder, but neither a LeRobot dataset (no meta/info.json) nor a "
                         "ROS 2 bag (no metadata.yaml); demonstrations are " + KINDS + ", or .csv, .json, .npz")
    suffix = path.suffix.lower()
    if suffix in (".db3", ".mcap") or (path.name == "metadata.yaml" and path.is_file()):
        raise ValueError(f"{path}: a ROS 2 bag is read as its folder (with metadata.yaml): give {path.parent}")
    if path.name == "info.json" and path.parent.name == "meta" and path.is_file():
        raise ValueError(f"{path}: a LeRobot dataset is read as its folder (with meta/info.json): give {path.parent.parent}")
    if suffix in HDF5_SUFFIXES:
        return "hdf5"
    if suffix == ".bag":
        return "rosbag"
    return None


def open_recording(path: Path, kind: str, *, key: str | None, joint_names: tuple[str, ...] | None) -> Recording:
    """The reader of `kind` (`recording_kind`) on `path`; `key` is the LeRobot feature, the HDF5
    obs key or the ROS topic (None: the format's default), `joint_names` the names of a recording
    that has none. Nothing is read but metadata until `read_frames`; use it as a context manager."""
    if kind == "lerobot":
        from latentrl.recorded.lerobot import LeRobotDataset

        return LeRobotDataset(path, key, joint_names)
    if kind == "hdf5":
        from latentrl.recorded.hdf5 import RobomimicFile

        return RobomimicFile(path, key, joint_names)
    from latentrl.recorded.rosbag import JointStateBag

    if joint_names is not None:
        raise ValueError(f"{path}: a bag's JointState messages name their joints; rename them with a joint map "
                         "(--joint-map old=new), not joint names")
    return JointStateBag(path, key)
