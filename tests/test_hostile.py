"""Hostile inputs (issue #21), one regression test per class of the issue where it is fixed:
edited runs (class 4), values that reached a panic (class 5), misleading messages (class 7)."""

import json

import numpy as np
import pytest

from latentrl import GPLVM, cli
from latentrl.saved_runs import saved_run
from latentrl._native import InvalidInputError, Sim
from latentrl.experiments import exp1
from latentrl.experiments.latent_runs import Fitted

TINY = ["run", "exp1", "--quick", "--trials", "2", "--episodes", "5", "--plant.max-steps", "20", "--no-progress"]


@pytest.fixture()
def finished_run(tmp_path):
    out = tmp_path / "run"
    assert cli.main([*TINY, "--out", str(out)]) == 0
    return out


def edit(out, change):
    meta = json.loads((out / "results.json").read_text())
    change(meta)
    (out / "results.json").write_text(json.dumps(meta))


@pytest.mark.parametrize(
    ("change", "says"),
    [
        (lambda m: m["preset"].update(seed=7), "seed: 0 in returns.npz, 7 in results.json"),
        (lambda m: m["preset"]["task"].update({"learner.alpha": 0.5}),
         "learner.alpha: not given in returns.npz, 0.5 in results.json"),
        (lambda m: m["preset"].update(trials=3), "trials: 2 in returns.npz, 3 in results.json"),
    ],
    ids=["seed", "a task key", "trials"],
)
def test_class_4_resume_refuses_an_edited_preset(finished_run, capsys, change, says):
    before = (finished_run / "returns.npz").read_bytes()
    edit(finished_run, change)
    assert cli.main(["run", "exp1", "--resume", str(finished_run), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "was edited after its trials ran" in err and says in err, err
    assert (finished_run / "returns.npz").read_bytes() == before, "nothing is rewritten"


def test_class_4_resume_refuses_another_model_fit(finished_run, capsys):
    edit(finished_run, lambda m: m["setup"]["gplvm"].update(nll=m["setup"]["gplvm"]["nll"] + 1.0))
    assert cli.main(["run", "exp1", "--resume", str(finished_run), "--no-progress"]) == 1
    assert "is not the one the saved trials used" in capsys.readouterr().err


@pytest.fixture()
def another_machine(monkeypatch):
    """Refits land elsewhere, as on a CPU whose BLAS kernel differs (docs/robustness.md): the
    GPLVM's optimiser stops after 5 iterations."""
    fit = Fitted.of.__func__
    monkeypatch.setattr(Fitted, "of", classmethod(lambda cls, demos, **kw: fit(cls, demos, **{**kw, "max_iter": 5})))


def resumes_unchanged(run):
    """`--resume` of a finished run succeeds and leaves every array as it was."""
    with np.load(run / "returns.npz") as npz:
        before = {k: npz[k] for k in npz.files}
    assert cli.main(["run", "exp1", "--resume", str(run), "--no-progress"]) == 0
    with np.load(run / "returns.npz") as npz:
        for key, value in before.items():
            np.testing.assert_array_equal(npz[key], value, err_msg=key)


def test_class_4_a_run_uses_its_saved_model_where_a_refit_differs(finished_run, another_machine, tmp_path):
    saved = GPLVM.load(finished_run / "gplvm.npz")
    resumes_unchanged(finished_run)
    assert cli.main(["plot", str(finished_run), "--out", str(tmp_path / "figures")]) == 0
    _, preset = saved_run(finished_run)
    np.testing.assert_array_equal(exp1.fit(preset, finished_run).model.Z_, saved.Z_)
    assert not np.array_equal(exp1.fit(preset).model.Z_, saved.Z_), "the refit must differ for this test to mean anything"


def test_class_4_a_run_without_its_model_refuses_a_refit_that_differs(finished_run, another_machine, capsys):
    (finished_run / "gplvm.npz").unlink()
    assert cli.main(["run", "exp1", "--resume", str(finished_run), "--no-progress"]) == 1
    err = capsys.readouterr().err
    assert "refitted on this machine" in err and "is not the one the saved trials used" in err, err
    _, preset = saved_run(finished_run)
    with pytest.raises(ValueError, match="is not the one the saved trials used"):
        exp1.fit(preset, finished_run)  # what replays and figures decode with


def test_class_4_a_corrupt_saved_model_is_named(finished_run, capsys):
    (finished_run / "gplvm.npz").write_bytes(b"not a zip")
    assert cli.main(["run", "exp1", "--resume", str(finished_run), "--no-progress"]) == 1
    assert "gplvm.npz" in capsys.readouterr().err


def test_class_4_an_unedited_run_resumes(finished_run):
    resumes_unchanged(finished_run)


ONE_LINK = '<robot name="r"><link name="a"><inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>'
JOINT = '<joint name="{name}" type="revolute"><parent link="{parent}"/><child link="{child}"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>'


def test_class_5_a_huge_physics_step_is_refused_before_any_step():
    with pytest.raises(InvalidInputError, match=r"physics.dt must lie in \(0, 0.05\], got 10000000000"):
        Sim(ONE_LINK + "</robot>", physics={"dt": 1e10})


def test_class_5_a_joint_whose_parent_is_its_child_is_refused():
    with pytest.raises(InvalidInputError, match="malformed URDF"):
        Sim(ONE_LINK + JOINT.format(name="k", parent="a", child="a") + "</robot>")


def test_class_7_identical_postures_say_so(tmp_path):
    from latentrl import GPLVM

    with pytest.raises(ValueError, match="all 10 postures are identical"):
        GPLVM(max_iter=5).fit(np.ones((10, 4)))


def test_class_7_a_model_out_that_is_not_npz_is_refused_before_the_fit(tmp_path, capsys):
    demos = tmp_path / "demos.csv"
    demos.write_text("a,b\n" + "\n".join(f"{i},{i * i}" for i in range(10)) + "\n")
    assert cli.main(["fit", str(demos), "--out", str(tmp_path / "model.json")]) == 1
    assert "give a file name ending in .npz" in capsys.readouterr().err
    assert not (tmp_path / "model.json").exists()


def test_class_7_loading_a_json_file_as_a_model_gives_no_pickle_advice(tmp_path):
    from latentrl import GPLVM

    (tmp_path / "m.json").write_text('{"a": 1}')
    with pytest.raises(ValueError, match="no zip archive header") as caught:
        GPLVM.load(tmp_path / "m.json")
    assert "pickle" not in str(caught.value)


def test_class_7_a_string_format_version_is_named_as_such(tmp_path):
    from latentrl import PCA

    good = tmp_path / "good.npz"
    PCA(n_components=1).fit(np.random.default_rng(0).normal(size=(5, 3))).save(good)
    with np.load(good) as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["format_version"] = np.array("1")
    np.savez(tmp_path / "edited.npz", **arrays)
    with pytest.raises(ValueError, match=r"format_version '1' \(<U1\) is not supported \(this latentrl reads the integer 1\)"):
        PCA.load(tmp_path / "edited.npz")


def test_class_1_a_gp_too_large_to_hold_is_refused_before_allocating():
    """60 000 points asked for a 28.8 GB kernel matrix and aborted the interpreter."""
    from latentrl import GPLVM, GpMap, _native
    from latentrl._native import gplvm_nll_grad

    n = _native.MAX_GP_POINTS + 1
    with pytest.raises(InvalidInputError, match=rf"inputs: {n} points need a {n}×{n} kernel matrix \(2.0 GiB\); the limit is"):
        GpMap(np.zeros((n, 2)), np.zeros((n, 1)), np.ones(3))
    with pytest.raises(InvalidInputError, match="latent points: 60000 points need"):
        gplvm_nll_grad(np.zeros((60000, 2)), np.zeros((60000, 3)), np.zeros(3))
    with pytest.raises(ValueError, match=rf"X: {n} postures, more than the {n - 1} an exact GPLVM fit takes .*"
                                         r"inducing=M .*--max-postures N"):
        GPLVM().fit(np.random.default_rng(0).normal(size=(n, 3)))


def test_class_3_a_run_too_long_to_hold_is_refused_before_allocating(tmp_path, capsys):
    """--episodes 1e12 allocated 21.8 TiB of per-episode arrays before any check: now past its
    rule; 1e8 episodes (its largest) of 2 trials are more than a run holds."""
    assert cli.main([*TINY, "--episodes", "1000000000000", "--out", str(tmp_path / "run")]) == 1
    err = capsys.readouterr().err
    assert "run.episodes must be an integer in [1, 100000000], got 1000000000000" in err, err
    assert cli.main([*TINY, "--episodes", "100000000", "--out", str(tmp_path / "run")]) == 1
    err = capsys.readouterr().err
    assert "run.trials × (episodes + test_episodes) = 200000000 episodes, more than the 10000000" in err, err
    assert not (tmp_path / "run").exists()


def test_class_6_and_7_demo_files_that_broke_the_reader_are_value_errors(tmp_path):
    """A CSV field over csv's 131072-character limit (_csv.Error), JSON nested 10⁵ deep
    (RecursionError), a FIFO (reported as an "empty file"), an oversized file."""
    import os

    from latentrl import load_demos
    from latentrl.demos import MAX_DEMO_FILE_BYTES

    (tmp_path / "long.csv").write_text("a,b\n1," + "2" * 200_000 + "\n")
    with pytest.raises(ValueError, match="long.csv: field larger than field limit"):
        load_demos(tmp_path / "long.csv")
    (tmp_path / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
    with pytest.raises(ValueError, match="deep.json: nested too deeply to read"):
        load_demos(tmp_path / "deep.json")
    os.mkfifo(tmp_path / "fifo.csv")
    with pytest.raises(ValueError, match=r"fifo.csv: is not a regular file \(a FIFO\)$"):
        load_demos(tmp_path / "fifo.csv")
    with open(tmp_path / "huge.csv", "wb") as fh:
        fh.truncate(MAX_DEMO_FILE_BYTES + 1)  # sparse: no disk used
    with pytest.raises(ValueError, match=f"more than the {MAX_DEMO_FILE_BYTES} a demo file may have"):
        load_demos(tmp_path / "huge.csv")


def test_class_3_a_sweep_grid_too_large_is_refused_before_it_is_expanded(tmp_path, capsys):
    """A 10⁶-cell grid was expanded in memory (3 GB) before any output."""
    values = ", ".join(str(0.1 * (i + 1)) for i in range(10))
    grid = "\n".join(f'"learner.{k}" = [{values}]' for k in ("alpha", "step", "rbf_width", "rbf_cutoff", "beta", "initial_weight"))
    sweep = tmp_path / "big.toml"
    sweep.write_text(f'experiment = "exp1"\n[grid]\n{grid}\n')
    assert cli.main(["sweep", str(sweep), "--out", str(tmp_path / "out"), "--no-progress"]) == 1
    assert "10 × 10 × 10 × 10 × 10 × 10 = 1000000 cells, more than the 10000" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def _npy(shape: tuple[int, ...], payload: bytes = b"") -> bytes:
    import io

    buf = io.BytesIO()
    np.lib.format.write_array_header_1_0(buf, {"descr": "<f8", "fortran_order": False, "shape": shape})
    return buf.getvalue() + payload


def test_class_3_model_files_that_would_unpack_huge_are_refused_before_unpacking(tmp_path, monkeypatch):
    """An NPZ whose header declares 10¹² elements, and a zip bomb (here: over a lowered limit)."""
    import zipfile

    from latentrl import GPLVM, _persistence

    with zipfile.ZipFile(tmp_path / "declared.npz", "w") as archive:
        archive.writestr("format.npy", _npy((10**12,), b"\0" * 64))
    with pytest.raises(ValueError, match="refused NPZ file: format.npy: its header declares 8000000000000 bytes"):
        GPLVM.load(tmp_path / "declared.npz")
    monkeypatch.setattr(_persistence, "MAX_NPZ_BYTES", 2**20)
    with zipfile.ZipFile(tmp_path / "bomb.npz", "w", compression=zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("a.npy", _npy((2**18,), b"\0" * 2**21))
    assert (tmp_path / "bomb.npz").stat().st_size < 10_000
    with pytest.raises(ValueError, match=r"refused NPZ file: it unpacks to \d+ bytes, more than the 1048576"):
        GPLVM.load(tmp_path / "bomb.npz")


def _chain(links: int) -> str:
    """A URDF chain of `links` links and revolute joints."""
    inertial = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
    body = "".join(f'<link name="l{i}">{inertial}</link>' for i in range(links))
    joints = "".join(JOINT.format(name=f"j{i}", parent=f"l{i}", child=f"l{i + 1}") for i in range(links - 1))
    return f'<robot name="chain">{body}{joints}</robot>'


def test_class_1_a_urdf_nested_too_deep_is_refused_before_parsing():
    """50 000 nested elements overflowed the parser's stack (SIGSEGV)."""
    deep = '<robot name="r"><link name="a">' + "<x>" * 50_000 + "</x>" * 50_000 + "</link></robot>"
    with pytest.raises(InvalidInputError, match="elements nested 50002 deep, more than the 256 a URDF may have"):
        Sim(deep)


def test_class_2_a_urdf_with_too_many_links_is_refused_before_building():
    """1000 links took 10 s to build, 10 000 over 3 minutes, deaf to Ctrl-C."""
    with pytest.raises(InvalidInputError, match="501 links, more than the 500 a robot may have"):
        Sim(_chain(501))
    assert len(Sim(_chain(20)).joint_names) == 19  # a robot within the limit builds


def test_class_7_a_bad_out_is_refused_before_any_work(tmp_path, capsys):
    """A bad --out was refused only after a 7 s fit."""
    demos = tmp_path / "demos.csv"
    demos.write_text("a,b\n" + "\n".join(f"{i},{i * i}" for i in range(10)) + "\n")
    assert cli.main(["fit", str(demos), "--out", str(tmp_path)]) == 1
    assert "is a directory, expected a file" in capsys.readouterr().err
    (tmp_path / "file").write_text("x")
    assert cli.main([*TINY, "--out", str(tmp_path / "file")]) == 1
    assert "is a file, expected a directory" in capsys.readouterr().err
    assert cli.main([*TINY, "--out", str(tmp_path / "file" / "run")]) == 1  # under a file
    assert f"cannot write under {tmp_path / 'file'}" in capsys.readouterr().err


def test_class_1_a_task_dict_nested_too_deep_is_refused_before_converting():
    """200 000 nested lists overflowed the stack of the dict conversion (SIGSEGV)."""
    from latentrl import Task

    deep: list = [0.0]
    for _ in range(200_000):
        deep = [deep]
    arms = Task.shipped("two_arms")
    config = arms.to_dict()
    config["target"]["position"] = deep
    with pytest.raises(ValueError, match="target.position: nested deeper than 32 lists or tables"):
        Task.from_dict(config, arms.base_dir)
