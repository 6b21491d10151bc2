"""Issue #41, first "Done when" item: two stock arms of pybullet 3.2.7's pybullet_data (vendored in
tests/robots/pybullet_iiwa and tests/robots/pybullet_panda, collision meshes only) with the
tasks of examples/stock/ (nobody tuned them: no [learner], [servo] or [physics] table). A run's
`rollout` starts where its frozen tests start, and its trained policy and random control differ
as the run's frozen tests (learner against the α = 1e-12 control) do. Measured numbers and wall
times: docs/robots.md, "Two stock arms learning"."""

import json
import subprocess
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from latentrl import Task
from latentrl.demos import load_demos

from learning import CONTROL_ALPHA, assert_separated

ROOT = Path(__file__).resolve().parents[1]
STOCK = ROOT / "examples" / "stock"
ROBOTS = {"iiwa_shelf": ROOT / "tests" / "robots" / "pybullet_iiwa",
          "panda_bins": ROOT / "tests" / "robots" / "pybullet_panda"}


def latentrl(*args: object) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "latentrl", *map(str, args)], capture_output=True, text=True,
                          cwd=ROOT, timeout=1200)


def trained(out: Path, name: str, *extra: str) -> dict:
    """`train --quick` (and `extra`) on the stock task `name`, then `rollout --episodes 20`: the
    frozen tests of returns.npz and the rollout's summary and arrays."""
    task = STOCK / name / "task.toml"
    # Measured with the GP encoder, train's default until the tracking encoder replaced it.
    train = latentrl("train", task, "--demos", STOCK / name / "demos.csv", "--out", out, "--quick", "--no-progress",
                     "--encoder", "gp", *extra)
    assert train.returncode == 0, train.stderr
    with np.load(out / "returns.npz") as npz:
        run = {"tests": npz["latent_test_reached"].mean(axis=1), "test_starts": npz["latent_test_start_hands"]}
    if extra:
        return run
    rollout = latentrl("rollout", out, "--out", out / "rollout", "--episodes", 20, "--no-progress")
    assert rollout.returncode == 0, rollout.stderr
    run["rollout"] = json.loads((out / "rollout" / "rollout.json").read_text())
    with np.load(out / "rollout" / "rollout.npz") as npz:
        run["paths"] = {kind: npz[f"{kind}_paths"] for kind in ("greedy", "softmax", "random")}
    assert run["rollout"]["starts"] == "test"
    for kind in ("greedy", "softmax"):  # the three policies meet the same starts
        assert np.array_equal(run["paths"][kind][:, :, 0], run["paths"]["random"][:, :, 0])
    return run


@pytest.mark.parametrize("name", sorted(ROBOTS))
def test_the_stock_tasks_load_their_vendored_robot_and_demos(name):
    """The vendored files are the loader's needs only (collision meshes, license, README), small;
    the task has no [learner] table and its demos are its robot's columns."""
    robot = ROBOTS[name]
    files = [f for f in robot.rglob("*") if f.is_file()]
    assert sum(f.stat().st_size for f in files) < 1_000_000
    assert (robot / "LICENSE.txt").is_file() and "3.2.7" in (robot / "README.md").read_text()
    assert not {"learner", "servo", "physics"} & set(tomllib.loads((STOCK / name / "task.toml").read_text()))
    task = Task.load(STOCK / name / "task.toml")
    demos = load_demos(STOCK / name / "demos.csv", expected_joints=task.joint_names)
    assert len(demos.postures) >= 100
    codes, _, _ = task.replace({"episode.start": "uniform"}).plant().classify(np.asarray(demos.postures, float))
    assert (np.asarray(codes) == 0).all()  # every demo is admissible at rest (the mesh hulls, the rules)


@pytest.mark.slow
def test_the_stock_iiwa_learns_to_carry_the_tray_to_the_shelf_and_its_rollout_says_so(tmp_path):
    """Measured once (2 shared cores, `--quick`: 2 trials × 300 episodes, seed 0): frozen test
    episodes reaching the shelf 0.8 and 1.0 per trial for the learner, 0 and 0 for the
    α = 1e-12 control; the rollout (20 episodes per trial from the test starts) reached the shelf
    in 78 % greedy, 85 % soft-max, 0 % random (box exit 31 of 40, obstacle 9). Train 139 s
    (control 80 s) and rollout 96 s wall, two runs side by side. The bounds leave room for
    another machine's trajectories: each side's threshold lies halfway or more from what was
    measured."""
    learner = trained(tmp_path / "learner", "iiwa_shelf")
    control = trained(tmp_path / "control", "iiwa_shelf", "--learner.alpha", str(CONTROL_ALPHA))
    assert_separated(learner["tests"], control["tests"], 0.4, "frozen test episodes reaching the shelf")
    rollout = learner["rollout"]
    assert rollout["greedy"]["reached_any_step"] >= 0.5 and rollout["softmax"]["reached_any_step"] >= 0.5, rollout
    assert rollout["random"]["reached_any_step"] <= 0.2, rollout["random"]
    # the test starts: the flange over the table, below the waypoint (y < -0.15), as the run's tests
    starts = learner["paths"]["random"][:, :, 0, :3]
    assert (starts[..., 1] < -0.15).all() and (learner["test_starts"][..., 1] < -0.15).all()


@pytest.mark.slow
def test_the_stock_panda_does_not_learn_the_bins_at_quick_and_its_rollout_says_so(tmp_path):
    """Did not learn (measured once, `--quick`, seed 0): no frozen test episode reached the left
    bin (0 and 0 per trial; ends: 9 obstacle, 11 drop of 20), nor any rollout (greedy, soft-max,
    random: 0 % of 40 each). The learnt paths head for the target low, through the divider
    (obstacle) or tilt the gripper past 0.25 rad on the way over it (drop); `--encoder tracking`
    and `--encoder back_constrained` reached 0 % too. So the rollout agrees with the frozen
    tests in that neither the trained policy nor the control reaches the bin. Train 71 s wall.
    `latentrl check` (GPLVM fitted to convergence) finds the target region 2 admissible points a
    learner step apart, about one step wide, and keeps the step: at half of it the starts would
    need more than half an episode (docs/robots.md; the zoo's Panda-style arm learnt in that state
    at the default budget; the check had warned here before, and said "will not learn" when its
    coarsened grid fell between the points)."""
    check = latentrl("check", STOCK / "panda_bins" / "task.toml", "--demos", STOCK / "panda_bins" / "demos.csv",
                     "--json", "--no-progress")
    assert check.returncode == 0, check.stderr
    findings = {f["name"]: f for f in json.loads(check.stdout)["findings"]}
    target = findings["target"]
    assert target["verdict"] == "ok" and target["values"]["reached_points"] <= 2, target
    assert "about one learner step wide, kept" in target["message"]
    learner = trained(tmp_path / "learner", "panda_bins")
    assert (learner["tests"] <= 0.2).all(), learner["tests"]
    rollout = learner["rollout"]
    for kind in ("greedy", "softmax", "random"):
        assert rollout[kind]["reached_any_step"] <= 0.2, rollout[kind]
    # the test starts: demo 0 (the grasp point low in the right bin, at (0.5, -0.3, 0.1)) ± 0.03 rad
    demo0 = np.loadtxt(STOCK / "panda_bins" / "demos.csv", delimiter=",", skiprows=1)[0]
    starts = learner["paths"]["random"][:, :, 0]
    assert np.abs(starts[..., 10:10 + 7] - demo0[:7]).max() <= 0.03 + 1e-3
    assert np.linalg.norm(starts[..., :3] - [0.5, -0.3, 0.1], axis=-1).max() < 0.08
