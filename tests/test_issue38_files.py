"""Issue #38, items 3–5 from Python: every file latentrl reads is a regular file under a documented
cap (a FIFO answers at once, a device or an oversized file is refused naming the cap), mesh counts
are checked against the bytes present, a URDF joint graph that is not one tree is refused naming
its joints, and the hull cache is verified, not trusted. The Rust side: crates/sim/tests/issue38.rs."""

from __future__ import annotations

import json
import os
import struct
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from latentrl import GPLVM, _native
from latentrl._persistence import read_npz
from latentrl._files import MAX_TASK_FILE_BYTES, MAX_URDF_BYTES, open_regular, read_bounded, read_text
from latentrl._native import InvalidInputError, Sim
from latentrl.results import read_json
from latentrl.experiments.sweep import load_sweep
from latentrl.task import Task

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"

INERTIAL = ('<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" '
            'izz="0.01"/></inertial>')


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    """`latentrl ARGS` in a child process; a hang fails the test (timeout)."""
    return subprocess.run([sys.executable, "-m", "latentrl", *args], capture_output=True, text=True, timeout=120)


@pytest.fixture
def fifo(tmp_path: Path) -> Path:
    path = tmp_path / "pipe"
    os.mkfifo(path)
    return path


def mesh_robot(mesh: str) -> str:
    return (f'<robot name="m"><link name="base">{INERTIAL}<collision><geometry><mesh filename="{mesh}"/>'
            '</geometry></collision></link></robot>')


def cube_stl() -> bytes:
    """A binary STL of the unit cube: 12 triangles on its 8 corners."""
    corner = [((i & 1), (i >> 1) & 1, (i >> 2) & 1) for i in range(8)]
    faces = [(0, 2, 1), (1, 2, 3), (4, 5, 6), (5, 7, 6), (0, 1, 4), (1, 5, 4), (2, 6, 3), (3, 6, 7),
             (0, 4, 2), (2, 4, 6), (1, 3, 5), (3, 7, 5)]
    out = bytearray(80) + struct.pack("<I", len(faces))
    for f in faces:
        out += struct.pack("<12fH", 0, 0, 0, *(c for i in f for c in corner[i]), 0)
    return bytes(out)


@pytest.mark.timeout(60)
def test_a_fifo_as_task_urdf_mesh_model_or_run_file_is_refused_at_once(fifo: Path, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="pipe: is not a regular file \\(a FIFO\\)"):
        Task.load(fifo)
    with pytest.raises(InvalidInputError, match="pipe: is not a regular file \\(a FIFO\\)"):
        Sim(str(fifo))
    (tmp_path / "robot.urdf").write_text(mesh_robot("pipe"))
    with pytest.raises(InvalidInputError, match='link "base".*pipe: is not a regular file \\(a FIFO\\)'):
        _native.urdf_info(str(tmp_path / "robot.urdf"))
    with pytest.raises(ValueError, match="pipe: is not a regular file \\(a FIFO\\)"):
        GPLVM.load(fifo)
    with pytest.raises(ValueError, match="pipe: is not a regular file \\(a FIFO\\)"):
        read_json(fifo)
    with pytest.raises(ValueError, match="pipe: is not a regular file \\(a FIFO\\)"):
        load_sweep(fifo)
    with pytest.raises(ValueError, match="^is not a regular file \\(a FIFO\\)$"):
        read_npz(fifo)


@pytest.mark.timeout(200)
def test_the_cli_given_a_fifo_exits_1_naming_it(fifo: Path, tmp_path: Path) -> None:
    result = cli("urdf-info", str(fifo))
    assert result.returncode == 1 and "pipe: is not a regular file (a FIFO)" in result.stderr, result.stderr
    result = cli("train", str(fifo), "--demos", str(EXAMPLE / "demos.csv"), "--out", str(tmp_path / "run"),
                 "--quick", "--no-progress")
    assert result.returncode == 1 and "pipe: is not a regular file (a FIFO)" in result.stderr, result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.parametrize("flag", ["task", "--demos", "--model"])
def test_train_given_a_symlink_loop_exits_1_naming_the_flag(tmp_path: Path, flag: str) -> None:
    """A loop of symbolic links as the task file, --demos or --model was a RuntimeError traceback
    (`Path.resolve`)."""
    (tmp_path / "a.csv").symlink_to(tmp_path / "b.csv")
    (tmp_path / "b.csv").symlink_to(tmp_path / "a.csv")
    loop = str(tmp_path / "a.csv")
    given = {"task": str(EXAMPLE / "glass_arm.toml"), "--demos": str(EXAMPLE / "demos.csv"), "--model": None}
    given[flag] = loop
    args = [given["task"], "--demos", given["--demos"], *(["--model", loop] if flag == "--model" else [])]
    result = cli("train", *args, "--out", str(tmp_path / "run"), "--quick", "--no-progress")
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert f"{'task file' if flag == 'task' else flag} {loop}: is a loop of symbolic links" in result.stderr
    assert not (tmp_path / "run").exists()


def test_devices_and_directories_are_refused_by_kind(tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="is not a regular file \\(a character device\\)"):
        Task.load("/dev/zero")
    with pytest.raises(ValueError, match="is not a regular file \\(a character device\\)"):
        GPLVM.load("/dev/zero")
    with pytest.raises(ValueError, match="is not a regular file \\(a directory\\)"):
        read_json(tmp_path)
    with pytest.raises(FileNotFoundError):
        read_bounded(tmp_path / "missing", 10, "a test file")


def test_a_file_over_its_cap_is_refused_naming_the_cap(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (MAX_TASK_FILE_BYTES + 1))
    refusal = "is 1048577 bytes, more than the 1048576 bytes (1 MiB) a task file may have"
    with pytest.raises(ValueError, match=refusal.replace("(", "\\(").replace(")", "\\)")):
        Task.load(big)  # the native reader
    with pytest.raises(ValueError) as python_side:
        read_text(big, MAX_TASK_FILE_BYTES, "a task file")
    assert str(python_side.value) == refusal  # the same cap on both sides
    urdf = tmp_path / "big.urdf"
    urdf.write_bytes(b" " * (MAX_URDF_BYTES + 1))
    with pytest.raises(InvalidInputError, match="more than the 16777216 bytes \\(16 MiB\\) a URDF may have"):
        Sim(str(urdf))
    with pytest.raises(ValueError, match="more than the 16777216 bytes \\(16 MiB\\) a URDF may have"):
        read_bounded(urdf, MAX_URDF_BYTES, "a URDF")

    model = tmp_path / "model.npz"
    GPLVM(n_components=1, max_iter=2, random_state=0).fit(np.random.default_rng(0).normal(size=(6, 2))).save(model)
    monkeypatch.setattr("latentrl._persistence.MAX_NPZ_BYTES", 1024)
    with pytest.raises(ValueError, match="model.npz: is \\d+ bytes, more than the 1024 bytes \\(1 KiB\\) an NPZ file"):
        GPLVM.load(model)
    results = tmp_path / "results.json"
    results.write_text(json.dumps({"x": 1}))
    monkeypatch.setattr("latentrl.results.MAX_JSON_BYTES", 4)
    with pytest.raises(ValueError, match="results.json: is 8 bytes, more than the 4 bytes"):
        read_json(results)


def test_open_regular_reads_a_regular_file(tmp_path: Path) -> None:
    path = tmp_path / "a.txt"
    path.write_text("hello")
    with open_regular(path, 5, "a test file") as fh:
        assert fh.read() == b"hello"
    assert read_text(path, 5, "a test file") == "hello"
    path.write_bytes(b"\xff\xfe")
    with pytest.raises(ValueError, match="is not UTF-8 text"):
        read_text(path, 5, "a test file")


def test_a_task_file_or_urdf_that_is_not_utf8_is_refused_naming_the_line(tmp_path: Path) -> None:
    """A Latin-1 byte (an accented comment) said "invalid utf-8 sequence of 1 bytes from index
    61", a byte offset, from the native reader (task file, URDF) and Python's alike."""
    text = (EXAMPLE / "glass_arm.toml").read_bytes().replace(b'name = "glass_arm"', b'name = "gl\xe4ss_arm"')
    (tmp_path / "task.toml").write_bytes(text)
    line = text[:text.index(b"\xe4")].count(b"\n") + 1
    says = f"is not UTF-8 text \\(line {line} has byte 0xe4\\); save it as UTF-8"
    with pytest.raises(ValueError, match=f"task.toml: {says}"):
        Task.load(tmp_path / "task.toml")
    with pytest.raises(ValueError, match=f"^{says}$"):
        read_text(tmp_path / "task.toml", 1 << 20, "a task file")


BOMB = """<?xml version="1.0"?><COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh><source id="p"><float_array id="a" count="COUNT">0 0 0 1 0 0 0 1 0 0 0 1</float_array>
<technique_common><accessor source="#a" count="4" stride="3"><param name="X" type="float"/><param name="Y" type="float"/>
<param name="Z" type="float"/></accessor></technique_common></source><vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="4"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p></triangles></mesh></geometry>
</library_geometries><library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node></visual_scene>
</library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>"""


@pytest.mark.timeout(120)
def test_mesh_counts_beyond_their_bytes_are_refused_not_allocated(tmp_path: Path) -> None:
    (tmp_path / "robot.urdf").write_text(mesh_robot("bomb.dae"))
    (tmp_path / "bomb.dae").write_text(BOMB.replace("COUNT", "2000000000"))  # 1 KB declaring 8 GB
    # In a child process: before the check, the reader's allocation aborted the interpreter.
    code = f"from latentrl import _native\n_native.urdf_info({str(tmp_path / 'robot.urdf')!r})"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert result.returncode == 1, result.stderr
    assert "<float_array> declares count=2000000000 values but holds 12" in result.stderr, result.stderr
    (tmp_path / "bomb.dae").write_text(BOMB.replace("COUNT", "12"))
    assert _native.urdf_info(str(tmp_path / "robot.urdf"))["collision"][0]["hull"]["vertices"] == 4

    stl = bytearray(cube_stl())
    stl[80:84] = struct.pack("<I", 3_000_000_000)
    (tmp_path / "cube.stl").write_bytes(stl)
    (tmp_path / "robot.urdf").write_text(mesh_robot("cube.stl"))
    with pytest.raises(InvalidInputError, match="declares 3000000000 triangles .* holds 12 .*cut short"):
        _native.urdf_info(str(tmp_path / "robot.urdf"))


def graph(joints: list[tuple[str, str, str]], links: list[str]) -> str:
    """A robot of `links` joined by revolute `joints`, each (name, parent, child)."""
    body = "".join(f'<link name="{name}">{INERTIAL}</link>' for name in links)
    body += "".join(f'<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><axis xyz="0 0 1"/>'
                    '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>' for n, p, c in joints)
    return f'<robot name="g">{body}</robot>'


@pytest.mark.parametrize("joints, links, says", [
    ([("shoulder", "a", "b"), ("elbow", "b", "b")], ["a", "b"],
     'joint "elbow" has link "b" as both its parent and its child'),
    ([("shoulder", "a", "b"), ("elbow", "b", "c"), ("again", "a", "c")], ["a", "b", "c"],
     'link "c" is the child of two joints, "elbow" (parent "b") and "again" (parent "a")'),
    ([("shoulder", "a", "b"), ("there", "c", "d"), ("back", "d", "c")], ["a", "b", "c", "d"],
     'joints "there" ("c" -> "d"), "back" ("d" -> "c") form a cycle: links "c", "d" lead to no root link'),
    ([("shoulder", "a", "b")], ["a", "b", "c"],
     '2 links are the child of no joint: "a" (a tree of 2 links), "c" (a tree of 1 links)'),
], ids=["self-loop", "two-parents", "cycle-unreachable", "two-roots"])
def test_joint_graphs_that_are_not_one_tree_are_refused_naming_the_joints(joints, links, says) -> None:
    with pytest.raises(InvalidInputError) as refused:
        Sim(graph(joints, links))
    assert says in str(refused.value)


def entry_bytes(points: list[tuple[float, float, float]], triangles: list[tuple[int, int, int]], source: int) -> bytes:
    """A hull cache entry in its on-disk format."""
    out = b"LRHULL01" + struct.pack("<III", len(points), len(triangles), source)
    out += b"".join(struct.pack("<3f", *p) for p in points)
    return out + b"".join(struct.pack("<3I", *t) for t in triangles)


def hull(urdf: Path) -> tuple[dict[str, object], list[str]]:
    info = _native.urdf_info(str(urdf))
    return info["collision"][0]["hull"], info["warnings"]


def test_a_tampered_cache_entry_is_not_used(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cache = tmp_path / "cache"
    monkeypatch.setenv("LATENTRL_CACHE_DIR", str(cache))
    (tmp_path / "cube.stl").write_bytes(cube_stl())
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(mesh_robot("cube.stl"))
    assert hull(urdf) == ({"triangles": 12, "vertices": 8, "cached": False}, [])
    assert hull(urdf) == ({"triangles": 12, "vertices": 8, "cached": True}, [])
    [entry] = list((cache / "hulls").iterdir())
    # Four of the cube's own corners: every vertex is the mesh's, the rest of the cube lies outside.
    entry.write_bytes(entry_bytes([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)],
                                  [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)], 12))
    found, warnings = hull(urdf)
    assert found == {"triangles": 12, "vertices": 8, "cached": False}
    assert len(warnings) == 1 and "is not the hull of" in warnings[0] and "beyond it in direction" in warnings[0]
    assert hull(urdf) == ({"triangles": 12, "vertices": 8, "cached": True}, [])  # rewritten


def test_a_cache_folder_others_may_write_warns_and_is_not_used(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    cache = tmp_path / "cache"
    (cache / "hulls").mkdir(parents=True)
    (cache / "hulls").chmod(0o777)
    monkeypatch.setenv("LATENTRL_CACHE_DIR", str(cache))
    (tmp_path / "cube.stl").write_bytes(cube_stl())
    urdf = tmp_path / "robot.urdf"
    urdf.write_text(mesh_robot("cube.stl"))
    for _ in range(2):
        found, warnings = hull(urdf)
        assert found["cached"] is False
        assert warnings == [f"hull cache folder {cache / 'hulls'} is writable by other users (mode 777): not used, "
                            "hulls are computed anew (make it private: `chmod go-w`, or set LATENTRL_CACHE_DIR to a "
                            "folder of your own)"]
    assert list((cache / "hulls").iterdir()) == []
    result = cli("urdf-info", str(urdf))
    assert result.returncode == 0 and "writable by other users (mode 777)" in result.stdout + result.stderr


@pytest.mark.parametrize("link", ["dangling", "loop"])
def test_an_out_folder_that_is_a_broken_symlink_is_refused_before_any_work(
        tmp_path: Path, link: str, capsys: pytest.CaptureFixture[str]) -> None:
    """`train --out` a dangling symlink or a loop of them fitted the GPLVM and derived the
    settings, then failed with "[Errno 17] File exists"."""
    from latentrl import cli

    out = tmp_path / "out"
    out.symlink_to(tmp_path / ("missing" if link == "dangling" else "out"))
    missing = str(tmp_path / "no-demos.csv")  # the --out check comes first: the demos are never read
    assert cli.main(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", missing, "--out", str(out)]) == 1
    assert f"--out {out}: is a symbolic link to nothing" in capsys.readouterr().err


def test_a_long_legal_output_name_is_written_and_one_too_long_is_refused_before_any_work(tmp_path: Path) -> None:
    """An output name of 218–255 characters (legal) was refused after the work, "File name too
    long": its temporary file's name added 38 characters. One longer than 255 bytes failed so
    after the fit; it is refused first, naming the flag."""
    from latentrl._persistence import atomic_path, atomic_write

    atomic_write(tmp_path / ("h" * 251 + ".npz"), lambda f: f.write(b"x"))
    with atomic_path(tmp_path / ("v" * 251 + ".gif")) as temp:
        temp.write_bytes(b"x")
    assert sorted(len(p.name) for p in tmp_path.iterdir()) == [255, 255]
    result = cli("fit", str(EXAMPLE / "demos.csv"), "--out", str(tmp_path / ("h" * 253 + ".npz")))
    assert result.returncode == 1 and f"--out {tmp_path}/hhh" in result.stderr
    assert "is 257 bytes long, more than the 255 a file or folder name may have" in result.stderr
