"""The results layout of a run (docs/method.md §Results layout): metadata JSON and per-episode
NPZ, written atomically and read back bounded; what results.json, returns.npz and gplvm.npz hold
(the keys of the arrays, rows of trials not run yet, each trial's summary, the fit and the
machine). A run's folder read back as one object is `latentrl.experiments.run_folder`."""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from latentrl._persistence import NAME_KEPT, atomic_write
from latentrl._files import MAX_JSON_BYTES, read_text
from latentrl.machine import machine
from latentrl.task import end_counts

if TYPE_CHECKING:  # the GPLVM (and SciPy) load with the first fit, not with `--help`
    from latentrl.gplvm import GPLVM

RESULTS_FORMAT = 1
"""Version of the results layout; bumped when a file changes meaning."""


def remove_stale_temporaries(path: Path) -> None:
    """Deletes temporary files that `atomic_write` left beside `path` when a process was killed
    while writing it (the file itself is always whole: the old or the new version)."""
    for stale in path.parent.glob(f".{path.name[:NAME_KEPT]}.*.tmp"):
        stale.unlink(missing_ok=True)


def write_json(path: Path, payload: Mapping[str, Any]) -> None:
    """Atomic, indented JSON; NumPy scalars and arrays become plain numbers and lists."""
    text = json.dumps(payload, indent=2, default=_to_plain, allow_nan=True)
    atomic_write(path, lambda f: f.write(text.encode()))


def as_saved(value: Any) -> Any:
    """`value` as `write_json` stores it and `read_json` gives it back (NumPy values, dataclasses
    and paths made plain): the form a saved run is compared in."""
    return json.loads(json.dumps(value, default=_to_plain, allow_nan=True))


def write_npz(path: Path, arrays: Mapping[str, np.ndarray]) -> None:
    """Atomic compressed NPZ."""
    # numpy's stub types **kwds as if a key could be `allow_pickle`; ours are array names.
    atomic_write(path, lambda f: np.savez_compressed(f, **arrays))  # type: ignore[arg-type]


def read_json(path: Path) -> dict[str, Any]:
    """A results JSON, or a ValueError naming the file if it is not one (or not a regular file of
    at most `MAX_JSON_BYTES`)."""
    try:
        payload = json.loads(read_text(path, MAX_JSON_BYTES, "a JSON file of a run"))
    except json.JSONDecodeError as err:
        raise ValueError(f"{path}: not valid JSON ({err})") from err
    except RecursionError:
        raise ValueError(f"{path}: nested too deeply to be a latentrl file") from None
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None
    if not isinstance(payload, dict):
        raise ValueError(f"{path}: expected a JSON object at the top level")
    return payload


RESULTS_OBJECTS = {"": ("preset", "setup", "trials", "environment"), "setup.": ("task", "gplvm", "inputs", "latent_box"),
                   "preset.": ("task",)}
"""The parts of a results.json that readers use, by where they sit: each must be a JSON object."""


def read_results(path: Path) -> dict[str, Any]:
    """A run's results.json (`read_json`) whose parts in `RESULTS_OBJECTS` are objects and whose
    recorded input digests are strings: a ValueError naming the file and the field otherwise."""
    meta = read_json(path)
    for prefix, keys in RESULTS_OBJECTS.items():
        parent = meta.get(prefix[:-1], {}) if prefix else meta
        for key in keys:
            if key in parent and not isinstance(parent[key], dict):
                raise ValueError(f"{path}: {prefix}{key} must be a JSON object, got {type(parent[key]).__name__}")
    inputs = meta.get("setup", {}).get("inputs", {})
    bad = [name for name, digest in inputs.items() if not isinstance(digest, str)]
    if bad:
        raise ValueError(f"{path}: setup.inputs[{bad[0]!r}] must be a SHA-256 string")
    return meta


# --- what returns.npz and gplvm.npz hold -----------------------------------------------------

PER_EPISODE = {
    "returns": "",
    "ends": "_end",
    "steps": "_steps",
    "reached": "_reached",
    "passed": "_passed",
}
"""Per-episode arrays of the native call, each (trials, episodes), and the suffix of their
key in returns.npz after the learner's name (docs/method.md §Results layout: `latent`, `latent_end`,
…)."""

PER_TRIAL = {
    "test_returns": "_test",
    "test_ends": "_test_end",
    "test_steps": "_test_steps",
    "test_reached": "_test_reached",
    "test_passed": "_test_passed",
    "trajectories": "_paths",
    "test_trajectories": "_test_paths",
    "test_start_hands": "_test_start_hands",
    "mean_states": "_mean_state",
    "weights": "_weights",
}
"""Further per-trial arrays of the native call (frozen test episodes (trials, K), recorded
paths, the effectors' (x, y, z) at the start of every test episode (trials, K, 3E), the
learner's mean state over every training episode (trials, episodes, d), final weights) and
their suffix in returns.npz; stored when the call returns them with a non-empty per-trial
part."""


def array_key(learner: str, what: str) -> str:
    """Key in returns.npz of a learner's array `what` (see PER_EPISODE and PER_TRIAL)."""
    return learner + {**PER_EPISODE, **PER_TRIAL}[what]


PRESET_KEY = "preset_json"
"""Key in returns.npz of the preset the arrays were computed with (JSON): `--resume` refuses a
results.json whose preset was edited since."""

MODEL_FILE = "gplvm.npz"
"""A run's GPLVM in its results directory (`GPLVM.save`): what its figures, replays and resumes
decode with, since a refit on another CPU or BLAS can give another latent space."""


def gplvm_info(model: GPLVM) -> dict[str, Any]:
    """The fitted GPLVM's objective, hyper-parameters and convergence, for results.json."""
    return {
        "nll": model.nll_,
        "theta": model.theta_,
        "converged": model.converged_,
        "n_iter": model.n_iter_,
        "encoder": model.fitted_encoder_,
        "encoder_theta": model.encoder_theta_,
    }


def finished_trials(arrays: Mapping[str, np.ndarray]) -> tuple[dict[str, np.ndarray], dict[str, int]]:
    """The rows of finished trials only, learner by learner (a partial run's unrun trials are
    NaN or −1), and how many each learner has. Learners with none are left out. A ValueError
    naming the array if a learner's end codes are not (trials, episodes) or one of its arrays has
    another number of trials (issue #38: an IndexError)."""
    learners = [key for key in arrays if array_key(key, "ends") in arrays]
    done = {}
    for name in learners:
        ends = arrays[array_key(name, "ends")]
        if ends.ndim != 2:
            raise ValueError(f"{array_key(name, 'ends')}: expected end codes of shape (trials, episodes), got shape "
                             f"{ends.shape}")
        done[name] = ends[:, 0] >= 0 if ends.shape[1] else np.zeros(len(ends), dtype=bool)
    kept: dict[str, np.ndarray] = {}
    for key, value in arrays.items():
        owner = max((n for n in learners if key == n or key.startswith(n + "_")), key=len, default=None)
        if owner is not None and (value.ndim == 0 or len(value) != len(done[owner])):
            raise ValueError(f"{key}: expected one row per trial ({len(done[owner])}, as "
                             f"{array_key(owner, 'ends')}), got shape {value.shape}")
        if owner is not None and done[owner].any():
            kept[key] = value[done[owner]]
    return kept, {name: int(mask.sum()) for name, mask in done.items() if mask.any()}


def summarise_trial(arrays: Mapping[str, np.ndarray], name: str, trial: int) -> dict[str, Any]:
    """Per-trial figures for results.json: early/late mean return, end counts, reach and pass
    rates over the episodes the trial ran (a trial the stopping rule ended ran fewer than its
    budget; the rest are unset, end −1); with frozen test episodes also `test_success` (share
    that reached the target), `test_passed`, their mean return and end counts."""
    ends = arrays[array_key(name, "ends")][trial]
    ran = int((ends >= 0).sum()) or len(ends)
    ends = ends[:ran]
    returns = arrays[array_key(name, "returns")][trial][:ran]
    reached = arrays[array_key(name, "reached")][trial][:ran]
    passed = arrays[array_key(name, "passed")][trial][:ran]
    window = max(1, len(returns) // 10)
    summary: dict[str, Any] = {
        "mean_return_first": float(returns[:window].mean()),
        "mean_return_last": float(returns[-window:].mean()),
        "reached_last": float(reached[-window:].mean()),
        "passed_last": float(passed[-window:].mean()),
        "window": window,
        "ends": end_counts(ends),
    }
    if array_key(name, "test_ends") in arrays:
        test_ends = arrays[array_key(name, "test_ends")][trial]
        summary.update(
            test_success=float(arrays[array_key(name, "test_reached")][trial].mean()),
            test_passed=float(arrays[array_key(name, "test_passed")][trial].mean()),
            test_mean_return=float(arrays[array_key(name, "test_returns")][trial].mean()),
            test_ends=end_counts(test_ends),
        )
    return summary


def not_run(key: str, trials: int, episodes: int) -> np.ndarray:
    """A (trials, episodes) array of the per-episode `key` before any trial ran: NaN returns, end −1,
    nothing reached, zero counts."""
    if key == "returns":
        return np.full((trials, episodes), np.nan)
    if key == "ends":
        return np.full((trials, episodes), -1, dtype=np.int8)
    if key == "reached":
        return np.zeros((trials, episodes), dtype=bool)
    return np.zeros((trials, episodes), dtype=np.int64)


def not_run_like(value: np.ndarray, trials: int) -> np.ndarray:
    """A (trials, …) array for per-trial rows like `value[i]`, every entry 'not run':
    NaN (floats), −1 (ints), False (bools)."""
    shape = (trials, *value.shape[1:])
    if value.dtype == bool:
        return np.zeros(shape, dtype=bool)
    if np.issubdtype(value.dtype, np.integer):
        return np.full(shape, -1, dtype=value.dtype)
    return np.full(shape, np.nan, dtype=value.dtype)


def _to_plain(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return dataclasses.asdict(value)
    if isinstance(value, Path):
        return str(value)
    raise TypeError(f"cannot write {type(value).__name__} to JSON")


def environment() -> dict[str, Any]:
    """What results.json records of the run's machine: the results layout's version, then
    `latentrl.machine.machine()`."""
    return {"results_format": RESULTS_FORMAT, **machine()}
