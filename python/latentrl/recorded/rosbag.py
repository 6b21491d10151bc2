"""A ROS 1 bag (``.bag``) or a ROS 2 bag (its folder, with ``metadata.yaml``) as a `Recording`: the
``sensor_msgs/JointState`` messages of one topic (default ``/joint_states``) are the frames of one
episode, each message's ``position`` matched to its own ``name`` list. Read with the rosbags
library, without a ROS install (``pip install 'latentrl[rosbag]'``).

A topic is read as a subscriber sees it: each message moves the joints it names. A frame is the
latest position of every joint the topic names, one per message that carries positions, from the
first message at which every joint has been named (the messages before it are left out, with a
warning naming the joint that came last). So several publishers on one topic (an arm driver and
a gripper driver; a ``joint_state_publisher`` republishing every joint beside the arm driver)
read as one robot, and a message with names but no positions (a driver publishing velocities
only) moves nothing. The topic is read once for its joint names and frame count before any frame
is kept, so a frame count in the bag's metadata is not trusted. Two publishers naming the same
joints interleave, as they do for a subscriber: a ROS 1 bag's callers are named in a warning."""

from __future__ import annotations

import math
import warnings
from collections.abc import Iterator
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.recorded.frames import Episode
from latentrl.recorded.libraries import needs

DEFAULT_TOPIC = "/joint_states"
JOINT_STATE = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")


def _damaged(path: Path, err: Exception) -> ValueError:
    """rosbags raises errors of many kinds on a damaged bag (its own, sqlite's, struct's): one
    ValueError naming the bag."""
    return ValueError(f"{path}: not a readable ROS bag (cut short?): {type(err).__name__}: {err}")


class JointStateBag:
    """Reads the JointState messages of `topic` in one bag (module docs)."""

    def __init__(self, path: Path, topic: str | None) -> None:
        highlevel = needs("rosbags.highlevel", "a ROS bag", "rosbag")
        typesys = needs("rosbags.typesys", "a ROS bag", "rosbag")
        self.path, self.field = path, topic or DEFAULT_TOPIC
        try:  # a ROS 2 bag may carry no message definitions: JointState is the same in every distribution
            self._reader = highlevel.AnyReader([path], default_typestore=typesys.get_typestore(typesys.Stores.ROS2_HUMBLE))
            self._reader.open()
        except Exception as err:  # noqa: BLE001 (see _damaged)
            raise _damaged(path, err) from err
        try:
            self._connections = self._topic()
            where = f"{path}: topic {self.field}"
            self.names, self._first, frames, last = self._scan(where)
            self.episodes: tuple[Episode, ...] = (Episode(0, frames, where),)
            if self._first:
                warnings.warn(f"{where}: its first {self._first} messages come before joint {last!r} is first named "
                              f"(message {self._first}): left out, as frames need every joint's position", stacklevel=2)
            self._warn_same_joints(where)
        except BaseException:
            self._reader.close()
            raise

    def _topic(self) -> list[Any]:
        connections = [c for c in self._reader.connections if c.topic == self.field]
        if not connections:
            states = sorted({c.topic for c in self._reader.connections if c.msgtype in JOINT_STATE})
            raise ValueError(f"{self.path}: no topic {self.field!r}; its JointState topics are {states} "
                             "(choose one with --demos-key)")
        kinds = sorted({c.msgtype for c in connections} - set(JOINT_STATE))
        if kinds:
            raise ValueError(f"{self.path}: topic {self.field} carries {kinds}, not sensor_msgs/JointState")
        return connections

    def _warn_same_joints(self, where: str) -> None:
        """Warns when two publishers of the topic (a ROS 1 bag's callers) name the same joints, as
        a stray `joint_state_publisher` of zeros beside the driver does: their messages interleave
        (as for a subscriber), which no reading rule can undo."""
        named: dict[str, set[str]] = {}
        for connection in self._connections:
            caller = getattr(connection.ext, "callerid", None)
            first = next(iter(self._reader.messages(connections=[connection])), None)
            if caller is None or first is None or caller in named:
                continue
            named[caller] = set(self._reader.deserialize(first[2], connection.msgtype).name)
        callers = sorted(named)
        for k, a in enumerate(callers):
            for b in callers[k + 1:]:
                if named[a] & named[b]:
                    warnings.warn(f"{where}: publishers {a} and {b} both name joints {sorted(named[a] & named[b])}: their "
                                  "messages interleave in the frames, as a subscriber sees them; record the topic "
                                  "with one of them", stacklevel=3)
                    return

    def _decoded(self) -> Iterator[tuple[int, Any]]:
        """Each message of the topic, deserialized, with its index; a damaged bag, whatever rosbags
        raises, is one ValueError naming it (`_damaged`)."""
        try:
            for i, (connection, _, raw) in enumerate(self._reader.messages(connections=self._connections)):
                yield i, self._reader.deserialize(raw, connection.msgtype)
        except Exception as err:  # noqa: BLE001 (see _damaged)
            raise _damaged(self.path, err) from err

    def _messages(self, where: str) -> Iterator[tuple[int, tuple[str, ...], NDArray[np.float64]]]:
        """Each message of the topic that carries positions: its index, names and positions."""
        for i, message in self._decoded():
            names, position = tuple(message.name), np.asarray(message.position, dtype=np.float64)
            if not len(position):
                continue
            if len(position) != len(names):
                raise ValueError(f"{where}: message {i}: {len(position)} positions for {len(names)} joint names "
                                 f"({list(names)})")
            if not all(names):
                raise ValueError(f"{where}: message {i} names a joint with an empty name ({list(names)})")
            yield i, names, position

    def _scan(self, where: str) -> tuple[tuple[str, ...], int, int, str]:
        """The topic's joint names (in the order first named), the index of the first message
        at which all are named, the frames from it on, and the joint named last."""
        names: dict[str, None] = {}
        first, frames, last = 0, 0, ""
        for i, message_names, _ in self._messages(where):
            new = [name for name in message_names if name not in names]
            if new:
                names.update(dict.fromkeys(new))
                first, frames, last = i, 0, new[-1]
            frames += 1
        return tuple(names), first, frames, last

    def read(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th frame: the latest position of every joint (module docs)."""
        rows = np.empty((math.ceil(episode.frames / step), len(self.names)))
        column = {name: c for c, name in enumerate(self.names)}
        latest = np.full(len(self.names), np.nan)
        count = frame = 0
        for i, names, position in self._messages(episode.where):
            if any(name not in column for name in names):
                raise ValueError(f"{episode.where}: message {i} names {list(names)}, joints the first reading of "
                                 "the bag did not find (was it written to meanwhile?)")
            latest[[column[name] for name in names]] = position
            if i < self._first:
                continue
            if frame % step == 0:
                if count == len(rows):
                    raise ValueError(f"{episode.where}: more frames than the first reading counted ({episode.frames})")
                rows[count] = latest
                count += 1
            frame += 1
        if count != len(rows):
            raise ValueError(f"{episode.where}: {count} of the {len(rows)} frames the first reading counted could be "
                             "read (cut short?)")
        return rows

    def __enter__(self) -> JointStateBag:
        return self

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None) -> None:
        self._reader.close()
