"""Hostile inputs under a memory limit (issue #21): each case runs in a child process whose
address space is capped at 2 GiB (`resource.RLIMIT_AS`), so an input that made the code
allocate what it names (a 20 000-point GP is 3 GiB, /dev/zero is endless) would end in a
MemoryError, an abort or a kill instead of the clear error asserted here. CLI cases must exit 1
with the message and no traceback; API cases must raise the named exception."""

from __future__ import annotations

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

LIMIT = 2 << 30

#: The child's prologue: the memory cap, then latentrl.
PROLOGUE = f"import resource; resource.setrlimit(resource.RLIMIT_AS, ({LIMIT}, {LIMIT}))\n"


def run_child(code: str, cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-c", PROLOGUE + textwrap.dedent(code)], capture_output=True,
                          text=True, cwd=cwd, timeout=120)


def cli(args: list[str]) -> str:
    return f"import sys; from latentrl.cli import main; sys.exit(main({args!r}))"


def api(call: str, error: str) -> str:
    """A child that exits 3 if `call` raises `error` (and prints its message), 0 if it returns."""
    return f"""
        import sys
        import numpy as np
        import latentrl
        from latentrl import _native
        try:
            {call}
        except {error} as err:
            print(err)
            sys.exit(3)
        """


def write_inputs(tmp: Path) -> None:
    """The hostile files, made cheaply (sparse files, small compressed bombs)."""
    with open(tmp / "huge.csv", "wb") as f:  # 300 MiB, sparse
        f.truncate(300 << 20)
    (tmp / "nested.json").write_text("[" * 200_000 + "]" * 200_000)
    (tmp / "grid.toml").write_text('experiment = "exp1"\n[grid]\nseed = [' + ", ".join(map(str, range(20_000))) + "]\n")
    (tmp / "devzero.urdf").write_text(
        '<robot name="r"><link name="base"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" '
        'ixz="0" iyz="0"/></inertial><collision><geometry><mesh filename="/dev/zero"/></geometry></collision></link></robot>')
    links = "".join(f'<link name="l{i}"><inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/></inertial></link>'
                    for i in range(100_000))
    (tmp / "links.urdf").write_text(f'<robot name="r">{links}</robot>')


CASES = {
    "a demo file over the size limit": (cli(["fit", "huge.csv", "--out", "m.npz"]), 1, "a demo file may have"),
    "a demo file nested 200 000 deep": (cli(["fit", "nested.json", "--out", "m.npz"]), 1, "nested.json"),
    "a sweep grid too large to expand": (cli(["sweep", "grid.toml", "--out", "sweep"]), 1, "cells"),
    "a run too long to hold": (cli(["run", "exp1", "--quick", "--episodes", "2000000000", "--out", "r"]), 1, "episodes"),
    "a URDF mesh that is /dev/zero": (api("_native.Sim('devzero.urdf')", "latentrl.InvalidInputError"), 3,
                                      "/dev/zero: is not a regular file"),
    "a URDF with 100 000 links": (api("_native.Sim('links.urdf')", "latentrl.InvalidInputError"), 3, "links"),
    "a GP map of 20 000 points (3 GiB)": (api("_native.GpMap(np.zeros((20000, 2)), np.zeros((20000, 1)), np.ones(3))",
                                              "latentrl.InvalidInputError"), 3, "16384"),
    "a task dict nested 100 000 deep": (api("""
            deep = {}
            for _ in range(100_000):
                deep = {"a": deep}
            latentrl.Task.from_dict({"name": "t", "urdf": "x.urdf", "plant": deep})""",
                                            "(latentrl.InvalidInputError, ValueError)"), 3, "deep"),
}


@pytest.fixture(scope="module")
def inputs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    tmp = tmp_path_factory.mktemp("hostile")
    write_inputs(tmp)
    return tmp


@pytest.mark.parametrize("case", CASES)
def test_hostile_input_under_a_2_gib_cap_is_refused_cleanly(inputs, case):
    code, exit_code, says = CASES[case]
    out = run_child(code, inputs)
    text = out.stdout + out.stderr
    assert out.returncode == exit_code, f"{case}: exit {out.returncode}\n{text[-2000:]}"
    assert "Traceback" not in text and "MemoryError" not in text, text[-2000:]
    assert says in text, f"{case}: {text[-2000:]}"
