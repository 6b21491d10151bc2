"""Every task parameter's bad value gets one message naming it as the user wrote it (issue #16),
whichever way it came in: a task-file override in Python, a `--table.key` flag of `latentrl
train` (exit 1 before any fit; nothing written), an Exp 2 preset. The cases are generated from
the native schema, so a parameter added in Rust is tested here without a line changed."""

from __future__ import annotations

import math
import re
from typing import Any

import numpy as np
import pytest

from latentrl import Task, cli
from latentrl.demos import Demonstrations, save_demos
from latentrl.envs import shipped_demos
from latentrl.experiments.exp2 import Exp2Preset
from latentrl.run_settings import with_overrides
from latentrl.task import schema

SHIPPED_TABLES = {"floor": "humanoid_lift", "fall": "humanoid_lift"}
"""Tables only one shipped task has; every other scalar key is tried on two_arms."""


def out_of_range(rule: str, kind: str) -> Any:
    """A value the rule refuses, read off the rule's text."""
    if m := re.search(r"in [\[(](-?[\d.e+]+), (-?[\d.e+]+)[\])]", rule):
        low, high = float(m.group(1)), float(m.group(2))
        if kind == "int":  # below 0 an unsigned key is refused by its type, not its rule
            return int(low) - 1 if low >= 1 else int(high) + 1
        return low - 1.0
    if "> 0" in rule or ">= 0" in rule:
        return -1.0
    return None


def cases() -> list[tuple[str, Any, str]]:
    """(key, bad value, what the message says) for every scalar key of a task file."""
    out = []
    for row in schema():
        key, kind, rule = row["key"], row["kind"], row["rule"]
        if "." not in key or "[]" in key or "NAME" in key or kind.startswith(("table", "list")) or "floats" in kind:
            continue
        choice = " | " in kind
        text = kind.split()[0] == "str"  # "str" or "str or none"
        out.append((key, 3.5 if text else "not a number", "unknown variant" if choice else "invalid type"))
        if kind.startswith("float"):
            out.append((key, math.nan, "got NaN"))
        bad = out_of_range(rule, kind.split()[0])
        if bad is not None:
            out.append((key, bad, re.escape(rule)))
    return out


CASES = cases()


def task_for(key: str) -> str:
    return SHIPPED_TABLES.get(key.partition(".")[0], "two_arms")


def test_every_scalar_key_has_cases():
    keys = {key for key, _, _ in CASES}
    assert {"learner.alpha", "learner.rbf_per_dim", "episode.max_steps", "physics.dt", "fall.max_tilt"} <= keys
    assert len(keys) >= 35, sorted(keys)


@pytest.mark.parametrize(("key", "value", "says"), CASES, ids=[f"{k}={v!r}" for k, v, _ in CASES])
def test_a_task_override_names_the_key_and_the_rule(key, value, says):
    with pytest.raises(ValueError, match=rf"{re.escape(key)}\b.*{says}|{says}.*{re.escape(key)}"):
        Task.shipped(task_for(key)).replace({key: value})


@pytest.mark.parametrize("key", ["servo.kp", "servo.kd", "physics.joint_damping"])
def test_a_gain_beyond_f32_is_refused_not_made_infinite(key):
    """Issue #38: rapier stores gains as f32; 1e300 passed as finite and became inf there."""
    with pytest.raises(ValueError, match=rf"{re.escape(key)}\b.*must lie in \[0, 3.4028234663852886e38\], got 1e300$"):
        Task.shipped("two_arms").replace({key: 1e300})
    assert Task.shipped("two_arms").replace({key: 1e30}).to_dict()[key.split(".")[0]][key.split(".")[1]] == 1e30


FLAG_CASES = [(k, v, s) for k, v, s in CASES if not isinstance(v, str) and s != "invalid type"]
"""The cases a flag can carry: argparse refuses a word where a number goes (exit 2, naming the
flag), and a number given to a text key's flag is that text."""


@pytest.fixture(scope="module")
def demo_files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("demos")
    files = {}
    for name in ("two_arms", "humanoid_lift"):
        files[name] = folder / f"{name}.csv"
        save_demos(Demonstrations(shipped_demos(name), Task.shipped(name).joint_names), files[name])
    return files


@pytest.mark.parametrize(("key", "value", "says"), FLAG_CASES, ids=[f"{k}={v!r}" for k, v, _ in FLAG_CASES])
def test_a_train_flag_exits_1_naming_the_flag_before_any_work(key, value, says, demo_files, tmp_path, capsys):
    table, _, name = key.partition(".")
    flag = f"--{name.replace('_', '-')}" if table == "run" else f"--{table}.{name.replace('_', '-')}"  # [run]: preset flags
    name_ = task_for(key)
    out = tmp_path / "run"
    code = cli.main(["train", str(Task.shipped(name_).urdf_path.parent.parent / "tasks" / f"{name_}.toml"),
                     "--demos", str(demo_files[name_]), "--out", str(out), "--no-progress", flag, str(value)])
    err = capsys.readouterr().err
    assert code == 1, err
    assert err.startswith("latentrl: error:") and "Traceback" not in err
    assert re.search(rf"{re.escape(key)}\b.*{says}", err), err
    assert not out.exists(), "nothing is written for a bad value"


@pytest.mark.parametrize("key", ["learner.alpha", "learner.gamma", "learner.rbf_per_dim", "episode.max_steps"])
def test_a_preset_override_gives_the_same_message(key):
    value, says = next((v, s) for k, v, s in FLAG_CASES if k == key)
    with pytest.raises(ValueError) as caught:
        with_overrides(Exp2Preset.quick(), {key: value}).validate()
    with pytest.raises(ValueError) as direct:
        Task.shipped("two_arms").replace({key: value})
    assert re.search(rf"{re.escape(key)}\b.*{says}", str(caught.value))
    assert str(direct.value).split(": ")[-1] == str(caught.value).split(": ")[-1]


def test_the_cases_are_really_refused_values():
    """A case that the rule accepts would make the tests above pass for the wrong reason."""
    arms = Task.shipped("two_arms")
    assert np.isclose(arms.replace({"learner.alpha": 0.5}).to_dict()["learner"]["alpha"], 0.5)
    assert out_of_range("must lie in (0, 1]", "float") == -1.0
    assert out_of_range("must be an integer in [2, 10000]", "int") == 1
    assert out_of_range("must be an integer in [0, 1000000]", "int") == 1000001
