"""`latentrl replay` (issue #23): a recorded episode of an Exp 2 or Exp 3 run as a GIF or MP4,
drawn from the stored path; bad requests exit 1 naming the problem and write nothing."""

import subprocess
import sys

import numpy as np
import pytest

iio = pytest.importorskip("imageio.v3")

from latentrl.cli import main  # noqa: E402

EXP3 = ["run", "exp3", "--quick", "--trials", "1", "--episodes", "4", "--episode.max-steps", "12",
        "--test-episodes", "2", "--no-progress"]
EXP2 = ["run", "exp2", "--quick", "--trials", "1", "--episodes", "2", "--episode.max-steps", "10",
        "--test-episodes", "1", "--fig5-samples", "50", "--gplvm-max-iter", "20", "--no-progress"]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    root = tmp_path_factory.mktemp("replay")
    assert main([*EXP3, "--out", str(root / "exp3")]) == 0
    assert main([*EXP2, "--out", str(root / "exp2")]) == 0
    return root


def test_a_test_episode_of_exp3_becomes_a_gif_with_one_frame_per_stored_step(runs):
    steps = int(np.load(runs / "exp3" / "returns.npz")["latent_test_steps"][0, 0])
    out = runs / "lift.gif"
    assert main(["replay", str(runs / "exp3"), "--test", "0", "--out", str(out)]) == 0
    frames = iio.imread(out)
    assert frames.shape == (steps + 1, 480, 960, 3)
    assert not np.array_equal(frames[0], frames[-1])  # the robot and the latent point moved


def test_a_training_episode_of_exp2_becomes_an_mp4(runs):
    out = runs / "arms.mp4"
    assert main(["replay", str(runs / "exp2"), "--episode", "0", "--out", str(out), "--fps", "10"]) == 0
    assert iio.improps(out).shape[1:] == (480, 960, 3)


@pytest.mark.parametrize("args, says", [
    (["--test", "5"], "--test 5: the run recorded test episodes 0..1"),
    (["--episode", "7"], "--episode 7: the run recorded training episodes [0, 1, 2, 3]"),
    (["--test", "0", "--trial", "3"], "--trial 3: the run has trials 0..0"),
    (["--test", "0", "--fps", "0"], "--fps must be at least 1"),
])
def test_bad_requests_exit_1_and_write_nothing(runs, tmp_path, capsys, args, says):
    out = tmp_path / "bad.gif"
    assert main(["replay", str(runs / "exp3"), *args, "--out", str(out)]) == 1
    assert says in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


def test_a_suffix_it_cannot_write_and_a_missing_extra_are_named(runs, tmp_path):
    err = subprocess.run([sys.executable, "-m", "latentrl", "replay", str(runs / "exp3"), "--test", "0",
                          "--out", str(tmp_path / "x.avi")], capture_output=True, text=True)
    assert err.returncode == 1 and "write a .gif or an .mp4" in err.stderr and "Traceback" not in err.stderr
    code = ("import sys; sys.modules['imageio'] = None; from latentrl.cli import main; "
            f"sys.exit(main(['replay', {str(runs / 'exp3')!r}, '--test', '0', '--out', {str(tmp_path / 'x.gif')!r}]))")
    err = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert err.returncode == 1 and "pip install 'latentrl[video]'" in err.stderr
    assert not (tmp_path / "x.gif").exists()


def test_a_latentrl_train_run_on_a_custom_task_replays(tmp_path):
    from pathlib import Path

    example = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"
    run = tmp_path / "glass"
    assert main(["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--out", str(run),
                 "--quick", "--trials", "1", "--episodes", "3", "--test-episodes", "1", "--episode.max-steps", "8",
                 "--no-progress"]) == 0
    out = tmp_path / "glass.gif"
    assert main(["replay", str(run), "--test", "0", "--out", str(out)]) == 0
    assert iio.imread(out).shape[1:] == (480, 960, 3)
