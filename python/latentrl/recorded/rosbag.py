"""A ROS 1 bag (``.bag``) or a ROS 2 bag (its folder, with ``metadata.yaml``) as a `Recording`: the
``sensor_msgs/JointState`` messages of one topic (default ``/joint_states``) are the frames of one
episode, each message's ``position`` matched to its own ``name`` list. Read with the rosbags
library, without a ROS install (``pip install 'latentrl[rosbag]'``).

Several publishers on one topic (an arm driver and a gripper driver on ``/joint_states``) are
told apart by the joints their messages name: when the messages of the topic's first
`PUBLISHERS_SEEN_NS` name two or more disjoint sets of joints, each message updates its own
joints and every message from the first at which all sets have been named is a frame holding
the latest position of every joint (the frames before it are left out). Name sets that overlap
are one publisher dropping joints: a message without one of them is refused, naming it."""

from __future__ import annotations

import math
from collections.abc import Iterator
from pathlib import Path
from types import TracebackType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.recorded.frames import Episode
from latentrl.recorded.libraries import needs

DEFAULT_TOPIC = "/joint_states"
PUBLISHERS_SEEN_NS = 2_000_000_000
"""How much of a topic's start (bag time, ns) is read for its publishers' joint name sets."""
JOINT_STATE = ("sensor_msgs/msg/JointState", "sensor_msgs/JointState")


def _damaged(path: Path, err: Exception) -> ValueError:
    """rosbags raises errors of many kinds on a damaged bag (its own, sqlite's, struct's): one
    ValueError naming the bag."""
    return ValueError(f"{path}: not a readable ROS bag (cut short?): {type(err).__name__}: {err}")


class JointStateBag:
    """Reads the JointState messages of `topic` in one bag; their count comes from the bag's index."""

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
            count = sum(c.msgcount for c in self._connections)
            self.names, self._sets, self._first = self._publishers()
            self.episodes: tuple[Episode, ...] = (Episode(0, count - self._first, f"{path}: topic {self.field}"),)
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

    def _messages(self, step: int) -> Iterator[tuple[int, Any]]:
        """Every `step`-th message of the topic, with its bag time (ns), deserialized."""
        try:
            for i, (connection, stamp, raw) in enumerate(self._reader.messages(connections=self._connections)):
                if i % step == 0:
                    yield stamp, self._reader.deserialize(raw, connection.msgtype)
        except Exception as err:  # noqa: BLE001 (see _damaged)
            raise _damaged(self.path, err) from err

    def _publishers(self) -> tuple[tuple[str, ...], tuple[frozenset[str], ...], int]:
        """The topic's joint names, its publishers' name sets (none: one publisher, nothing to
        merge) and the index of its first complete frame, from its first `PUBLISHERS_SEEN_NS`."""
        seen: dict[tuple[str, ...], int] = {}  # each name set as its first message lists it, and that message
        start = 0
        for i, (stamp, message) in enumerate(self._messages(1)):
            start = stamp if i == 0 else start
            if stamp - start > PUBLISHERS_SEEN_NS:
                break
            if all(set(message.name) != set(names) for names in seen):
                seen[tuple(message.name)] = i
        # A set inside another is a message missing joints, not a publisher: refused when read.
        kept = [names for names in seen if not any(set(names) < set(other) for other in seen)]
        sets = [frozenset(names) for names in kept]
        if len(sets) < 2 or any(a & b for k, a in enumerate(sets) for b in sets[k + 1:]):
            return (kept[0] if kept else ()), (), 0
        return tuple(name for names in kept for name in names), tuple(sets), max(seen[names] for names in kept)

    def read(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th message's positions in the order of `names` (a message may list its
        joints in another order); a message without one of them, or with positions that do not
        match its names, is a ValueError naming the message. With several publishers, every
        `step`-th merged frame (the module's docs)."""
        if self._sets:
            return self._merged(episode, step)
        rows = np.empty((math.ceil(episode.frames / step), len(self.names)))
        order: dict[tuple[str, ...], list[int]] = {}
        count = 0
        for _, message in self._messages(step):
            where = f"{episode.where}: message {count * step}"
            names, position = _checked(message, where)
            if names not in order:
                missing = [name for name in self.names if name not in names]
                if missing:
                    raise ValueError(f"{where}: no position of joints {missing} (it names {list(names)})")
                order[names] = [names.index(name) for name in self.names]
            if count == len(rows):
                raise ValueError(f"{episode.where}: more messages than the bag's index counts ({episode.frames})")
            rows[count] = position[order[names]]
            count += 1
        if count != len(rows):
            raise ValueError(f"{episode.where}: {count} of the {len(rows)} messages the bag's index counts could "
                             "be read (cut short?)")
        return rows

    def _merged(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th frame of the latest positions of all joints, from the first complete one."""
        rows = np.empty((math.ceil(episode.frames / step), len(self.names)))
        column = {name: c for c, name in enumerate(self.names)}
        latest = np.empty(len(self.names))
        count = 0
        for i, (_, message) in enumerate(self._messages(1)):
            names, position = _checked(message, f"{episode.where}: message {i}")
            if frozenset(names) not in self._sets:
                raise ValueError(f"{episode.where}: message {i} names {list(names)}, none of the joint sets the "
                                 f"topic's publishers name ({[sorted(s, key=column.__getitem__) for s in self._sets]})")
            latest[[column[name] for name in names]] = position
            frame = i - self._first
            if frame >= 0 and frame % step == 0:
                if count == len(rows):
                    raise ValueError(f"{episode.where}: more messages than the bag's index counts")
                rows[count] = latest
                count += 1
        if count != len(rows):
            raise ValueError(f"{episode.where}: {count} of the {len(rows)} frames the bag's index counts could be "
                             "read (cut short?)")
        return rows

    def __enter__(self) -> JointStateBag:
        return self

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None) -> None:
        self._reader.close()


def _checked(message: Any, where: str) -> tuple[tuple[str, ...], NDArray[np.float64]]:
    """A JointState message's names and positions, as many of each (else a ValueError at `where`)."""
    names, position = tuple(message.name), np.asarray(message.position, dtype=np.float64)
    if len(position) != len(names):
        raise ValueError(f"{where}: {len(position)} positions for {len(names)} joint names (mixed shapes)")
    return names, position
