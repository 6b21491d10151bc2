"""The core of latentrl without matplotlib (the `[plot]` extra): models, envs, training,
`latentrl fit` and `latentrl train` (all but its figures, which it says how to draw) work;
figures and `render_mode="rgb_array"` fail with a message naming the extra. Run as a script (by `tests/test_optional_deps.py` and `make install-check`); it hides
matplotlib itself, so it means the same in an environment that has it."""

from __future__ import annotations

import contextlib
import io
import sys
import tempfile
from pathlib import Path


class _HideMatplotlib:
    def find_spec(self, name: str, path: object = None, target: object = None) -> None:
        if name.split(".")[0] == "matplotlib":
            raise ModuleNotFoundError(f"No module named {name!r}", name=name)


def main() -> None:
    sys.meta_path.insert(0, _HideMatplotlib())
    import gymnasium as gym
    import numpy as np

    import latentrl.envs  # noqa: F401  (registers the envs)
    from latentrl import GPLVM, Demonstrations, Task, save_demos
    from latentrl.cli import main as cli
    from latentrl.datasets import arm_postures
    from latentrl import train_latent_policy

    model = GPLVM(n_components=2, max_iter=20, random_state=0).fit(arm_postures(30, np.random.default_rng(0)))
    policy = train_latent_policy(
        model, trials=1, episodes=2, test_episodes=0, overrides={"episode.max_steps": 10}
    )
    assert policy.returns.shape == (1, 2) and np.isfinite(policy.returns).all()
    env = gym.make("latentrl/TwoArms-v0")
    env.reset(seed=0)
    env.step(env.action_space.sample())
    try:
        gym.make("latentrl/TwoArms-v0", render_mode="rgb_array")
        raise AssertionError("render_mode='rgb_array' worked without matplotlib")
    except ModuleNotFoundError as err:
        assert "latentrl[plot]" in str(err), err
    with tempfile.TemporaryDirectory() as tmp:
        demos = Path(tmp) / "demos.csv"
        save_demos(Demonstrations(arm_postures(20, np.random.default_rng(1)), Task.shipped("two_arms").joint_names), demos)
        with contextlib.redirect_stdout(io.StringIO()):
            assert cli(["fit", str(demos), "--out", str(Path(tmp) / "m.npz"), "--max-iter", "10"]) == 0
        example, run = Path(__file__).resolve().parents[1] / "examples" / "glass_arm", Path(tmp) / "train"
        stderr = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(stderr):
            code = cli(["train", str(example / "glass_arm.toml"), "--demos", str(example / "demos.csv"), "--quick",
                        "--episodes", "10", "--trials", "1", "--no-progress", "--out", str(run)])
        assert code == 0 and (run / "policy.npz").is_file() and (run / "report.json").is_file(), stderr.getvalue()
        assert not list(run.glob("*.png")), "figures without matplotlib"
        assert f"pip install 'latentrl[plot]', then latentrl plot {run} draws them" in stderr.getvalue()
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            code = cli(["run", "exp2", "--quick", "--out", str(Path(tmp) / "run")])
        assert code == 1 and "pip install 'latentrl[plot]'" in stderr.getvalue(), (code, stderr.getvalue())
        assert not (Path(tmp) / "run").exists(), "the run started although it could not draw its figures"
    assert not any(name.split(".")[0] == "matplotlib" for name in sys.modules)
    print("core without matplotlib: ok")


if __name__ == "__main__":
    main()
