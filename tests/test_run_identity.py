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
