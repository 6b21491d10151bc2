"""Tasks: a robot (URDF), its servos and physics, effectors with a target and a Gaussian reward,
the rules that end an episode, the episodes and the learner, read from a TOML task file
(docs/tasks.md) or built in Python. Every key, default and rule is the native side's
(`crates/sim/src/task/config.rs`); this module loads, derives and names them. The schema's
accessors (`latentrl.task_schema`) and the end reasons (`latentrl.episode_ends`) are importable
from here too.

    task = Task.load("my_robot.toml")            # or Task.shipped("two_arms")
    quick = task.replace({"learner.initial_weight": 100.0, "episode.max_steps": 200})
    plant = quick.plant(demos)                    # the native plant: reset, step, classify
"""

from __future__ import annotations

import json
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl._files import MAX_TASK_FILE_BYTES, MAX_URDF_BYTES, read_bounded, read_text
from latentrl.demos import Demonstrations, load_demos
from latentrl.episode_ends import end_counts, end_reasons
from latentrl.recorded import recording_kind
from latentrl.task_schema import (
    by_path,
    changed_since,
    check_run,
    encoders,
    key_paths,
    ran_with,
    run_default,
    run_settings,
    schema,
    schema_markdown,
)

__all__ = [
    "DEGREES", "SHIPPED", "Task", "by_path", "changed_since", "check_run", "encoders", "end_counts", "end_reasons",
    "key_paths", "ran_with", "run_default", "run_settings", "schema", "schema_markdown", "shipped_path",
]

DEGREES = 2 * np.pi + 1e-6
"""A joint angle beyond ±2π rad and outside its joint's limits is taken for degrees (no limited
robot joint turns more than once): `Task.demo_postures` refuses it, `latentrl check` names it."""

SHIPPED = ("two_arms", "humanoid_lift")
"""The task files shipped in `latentrl/tasks/`: Experiment 2's arms and Experiment 3's lift."""


def shipped_path(name: str) -> Path:
    """Path of the shipped task file `name` (one of `SHIPPED`)."""
    if name not in SHIPPED:
        raise ValueError(f"no shipped task {name!r}; shipped tasks: {', '.join(SHIPPED)}")
    from importlib import resources  # loaded when a shipped task is, not by `latentrl --help`

    return Path(str(resources.files("latentrl") / "tasks" / f"{name}.toml"))


def _plain(value: Any) -> Any:
    """`value` with every tuple and list a fresh list and every dict a fresh dict."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _label(origin: str) -> str:
    """`origin` as valid UTF-8, the text native code takes: a path's undecodable bytes (a folder
    named in Latin-1, read as surrogates) as their escapes, ``lat\\udce9n``, as Python prints
    them (a run in such a folder failed after its training, loading its policy)."""
    return origin.encode("utf-8", "backslashreplace").decode("utf-8")


def _set(config: dict[str, Any], key: str, value: Any, origin: str) -> None:
    """Sets the dotted `key` of a nested task dict (tables are created as needed)."""
    *tables, last = key.split(".")
    node = config
    for i, table in enumerate(tables):
        child = node.setdefault(table, {})
        if child is None:
            child = node[table] = {}
        if not isinstance(child, dict):
            raise ValueError(f"{origin}: {'.'.join(tables[: i + 1])} is not a table, so {key} cannot be set")
        node = child
    node[last] = value


class Task:
    """A checked task (a thin wrapper of the native `Task`): its configuration, its robot's joint
    names and limits, its effectors; `plant()` builds the native plant that applies its rules."""

    def __init__(self, native: _native.Task, base_dir: Path, given: frozenset[str] = frozenset()) -> None:
        self._native = native
        self.base_dir = base_dir
        """The folder the task's URDF path is relative to (the task file's)."""
        self.given = given
        """The keys (by path) its file, dict or overrides set; the others are at their defaults,
        and `latentrl.derive` may derive them from the data."""

    @classmethod
    def load(cls, path: str | Path) -> Task:
        """Reads a TOML task file; an error names the file, the key and the rule (ValueError)."""
        path = Path(path)
        native = _native.Task.load(path)  # checked (size, syntax, keys) before it is read here
        try:
            text = read_text(path, MAX_TASK_FILE_BYTES, "a task file")  # it may have changed since
        except ValueError as err:
            raise ValueError(f"{path}: {err}") from None
        try:  # a byte-order mark (Windows editors write one) is no TOML, but the native reader skips it
            written = key_paths(tomllib.loads(text.removeprefix("\ufeff")))
        except tomllib.TOMLDecodeError as err:
            raise ValueError(f"{path}: {err}") from None
        return cls(native, path.parent, frozenset(written))

    @classmethod
    def shipped(cls, name: str) -> Task:
        """A task file shipped with latentrl (`SHIPPED`)."""
        return cls.load(shipped_path(name))

    @classmethod
    def from_dict(cls, config: Mapping[str, Any], base_dir: str | Path = ".", origin: str = "<dict>") -> Task:
        """A task from a dict of task-file keys (nested tables as dicts); the URDF path is
        relative to `base_dir`; `origin` names it in errors (any text: a path that is not
        UTF-8 is shown with escapes)."""
        if not isinstance(config, Mapping):  # issue #38: a list said "dictionary update sequence element #0 …"
            raise TypeError(f"{origin}: expected a table of task keys (a dict), got {type(config).__name__}")
        base = Path(base_dir)
        return cls(_native.Task.from_dict(dict(config), base, _label(origin)), base, frozenset(key_paths(config)))

    def replace(self, overrides: Mapping[str, Any], origin: str | None = None) -> Task:
        """This task with `overrides` (dotted keys: ``{"learner.alpha": 0.5}``) applied and checked."""
        if not overrides:
            return self
        config = self.to_dict()
        name = origin or f"{self.origin} with {', '.join(sorted(overrides))}"
        for key, value in overrides.items():
            _set(config, key, value, name)
        native = _native.Task.from_dict(config, self.base_dir, _label(name))
        return Task(native, self.base_dir, self.given | frozenset(overrides))

    def run_given(self) -> dict[str, Any]:
        """The run settings its file, dict or overrides set (`[run]`), by name; the preset of
        a run on this task takes them (`presets.with_task_run`)."""
        run = self.to_dict()["run"]
        return {k: run[k] for k in (key.removeprefix("run.") for key in sorted(self.given) if key.startswith("run."))}

    def to_dict(self) -> dict[str, Any]:
        """Every key with its effective value: a fresh nested dict of plain values (lists, not
        tuples, so that it equals itself read back from JSON)."""
        config: dict[str, Any] = _plain(self._native.to_dict())
        return config

    def digest(self) -> str:
        """SHA-256 of the effective configuration but `[run]` (how long a run was, not what it
        ran on) and the URDF's text: what a saved policy records, so that it is not run on
        another task."""
        return task_digest(self.to_dict(), self.urdf_path)

    def plant(self, demos: NDArray[np.float64] | None = None) -> _native.TaskPlant:
        """The native plant of this task (home posture: demo `episode.start_demo` of `demos`); a
        home posture the robot cannot take is named by its row where episodes start there, else
        the robot stands at every joint's 0 within its limits (`sim::TaskPlant::new`)."""
        rows = None if demos is None else np.ascontiguousarray(demos, dtype=np.float64)
        return _native.TaskPlant(self._native, rows)

    def check_joints(self, joint_names: tuple[str, ...] | list[str], where: str) -> None:
        """ValueError naming `where` unless `joint_names` are this robot's actuated joints in order."""
        expected = list(self.joint_names)
        if list(joint_names) != expected:
            missing = [j for j in expected if j not in joint_names]
            extra = [j for j in joint_names if j not in expected]
            detail = f"missing {missing}, not joints of the robot {extra}" if missing or extra else "in another order"
            raise ValueError(f"{where}: the columns must be the actuated joints of {self.origin} in URDF order "
                             f"{expected}; got {list(joint_names)} ({detail})")

    def demo_postures(self, joint_names: tuple[str, ...] | list[str], postures: NDArray[np.float64],
                      where: str) -> NDArray[np.float64]:
        """`postures` (columns named `joint_names`) as this robot's postures: the actuated joints'
        columns in URDF order. Columns may come in any order; a mimic joint's column is checked
        against its leader and dropped (the rule: `UrdfModel::demo_columns`). ValueError naming
        `where` and the joint (or row) that does not fit."""
        rows = np.ascontiguousarray(postures, dtype=np.float64)
        try:
            columns = _native.demo_columns(self.urdf_path, list(joint_names), rows)
        except ValueError as err:  # InvalidInputError stays one
            raise type(err)(f"{where}: {err}") from err
        chosen = rows[:, columns]
        self._refuse_degrees(chosen, where)
        return chosen

    def demos(self, path: str | Path, **options: Any) -> Demonstrations:
        """This robot's demonstrations from `path`, a file of postures or a recording read by
        `load_demos` with `options` (its keywords but `expected_joints`), as `latentrl train` and
        `check` read them: the actuated joints in URDF order (a file's columns in any order, a mimic
        joint's checked against its leader and dropped: `demo_postures`; a recording's other joints
        dropped). With ``degrees=True`` only the revolute and continuous joints are converted to
        radians, a prismatic joint's metres kept. ValueError naming the file and what does not fit."""
        recorded = recording_kind(Path(path)) is not None
        if options.get("degrees") is True:
            options["degrees"] = self._angular_joints(str(path))
        loaded = load_demos(path, expected_joints=self.joint_names if recorded else None, **options)
        postures = self.demo_postures(loaded.joint_names, loaded.postures, str(path))
        return Demonstrations(postures, self.joint_names, loaded.episodes, loaded.frames)

    def _joint_types(self) -> dict[str, str]:
        """Each joint's URDF type (mimic joints too), by name."""
        from latentrl.robot_info import urdf_info

        joints = urdf_info(self.urdf_path, balance_inertia=bool(self.to_dict()["balance_inertia"]))["joints"]
        return {str(j["name"]): str(j["type"]) for j in joints}

    def _angular_joints(self, where: str) -> tuple[str, ...]:
        """The robot's joints (mimic ones too) whose positions are angles, not lengths (prismatic):
        those `--degrees` converts; ValueError naming `where` for a robot without any."""
        angular = tuple(name for name, kind in self._joint_types().items() if kind != "prismatic")
        if not angular:
            raise ValueError(f"{where}: --degrees (degrees=True) was given, but {self.origin}'s robot has only "
                             "prismatic joints, whose positions are lengths; drop --degrees")
        return angular

    def postures_of(self, demos: Any, where: str = "demos") -> NDArray[np.float64]:
        """`demos` as this robot's (N, D) postures: a DataFrame whose columns are named (strings)
        is matched to the joints by name (`demo_postures`); other arrays must hold the joints in
        `joint_names` order. ValueError naming `where`, the shape or the joint that does not fit."""
        from latentrl._estimator import column_names

        names = column_names(demos)
        rows = np.asarray(demos, dtype=np.float64)
        if names is not None:
            return self.demo_postures([str(n) for n in names], rows, where)
        if rows.ndim != 2 or rows.shape[1] != len(self.joint_names):
            raise ValueError(f"{where}: expected postures of shape (N, {len(self.joint_names)}) for {self.name}'s "
                             f"joints {list(self.joint_names)}, got shape {rows.shape}")
        bad = np.argwhere(~np.isfinite(rows))
        if len(bad):
            row, column = bad[0]
            raise ValueError(f"{where}: posture {row} (counting from 0) has {self.joint_names[column]} = "
                             f"{rows[row, column]}: expected finite numbers ({len(bad)} such values)")
        return np.ascontiguousarray(rows)

    def _refuse_degrees(self, postures: NDArray[np.float64], where: str) -> None:
        """ValueError naming `where`, the first such posture and its joint when a value lies beyond
        ±2π rad and outside its joint's limits (`DEGREES`)."""
        beyond = (np.abs(postures) > DEGREES) & ((postures < self.lower) | (postures > self.upper))
        if not beyond.any():
            return
        rows, columns = np.nonzero(beyond)
        joint, value = self.joint_names[columns[0]], postures[rows[0], columns[0]]
        lower, upper = self.lower[columns[0]], self.upper[columns[0]]
        said = (f"{where}: posture {rows[0]} (counting from 0) has {joint} = {value:.6g}, beyond ±2π and outside the "
                f"joint's limits [{lower:.6g}, {upper:.6g}] ({len(np.unique(rows[columns == columns[0]]))} of "
                f"{len(postures)} postures like it)")
        if self._joint_types().get(joint) == "prismatic":
            raise ValueError(f"{said}: {joint} is prismatic, its positions metres; these look like millimetres or "
                             "centimetres: divide that column by 1000 or 100")
        raise ValueError(f"{said}: these look like degrees; give --degrees (degrees=True) or write the "
                         "demonstrations in radians (np.deg2rad)")

    @property
    def warnings(self) -> list[str]:
        """What loading the robot repaired (`balance_inertia = true`: each link's inertia), one
        sentence each."""
        return list(self._native.warnings)

    @property
    def urdf_path(self) -> Path:
        """The robot's URDF file (the task's `urdf` key, relative to `base_dir`)."""
        return self.base_dir / str(self.to_dict()["urdf"])

    @property
    def name(self) -> str:
        """The task's name."""
        return self._native.name

    @property
    def origin(self) -> str:
        """Where the task came from (its file, or the name it was given)."""
        return self._native.origin

    @property
    def joint_names(self) -> tuple[str, ...]:
        """The robot's actuated joints, the columns of its postures (URDF order)."""
        return tuple(self._native.joint_names)

    @property
    def link_names(self) -> tuple[str, ...]:
        """Every URDF link, in URDF order (the rows of `TaskPlant.link_poses`)."""
        return tuple(self._native.link_names)

    @property
    def edges(self) -> list[tuple[str, str]]:
        """(parent link, child link) of every joint: the kinematic tree, to draw it."""
        return list(self._native.edges)

    @property
    def effectors(self) -> tuple[str, ...]:
        """The effector links, whose positions the reward and the paths use."""
        return tuple(self._native.effectors)

    @property
    def lower(self) -> NDArray[np.float64]:
        """Lower joint limits."""
        return np.asarray(self._native.lower)

    @property
    def upper(self) -> NDArray[np.float64]:
        """Upper joint limits."""
        return np.asarray(self._native.upper)

    @property
    def row_len(self) -> int:
        """Columns of a recorded path row: 3 per effector, the base pose (7), the joints."""
        return int(self._native.row_len)

    @property
    def rl_dt(self) -> float:
        """Duration of one RL step (s)."""
        return float(self._native.rl_dt)

    def row_slices(self) -> dict[str, slice]:
        """Where a recorded path row keeps the effectors (x, y, z each), the base position, the
        base quaternion (x, y, z, w) and the joints."""
        e = 3 * len(self.effectors)
        return {
            "effectors": slice(0, e),
            "base_position": slice(e, e + 3),
            "base_quaternion": slice(e + 3, e + 7),
            "joints": slice(e + 7, e + 7 + len(self.joint_names)),
        }

    def __repr__(self) -> str:
        return f"Task({self.name!r}, {self.origin!r}, {len(self.joint_names)} joints, effectors {list(self.effectors)})"


def task_digest(config: Mapping[str, Any], urdf_path: Path) -> str:
    """`Task.digest` of the task keys `config` (`Task.to_dict()`, `[run]` left out) and the URDF
    at `urdf_path`; a saved policy's recorded keys give the digest it was saved with."""
    text = json.dumps({k: v for k, v in config.items() if k != "run"}, sort_keys=True, allow_nan=True)
    try:
        urdf = read_bounded(urdf_path, MAX_URDF_BYTES, "a URDF")
    except ValueError as err:
        raise ValueError(f"{urdf_path}: {err}") from None
    import hashlib  # OpenSSL: loaded by the first digest, not by `import latentrl`

    return hashlib.sha256(text.encode() + b"\0" + urdf).hexdigest()
