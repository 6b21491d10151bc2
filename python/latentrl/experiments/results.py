"""Results files of a run (docs/method.md §Results layout): metadata JSON and per-episode NPZ,
written atomically."""

from __future__ import annotations

import dataclasses
import json
import os
import platform
import resource
import subprocess
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from latentrl._base import atomic_write
from latentrl._files import MAX_JSON_BYTES, read_text

RESULTS_FORMAT = 1
"""Version of the results layout; bumped when a file changes meaning."""


def remove_stale_temporaries(path: Path) -> None:
    """Deletes temporary files that `atomic_write` left beside `path` when a process was killed
    while writing it (the file itself is always whole: the old or the new version)."""
    for stale in path.parent.glob(f".{path.name}.*.tmp"):
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


RESULTS_OBJECTS = {"": ("preset", "setup", "trials", "environment"), "setup.": ("task", "gplvm", "inputs", "latent_box")}
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
    """Package and dependency versions, git revision if known, Python, platform, CPU model,
    threads. The CPU matters for reproducing numbers: the same seed gives the same results on
    one machine, but the physics' f32 maths (glibc picks CPU-specific sin/cos/exp) may differ
    in the last bits on another CPU, and RL runs amplify that."""
    from importlib import metadata  # (and its email parsers): loaded by a run, not by `--help`

    versions: dict[str, str | None] = {}
    for name in ("latentrl", "numpy", "scipy", "matplotlib"):
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return {
        "results_format": RESULTS_FORMAT,
        "versions": versions,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu": _cpu_model(),
        "cpu_flags": _cpu_flags(),
        "blas": _blas(),
        "git_revision": _git_revision(),
        "cpu_count": os.cpu_count(),
        "rayon_threads": worker_threads(),
    }


def _cpu_model() -> str:
    """The CPU's model name (Linux: /proc/cpuinfo), else `platform.processor()`."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


SIMD_FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f", "avx512dq", "avx512vl")
"""The CPU features that change floating-point results here (libm and BLAS kernels pick by them)."""


def _cpu_flags() -> list[str]:
    """Which of SIMD_FLAGS the CPU has (Linux: /proc/cpuinfo; empty elsewhere)."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("flags"):
                have = set(line.split(":", 1)[1].split())
                return [flag for flag in SIMD_FLAGS if flag in have]
    except OSError:
        pass
    return []


def _blas() -> dict[str, Any]:
    """NumPy's BLAS (name, version, build configuration) and an OPENBLAS_CORETYPE override: the
    GPLVM fit's last bits depend on the kernel OpenBLAS picks for the CPU."""
    config: dict[str, Any] = {}
    try:
        config = dict(np.show_config(mode="dicts")["Build Dependencies"]["blas"])
    except (KeyError, TypeError):
        pass
    return {
        "name": config.get("name"),
        "version": config.get("version"),
        "configuration": config.get("openblas configuration"),
        "OPENBLAS_CORETYPE": os.environ.get("OPENBLAS_CORETYPE"),
    }


def worker_threads() -> int:
    """Threads the native trial runners use, as rayon picks them: RAYON_NUM_THREADS if it is a
    positive integer, else the CPUs this process may run on. Runs are split into chunks of this
    many trials; the results do not depend on it."""
    try:
        requested = int(os.environ.get("RAYON_NUM_THREADS", ""))
    except ValueError:
        requested = 0
    if requested > 0:
        return requested
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1


def peak_rss_mib() -> float:
    """Peak resident memory of this process so far, MiB (`getrusage`; Linux reports KiB)."""
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return peak / (1024 * 1024 if platform.system() == "Darwin" else 1024)


def _git_revision() -> str | None:
    try:
        out = subprocess.run(
            ["git", "rev-parse", "HEAD"],
            cwd=Path(__file__).resolve().parent,
            capture_output=True,
            text=True,
            timeout=5,
            check=True,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip() or None
