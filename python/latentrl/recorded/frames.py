"""From a recording's episodes to the frames `load_demos` keeps: joint names renamed and matched,
the size cap, every-k-th-frame reading past it, NaN frames and degrees refused by name.

A reader (`Recording`) knows from metadata alone its joint names and each episode's frame count;
`read_frames` decides from them how much to read before it reads anything.
"""

from __future__ import annotations

import math
from collections.abc import Collection, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

MAX_RECORDED_VALUES = 32 * 2**20
"""The most joint values (frames × values per frame, as the recording holds them) `load_demos`
brings into memory from one recording: 33 554 432, 256 MiB as float64 — 100 000 frames of 335
joints, or 4.7 million frames of a 7-joint arm. Counted from metadata before anything is read.
Past it, a recording is refused unless `max_postures` is given; then every k-th frame of each
episode is read, k the smallest step that keeps the values read under the cap. The kept values
are filled into one array an episode at a time; with the copy `Demonstrations` keeps, a read
holds at most twice the cap (512 MiB) plus one episode as recorded."""

REVOLUTE_BOUND = 2 * math.pi
"""A kept joint whose recorded values go beyond ±2π looks like degrees: refused without `degrees`;
with it, values none of which goes beyond look like radians already (`to_radians`)."""


Degrees = bool | Collection[str]
"""Which joints' values are degrees: all (True), none (False), or those named (a robot's angular
joints: `Task.demos` leaves a prismatic joint's metres as they are)."""


def to_radians(values: NDArray[np.float64], names: Sequence[str], degrees: Degrees, where: str) -> None:
    """Converts in place the columns of `values` (named `names`) that `degrees` gives as degrees;
    a ValueError naming `where` when their values all lie within ±2π: they look like radians
    (converted again, every motion would shrink 57-fold without a word)."""
    if isinstance(degrees, str):
        raise TypeError(f"degrees: expected a bool or a collection of joint names, got the string {degrees!r}")
    columns = [c for c, name in enumerate(names) if degrees is True or (degrees and name in degrees)]
    if not len(values) or not columns:
        return
    largest = max(float(np.abs(values[:, c]).max()) for c in columns)  # a column at a time: no copy of them all
    if not largest > REVOLUTE_BOUND:
        raise ValueError(f"{where}: --degrees (degrees=True) was given, but no value lies beyond ±2π (the largest "
                         f"is {largest:g}): these look like radians already; drop --degrees")
    for c in columns:
        np.radians(values[:, c], out=values[:, c])


@dataclass(frozen=True)
class Episode:
    """One episode of a recording as its metadata gives it: its index, its frame count, and where
    it is (the file, or file and field), for the messages."""

    index: int
    frames: int
    where: str


class Recording(Protocol):
    """A reader of one recording format: joint names and episodes from metadata, then the frames
    of one episode on request. A context manager: the file stays open between the two."""

    path: Path
    field: str
    """Where the joint positions are: the LeRobot feature, the HDF5 obs key, the ROS topic."""
    names: tuple[str, ...]
    """The joint names as recorded, one per value of a frame."""
    episodes: tuple[Episode, ...]

    def read(self, episode: Episode, step: int) -> NDArray[np.float64]:
        """Every `step`-th frame of `episode`, (⌈frames / step⌉, len(names)); ValueError naming the
        file and field for a frame of another width or a file cut short."""
        ...

    def __enter__(self) -> Recording: ...

    def __exit__(self, kind: type[BaseException] | None, err: BaseException | None,
                 tb: TracebackType | None) -> None: ...


@dataclass(frozen=True)
class Frames:
    """The frames kept of a recording: values (N, D) in radians, the joint names (D,), and per
    frame its episode and its frame index within the episode."""

    values: NDArray[np.float64]
    names: tuple[str, ...]
    episodes: NDArray[np.int64]
    frames: NDArray[np.int64]


def renamed(names: Sequence[str], joint_map: Mapping[str, str]) -> tuple[str, ...]:
    """`names` with `joint_map`'s renames (old → new; new "": the column is left out, its name
    ""); a name to rename that is not there, or two joints that end up with one name, is a
    ValueError."""
    unnamed = [c for c, name in enumerate(names) if not name]
    if unnamed:  # "" would read as a column the map leaves out: dropped without a word
        raise ValueError(f"recorded joints {unnamed} (counting from 0) have an empty name, in {list(names)}; "
                         "give the joint names (--joint-names a,b,…) or fix the recorder's")
    absent = sorted(set(joint_map) - set(names))
    if absent:
        raise ValueError(f"the joint map renames {absent}, which are not among the joints {list(names)}")
    new = tuple(joint_map.get(name, name) for name in names)
    twice = sorted({name for name in new if name and new.count(name) > 1})
    if twice:
        raise ValueError(f"{'after the joint map, ' if joint_map else ''}joints {twice} name two columns each")
    return new


def kept_columns(names: tuple[str, ...], expected: Sequence[str] | None, where: str) -> list[int]:
    """Columns of `expected` in `names`, in `expected`'s order (without it, all but those a joint
    map left out, named ""): joints the recording has beyond them are dropped, one it lacks is a
    ValueError naming it."""
    if expected is None:
        kept = [c for c, name in enumerate(names) if name]
        if not kept:
            raise ValueError(f"{where}: the joint map leaves out every column")
        return kept
    missing = [name for name in expected if name not in names]
    if missing:
        raise ValueError(f"{where}: joints {missing} are not in the recording, which has {list(names)} "
                         "(rename recorded joints with a joint map: --joint-map old=new)")
    return [names.index(name) for name in expected]


def frame_step(recording: Recording, max_postures: int | None) -> int:
    """1, or the step k of every-k-th-frame reading for a recording past `MAX_RECORDED_VALUES`
    (with `max_postures`; without it, a ValueError naming the cap and ``--max-postures``)."""
    total = sum(e.frames for e in recording.episodes)
    values = total * len(recording.names)
    if values <= MAX_RECORDED_VALUES:
        return 1
    if max_postures is None:
        raise ValueError(
            f"{recording.path}: {total} frames of {len(recording.names)} values ({values} values) are more than the "
            f"{MAX_RECORDED_VALUES} a recording may bring into memory (latentrl.recorded.MAX_RECORDED_VALUES, "
            "256 MiB as float64); give --max-postures N (max_postures=N): every k-th frame is then read, "
            "and N postures chosen among them")
    return math.ceil(values / MAX_RECORDED_VALUES)


def _finite(block: NDArray[np.float64], names: tuple[str, ...], episode: Episode, step: int) -> None:
    bad = np.argwhere(~np.isfinite(block))
    if bad.size:
        row, col = bad[0]
        raise ValueError(f"{episode.where}: episode {episode.index}, frame {row * step}, joint {names[col]!r}: "
                         f"{block[row, col]} (a frame with a non-finite value cannot be a posture; drop it)")


def read_frames(recording: Recording, *, expected_joints: Sequence[str] | None = None,
                joint_map: Mapping[str, str] | None = None, degrees: Degrees = False,
                max_postures: int | None = None) -> Frames:
    """The frames of `recording` as postures. The rule, in order:

    1. a recording without episodes, or with an episode without frames, is refused;
    2. the recorded joint names, renamed by `joint_map` (old → new);
    3. with `expected_joints`, those joints' columns in that order: other recorded joints are
       dropped, a missing one is refused by name; without it, every joint; the values to read
       (frames × values per frame, from metadata) are checked against `MAX_RECORDED_VALUES`
       before anything is read (`frame_step`);
    4. each episode read (every k-th frame past the cap), a frame with a NaN or infinite
       kept value refused naming its episode and frame;
    5. units: with `degrees`, every kept value (or those of the joints it names) is converted to
       radians; without it, a kept joint whose values reach beyond ±2π is refused as looking like
       degrees.

    Errors are ValueErrors naming the file (and field) and what is wrong where."""
    where = f"{recording.path} ({recording.field})"
    if not recording.episodes:
        raise ValueError(f"{where}: no episodes")
    for episode in recording.episodes:
        if episode.frames == 0:
            raise ValueError(f"{episode.where}: episode {episode.index} has no frames")
    try:
        names = renamed(recording.names, joint_map or {})
    except ValueError as err:
        raise ValueError(f"{where}: {err}") from err
    columns = kept_columns(names, expected_joints, where)
    kept = tuple(names[c] for c in columns)
    step = frame_step(recording, max_postures)
    counts = [math.ceil(e.frames / step) for e in recording.episodes]
    values = np.empty((sum(counts), len(columns)))  # the kept values, filled an episode at a time
    episode_of = np.repeat([e.index for e in recording.episodes], counts).astype(np.int64)
    frame_of = np.concatenate([np.arange(n, dtype=np.int64) * step for n in counts])
    start = 0
    for episode, count in zip(recording.episodes, counts):
        block = recording.read(episode, step)
        if len(block) != count:
            raise ValueError(f"{episode.where}: {len(block)} frames read where its metadata gives {count} "
                             f"({episode.frames} frames, every {step}-th read)")
        values[start:start + count] = block[:, columns]
        _finite(values[start:start + count], kept, episode, step)
        start += count
    if degrees:
        to_radians(values, kept, degrees, where)
    else:
        beyond = np.abs(values) > REVOLUTE_BOUND
        if beyond.any():
            row, col = np.argwhere(beyond)[0]
            raise ValueError(
                f"{where}: joint {kept[col]!r} is {values[row, col]:g} at episode {episode_of[row]}, frame "
                f"{frame_of[row]}, beyond ±2π: the recording looks like degrees; give --degrees (degrees=True) "
                "to convert it to radians")
    return Frames(values, kept, episode_of, frame_of)
