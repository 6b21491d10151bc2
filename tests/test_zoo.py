"""The robot zoo (examples/zoo/, issue #37 item 4): six robots and tasks nobody tuned. By default
the fastest of them (the planar snake) is checked and trained with --quick end to end; the slow
tests train every robot with the defaults and ask for the issue's goal: the saved policy's greedy
rollouts reach the target in ≥ 80 % of 40, the random control from the same starts in ≤ 30 %.
Robots measured to miss it are expected failures, with the measured reason (examples/zoo/README.md)."""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
ZOO = ROOT / "examples" / "zoo"
ROBOTS = ("snake_planar", "bimanual_box", "ur_reach", "panda_bins", "iiwa_tray", "biped_pick")
FASTEST = "snake_planar"  # quick train + rollout ≈ 15 s on 2 cores (examples/zoo/README.md)


def latentrl(*args):
    return subprocess.run([sys.executable, "-m", "latentrl", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, timeout=3600)


def files(robot):
    return ZOO / robot / "task.toml", ZOO / robot / "demos.csv"


@pytest.mark.parametrize("robot", ROBOTS)
def test_every_zoo_robot_has_its_files_and_no_learner_table(robot):
    task, demos = files(robot)
    assert (ZOO / robot / "robot.urdf").exists() and (ZOO / robot / "make_demos.py").exists() and demos.exists()
    text = task.read_text()
    assert text.startswith("#"), "a task file starts with a comment saying what the task is"
    assert not any(line.strip().startswith("[learner") for line in text.splitlines()), \
        "zoo tasks run the learner's defaults"
    assert 40 <= len(demos.read_text().splitlines()) - 1 <= 150


def test_the_fastest_zoo_robot_checks_trains_and_rolls_out(tmp_path):
    task, demos = files(FASTEST)
    check = latentrl("check", task, "--demos", demos, "--json", "--no-progress")
    assert check.returncode in (0, 3), check.stderr
    report = json.loads(check.stdout)
    assert report["verdict"] != "will not learn", report
    run = tmp_path / FASTEST
    train = latentrl("train", task, "--demos", demos, "--out", run, "--quick", "--no-progress")
    assert train.returncode == 0, train.stderr
    rollout = latentrl("rollout", run, "--out", run / "rollout", "--episodes", 5, "--no-progress")
    assert rollout.returncode == 0, rollout.stderr
    result = json.loads((run / "rollout" / "rollout.json").read_text())
    for policy in ("greedy", "softmax", "random"):
        assert 0.0 <= result[policy]["reached_any_step"] <= 1.0


MISSED = {
    "snake_planar": "measured 40 % greedy (soft-max 42 %, random 5 %): its greedy policy stops next to the "
                    "target, where the learnt V is flatter than its errors (examples/zoo/README.md, session 9)",
}
"""The zoo robots that miss the goal with the defaults, and why (measured 2026-12-06, 2 trials: the
other five reach their targets in 82–100 % of greedy rollouts; docs/zoo.md)."""


@pytest.mark.slow
@pytest.mark.parametrize("robot", [pytest.param(r, marks=pytest.mark.xfail(reason=MISSED[r])) if r in MISSED else r
                                   for r in ROBOTS])
def test_zoo_robot_learns_with_the_defaults(robot, tmp_path):
    task, demos = files(robot)
    run = tmp_path / robot
    train = latentrl("train", task, "--demos", demos, "--out", run, "--no-progress")
    assert train.returncode == 0, train.stderr
    rollout = latentrl("rollout", run, "--out", run / "rollout", "--episodes", 20, "--no-progress")
    assert rollout.returncode == 0, rollout.stderr
    result = json.loads((run / "rollout" / "rollout.json").read_text())
    assert result["greedy"]["reached_any_step"] >= 0.8 and result["random"]["reached_any_step"] <= 0.3, result
