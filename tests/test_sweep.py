"""Sweeps (`latentrl.experiments.sweep`): descriptions and their errors, cells, the local
backend against running each cell's preset directly, the Ray backend (a local Ray instance)
against the local backend bit for bit, a killed worker retried, resume, the summary, the CLI."""

import dataclasses
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from child import CHILD, wait_for

from latentrl.cli import main
from latentrl.experiments.exp1 import Exp1Preset
from latentrl.experiments import run_experiment
from latentrl.experiments.sweep import Sweep, SweepError, load_sweep, run_sweep
from latentrl.experiments.sweep import episodes_to_threshold

# A local Ray instance on 127.0.0.1 only (Ray's single-machine mode), set before ray is imported.
os.environ.setdefault("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER", "0")

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "sweep.toml"
TINY = {"episodes": 20, "plant.max_steps": 50, "gplvm_max_iter": 100}
SWEEP = Sweep("exp1", quick=True, trials=2, base=TINY, grid={"learner.beta": [5.0, 10.0]})
SWEEP_TOML = """
experiment = "exp1"
quick = true
trials = 2
[base]
episodes = 20
gplvm_max_iter = 100
plant.max_steps = 50
[grid.learner]
beta = [5, 10.0]
"""


def write(tmp_path, text, name="sweep.toml"):
    path = tmp_path / name
    path.write_text(text)
    return path


def results_of(cell_dir):
    """What two runs of a cell must share bit for bit: every array, the per-trial summaries,
    the setup facts and the preset."""
    with np.load(cell_dir / "returns.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    meta = json.loads((cell_dir / "results.json").read_text())
    return arrays, {k: meta[k] for k in ("trials", "setup", "preset")}


def assert_same_results(a_dir, b_dir):
    (a, a_meta), (b, b_meta) = results_of(a_dir), results_of(b_dir)
    assert a.keys() == b.keys()
    for key in a:
        assert a[key].dtype == b[key].dtype, key
        np.testing.assert_array_equal(a[key], b[key], err_msg=key)
    assert a_meta == b_meta


def assert_same_sweep(a_out, b_out):
    for cell in SWEEP.expand():
        assert_same_results(a_out / cell.id, b_out / cell.id)


# --- descriptions -----------------------------------------------------------------------------


def test_toml_file_gives_the_python_sweep(tmp_path):
    assert load_sweep(write(tmp_path, SWEEP_TOML)) == SWEEP  # the int 5 of a float field is 5.0


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ('experiment = "exp9"', "unknown experiment 'exp9'; sweeps run exp1, exp2"),
        ('experiment = "table1"', "unknown experiment 'table1'"),
        ("quick = true", "no experiment"),
        ('experiment = "exp1"\ntrails = 3', "unknown key 'trails'"),
        ('experiment = "exp1"\n[grid]\n"learner.betaa" = [1.0]', "grid.learner.betaa: 'learner.betaa' is not a field of the preset or a task key; did you mean 'learner.beta'"),
        ('experiment = "exp1"\n[base]\nno_such = 1', "base.no_such: 'no_such' is not a field"),
        ('experiment = "exp1"\n[grid.learner]\nbeta = []', "grid.learner.beta: empty list"),
        ('experiment = "exp1"\n[grid.learner]\nbeta = 5.0', "grid.learner.beta: expected a list of values, got 5.0"),
        ('experiment = "exp1"\n[grid.learner]\nbeta = [5.0, 5]', "grid.learner.beta: 5.0 appears twice"),
        ('experiment = "exp1"\n[grid]\nepisodes = [10, 2.5]', r"grid.episodes\[1\]: expected an integer, got 2.5"),
        ('experiment = "exp1"\n[grid.learner]\nbeta = ["hot"]', r"grid.learner.beta\[0\]: expected a number, got 'hot'"),
        ('experiment = "exp1"\n[base]\nepisodes = true', "base.episodes: expected an integer, got True"),
        ('experiment = "exp1"\ntrials = 0', r"run.trials must be an integer in \[1, 1000000\], got 0"),
        ('experiment = "exp1"\nquick = "yes"', "quick: expected true or false"),
        ('experiment = "exp1"\ntrials = 2\n[base]\ntrials = 3', "base.trials: trials is already set"),
        ('experiment = "exp1"\ntrials = 2\n[base.run]\ntrials = 3', "base.run.trials: trials is already set"),
        ('experiment = "exp1"\n[base.learner]\ngamma = 1.5', r"cell 00: learner.gamma must lie in \[0, 1\)"),
        ('experiment = "exp1"\ncells = 3', "cells: expected a list of tables"),
        ('experiment = "exp1"\n[grid.learner]\nbeta = [1.0]\n[[cells]]\n"learner.beta" = 2.0', r"cells\[0\]: learner.beta also in the grid"),
        ('experiment = "exp1"\n[[cells]]\nlearner.beta = 2.0\n[[cells]]\nlearner.beta = 2', "cells 00_learner.beta=2.0 and 01_learner.beta=2.0 are the same"),
        ('experiment = "exp1"\n[grid\n', "not valid TOML"),
    ],
)
def test_bad_descriptions_are_value_errors_naming_the_problem(tmp_path, text, message):
    path = write(tmp_path, text)
    with pytest.raises(ValueError, match=message) as info:
        load_sweep(path)
    assert str(info.value).startswith(str(path))


def test_yaml_file_when_pyyaml_is_there(tmp_path):
    pytest.importorskip("yaml")
    text = "experiment: exp1\nquick: true\ntrials: 2\nbase: {episodes: 20, plant.max_steps: 50, gplvm_max_iter: 100}\n"
    assert load_sweep(write(tmp_path, text + "grid: {learner: {beta: [5, 10.0]}}\n", "s.yaml")) == SWEEP


def test_cells_are_the_explicit_cells_crossed_with_the_grid():
    sweep = Sweep(
        "exp1", trials=4, seed=7, base={"episodes": 30, "learner.beta": 3.0},
        grid={"learner": {"alpha": [0.5, 0.9], "gamma": [0.9, 0.95]}}, cells=[{"learner.beta": 1}, {"plant.max_steps": 80}],
    )
    cells = sweep.expand()
    assert [c.overrides for c in cells[:4]] == [
        {"learner.beta": 1.0, "learner.alpha": a, "learner.gamma": g} for a in (0.5, 0.9) for g in (0.9, 0.95)
    ]
    assert len(cells) == 8 and cells[4].overrides == {"plant.max_steps": 80, "learner.alpha": 0.5, "learner.gamma": 0.9}
    assert cells[0].id == "00_learner.alpha=0.5_learner.gamma=0.9_learner.beta=1.0"
    assert cells[7].id == "07_learner.alpha=0.9_learner.gamma=0.95_plant.max_steps=80"
    expected = dataclasses.replace(Exp1Preset(), trials=4, seed=7, episodes=30,
                                   task={"learner.beta": 1.0, "learner.alpha": 0.5, "learner.gamma": 0.9})
    assert cells[0].preset == expected and isinstance(cells[0].preset.task["learner.beta"], float)
    assert cells[4].preset.task["learner.beta"] == 3.0 and cells[4].preset.task["plant.max_steps"] == 80
    assert len(Sweep("exp2").expand()) == 1 and Sweep("exp2").expand()[0].id == "00"


def test_a_run_key_by_path_sets_the_preset_field():
    cells = Sweep("exp1", quick=True, grid={"run.episodes": [5, 6]}).expand()
    assert [c.preset.episodes for c in cells] == [5, 6] and all("run.episodes" not in c.preset.task for c in cells)


def test_the_example_file_describes_a_sweep():
    cells = load_sweep(EXAMPLE).expand()
    assert len(cells) == 4 and all(c.preset.trials == 3 and c.preset.episodes == 300 for c in cells)


def test_episodes_to_threshold_uses_the_running_mean_of_full_windows():
    returns = np.array([[0.0, 0.0, 4.0, 4.0, 4.0], [1.0, 1.0, 1.0, 1.0, 1.0], [5.0, 0.0, 0.0, 0.0, 0.0]])
    np.testing.assert_array_equal(episodes_to_threshold(returns, 3.0, 2), [4, -1, -1])
    np.testing.assert_array_equal(episodes_to_threshold(returns, 1.0, 1), [3, 1, 1])


# --- the local backend ----------------------------------------------------------------------------


@pytest.fixture(scope="module")
def local_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("sweep_local")
    state = run_sweep(SWEEP, out, progress=False)
    return out, state


def test_local_backend_equals_running_each_cell_preset(local_run, tmp_path):
    out, state = local_run
    for cell in SWEEP.expand():
        run_experiment("exp1", cell.preset, tmp_path / cell.id, progress=False)
        assert_same_results(out / cell.id, tmp_path / cell.id)
        assert (out / cell.id / "fig4a.png").exists()
    assert [c["status"] for c in state["cells"]] == ["done", "done"]
    assert [c["trials_done"] for c in state["cells"]] == [4, 4]  # 2 trials × 2 learners
    assert state["runs"][0]["backend"] == "local"


def test_summary_has_a_row_per_cell_and_learner(local_run):
    out, state = local_run
    summary = json.loads((out / "summary.json").read_text())
    assert [(r["cell"], r["learner"]) for r in summary["rows"]] == [
        (c.id, learner) for c in SWEEP.expand() for learner in ("latent", "full")
    ]
    row = summary["rows"][0]
    with np.load(out / row["cell"] / "returns.npz") as npz:
        final = npz["latent"][:, -2:].mean(axis=1)  # the last 10 % of 20 episodes
    assert row["final_return_mean"] == pytest.approx(final.mean()) and row["trials"] == row["of"] == 2
    best = max(r["final_return_mean"] for r in summary["rows"])
    assert summary["threshold"] == pytest.approx(best / 2) and summary == state["summary"]
    table = (out / "summary.md").read_text()
    assert "| 00_learner.beta=5.0 | 5.0 | latent | 2/2 |" in table and (out / "sweep.png").stat().st_size > 1000


def test_a_sweep_directory_is_resumed_only_when_asked_and_only_by_the_same_sweep(local_run):
    out, _ = local_run
    with pytest.raises(ValueError, match="already holds a sweep; resume it"):
        run_sweep(SWEEP, out, progress=False)
    with pytest.raises(ValueError, match="holds a different sweep"):
        run_sweep(dataclasses.replace(SWEEP, seed=3), out, resume=True, progress=False)
    before = (out / "00_learner.beta=5.0" / "returns.npz").stat().st_mtime_ns
    state = run_sweep(SWEEP, out, resume=True, progress=False)  # nothing left to run
    assert (out / "00_learner.beta=5.0" / "returns.npz").stat().st_mtime_ns == before
    assert len(state["runs"]) == 2


# --- the Ray backend, on a local Ray instance -------------------------------------------------


@pytest.fixture(scope="module")
def ray_instance():
    ray = pytest.importorskip("ray")
    ray.init(address="local", num_cpus=2, include_dashboard=False, log_to_driver=False,
             logging_level="WARNING")
    yield ray
    ray.shutdown()


def test_ray_backend_equals_the_local_backend_bit_for_bit(ray_instance, local_run, tmp_path, capsys):
    # Through the CLI: `--backend ray` without --address uses the Ray that is running.
    out = tmp_path / "out"
    assert main(["sweep", str(write(tmp_path, SWEEP_TOML)), "--backend", "ray", "--no-progress", "--out", str(out)]) == 0
    assert "| 01_learner.beta=10.0 | 10.0 | full | 2/2 |" in capsys.readouterr().out
    assert_same_sweep(local_run[0], out)
    state = json.loads((out / "sweep.json").read_text())
    assert [c["status"] for c in state["cells"]] == ["done", "done"]
    assert state["runs"][0]["backend"] == "ray" and ray_instance.is_initialized()  # not ours to stop
    assert (out / "01_learner.beta=10.0" / "fig4a.png").exists()
    assert json.loads((out / "summary.json").read_text()) == json.loads((local_run[0] / "summary.json").read_text())


def test_a_killed_worker_is_retried_and_the_results_stay_the_same(ray_instance, local_run, tmp_path):
    from latentrl.experiments.ray_backend import RayBackend

    marker = tmp_path / "killed"

    def die_once(*args):  # the first task to get here kills its worker process
        import os

        from latentrl.experiments.ray_backend import run_chunk

        try:
            open(marker, "x").close()
        except FileExistsError:
            return run_chunk(*args)
        os._exit(1)

    run_sweep(SWEEP, tmp_path / "out", backend=RayBackend(task=die_once, batch=2), progress=False)
    assert marker.exists()
    assert_same_sweep(local_run[0], tmp_path / "out")


def test_a_failed_trial_fails_its_cell_and_resume_runs_only_that_trial(ray_instance, local_run, tmp_path):
    from latentrl.experiments.ray_backend import RayBackend

    out, ran = tmp_path / "out", tmp_path / "ran"
    ran.mkdir()

    def failing(experiment, preset, fingerprint, learner, first, n):
        from latentrl.experiments.ray_backend import run_chunk

        if preset.task["learner.beta"] == 10.0 and learner == "full" and first == 1:
            raise RuntimeError("injected failure")
        return run_chunk(experiment, preset, fingerprint, learner, first, n)

    def counting(experiment, preset, fingerprint, learner, first, n):
        from latentrl.experiments.ray_backend import run_chunk

        (ran / f"{preset.task['learner.beta']}-{learner}-{first}-{n}").touch()
        return run_chunk(experiment, preset, fingerprint, learner, first, n)

    with pytest.raises(SweepError, match="1 of 2 cells failed.*full trials 1..1: RuntimeError: injected failure"):
        run_sweep(SWEEP, out, backend=RayBackend(task=failing), progress=False)
    cells = json.loads((out / "sweep.json").read_text())["cells"]
    assert [(c["status"], c["trials_done"]) for c in cells] == [("done", 4), ("failed", 3)]
    with np.load(out / "01_learner.beta=10.0" / "returns.npz") as npz:
        assert (npz["full_end"][1] == -1).all() and (npz["full_end"][0] >= 0).all()
    run_sweep(SWEEP, out, backend=RayBackend(task=counting), resume=True, progress=False)
    assert sorted(p.name for p in ran.iterdir()) == ["10.0-full-1-1"]
    assert_same_sweep(local_run[0], out)


# --- the command line -------------------------------------------------------------------------


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["local", "ray"])
def test_the_documented_example_runs(tmp_path, backend):
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, "-m", "latentrl", "sweep", str(EXAMPLE), "--backend", backend, "--no-progress",
         "--out", str(out)], capture_output=True, text=True, timeout=600,
    )
    assert result.returncode == 0, result.stderr
    cells = json.loads((out / "sweep.json").read_text())["cells"]
    assert [c["status"] for c in cells] == ["done"] * 4 and "| 03_learner.initial_weight=20.0_learner.beta=10.0 |" in result.stdout


def test_the_package_never_imports_ray_itself():
    code = ("import sys, latentrl.cli, latentrl.experiments.ray_backend, latentrl.experiments.sweep; "
            "latentrl.cli.build_parser(); sys.exit('ray' in sys.modules)")
    assert subprocess.run([sys.executable, "-c", code], timeout=120).returncode == 0


def test_cli_errors_exit_1_with_the_message(tmp_path, capsys):
    bad = write(tmp_path, 'experiment = "exp1"\n[grid.learner]\nbeta = []')
    assert main(["sweep", str(bad), "--out", str(tmp_path / "a")]) == 1
    assert "grid.learner.beta: empty list" in capsys.readouterr().err
    good = write(tmp_path, SWEEP_TOML, "good.toml")
    assert main(["sweep", str(good), "--address", "auto", "--out", str(tmp_path / "b")]) == 1
    assert "--address and --batch are options of --backend ray" in capsys.readouterr().err
    assert main(["sweep", str(tmp_path / "missing.toml")]) == 1


def test_cli_sweep_stopped_by_ctrl_c_exits_130_and_resumes(local_run, tmp_path):
    path, out = write(tmp_path, SWEEP_TOML), tmp_path / "out"
    held = tmp_path / "held"
    args = ["sweep", str(path), "--no-progress", "--out", str(out)]
    env = {**os.environ, "RAYON_NUM_THREADS": "1", "LATENTRL_TEST_HOLD_AFTER_SAVE": str(held)}
    proc = subprocess.Popen([sys.executable, "-c", CHILD, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, env=env)
    wait_for(held, proc)  # the child holds after the first cell's first saved trial
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert f"--out {out} --resume" in err
    state = json.loads((out / "sweep.json").read_text())
    assert state["cells"][1]["status"] in ("pending", "partial")
    assert main([*args, "--resume"]) == 0
    assert_same_sweep(local_run[0], out)
