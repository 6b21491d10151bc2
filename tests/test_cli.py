"""The `latentrl` command: help, info, runs, exit codes."""

import json
import subprocess
import sys

import pytest

from latentrl.cli import build_parser, main


def latentrl(*args, timeout=300):
    return subprocess.run(
        [sys.executable, "-m", "latentrl", *args], capture_output=True, text=True, timeout=timeout
    )


def test_info_prints_versions_as_json():
    result = latentrl("info")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert info["versions"]["latentrl"] and info["cpu_count"] >= 1


def test_help_documents_every_preset_flag():
    text = build_parser()._subparsers._group_actions[0].choices["run"].format_help()  # noqa: SLF001
    assert all(name in text for name in ("table1", "exp1", "exp2"))
    exp1 = latentrl("run", "exp1", "--help")
    assert exp1.returncode == 0
    assert "--drop-tolerance" in exp1.stdout and "Soft-max inverse temperature" in exp1.stdout


def test_run_exp1_tiny(tmp_path):
    out = tmp_path / "run"
    result = latentrl(
        "run", "exp1", "--quick", "--no-progress", "--trials", "1", "--episodes", "5",
        "--steps", "20", "--out", str(out),
    )
    assert result.returncode == 0, result.stderr
    assert (out / "results.json").exists() and (out / "fig4a.png").exists()


def test_run_table1_tiny(tmp_path):
    result = latentrl("run", "table1", "--quick", "--no-progress", "--trials", "1", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "table1.md").exists()


def test_bad_values_exit_1_with_a_message(tmp_path):
    assert main(["run", "exp1", "--quick", "--no-progress", "--trials", "0", "--out", str(tmp_path)]) == 1


def test_unknown_flag_exits_2():
    with pytest.raises(SystemExit) as exit_info:
        main(["run", "exp1", "--no-such-flag"])
    assert exit_info.value.code == 2


@pytest.mark.parametrize(
    "script", ["table1.py", "exp1.py", pytest.param("exp2.py", marks=pytest.mark.slow)]
)
def test_examples_run_quick(script, tmp_path):
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / script
    result = subprocess.run(
        [sys.executable, str(path), "--quick", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=600,
    )
    assert result.returncode == 0, result.stderr
    assert any(tmp_path.iterdir())
