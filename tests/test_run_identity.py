"""A run is what it says it is (issue #38): `train --resume` refuses a run whose URDF was edited,
whose demos were reordered or whose saved GPLVM's latent points were permuted, naming what
changed (each was continued and merged before, with exit code 0)."""

import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"


def latentrl(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "latentrl", *args], capture_output=True, text=True, timeout=300,
                          cwd=cwd)


@pytest.fixture()
def run(tmp_path):
    for name in ("glass_arm.toml", "glass_arm.urdf", "demos.csv"):
        shutil.copy(EXAMPLE / name, tmp_path / name)
    args = ["train", str(tmp_path / "glass_arm.toml"), "--demos", str(tmp_path / "demos.csv"), "--out",
            str(tmp_path / "out"), "--quick", "--trials", "1", "--episodes", "3", "--test-episodes", "1",
            "--episode.max-steps", "10", "--no-progress"]
    assert latentrl(*args).returncode == 0
    return tmp_path, [*args, "--resume"]


def test_an_unchanged_run_resumes(run):
    _, resume = run
    result = latentrl(*resume)
    assert result.returncode == 0, result.stderr


def edit_urdf(folder):
    text = (folder / "glass_arm.urdf").read_text()
    assert '<origin xyz="0.30 0 0"/>' in text  # the upper arm, 0.30 → 0.60 m
    (folder / "glass_arm.urdf").write_text(text.replace('<origin xyz="0.30 0 0"/>', '<origin xyz="0.60 0 0"/>'))


def reorder_demos(folder):
    lines = (folder / "demos.csv").read_text().splitlines()
    (folder / "demos.csv").write_text("\n".join([lines[0], *reversed(lines[1:])]) + "\n")


def permute_model(folder):
    path = folder / "out" / "gplvm.npz"
    arrays = dict(np.load(path))
    arrays["Z_"] = arrays["Z_"][::-1].copy()
    np.savez(path, **arrays)


@pytest.mark.parametrize(("edit", "name"), [(edit_urdf, "urdf"), (reorder_demos, "demos"), (permute_model, "model")])
def test_an_edited_input_is_refused_by_name(run, edit, name):
    folder, resume = run
    before = (folder / "out" / "returns.npz").read_bytes()
    edit(folder)
    result = latentrl(*resume)
    assert result.returncode == 1 and f"its {name} changed since the run (sha256 " in result.stderr, result.stderr
    assert "Traceback" not in result.stderr
    assert (folder / "out" / "returns.npz").read_bytes() == before


def edit_task(folder):
    text = (folder / "glass_arm.toml").read_text()
    (folder / "glass_arm.toml").write_text(text + "\n# an edit\n")


@pytest.mark.parametrize(("edit", "name"), [(reorder_demos, "demos"), (edit_task, "task file")])
def test_a_run_whose_inputs_changed_is_not_replayed(run, tmp_path, edit, name):
    """Issue #38: replay reads the run back from its inputs; an edited input is refused by name,
    as resume refuses it, and nothing is written. (A rollout runs the saved policy.npz, which holds
    its task, demos and model and checks its task and URDF hashes on load.)"""
    folder, _ = run
    edit(folder)
    result = latentrl("replay", str(folder / "out"), "--test", "0", "--out", str(tmp_path / "x.gif"))
    assert result.returncode == 1 and f"its {name} changed since the run (sha256 " in result.stderr, result.stderr
    assert not (tmp_path / "x.gif").exists()


def test_a_run_started_with_relative_paths_is_read_back_from_anywhere(tmp_path):
    """Issue #38: `train` records its task file and demos as absolute paths, so the run folder is
    rolled out from another working directory."""
    for name in ("glass_arm.toml", "glass_arm.urdf", "demos.csv"):
        shutil.copy(EXAMPLE / name, tmp_path / name)
    assert latentrl("train", "glass_arm.toml", "--demos", "demos.csv", "--out", "out", "--quick", "--trials", "1",
                    "--episodes", "3", "--test-episodes", "1", "--episode.max-steps", "10", "--no-progress",
                    cwd=tmp_path).returncode == 0
    import json

    preset = json.loads((tmp_path / "out" / "results.json").read_text())["preset"]
    assert preset["task_file"] == str(tmp_path / "glass_arm.toml") and preset["demos"] == str(tmp_path / "demos.csv")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    result = latentrl("rollout", str(tmp_path / "out"), "--out", "rolled", "--episodes", "1", "--no-progress",
                      cwd=elsewhere)
    assert result.returncode == 0, result.stderr
