"""`latentrl.train`: the README tutorial as written, the humanoid task, bad input."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from latentrl import GPLVM, PCA, _native
from latentrl.datasets import arm_postures
from latentrl.experiments import exp2
from latentrl.train import train_latent_policy

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


def test_joint_names_are_the_urdf_ones() -> None:
    sim = _native.Sim(exp2.urdf_path())
    assert tuple(sim.joint_names) == exp2.JOINT_NAMES


@pytest.fixture(scope="module")
def arms_model() -> GPLVM:
    return GPLVM(n_components=2, max_iter=50, random_state=0).fit(arm_postures(40, np.random.default_rng(1)))


def test_same_seed_same_policy_and_value_matches_weights(arms_model: GPLVM) -> None:
    runs = [train_latent_policy(arms_model, trials=2, episodes=3, steps=50, test_episodes=0, seed=s) for s in (4, 4, 5)]
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
    with pytest.raises(ValueError, match="trial must be in 0..1"):
        policy.value(arms_model.Z_, trial=2)


def test_humanoid_task_runs() -> None:
    from latentrl.experiments.exp3 import Exp3Preset, fit

    model = fit(Exp3Preset.quick()).model
    policy = train_latent_policy(model, "humanoid_lift", trials=1, episodes=2, steps=10, test_episodes=0)
    assert policy.returns.shape == (1, 2)
    assert np.isfinite(policy.returns).all()
    assert policy.weights.shape == (1, 400)
    few = GPLVM(n_components=2, max_iter=20, random_state=0).fit(model.X_train_[:5])
    with pytest.raises(ValueError, match="start_demo=6 is not a row of the model's 5 postures"):
        train_latent_policy(few, "humanoid_lift", start_demo=6)


@pytest.mark.parametrize(
    ("kwargs", "error", "message"),
    [
        ({"task": "walk"}, ValueError, "task must be one of"),
        ({"preset": "huge"}, ValueError, "preset must be 'quick' or 'paper'"),
        ({"episodes_per_trial": 3}, ValueError, "unknown preset fields"),
        ({"episodes": 0}, ValueError, "episodes must be an int >= 1"),
        ({"task": "humanoid_lift"}, ValueError, "humanoid_lift needs a GPLVM with n_components=2 fitted to postures of its 19"),
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
    with pytest.raises(ValueError, match="n_components=3"):
        train_latent_policy(three)
