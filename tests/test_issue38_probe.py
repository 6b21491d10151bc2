"""Issue #38: regressions from the developers' hostile-input probe (tests/hostile_probe.py,
docs/robustness.md#the-developers-hostile-input-probe): each input below once ended in a traceback,
a message naming no file, or a half-written run folder."""

from __future__ import annotations

import json
from collections.abc import Iterator
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from latentrl import GPLVM, LatentPolicy, Task, load_demos
from latentrl.datasets import arm_postures
from latentrl.replay import check_replay_arrays, rollout_episode
from latentrl import train_latent_policy

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"


@pytest.fixture(scope="module")
def policy_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    model = GPLVM(n_components=2, max_iter=50, random_state=0).fit(arm_postures(40, np.random.default_rng(1)))
    policy = train_latent_policy(model, trials=1, episodes=2, overrides={"episode.max_steps": 10}, test_episodes=0)
    path = tmp_path_factory.mktemp("policy") / "policy.npz"
    policy.save(path)
    return path


def edited(policy_file: Path, tmp_path: Path, **arrays: np.ndarray) -> Path:
    path = tmp_path / "edited.npz"
    np.savez(path, **{**dict(np.load(policy_file)), **arrays})
    return path


def test_a_policy_whose_end_codes_are_unknown_is_refused_naming_the_file_and_array(policy_file: Path, tmp_path: Path) -> None:
    """Issue #38: `latentrl report` on end codes 99 was an IndexError traceback (in `end_counts`)."""
    ends = np.load(policy_file)["record.ends"]
    for bad in (np.full_like(ends, 99), ends.astype(np.float64)):
        with pytest.raises(ValueError, match=r"edited\.npz: record\.ends: expected end codes"):
            LatentPolicy.load(edited(policy_file, tmp_path, **{"record.ends": bad}))


def test_a_policy_whose_task_json_is_cut_is_refused_naming_the_file(policy_file: Path, tmp_path: Path) -> None:
    """Issue #38: a cut task JSON said only "Unterminated string starting at …"."""
    task = str(np.load(policy_file)["task"])
    with pytest.raises(ValueError, match=r"edited\.npz: its task is not valid JSON"):
        LatentPolicy.load(edited(policy_file, tmp_path, task=np.array(task[:40])))


def test_a_seed_beyond_64_bits_is_refused_before_a_run_folder_is_written(tmp_path: Path) -> None:
    """Issue #38: `latentrl train --seed 2**70` wrote the run folder, then failed in the native
    runner ("base_seed must lie in …", not the flag's name)."""
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, "-m", "latentrl", "train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"),
         "--quick", "--trials", "1", "--episodes", "2", "--seed", str(2**70), "--out", str(out), "--no-progress"],
        capture_output=True, text=True, timeout=300)
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert f"run: seed: the integer {2**70} is too large" in result.stderr
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize(("arrays", "says"), [
    ({"latent": np.zeros((1, 4)), "latent_paths": np.zeros(24)}, r"latent_paths: expected real numbers of shape \(trials, episodes"),
    ({"latent": np.zeros((1, 4)).astype(str)}, r"latent: expected real numbers .* got <U32"),
    ({"latent": np.zeros((1, 4)), "latent_weights": np.zeros((2, 9))}, "latent_weights has 2 trials, 'latent' 1"),
    ({"preset_json": np.array("{}")}, "no array 'latent'"),
])
def test_replay_refuses_run_arrays_of_another_shape_naming_the_file_and_array(arrays: dict[str, np.ndarray], says: str) -> None:
    """Issue #38: a flattened `latent_paths` in returns.npz was an IndexError traceback in `latentrl replay`."""
    with pytest.raises(ValueError, match=rf"^run/returns\.npz: .*{says}"):
        check_replay_arrays(Path("run/returns.npz"), arrays)


@pytest.mark.parametrize(("paths", "says"), [
    (None, "no array 'greedy_paths'"),
    (np.zeros(10), r"greedy_paths: expected floats of shape \(trials 1"),
    (np.full((1, 2, 5, 3), np.nan), "greedy_paths: episode 0 of trial 0 has no finite stored step"),
])
def test_replay_of_a_rollout_refuses_broken_paths_naming_rollout_npz(policy_file: Path, tmp_path: Path, paths: np.ndarray | None,
                                                                     says: str) -> None:
    """Issue #38: `latentrl replay` of a rollout whose rollout.npz lost its paths was a KeyError
    traceback; NaN paths said "need at least one array to stack"."""
    (tmp_path / "rollout.json").write_text(json.dumps({"trials": [0], "greedy": {}, "policy": str(policy_file)}))
    np.savez(tmp_path / "rollout.npz", **({} if paths is None else {"greedy_paths": paths}), other=np.zeros(1))
    with pytest.raises(ValueError, match=rf"rollout\.npz: {says}"):
        rollout_episode(tmp_path, "greedy", 0, 0)


@pytest.mark.parametrize("action", [np.full(3, np.nan), np.zeros(2), [0.1, "x", 0.2]])
def test_a_task_env_refuses_an_action_that_is_not_its_joints_finite_values(action: object) -> None:
    """Issue #38: `TaskEnv.step` clipped a NaN action to NaN and stepped without a word; an action
    of another length failed in NumPy's broadcasting, naming nothing."""
    from latentrl import Task
    from latentrl.envs import TaskEnv

    env = TaskEnv(Task.load(EXAMPLE / "glass_arm.toml"))
    env.reset(seed=0)
    with pytest.raises(ValueError, match=r"^action: expected 3 finite numbers"):
        env.step(action)  # type: ignore[arg-type]


def test_a_video_that_cannot_be_written_names_its_file(tmp_path: Path) -> None:
    """Issue #38: `latentrl replay --out` on a full disk said only "[Errno 28] No space left on device"."""
    import errno

    from latentrl import replay

    def frames_on_a_full_disk() -> Iterator[np.ndarray]:  # the write fails while the frames stream in
        yield np.zeros((2, 2, 3), np.uint8)
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError, match=rf"cannot write {re.escape(str(tmp_path / 'v.gif'))}: No space left on device"):
        replay.write_video(frames_on_a_full_disk(), tmp_path / "v.gif", 10)
    assert list(tmp_path.iterdir()) == []


def test_a_task_from_a_list_is_a_type_error_naming_its_origin() -> None:
    """Issue #38: `Task.from_dict([1, 2], …)` said "cannot convert dictionary update sequence element #0"."""
    from latentrl import Task

    with pytest.raises(TypeError, match=r"^keys\.toml: expected a table of task keys \(a dict\), got list"):
        Task.from_dict([1, 2], EXAMPLE, "keys.toml")  # type: ignore[arg-type]


def test_demos_in_degrees_are_refused_naming_the_file_posture_and_joint(tmp_path: Path) -> None:
    """Issue #38: postures at 9 rad (limits ±3.1) ended in "latent_high[1] = 0 must exceed
    latent_low[1] = 0", naming neither the demo file nor the joint."""
    lines = (EXAMPLE / "demos.csv").read_text().splitlines()
    header, rows = lines[0], [list(map(float, line.split(","))) for line in lines[1:]]
    rows[3][1] = 9.0
    demos = tmp_path / "demos.csv"
    demos.write_text("\n".join([header, *(",".join(map(repr, r)) for r in rows)]) + "\n")
    joint = header.split(",")[1]
    out = tmp_path / "out"
    for command in ("train", "check"):
        result = subprocess.run(
            [sys.executable, "-m", "latentrl", command, str(EXAMPLE / "glass_arm.toml"), "--demos", str(demos), "--quick",
             "--no-progress", *(["--out", str(out)] if command == "train" else [])],
            capture_output=True, text=True, timeout=300)
        assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
        assert f"{demos}: posture 3 (counting from 0) has {joint} = 9" in result.stderr
        assert "look like degrees" in result.stderr
    assert not out.exists() or not any(out.iterdir())


def test_a_full_disk_names_the_file_and_a_new_run_leaves_no_folder(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    """Issue #38's probe: `latentrl train --out` on a full disk said "[Errno 28] No space left on
    device" without the file and left a run folder holding gplvm.npz and no trial."""
    import errno

    from latentrl import _persistence, cli

    def full(fh: object) -> None:
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError, match=r"cannot write .*results\.json: No space left on device"):
        _persistence.atomic_write(tmp_path / "results.json", full)
    assert list(tmp_path.iterdir()) == []  # the temporary file is gone too

    from latentrl import results

    monkeypatch.setattr(results, "atomic_write",
                        lambda path, write: _persistence.atomic_write(path, full if Path(path).name == "results.json" else write))
    out = tmp_path / "run"
    code = cli.main(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--quick",
                     "--trials", "1", "--episodes", "2", "--test-episodes", "0", "--no-progress", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and f"cannot write {out / 'results.json'}: No space left on device" in err, err
    assert not out.exists(), (err, sorted(p.name for p in out.iterdir()))

    # The disk full only when the figures are drawn: the run is saved, and the message says how to
    # draw them again.
    from latentrl import plots

    monkeypatch.setattr(results, "atomic_write", _persistence.atomic_write)
    monkeypatch.setattr(plots, "atomic_write", lambda path, write: _persistence.atomic_write(path, full))
    code = cli.main(["train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"), "--quick",
                     "--trials", "1", "--episodes", "2", "--test-episodes", "0", "--no-progress", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == 1 and f"the run's results are saved in {out}: `latentrl plot {out}`" in err, err
    assert (out / "results.json").exists() and (out / "returns.npz").exists()


@pytest.mark.parametrize("argv0", ["/usr/local/bin/latentrl", "my_script.py"])
def test_ctrl_c_while_the_command_imports_is_its_own_message(argv0: str) -> None:
    """Issue #38's probe: SIGINT in a command's first ~0.3 s, while Python still imported latentrl,
    printed the interpreter's KeyboardInterrupt traceback. Here the interrupt lands inside
    `import latentrl` (an import hook raises it at `latentrl.gplvm`): the `latentrl` command says
    it was interrupted and exits 130; any other program gets its KeyboardInterrupt as ever."""
    child = f"""
import sys
class Interrupt:
    def find_spec(self, name, path=None, target=None):
        if name == "latentrl.gplvm":
            raise KeyboardInterrupt
sys.meta_path.insert(0, Interrupt())
sys.argv[0] = {argv0!r}
import latentrl
"""
    result = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True, timeout=120)
    if argv0.endswith("latentrl"):
        assert (result.returncode, result.stderr) == (130, "latentrl: interrupted; nothing was written\n")
    else:
        assert result.returncode != 0 and "Traceback" in result.stderr and "KeyboardInterrupt" in result.stderr


def test_degrees_given_for_demos_in_radians_are_refused(tmp_path: Path) -> None:
    """`--degrees` on a demo file already in radians shrank every motion 57-fold and trained on
    it without a word (exit 0); a file in degrees is refused offering `--degrees`."""
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, "-m", "latentrl", "train", str(EXAMPLE / "glass_arm.toml"), "--demos", str(EXAMPLE / "demos.csv"),
         "--degrees", "--quick", "--no-progress", "--out", str(out)], capture_output=True, text=True, timeout=300)
    assert result.returncode == 1 and "Traceback" not in result.stderr, result.stderr
    assert f"{EXAMPLE / 'demos.csv'}: --degrees (degrees=True) was given, but no value lies beyond ±2π" in result.stderr
    assert "look like radians already" in result.stderr and not out.exists()
    lines = (EXAMPLE / "demos.csv").read_text().splitlines()
    degrees = [lines[0], *(",".join(repr(float(np.degrees(float(v)))) for v in line.split(",")) for line in lines[1:])]
    (tmp_path / "deg.csv").write_text("\n".join(degrees) + "\n")
    with pytest.raises(ValueError, match=r"look like degrees; give --degrees \(degrees=True\)"):
        Task.load(EXAMPLE / "glass_arm.toml").demo_postures(tuple(lines[0].split(",")),
                                                             load_demos(tmp_path / "deg.csv").postures, "deg.csv")
    assert load_demos(tmp_path / "deg.csv", degrees=True).postures == pytest.approx(load_demos(EXAMPLE / "demos.csv").postures)


def test_a_write_to_a_read_only_folder_names_the_file_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """On a read-only file system the cleanup's unlink of the temporary file (missing) raised
    EROFS itself, so `latentrl plot` into a read-only run folder said "Read-only file system:
    '…/.returns.png.<hex>.tmp'", naming a file the user never asked for."""
    import errno

    from latentrl._persistence import atomic_path, atomic_write

    def read_only(self: Path, missing_ok: bool = False) -> None:
        raise OSError(errno.EROFS, "Read-only file system", str(self))

    def fail(fh: object) -> None:
        raise OSError(errno.EROFS, "Read-only file system")

    monkeypatch.setattr(Path, "unlink", read_only)
    target = tmp_path / "returns.png"
    with pytest.raises(OSError, match=f"^\\[Errno 30\\] cannot write {re.escape(str(target))}: Read-only file system$"):
        atomic_write(target, fail)
    with pytest.raises(OSError, match=f"cannot write {re.escape(str(target))}: Read-only file system$"):
        with atomic_path(target):
            fail(None)
