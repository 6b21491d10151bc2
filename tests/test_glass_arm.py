"""The README's "your robot" block (issue #15): a robot, demonstrations and a task file the
experiments never use train end to end from the CLI, learn (against the non-learning control on
the same trials), save a policy and roll it out; bad input to `train` is one line naming the
file, the key or the column, with nothing written."""

import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from latentrl import LatentPolicy, cli, load_demos

from learning import CONTROL_ALPHA, assert_separated

ROOT = Path(__file__).resolve().parents[1]
EXAMPLE = ROOT / "examples" / "glass_arm"


def commands() -> list[list[str]]:
    """The README's `latentrl …` lines between the robot markers."""
    block = re.search(r"<!-- robot:begin -->\n```sh\n(.*?)```\n<!-- robot:end -->", (ROOT / "README.md").read_text(), re.S)
    assert block is not None, "README lost its robot markers"
    return [shlex.split(line) for line in block.group(1).splitlines() if line.startswith("latentrl ")]


def latentrl(args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "latentrl", *args], capture_output=True, text=True, cwd=cwd,
                          timeout=600)


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """The README's commands with --out under a temporary folder, and the control's training."""
    out = tmp_path_factory.mktemp("glass")
    done = {}
    for name, extra in (("learner", []), ("control", ["--learner.alpha", str(CONTROL_ALPHA)])):
        for cmd in commands():
            args = [str(out / name / Path(a).relative_to("runs/glass_arm")) if a.startswith("runs/glass_arm") else a
                    for a in cmd[1:]]
            if args[0] == "train":
                args += ["--no-progress", *extra]
            result = latentrl(args)
            assert result.returncode == 0, result.stderr
        done[name] = out / name
    return done


def test_the_readme_commands_train_save_and_roll_out(runs):
    """Calibrated on 10 trials of --quick (AMD EPYC, the task's 1/120 s × 6, 3 × 4 physics): return of
    the last 50 training episodes 159–177 against the control's 9–20; frozen test episodes reaching
    the shelf 0.9–1.0 in nine trials and 0.2 in one (its tests stall short of the shelf), against
    the control's 0–0.4. So the tests are compared pooled over the run's trials: any two of the ten
    reach ≥ 0.55 together, any two of the control's ≤ 0.35.
    The rollout (20 episodes per trial from the task's test starts) is a learning test too: it
    runs the random control from the same starts. Measured on 2 trials of --quick: the trained
    policy reaches the shelf in 78 % (greedy) and 92 % (soft-max) of 40 episodes, the random
    control in 18 %; `train`'s verdict on it is "learnt", on the α = 1e-12 control's not."""
    late, tests = {}, {}
    for name, out in runs.items():
        with np.load(out / "returns.npz") as npz:
            late[name] = npz["latent"][:, -50:].mean(axis=1)
            tests[name] = npz["latent_test_reached"].mean()
    assert_separated(late["learner"], late["control"], 80.0, "return of the last 50 episodes")
    assert_separated(tests["learner"], tests["control"], 0.45, "frozen test episodes reaching the shelf, pooled")
    rollout = json.loads((runs["learner"] / "rollout" / "rollout.json").read_text())
    assert rollout["starts"] == "test" and rollout["softmax"]["reached_any_step"] >= 0.6
    assert rollout["random"]["reached_any_step"] <= 0.3, rollout["random"]
    for kind in ("greedy", "softmax", "random"):
        assert set(rollout[kind]["ends"]) == {"timeout", "obstacle", "box_exit", "drop", "fall", "variance_gate",
                                              "success"}
        assert sum(rollout[kind]["ends"].values()) == 2 * 20 and rollout[kind]["success"] is None
    with np.load(runs["learner"] / "rollout" / "rollout.npz") as npz:
        assert npz["greedy_returns"].shape == (2, 20) and npz["random_paths"].shape[-1] == 3 + 7 + 3
    report = json.loads((runs["learner"] / "report.json").read_text())
    assert report["verdict"] == "learnt" and report["next"] == []
    assert json.loads((runs["control"] / "report.json").read_text())["verdict"] != "learnt"
    assert (runs["learner"] / "failures.png").is_file()
    meta = json.loads((runs["learner"] / "results.json").read_text())
    assert meta["preset"]["name"] == "TrainRun" and meta["setup"]["task"]["name"] == "glass_arm"
    derived = {d["key"]: d["value"] for d in meta["setup"]["derived"]}
    assert derived == {"learner.initial_weight": pytest.approx(100.0), "learner.step": 0.5, "episode.stop_window": 100}
    assert meta["setup"]["task"]["learner"]["step"] == 0.5
    assert (runs["learner"] / "policy.npz").is_file() and (runs["learner"] / "returns.png").is_file()


def test_plot_redraws_a_train_runs_figures(runs, tmp_path):
    """Issue #38's probe: `latentrl plot` refused a train run ("names no RL experiment's preset")."""
    result = subprocess.run([sys.executable, "-m", "latentrl", "plot", str(runs["learner"]), "--out", str(tmp_path)],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert {"returns.png", "value_after.png", "failures.png"} <= {p.name for p in tmp_path.iterdir()}


def test_rollout_runs_the_policies_asked_for_and_a_success_rule_ends_episodes(runs, tmp_path):
    assert cli.main(["rollout", str(runs["learner"]), "--out", str(tmp_path), "--episodes", "3", "--policy",
                     "softmax", "--starts", "train", "--no-progress"]) == 0
    rollout = json.loads((tmp_path / "rollout.json").read_text())
    assert "greedy" not in rollout and rollout["starts"] == "train"
    assert sum(rollout["softmax"]["ends"].values()) == 2 * 3
    bad = latentrl(["rollout", str(runs["learner"]), "--out", str(tmp_path), "--policy", "best"])
    assert bad.returncode == 2 and "expected some of greedy, softmax, random, got 'best'" in bad.stderr


def test_a_success_rule_ends_an_episode_held_at_the_target(tmp_path):
    """`target.hold_steps`: an episode within the reach radius that many steps running ends as a
    success (code 6), not terminal; measured on 2 trials of --quick with 5 steps: 95 % greedy,
    100 % soft-max and 8 % random rollouts end as successes."""
    out = tmp_path / "hold"
    assert latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--out",
                     str(out), "--quick", "--no-progress", "--target.hold-steps", "5"]).returncode == 0
    with np.load(out / "returns.npz") as npz:
        ends, steps, reached = npz["latent_end"], npz["latent_steps"], npz["latent_reached"]
    assert (ends[:, -50:] == 6).mean() > 0.5 and (reached[ends == 6]).all() and (steps[ends == 6] >= 5).all()
    assert cli.main(["rollout", str(out), "--out", str(out / "rollout"), "--episodes", "10", "--no-progress"]) == 0
    rollout = json.loads((out / "rollout" / "rollout.json").read_text())
    assert rollout["softmax"]["success"] >= 0.6 and rollout["random"]["success"] <= 0.3, rollout
    assert rollout["softmax"]["success"] == rollout["softmax"]["ends"]["success"] / 20


def test_a_target_no_episode_reaches_gets_that_verdict_and_what_to_try(tmp_path):
    """A shelf 2 m below the arm (a list-valued task flag, too): "never reached it", and the
    check's target finding names a reachable target."""
    out = tmp_path / "far"
    result = latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--out",
                       str(out), "--quick", "--episodes", "20", "--no-progress", "--target.position",
                       "[[0.0, -2.0, 0.0]]"])
    assert result.returncode == 0, result.stderr
    assert "verdict: never reached it" in result.stdout and "target: target.position = " in result.stdout
    again = latentrl(["report", str(out), "--json"])
    assert again.returncode == 0 and json.loads(again.stdout)["verdict"] == "never reached it"
    assert latentrl(["report", str(tmp_path)]).returncode == 1


def test_a_finished_run_is_not_overwritten_and_resume_keeps_it(runs):
    train = next(c for c in commands() if c[1] == "train")[1:]
    out = str(runs["learner"])
    args = [out if a.startswith("runs/") else a for a in train] + ["--no-progress"]
    result = latentrl(args)
    assert result.returncode == 1 and "holds a run already: add --resume" in result.stderr
    before = (runs["learner"] / "returns.npz").read_bytes()
    assert latentrl([*args, "--resume"]).returncode == 0
    assert (runs["learner"] / "returns.npz").read_bytes() == before


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("max_angle = 0.3", "max_angle = 7.0"), r"glass_arm.toml: constraints\[0\].max_angle must lie in \(0, 3.14"),
        (('link = "glass"', 'link = "cup"'), r'constraints\[0\].link: unknown link "cup"; links are: base, upper'),
        (("[learner]", "[learner]\nalfa = 0.5"), r"learner.alfa \(line \d+\): unknown field `alfa`"),
    ],
)
def test_bad_task_files_are_one_line_and_write_nothing(tmp_path, edit, message):
    old, new = edit
    text = (EXAMPLE / "glass_arm.toml").read_text()
    assert old in text
    (tmp_path / "glass_arm.toml").write_text(text.replace(old, new))
    (tmp_path / "glass_arm.urdf").write_text((EXAMPLE / "glass_arm.urdf").read_text())
    result = latentrl(["train", str(tmp_path / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"),
                       "--out", str(tmp_path / "out")])
    assert result.returncode == 1 and re.search(message, result.stderr), result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out").exists()


def test_a_test_start_no_start_meets_fails_after_the_fit_and_leaves_nothing(tmp_path):
    """The test-start rule is tried before training; a new run that saved no trial left its
    gplvm.npz and .lock behind (session 13's sweep)."""
    out = tmp_path / "out"
    result = latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--quick",
                       "--trials", "1", "--episodes", "2", "--no-progress", "--out", str(out),
                       "--episode.test-start", "below_waypoint", "--waypoint.below", "-1000",
                       "--episode.max-start-draws", "100"])
    assert result.returncode == 1, result.stderr
    assert "no start of a frozen test episode in 100 draws, tried before training" in result.stderr, result.stderr
    assert "episode.test_start" in result.stderr and "Traceback" not in result.stderr
    assert not out.exists()


def test_demos_of_another_robot_are_refused_by_column(tmp_path):
    csv = tmp_path / "demos.csv"
    csv.write_text("shoulder,elbow,knee\n0.1,0.2,0.3\n0.2,0.3,0.4\n0.3,0.1,0.2\n")
    result = latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(csv), "--out", str(tmp_path / "out")])
    assert result.returncode == 1 and "missing ['wrist'], not joints of the robot ['knee']" in result.stderr
    assert not (tmp_path / "out").exists()
    result = latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(csv), "--out", str(tmp_path / "o"),
                       "--learner.gamma", "1.5"])
    assert result.returncode == 1 and "learner.gamma must lie in [0, 1), got 1.5" in result.stderr
    csv.write_text("shoulder,elbow,wrist\n" + "0.1,0.2,0.3\n" * 20)  # issue #38's probe: the file was not named
    result = latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(csv), "--out", str(tmp_path / "i")])
    assert result.returncode == 1 and f"{csv}: X: all 20 postures are identical" in result.stderr, result.stderr
    assert not (tmp_path / "i").exists()


def test_a_task_with_move_corrections_trains_draws_and_saves(tmp_path):
    out = tmp_path / "out"
    result = latentrl(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--out", str(out),
                       "--quick", "--trials", "1", "--episodes", "5", "--test-episodes", "1", "--no-progress",
                       "--learner.move-correction", "true"])
    assert result.returncode == 0, result.stderr
    assert (out / "value_before.png").is_file() and (out / "value_after.png").is_file()
    policy = LatentPolicy.load(out / "policy.npz")
    grid = policy.task.to_dict()["learner"]["rbf_per_dim"] ** 2
    assert policy.weights.shape == (1, grid * (1 + 8))  # V, then one correction per action


def test_the_failures_figure_shows_the_last_episodes_a_stopped_trial_ran(monkeypatch, tmp_path):
    """A trial the stopping rule ended after 500 of 1000 episodes: the figure's "last fifth" is
    of the 500 it ran (100, every one failed here), not of the budget's NaN tail."""
    from latentrl import plots
    from latentrl.experiments import training

    titles = []
    monkeypatch.setattr(plots, "latent_value_panel", lambda *args, **kwargs: None)
    monkeypatch.setattr(plots, "save_figure", lambda fig, out, name: titles.append(fig.axes[0].get_title()))
    budget, ran = 1000, 500
    ends = np.full((1, budget), -1, dtype=np.int8)
    ends[0, :ran] = 0  # timeouts
    means = np.full((1, budget, 2), np.nan)
    means[0, :ran] = 0.0
    arrays = {"latent": np.full((1, budget), np.nan), "latent_end": ends, "latent_reached": np.zeros((1, budget), bool),
              "latent_mean_state": means, "latent_weights": np.zeros((1, 4))}
    training.failures(arrays, "stopped", np.zeros(2), np.ones(2), None, {}, tmp_path)
    assert titles == ["stopped: the last 100 training episodes of trial 0: 100 never reached the target,\n"
                      "marked at each one's mean latent state by how it ended"]


def test_a_stopped_trial_is_summarised_over_the_episodes_it_ran():
    """results.json's per-trial summary of a trial the stopping rule ended after 400 of 1000
    episodes: its last tenth is of the 400 (the zoo's iiwa-style arm had `mean_return_last` NaN
    and `reached_last` 0 from the budget's unset tail)."""
    from latentrl.results import summarise_trial

    budget, ran = 1000, 400
    ends = np.full((1, budget), -1, dtype=np.int8)
    ends[0, :ran] = 0
    returns = np.full((1, budget), np.nan)
    returns[0, :ran] = np.arange(ran)
    reached = np.zeros((1, budget), bool)
    reached[0, ran - 20:ran] = True
    arrays = {"latent": returns, "latent_end": ends, "latent_reached": reached, "latent_passed": reached}
    summary = summarise_trial(arrays, "latent", 0)
    assert summary["window"] == 40 and summary["ends"]["timeout"] == ran
    assert summary["mean_return_first"] == pytest.approx(19.5) and summary["mean_return_last"] == pytest.approx(379.5)
    assert summary["reached_last"] == pytest.approx(0.5) and summary["passed_last"] == pytest.approx(0.5)


def test_a_run_reads_back_under_a_version_with_a_new_model_parameter(runs, monkeypatch):
    """Issue #38: a run's GPLVM is identified by the arrays its gplvm.npz holds, not by how this
    version would write them: a parameter added since (here `future`, None) is not a changed
    model (the sparse GPLVM's `inducing` made every earlier train run "changed since the run")."""
    from latentrl import GPLVM
    from latentrl.results import read_results
    from latentrl.experiments.training import TrainRun, prepared

    out = runs["learner"]
    fields = dict(read_results(out / "results.json")["preset"])
    fields.pop("name")
    get_params = GPLVM.get_params
    monkeypatch.setattr(GPLVM, "get_params", lambda self, deep=True: {**get_params(self, deep), "future": None})
    prepared(TrainRun(**fields), out)  # raised "its model changed since the run"


def test_a_disk_that_fills_at_the_figures_keeps_the_policy(monkeypatch, tmp_path):
    """The policy was written after the figures: a full disk there left a run whose trials were
    saved but had no policy.npz (`report` and `rollout` refused it) while the message offered
    `latentrl plot`, which does not write one."""
    import errno

    import latentrl.plots
    from latentrl.experiments.training import TrainRun, run_training

    def full(*args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(latentrl.plots, "save_figure", full)
    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), trials=1, episodes=3,
                   test_episodes=1, task={"episode.max_steps": 10})
    with pytest.raises(OSError, match="draws its figures again"):
        run_training(run, tmp_path / "out", progress=False)
    assert LatentPolicy.load(tmp_path / "out" / "policy.npz").weights.shape[0] == 1


def test_plot_interrupted_between_figures_does_not_say_nothing_was_written(monkeypatch, tmp_path, capsys):
    """Ctrl-C during `latentrl plot` after its first figure said "interrupted; nothing was
    written" while returns.png was new."""
    import latentrl.plots
    from latentrl.experiments.training import TrainRun, run_training

    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), trials=1, episodes=3,
                   test_episodes=1, task={"episode.max_steps": 10})
    run_training(run, tmp_path / "out", progress=False)
    save_figure, saved = latentrl.plots.save_figure, []

    def then_ctrl_c(fig, out, name):
        if saved:
            raise KeyboardInterrupt
        saved.append(name)
        save_figure(fig, out, name)

    monkeypatch.setattr(latentrl.plots, "save_figure", then_ctrl_c)
    assert cli.main(["plot", str(tmp_path / "out"), "--out", str(tmp_path / "figs")]) == 130
    err = capsys.readouterr().err
    assert "nothing was written" not in err and f"the figures drawn so far are in {tmp_path / 'figs'}" in err, err
    assert {p.name for p in (tmp_path / "figs").iterdir()} == {"returns.png", "returns.pdf"}


def test_a_rollout_cut_between_its_two_files_leaves_no_stale_summary(monkeypatch, tmp_path, capsys):
    """A second `latentrl rollout` into the same --out killed between rollout.npz and rollout.json
    left the first rollout's summary beside the second's episodes (replay showed them as the
    first's); now no summary is left, which replay refuses by name."""
    import latentrl.results
    from latentrl.experiments.training import TrainRun, run_training

    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), trials=1, episodes=3,
                   test_episodes=1, task={"episode.max_steps": 10})
    run_training(run, tmp_path / "run", progress=False)
    rollout = ["rollout", str(tmp_path / "run"), "--episodes", "2", "--out", str(tmp_path / "ro"), "--no-progress"]
    assert cli.main(rollout) == 0

    def killed(path, value):
        raise KeyboardInterrupt

    monkeypatch.setattr(latentrl.results, "write_json", killed)
    assert cli.main([*rollout, "--seed", "7"]) == 130
    assert not (tmp_path / "ro" / "rollout.json").exists()


def test_a_given_model_encodes_with_the_runs_encoder(tmp_path):
    """`train --model M --encoder tracking` recorded "tracking" and ran M's own "gp" encoder; a
    back-constrained encoder, which is another fit, is refused naming the flag and the file, and a
    back-constrained fit runs projection and tracking but is not a "gp" one."""
    from latentrl import GPLVM
    from latentrl.experiments.training import TrainRun, fitted

    demos = load_demos(EXAMPLE / "demos.csv").postures
    GPLVM(n_components=2, random_state=0, max_iter=50).fit(demos).save(tmp_path / "m.npz")
    given = dict(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), model=str(tmp_path / "m.npz"))
    for encoder in ("tracking", "projection", "gp"):
        assert fitted(TrainRun(**given, encoder=encoder))[2].encoder == encoder
    with pytest.raises(ValueError, match=r"--encoder back_constrained: .*m\.npz was fitted with the 'gp' encoder"):
        fitted(TrainRun(**given, encoder="back_constrained"))
    GPLVM(n_components=2, random_state=0, max_iter=50, encoder="back_constrained").fit(demos).save(tmp_path / "b.npz")
    given["model"] = str(tmp_path / "b.npz")
    assert fitted(TrainRun(**given, encoder="tracking"))[2].encoder == "tracking"
    with pytest.raises(ValueError, match=r"--encoder gp: .*b\.npz was fitted with the 'back_constrained' encoder"):
        fitted(TrainRun(**given, encoder="gp"))


def test_a_given_model_refuses_the_flags_of_a_fit_it_skips(tmp_path):
    """`train --model M --gplvm-max-iter 5` recorded 5 and ran M as fitted, as the API did before
    it refused them (session 14's second sweep)."""
    from latentrl import GPLVM

    GPLVM(n_components=2, random_state=0, max_iter=50).fit(load_demos(EXAMPLE / "demos.csv").postures).save(
        tmp_path / "m.npz")
    base = ["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--model",
            str(tmp_path / "m.npz"), "--quick", "--out", str(tmp_path / "out")]
    for flag, value in (("--gplvm-max-iter", "5"), ("--latent-spacing", "even")):
        result = latentrl([*base, flag, value])
        assert result.returncode == 1 and f"{flag}: a setting of the GPLVM fit, which --model" in result.stderr, \
            result.stderr
    assert not (tmp_path / "out").exists()


def test_a_model_of_other_joints_or_order_is_refused_naming_both(tmp_path, capsys):
    """A model file kept no joint names: one fitted to the glass arm's columns reordered (wrist,
    shoulder, elbow) trained without a word and learnt nothing (session 14's sweep, 0 % reached),
    and `check` advised on the scrambled space. `latentrl fit` now records the demo file's columns,
    a DataFrame's fit its columns; train, check, the API and a policy refuse other joints or another
    order by name. A model without names (fitted to an array, or saved before) is taken as before."""
    import pandas as pd

    from latentrl import GPLVM, Task, train_latent_policy
    from latentrl.check import check
    from latentrl.experiments.training import TrainRun, fitted

    demos = load_demos(EXAMPLE / "demos.csv")
    joints = ["shoulder", "elbow", "wrist"]
    assert list(demos.joint_names) == joints
    order = [2, 0, 1]
    csv = tmp_path / "reordered.csv"
    np.savetxt(csv, demos.postures[:, order], delimiter=",", header="wrist,shoulder,elbow", comments="")
    assert cli.main(["fit", str(csv), "--max-iter", "20", "--out", str(tmp_path / "m.npz")]) == 0
    assert list(GPLVM.load(tmp_path / "m.npz").feature_names_in_) == ["wrist", "shoulder", "elbow"]
    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"),
                   model=str(tmp_path / "m.npz"))
    in_order = (r"m\.npz: fitted to the task's joints in another order, \['wrist', 'shoulder', 'elbow'\]; "
                r"the task's joints are \['shoulder', 'elbow', 'wrist'\]")
    with pytest.raises(ValueError, match=in_order):
        fitted(run)
    capsys.readouterr()
    assert cli.main(["check", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"),
                     "--model", str(tmp_path / "m.npz")]) == 1
    assert re.search(in_order, capsys.readouterr().err)

    task = Task.load(EXAMPLE / "glass_arm.toml")
    frame = pd.DataFrame(demos.postures[:, order], columns=["wrist", "shoulder", "elbow"])
    model = GPLVM(max_iter=20, random_state=0).fit(frame)
    for call in (lambda: check(task, demos.postures, model), lambda: train_latent_policy(model, task, trials=1)):
        with pytest.raises(ValueError, match=r"model.*in another order, \['wrist', 'shoulder', 'elbow'\]"):
            call()
    with pytest.raises(ValueError, match="model: fitted to the task's joints in another order"):
        LatentPolicy(task=task, model=model, demos=demos.postures, latent_low=np.zeros(2), latent_high=np.ones(2),
                     weights=np.zeros((1, 400)))
    other = GPLVM(max_iter=20, random_state=0).fit(frame.set_axis(["wrist", "shoulder", "knee"], axis=1))
    with pytest.raises(ValueError, match=r"fitted to 3 joints \['wrist', 'shoulder', 'knee'\], not to the task's "
                                         r"3 joints \['shoulder', 'elbow', 'wrist'\]"):
        check(task, demos.postures, other)
    named = GPLVM(max_iter=20, random_state=0).fit(pd.DataFrame(demos.postures, columns=joints))
    plain = GPLVM(max_iter=20, random_state=0).fit(demos.postures)
    for ok in (named, plain):
        assert check(task, demos.postures, ok).verdict


def test_the_model_a_run_fits_names_its_task_joints(tmp_path, capsys):
    """The GPLVM `train` fits recorded no joint names, so its model.npz was taken for any task
    with as many joints; it now names the task's, and another task's run refuses it by name."""
    from latentrl import GPLVM
    from latentrl.experiments.training import TrainRun, fitted

    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), gplvm_max_iter=20)
    _, _, model = fitted(run)
    assert list(model.feature_names_in_) == ["shoulder", "elbow", "wrist"]
    model.save(tmp_path / "m.npz")
    renamed = GPLVM.load(tmp_path / "m.npz")
    renamed.feature_names_in_ = np.array(["a", "b", "c"], dtype=object)
    renamed.save(tmp_path / "other.npz")
    assert cli.main(["check", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"),
                     "--model", str(tmp_path / "other.npz")]) == 1
    assert re.search(r"other\.npz: fitted to 3 joints \['a', 'b', 'c'\], not to the task's 3 joints", capsys.readouterr().err)


def test_rollout_and_report_of_a_run_stopped_before_its_policy_name_the_command_that_finishes_it(tmp_path, capsys):
    """A train stopped by Ctrl-C after a trial was saved holds results.json but no policy.npz:
    `rollout` said "[Errno 2] No such file or directory: 'half/policy.npz'" and `report` "no
    policy.npz there (a directory of latentrl train)" (session 14's sweep). Both now name the
    stopped run and the `latentrl train … --resume` command that finishes it, which does."""
    from latentrl.experiments.training import TrainRun, run_training

    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), trials=1, episodes=3,
                   test_episodes=1, task={"episode.max_steps": 10})
    out = tmp_path / "half"
    run_training(run, out, progress=False)
    (out / "policy.npz").unlink()
    capsys.readouterr()
    errors = []
    for command in (["rollout", str(out), "--out", str(tmp_path / "ro"), "--no-progress"], ["report", str(out)]):
        assert cli.main(command) == 1
        errors.append(capsys.readouterr().err)
    assert errors[0] == errors[1], errors
    said = re.search(r"a run of latentrl train stopped before its policy.npz was written \(1 of 1 trials saved\); "
                     r"finish it with: latentrl (train .*--resume.*)", errors[0])
    assert said is not None, errors[0]
    assert "--episode.max-steps 10" in said.group(1) and "--episodes 3" in said.group(1)
    assert cli.main([*shlex.split(said.group(1)), "--no-progress"]) == 0
    assert (out / "policy.npz").is_file()


def test_a_rollout_into_its_run_folder_is_refused(tmp_path, capsys):
    """`rollout RUN --out RUN` wrote rollout.json beside results.json; `replay RUN --episode 0` then
    drew a rollout episode as the run's training episode 0 and `--test 0` was refused (session 14's
    sweep). A rollout's --out that holds a run is refused, naming a folder of its own."""
    from latentrl.experiments.training import TrainRun, run_training

    run = TrainRun(task_file=str(EXAMPLE / "glass_arm.toml"), demos=str(EXAMPLE / "demos.csv"), trials=1, episodes=3,
                   test_episodes=1, task={"episode.max_steps": 10})
    run_training(run, tmp_path / "run", progress=False)
    capsys.readouterr()
    for results in (tmp_path / "run", tmp_path / "run" / "policy.npz"):
        assert cli.main(["rollout", str(results), "--out", str(tmp_path / "run"), "--episodes", "1",
                         "--no-progress"]) == 1
        err = capsys.readouterr().err
        assert f"--out {tmp_path / 'run'}: holds a run (results.json)" in err, err
        assert f"--out {tmp_path / 'run' / 'rollout'}" in err
    assert not (tmp_path / "run" / "rollout.json").exists()
