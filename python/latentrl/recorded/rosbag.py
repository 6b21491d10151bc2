"""A ROS 1 bag (``.bag``) or a ROS 2 bag (its folder, with ``metadata.yaml``) as a `Recording`: the
``sensor_msgs/JointState`` messages of one topic (default ``/joint_states``) are the frames of one
episode, each message's ``position`` matched to its own ``name`` list. Read with the rosbags
library, without a ROS install (``pip install 'latentrl[rosbag]'``)."""

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
            self.episodes: tuple[Episode, ...] = (Episode(0, count, f"{path}: topic {self.field}"),)
            first = next(self._messages(1), None)
            self.names = tuple(first.name) if first is not None else ()
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

    def _messages(self, step: int) -> Iterator[Any]:
        """Every `step`-th message of the topic, deserialized."""
        try:
            for i, (connection, _, raw) in enumerate(self._reader.messages(connections=self._connections)):
                if i % step == 0:
                    yield self._reader.deserialize(raw, connection.msgtype)
        except Exception as err:  # noqa: BLE001 (see _damaged)
            raise _damaged(self.path, err) from err

    def read(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th message's positions in the order of `names` (a message may list its
        joints in another order); a message without one of them, or with positions that do not
        match its names, is a ValueError naming the message."""
        rows = np.empty((math.ceil(episode.frames / step), len(self.names)))
        order: dict[tuple[str, ...], list[int]] = {}
        count = 0
        for message in self._messages(step):
            names, position = tuple(message.name), message.position
            where = f"{episode.where}: message {count * step}"
            if len(position) != len(names):
                raise ValueError(f"{where}: {len(position)} positions for {len(names)} joint names (mixed shapes)")
            if names not in order:
                missing = [name for name in self.names if name not in names]
                if missing:
                    raise ValueError(f"{where}: no position of joints {missing} (it names {list(names)})")
                order[names] = [names.index(name) for name in self.names]
            if count == len(rows):
                raise ValueError(f"{episode.where}: more messages than the bag's index counts ({episode.frames})")
            rows[count] = np.asarray(position, dtype=np.float64)[order[names]]
            count += 1
        if count != len(rows):
            raise ValueError(f"{episode.where}: {count} of the {len(rows)} messages the bag's index counts could "
                             "be read (cut short?)")
        return rows

    def __enter__(self) -> JointStateBag:
        return self

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None, tb: TracebackType | None) -> None:
        self._reader.close()
