"""A run is what it says it is (issue #38): `train --resume` refuses a run whose task file or URDF
was edited, whose demos were reordered or whose saved GPLVM's latent points were permuted, naming
what changed (each was continued and merged before, with exit code 0); a `train` run killed
(SIGKILL) or interrupted (SIGINT) mid-way resumes to the bits of an uninterrupted run; a run
folder moved elsewhere still replays and plots."""

import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from child import CHILD, wait_for
from latentrl.results import PRESET_KEY

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


def edit_task(folder):
    text = (folder / "glass_arm.toml").read_text()
    (folder / "glass_arm.toml").write_text(text + "\n# an edit\n")


@pytest.mark.parametrize(("edit", "name"), [(edit_task, "task file"), (edit_urdf, "urdf"), (reorder_demos, "demos"),
                                            (permute_model, "model")])
def test_an_edited_input_is_refused_by_name(run, edit, name):
    folder, resume = run
    before = (folder / "out" / "returns.npz").read_bytes()
    edit(folder)
    result = latentrl(*resume)
    assert result.returncode == 1 and f"its {name} changed since the run (sha256 " in result.stderr, result.stderr
    assert "Traceback" not in result.stderr
    assert (folder / "out" / "returns.npz").read_bytes() == before


@pytest.mark.parametrize(("edit", "name"), [(edit_task, "task file"), (edit_urdf, "urdf"), (reorder_demos, "demos")])
def test_an_edited_input_is_refused_before_the_fit(run, monkeypatch, capsys, edit, name):
    """The refusal came after the GPLVM fit and the derived settings (seconds to minutes on a
    7-DoF arm, and "derived …" lines printed first): the task file, URDF and demos are compared
    before anything is fitted."""
    from latentrl import cli
    from latentrl.gplvm import GPLVM

    folder, resume = run
    edit(folder)
    monkeypatch.setattr(GPLVM, "fit", lambda *a, **k: pytest.fail("fitted before the inputs were compared"))
    assert cli.main(resume) == 1
    out, err = capsys.readouterr()
    assert f"its {name} changed since the run (sha256 " in err and out == "", (out, err)


def test_a_resume_with_other_flags_is_refused_naming_each_change(run):
    """A resume with another flag said only "holds a run of a different preset", naming nothing:
    it names each field and task key that differs, as the user gave it, and writes nothing."""
    folder, resume = run
    before = (folder / "out" / "returns.npz").read_bytes()
    changed = [a if a != "3" else "4" for a in resume]  # --episodes 3 → 4
    result = latentrl(*changed, "--learner.alpha", "0.5")
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert "different preset (episodes: 3 in the run, 4 now; learner.alpha: not given in the run, 0.5 now)" \
        in result.stderr, result.stderr
    assert (folder / "out" / "returns.npz").read_bytes() == before


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


# --- a train run stopped mid-way, and moved ---------------------------------------------------

TWO_TRIALS = ["--quick", "--trials", "2", "--episodes", "4", "--test-episodes", "1", "--episode.max-steps", "10",
              "--no-progress"]
"""Two trials, so that with one rayon thread the runner saves after the first and the child can be
stopped between the two."""


def train_args(inputs, out):
    return ["train", str(inputs / "glass_arm.toml"), "--demos", str(inputs / "demos.csv"), "--out", str(out),
            *TWO_TRIALS]


def saved_arrays(out):
    """What a resumed run must reproduce bit for bit: returns.npz's arrays, the per-trial summaries
    of results.json, the policy's arrays and the saved GPLVM."""
    found = {}
    for name in ("returns.npz", "policy.npz", "gplvm.npz"):
        with np.load(out / name) as npz:
            found.update({f"{name}:{key}": npz[key] for key in npz.files})
    found["results.json:trials"] = json.loads((out / "results.json").read_text())["trials"]
    return found


@pytest.fixture(scope="module")
def uninterrupted_train(tmp_path_factory):
    """The inputs (copied once: the preset records their absolute paths) and the arrays of an
    uninterrupted two-trial run on one thread."""
    inputs = tmp_path_factory.mktemp("inputs")
    for name in ("glass_arm.toml", "glass_arm.urdf", "demos.csv"):
        shutil.copy(EXAMPLE / name, inputs / name)
    out = inputs / "uninterrupted"
    result = subprocess.run([sys.executable, "-m", "latentrl", *train_args(inputs, out)], capture_output=True,
                            text=True, timeout=300, env={**os.environ, "RAYON_NUM_THREADS": "1"})
    assert result.returncode == 0, result.stderr
    return inputs, saved_arrays(out)


@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGKILL], ids=["ctrl-c", "kill-9"])
def test_a_train_run_stopped_mid_way_resumes_to_the_uninterrupted_bits(uninterrupted_train, tmp_path, how):
    """Issue #38: `latentrl train` stopped after its first trial was saved (the child holds there:
    tests/child.py), by Ctrl-C (exit 130, the resume command named) or kill -9, then continued
    with `--resume`, ends with the arrays, summaries, policy and model of the uninterrupted run."""
    inputs, expected = uninterrupted_train
    out, held = tmp_path / "run", tmp_path / "held"
    env = {**os.environ, "RAYON_NUM_THREADS": "1", "LATENTRL_TEST_HOLD_AFTER_SAVE": str(held)}
    proc = subprocess.Popen([sys.executable, "-c", CHILD, *train_args(inputs, out)], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)
    wait_for(held, proc)
    proc.send_signal(how)
    _, err = proc.communicate(timeout=60)
    if how == signal.SIGINT:
        assert proc.returncode == 130, err
        assert "interrupted; finished trials are in" in err and "--resume" in err, err
        assert "Traceback" not in err
    else:
        assert proc.returncode == -signal.SIGKILL
    with np.load(out / "returns.npz") as npz:  # whatever was saved is whole (atomic writes)
        assert (npz["latent_end"][:, 0] >= 0).sum() == 1, "expected the run stopped after its first trial"
    assert not (out / "policy.npz").exists()
    resumed = latentrl(*train_args(inputs, out), "--resume")
    assert resumed.returncode == 0, resumed.stderr
    found = saved_arrays(out)
    assert found.keys() == expected.keys()
    for key, value in expected.items():
        if isinstance(value, np.ndarray):
            np.testing.assert_array_equal(found[key], value, err_msg=key)
        else:
            assert found[key] == value, key
    assert not list(out.glob(".*.tmp")), "a killed write's temporary file was left behind"


def test_a_moved_train_run_folder_replays_and_plots(run, tmp_path):
    """Issue #38: a run folder moved (renamed into another directory) is read back where it now
    is: replayed and re-plotted, its inputs still checked (they did not change)."""
    folder, _ = run
    moved = tmp_path / "elsewhere" / "moved"
    moved.parent.mkdir()
    (folder / "out").rename(moved)
    video = tmp_path / "moved.gif"
    result = latentrl("replay", str(moved), "--test", "0", "--out", str(video))
    assert result.returncode == 0 and video.is_file(), result.stderr
    result = latentrl("plot", str(moved), "--out", str(tmp_path / "figures"))
    assert result.returncode == 0 and (tmp_path / "figures" / "returns.png").is_file(), result.stderr
    reorder_demos(folder)  # and an input edited since is still refused by name from the new place
    result = latentrl("replay", str(moved), "--test", "0", "--out", str(tmp_path / "x.gif"))
    assert result.returncode == 1 and "its demos changed since the run (sha256 " in result.stderr, result.stderr


def test_an_edited_collision_mesh_is_refused_by_name(tmp_path):
    """Issue #38: a run records the SHA-256 of every collision mesh its robot reads; `--resume`
    after the mesh was edited is refused naming the meshes (it had been continued)."""
    from test_issue38_files import cube_stl

    for name in ("glass_arm.toml", "demos.csv"):
        shutil.copy(EXAMPLE / name, tmp_path / name)
    urdf = (EXAMPLE / "glass_arm.urdf").read_text()
    capsule = '<capsule radius="0.015" length="0.07"/>'  # the hand's
    assert capsule in urdf
    (tmp_path / "glass_arm.urdf").write_text(urdf.replace(capsule, '<mesh filename="hand.stl" scale="0.07 0.03 0.03"/>'))
    (tmp_path / "hand.stl").write_bytes(cube_stl())
    args = ["train", str(tmp_path / "glass_arm.toml"), "--demos", str(tmp_path / "demos.csv"), "--out",
            str(tmp_path / "out"), "--quick", "--trials", "1", "--episodes", "3", "--test-episodes", "1",
            "--episode.max-steps", "10", "--no-progress"]
    first = latentrl(*args)
    assert first.returncode == 0, first.stderr
    assert "meshes" in json.loads((tmp_path / "out" / "results.json").read_text())["setup"]["inputs"]
    stl = bytearray(cube_stl())
    stl[0] = ord("x")  # the 80-byte header: other bytes, the same cube
    (tmp_path / "hand.stl").write_bytes(bytes(stl))
    result = latentrl(*args, "--resume")
    assert result.returncode == 1 and "its meshes changed since the run (sha256 " in result.stderr, result.stderr


def test_a_run_recorded_before_a_preset_field_existed_resumes_with_its_default(run):
    """A field added to TrainRun since a run was saved is not "not given in the run": it takes its
    default there, the behaviour before it existed; a resume that sets it otherwise is refused."""
    folder, resume = run
    out = folder / "out"
    meta = json.loads((out / "results.json").read_text())
    del meta["preset"]["max_postures"]
    (out / "results.json").write_text(json.dumps(meta))
    arrays = dict(np.load(out / "returns.npz"))
    preset = json.loads(str(arrays[PRESET_KEY]))
    del preset["max_postures"]
    np.savez_compressed(out / "returns.npz", **{**arrays, PRESET_KEY: np.array(json.dumps(preset))})
    result = latentrl(*resume)
    assert result.returncode == 0, result.stderr
    result = latentrl(*resume, "--max-postures", "50")
    assert result.returncode == 1 and "max_postures: 0 in the run, 50 now" in result.stderr, result.stderr


def test_a_preset_of_another_kind_is_named_alone():
    """An Exp 1 run resumed by `train` listed all 15 fields the two kinds of preset differ in."""
    from latentrl.experiments.run_folder import edits

    exp1 = {"name": "Exp1Preset", "seed": 0, "n_demos": 50, "task": {"learner.step": 0.5}}
    train = {"name": "TrainRun", "seed": 0, "demos": "d.csv", "task": {}}
    assert edits(exp1, train, {}, "in the run", "now") == "name: 'Exp1Preset' in the run, 'TrainRun' now"
    assert edits({**train, "seed": 1}, train, {}, "in the run", "now") == "seed: 1 in the run, 0 now"
