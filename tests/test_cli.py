"""The `latentrl` command: help, info, runs, exit codes; results that do not depend on the
thread count; runs interrupted (Ctrl-C) or killed mid-way and resumed to the uninterrupted result."""

import json
import os
import signal
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

from latentrl import __version__ as latentrl_version
from latentrl.cli import build_parser, main

from child import CHILD, wait_for


def latentrl(*args, timeout=300):
    return subprocess.run(
        [sys.executable, "-m", "latentrl", *args], capture_output=True, text=True, timeout=timeout
    )


def test_info_on_a_full_disk_says_so_in_one_line():
    """Issue #38's probe: `latentrl info > /dev/full` was an OSError traceback."""
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "latentrl", "info"], stdout=full, stderr=subprocess.PIPE,
                                text=True)
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert result.stderr.strip() == "latentrl: error: cannot write to standard output: [Errno 28] No space left on device"


def test_a_reader_gone_or_a_full_disk_on_stdout_stops_the_printing_not_the_work(tmp_path, capfd):
    """`latentrl train … | head -2` trained, then exited 1 ("[Errno 32] Broken pipe") without
    writing report.json; `report RUN | head -1`, `check … | true` exited 1 so. As other CLIs: the
    command finishes silently with its own exit code; a full disk for stdout is one line, exit 1,
    after the files are written."""
    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    train = ["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--quick", "--episodes",
             "10", "--trials", "1", "--out"]

    def no_reader(*args, stderr_too=False):
        read, write = os.pipe()
        os.close(read)
        try:
            return subprocess.run([sys.executable, "-m", "latentrl", *args], stdout=write,
                                  stderr=write if stderr_too else subprocess.PIPE, text=True, timeout=300)
        finally:
            os.close(write)

    assert no_reader(*train, str(tmp_path / "run"), stderr_too=True).returncode == 0  # `2>&1 | head -2`, progress too
    assert (tmp_path / "run" / "report.json").is_file()
    for args in (["report", str(tmp_path / "run")], ["info"]):
        result = no_reader(*args)
        assert (result.returncode, result.stderr) == (0, ""), (args, result.stderr)
    with open("/dev/full", "w") as full:
        result = subprocess.run([sys.executable, "-m", "latentrl", *train, str(tmp_path / "full"), "--no-progress"],
                                stdout=full, stderr=subprocess.PIPE, text=True, timeout=300)
    assert result.returncode == 1 and (tmp_path / "full" / "report.json").is_file()
    assert result.stderr == "latentrl: error: cannot write to standard output: [Errno 28] No space left on device\n"
    # In this process, the streams are put back, flushed: what follows main() is not held in a buffer.
    assert main(["info"]) == 0
    print("after")
    assert capfd.readouterr().out.endswith("}\nafter\n")


def test_a_closed_stderr_costs_no_result_and_sends_no_message_to_stdout(tmp_path):
    """`latentrl train … 2>&-` exited 1 after its fit without a word (the progress bar asked the
    missing stderr whether it is a terminal), and an error printed to the missing stderr went to
    stdout. Each command runs as it would, silently on stderr."""
    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    task, demos, run = str(example / "glass_arm.toml"), str(example / "demos.csv"), tmp_path / "run"

    def closed_stderr(*args):
        return subprocess.run([sys.executable, "-m", "latentrl", *args], stdout=subprocess.PIPE, text=True,
                              preexec_fn=lambda: os.close(2), timeout=300)

    trained = closed_stderr("train", task, "--demos", demos, "--quick", "--episodes", "10", "--trials", "1", "--out",
                            str(run))
    assert trained.returncode == 0 and "verdict: " in trained.stdout and (run / "report.json").is_file()
    assert closed_stderr("check", task, "--demos", demos).returncode == 0
    assert closed_stderr("rollout", str(run), "--out", str(tmp_path / "rollout"), "--episodes", "2").returncode == 0
    assert (tmp_path / "rollout" / "rollout.json").is_file()
    refused = closed_stderr("fit", str(tmp_path / "missing.csv"), "--out", str(tmp_path / "m.npz"))
    assert refused.returncode == 1 and refused.stdout == ""


def test_a_terminal_that_lacks_a_character_gets_its_escape_not_an_error():
    """PYTHONIOENCODING=ascii (or latin-1, a Latin-1 locale): `train --help` failed on "…", `check` after its
    survey on "×", `train` after its fit on "−", each exit 1."""
    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    env = {**os.environ, "PYTHONIOENCODING": "ascii"}
    for args, escape in [(["train", "--help"], "\\u2026"),
                         (["check", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv")], "\\xd7")]:
        result = subprocess.run([sys.executable, "-m", "latentrl", *args], capture_output=True, text=True, env=env,
                                timeout=300)
        assert result.returncode == 0 and escape in result.stdout, result.stderr


def test_info_prints_versions_git_revision_and_threads_as_json():
    """What the README promises of `latentrl info`: versions, git revision, thread count."""
    result = latentrl("info")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)
    assert info["versions"]["latentrl"] == latentrl_version and info["versions"]["numpy"] == np.__version__
    revision = subprocess.run(["git", "rev-parse", "HEAD"], capture_output=True, text=True,
                              cwd=Path(__file__).parent).stdout.strip()
    assert info["git_revision"] == (revision or None)
    assert info["cpu_count"] >= 1 and info["rayon_threads"] >= 1
    # What decides the last bits on another machine (docs/robustness.md): SIMD flags, BLAS.
    assert set(info["cpu_flags"]) <= {"sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512vl"}
    assert info["blas"]["name"] and "OPENBLAS_CORETYPE" in info["blas"]
    env = {**os.environ, "RAYON_NUM_THREADS": "1"}
    one = subprocess.run([sys.executable, "-m", "latentrl", "info"], capture_output=True, text=True, env=env)
    assert json.loads(one.stdout)["rayon_threads"] == 1


def test_the_thread_count_recorded_is_the_one_rayon_reads(monkeypatch):
    """`RAYON_NUM_THREADS=1_0` (or " 1") recorded 10 (1) threads in results.json: Python's int()
    reads them, rayon (Rust's `usize::from_str`) does not and runs one per CPU."""
    from latentrl.machine import worker_threads

    cpus = len(os.sched_getaffinity(0))
    for value, threads in [("1_0", cpus), (" 1", cpus), ("10", 10), ("+3", 3), ("007", 7), ("70000", 2**16 - 1),
                           ("1\n", cpus), ("\u0663", cpus), ("0", cpus), ("-1", cpus), ("", cpus),
                           ("2e1", cpus), (str(2**64), cpus)]:
        monkeypatch.setenv("RAYON_NUM_THREADS", value)
        assert worker_threads() == threads, value


def test_help_documents_every_preset_flag():
    text = build_parser()._subparsers._group_actions[0].choices["run"].format_help()  # noqa: SLF001
    assert all(name in text for name in ("table1", "exp1", "exp2"))
    exp1 = latentrl("run", "exp1", "--help")
    assert exp1.returncode == 0
    assert "--plant.drop-tolerance" in exp1.stdout and "Soft-max inverse temperature" in exp1.stdout
    exp2 = " ".join(latentrl("run", "exp2", "--help").stdout.split())
    # Task keys: the native doc, kind, rule and default of each.
    assert "--learner.gamma FLOAT Discount γ; below 1" in exp2 and "must lie in [0, 1); default: 0.99)" in exp2
    assert "--physics.dt" in exp2 and "default: 0.008333333333333333" in exp2


@pytest.mark.parametrize("experiment", ["table1", "exp1", "exp2", "exp3"])
def test_help_of_every_experiment_renders(experiment):
    # A "%" in a field docstring once broke argparse's help formatting for exp2.
    result = latentrl("run", experiment, "--help")
    assert result.returncode == 0, result.stderr
    assert "--seed" in result.stdout and "--out" in result.stdout
    assert ("--resume" in result.stdout) == (experiment != "table1")


def test_run_exp1_tiny(tmp_path):
    out = tmp_path / "run"
    result = latentrl(
        "run", "exp1", "--quick", "--no-progress", "--trials", "1", "--episodes", "5",
        "--plant.max-steps", "20", "--out", str(out),
    )
    assert result.returncode == 0, result.stderr
    assert (out / "results.json").exists() and (out / "fig4a.png").exists()


def test_run_table1_tiny(tmp_path):
    result = latentrl("run", "table1", "--quick", "--no-progress", "--trials", "1", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "table1.md").exists()


def test_bad_values_exit_1_with_a_message(tmp_path, capsys):
    assert main(["run", "exp1", "--quick", "--no-progress", "--trials", "0", "--out", str(tmp_path)]) == 1
    err = capsys.readouterr().err
    assert err.startswith("latentrl: error:") and "trials" in err and "got 0" in err, err
    assert not any(tmp_path.iterdir()), "nothing is written for a bad value"


def test_unknown_flag_exits_2():
    with pytest.raises(SystemExit) as exit_info:
        main(["run", "exp1", "--no-such-flag"])
    assert exit_info.value.code == 2


@pytest.mark.parametrize("argv", [["--help"], ["train", "--nope"]])
def test_help_and_a_bad_flag_load_no_experiment(argv):
    """Issue #39, item 5: a subcommand's flags are built when it is used, so `--help` and a
    mistyped flag import no experiment, its registry or tqdm (benches/bench_startup.py times them)."""
    code = ("import contextlib, io, sys; from latentrl.cli import main\n"
            "with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):\n"
            "    try: main(sys.argv[1:])\n"
            "    except SystemExit: pass\n"
            "print(sorted(m for m in sys.modules if m.startswith(('latentrl.experiments.exp', "
            "'latentrl.experiments.table1', 'latentrl.experiments.runner', 'tqdm'))))")
    done = subprocess.run([sys.executable, "-c", code, *argv], capture_output=True, text=True, timeout=300, check=True)
    assert done.stdout.strip() == "[]"


@pytest.mark.parametrize(
    "script", ["table1.py", "exp1.py", pytest.param("exp2.py", marks=pytest.mark.slow)]
)
def test_examples_run_quick(script, tmp_path):
    path = Path(__file__).resolve().parents[1] / "examples" / script
    result = subprocess.run(
        [sys.executable, str(path), "--quick", "--out", str(tmp_path)],
        capture_output=True, text=True, timeout=600,
    )
    assert result.returncode == 0, result.stderr
    figure = {"table1.py": "table1.md", "exp1.py": "fig4a.png", "exp2.py": "fig6a.png"}[script]
    assert any(p.name == figure and p.stat().st_size > 0 for p in tmp_path.rglob("*")), sorted(tmp_path.rglob("*"))


# Small runs of each experiment; RL trials long enough (~1-3 s each) to be caught mid-way.
TINY_RUNS = {
    "table1": ["--quick", "--gplvm-max-iter", "200"],
    "exp1": ["--quick", "--trials", "3", "--episodes", "40", "--plant.max-steps", "300"],
    "exp2": ["--quick", "--trials", "3", "--episodes", "20", "--episode.max-steps", "500", "--test-episodes", "2",
             "--fig5-samples", "200", "--gplvm-max-iter", "100"],
    "exp3": ["--quick", "--trials", "2", "--episodes", "3", "--episode.max-steps", "8", "--test-episodes", "1",
             "--map-grid", "8"],
}
def start(experiment, out, threads, *extra, env=None, runs=None):
    args = ["run", experiment, "--no-progress", *(runs or TINY_RUNS)[experiment], "--out", str(out), *extra]
    env = {**os.environ, "RAYON_NUM_THREADS": str(threads), **(env or {})}
    return subprocess.Popen([sys.executable, "-c", CHILD, *args], env=env, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def without_timings(value):
    """`value` without its wall times (keys ending in "seconds"), at any depth."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if not k.endswith("seconds")}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def results_of(out):
    """What a run's results must reproduce: every array, and the per-trial summaries."""
    if (out / "table1.json").exists():
        saved = json.loads((out / "table1.json").read_text())
        return without_timings({"trials": saved["trials"], "summary": saved["summary"]})
    with np.load(out / "returns.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    return {"trials": json.loads((out / "results.json").read_text())["trials"], **arrays}


def assert_same_results(a, b):
    assert a.keys() == b.keys()
    for key in a:
        if isinstance(a[key], np.ndarray):
            np.testing.assert_array_equal(a[key], b[key], err_msg=key)
        else:
            assert a[key] == b[key], key


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    """Each experiment's tiny run, once with 1 thread and once with 2: results by (experiment, threads)."""
    runs = {}
    for experiment in TINY_RUNS:
        for threads in (1, 2):
            out = tmp_path_factory.mktemp(f"{experiment}_{threads}")
            proc = start(experiment, out, threads)
            _, err = proc.communicate(timeout=300)
            assert proc.returncode == 0, err
            runs[experiment, threads] = results_of(out)
    return runs


@pytest.mark.parametrize("experiment", list(TINY_RUNS))
def test_thread_count_does_not_change_results(uninterrupted, experiment):
    assert_same_results(uninterrupted[experiment, 1], uninterrupted[experiment, 2])


@pytest.mark.parametrize("experiment", ["exp1", "exp2"])
@pytest.mark.parametrize("how", [signal.SIGINT, signal.SIGKILL], ids=["ctrl-c", "kill-9"])
def test_run_stopped_mid_way_resumes_to_the_uninterrupted_result(uninterrupted, tmp_path, experiment, how):
    out, held = tmp_path / "run", tmp_path / "held"
    # One thread: one trial per chunk, saved as it finishes; the child holds after the first.
    proc = start(experiment, out, 1, env={"LATENTRL_TEST_HOLD_AFTER_SAVE": str(held)})
    wait_for(held, proc)
    proc.send_signal(how)
    _, err = proc.communicate(timeout=60)
    if how == signal.SIGINT:
        assert proc.returncode == 130, err
        assert f"--resume {out}" in err
    else:
        assert proc.returncode == -signal.SIGKILL
    with np.load(out / "returns.npz") as npz:  # whatever was saved is whole (atomic writes)
        done = (npz["latent_end"][:, 0] >= 0).sum()
    assert done == 1, f"expected the run stopped after its first latent trial, {done} of 3 done"
    resumed = latentrl("run", experiment, "--no-progress", "--resume", str(out))
    assert resumed.returncode == 0, resumed.stderr
    assert_same_results(results_of(out), uninterrupted[experiment, 1])
    assert not list(out.glob(".*.tmp")), "a killed write's temporary file was left behind"


def test_ctrl_c_stops_a_native_trial_call_mid_way(tmp_path):
    """SIGINT sent while the Rust trials run (the child says so from inside the call) stops the
    call: exit 130 long before the ~10⁵ episodes it was given could finish."""
    out, started = tmp_path / "run", tmp_path / "started"
    long_run = {"exp1": ["--quick", "--trials", "1", "--episodes", "100000", "--plant.max-steps", "500"]}
    proc = start("exp1", out, 1, env={"LATENTRL_TEST_NATIVE_STARTED": str(started)}, runs=long_run)
    wait_for(started, proc)
    proc.send_signal(signal.SIGINT)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert "interrupted before any trial finished; nothing was written" in err
    assert not (out / "returns.npz").exists()


def test_resume_refuses_flags_and_foreign_directories(tmp_path):
    result = latentrl("run", "exp1", "--resume", str(tmp_path), "--trials", "3", "--quick")
    assert result.returncode == 2 and "drop --quick --trials" in result.stderr
    result = latentrl("run", "exp1", "--resume", str(tmp_path))
    assert result.returncode == 1 and "no results.json" in result.stderr
    (tmp_path / "results.json").write_text(json.dumps({"preset": {"name": "Exp2Preset", "trials": 1}}))
    result = latentrl("run", "exp1", "--resume", str(tmp_path))
    assert result.returncode == 1 and "holds a run of exp2, not of exp1" in result.stderr
    (tmp_path / "results.json").write_text(json.dumps({"preset": {"name": "Table1Preset"}}))
    result = latentrl("run", "exp1", "--resume", str(tmp_path))
    assert result.returncode == 1 and "names no RL experiment's preset (found 'Table1Preset')" in result.stderr
    (tmp_path / "results.json").write_text(json.dumps({"preset": {"name": "Exp1Preset", "trialz": 1}}))
    result = latentrl("run", "exp1", "--resume", str(tmp_path))
    assert result.returncode == 1 and "does not know: ['trialz']" in result.stderr
    # Issue #38: a results.json of the wrong structure, or nested past the parser, named as such.
    for payload, message in ((json.dumps({"preset": "Exp1Preset"}), "preset must be a JSON object, got str"),
                             (json.dumps({"setup": {"inputs": {"demos": 3}}}), "setup.inputs['demos'] must be"),
                             ("[" * 100_000 + "]" * 100_000, "nested too deeply")):
        (tmp_path / "results.json").write_text(payload)
        result = latentrl("run", "exp1", "--resume", str(tmp_path))
        assert result.returncode == 1 and f"{tmp_path / 'results.json'}: {message}" in result.stderr, result.stderr
        assert "Traceback" not in result.stderr


@pytest.mark.parametrize("model", ["gplvm", "pca"])
def test_fit_saves_the_model_a_fit_in_python_gives(tmp_path, model):
    from latentrl import GPLVM, PCA, Demonstrations, save_demos
    from latentrl.datasets import arm_postures

    postures = arm_postures(40, np.random.default_rng(0))
    names = ("left_shoulder", "left_elbow", "right_shoulder", "right_elbow")
    save_demos(Demonstrations(postures, names), tmp_path / "demos.csv")
    result = latentrl("fit", str(tmp_path / "demos.csv"), "--model", model, "--max-iter", "30",
                      "--out", str(tmp_path / "model.npz"))
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["joint_names"] == list(names) and summary["postures"] == 40
    if model == "gplvm":
        expected = GPLVM(n_components=2, max_iter=30, random_state=0).fit(postures)
        loaded = GPLVM.load(tmp_path / "model.npz")
        assert summary["nll"] == expected.nll_
    else:
        expected, loaded = PCA(n_components=2).fit(postures), PCA.load(tmp_path / "model.npz")
    assert list(loaded.feature_names_in_) == list(names)  # the demo file's columns: train refuses other joints
    with pytest.warns(UserWarning, match="fitted with feature names"):  # as scikit-learn, for unnamed postures
        np.testing.assert_array_equal(loaded.transform(postures), expected.transform(postures))


def test_fit_auto_chooses_the_dimension_and_names_bad_values(tmp_path):
    from latentrl import GPLVM, Demonstrations, save_demos
    from latentrl.datasets import arm_postures

    postures = arm_postures(40, np.random.default_rng(0))
    save_demos(Demonstrations(postures, ("a", "b", "c", "d")), tmp_path / "demos.csv")
    result = latentrl("fit", str(tmp_path / "demos.csv"), "--n-components", "auto", "--max-iter", "30",
                      "--out", str(tmp_path / "model.npz"))
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    expected = GPLVM(n_components="auto", max_iter=30, random_state=0).fit(postures)
    assert summary["fitted_n_components"] == expected.n_components_ == GPLVM.load(tmp_path / "model.npz").n_components_
    assert summary["relevance"] == expected.relevance_.tolist()
    bad = latentrl("fit", str(tmp_path / "demos.csv"), "--n-components", "two", "--out", str(tmp_path / "m.npz"))
    assert bad.returncode == 2 and "expected an integer or auto, got 'two'" in bad.stderr
    pca = latentrl("fit", str(tmp_path / "demos.csv"), "--model", "pca", "--n-components", "auto",
                   "--out", str(tmp_path / "m.npz"))
    assert pca.returncode == 1 and "only --model gplvm chooses its dimension" in pca.stderr
    assert not (tmp_path / "m.npz").exists()


@pytest.mark.parametrize(("flags", "outcome"), [
    (["--inducing", "8"], "fits"),
    (["--inducing", "0"], "inducing must be None"),
    (["--model", "pca", "--inducing", "8"], "--inducing: only --model gplvm"),
])
def test_fit_inducing_fits_the_sparse_gplvm(tmp_path, flags, outcome):
    from latentrl import GPLVM, Demonstrations, save_demos
    from latentrl.datasets import arm_postures

    save_demos(Demonstrations(arm_postures(60, np.random.default_rng(0)), tuple("abcd")), tmp_path / "d.csv")
    done = latentrl("fit", str(tmp_path / "d.csv"), *flags, "--max-iter", "30", "--out", str(tmp_path / "m.npz"))
    if outcome != "fits":
        assert done.returncode == 1 and outcome in done.stderr
        return
    assert done.returncode == 0 and json.loads(done.stdout)["inducing"] == 8, done.stderr
    assert GPLVM.load(tmp_path / "m.npz").inducing_.shape == (8, 2)


def test_fit_reports_bad_demonstration_files(tmp_path):
    result = latentrl("fit", str(tmp_path / "missing.csv"), "--out", str(tmp_path / "m.npz"))
    assert result.returncode == 1 and f"demos {tmp_path / 'missing.csv'}: no such file" in result.stderr
    (tmp_path / "two.csv").write_text("a,b,c\n0,1,2\n1,2,3\n")
    result = latentrl("fit", str(tmp_path / "two.csv"), "--out", str(tmp_path / "m.npz"))
    assert result.returncode == 1 and "2 postures, expected at least 3" in result.stderr
    assert not (tmp_path / "m.npz").exists()


def test_plot_redraws_the_finished_trials_of_a_partial_run(tmp_path):
    from latentrl.experiments.exp1 import Exp1Preset
    from latentrl.experiments import run_experiment
    from latentrl.run_settings import with_overrides
    from latentrl.results import finished_trials, write_npz
    from latentrl.experiments.run_folder import RunFolder

    run_experiment("exp1", with_overrides(Exp1Preset.quick(), {"trials": 2, "episodes": 5, "plant.max_steps": 20}),
             tmp_path / "run", progress=False)
    arrays = RunFolder(tmp_path / "run").arrays()
    arrays["full_end"][1] = -1  # as an interrupted run leaves it: full trial 2 not run
    arrays["full"][1] = np.nan
    write_npz(tmp_path / "run" / "returns.npz", arrays)
    kept, done = finished_trials(arrays)
    assert done == {"latent": 2, "full": 1}
    assert kept["latent"].shape == (2, 5) and kept["full"].shape == kept["full_end"].shape == (1, 5)
    np.testing.assert_array_equal(kept["full_steps"], arrays["full_steps"][:1])
    result = latentrl("plot", str(tmp_path / "run"), "--out", str(tmp_path / "figs"))
    assert result.returncode == 0, result.stderr
    assert "latent 2 of 2, full 1 of 2 trials" in result.stdout
    for fig in ("fig4a", "fig4b", "fig4c"):
        assert (tmp_path / "figs" / f"{fig}.png").stat().st_size > 1000
    result = latentrl("plot", str(tmp_path / "figs"))
    assert result.returncode == 1 and "no results.json" in result.stderr


def test_resume_names_what_is_wrong_with_returns_npz(tmp_path):
    """Issue #38's probe: a returns.npz without an array was a KeyError traceback, one of strings a
    TypeError traceback, one that is not a zip or of end codes 99 a message without the file."""
    out = tmp_path / "run"
    first = latentrl("run", "exp1", "--no-progress", *TINY_RUNS["exp1"], "--out", str(out))
    assert first.returncode == 0, first.stderr
    saved = dict(np.load(out / "returns.npz"))
    edits = {"latent_end missing": ({k: v for k, v in saved.items() if k != "latent_end"}, "latent_end is missing"),
             "strings": ({**saved, "latent": saved["latent"].astype(str)}, "latent holds <U"),
             "end code 99": ({**saved, "latent_end": np.full_like(saved["latent_end"], 99)},
                             "latent_end holds values other than end codes"),
             "not a zip": (None, "not a readable NPZ file")}
    for name, (arrays, message) in edits.items():
        if arrays is None:
            (out / "returns.npz").write_bytes(b"hello")
        else:
            np.savez(out / "returns.npz", **arrays)
        result = latentrl("run", "exp1", "--no-progress", "--resume", str(out))
        assert result.returncode == 1 and "Traceback" not in result.stderr, (name, result.stderr)
        assert f"{out / 'returns.npz'}: " in result.stderr and message in result.stderr, (name, result.stderr)


def test_a_missing_input_or_an_empty_path_is_named_before_any_work(tmp_path):
    """`--model nothere.npz` failed after reading the demos with a bare errno; `--out ''` (an
    unset variable) wrote the run into the current directory."""
    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    task, demos = str(example / "glass_arm.toml"), str(example / "demos.csv")
    result = latentrl("train", task, "--demos", demos, "--model", "nothere.npz", "--out", str(tmp_path / "run"))
    assert result.returncode == 1 and "--model nothere.npz: no such file or directory" in result.stderr, result.stderr
    result = latentrl("check", task, "--demos", "nothere.csv")
    assert result.returncode == 1 and "--demos nothere.csv: no such file or directory" in result.stderr, result.stderr
    result = latentrl("train", task, "--demos", demos, "--out", "")
    assert result.returncode == 2 and "argument --out: an empty path" in result.stderr, result.stderr


def test_a_costly_exact_fit_says_its_cost_first_in_one_line(tmp_path, monkeypatch, capsys):
    """The sweep's 5 000-row CSV fitted for minutes without a word: beyond `COSTLY_EXACT_FIT`
    postures the fit first says what an iteration costs and how to spend less, as a CLI warning."""
    from latentrl import gplvm

    monkeypatch.setattr(gplvm, "COSTLY_EXACT_FIT", 30)
    rng = np.random.default_rng(0)
    demos = tmp_path / "demos.csv"
    demos.write_text("a,b,c\n" + "\n".join(",".join(f"{v:.6f}" for v in row) for row in rng.uniform(-1, 1, (40, 3))))
    with warnings.catch_warnings():
        warnings.simplefilter("always")  # pytest's filter makes warnings errors; a user's shell does not
        assert main(["fit", str(demos), "--max-iter", "5", "--out", str(tmp_path / "m.npz")]) == 0
    err = capsys.readouterr().err
    warned = [line for line in err.splitlines() if "each iteration of an exact GPLVM fit costs" in line]
    assert len(warned) == 1 and warned[0].startswith("latentrl: warning: X: 40 postures:"), err
    assert "--max-postures 1000" in warned[0] and "--inducing 256" in warned[0]
    with pytest.warns(UserWarning, match="40 postures: each iteration"):
        gplvm.GPLVM(max_iter=2).fit(rng.uniform(-1, 1, (40, 3)))
    gplvm.GPLVM(max_iter=2).fit(rng.uniform(-1, 1, (30, 3)))  # at the bound: no warning (pytest's -W error)


def test_a_run_in_a_folder_named_in_latin1_finishes_and_reports(tmp_path):
    """`--out` in a folder whose name is not UTF-8 (b"lat\\xe9n", read as a surrogate) trained,
    then exited 1 before report.json: the policy's task label went to native code as text."""
    from latentrl import LatentPolicy, Task

    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    out = tmp_path / os.fsdecode(b"lat\xe9n") / "run"
    assert main(["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--out", str(out),
                 "--quick", "--trials", "1", "--episodes", "2", "--test-episodes", "1", "--episode.max-steps", "6",
                 "--no-progress"]) == 0
    assert (out / "report.json").is_file() and main(["report", str(out)]) == 0
    assert "lat\\udce9n" in LatentPolicy.load(out / "policy.npz").task.origin
    task = Task.from_dict(Task.load(example / "glass_arm.toml").to_dict(), example, origin=str(out))
    assert task.replace({"learner.alpha": 0.5}, origin=str(out)).origin == task.origin


def test_report_prints_the_verdict_train_saved_for_this_policy(tmp_path, capsys, monkeypatch):
    """`latentrl report DIR` made the check and the verdict's rollouts again (120–144 s on a real
    arm, no progress shown) where report.json already held them: it prints report.json where
    that was written for the policy.npz there now (its digest), and makes the verdict anew
    otherwise (a report of an earlier version, or of the policy before a resume)."""
    import latentrl.check

    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    out = tmp_path / "run"
    assert main(["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--out", str(out),
                 "--quick", "--trials", "1", "--episodes", "2", "--test-episodes", "1", "--episode.max-steps", "6",
                 "--no-progress"]) == 0
    trained = capsys.readouterr().out
    saved = json.loads((out / "report.json").read_text())

    def anew(*args, **kwargs):
        raise AssertionError("the verdict was made anew")

    monkeypatch.setattr(latentrl.check, "check_task", anew)
    assert main(["report", str(out)]) == 0
    printed = capsys.readouterr().out
    assert printed.startswith("verdict: ") and printed.strip() in trained
    assert main(["report", str(out), "--json"]) == 0
    assert json.loads(capsys.readouterr().out) == {k: saved[k] for k in saved if k not in ("policy_sha256", "environment")}
    (out / "report.json").write_text(json.dumps({**saved, "policy_sha256": "0" * 64}))
    with pytest.raises(AssertionError, match="made anew"):
        main(["report", str(out)])
