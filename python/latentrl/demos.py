"""Demonstrated postures with their joint names, read from and written to CSV, NPZ or JSON, and
read from recordings (LeRobot datasets, robomimic HDF5, ROS bags: `latentrl.recorded`).

Formats (by extension):

- ``.csv``: a header row of joint names, then one posture per row.
- ``.npz``: arrays ``postures`` (N, D) and ``joint_names`` (D,) of strings (and, where the
  demonstrations have them, ``episodes`` and ``frames`` (N,)).
- ``.json``: ``{"joint_names": [...], "postures": [[...], ...]}``.
- recordings (read only): a LeRobot dataset folder, ``.hdf5``/``.h5``, ``.bag``, a ROS 2 bag folder.
"""

from __future__ import annotations

import codecs
import csv
import io
import json
import stat
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from latentrl._files import not_regular, utf8
from latentrl._persistence import PathLike, atomic_write, read_npz
from latentrl.recorded import KINDS, open_recording, read_frames, recording_kind
from latentrl.recorded.frames import Degrees, kept_columns, renamed, to_radians
from latentrl.recorded.sampling import farthest_points


@dataclass(frozen=True, eq=False)
class Demonstrations:
    """Demonstrated postures (N, D), one column per joint, and the joints' names (D,); for
    postures taken from a recording, the episode (N,) each comes from and its frame index in
    that episode (N,), else None.

    Checked on construction: names non-empty and unique, at least one posture, one column
    per name, every value finite, one episode and frame index per posture. `postures` is stored
    as a read-only float64 copy, `episodes` and `frames` as read-only int64 ones.
    """

    postures: NDArray[np.float64]
    joint_names: tuple[str, ...]
    episodes: NDArray[np.int64] | None = None
    frames: NDArray[np.int64] | None = None

    def __post_init__(self) -> None:
        names = tuple(self.joint_names)
        if not all(isinstance(name, str) and name.strip() for name in names):
            raise ValueError(f"joint_names: every name must be a non-empty string, got {names}")
        duplicates = sorted({name for name in names if names.count(name) > 1})
        if duplicates:
            raise ValueError(f"joint_names: duplicate joint names {duplicates}")
        postures = np.array(self.postures, dtype=np.float64)
        if postures.ndim != 2 or postures.shape[0] == 0:
            raise ValueError(
                f"postures: expected a 2-D array of at least one posture, "
                f"got shape {postures.shape}"
            )
        if postures.shape[1] != len(names):
            raise ValueError(f"postures: {postures.shape[1]} columns for {len(names)} joint names")
        bad = np.argwhere(~np.isfinite(postures))
        if bad.size:
            i, j = bad[0]
            raise ValueError(f"posture {i}, joint {names[j]!r}: non-finite value {postures[i, j]}")
        postures.flags.writeable = False
        object.__setattr__(self, "postures", postures)
        object.__setattr__(self, "joint_names", names)
        for field in ("episodes", "frames"):
            value = getattr(self, field)
            if value is None:
                continue
            index = np.array(value)
            if index.shape != (len(postures),) or index.dtype.kind not in "iu":
                raise ValueError(f"{field}: expected {len(postures)} integers (one per posture), "
                                 f"got dtype {index.dtype} shape {index.shape}")
            index = index.astype(np.int64)
            index.flags.writeable = False
            object.__setattr__(self, field, index)

    def subset(self, rows: Sequence[int] | NDArray[np.intp]) -> Demonstrations:
        """These demonstrations' postures `rows` (with their episode and frame indices)."""
        pick = np.asarray(rows, dtype=np.intp)
        return Demonstrations(self.postures[pick], self.joint_names,
                              None if self.episodes is None else self.episodes[pick],
                              None if self.frames is None else self.frames[pick])

    def __repr__(self) -> str:
        return f"Demonstrations({self.postures.shape[0]} postures of {list(self.joint_names)})"


def _number(cell: Any, where: str) -> float:
    if isinstance(cell, (int, float, str)) and not isinstance(cell, bool) and not (isinstance(cell, str) and "_" in cell):
        try:  # no "_": Python reads "0_5" as 5
            return float(cell)
        except ValueError:
            pass
    raise ValueError(f"{where}: {cell!r} is not a number")


def _is_number(text: str) -> bool:
    try:
        _number(text, "")
    except ValueError:
        return False
    return True


def _table(rows: Sequence[tuple[str, Sequence[Any]]], names: Sequence[str],
           columns: Sequence[int]) -> NDArray[np.float64]:
    """(label, cells) rows → (N, len(columns)) floats of those `columns` (the others are never
    parsed); ragged rows and non-numbers named by label and joint, a column without a number (a
    time stamp, notes) with how to leave it out, as a numeric column that is no joint is told."""
    values = np.empty((len(rows), len(columns)))
    for i, (label, cells) in enumerate(rows):
        if len(cells) != len(names):
            raise ValueError(f"{label}: {len(cells)} values, expected {len(names)} (one per joint)")
        for k, j in enumerate(columns):
            try:
                values[i, k] = _number(cells[j], f"{label}, joint {names[j]!r}")
            except ValueError as err:
                if any(_is_number(row[j]) for _, row in rows if len(row) == len(names)):
                    raise
                raise ValueError(f"{err}; column {names[j]!r} holds no number: a column that is no joint is left "
                                 f"out with --joint-map {names[j]}= (joint_map={{{names[j]!r}: ''}})") from None
    return values


def _mapped(names: Sequence[str], joint_map: Mapping[str, str]) -> tuple[list[int], tuple[str, ...]]:
    """The columns of `names` kept after `joint_map` (a column mapped to "", or named "", is left
    out) and their new names."""
    new = renamed(names, joint_map) if joint_map else tuple(names)  # duplicates: `Demonstrations` names them
    kept = kept_columns(new, None, "demo columns")
    return kept, tuple(new[c] for c in kept)


def _unnamed(names: Sequence[str], rows: Sequence[tuple[str, Sequence[str]]]) -> None:
    """A column without a name whose every cell is empty (a trailing comma on every line) is left
    out; one with a value is a ValueError naming it (a DataFrame's index when it is the first)."""
    for c in (c for c, name in enumerate(names) if not name):
        label, cell = next(((label, row[c]) for label, row in rows if c < len(row) and row[c].strip()), ("", ""))
        if not cell:
            continue
        where = f"column {c + 1} has no name in the header but values ({label}: {cell!r})"
        if c == 0:
            raise ValueError(f"{where}: it looks like a DataFrame's index written with the CSV; write it "
                             "with to_csv(index=False)")
        raise ValueError(f"{where}: name it in the header (a joint, or a column to leave out with --joint-map NAME= "
                         "(joint_map={'NAME': ''}))")


def _read_csv(path: Path, joint_map: Mapping[str, str]) -> Demonstrations:
    text = utf8(path.read_bytes().removeprefix(codecs.BOM_UTF8), " (a spreadsheet's 'CSV UTF-8')")
    fast = _numbers_below_header(text, joint_map)
    if fast is not None:
        return fast
    reader = csv.reader(io.StringIO(text, newline=""))
    lines = [(reader.line_num, row) for row in reader if row]
    while lines and lines[0][1][0].lstrip().startswith("#"):  # a recorder's comments above the header
        lines.pop(0)
    if not lines:
        raise ValueError("empty file (no header row)")
    (_, header), body = lines[0], lines[1:]
    names = [name.strip() for name in header]
    if all(_is_number(name) for name in names if name):
        raise ValueError(f"line {lines[0][0]} holds numbers, not joint names: the first row must name the joints")
    other = next((sep for sep in (";", "\t", "|") if len(names) == 1 and sep in names[0]), None)
    if other is not None:
        raise ValueError(f"line 1 is one column, {names[0]!r}: the file is separated by {other!r}, not by commas")
    rows = [(f"line {line} (posture {i})", row) for i, (line, row) in enumerate(body)]
    _unnamed(names, rows)
    kept, kept_names = _mapped(names, joint_map)
    return Demonstrations(_table(rows, names, kept), kept_names)


def _numbers_below_header(text: str, joint_map: Mapping[str, str]) -> Demonstrations | None:
    """A header of names over rows of plain finite numbers (in the columns `joint_map` keeps;
    the others are never parsed), read by NumPy's C reader (2 million rows of 7 joints in 3.5 s,
    not 19); None for anything else, which `_read_csv` reads cell by cell (and names the line,
    the posture and the joint of what is wrong)."""
    header, _, body = text.partition("\n")
    if header.lstrip().startswith("#"):
        return None  # comments above the header: the cell-by-cell reader skips them
    names = [name.strip() for name in next(csv.reader([header]), [])]
    if not all(names) or not body or body.isspace() or all(_is_number(name) for name in names):  # isspace, not strip: no copy of a large body
        return None  # an unnamed column: the cell-by-cell reader checks that it is empty
    kept, kept_names = _mapped(names, joint_map)
    try:
        values = np.loadtxt(io.StringIO(body), delimiter=",", comments=None, ndmin=2, dtype=np.float64, usecols=kept)
    except ValueError:
        return None
    if body.count(",") != len(values) * (len(names) - 1) or not np.isfinite(values).all():
        return None  # a ragged row (or a quoted comma), a non-finite value: the cell-by-cell reader names its line
    return Demonstrations(values, kept_names)


def _read_json(path: Path, joint_map: Mapping[str, str]) -> Demonstrations:
    try:
        doc = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as err:
        raise ValueError(f"not valid JSON: {err}") from err
    if not isinstance(doc, dict) or not {"joint_names", "postures"} <= doc.keys():
        raise ValueError('expected an object with keys "joint_names" and "postures"')
    names, postures = doc["joint_names"], doc["postures"]
    if not isinstance(names, list) or not isinstance(postures, list):
        raise ValueError('"joint_names" and "postures" must be lists')
    for i, row in enumerate(postures):
        if not isinstance(row, list):
            raise ValueError(f"posture {i}: expected a list of numbers, got {row!r}")
    rows = [(f"posture {i}", row) for i, row in enumerate(postures)]
    return _remapped(Demonstrations(_table(rows, names, range(len(names))), tuple(names)), joint_map)


def _read_npz(path: Path, joint_map: Mapping[str, str]) -> Demonstrations:
    arrays = read_npz(path)
    missing = sorted({"postures", "joint_names"} - arrays.keys())
    if missing:
        raise ValueError(f"missing arrays {missing}")
    postures, names = arrays["postures"], arrays["joint_names"]
    if postures.dtype.kind not in "iuf":
        raise ValueError(f"postures: expected numbers, got dtype {postures.dtype}")
    if names.dtype.kind != "U" or names.ndim != 1:
        raise ValueError(
            "joint_names: expected a 1-D array of strings, "
            f"got dtype {names.dtype} shape {names.shape}"
        )
    demos = Demonstrations(postures, tuple(str(name) for name in names), arrays.get("episodes"), arrays.get("frames"))
    return _remapped(demos, joint_map)


def _remapped(demos: Demonstrations, joint_map: Mapping[str, str]) -> Demonstrations:
    """`demos` with `joint_map` applied to its columns."""
    kept, names = _mapped(demos.joint_names, joint_map)
    return Demonstrations(demos.postures[:, kept], names, demos.episodes, demos.frames)


def _write_csv(demos: Demonstrations, fh: IO[bytes]) -> None:
    text = io.StringIO(newline="")
    writer = csv.writer(text, lineterminator="\n")
    writer.writerow(demos.joint_names)
    writer.writerows(demos.postures.tolist())
    fh.write(text.getvalue().encode("utf-8"))


def _write_json(demos: Demonstrations, fh: IO[bytes]) -> None:
    doc = {"joint_names": list(demos.joint_names), "postures": demos.postures.tolist()}
    fh.write(json.dumps(doc, indent=1).encode("utf-8"))


def _write_npz(demos: Demonstrations, fh: IO[bytes]) -> None:
    arrays: dict[str, Any] = {"postures": demos.postures, "joint_names": np.array(demos.joint_names, dtype=str)}
    arrays.update((k, v) for k, v in (("episodes", demos.episodes), ("frames", demos.frames)) if v is not None)
    np.savez(fh, **arrays)


_Reader = Callable[[Path, Mapping[str, str]], Demonstrations]
"""Reads a file of postures, applying a joint map (old → new; new "": the column is left out)."""
_Writer = Callable[[Demonstrations, IO[bytes]], None]

_FORMATS: dict[str, tuple[_Reader, _Writer]] = {
    ".csv": (_read_csv, _write_csv),
    ".json": (_read_json, _write_json),
    ".npz": (_read_npz, _write_npz),
}


def _format(path: Path) -> tuple[_Reader, _Writer]:
    try:
        return _FORMATS[path.suffix.lower()]
    except KeyError:
        raise ValueError(
            f"{path}: unsupported extension {path.suffix!r}; expected one of {', '.join(_FORMATS)}, "
            f"or a recording: {KINDS}"
        ) from None


def _select(demos: Demonstrations, expected: Sequence[str]) -> Demonstrations:
    missing = [name for name in expected if name not in demos.joint_names]
    unknown = [name for name in demos.joint_names if name not in expected]
    if missing or unknown:
        hint = (" (a task's demonstrations, a mimic joint's column checked against its leader and dropped: "
                f"Task.demos(path); a column to leave out: joint_map={{{unknown[0]!r}: ''}})") if unknown else ""
        raise ValueError(f"joint names do not match the expected ones: missing {missing}, unknown {unknown}{hint}")
    columns = [demos.joint_names.index(name) for name in expected]
    return Demonstrations(demos.postures[:, columns], tuple(expected), demos.episodes, demos.frames)


MAX_DEMO_FILE_BYTES = 256 * 2**20
"""The largest demo file `load_demos` reads (it reads a file whole): 256 MiB."""


def load_demos(
    path: PathLike,
    *,
    expected_joints: Sequence[str] | None = None,
    min_postures: int = 1,
    max_postures: int | None = None,
    joint_map: Mapping[str, str] | None = None,
    degrees: Degrees = False,
    key: str | None = None,
    joint_names: Sequence[str] | None = None,
) -> Demonstrations:
    """Reads demonstrations from a ``.csv``, ``.npz`` or ``.json`` file, or from a recording: a
    LeRobot dataset folder, robomimic HDF5 (``.hdf5``, ``.h5``), a ROS 1 bag (``.bag``) or a ROS 2
    bag folder (docs/demos.md; each needs its extra: `latentrl.recorded`).

    `joint_map` renames joints (old → new) before they are matched; a joint mapped to ``""`` is
    left out (a time stamp, a gripper: ``{"time": ""}``). With `expected_joints`, a
    file of postures must name exactly those joints; a recording must have them and its other
    joints (a gripper, a wheel) are dropped; the columns are returned in that order (a robot's
    demonstrations as `latentrl train` reads them, mimic columns checked and dropped: `Task.demos`).
    `degrees`: the values are degrees, converted to radians: every column (True) or the joints
    named (a robot's revolute and continuous ones; `Task.demos` passes them); a recording's kept
    joint beyond ±2π is refused without it, as looking like degrees. `key`: where a recording keeps the joint positions (the
    LeRobot feature, default ``observation.state``; the HDF5 obs key, default
    ``robot0_joint_pos``; the ROS topic, default ``/joint_states``); `joint_names`: the names of
    a recording that has none. A recording's episode and frame index per posture are kept
    (`Demonstrations.episodes`, `.frames`); one that would bring more than
    `latentrl.recorded.MAX_RECORDED_VALUES` values into memory is refused before it is read,
    unless `max_postures` is given (then every k-th frame of each episode is read).

    `max_postures`: at most that many postures, chosen by farthest-point sampling in joint space
    from the first one (`latentrl.recorded.sampling.farthest_points`), in their recorded order.
    Fewer than `min_postures` postures is an error. Every problem is a ValueError naming the
    file (and field) and what is wrong where; a missing format library a ModuleNotFoundError
    naming the extra to install.
    """
    path = Path(path)
    if max_postures is not None and not (isinstance(max_postures, int) and max_postures >= 1):
        raise ValueError(f"max_postures must be an int >= 1 or None, got {max_postures!r}")
    if max_postures is not None and max_postures < min_postures:
        raise ValueError(f"max_postures (--max-postures) = {max_postures} keeps fewer postures than the "
                         f"{min_postures} a fit needs")
    kind = recording_kind(path)
    if kind is None:
        if key is not None or joint_names is not None:
            raise ValueError(f"{path}: a file of postures names its joints; key and joint names are options of "
                             f"recordings ({KINDS})")
        demos = _load_file(path, expected_joints, joint_map or {}, degrees)
    else:
        path.stat()  # a missing file: FileNotFoundError, an OSError
        names = None if joint_names is None else tuple(joint_names)
        with open_recording(path, kind, key=key, joint_names=names) as recording:
            frames = read_frames(recording, expected_joints=expected_joints, joint_map=joint_map, degrees=degrees,
                                 max_postures=max_postures)
        demos = Demonstrations(frames.values, frames.names, frames.episodes, frames.frames)
    if max_postures is not None and len(demos.postures) > max_postures:
        demos = demos.subset(farthest_points(demos.postures, max_postures))
    if len(demos.postures) < min_postures:
        raise ValueError(
            f"{path}: {len(demos.postures)} postures, expected at least {min_postures}"
        )
    return demos


def _load_file(path: Path, expected_joints: Sequence[str] | None, joint_map: Mapping[str, str],
               degrees: Degrees) -> Demonstrations:
    read, _ = _format(path)
    info = path.stat()  # a missing file: FileNotFoundError, an OSError
    size = info.st_size
    if not stat.S_ISREG(info.st_mode):
        raise ValueError(f"{path}: {not_regular(info.st_mode)}")
    if size == 0:
        raise ValueError(f"{path}: empty file")
    if size > MAX_DEMO_FILE_BYTES:
        raise ValueError(f"{path}: {size} bytes, more than the {MAX_DEMO_FILE_BYTES} a demo file may have "
                         "(it is read whole); demonstrations are postures, not trajectories of millions of rows")
    try:
        demos = read(path, joint_map)
        if expected_joints is not None:
            demos = _select(demos, tuple(expected_joints))
    except (ValueError, csv.Error) as err:
        raise ValueError(f"{path}: {err}") from err
    except RecursionError as err:
        raise ValueError(f"{path}: nested too deeply to read") from err
    if degrees:
        postures = demos.postures.copy()
        to_radians(postures, demos.joint_names, degrees, str(path))
        demos = Demonstrations(postures, demos.joint_names, demos.episodes, demos.frames)
    return demos


def save_demos(demos: Demonstrations, path: PathLike) -> None:
    """Writes `demos` to a ``.csv``, ``.npz`` or ``.json`` file (atomically)."""
    path = Path(path)
    _, write = _format(path)
    atomic_write(path, lambda fh: write(demos, fh))
