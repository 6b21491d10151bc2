"""A tiny `latentrl train` run folder (with a `latentrl rollout` beside it) and every reader of its
files, and the Hypothesis strategies that mutate one of them (`json_mutations`, `npz_mutations`),
for the run-folder fuzzers (issue #38): `tests/test_fuzz.py` and `fuzz/fuzz_run_folder.py`
(atheris) mutate one file of the folder and read it back (`read_mutated`).

The property both check: each reader reads the file or refuses it with a ValueError or OSError
(the project's errors are ValueError subclasses) whose message names the file; never another
exception, a hang, or NaN where the run stored finite numbers."""

from __future__ import annotations

import contextlib
import dataclasses
import io
import json
import math
import shutil
import warnings
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
from hypothesis import event
from hypothesis import strategies as st

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"

#: The files of the folder the fuzzers mutate, relative to its root: the run's (`out/`) and the
#: rollout's (`rollout/`).
FILES = ("out/results.json", "out/returns.npz", "out/gplvm.npz", "out/policy.npz", "rollout/rollout.json",
         "rollout/rollout.npz")


def train_run(root: Path) -> Any:
    """The `TrainRun` of the folder under `root` (its inputs copied there)."""
    from latentrl.experiments.training import TrainRun

    inputs = root / "inputs"
    return dataclasses.replace(TrainRun.quick(), trials=1, episodes=3, test_episodes=1,
                               task={"episode.max_steps": 10}, task_file=str(inputs / "glass_arm.toml"),
                               demos=str(inputs / "demos.csv"))


def make_folder(root: Path) -> Path:
    """Under `root`: `inputs/` (the glass arm's task, URDF and demos), `out/` (a train run of one
    trial of 3 episodes and one test episode, without its figures: results.json, returns.npz,
    gplvm.npz, policy.npz) and `rollout/` (2 episodes of each policy: rollout.json, rollout.npz).
    About 3 s."""
    from latentrl.cli import main
    from latentrl.experiments.runner import run_rl
    from latentrl.experiments.training import save_policy, setup

    (root / "inputs").mkdir(parents=True)
    for name in ("glass_arm.toml", "glass_arm.urdf", "demos.csv"):
        shutil.copy(EXAMPLE / name, root / "inputs" / name)
    run = train_run(root)
    run_rl(run, root / "out", setup=setup, figures=lambda *_: None, progress=False)
    save_policy(run, root / "out")
    with contextlib.redirect_stdout(io.StringIO()):
        code = main(["rollout", str(root / "out"), "--out", str(root / "rollout"), "--episodes", "2", "--no-progress"])
    assert code == 0
    return root


def read_file(root: Path, name: str, *, draw: bool = False) -> None:
    """Every reader of the file `name` (one of FILES) of the folder under `root`, as the commands
    that read it call them; with `draw`, also what `replay` computes from what it read before
    drawing (the latent path, the links' poses: ~0.5 s an episode, in the GP encoder)."""
    from latentrl.saved_runs import saved_run
    from latentrl.experiments.run_folder import RunFolder
    from latentrl.experiments.training import setup
    from latentrl.replay import replay, rollout_episode
    from latentrl.train import LatentPolicy

    out = root / "out"
    run = train_run(root)
    if name == "rollout/rollout.json" or name == "rollout/rollout.npz":
        with contextlib.ExitStack() as stack:
            if not draw:
                stack.enter_context(_patched("robot_episode", _no_robot_episode))
            for policy in ("greedy", "random"):
                drawn = rollout_episode(root / "rollout", policy, 0, 1)
                assert drawn is None or np.isfinite(drawn.latent).all() and np.isfinite(drawn.poses).all()
        return
    if name == "out/policy.npz":
        policy = LatentPolicy.load(out / "policy.npz")
        policy.end_counts()
        assert np.isfinite(policy.weights).all() and np.isfinite(policy.latent_low).all()
        return
    # results.json, returns.npz, gplvm.npz: as `train --resume` reads them (runner.run_rl) …
    folder = RunFolder(out)
    folder.preset(), folder.recorded_task(), folder.recorded_inputs()
    arrays, meta = folder.previous(run)
    built = setup(run, out)
    if meta is not None:
        folder.check_continued(meta, built.learners, built.info, arrays)
    folder.finished()
    # … and as `replay` does (cli_commands._replay, replay.replay), short of rendering
    experiment, preset = saved_run(out, train=True)
    with contextlib.ExitStack() as stack:
        stack.enter_context(_patched("render", lambda drawn, *_, **__: _check_drawn(drawn)))
        if not draw:
            stack.enter_context(_patched("recorded", _recorded_not_drawn))
        for episode, test in ((2, None), (None, 0)):
            replay(out, experiment, preset, root / "episode.gif", episode=episode, test=test)


def _check_drawn(drawn: Any) -> str:
    """What `replay.render` is given: finite paths (None: `_recorded_not_drawn`'s)."""
    assert drawn is None or np.isfinite(drawn.latent).all() and np.isfinite(drawn.poses).all()
    return "checked"


def _recorded_not_drawn(experiment: str, preset: Any, run_dir: Path, rows: Any, weights: Any, *_: Any) -> None:
    """`replay.recorded` short of the latent path and the links' poses: the run's setup read."""
    from latentrl.replay import run_setup

    _, _, (low, high) = run_setup(experiment, preset, run_dir)
    assert all(np.isfinite(a).all() for a in (low, high, rows, weights))


def _no_robot_episode(task: Any, model: Any, low: Any, high: Any, rows: Any, weights: Any, *_: Any, **__: Any) -> None:
    """`replay.robot_episode` short of the latent path and the links' poses."""
    assert all(np.isfinite(a).all() for a in (low, high, rows, weights))


@contextlib.contextmanager
def _patched(name: str, replacement: Any) -> Iterator[None]:
    """`latentrl.replay.<name>` replaced while inside."""
    from latentrl import replay

    original = getattr(replay, name)
    setattr(replay, name, replacement)
    try:
        yield
    finally:
        setattr(replay, name, original)


def read_mutated(root: Path, name: str, mutated: bytes, original: bytes, *, draw: bool = False) -> str:
    """`read_file` (with `draw`) of the folder under `root` with the file `name` holding `mutated`
    (`original` restored after): "read", or the name of the ValueError/OSError it was refused with, whose
    message must name the file or its folder. Anything else propagates."""
    path = root / name
    try:
        path.write_bytes(mutated)
        read_file(root, name, draw=draw)
        return "read"
    except (ValueError, OSError) as err:
        assert path.name in str(err) or str(path.parent) in str(err), f"{type(err).__name__} names no file: {err}"
        return type(err).__name__
    finally:
        path.write_bytes(original)


#: What a JSON value or an array element may become.
ODD_VALUES = st.sampled_from([
    None, True, -1, 0, 2**70, -(10**400), 1e308, -1e308, math.nan, math.inf, 1e-320, "", "x", "results.json", [],
    [1.0, "a"], {}, {"": None}, [[[]]],
])


@st.composite
def json_mutations(draw: st.DrawFn, text: str) -> bytes:
    """`text` (a JSON object) with one value somewhere inside it deleted, retyped, nested or
    replaced by an odd value, or its bytes cut or flipped."""
    how = draw(st.sampled_from(["delete", "replace", "nest", "top", "truncate", "flip"]))
    if how == "truncate":
        return text.encode()[: draw(st.integers(0, len(text) - 1))]
    if how == "flip":
        blob = bytearray(text.encode())
        for _ in range(draw(st.integers(1, 4))):
            blob[draw(st.integers(0, len(blob) - 1))] = draw(st.integers(0, 255))
        return bytes(blob)
    doc = json.loads(text)
    if how == "top":
        doc = draw(st.sampled_from([[doc], None, 3, "x", []]))
        return json.dumps(doc).encode()
    parent: Any = doc
    for _ in range(draw(st.integers(0, 4))):  # down a random path into the document
        children = list(parent.items()) if isinstance(parent, dict) else list(enumerate(parent))
        children = [(k, v) for k, v in children if isinstance(v, (dict, list)) and v]
        if not children:
            break
        parent = draw(st.sampled_from(children))[1]
    if not parent:
        return json.dumps(doc).encode()
    key = draw(st.sampled_from(sorted(parent) if isinstance(parent, dict) else range(len(parent))))
    event(f"json {how} {key}")
    if how == "delete":
        del parent[key]
    elif how == "nest":
        parent[key] = draw(st.sampled_from([[parent[key]], {"value": parent[key]}]))
    else:
        parent[key] = draw(ODD_VALUES)
    return json.dumps(doc, allow_nan=True).encode()


@st.composite
def npz_mutations(draw: st.DrawFn, blob: bytes) -> bytes:
    """The NPZ file `blob` with one array dropped, renamed, retyped, reshaped or given odd
    values, an array added, or its bytes cut or flipped."""
    how = draw(st.sampled_from(["drop", "rename", "dtype", "shape", "values", "add", "truncate", "flip"]))
    if how == "truncate":
        return blob[: draw(st.integers(0, len(blob) - 1))]
    if how == "flip":
        flipped = bytearray(blob)
        for _ in range(draw(st.integers(1, 4))):
            flipped[draw(st.integers(0, len(flipped) - 1))] = draw(st.integers(0, 255))
        return bytes(flipped)
    with np.load(io.BytesIO(blob)) as npz:
        arrays = {k: npz[k] for k in npz.files}
    key = draw(st.sampled_from(sorted(arrays)))
    value = arrays[key]
    event(f"npz {how} {key}")
    if how == "drop":
        del arrays[key]
    elif how == "rename":
        arrays[key + draw(st.sampled_from(["_", "x", ".0"]))] = arrays.pop(key)
    elif how == "add":
        arrays[draw(st.sampled_from(["extra", "latent_x", "record.extra", "model.extra", "greedy_more"]))] = value
    elif how == "dtype":
        kind = draw(st.sampled_from(["f4", "f8", "i1", "i8", "u8", "?", "c16", "U3", "S2", "V8"]))
        try:
            with np.errstate(all="ignore"), warnings.catch_warnings():  # NaN as an int, 1e300 as f4
                warnings.simplefilter("ignore")
                arrays[key] = value.astype(kind)
        except (TypeError, ValueError):  # a string array as numbers, numbers as V8
            arrays[key] = np.zeros(value.shape, dtype=kind)
    elif how == "shape":
        shape = draw(st.sampled_from(["flat", "scalar", "empty", "extra axis", "transpose", "first"]))
        if shape == "flat":
            arrays[key] = value.reshape(-1)
        elif shape == "scalar":
            arrays[key] = np.asarray(value.reshape(-1)[0] if value.size else 0)
        elif shape == "empty":
            arrays[key] = value[:0] if value.ndim else value.reshape(1)[:0]
        elif shape == "extra axis":
            arrays[key] = value[None]
        elif shape == "transpose":
            arrays[key] = value.T
        else:
            arrays[key] = value[:1] if value.ndim else value
    elif value.dtype.kind in "biuf" and value.size:
        odd = draw(st.sampled_from([math.nan, math.inf, -math.inf, 1e300, -1.0, 99.0, 0.0, 2.0**63]))
        changed = value.astype(np.float64) if value.dtype.kind in "biu" and not math.isfinite(odd) else value.copy()
        with np.errstate(all="ignore"):
            flat = changed.reshape(-1)
            flat[draw(st.integers(0, flat.size - 1))] = odd if changed.dtype.kind == "f" else int(np.clip(odd, -128, 127))
        arrays[key] = changed
    else:  # a string: another one
        arrays[key] = np.array(draw(st.sampled_from(["", "x", "{", "[]", "null", "latentrl.GPLVM"])))
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()


