"""The machine a run ran on, as its results record it: package and dependency versions, git
revision, Python, platform, CPU model and the features that change floating-point results, BLAS,
the native runners' threads; and the process's peak memory."""

from __future__ import annotations

import os
import platform
import re
import resource
import subprocess
from pathlib import Path
from typing import Any

import numpy as np


def machine() -> dict[str, Any]:
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


RAYON_MAX_THREADS = 2**16 - 1
"""The most threads rayon runs in a pool (its `max_num_threads()` on 64-bit targets)."""


def worker_threads() -> int:
    """Threads the native trial runners use, as rayon picks them: RAYON_NUM_THREADS read as rayon
    reads it (Rust's `usize::from_str`: ASCII digits after an optional "+"; Python's int() also
    took "1_0" and " 1", which rayon ignores) if above 0 (at most `RAYON_MAX_THREADS`), else the
    CPUs this process may run on. Runs are split into chunks of this many trials; the results do
    not depend on it."""
    requested = os.environ.get("RAYON_NUM_THREADS", "")
    if re.fullmatch(r"\+?[0-9]+", requested) and 0 < int(requested) < 2**64:
        return min(int(requested), RAYON_MAX_THREADS)
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
