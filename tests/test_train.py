"""`latentrl.train`: the README tutorial as written, the humanoid task, bad input."""

from __future__ import annotations

import json
import re
import signal
import time
from pathlib import Path

import numpy as np
import pytest
from latentrl import GPLVM, PCA, LatentPolicy, Task, _native, _reference
from latentrl.cli import build_parser
from latentrl.cli_commands import _training_run
from latentrl.datasets import arm_postures
from latentrl import train_latent_policy
from latentrl.run_settings import latent_box
from latentrl.task import task_digest

README = Path(__file__).resolve().parents[1] / "README.md"


def tutorial() -> str:
    """The README's tutorial code block."""
    block = re.search(r"<!-- tutorial:begin -->\n```python\n(.*?)```\n<!-- tutorial:end -->", README.read_text(), re.S)
    assert block is not None, "README lost its tutorial markers"
    return block.group(1)


def test_readme_tutorial_learns(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    scope: dict[str, object] = {}
    exec(compile(tutorial(), "README tutorial", "exec"), scope)
    # the progress bar counts 2 trials × (150 training + 50 frozen test episodes)
    assert "400/400" in capsys.readouterr().err
    policy = scope["policy"]
    early, late = policy.returns[:, :25].mean(), policy.returns[:, -25:].mean()  # type: ignore[attr-defined]
    assert late > 2 * early, (early, late)
    assert policy.reached[:, -25:].mean() > 0.5  # type: ignore[attr-defined]
    assert policy.test_returns.shape == (2, 50) and policy.test_reached.mean() > 0.5  # type: ignore[attr-defined]
    assert scope["values"].shape == (123,)  # type: ignore[attr-defined]
    assert (tmp_path / "postures.csv").is_file()
    assert scope["target"].shape == (4,) and np.isfinite(scope["target"]).all()  # type: ignore[attr-defined]


@pytest.fixture(scope="module")
def arms_model() -> GPLVM:
    return GPLVM(n_components=2, max_iter=50, random_state=0).fit(arm_postures(40, np.random.default_rng(1)))


def test_ctrl_c_stops_training_inside_its_start_draws(arms_model: GPLVM) -> None:
    """Issue #38: Ctrl-C is read before every start draw and step, not between episodes: a test
    episode whose every start is refused, allowed 10⁹ draws (≈ 2 h here), stops within seconds
    of the signal (SIGALRM raising KeyboardInterrupt, as Ctrl-C does, half a second in). A step
    inside a long episode: `latent_core`'s trials test."""

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    previous = signal.signal(signal.SIGALRM, interrupt)
    signal.setitimer(signal.ITIMER_REAL, 0.5)
    began = time.monotonic()
    try:
        with pytest.raises(KeyboardInterrupt):
            train_latent_policy(arms_model, trials=1, episodes=1, test_episodes=1, overrides={
                "episode.max_start_draws": 10**9, "episode.test_start": "below_waypoint", "waypoint.below": -1000.0})
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)
    assert time.monotonic() - began < 30  # a hang guard, not a speed bound: the draws take hours


def test_same_seed_same_policy_and_value_matches_weights(arms_model: GPLVM) -> None:
    runs = [train_latent_policy(arms_model, trials=2, episodes=3, overrides={"episode.max_steps": 50}, test_episodes=0, seed=s)
            for s in (4, 4, 5)]
    np.testing.assert_array_equal(runs[0].returns, runs[1].returns)
    np.testing.assert_array_equal(runs[0].weights, runs[1].weights)
    assert not np.array_equal(runs[0].returns, runs[2].returns)
    assert runs[0].returns.shape == runs[0].ends.shape == (2, 3)
    assert runs[0].test_returns.shape == runs[0].test_reached.shape == (2, 0)
    assert sum(runs[0].end_counts().values()) == 6
    policy = runs[0]
    assert policy.value(arms_model.Z_, trial=1).shape == (40,)
    with pytest.raises(ValueError, match=r"z must have shape \(M, 2\)"):
        policy.value(np.zeros(2))
    with pytest.raises(ValueError, match=r"trial must be an int in 0..1"):
        policy.value(arms_model.Z_, trial=2)
    np.testing.assert_allclose(
        policy.value(arms_model.Z_, trial=1),
        _reference.value_function(policy.weights[1], policy.latent_low, policy.latent_high, arms_model.Z_),
        rtol=1e-12, atol=1e-12,
    )


def test_a_trial_is_the_same_however_many_trials_run(arms_model: GPLVM) -> None:
    """`TrainPreset.trials` is 2 because trial 0, the one `act` uses, is the same bits with 4:
    more trials only add others beside it."""
    two, four = (train_latent_policy(arms_model, trials=n, episodes=4, overrides={"episode.max_steps": 30},
                                     test_episodes=1, seed=3) for n in (2, 4))
    np.testing.assert_array_equal(two.weights, four.weights[:2])
    np.testing.assert_array_equal(two.returns, four.returns[:2])
    np.testing.assert_array_equal(two.test_returns, four.test_returns[:2])


@pytest.mark.parametrize("move_correction", [False, True])
def test_a_saved_policy_loads_acts_and_rolls_out_the_same(arms_model: GPLVM, tmp_path: Path, move_correction: bool) -> None:
    overrides = {"episode.max_steps": 30, "learner.move_correction": move_correction}
    policy = train_latent_policy(arms_model, trials=2, episodes=5, overrides=overrides, test_episodes=0)
    # V's weights over the 20 × 20 grid, then with corrections one block per action (8).
    assert policy.weights.shape == (2, 400 * (9 if move_correction else 1))
    assert policy.value(arms_model.Z_).shape == (40,)
    policy.save(tmp_path / "policy.npz")
    loaded = LatentPolicy.load(tmp_path / "policy.npz")
    np.testing.assert_array_equal(loaded.weights, policy.weights)
    np.testing.assert_array_equal(loaded.returns, policy.returns)
    posture = arms_model.X_train_[3]
    np.testing.assert_array_equal(loaded.act(posture, trial=1), policy.act(posture, trial=1))
    once, again = policy.rollout(4, seed=2), loaded.rollout(4, seed=2)
    np.testing.assert_array_equal(once["returns"], again["returns"])
    assert once["returns"].shape == (2, 4) and 0.0 <= once["summary"]["reached_any_step"] <= 1.0
    assert once["summary"]["success"] is None  # the task has no success rule (target.hold_steps = 0)
    assert sum(once["summary"]["ends"].values()) == 8
    drawn = [loaded.rollout(4, seed=s, policy="softmax") for s in (2, 2, 3)]
    np.testing.assert_array_equal(drawn[0]["returns"], drawn[1]["returns"])
    assert drawn[0]["returns"].shape == (2, 4) and not np.array_equal(drawn[0]["returns"], once["returns"])
    assert drawn[0]["paths"].shape[:2] == once["paths"].shape[:2] == (2, 4)
    assert not np.array_equal(drawn[0]["returns"], drawn[2]["returns"])
    # Every trial in one run, side by side, is each trial run alone (its own weights and seeds).
    alone = [loaded.rollout(4, seed=2, trial=t) for t in (0, 1)]
    for key in ("returns", "ends", "reached", "paths"):
        np.testing.assert_array_equal(once[key], np.concatenate([a[key] for a in alone]))
    # The greedy step: act() moves the encoded posture by one action and decodes it.
    target = policy.act(posture)
    assert target.shape == (4,) and np.isfinite(target).all()
    with pytest.raises(ValueError, match=r"posture: expected the 4 finite joint positions .*got shape \(3,\)"):
        policy.act(posture[:3])
    with pytest.raises(ValueError, match=r"got shape \(2, 4\)"):  # said "dimensionality mismatch: from=2, to=1"
        policy.act(np.stack([posture, posture]))
    with pytest.raises(ValueError, match=r"got shape \(4,\) with NaN or inf"):
        policy.act(np.where(np.arange(4) == 1, np.nan, posture))


def test_rollouts_start_where_the_tests_start_and_share_their_starts(arms_model: GPLVM) -> None:
    """Issue #41: `rollout` draws its starts as the task's frozen tests do (Exp 2's: both hands
    below the wall, `episode.test_start = "below_waypoint"`), or with starts="train" as its
    training episodes; greedy, soft-max and the random control meet the same starts."""
    policy = train_latent_policy(arms_model, trials=1, episodes=2, overrides={"episode.max_steps": 5}, test_episodes=0)
    below = policy.task.to_dict()["waypoint"]["below"]
    hands_y = policy.task.row_slices()["effectors"]

    def start_heights(**kwargs: str) -> np.ndarray:
        paths = policy.rollout(20, seed=1, **kwargs)["paths"][0]
        return paths[:, 0, hands_y].reshape(20, -1, 3)[:, :, 1]

    tested = start_heights()
    assert (tested < below).all()
    assert (start_heights(starts="train") >= below).any()
    for kind in ("softmax", "random"):
        np.testing.assert_array_equal(start_heights(policy=kind), tested)
    with pytest.raises(ValueError, match=r"policy must be one of \['greedy', 'softmax', 'random'\], got 'best'"):
        policy.rollout(1, policy="best")
    with pytest.raises(ValueError, match="starts must be 'test' or 'train'"):
        policy.rollout(1, starts="demo")
    for seed in (-1, 2**64, 1.5, True):  # named as the caller wrote it, not as the binding's base_seed
        with pytest.raises(ValueError, match=r"seed must be an int in 0\.\.2\*\*64 - 1, got "):
            policy.rollout(1, seed=seed)


def test_a_rollout_takes_one_row_of_weights_or_one_per_trial(arms_model: GPLVM) -> None:
    policy = train_latent_policy(arms_model, trials=2, episodes=2, overrides={"episode.max_steps": 5}, test_episodes=0)
    run = dict(decoder=arms_model.decoder_, encoder=arms_model.loop_encoder_, latent_low=policy.latent_low,
               latent_high=policy.latent_high, n_trials=2, episodes=2, base_seed=0, rollout="greedy")
    with pytest.raises(_native.InvalidInputError, match=r"weights: expected shape one row, or one per trial \(2\), got 3 rows"):
        _native.run_task_trials(policy.task._native, weights=np.vstack([policy.weights] * 2)[:3], **run)
    with pytest.raises(TypeError, match="weights"):
        _native.run_task_trials(policy.task._native, weights=np.zeros(400), **run)


def test_a_policy_file_is_checked(arms_model: GPLVM, tmp_path: Path) -> None:
    policy = train_latent_policy(arms_model, trials=1, episodes=2, overrides={"episode.max_steps": 10}, test_episodes=0)
    policy.save(tmp_path / "policy.npz")
    arms_model.save(tmp_path / "model.npz")
    with pytest.raises(ValueError, match="holds latentrl.GPLVM, expected latentrl.LatentPolicy"):
        LatentPolicy.load(tmp_path / "model.npz")
    (tmp_path / "junk.npz").write_bytes(b"not a zip")
    with pytest.raises(ValueError, match="junk.npz"):
        LatentPolicy.load(tmp_path / "junk.npz")
    arrays = dict(np.load(tmp_path / "policy.npz"))
    arrays["task"] = np.array(str(arrays["task"]).replace('"beta": 20.0', '"beta": 5.0'))
    np.savez(tmp_path / "edited.npz", **arrays)
    with pytest.raises(ValueError, match="its task .* changed since it was saved"):
        LatentPolicy.load(tmp_path / "edited.npz")
    # Saved before the schema had learner.move_correction: loads with the key at its default.
    older = json.loads(str(arrays["task"]))
    del older["learner"]["move_correction"]
    np.savez(tmp_path / "older.npz", **{**arrays, "task": np.array(json.dumps(older)),
                                        "task_digest": np.array(task_digest(older, policy.task.urdf_path))})
    assert LatentPolicy.load(tmp_path / "older.npz").task.to_dict()["learner"]["move_correction"] is False
    np.savez(tmp_path / "older_digest.npz", **{**arrays, "task": np.array(json.dumps(older))})
    with pytest.raises(ValueError, match="its task .* changed since it was saved"):
        LatentPolicy.load(tmp_path / "older_digest.npz")
    # Issue #38: a newer format, weights or a record of the wrong shape, NaN demos: refused, naming the file.
    edits = {"format_version": np.array(99), "weights": arrays["weights"][..., :3],
             "demos": np.full_like(arrays["demos"], np.nan), "record.returns": arrays["record.returns"].ravel()}
    for key, value in edits.items():
        np.savez(tmp_path / f"{key}.npz", **{**dict(np.load(tmp_path / "policy.npz")), key: value})
        with pytest.raises(ValueError, match=rf"^{re.escape(str(tmp_path / key))}\.npz: .*(99|weights|demos|record)"):
            LatentPolicy.load(tmp_path / f"{key}.npz")


def test_humanoid_task_runs() -> None:
    from latentrl.experiments.exp3 import Exp3Preset, fit

    model = fit(Exp3Preset.quick()).model
    policy = train_latent_policy(model, "humanoid_lift", trials=1, episodes=2, overrides={"episode.max_steps": 10},
                                 test_episodes=0)
    assert policy.returns.shape == (1, 2)
    assert np.isfinite(policy.returns).all()
    assert policy.weights.shape == (1, 400 * (1 + 8))  # V, then the task's move corrections
    few = GPLVM(n_components=2, max_iter=20, random_state=0).fit(model.X_train_[:5])
    with pytest.raises(ValueError, match="episode.start_demo = 6 is not a row of the 5 demonstrations"):
        train_latent_policy(few, "humanoid_lift", encoder="gp", overrides={"episode.start_demo": 6})


def test_a_task_of_ones_own_trains(arms_model: GPLVM) -> None:
    task = Task.from_dict({**Task.shipped("two_arms").to_dict(), "name": "mine"}, Task.shipped("two_arms").base_dir)
    policy = train_latent_policy(arms_model, task, trials=1, episodes=3, overrides={"episode.max_steps": 20}, test_episodes=1)
    assert policy.task.name == "mine" and policy.returns.shape == (1, 3) and policy.test_returns.shape == (1, 1)


def test_the_runs_encoder_maps_the_loop_as_latentrl_train_runs_it(arms_model: GPLVM) -> None:
    """The run's encoder (a keyword, else the preset's: "tracking" for a Task) maps the loop's
    states, as `latentrl train --model` runs it; the model given keeps its own, and the preset
    records what ran (the encoder, the model's fit settings). It was recorded and not used."""
    table = {key: value for key, value in Task.shipped("two_arms").to_dict().items() if key != "run"}
    task = Task.from_dict({**table, "name": "mine"}, Task.shipped("two_arms").base_dir)
    runs = {encoder: train_latent_policy(arms_model, task, trials=1, episodes=3, test_episodes=0, seed=2,
                                         overrides={"episode.max_steps": 30}, **({"encoder": encoder} if encoder else {}))
            for encoder in ("", "tracking", "gp")}
    assert runs[""].model.encoder == runs[""].preset.encoder == "tracking" and arms_model.encoder == "gp"
    np.testing.assert_array_equal(runs[""].returns, runs["tracking"].returns)
    assert not np.array_equal(runs["gp"].returns, runs["tracking"].returns)
    assert (runs["gp"].preset.encoder, runs["gp"].preset.gplvm_max_iter, runs["gp"].preset.latent_spacing) == ("gp", 50, "fit")


def test_a_task_files_run_table_sets_the_run_and_arguments_and_flags_win(arms_model: GPLVM, tmp_path: Path) -> None:
    """`[run]` replaces the paper preset's run settings; an API argument or a flag replaces it."""
    shipped = Task.shipped("two_arms")
    text = (shipped.base_dir / "two_arms.toml").read_text().replace('urdf = "../data/', f'urdf = "{shipped.urdf_path.parent}/')
    path = tmp_path / "arms.toml"
    path.write_text(text + "\n[run]\ntrials = 1\nepisodes = 3\ntest_episodes = 0\nlatent_margin = 0.2\n")
    task = Task.load(path)
    policy = train_latent_policy(arms_model, task, preset="paper", episodes=2, overrides={"episode.max_steps": 20})
    assert policy.returns.shape == (1, 2) and policy.test_returns.shape == (1, 0)
    assert np.allclose(policy.latent_low, latent_box(arms_model.Z_, 0.2)[0])
    args = build_parser().parse_args(["train", str(path), "--demos", "demos.csv", "--out", str(tmp_path / "out"),
                                      "--episodes", "5", "--encoder", "gp"])
    run = _training_run(args, {})
    assert (run.trials, run.episodes, run.latent_margin, run.encoder, run.gplvm_max_iter) == (1, 5, 0.2, "gp", 10000)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"task": "walk"}, ValueError, "task must be a Task or one of"),
        ({"task": 3}, TypeError, "task must be a latentrl.Task"),
        ({"preset": "huge"}, ValueError, "preset must be 'quick' or 'paper'"),
        ({"episodes_per_trial": 3}, ValueError, "unknown preset fields"),
        ({"episodes": 0}, ValueError, r"run.episodes must be an integer in \[1, 100000000\], got 0"),
        ({"task": "humanoid_lift"}, ValueError, r"model for humanoid_lift: fitted to 4 joints.*not to the task's 19 joints"),
        ({"overrides": {"learner.alpha": 2.0}}, ValueError, r"learner.alpha must lie in \(0, 1\], got 2"),
        ({"encoder": "back_constrained"}, ValueError, r"encoder='back_constrained': the model was fitted with the 'gp' "
                                                      r"encoder, which is another fit.*give encoder='gp', 'projection'"),
        ({"gplvm_max_iter": 5}, ValueError, r"^gplvm_max_iter: settings of the GPLVM fit"),
        ({"overrides": {"run.latent_spacing": "even"}}, ValueError, r"^run.latent_spacing: settings of the GPLVM fit"),
    ],
)
def test_bad_arguments(arms_model: GPLVM, kwargs: dict[str, object], error: type, message: str) -> None:
    with pytest.raises(error, match=message):
        train_latent_policy(arms_model, **kwargs)  # type: ignore[arg-type]


def test_bad_models() -> None:
    X = arm_postures(40, np.random.default_rng(1))
    with pytest.raises(TypeError, match="fitted latentrl.GPLVM"):
        train_latent_policy(PCA(n_components=2).fit(X))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="fitted latentrl.GPLVM"):
        train_latent_policy(GPLVM())
    three = GPLVM(n_components=3, max_iter=5).fit(X)
    policy = train_latent_policy(three, trials=1, episodes=2, overrides={"episode.max_steps": 5}, test_episodes=0)
    assert policy.weights.shape == (1, 20**3), "a 3-D latent space: a 20³ grid"


def test_a_trial_that_stopped_improving_stops_and_is_read_as_it_ran(arms_model: GPLVM) -> None:
    """Issue #37: under `episode.stop_window` a trial ends once it stopped improving; its arrays
    hold NaN returns and end −1 after; end counts and the verdict count the episodes it ran."""
    from latentrl.verdict import training_verdict

    task = Task.from_dict({**Task.shipped("two_arms").to_dict(), "name": "mine"}, Task.shipped("two_arms").base_dir)
    policy = train_latent_policy(arms_model, task, trials=2, episodes=400, test_episodes=1,
                                 overrides={"episode.max_steps": 10, "episode.stop_window": 10,
                                            "episode.stop_patience": 1})
    ran = (policy.record["ends"] >= 0).sum(axis=1)
    assert (ran < 400).all() and (ran % 10 == 0).all()
    assert np.isnan(policy.returns[0, ran[0]:]).all() and np.isfinite(policy.returns[0, :ran[0]]).all()
    assert sum(policy.end_counts().values()) == ran.sum()
    assert sum(policy.end_counts(last=5).values()) == 2 * 5
    verdict = training_verdict(policy, episodes=2)
    assert sum(verdict.late_ends.values()) == sum(max(1, int(ran.min()) // 5) for _ in ran)
    # Each trial's share too (the pooled one hides trials far apart), in report.json and printed.
    greedy = policy.rollout(2, policy="greedy")
    assert verdict.per_trial["greedy"] == [float(r.mean()) for r in greedy["reached"]]
    assert verdict.to_dict()["per_trial"] == verdict.per_trial
    assert "  greedy per trial: " in str(verdict) and "random per trial" not in str(verdict)


def test_timeouts_are_told_apart_by_their_reward_per_step() -> None:
    """Issue #37: timed-out episodes earning ≥ ½ per step hover near the target (more episodes
    helped the zoo's snake, a smaller step did not); earning less they wander away from it (the
    zoo's iiwa arm: its timeouts sat in a band of the latent space far from the demos)."""
    from types import SimpleNamespace

    from latentrl.verdict import timeout_advice

    policy = SimpleNamespace(task=SimpleNamespace(to_dict=lambda: {"episode": {"max_steps": 200}}))
    near = timeout_advice(policy, np.array([110.0, 130.0]))
    assert "near the target (mean reward 0.60 per step): the policy hovers" in near
    assert "--episode.stop-window 0" in near and "smaller learner.step" not in near
    far = timeout_advice(policy, np.array([10.0, 30.0]))
    assert "away from the target (mean reward 0.10 per step)" in far and "smaller learner.step" not in far


def test_the_advice_follows_how_the_greedy_rollouts_failed_not_training() -> None:
    """Issue #37: the zoo's snake failed its training episodes mostly on the wall (the soft-max
    explores) while its greedy rollouts mostly hovered beside the target; the advice was for the
    wall. It follows the greedy rollouts that missed, the policy `act()` runs."""
    from types import SimpleNamespace
    from typing import Any

    from latentrl.episode_ends import end_reasons
    from latentrl.rollout_summary import rollout_summary
    from latentrl.verdict import training_verdict

    names = end_reasons()
    timeout, obstacle = names.index("timeout"), names.index("obstacle")
    config = {"episode": {"max_steps": 100}, "learner": {"move_correction": False}, "target": {"hold_steps": 0}}
    task = SimpleNamespace(to_dict=lambda: config)
    greedy = {"ends": np.array([[timeout] * 6 + [obstacle] * 2]), "reached": np.array([[True] * 3 + [False] * 5]),
              "returns": np.full((1, 8), 70.0)}

    def rollout(episodes: int, seed: int, policy: str) -> dict[str, Any]:
        run = greedy if policy == "greedy" else {**greedy, "reached": np.zeros((1, 8), dtype=bool)}
        return {**run, "summary": rollout_summary(run["ends"].ravel(), run["reached"].ravel(),
                                                  run["returns"].ravel(), task)}

    training = np.array([[timeout] * 10 + [obstacle] * 40])
    policy = SimpleNamespace(task=task, rollout=rollout, record={
        "ends": training, "reached": np.arange(50)[None] < 5, "returns": np.zeros(training.shape)})
    verdict = training_verdict(policy, episodes=8)
    assert verdict.late_ends["obstacle"] == 10 and verdict.late_ends["timeout"] == 0
    assert len(verdict.next) == 1 and "time out near the target (mean reward 0.70 per step)" in verdict.next[0]
    assert verdict.verdict == "stopped improving below the target" and not verdict.rising
    greedy["ends"] = np.array([[timeout] * 3 + [obstacle] * 5])
    assert "most failing greedy rollouts end as obstacle" in training_verdict(policy, episodes=8).next[0]
    # Reaching more in its last tenth than in the one before, it was still improving (the sweep's
    # "stopped improving below the target" beside "still rising").
    policy.record["reached"] = np.arange(50)[None] >= 45
    rising = training_verdict(policy, episodes=8)
    assert rising.rising and rising.verdict == "still improving below the target"


def test_a_greedy_policy_below_the_random_control_is_told() -> None:
    """A real run: greedy 0 %, soft-max 15 %, the random control 8 % from the same starts, and the
    verdict ("stopped improving below the target") did not say that what `act()` runs does worse
    than chance. Said in its lines and in report.json; not when greedy is level with the control."""
    from types import SimpleNamespace
    from typing import Any

    from latentrl.episode_ends import end_reasons
    from latentrl.rollout_summary import rollout_summary
    from latentrl.verdict import training_verdict

    timeout = end_reasons().index("timeout")
    config = {"episode": {"max_steps": 100}, "learner": {"move_correction": False}, "target": {"hold_steps": 0}}
    task = SimpleNamespace(to_dict=lambda: config)
    reached = {"greedy": 0, "softmax": 3, "random": 2}  # of 20 rollouts: 0, 15 and 10 %

    def rollout(episodes: int, seed: int, policy: str) -> dict[str, Any]:
        run = {"ends": np.full((1, 20), timeout), "reached": np.arange(20)[None] < reached[policy],
               "returns": np.full((1, 20), 10.0)}
        return {**run, "summary": rollout_summary(run["ends"].ravel(), run["reached"].ravel(), run["returns"].ravel(),
                                                  task)}

    training = np.full((1, 50), timeout)
    policy = SimpleNamespace(task=task, rollout=rollout, record={
        "ends": training, "reached": np.arange(50)[None] < 5, "returns": np.zeros(training.shape)})
    verdict = training_verdict(policy, episodes=20)
    told = ("greedy reaches the target less often than the random control (0% vs 10%): it has learnt nothing "
            "usable from these starts")
    assert verdict.below_control == told and verdict.to_dict()["below_control"] == told
    assert f"\n  {told}\n" in str(verdict)
    reached["greedy"] = 2
    level = training_verdict(policy, episodes=20)
    assert level.below_control is None and "random control" not in str(level)


def test_a_trial_stopped_in_a_dip_below_another_is_told() -> None:
    """Issue #37: the zoo's snake had trials stopped at 900 episodes far below one that ran on;
    run to the budget, it reached more. Stopped trials level with the best are not told."""
    from latentrl.verdict import stop_advice

    reached = np.zeros((3, 100), dtype=bool)
    reached[0, :100:2] = True  # ran the budget, 50 % in its last tenth
    reached[1, :40:4] = True  # stopped at 40, 25 % in its last tenth
    reached[2, :60:2] = True  # stopped at 60, level with the best
    runs = np.array([100, 40, 60])
    told = stop_advice(reached, runs)
    assert told is not None and "ended 1 of 3 trials below the best one, at 40 episodes" in told and "25 %" not in told
    assert "25%" in told and "reached 50%" in told and "--episode.stop-window 0" in told
    assert stop_advice(reached[[0, 2]], runs[[0, 2]]) is None
    assert stop_advice(reached, np.array([100, 100, 100])) is None  # none stopped


def test_obstacle_advice_does_not_repeat_what_the_run_already_did() -> None:
    from latentrl.verdict import end_advice

    assert "move_correction = true" in str(end_advice("obstacle", {"move_correction": False}))
    assert "move_correction" not in str(end_advice("obstacle", {"move_correction": True}))
    assert all("servo.kd" in str(end_advice("obstacle", {"move_correction": on})) for on in (False, True))
    assert end_advice("timeout", {"move_correction": False}) is None


def test_a_latent_margin_that_overflows_the_box_is_refused_naming_it():
    """`--latent-margin 1e308` passed the margin's rule (finite, ≥ 0), then failed naming only
    "latent_low contains a non-finite value (-inf)"."""
    latent = np.array([[0.0, -1.0], [2.0, 1.0]])
    assert [b.tolist() for b in latent_box(latent, 0.5)] == [[-1.0, -2.0], [3.0, 2.0]]
    with pytest.raises(ValueError, match=r"run.latent_margin = 1e\+308 widens the latent box beyond the largest float"):
        latent_box(latent, 1e308)


def test_a_rollout_line_says_which_endings_came_after_reaching_the_target() -> None:
    """A policy that arrives and stays ends by timeout: "ends: timeout 39" read as a policy that
    mostly timed out (helper-33's figure review: 35 of the glass arm's 39 had reached it)."""
    from latentrl.rollout_summary import format_rollout, rollout_summary
    from latentrl.task import end_reasons

    names = end_reasons()
    ends = np.array([names.index("timeout")] * 3 + [names.index("obstacle")])
    summary = rollout_summary(ends, np.array([True, True, False, False]), np.zeros(4), Task.shipped("two_arms"))
    assert summary["ends_after_reaching"]["timeout"] == 2 and summary["ends_after_reaching"]["obstacle"] == 0
    assert format_rollout(summary).endswith("ends: timeout 3 (2 after reaching), obstacle 1")
