"""Experiment 3 end to end: the native humanoid runner's checks and records, the quick preset
(finite returns, end codes, the results layout (docs/method.md) and figure names), same seed same
results, resumes, and the CLI."""

import dataclasses
import json
import subprocess
import sys

import numpy as np
import pytest

from latentrl._native import run_task_trials
from latentrl.saved_runs import saved_run
from latentrl.experiments import exp3
from latentrl.experiments.exp3 import Exp3Preset
from latentrl.experiments import run_experiment
from latentrl.run_settings import with_overrides
from latentrl.results import write_npz
from learning import assert_separated

EXPERIMENT = "exp3"
"""The experiment of `quick_run` and `control_run` (conftest.py)."""

TINY = with_overrides(Exp3Preset.quick(), {"trials": 2, "episodes": 3, "episode.max_steps": 8, "test_episodes": 1,
                                           "map_grid": 8})


@pytest.fixture(scope="module")
def fitted():
    return exp3.fit(Exp3Preset.quick())


def test_runs_record_postures_of_the_given_task(fitted):
    task = exp3.task_of(with_overrides(TINY, {"episode.max_steps": 5}))
    a = run_task_trials(task._native, decoder=fitted.model.decoder_, encoder=fitted.model.encoder_,
                        latent_low=fitted.low, latent_high=fitted.high, demos=fitted.demos, n_trials=2, episodes=2,
                        base_seed=0, record_episodes=[1], test_episodes=1, record_test_episodes=[0], return_weights=True)
    rows = task.row_slices()
    assert a["returns"].shape == (2, 2) and a["trajectories"].shape == (2, 1, 6, task.row_len) == (2, 1, 6, 32)
    assert np.isfinite(a["returns"]).all() and set(np.unique(a["ends"])) <= {0, 1, 2, 3, 4}
    start = a["trajectories"][:, 0, 0]
    # Starts hold the object, stand on the floor, and the row's joints are a posture of the robot.
    grip = np.linalg.norm(start[:, 3:6] - start[:, :3], axis=1)
    assert np.all(np.abs(grip - 0.10) <= 0.02), grip
    joints = start[:, rows["joints"]]
    assert np.all((joints >= task.lower - 1e-9) & (joints <= task.upper + 1e-9))
    np.testing.assert_allclose(np.linalg.norm(start[:, rows["base_quaternion"]], axis=1), 1.0, atol=1e-6)
    # The recorded base pose and joints give the recorded hands through the native kinematics
    # (f64 FK of the recorded values against the f32 world's frames: 2e-8 m seen, f32 ε × 0.2 m).
    plant = task.plant(fitted.demos)
    base = np.r_[rows["base_position"], rows["base_quaternion"]]
    for row in start:
        poses = plant.pose_links(row[base], row[rows["joints"]])
        np.testing.assert_allclose(poses[task.link_names.index("l_hand")][:3], row[:3], rtol=0, atol=1e-6)
    config = task.to_dict()
    assert config["physics"]["solver_iterations"] == 2 and config["physics"]["pgs_iterations"] == 4
    assert config["servo"]["kp"] == 8.0 and config["servo"]["max_force"] == 1.2 and config["episode"]["max_steps"] == 5


def test_quick_preset_ends_episodes_correctly(quick_run):
    """Finite returns within the reward's bounds, every episode ended by a known code, a
    terminal step (obstacle, box, drop, fall) carries the −1 and a time-out ran all steps."""
    out, meta = quick_run
    preset = Exp3Preset.quick()
    max_steps = exp3.task_of(preset).to_dict()["episode"]["max_steps"]
    with np.load(out / "returns.npz") as npz:
        returns, ends, steps = npz["latent"], npz["latent_end"], npz["latent_steps"]
    assert np.isfinite(returns).all()
    assert set(np.unique(ends)) <= {0, 1, 2, 3, 4}
    assert max_steps == 100 and np.all(steps[ends == 0] == max_steps)
    assert np.all((steps[ends != 0] >= 1) & (steps[ends != 0] <= max_steps))
    assert np.all(returns <= steps) and np.all(returns >= -1.0)
    assert np.all(returns[ends != 0] <= steps[ends != 0] - 1.0 + 1e-9), "penalty on terminal steps"
    # Measured 84-89 % per trial (Intel, seed 0, 6 trials): a floor well below, for episodes that neither
    # fall, drop nor touch the block; a plant that ended episodes at random would miss it.
    assert (ends == 0).mean() >= 0.4, "fewer than 40 % of episodes ran to the time-out"
    for summary in meta["trials"]["latent"].values():
        assert sum(summary["ends"].values()) == preset.episodes


def test_quick_preset_learns(quick_run, control_run):
    """The mean return of the last 50 episodes lies above 58 for the learner and below it for the
    control (α = 1e-12) on the same trials. Calibrated on 6 trials of seed 0 (Intel Xeon,
    2026-12-03, the bridged demos, back-constrained encoder and sole-relative h*): learner
    76.4–88.9, control 28.8–42.5."""
    late = {}
    for name, out in (("learner", quick_run[0]), ("control", control_run)):
        with np.load(out / "returns.npz") as npz:
            late[name] = npz["latent"][:, -50:].mean(axis=1)
    assert_separated(late["learner"], late["control"], 58.0, "mean return of the last 50 episodes")


def test_quick_preset_lifts_from_the_floor(quick_run, control_run):
    """Issue #18: every frozen test of the quick preset starts with both hands at floor level
    (≤ 0.10 m); at least 60 % of them reach h* and end by the step limit (no obstacle, fall or
    drop). Measured per trial on 6 trials of seed 0 (Intel Xeon, 2026-12-03; 20 tests each):
    learner 0.70–0.95, control (α = 1e-12) 0.00 in every trial."""
    rates = {}
    for name, out in (("learner", quick_run[0]), ("control", control_run)):
        with np.load(out / "returns.npz") as npz:
            assert (npz["latent_test_start_hands"][..., [2, 5]] < exp3.FLOOR_LEVEL).all(), "a test started higher"
            rates[name] = ((npz["latent_test_end"] == 0) & npz["latent_test_reached"]).mean()
    assert rates["learner"] >= 0.6, rates
    assert rates["control"] < 0.3, rates


def test_results_layout_follows_spec(quick_run):
    out, _ = quick_run
    saved = json.loads((out / "results.json").read_text())
    preset = Exp3Preset.quick()
    assert saved["preset"] == {"name": "Exp3Preset", **dataclasses.asdict(preset)}
    assert saved["setup"]["task"] == exp3.task_of(preset).to_dict()
    assert set(saved["trials"]) == {"latent"} and len(saved["trials"]["latent"]) == preset.trials
    with np.load(out / "returns.npz") as npz:
        assert npz["latent"].shape == npz["latent_end"].shape == (preset.trials, preset.episodes)
        assert npz["latent_test"].shape == (preset.trials, preset.test_episodes)
        # V's 20 × 20 weights, then a move correction per action (8), the task's move_correction.
        assert npz["latent_weights"].shape == (preset.trials, 20**2 * (1 + 8))
        assert npz["latent_test_paths"].shape[-1] == 6 + 7 + 19
        # Both hands at the start of every frozen test: the first row of each recorded test path.
        starts = npz["latent_test_start_hands"]
        assert starts.shape == (preset.trials, preset.test_episodes, 6) and np.isfinite(starts).all()
        recorded = npz["latent_test_paths"].shape[1]
        np.testing.assert_array_equal(starts[:, :recorded], npz["latent_test_paths"][:, :, 0, :6])
        # Every training episode's mean latent state lies in the latent box.
        mean = npz["latent_mean_state"]
        box = saved["setup"]["latent_box"]
        assert mean.shape == (preset.trials, preset.episodes, 2)
        assert np.all((mean >= np.array(box["low"])) & (mean <= np.array(box["high"])))
    for fig in ("fig7b", "fig7c", "fig7d", "fig7e", "fig7f", "fig8"):
        for ext in ("png", "pdf"):
            assert (out / f"{fig}.{ext}").stat().st_size > 1000
    assert not list(out.glob(".*tmp")), "temporary files left behind"


def test_same_seed_same_results_and_a_missing_trial_is_rerun_identically(tmp_path):
    a = run_experiment("exp3", TINY, tmp_path / "a", progress=False)
    b = run_experiment("exp3", TINY, tmp_path / "b", progress=False)
    assert a["trials"] == b["trials"]
    with np.load(tmp_path / "b" / "returns.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["latent_end"][1] = -1
    write_npz(tmp_path / "b" / "returns.npz", arrays)
    run_experiment("exp3", TINY, tmp_path / "b", progress=False)
    with np.load(tmp_path / "a" / "returns.npz") as whole, np.load(tmp_path / "b" / "returns.npz") as resumed:
        assert whole.files == resumed.files
        for key in whole.files:
            np.testing.assert_array_equal(whole[key], resumed[key], err_msg=key)


def test_a_run_made_before_the_shipped_task_changed_is_plotted_and_resumed_as_it_ran(tmp_path):
    # A run from before humanoid_lift.toml turned learner.move_correction on: no override, and no
    # such key in its recorded task (the key's default is the behaviour before it existed).
    old = with_overrides(TINY, {"learner.move_correction": False})
    run_experiment("exp3", old, tmp_path / "a", progress=False)
    run_experiment("exp3", old, tmp_path / "b", progress=False)
    meta_path = tmp_path / "b" / "results.json"
    meta = json.loads(meta_path.read_text())
    meta["preset"]["task"] = {k: v for k, v in meta["preset"]["task"].items() if k != "learner.move_correction"}
    del meta["setup"]["task"]["learner"]["move_correction"]
    meta_path.write_text(json.dumps(meta))
    _, preset = saved_run(tmp_path / "b")
    assert preset.task["learner.move_correction"] is False
    with np.load(tmp_path / "b" / "returns.npz") as npz:
        arrays = {k: npz[k] for k in npz.files}
    arrays["latent_end"][1] = -1
    arrays["preset_json"] = np.array(json.dumps(meta["preset"], sort_keys=True))
    write_npz(tmp_path / "b" / "returns.npz", arrays)
    # Continuing it with the shipped task as it is now would mix two learners: refused.
    with pytest.raises(ValueError, match=r"ran with another task \(learner.move_correction differ\)"):
        run_experiment("exp3", TINY, tmp_path / "b", progress=False)
    for cmd in (["run", "exp3", "--resume"], ["plot"]):
        result = subprocess.run([sys.executable, "-m", "latentrl", *cmd, str(tmp_path / "b")], capture_output=True,
                                text=True, timeout=300)
        assert result.returncode == 0, result.stderr
    with np.load(tmp_path / "a" / "returns.npz") as whole, np.load(tmp_path / "b" / "returns.npz") as resumed:
        for key in ("latent", "latent_end", "latent_weights"):
            np.testing.assert_array_equal(whole[key], resumed[key], err_msg=key)


def test_the_plant_marks_the_demos_and_the_target_is_the_top_demo():
    """Of the 14 demos only the paper's straight-arm 0-2 touch the block; h* (measured from the
    left sole) is demo 6's hands wherever that demo stands."""
    fitted = exp3.fit(Exp3Preset.quick())
    task = exp3.task_of(Exp3Preset())
    codes, hands, targets = task.plant(fitted.demos).classify(fitted.demos)
    np.testing.assert_array_equal(codes, [1, 1, 1] + [0] * 11)
    np.testing.assert_allclose(hands[6], targets[6], atol=1e-9)
    assert np.abs(hands[6] - np.ravel(task.to_dict()["target"]["position"])).max() > 0.01, "h* is not a world point"


def test_preset_validation():
    with pytest.raises(ValueError, match="episode.start: unknown variant `anywhere`"):
        with_overrides(Exp3Preset(), {"episode.start": "anywhere"}).validate()
    with pytest.raises(ValueError, match="learner.gamma"):
        with_overrides(Exp3Preset(), {"learner.gamma": 1.0}).validate()
    with pytest.raises(ValueError, match=r"servo.max_force must be >= 0 \(inf allowed\), got -1"):
        with_overrides(Exp3Preset(), {"servo.max_force": -1.0}).validate()
    quick = Exp3Preset.quick()
    config = exp3.task_of(quick).to_dict()
    assert (quick.trials, quick.episodes, config["episode"]["max_steps"], config["learner"]["initial_weight"]) == (
        2, 300, 100, 100.0)
    Exp3Preset().validate()


def test_cli_runs_exp3_tiny(tmp_path):
    cmd = [sys.executable, "-m", "latentrl", "run", "exp3", "--quick", "--no-progress", "--trials", "1",
           "--episodes", "2", "--episode.max-steps", "5", "--test-episodes", "1", "--map-grid", "6",
           "--episode.start", "demo", "--episode.start-demo", "7",  # a floor-level squat: the quick tests start there
           "--out", str(tmp_path)]
    result = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    saved = json.loads((tmp_path / "results.json").read_text())
    assert saved["preset"]["task"]["episode.start"] == "demo" and saved["setup"]["task"]["episode"]["start"] == "demo"
    assert "test_success" in saved["trials"]["latent"]["0"]
    assert (tmp_path / "fig8.png").is_file()


def test_a_demo_is_of_its_own_style(fitted):
    """`episode_styles` gives each demo's own latent point its style (rows of `STYLES`), and a
    trial that was not run −1."""
    styles = exp3.episode_styles(fitted.model.Z_[None], fitted.model.Z_)[0]
    want = np.empty(len(fitted.model.Z_), dtype=int)
    for k, rows in enumerate(exp3.STYLES.values()):
        want[list(rows)] = k
    np.testing.assert_array_equal(styles, want)
    assert exp3.episode_styles(np.full((1, 3, 2), np.nan), fitted.model.Z_).tolist() == [[-1, -1, -1]]
