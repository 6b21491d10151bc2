"""Issue #38: a probe of hostile inputs over six surfaces, run as a user would meet them.

Not a pytest module (no ``test_`` prefix): it builds one tiny `latentrl train` run, a rollout of it
and a fitted model, then for each case builds a hostile input in a temporary folder, runs one
command on it in a child process with a timeout and classifies what happened:

- ``refused, named``: exit 1/2 (an API call: ValueError/TypeError/OSError), no traceback, and the
  message names the file, key or flag;
- ``refused, unnamed``: the same, but the message names none of them;
- ``ran``: exit 0 where running is right (a benign oddity, a tampered hull cache entry that is
  replaced, a folder that is fine), checked where it matters (the hull, the run's trials);
- ``silent``: exit 0 on an input that must be refused, or a wrong result (a bad hull);
- ``lost``: a run whose finished trials did not survive (or could not be resumed);
- ``half-written``: a refused command that left a partial output file behind;
- ``traceback``: a Python traceback on stderr (or an undocumented exception type);
- ``abort``: killed by a signal it was not sent, or an exit code outside 0/1/2/3/130 (a process
  fault's case that dies of the signal it was sent, or exits 130, counts as ``ran`` when its run
  survives: the trials it kept are resumed to the end);
- ``hang``: the timeout was reached.

Usage (about ten minutes on two cores)::

    PYTHONPATH=python python tests/hostile_probe.py --markdown /tmp/probe.md [--jobs 3] [--only WORD]

The table it prints (markdown) is the one in docs/robustness.md. Cases that need root (a full
tmpfs, a read-only mount) are skipped otherwise.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
from collections import Counter
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any
from collections.abc import Callable

import numpy as np
from test_issue38_files import INERTIAL, cube_stl, entry_bytes  # tests/ is this script's folder

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "glass_arm"
PY = sys.executable
TIMEOUT = 120.0
ROOT_USER = os.geteuid() == 0
TINY = ["--quick", "--trials", "1", "--episodes", "20", "--test-episodes", "2", "--no-progress"]


@dataclass
class Base:
    """The shared inputs every case copies: a train run, a rollout of it, a fitted GPLVM."""

    dir: Path

    @property
    def run(self) -> Path:
        return self.dir / "tr"

    @property
    def rollout(self) -> Path:
        return self.dir / "ro"

    @property
    def model(self) -> Path:
        return self.dir / "model.npz"


@dataclass
class Probe:
    """One command on one hostile input: `argv` for the CLI, or `api` Python code run in a child."""

    argv: list[str] | None = None
    api: str | None = None
    names: list[str] = field(default_factory=list)
    """What a good message names (any one): the file, key or flag."""
    expect: str = "refuse"
    """"refuse", "ok" (must run), or "either"."""
    env: dict[str, str] = field(default_factory=dict)
    check: Callable[[subprocess.CompletedProcess[str]], str | None] | None = None
    """After the command: a class ("silent", "lost", "half-written") when something is wrong."""
    custom: Callable[[], tuple[subprocess.CompletedProcess[str], float]] | None = None
    shown: str = ""
    """The command as the table shows it (default: from argv)."""
    stdout_to: str | None = None


@dataclass
class Case:
    surface: int
    name: str
    build: Callable[[Path, Base], Probe]
    root_only: bool = False


CASES: list[Case] = []


def case(surface: int, name: str, root_only: bool = False) -> Callable[[Callable[[Path, Base], Probe]], Callable[[Path, Base], Probe]]:
    def register(build: Callable[[Path, Base], Probe]) -> Callable[[Path, Base], Probe]:
        CASES.append(Case(surface, name, build, root_only))
        return build
    return register


def cli(*args: Any) -> list[str]:
    return [PY, "-m", "latentrl", *map(str, args)]


# --------------------------------------------------------------------------------------------
# (1) task files and CLI flags

TASK = (EXAMPLE / "glass_arm.toml").read_text()


def task_file(tmp: Path, text: str, name: str = "task.toml") -> Path:
    shutil.copy(EXAMPLE / "glass_arm.urdf", tmp / "glass_arm.urdf")
    path = tmp / name
    path.write_text(text)
    return path


def train(tmp: Path, task: Path | str, *extra: Any, demos: Path | str = EXAMPLE / "demos.csv") -> list[str]:
    return cli("train", task, "--demos", demos, *TINY, "--out", tmp / "out", *extra)


def no_output(tmp: Path) -> Callable[[subprocess.CompletedProcess[str]], str | None]:
    """A refused train leaves no run folder (or an empty one) behind."""
    def check(result: subprocess.CompletedProcess[str]) -> str | None:
        out = tmp / "out"
        if result.returncode != 0 and out.is_dir() and any(out.iterdir()):
            return "half-written"
        return None
    return check


TASK_EDITS: list[tuple[str, str, str, list[str]]] = [
    # name, old text, new text, what the message should name
    ("task: urdf missing", 'urdf = "glass_arm.urdf"', 'urdf = "nowhere.urdf"', ["nowhere.urdf"]),
    ("task: urdf is a folder", 'urdf = "glass_arm.urdf"', 'urdf = "."', ["urdf", "task.toml"]),
    ("task: unknown top-level key", 'root = "fixed"', 'root = "fixed"\ntaget = 1', ["taget"]),
    ("task: misspelt learner key", "alpha = 0.8", "alpah = 0.8", ["alpah"]),
    ("task: servo.kp negative", "kp = 2000.0", "kp = -2000.0", ["kp"]),
    ("task: servo.kp a string", "kp = 2000.0", 'kp = "stiff"', ["kp"]),
    ("task: physics.dt 0", "dt = 0.008333333333333333", "dt = 0.0", ["dt"]),
    ("task: physics.dt nan", "dt = 0.008333333333333333", "dt = nan", ["dt"]),
    ("task: physics.dt inf", "dt = 0.008333333333333333", "dt = inf", ["dt"]),
    ("task: physics.substeps 0", "substeps = 6", "substeps = 0", ["substeps"]),
    ("task: physics.substeps 1.5", "substeps = 6", "substeps = 1.5", ["substeps"]),
    ("task: physics.substeps 2**40", "substeps = 6", "substeps = 1099511627776", ["substeps"]),
    ("task: target.position of 2 values", "position = [[-0.25, 0.35, 0.0]]", "position = [[-0.25, 0.35]]", ["position"]),
    ("task: target.position empty", "position = [[-0.25, 0.35, 0.0]]", "position = []", ["position"]),
    ("task: target.width negative", "width = 0.08", "width = -0.08", ["width"]),
    ("task: target.theta inf", "theta = 0.35", "theta = inf", ["theta"]),
    ("task: constraint kind unknown", 'kind = "orientation"', 'kind = "telepathy"', ["kind", "telepathy"]),
    ("task: constraint link unknown", 'link = "glass"', 'link = "cup"', ["cup"]),
    ("task: constraint axis zero", "axis = [0.0, 1.0, 0.0]", "axis = [0.0, 0.0, 0.0]", ["axis"]),
    ("task: constraint max_angle negative", "max_angle = 0.3", "max_angle = -0.3", ["max_angle"]),
    ("task: episode.max_steps 0", "max_steps = 200", "max_steps = 0", ["max_steps"]),
    ("task: episode.max_steps 10**15", "max_steps = 200", "max_steps = 1000000000000000", ["max_steps"]),
    ("task: episode.start unknown", 'start = "uniform"', 'start = "sideways"', ["start", "sideways"]),
    ("task: learner.gamma 1.5", "gamma = 0.99", "gamma = 1.5", ["gamma"]),
    ("task: learner.beta negative", "beta = 20.0", "beta = -20.0", ["beta"]),
    ("task: learner.actions unknown", 'actions = "axes_and_diagonals"', 'actions = "everywhere"', ["actions", "everywhere"]),
    ("task: effector unknown", 'effectors = ["glass"]', 'effectors = ["mug"]', ["mug"]),
    ("task: effectors empty", 'effectors = ["glass"]', "effectors = []", ["effectors"]),
    ("task: root unknown", 'root = "fixed"', 'root = "hovering"', ["root", "hovering"]),
    ("task: duplicate key", "gamma = 0.99", "gamma = 0.99\ngamma = 0.9", ["gamma", "task.toml"]),
    ("task: [servo] a number", "[servo]\nkp = 2000.0\nkd = 20.0\n", "servo = 3\n", ["servo"]),
    ("task: unclosed table header", "[learner]", "[learner", ["task.toml"]),
]


def _task_edit(name: str, old: str, new: str, names: list[str]) -> None:
    assert old in TASK, name

    @case(1, name)
    def build(tmp: Path, base: Base) -> Probe:
        return Probe(train(tmp, task_file(tmp, TASK.replace(old, new, 1))), names=names, check=no_output(tmp))


for _edit in TASK_EDITS:
    _task_edit(*_edit)


@case(1, "task: name missing (defaults to \"task\")")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(train(tmp, task_file(tmp, TASK.replace('name = "glass_arm"\n', "", 1))), expect="either", check=no_output(tmp))


@case(1, "task: empty file")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(train(tmp, task_file(tmp, "")), names=["task.toml", "name", "urdf"], check=no_output(tmp))


@case(1, "task: random bytes")
def _(tmp: Path, base: Base) -> Probe:
    path = task_file(tmp, "")
    path.write_bytes(bytes(range(256)) * 4)
    return Probe(train(tmp, path), names=["task.toml"], check=no_output(tmp))


@case(1, "task: UTF-16 with BOM")
def _(tmp: Path, base: Base) -> Probe:
    path = task_file(tmp, "")
    path.write_bytes(TASK.encode("utf-16"))
    return Probe(train(tmp, path), names=["task.toml"], check=no_output(tmp))


@case(1, "task: file missing")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(train(tmp, tmp / "none.toml"), names=["none.toml"], check=no_output(tmp))


@case(1, "task: dangling symlink")
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "link.toml").symlink_to(tmp / "gone.toml")
    return Probe(train(tmp, tmp / "link.toml"), names=["link.toml", "gone.toml"], check=no_output(tmp))


@case(1, "task: unknown shipped name")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(train(tmp, "no_such_robot"), names=["no_such_robot"], check=no_output(tmp))


FLAG_CASES: list[tuple[str, list[str], list[str]]] = [
    ("flag: --episodes 0", ["--episodes", "0"], ["--episodes", "episodes"]),
    ("flag: --episodes -5", ["--episodes", "-5"], ["--episodes", "episodes"]),
    ("flag: --episodes abc", ["--episodes", "abc"], ["--episodes"]),
    ("flag: --episodes 1e12", ["--episodes", "1e12"], ["--episodes", "episodes"]),
    ("flag: --trials 0", ["--trials", "0"], ["--trials", "trials"]),
    ("flag: --test-episodes -1", ["--test-episodes", "-1"], ["--test-episodes", "test_episodes"]),
    ("flag: --seed -1", ["--seed", "-1"], ["--seed", "seed"]),
    ("flag: --seed 2**70", ["--seed", str(2**70)], ["--seed", "seed"]),
    ("flag: --latent-margin -1", ["--latent-margin", "-1"], ["--latent-margin", "latent_margin"]),
    ("flag: --latent-margin nan", ["--latent-margin", "nan"], ["--latent-margin", "latent_margin"]),
    ("flag: --physics.dt -0.01", ["--physics.dt", "-0.01"], ["--physics.dt", "physics.dt", "dt"]),
    ("flag: --servo.kp inf", ["--servo.kp", "inf"], ["--servo.kp", "servo.kp", "kp"]),
    ("flag: --servo.use-urdf-effort maybe", ["--servo.use-urdf-effort", "maybe"], ["--servo.use-urdf-effort"]),
    ("flag: --encoder unknown", ["--encoder", "telepathic"], ["--encoder", "encoder"]),
    ("flag: --gplvm-max-iter 0", ["--gplvm-max-iter", "0"], ["--gplvm-max-iter", "gplvm_max_iter", "max_iter"]),
    ("flag: --joint-map to an unknown joint", ["--joint-map", "shoulder=hip"], ["--joint-map", "hip"]),
    ("flag: --model a missing file", ["--model", "/nonexistent/m.npz"], ["m.npz", "--model"]),
]


def _flag_case(name: str, extra: list[str], names: list[str]) -> None:
    @case(1, name)
    def build(tmp: Path, base: Base) -> Probe:
        return Probe(train(tmp, EXAMPLE / "glass_arm.toml", *extra), names=names, check=no_output(tmp))


for _flag in FLAG_CASES:
    _flag_case(*_flag)


DEMO_CASES: list[tuple[str, str, list[str]]] = [
    ("demos: empty file", "", ["demos.csv"]),
    ("demos: header only", "shoulder,elbow,wrist\n", ["demos.csv"]),
    ("demos: a column missing", "shoulder,elbow\n0.1,0.2\n0.3,0.4\n", ["demos.csv", "wrist"]),
    ("demos: NaN cell", "shoulder,elbow,wrist\n0.1,nan,0.2\n0.3,0.4,0.5\n", ["demos.csv"]),
    ("demos: text cell", "shoulder,elbow,wrist\n0.1,elbow,0.2\n0.3,0.4,0.5\n", ["demos.csv"]),
    ("demos: ragged row", "shoulder,elbow,wrist\n0.1,0.2\n0.3,0.4,0.5\n", ["demos.csv"]),
    ("demos: duplicate header", "shoulder,shoulder,wrist\n0.1,0.2,0.3\n0.3,0.4,0.5\n", ["demos.csv", "shoulder"]),
    ("demos: postures beyond the joint limits", "shoulder,elbow,wrist\n" + "".join(f"{9 + i / 10},9,9\n" for i in range(20)),
     ["demos.csv", "shoulder"]),
    ("demos: every posture the same", "shoulder,elbow,wrist\n" + "0.1,0.2,0.3\n" * 20, ["demos.csv"]),
]


def _demo_case(name: str, text: str, names: list[str]) -> None:
    @case(1, name)
    def build(tmp: Path, base: Base) -> Probe:
        (tmp / "demos.csv").write_text(text)
        return Probe(train(tmp, EXAMPLE / "glass_arm.toml", demos=tmp / "demos.csv"), names=names, check=no_output(tmp))


for _demo in DEMO_CASES:
    _demo_case(*_demo)


@case(1, "demos: a folder")
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "d.csv").mkdir()
    return Probe(train(tmp, EXAMPLE / "glass_arm.toml", demos=tmp / "d.csv"), names=["d.csv"], check=no_output(tmp))


@case(1, "demos: unknown extension")
def _(tmp: Path, base: Base) -> Probe:
    shutil.copy(EXAMPLE / "demos.csv", tmp / "demos.xlsx")
    return Probe(train(tmp, EXAMPLE / "glass_arm.toml", demos=tmp / "demos.xlsx"), names=["demos.xlsx"],
                 check=no_output(tmp))


@case(1, "flag: rollout --episodes 0")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("rollout", base.run, "--episodes", "0", "--out", tmp / "ro", "--no-progress"), names=["--episodes"])


@case(1, "flag: rollout --trial 5 of 1")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("rollout", base.run, "--trial", "5", "--out", tmp / "ro", "--no-progress"), names=["--trial", "trial"])


@case(1, "flag: rollout --policy unknown")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("rollout", base.run, "--policy", "greedy,lucky", "--out", tmp / "ro", "--no-progress"),
                 names=["--policy", "lucky"])


@case(1, "flag: replay --episode 9999")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("replay", base.run, "--episode", "9999", "--out", tmp / "v.gif", "--max-frames", "3"),
                 names=["--episode", "9999"])


@case(1, "flag: replay --test -1")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("replay", base.run, "--test", "-1", "--out", tmp / "v.gif", "--max-frames", "3"), names=["--test"])


@case(1, "flag: replay --max-frames 0")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("replay", base.run, "--test", "0", "--out", tmp / "v.gif", "--max-frames", "0"),
                 names=["--max-frames"])


@case(1, "flag: replay --out .xyz")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("replay", base.run, "--test", "0", "--out", tmp / "v.xyz", "--max-frames", "3"),
                 names=["--out", "v.xyz", ".xyz"])


@case(1, "flag: replay --fps 0")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("replay", base.run, "--test", "0", "--out", tmp / "v.gif", "--fps", "0"), names=["--fps"])


@case(1, "flag: fit --n-components 0")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("fit", EXAMPLE / "demos.csv", "--n-components", "0", "--out", tmp / "m.npz"),
                 names=["--n-components", "n_components"])


@case(1, "flag: fit --n-components 50 (over the 3 joints)")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("fit", EXAMPLE / "demos.csv", "--model", "pca", "--n-components", "50", "--out", tmp / "m.npz"),
                 names=["--n-components", "n_components"])


@case(1, "flag: report on a missing folder")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("report", tmp / "nothing"), names=["nothing"])


@case(1, "flag: report on a file")
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "f").write_text("x")
    return Probe(cli("report", tmp / "f"), names=[str(tmp / "f")])


@case(1, "flag: train --resume on an empty folder (starts the run)")
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "out").mkdir()
    return Probe(train(tmp, EXAMPLE / "glass_arm.toml", "--resume"), names=["out", "results.json"], expect="either")


# --------------------------------------------------------------------------------------------
# (2) URDFs and meshes: `latentrl urdf-info` (the loader a task uses)

ARM = (EXAMPLE / "glass_arm.urdf").read_text()


def mesh_robot(mesh: str, scale: str = "1 1 1") -> str:
    return (f'<robot name="m"><link name="base">{INERTIAL}<collision><geometry><mesh filename="{mesh}" '
            f'scale="{scale}"/></geometry></collision></link></robot>')


URDF_TEXTS: list[tuple[str, str, list[str]]] = [
    ("urdf: empty", "", ["robot.urdf"]),
    ("urdf: not XML", "hello, robot", ["robot.urdf"]),
    ("urdf: truncated", ARM[: len(ARM) // 2], ["robot.urdf"]),
    ("urdf: no links", '<robot name="r"></robot>', ["robot.urdf", "link"]),
    ("urdf: joint to a missing link", ARM.replace('<child link="fore"/>', '<child link="forearm"/>', 1), ["forearm", "elbow"]),
    ("urdf: a 2-cycle of joints", ARM.replace("</robot>", '<joint name="back" type="fixed"><parent link="fore"/>'
                                              '<child link="upper"/></joint></robot>'), ["back", "upper"]),
    ("urdf: negative mass", ARM.replace('<mass value="0.4"/>', '<mass value="-0.4"/>', 1), ["upper", "mass"]),
    ("urdf: NaN mass", ARM.replace('<mass value="0.4"/>', '<mass value="NaN"/>', 1), ["upper", "mass"]),
    ("urdf: inertia breaking the triangle inequality", ARM.replace('iyy="3.1e-3" iyz="0" izz="3.1e-3"', 'iyy="3.1e-3" iyz="0" izz="9"', 1),
     ["upper", "inertia"]),
    ("urdf: limit lower > upper", ARM.replace('lower="-3.1" upper="3.1"', 'lower="3.1" upper="-3.1"', 1), ["shoulder", "limit"]),
    ("urdf: zero axis", ARM.replace('<axis xyz="0 0 1"/>', '<axis xyz="0 0 0"/>', 1), ["shoulder", "axis"]),
    ("urdf: unknown joint type", ARM.replace('type="revolute"', 'type="wobbly"', 1), ["shoulder", "wobbly"]),
    ("urdf: duplicate link", ARM.replace('<link name="glass"/>', '<link name="glass"/><link name="glass"/>'), ["glass"]),
    ("urdf: a billion-laughs entity", '<?xml version="1.0"?><!DOCTYPE r [<!ENTITY a "aaaaaaaaaa">'
     '<!ENTITY b "&a;&a;&a;&a;&a;&a;&a;&a;&a;&a;"><!ENTITY c "&b;&b;&b;&b;&b;&b;&b;&b;&b;&b;">'
     '<!ENTITY d "&c;&c;&c;&c;&c;&c;&c;&c;&c;&c;"><!ENTITY e "&d;&d;&d;&d;&d;&d;&d;&d;&d;&d;">]>'
     '<robot name="&e;"><link name="base"/></robot>', ["robot.urdf"]),
    ("urdf: NaN joint origin", ARM.replace('<origin xyz="0.30 0 0"/>', '<origin xyz="NaN 0 0"/>', 1), ["elbow", "origin"]),
    ("urdf: link name of 100 000 chars", ARM.replace('"glass"', '"' + "g" * 100_000 + '"'), ["robot.urdf", "g" * 20]),
    ("urdf: a mesh file missing", mesh_robot("none.stl"), ["none.stl"]),
    ("urdf: mesh with package:// of an unknown package", mesh_robot("package://nopkg/m.stl"), ["nopkg", "m.stl"]),
    ("urdf: mesh path a folder", mesh_robot("."), ["robot.urdf", "base", "mesh"]),
    ("urdf: mesh of unknown extension", mesh_robot("m.xyz"), ["m.xyz"]),
]


BENIGN = ("urdf: no links", "urdf: link name of 100 000 chars", "mesh: scale negative")
"""Inputs that may load: urdf-info reports a robot of no links as such; a long name is a name; a
negative scale mirrors a mesh (URDF allows it)."""


def _urdf_case(name: str, text: str, names: list[str]) -> None:
    @case(2, name)
    def build(tmp: Path, base: Base) -> Probe:
        (tmp / "robot.urdf").write_text(text)
        return Probe(cli("urdf-info", tmp / "robot.urdf"), names=names, expect="either" if name in BENIGN else "refuse")


for _u in URDF_TEXTS:
    _urdf_case(*_u)


MESH_BYTES: list[tuple[str, str, Callable[[], bytes], str, list[str]]] = [
    ("mesh: empty STL", "m.stl", lambda: b"", "1 1 1", ["m.stl"]),
    ("mesh: random bytes as STL", "m.stl", lambda: bytes(range(256)) * 3, "1 1 1", ["m.stl"]),
    ("mesh: STL cut short", "m.stl", lambda: cube_stl()[:300], "1 1 1", ["m.stl"]),
    ("mesh: STL with NaN vertices", "m.stl", lambda: cube_stl().replace(struct.pack("<f", 1.0), struct.pack("<f", float("nan"))),
     "1 1 1", ["m.stl"]),
    ("mesh: STL of one flat triangle", "m.stl", lambda: bytes(80) + struct.pack("<I", 1) + struct.pack("<12fH", 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0),
     "1 1 1", ["m.stl", "base"]),
    ("mesh: scale 0", "m.stl", cube_stl, "0 0 0", ["scale", "m.stl", "base"]),
    ("mesh: scale negative", "m.stl", cube_stl, "-1 1 1", ["scale", "m.stl", "base"]),
    ("mesh: scale NaN", "m.stl", cube_stl, "NaN 1 1", ["scale", "m.stl", "base"]),
    ("mesh: OBJ face index out of range", "m.obj", lambda: b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 99\n", "1 1 1", ["m.obj"]),
    ("mesh: OBJ with text vertices", "m.obj", lambda: b"v a b c\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "1 1 1", ["m.obj"]),
    ("mesh: COLLADA not XML", "m.dae", lambda: b"<COLLADA><mesh", "1 1 1", ["m.dae"]),
    ("mesh: COLLADA declaring 2e9 floats", "m.dae", lambda: (
        b'<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
        b'<library_geometries><geometry id="g"><mesh><source id="s"><float_array id="a" count="2000000000">0 0 0'
        b'</float_array></source></mesh></geometry></library_geometries></COLLADA>'), "1 1 1", ["m.dae"]),
    ("mesh: /dev/zero behind a symlink", "m.stl", lambda: b"", "1 1 1", ["m.stl", "/dev/zero"]),
]


def _mesh_case(name: str, file: str, data: Callable[[], bytes], scale: str, names: list[str]) -> None:
    @case(2, name)
    def build(tmp: Path, base: Base) -> Probe:
        if "/dev/zero" in name:
            (tmp / file).symlink_to("/dev/zero")
        else:
            (tmp / file).write_bytes(data())
        (tmp / "robot.urdf").write_text(mesh_robot(file, scale))
        return Probe(cli("urdf-info", tmp / "robot.urdf"), names=names, env={"LATENTRL_CACHE_DIR": str(tmp / "cache")},
                     expect="either" if name in BENIGN else "refuse")


for _m in MESH_BYTES:
    _mesh_case(*_m)


@case(2, "urdf: a task whose URDF has a missing mesh")
def _(tmp: Path, base: Base) -> Probe:
    task = task_file(tmp, TASK)
    (tmp / "glass_arm.urdf").write_text(ARM.replace('<geometry><capsule radius="0.02" length="0.26"/></geometry>',
                                                    '<geometry><mesh filename="lost.stl"/></geometry>', 1))
    return Probe(train(tmp, task), names=["lost.stl"], check=no_output(tmp))


# --------------------------------------------------------------------------------------------
# (3) saved runs and policies


def copy_run(tmp: Path, base: Base) -> Path:
    run = tmp / "run"
    shutil.copytree(base.run, run)
    return run


def npz_edit(path: Path, edit: Callable[[dict[str, Any]], dict[str, Any]]) -> None:
    with np.load(path, allow_pickle=False) as z:
        arrays = {k: z[k] for k in z.files}
    np.savez(path, **edit(arrays))


def json_edit(path: Path, edit: Callable[[Any], Any]) -> None:
    path.write_text(json.dumps(edit(json.loads(path.read_text()))))


def set_key(d: dict[str, Any], key: str, value: Any) -> dict[str, Any]:
    d[key] = value
    return d


def drop_key(d: dict[str, Any], key: str) -> dict[str, Any]:
    d.pop(key)
    return d


def nested(d: dict[str, Any], path: str, value: Any) -> dict[str, Any]:
    *parents, last = path.split(".")
    node = d
    for p in parents:
        node = node[p]
    if value is KeyError:
        node.pop(last)
    else:
        node[last] = value
    return d


RUN_COMMANDS: dict[str, Callable[[Path, Path], list[str]]] = {
    "report": lambda run, tmp: cli("report", run),
    "rollout": lambda run, tmp: cli("rollout", run, "--episodes", "2", "--out", tmp / "ro", "--no-progress"),
    "plot": lambda run, tmp: cli("plot", run, "--out", tmp / "figs"),
    "replay": lambda run, tmp: cli("replay", run, "--test", "0", "--out", tmp / "v.gif", "--max-frames", "3"),
    "resume": lambda run, tmp: cli("train", EXAMPLE / "glass_arm.toml", "--demos", EXAMPLE / "demos.csv", *TINY,
                                   "--out", run, "--resume"),
    "resume-reordered": lambda run, tmp: cli("train", EXAMPLE / "glass_arm.toml", "--demos", reordered_demos(tmp), *TINY,
                                             "--out", run, "--resume"),
}

Edit = Callable[[Path], None]
SHOWN = {"resume": "train … --out RUN --resume", "resume-reordered": "train … --demos REORDERED --out RUN --resume"}


def reordered_demos(tmp: Path) -> Path:
    """The example demos, last posture first (another GPLVM fit: a run must not continue on it)."""
    header, *rows = (EXAMPLE / "demos.csv").read_text().splitlines()
    path = tmp / "demos.csv"
    path.write_text("\n".join([header, *rows[::-1]]) + "\n")
    return path

RUN_EDITS: list[tuple[str, str, Edit, list[str], list[str]]] = [
    # name, file, edit of the run folder, commands, what to name
    ("results.json: a list", "results.json", lambda r: (r / "results.json").write_text("[1, 2]"), ["replay", "resume"], []),
    ("results.json: truncated", "results.json", lambda r: (r / "results.json").write_text((r / "results.json").read_text()[:200]),
     ["replay", "resume"], []),
    ("results.json: empty", "results.json", lambda r: (r / "results.json").write_text(""), ["replay"], []),
    ("results.json: deleted", "results.json", lambda r: (r / "results.json").unlink(), ["replay"], []),
    ("results.json: deleted (resume starts the run anew)", "results.json", lambda r: (r / "results.json").unlink(), ["resume"], []),
    ("results.json: preset a string", "results.json", lambda r: json_edit(r / "results.json", lambda d: set_key(d, "preset", "x")),
     ["resume", "replay"], ["preset"]),
    ("results.json: setup dropped (a run from before the record)", "results.json", lambda r: json_edit(r / "results.json", lambda d: drop_key(d, "setup")),
     ["resume", "replay"], ["setup"]),
    ("results.json: setup.inputs dropped (a run from before the record)", "results.json",
     lambda r: json_edit(r / "results.json", lambda d: nested(d, "setup.inputs", KeyError)), ["resume"], ["inputs"]),
    ("results.json: setup.inputs dropped, then resumed on reordered demos", "results.json",
     lambda r: json_edit(r / "results.json", lambda d: nested(d, "setup.inputs", KeyError)), ["resume-reordered"],
     ["inputs", "demos"]),
    ("resumed on reordered demos", "results.json", lambda r: None, ["resume-reordered"], ["demos"]),
    ("results.json: preset.seed edited", "results.json",
     lambda r: json_edit(r / "results.json", lambda d: nested(d, "preset.seed", 7)), ["resume"], ["seed"]),
    ("results.json: NaN under an unknown trials key (ignored)", "results.json",
     lambda r: (r / "results.json").write_text((r / "results.json").read_text().replace('"trials": {', '"trials": {"x": NaN, ', 1)),
     ["replay", "resume"], ["trials", "x"]),
    ("results.json: nested 100 000 deep", "results.json", lambda r: (r / "results.json").write_text("[" * 100_000 + "]" * 100_000),
     ["replay", "resume"], []),
    ("results.json: a FIFO", "results.json", lambda r: ((r / "results.json").unlink(), os.mkfifo(r / "results.json")), ["replay", "resume"], []),
    ("returns.npz: preset_json dropped (a run from before it)", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: drop_key(d, "preset_json")), ["resume", "replay"], []),
    ("returns.npz: latent_test_paths dropped", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: drop_key(d, "latent_test_paths")), ["replay"], ["--test", "test"]),
    ("returns.npz: latent dropped", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: drop_key(d, "latent")), ["resume", "replay"], ["latent"]),
    ("returns.npz: latent_end of unknown codes", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: set_key(d, "latent_end", np.full_like(d["latent_end"], 99))),
     ["resume"], ["latent_end"]),
    ("returns.npz: arrays flattened", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: {k: (v.reshape(-1) if v.ndim > 1 else v) for k, v in d.items()}),
     ["resume", "replay"], []),
    ("returns.npz: arrays as strings", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: {k: v.astype(str) for k, v in d.items()}), ["replay", "resume"], []),
    ("returns.npz: not a zip", "returns.npz", lambda r: (r / "returns.npz").write_bytes(b"hello"), ["replay", "resume"], []),
    ("returns.npz: empty", "returns.npz", lambda r: (r / "returns.npz").write_bytes(b""), ["resume"], []),
    ("returns.npz: an object array (pickle)", "returns.npz",
     lambda r: npz_edit(r / "returns.npz", lambda d: {**d, "evil": np.array([{"a": 1}], dtype=object)}), ["replay", "resume"], []),
    ("policy.npz: weights dropped", "policy.npz", lambda r: npz_edit(r / "policy.npz", lambda d: drop_key(d, "weights")),
     ["report", "rollout"], ["weights"]),
    ("policy.npz: weights of 3 values", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "weights", d["weights"][..., :3])), ["rollout", "report"], ["weights"]),
    ("policy.npz: NaN weights", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "weights", np.full_like(d["weights"], np.nan))),
     ["rollout", "report"], ["weights"]),
    ("policy.npz: format_version 99", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "format_version", np.array(99))), ["rollout", "report"],
     ["format_version"]),
    ("policy.npz: format of a GPLVM", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "format", np.array("latentrl.GPLVM"))), ["rollout"], ["format", "GPLVM"]),
    ("policy.npz: not a zip", "policy.npz", lambda r: (r / "policy.npz").write_bytes(b"PK\x03\x04junk"), ["rollout", "report"], []),
    ("policy.npz: task JSON cut short", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "task", np.array(str(d["task"])[:40]))), ["rollout"], ["task"]),
    ("policy.npz: task_digest edited", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "task_digest", np.array("0" * 64))), ["rollout"], ["task"]),
    ("policy.npz: task_dir moved away", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "task_dir", np.array("/nonexistent/dir"))), ["rollout"],
     ["/nonexistent/dir", "glass_arm.urdf"]),
    ("policy.npz: latent_low above latent_high", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(set_key(d, "latent_low", d["latent_high"] + 1), "latent_high", d["latent_low"])),
     ["rollout"], ["latent_low", "latent_high", "latent"]),
    ("policy.npz: latent_low NaN", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "latent_low", np.full_like(d["latent_low"], np.nan))),
     ["rollout"], ["latent_low", "latent"]),
    ("policy.npz: demos of 2 joints", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "demos", d["demos"][:, :2])), ["rollout"], ["demos"]),
    ("policy.npz: record.returns of another shape", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "record.returns", d["record.returns"][:, :3].T)), ["report"],
     ["record.returns"]),
    ("policy.npz: record.ends of unknown codes", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: set_key(d, "record.ends", np.full_like(d["record.ends"], 99))), ["report"],
     ["record.ends", "ends"]),
    ("policy.npz: the model's arrays dropped", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: {k: v for k, v in d.items() if not k.startswith("model.")}), ["rollout"],
     ["model", "format"]),
    ("policy.npz: the model's latent points NaN", "policy.npz",
     lambda r: npz_edit(r / "policy.npz", lambda d: {k: (np.full_like(v, np.nan) if k == "model.Z_" else v) for k, v in d.items()}),
     ["rollout"], ["Z_", "model"]),
    ("policy.npz: deleted", "policy.npz", lambda r: (r / "policy.npz").unlink(), ["report", "rollout"], ["policy.npz"]),
    ("gplvm.npz: latent points dropped", "gplvm.npz",
     lambda r: npz_edit(r / "gplvm.npz", lambda d: {k: v for k, v in d.items() if k != "Z_"}), ["replay", "resume"], ["Z_"]),
    ("gplvm.npz: latent points permuted", "gplvm.npz",
     lambda r: npz_edit(r / "gplvm.npz", lambda d: set_key(d, "Z_", d["Z_"][::-1].copy())), ["replay", "resume"], ["model", "sha256"]),
    ("gplvm.npz: not a zip", "gplvm.npz", lambda r: (r / "gplvm.npz").write_bytes(b"\x00" * 64), ["replay", "resume"], []),
    ("gplvm.npz: deleted (a run from before it: refitted, compared)", "gplvm.npz", lambda r: (r / "gplvm.npz").unlink(), ["replay", "resume"], []),
    ("a stray .tmp file beside results.json", "results.json.tmp",
     lambda r: (r / "results.json.tmp").write_text("{"), ["resume"], []),
]


def _run_case(name: str, file: str, edit: Edit, commands: list[str], names: list[str]) -> None:
    for command in commands:
        expect = "either" if file == "results.json.tmp" or "(" in name else "refuse"

        @case(3, f"{name} → {command}")
        def build(tmp: Path, base: Base, command: str = command, expect: str = expect) -> Probe:
            run = copy_run(tmp, base)
            edit(run)
            return Probe(RUN_COMMANDS[command](run, tmp), names=[f"{run}/{file}", f"{run}", file, *names], expect=expect,
                         shown=f"latentrl {SHOWN.get(command, command + ' RUN')} ({file} edited)")


for _r in RUN_EDITS:
    _run_case(*_r)


ROLLOUT_EDITS: list[tuple[str, Callable[[Path], None], list[str]]] = [
    ("rollout.json: a list", lambda r: (r / "rollout.json").write_text("[]"), ["rollout.json"]),
    ("rollout.json: truncated", lambda r: (r / "rollout.json").write_text((r / "rollout.json").read_text()[:50]), ["rollout.json"]),
    ("rollout.json: deleted", lambda r: (r / "rollout.json").unlink(), ["rollout.json"]),
    ("rollout.json: policy path elsewhere (found beside it)", lambda r: json_edit(r / "rollout.json", lambda d: {
        k: ("/nonexistent/run" if isinstance(v, str) and v.endswith("tr") else v) for k, v in d.items()}), ["rollout.json", "/nonexistent"]),
    ("rollout.npz: paths dropped", lambda r: npz_edit(r / "rollout.npz", lambda d: {k: v for k, v in d.items() if not k.endswith("paths")}),
     ["rollout.npz"]),
    ("rollout.npz: NaN paths", lambda r: npz_edit(r / "rollout.npz", lambda d: {k: (np.full_like(v, np.nan) if k.endswith("paths") else v)
                                                                              for k, v in d.items()}), ["rollout.npz", "paths"]),
]


def _rollout_case(name: str, edit: Callable[[Path], None], names: list[str]) -> None:
    @case(3, f"{name} → replay")
    def build(tmp: Path, base: Base) -> Probe:
        ro = tmp / "ro"
        shutil.copytree(base.rollout, ro)
        edit(ro)
        return Probe(cli("replay", ro, "--episode", "0", "--out", tmp / "v.gif", "--max-frames", "3"), names=[*names, str(ro)],
                     shown="latentrl replay RO --episode 0", expect="either" if "(" in name else "refuse")


for _ro in ROLLOUT_EDITS:
    _rollout_case(*_ro)


# --------------------------------------------------------------------------------------------
# (4) the mesh hull cache: each must run and give the cube's true hull (8 vertices, 12 triangles)


def hull_ok(result: subprocess.CompletedProcess[str]) -> str | None:
    if result.returncode != 0:
        return None
    try:
        info = json.loads(result.stdout)
        found = info["collision"][0]["hull"]
    except (ValueError, KeyError, IndexError, TypeError):
        return "silent"
    return None if (found["vertices"], found["triangles"]) == (8, 12) else "silent"


def cache_probe(tmp: Path, cache: Path, poison: Callable[[Path], None] | None) -> Probe:
    """The cube robot; a first load fills `cache`, `poison(entry)` edits the entry, the probe is a second load."""
    (tmp / "cube.stl").write_bytes(cube_stl())
    (tmp / "robot.urdf").write_text(mesh_robot("cube.stl"))
    env = {**os.environ, "LATENTRL_CACHE_DIR": str(cache)}
    if poison is not None:
        subprocess.run(cli("urdf-info", "--json", tmp / "robot.urdf"), env=env, capture_output=True, timeout=TIMEOUT, check=True)
        [entry] = list((cache / "hulls").iterdir())
        poison(entry)
    return Probe(cli("urdf-info", "--json", tmp / "robot.urdf"), expect="ok", env={"LATENTRL_CACHE_DIR": str(cache)},
                 check=hull_ok, names=["hull"], shown="latentrl urdf-info --json robot.urdf (cube mesh, cache poisoned)")


TETRA = ([(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)], [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)])


def _replace(entry: Path, data: bytes) -> None:
    entry.unlink()
    entry.write_bytes(data)
    entry.chmod(0o600)


CACHE_POISONS: list[tuple[str, Callable[[Path], None]]] = [
    ("cache: a forged hull of 4 of the cube's corners", lambda e: _replace(e, entry_bytes(*TETRA, 12))),
    ("cache: entry truncated", lambda e: _replace(e, e.read_bytes()[:30])),
    ("cache: entry empty", lambda e: _replace(e, b"")),
    ("cache: entry of another magic", lambda e: _replace(e, b"XXHULL01" + e.read_bytes()[8:])),
    ("cache: entry declaring 2**31 points", lambda e: _replace(e, b"LRHULL01" + struct.pack("<III", 2**31, 12, 12) + e.read_bytes()[20:])),
    ("cache: entry with NaN points", lambda e: _replace(e, e.read_bytes()[:20] + struct.pack("<f", float("nan")) * 24 + e.read_bytes()[20 + 96:])),
    ("cache: entry with indices out of range", lambda e: _replace(e, e.read_bytes()[:-4] + struct.pack("<I", 10**6))),
    ("cache: entry of the cube scaled 2×", lambda e: _replace(e, b"LRHULL01" + e.read_bytes()[8:20] + b"".join(
        struct.pack("<f", 2 * v) for v in struct.unpack(f"<{24}f", e.read_bytes()[20:116])) + e.read_bytes()[116:])),
    ("cache: entry a FIFO", lambda e: (e.unlink(), os.mkfifo(e))),
    ("cache: entry a symlink to /dev/zero", lambda e: (e.unlink(), e.symlink_to("/dev/zero"))),
    ("cache: entry a folder", lambda e: (e.unlink(), e.mkdir())),
    ("cache: entry group-writable", lambda e: (_replace(e, entry_bytes(*TETRA, 12)), e.chmod(0o664))),
    ("cache: entry of 17 MiB (sparse)", lambda e: (e.unlink(), open(e, "wb").truncate(17 << 20), e.chmod(0o600))),
    ("cache: folder made world-writable with a forged entry", lambda e: (_replace(e, entry_bytes(*TETRA, 12)), e.parent.chmod(0o777))),
]


def _cache_case(name: str, poison: Callable[[Path], None]) -> None:
    @case(4, name)
    def build(tmp: Path, base: Base) -> Probe:
        return cache_probe(tmp, tmp / "cache", poison)


for _c in CACHE_POISONS:
    _cache_case(*_c)


@case(4, "cache: LATENTRL_CACHE_DIR a regular file")
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "cachefile").write_text("x")
    return cache_probe(tmp, tmp / "cachefile", None)


@case(4, "cache: LATENTRL_CACHE_DIR a dangling symlink")
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "cachelink").symlink_to(tmp / "gone")
    return cache_probe(tmp, tmp / "cachelink", None)


@case(4, "cache: folder on a read-only mount", root_only=True)
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "ro").mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "ro,size=64k", "tmpfs", tmp / "ro"], check=True)
    return cache_probe(tmp, tmp / "ro", None)


@case(4, "cache: folder on a full disk", root_only=True)
def _(tmp: Path, base: Base) -> Probe:
    (tmp / "full").mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", "size=4k", "tmpfs", tmp / "full"], check=True)
    (tmp / "full" / "hulls").mkdir(mode=0o700)
    with open(tmp / "full" / "filler", "wb") as fh:
        try:
            fh.write(b"x" * 65536)
        except OSError:
            pass
    return cache_probe(tmp, tmp / "full", None)


# --------------------------------------------------------------------------------------------
# (5) process faults


def run_with_signal(argv: list[str], env: dict[str, str], when: Callable[[float], bool], sig: int,
                    ) -> tuple[subprocess.CompletedProcess[str], float]:
    """Runs `argv`, sends `sig` once `when(elapsed)` holds (polled every 0.05 s), waits for the end."""
    start = time.monotonic()
    proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    sent = False
    while proc.poll() is None and time.monotonic() - start < TIMEOUT:
        if not sent and when(time.monotonic() - start):
            proc.send_signal(sig)
            sent = True
        time.sleep(0.05)
    if proc.poll() is None:
        proc.kill()
        out, err = proc.communicate()
        raise subprocess.TimeoutExpired(argv, TIMEOUT, out, err)
    out, err = proc.communicate()
    return subprocess.CompletedProcess(argv, proc.returncode, out, err), time.monotonic() - start


def trials_saved(results: Path) -> int:
    try:
        return sum(len(v) for v in json.loads(results.read_text())["trials"].values())
    except (OSError, ValueError, KeyError, AttributeError):
        return 0


def interrupted_train(tmp: Path, sig: int, when: Callable[[Path, float], bool], trials: int = 3) -> Probe:
    """`train` of `trials` trials interrupted by `sig`; then `--resume`, which must finish the run
    with every trial (kept ones unchanged)."""
    out = tmp / "out"
    argv = cli("train", EXAMPLE / "glass_arm.toml", "--demos", EXAMPLE / "demos.csv", "--quick", "--trials", trials,
               "--episodes", "40", "--test-episodes", "2", "--no-progress", "--out", out)
    env = {**os.environ, "RAYON_NUM_THREADS": "1"}

    def custom() -> tuple[subprocess.CompletedProcess[str], float]:
        result, took = run_with_signal(argv, env, lambda t: when(out, t), sig)
        kept = trials_saved(out / "results.json")
        # the resume is a whole run (3 trials): its own, longer timeout; a hang is the signalled command's
        resumed = subprocess.run([*argv, "--resume"] if kept else argv, env=env, capture_output=True, text=True,
                                 timeout=5 * TIMEOUT)
        done = trials_saved(out / "results.json")
        result.stderr += f"\n[probe: {kept} trial(s) kept; resume exit {resumed.returncode}, {done} of {trials} done]"
        if resumed.returncode != 0 or done != trials:
            result.stderr += "\n[probe: LOST] " + resumed.stderr[-300:]
        return result, took

    def check(result: subprocess.CompletedProcess[str]) -> str | None:
        return "lost" if "[probe: LOST]" in result.stderr else None

    return Probe(custom=custom, expect="either", check=check, names=["--resume"],
                 shown=f"latentrl train … --trials {trials} --out OUT, signal {signal.Signals(sig).name}; then --resume")


@case(5, "SIGINT at 0.3 s (while importing)")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGINT, lambda out, t: t > 0.3)


@case(5, "SIGINT at 2 s (while fitting the GPLVM)")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGINT, lambda out, t: t > 2.0)


@case(5, "SIGINT once gplvm.npz is written")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGINT, lambda out, t: (out / "gplvm.npz").exists())


@case(5, "SIGINT after the first trial is saved")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGINT, lambda out, t: trials_saved(out / "results.json") >= 1)


@case(5, "SIGINT twice, 0.1 s apart, in the trials")
def _(tmp: Path, base: Base) -> Probe:
    state: dict[str, float] = {}

    def when(out: Path, t: float) -> bool:
        if (out / "gplvm.npz").exists() and "t" not in state:
            state["t"] = t
        return "t" in state
    probe = interrupted_train(tmp, signal.SIGINT, when)
    inner = probe.custom
    assert inner is not None
    out = tmp / "out"

    def custom() -> tuple[subprocess.CompletedProcess[str], float]:
        # a second SIGINT while the first is handled: run by hand
        argv = cli("train", EXAMPLE / "glass_arm.toml", "--demos", EXAMPLE / "demos.csv", "--quick", "--trials", 3,
                   "--episodes", "40", "--test-episodes", "2", "--no-progress", "--out", out)
        env = {**os.environ, "RAYON_NUM_THREADS": "1"}
        start = time.monotonic()
        proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        sent = 0
        while proc.poll() is None and time.monotonic() - start < TIMEOUT:
            if sent < 2 and (out / "gplvm.npz").exists():
                proc.send_signal(signal.SIGINT)
                sent += 1
            time.sleep(0.1)
        if proc.poll() is None:
            proc.kill()
            o, e = proc.communicate()
            raise subprocess.TimeoutExpired(argv, TIMEOUT, o, e)
        o, e = proc.communicate()
        kept = trials_saved(out / "results.json")
        resumed = subprocess.run([*argv, "--resume"] if (out / "results.json").exists() else argv, env=env,
                                 capture_output=True, text=True, timeout=5 * TIMEOUT)
        done = trials_saved(out / "results.json")
        e += f"\n[probe: {kept} trial(s) kept; resume exit {resumed.returncode}, {done} of 3 done]"
        if resumed.returncode != 0 or done != 3:
            e += "\n[probe: LOST] " + resumed.stderr[-300:]
        return subprocess.CompletedProcess(argv, proc.returncode, o, e), time.monotonic() - start
    probe.custom = custom
    probe.shown = "latentrl train … --trials 3 --out OUT, SIGINT twice; then --resume"
    return probe


@case(5, "SIGKILL after the first trial is saved, then --resume")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGKILL, lambda out, t: trials_saved(out / "results.json") >= 1)


@case(5, "SIGKILL while gplvm.npz is being written, then --resume")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGKILL, lambda out, t: out.is_dir() and any(p.suffix == ".tmp" or "gplvm" in p.name
                                                                                      for p in out.iterdir()))


@case(5, "SIGTERM in the trials, then --resume")
def _(tmp: Path, base: Base) -> Probe:
    return interrupted_train(tmp, signal.SIGTERM, lambda out, t: (out / "gplvm.npz").exists())


def simple_signal(argv: list[str], sig: int, delay: float, shown: str, names: list[str]) -> Probe:
    def custom() -> tuple[subprocess.CompletedProcess[str], float]:
        return run_with_signal(argv, dict(os.environ), lambda t: t > delay, sig)
    return Probe(custom=custom, expect="either", names=names, shown=shown)


@case(5, "SIGINT during a rollout of 400 episodes")
def _(tmp: Path, base: Base) -> Probe:
    argv = cli("rollout", base.run, "--episodes", "400", "--out", tmp / "ro", "--no-progress")
    probe = simple_signal(argv, signal.SIGINT, 3.0, "latentrl rollout RUN --episodes 400, SIGINT at 3 s", ["rollout"])
    probe.check = lambda r: "half-written" if r.returncode != 0 and (tmp / "ro" / "rollout.json").exists() and not (
        tmp / "ro" / "rollout.npz").exists() else None
    return probe


@case(5, "SIGINT during replay rendering")
def _(tmp: Path, base: Base) -> Probe:
    argv = cli("replay", base.run, "--test", "0", "--out", tmp / "v.gif")
    probe = simple_signal(argv, signal.SIGINT, 4.0, "latentrl replay RUN --test 0 --out v.gif, SIGINT at 4 s", ["replay"])
    probe.check = lambda r: "half-written" if r.returncode != 0 and (tmp / "v.gif").exists() else None
    return probe


@case(5, "SIGINT during fit")
def _(tmp: Path, base: Base) -> Probe:
    argv = cli("fit", EXAMPLE / "demos.csv", "--max-iter", "5000", "--out", tmp / "m.npz")
    probe = simple_signal(argv, signal.SIGINT, 2.5, "latentrl fit demos.csv --max-iter 5000, SIGINT at 2.5 s", ["fit", "m.npz"])
    probe.check = lambda r: "half-written" if r.returncode != 0 and (tmp / "m.npz").exists() else None
    return probe


def mounted(tmp: Path, options: str) -> Path:
    where = tmp / "mnt"
    where.mkdir()
    subprocess.run(["mount", "-t", "tmpfs", "-o", options, "tmpfs", where], check=True)
    return where


def no_partial(path: Path) -> Callable[[subprocess.CompletedProcess[str]], str | None]:
    def check(result: subprocess.CompletedProcess[str]) -> str | None:
        if result.returncode == 0:
            return None
        if path.is_dir() and (path / "results.json").is_file() and "results are saved" in result.stderr:
            return None  # the trials were saved whole before the disk filled; the message says so
        if path.is_file() or (path.is_dir() and any(p.name != "lost+found" for p in path.rglob("*") if p.is_file())):
            return "half-written"
        return None
    return check


OUT_COMMANDS: dict[str, Callable[[Base, Path], list[str]]] = {
    "train": lambda base, out: cli("train", EXAMPLE / "glass_arm.toml", "--demos", EXAMPLE / "demos.csv", *TINY, "--out", out),
    "fit": lambda base, out: cli("fit", EXAMPLE / "demos.csv", "--max-iter", "20", "--out", out),
    "rollout": lambda base, out: cli("rollout", base.run, "--episodes", "2", "--out", out, "--no-progress"),
    "replay": lambda base, out: cli("replay", base.run, "--test", "0", "--out", out, "--max-frames", "3"),
}


def _fault_out(kind: str, command: str) -> None:
    @case(5, f"{kind} as --out of {command}", root_only=kind in ("a full disk (64 KiB tmpfs)", "a read-only mount"))
    def build(tmp: Path, base: Base) -> Probe:
        suffix = {"fit": "m.npz", "replay": "v.gif"}.get(command, "run")
        if kind == "a full disk (64 KiB tmpfs)":
            out = mounted(tmp, "size=64k") / suffix
        elif kind == "a read-only mount":
            out = mounted(tmp, "ro,size=64k") / suffix
        elif kind == "a dangling symlink":
            out = tmp / suffix
            out.symlink_to(tmp / "gone" / "target")
        elif kind == "an existing regular file":
            out = tmp / suffix
            out.write_text("keep me")
        else:  # a path under a regular file
            (tmp / "file").write_text("x")
            out = tmp / "file" / suffix
        probe = Probe(OUT_COMMANDS[command](base, out), expect="either", names=[str(out), suffix, "--out"],
                      shown=f"latentrl {command} … --out {kind}")
        if kind in ("a full disk (64 KiB tmpfs)", "a read-only mount"):
            probe.check = no_partial(out)
        elif kind == "an existing regular file":
            probe.check = lambda r: "lost" if command in ("train", "rollout") and out.read_text() != "keep me" else None
        return probe


for _kind in ["a full disk (64 KiB tmpfs)", "a read-only mount", "a dangling symlink", "an existing regular file",
              "a path under a regular file"]:
    for _command in ["train", "fit", "rollout", "replay"]:
        _fault_out(_kind, _command)


@case(5, "stdout a full device (/dev/full) for report")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("report", base.run), names=["stdout", "No space", "/dev/full"], expect="either", stdout_to="/dev/full",
                 shown="latentrl report RUN > /dev/full")


@case(5, "stdout a full device (/dev/full) for info")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("info"), names=["stdout", "No space", "/dev/full"], expect="either", stdout_to="/dev/full",
                 shown="latentrl info > /dev/full")


@case(5, "stdout closed (a broken pipe) for urdf-info")
def _(tmp: Path, base: Base) -> Probe:
    return Probe(cli("urdf-info", EXAMPLE / "glass_arm.urdf"), names=["stdout", "pipe"], expect="either", stdout_to="|head-0",
                 shown="latentrl urdf-info glass_arm.urdf | (exit at once)")


# --------------------------------------------------------------------------------------------
# (6) the Python API: each call in a child; a ValueError/TypeError/OSError naming the problem


def api(code: str, names: list[str], expect: str = "refuse") -> Callable[[Path, Base], Probe]:
    def build(tmp: Path, base: Base) -> Probe:
        prelude = (f"import numpy as np\nfrom pathlib import Path\nimport latentrl\nfrom latentrl import *\n"
                   f"from latentrl.task import Task\nTMP = Path({str(tmp)!r})\nEX = Path({str(EXAMPLE)!r})\n"
                   f"RUN = Path({str(base.run)!r})\nMODEL = Path({str(base.model)!r})\n")
        return Probe(api=prelude + code, names=names, expect=expect, shown=code.strip().splitlines()[-1][:90])
    return build


API_CASES: list[tuple[str, str, list[str]]] = [
    ("GPLVM.fit on strings", "GPLVM(n_components=2).fit(np.array([['a', 'b']] * 10))", ["str", "dtype", "string", "numeric"]),
    ("GPLVM.fit on one posture", "GPLVM(n_components=2).fit(np.zeros((1, 3)))", ["n_components", "n_samples", "X:"]),
    ("GPLVM.fit on NaN", "GPLVM(n_components=2).fit(np.full((10, 3), np.nan))", ["NaN", "finite"]),
    ("GPLVM(n_components=0)", "GPLVM(n_components=0).fit(np.random.rand(10, 3))", ["n_components"]),
    ("GPLVM(n_components=1.5)", "GPLVM(n_components=1.5).fit(np.random.rand(10, 3))", ["n_components"]),
    ("GPLVM(max_iter=-1)", "GPLVM(n_components=2, max_iter=-1).fit(np.random.rand(10, 3))", ["max_iter"]),
    ("GPLVM.transform before fit", "GPLVM(n_components=2).transform(np.zeros((2, 3)))", ["fit", "fitted"]),
    ("GPLVM.transform of another width", "m = GPLVM.load(MODEL)\nm.transform(np.zeros((2, 7)))", ["features"]),
    ("GPLVM.inverse_transform of NaN", "m = GPLVM.load(MODEL)\nm.inverse_transform(np.full((2, m.n_components), np.nan))",
     ["NaN", "finite"]),
    ("GPLVM.load on a policy file", "GPLVM.load(RUN / 'policy.npz')", ["policy.npz"]),
    ("GPLVM.load on a CSV", "GPLVM.load(EX / 'demos.csv')", ["demos.csv"]),
    ("PCA.load on a GPLVM file", "PCA.load(MODEL)", ["model.npz"]),
    ("PCA(n_components=-1).fit", "PCA(n_components=-1).fit(np.random.rand(10, 3))", ["n_components"]),
    ("PCA.fit on a 3-axis array", "PCA(n_components=1).fit(np.zeros((2, 3, 4)))", ["2-D", "2D", "shape", "ndim", "axes"]),
    ("Task.load of a missing file", "Task.load(TMP / 'none.toml')", ["none.toml"]),
    ("Task.load of a folder", "Task.load(TMP)", ["hp_"]),
    ("Task.from_dict of a list", "Task.from_dict([1, 2], TMP, 'd')", ["d:", "table", "mapping"]),
    ("Task.from_dict without urdf", "Task.from_dict({'name': 'x'}, TMP, 'd')", ["urdf"]),
    ("Task.from_dict nested 10 000 deep", "d = {}\nx = d\nfor _ in range(10000):\n    x['a'] = {}\n    x = x['a']\n"
     "Task.from_dict(d, TMP, 'd')", ["d", "deep", "nest"]),
    ("Task.shipped of an unknown name", "Task.shipped('no_such')", ["no_such"]),
    ("Task.plant of demos of 2 joints", "t = Task.load(EX / 'glass_arm.toml')\nt.plant(np.zeros((5, 2)))", ["demonstration", "glass_arm.toml"]),
    ("load_demos of an unknown extension", "(TMP / 'd.xlsx').write_text('a')\nload_demos(TMP / 'd.xlsx')", ["d.xlsx"]),
    ("load_demos of JSON of the wrong shape", "(TMP / 'd.json').write_text('{\"postures\": 3}')\nload_demos(TMP / 'd.json')",
     ["d.json"]),
    ("load_demos with expected_joints unknown", "load_demos(EX / 'demos.csv', expected_joints=['hip', 'knee', 'ankle'])",
     ["demos.csv", "hip"]),
    ("load_demos with min_postures 1000", "load_demos(EX / 'demos.csv', min_postures=1000)", ["demos.csv", "1000"]),
    ("load_demos of an NPZ without arrays", "np.savez(TMP / 'd.npz')\nload_demos(TMP / 'd.npz')", ["d.npz"]),
    ("LatentPolicy.load of a GPLVM file", "from latentrl.train import LatentPolicy\nLatentPolicy.load(MODEL)", ["model.npz"]),
    ("LatentPolicy.act of a posture of 2", "from latentrl.train import LatentPolicy\np = LatentPolicy.load(RUN / 'policy.npz')\n"
     "p.act([0.1, 0.2])", ["posture"]),
    ("LatentPolicy.act of NaN", "from latentrl.train import LatentPolicy\np = LatentPolicy.load(RUN / 'policy.npz')\n"
     "print(p.act([np.nan, 0.2, 0.1]))", ["posture", "NaN", "finite"]),
    ("LatentPolicy.act with trial=1.5", "from latentrl.train import LatentPolicy\np = LatentPolicy.load(RUN / 'policy.npz')\n"
     "p.act([0.1, 0.2, 0.3], trial=1.5)", ["trial"]),
    ("LatentPolicy.value of the wrong width", "from latentrl.train import LatentPolicy\np = LatentPolicy.load(RUN / 'policy.npz')\n"
     "p.value(np.zeros((3, 9)))", ["z"]),
    ("LatentPolicy.rollout(episodes=-1)", "from latentrl.train import LatentPolicy\np = LatentPolicy.load(RUN / 'policy.npz')\n"
     "p.rollout(episodes=-1)", ["episodes"]),
    ("LatentPolicy.rollout(starts='x')", "from latentrl.train import LatentPolicy\np = LatentPolicy.load(RUN / 'policy.npz')\n"
     "p.rollout(2, starts='x')", ["starts"]),
    ("TaskEnv with max_step 0", "from latentrl.envs import TaskEnv\nTaskEnv(Task.load(EX / 'glass_arm.toml'), max_step=0)",
     ["max_step"]),
    ("TaskEnv.step with an action of 2", "from latentrl.envs import TaskEnv\ne = TaskEnv(Task.load(EX / 'glass_arm.toml'))\n"
     "e.reset(seed=0)\ne.step(np.zeros(2))", ["action"]),
    ("TaskEnv.step with a NaN action", "from latentrl.envs import TaskEnv\ne = TaskEnv(Task.load(EX / 'glass_arm.toml'))\n"
     "e.reset(seed=0)\nprint(e.step(np.full(3, np.nan)))", ["action"]),
    ("TaskEnv.reset with a posture of 5", "from latentrl.envs import TaskEnv\ne = TaskEnv(Task.load(EX / 'glass_arm.toml'))\n"
     "e.reset(options={'posture': np.zeros(5)})", ["posture"]),
    ("TaskEnv render_mode unknown", "from latentrl.envs import TaskEnv\nTaskEnv(Task.load(EX / 'glass_arm.toml'), render_mode='vr')",
     ["render_mode", "vr"]),
]


def _api_case(name: str, code: str, names: list[str]) -> None:
    case(6, name)(api(code, names))


for _a in API_CASES:
    _api_case(*_a)


# --------------------------------------------------------------------------------------------
# running and classifying

API_WRAPPER = """
import sys
SNIPPET = {code!r}
try:
    exec(compile(SNIPPET, "<probe>", "exec"))
except (ValueError, TypeError, OSError) as err:
    print(f"latentrl-probe: {{type(err).__name__}}: {{err}}", file=sys.stderr)
    sys.exit(1)
"""


@dataclass
class Outcome:
    case: Case
    shown: str
    outcome: str
    code: int | None
    seconds: float
    message: str


def message_of(stderr: str) -> str:
    lines = [line for line in stderr.strip().splitlines() if line.strip() and not line.startswith("[probe")]
    errors = [line for line in lines if "error" in line.lower() or line.startswith("latentrl-probe:")]
    return (errors[-1] if errors else lines[-1] if lines else "").strip()


def run_case(c: Case, base: Base) -> Outcome:
    with tempfile.TemporaryDirectory(prefix="hp_") as name:
        tmp = Path(name)
        try:
            return _run(c, base, tmp)
        finally:
            for mount in (tmp / "mnt", tmp / "ro", tmp / "full"):
                if os.path.ismount(mount):
                    subprocess.run(["umount", mount], check=False)
            for p in tmp.rglob("*"):  # let the folder be removed (modes set by a case)
                if p.is_dir() and not p.is_symlink():
                    p.chmod(0o700)


def _run(c: Case, base: Base, tmp: Path) -> Outcome:
    try:
        probe = c.build(tmp, base)
    except Exception as err:  # noqa: BLE001 - the probe's own setup failed: shown, not hidden
        return Outcome(c, "(setup)", "probe error", None, 0.0, f"{type(err).__name__}: {err}")
    shown = probe.shown or ("python -c '…'" if probe.api else " ".join(
        "latentrl" if a == "latentrl" else (Path(a).name if a.startswith("/") else a) for a in probe.argv[3:][:12]))
    if probe.argv and not probe.shown:
        shown = "latentrl " + shown
    env = {**os.environ, **probe.env}
    start = time.monotonic()
    try:
        if probe.custom is not None:
            result, took = probe.custom()
        else:
            argv = probe.argv if probe.argv is not None else [PY, "-c", API_WRAPPER.format(code=probe.api)]
            if probe.stdout_to == "|head-0":
                proc = subprocess.Popen(argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
                assert proc.stdout is not None
                proc.stdout.close()
                _, err = proc.communicate(timeout=TIMEOUT)
                result = subprocess.CompletedProcess(argv, proc.returncode, "", err)
            elif probe.stdout_to is not None:
                with open(probe.stdout_to, "w") as sink:
                    done = subprocess.run(argv, env=env, stdout=sink, stderr=subprocess.PIPE, text=True, timeout=TIMEOUT)
                result = subprocess.CompletedProcess(argv, done.returncode, "", done.stderr)
            else:
                result = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=TIMEOUT)
            took = time.monotonic() - start
    except subprocess.TimeoutExpired:
        return Outcome(c, shown, "hang", None, TIMEOUT, f"no answer in {TIMEOUT:.0f} s")
    message = message_of(result.stderr)
    code = result.returncode
    signalled = probe.custom is not None and code in (-signal.SIGKILL, -signal.SIGTERM, -signal.SIGINT)
    if "Traceback (most recent call last)" in result.stderr:
        outcome = "traceback"
        message = [line for line in result.stderr.strip().splitlines() if not line.startswith("[probe")][-1]
    elif (code < 0 and not signalled) or code not in (0, 1, 2, 3, 130, -signal.SIGKILL, -signal.SIGTERM, -signal.SIGINT):
        outcome = "abort"
    elif code == 0 and probe.expect == "refuse":
        outcome = "silent"
    elif code in (0, 3) or signalled:
        outcome = "ran"
    else:
        named = any(n and n in message for n in probe.names)
        outcome = "refused, named" if named else "refused, unnamed"
    if probe.check is not None and outcome not in ("hang", "traceback", "abort"):
        outcome = probe.check(result) or outcome
    if probe.custom is not None and code == 130:
        outcome = "ran" if outcome in ("refused, named", "refused, unnamed") else outcome
    tail = [line for line in result.stderr.splitlines() if line.startswith("[probe:")]
    if probe.custom is not None:
        message = f"exit {code}; {message} {' '.join(dict.fromkeys(tail))}".strip()
    return Outcome(c, shown, outcome, code, took, message)


def build_base(where: Path) -> Base:
    base = Base(where)
    if not (base.run / "policy.npz").exists():
        subprocess.run(cli("train", EXAMPLE / "glass_arm.toml", "--demos", EXAMPLE / "demos.csv", *TINY, "--out", base.run),
                       check=True, capture_output=True, timeout=600)
    if not (base.rollout / "rollout.json").exists():
        subprocess.run(cli("rollout", base.run, "--episodes", "2", "--out", base.rollout, "--no-progress"), check=True,
                       capture_output=True, timeout=600)
    if not base.model.exists():
        subprocess.run(cli("fit", EXAMPLE / "demos.csv", "--max-iter", "30", "--out", base.model), check=True,
                       capture_output=True, timeout=600)
    return base


GOOD = ("refused, named", "ran")
SURFACES = {1: "task files and CLI flags", 2: "URDFs and meshes", 3: "saved runs and policies", 4: "the mesh hull cache",
            5: "process faults", 6: "the Python API"}


def markdown(outcomes: list[Outcome]) -> str:
    counts = Counter(o.outcome for o in outcomes)
    lines = [f"{len(outcomes)} inputs: " + ", ".join(f"{n} {k}" for k, n in sorted(counts.items(), key=lambda kv: -kv[1])) + ".", ""]
    for surface, title in SURFACES.items():
        rows = [o for o in outcomes if o.case.surface == surface]
        if not rows:
            continue
        lines += [f"**({surface}) {title}** ({len(rows)})", "", "| input | command | outcome | s | message (where not good) |",
                  "|---|---|---|---|---|"]
        for o in rows:
            shown_message = "" if o.outcome in GOOD and not o.outcome.startswith("ran") else o.message
            if o.outcome == "refused, named":
                shown_message = ""
            text = shown_message.replace("|", "\\|").replace(str(ROOT), "…")
            text = re.sub(r"/tmp/hp_[^/ ]+", "TMP", text)[:220]
            cell = o.shown.replace("|", "\\|")
            lines.append(f"| {o.case.name.replace('|', '/')} | `{cell}` | {o.outcome} | {o.seconds:.1f} | {text} |")
        lines.append("")
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", type=Path, help="a folder for the shared run (kept; reused if present)")
    parser.add_argument("--jobs", type=int, default=3)
    parser.add_argument("--only", default="", help="run the cases whose name contains this")
    parser.add_argument("--markdown", type=Path, help="write the table here")
    parser.add_argument("--json", type=Path, help="write the outcomes here")
    args = parser.parse_args()
    # A probe started in the background of a shell without job control inherits SIGINT ignored,
    # and so would every command it signals (Python keeps an ignored SIGINT ignored): restore it.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    where = args.base or Path(tempfile.mkdtemp(prefix="hp_base_"))
    where.mkdir(parents=True, exist_ok=True)
    base = build_base(where)
    cases = [c for c in CASES if args.only in c.name and (ROOT_USER or not c.root_only)]
    print(f"{len(cases)} cases ({len(CASES) - len(cases)} skipped)", flush=True)
    with ThreadPoolExecutor(args.jobs) as pool:
        outcomes = []
        for o in pool.map(lambda c: run_case(c, base), cases):
            print(f"[{o.case.surface}] {o.case.name:60.60s} {o.outcome:17s} {o.seconds:5.1f}s  {o.message[:150]}", flush=True)
            outcomes.append(o)
    table = markdown(outcomes)
    print(table.splitlines()[0])
    if args.markdown:
        args.markdown.write_text(table)
    if args.json:
        args.json.write_text(json.dumps([{"surface": o.case.surface, "input": o.case.name, "command": o.shown, "outcome": o.outcome,
                                          "exit": o.code, "seconds": round(o.seconds, 2), "message": o.message} for o in outcomes],
                                         indent=1))
    return 0 if all(o.outcome in GOOD or o.outcome == "refused, unnamed" for o in outcomes) else 1


if __name__ == "__main__":
    sys.exit(main())
