"""Picture of the fall check (paper Fig. 7a): frames of the PCA and GPLVM runs of one segment side
by side; needs matplotlib (the `[plot]` extra).

The frames are recorded by the Rust check itself (`fallcheck.fall_check(record_times=...)`: base
pose and joints), and drawn through the native kinematics of the task's plant.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.axes import Axes
from numpy.typing import NDArray

from latentrl.experiments.fallcheck import FallCheckPreset, fall_check, fit_coders, humanoid, segment_targets, segments
from latentrl.plots import box_corners, link_positions, save_figure, side_view_stick

#: Default times (s) of the drawn frames.
TIMES = (0.0, 0.25, 0.5, 1.0, 1.5, 2.0)


def recorded_run(targets: NDArray[np.float64], hold: float, times: Sequence[float] = TIMES) -> dict[str, Any]:
    """The fall check of `targets` (M, D), each held `hold` s from standing at the first, with
    frames at the first check at or after each of `times` (s). Returns the frames (time, link
    poses, fallen by then, base height), whether and when (s) it fell, the smallest support
    margin (m), the final base height (m) and the simulated duration (s)."""
    run = fall_check(targets[0], targets, hold=hold, record_times=times)
    plant = humanoid().plant()
    frames = []
    for f in run.frames:
        poses = plant.pose_links(f[2:9], f[9:])
        frames.append({"time": float(f[0]), "poses": poses, "com": plant.center_of_mass(), "fell": bool(f[1]),
                       "base_height": float(f[4])})
    last = run.segments[-1]
    dt = humanoid().to_dict()["physics"]["dt"]
    return {"frames": frames, "fell": bool(last[0]), "fall_time": float(last[6]) if last[0] else None,
            "min_margin": float(run.segments[:, 1].min()), "base_height": float(last[5]),
            "duration": len(targets) * math.ceil(hold / dt) * dt}


def _stick(ax: Axes, poses: NDArray[np.float64], com: NDArray[np.float64], colour: str) -> None:
    """Side view (x–z) of the kinematic tree at the link `poses` (L, 7), the sole boxes and the
    centre of mass `com`."""
    task = humanoid()
    names = task.link_names
    soles = task.to_dict()["fall"]["soles"]
    for shape in task._native.collision_shapes():
        if shape["link"] in soles and shape["kind"] == "box":
            corners = box_corners(poses[names.index(shape["link"])], shape)
            face = corners[[0, 4, 5, 1]]  # one side face: x-, x+ by z-, z+
            ax.fill(face[:, 0], face[:, 2], color=colour, alpha=0.6, lw=0)
    side_view_stick(ax, task.edges, link_positions(names, poses), colour)
    ax.plot([com[0]], [com[2]], "*", color="k", ms=7)
    ax.plot([com[0]], [0.0], "|", color="k", ms=8)


def fallcheck_frames(
    out_dir: Path,
    segment: tuple[str, int] = ("pose", 6),
    preset: FallCheckPreset | None = None,
    times: Sequence[float] = TIMES,
) -> dict[str, dict[str, Any]]:
    """Fig. 7a into `out_dir` (`fig7a.png`, `fig7a.pdf`): frames at `times` of the fall check of
    `segment` (("pose", i) or ("line", i) for the line i → i+1) decoded by PCA (top row) and
    the GPLVM (bottom row), side view, red once fallen. Returns per method what `recorded_run` saw:
    fell, fall_time (s or None), min_margin, final base_height (m) and duration (s)."""
    p = preset or FallCheckPreset()
    kind, i = segment
    name = f"pose {i}" if kind == "pose" else f"line {i}-{i + 1}"
    if kind not in ("pose", "line") or name not in segments(p):
        raise ValueError(f"segment must name one of {segments(p)} as ('pose', i) or ('line', i), got {segment!r}")
    X, coders = fit_coders(p)
    runs = {}
    for method in ("PCA", "GPLVM"):
        targets, _, hold = segment_targets(X, coders[method], name, p)
        runs[method] = recorded_run(targets, hold, times)
    points = np.array([t[:3] for r in runs.values() for f in r["frames"] for t in f["poses"]])
    cols = max(len(r["frames"]) for r in runs.values())
    fig, axes = plt.subplots(2, cols, figsize=(2.0 * cols, 4.2), squeeze=False, sharex=True,
                             sharey=True, layout="constrained")
    for row, (method, run) in zip(axes, runs.items(), strict=True):
        for ax, frame in zip(row, run["frames"], strict=False):
            _stick(ax, frame["poses"], frame["com"], "tab:red" if frame["fell"] else "tab:blue")
            ax.axhline(0.0, color="0.3", lw=1.5)
            ax.set_title(f"{frame['time']:.2f} s: {'fallen' if frame['fell'] else 'standing'}",
                         fontsize=9)
            ax.set_aspect("equal")
        when = f"fell at {run['fall_time']:.2f} s" if run["fell"] else "stands"
        row[0].set_ylabel(f"{method} ({when})\nz (m)")
    for ax in axes[-1]:
        ax.set_xlabel("x (m, forward)")
    pad = 0.03
    axes[0, 0].set(xlim=(points[:, 0].min() - pad, points[:, 0].max() + pad),
                   ylim=(-0.01, points[:, 2].max() + pad))
    fig.suptitle(f"fall check, {name} of the heel-side demos decoded by PCA and the GPLVM "
                 f"(d = 2), held {runs['PCA']['duration']:.2f} s\nside view; red: fallen; ★ centre of mass, "
                 "| its ground projection")
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    save_figure(fig, Path(out_dir), "fig7a")
    return {m: {k: v for k, v in r.items() if k != "frames"} for m, r in runs.items()}
