"""Picture of the fall check (paper Fig. 7a): frames of the PCA and GPLVM runs of one segment side
by side; needs matplotlib (the `[plot]` extra).

The run is replayed from Python with `_native.Sim` exactly as `sim::humanoid::run_fall_check`
does it (same servo and physics, reset on the left sole 0.5 mm up, fall test and margin every 4
physics steps, fallen when a sole tilts > 20°, another link touches the floor or the base drops
below half its start height). `Sim` reads out link positions but no orientations, so every link's
world pose is rebuilt from the joint positions with the NumPy kinematics and the base pose that
best fits the links' world positions (least squares; exact up to rounding for a multibody).
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

from latentrl import _native
from latentrl.experiments.fallcheck import FallCheckPreset, fit_coders, segment_targets, segments
from latentrl.humanoid import PHYSICS, SERVO, Humanoid, hull_margin, model, urdf_path
from latentrl.plots import save_figure, side_view_stick

#: Sole links of the fall test and the support polygon (the first one is stood on at reset).
SOLES = ("l_foot", "r_foot")
#: Default times (s) of the drawn frames.
TIMES = (0.0, 0.25, 0.5, 1.0, 1.5, 2.0)
#: Sole corners up to this far above the lowest one are in the support polygon (as in Rust).
SOLE_CONTACT_TOLERANCE = 2e-3


def _world_poses(sim: _native.Sim, h: Humanoid) -> dict[str, NDArray[np.float64]]:
    """World 4×4 pose of every link: the NumPy kinematics at the sim's joint positions, based at
    the rigid transform (Kabsch) that maps the links' local origins onto `Sim.frame_position`."""
    q = sim.joint_positions()
    local = h.link_poses(q)
    a = np.array([t[:3, 3] for t in local.values()])
    b = np.array([sim.frame_position(name) for name in local])
    u, _, vt = np.linalg.svd((a - a.mean(0)).T @ (b - b.mean(0)))
    flip = np.diag([1.0, 1.0, np.sign(np.linalg.det(vt.T @ u.T))])
    base = np.eye(4)
    base[:3, :3] = vt.T @ flip @ u.T
    base[:3, 3] = b.mean(0) - base[:3, :3] @ a.mean(0)
    return h.link_poses(q, base)


def _margin(h: Humanoid, poses: dict[str, NDArray[np.float64]]) -> float:
    """Support margin (m) of `poses` as `sim::humanoid::support_margin` computes it."""
    corners = np.array([c for s in SOLES for c in h.sole_corners(poses, s)])
    touching = corners[corners[:, 2] <= corners[:, 2].min() + SOLE_CONTACT_TOLERANCE]
    return hull_margin(h.com(poses)[:2], touching[:, :2])


def replay(
    targets: NDArray[np.float64], hold: float, times: Sequence[float] = TIMES, check_every: int = 4
) -> dict[str, Any]:
    """Replays the fall check of `targets` (M, D), each held `hold` s from standing at the first,
    recording frames at the first check at or after each of `times` (s). Returns the frames
    (time, link poses, fallen by then, base height), whether and when (s) it fell, the smallest
    support margin (m), the final base height (m) and the simulated duration (s)."""
    h = model()
    sim = _native.Sim(str(urdf_path()), root="floating", ground=0.0, **SERVO, **PHYSICS)
    sim.reset_on_ground(targets[0], SOLES[0], 5e-4)
    dt = PHYSICS["dt"]
    min_base = 0.5 * float(sim.base_position()[2])
    steps = math.ceil(hold / dt)
    pending = sorted(round(t / dt) for t in times)
    frames: list[dict[str, Any]] = []
    fell_at: float | None = None
    min_margin, done = math.inf, 0

    def record(poses: dict[str, NDArray[np.float64]]) -> None:
        while pending and done >= pending[0]:
            pending.pop(0)
            frames.append({"time": done * dt, "poses": poses, "fell": fell_at is not None,
                           "base_height": float(sim.base_position()[2])})

    record(_world_poses(sim, h))
    for target in targets:
        sim.set_targets(target)
        for start in range(0, steps, check_every):
            n = min(check_every, steps - start)
            sim.step(n)
            done += n
            poses = _world_poses(sim, h)
            min_margin = min(min_margin, _margin(h, poses))
            if fell_at is None and sim.fall_status(list(SOLES), min_base_height=min_base)[0]:
                fell_at = done * dt
            record(poses)
    return {"frames": frames, "fell": fell_at is not None, "fall_time": fell_at,
            "min_margin": min_margin, "base_height": float(sim.base_position()[2]),
            "duration": done * dt}


def _stick(ax: Axes, h: Humanoid, poses: dict[str, NDArray[np.float64]], colour: str) -> None:
    """Side view (x–z) of the kinematic tree at `poses`, the sole boxes and the centre of mass."""
    for sole in SOLES:
        corners = h.sole_corners(poses, sole)
        face = np.array([corners[k] for k in (0, 4, 5, 1)])  # one side face: x-, x+ by z-, z+
        ax.fill(face[:, 0], face[:, 2], color=colour, alpha=0.6, lw=0)
    side_view_stick(ax, h.edges, poses, colour)
    com = h.com(poses)
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
    the GPLVM (bottom row), side view, red once fallen. Returns per method what `replay` saw:
    fell, fall_time (s or None), min_margin, final base_height (m) and duration (s)."""
    p = preset or FallCheckPreset()
    kind, i = segment
    name = f"pose {i}" if kind == "pose" else f"line {i}-{i + 1}"
    if kind not in ("pose", "line") or name not in segments(p):
        raise ValueError(f"segment must name one of {segments(p)} as ('pose', i) or ('line', i), got {segment!r}")
    X, coders = fit_coders(p)
    h = model()
    runs = {}
    for method in ("PCA", "GPLVM"):
        targets, _, hold = segment_targets(X, coders[method], name, p)
        runs[method] = replay(targets, hold, times)
    points = np.array([t[:3, 3] for r in runs.values() for f in r["frames"]
                       for t in f["poses"].values()])
    cols = max(len(r["frames"]) for r in runs.values())
    fig, axes = plt.subplots(2, cols, figsize=(2.0 * cols, 4.2), squeeze=False, sharex=True,
                             sharey=True, layout="constrained")
    for row, (method, run) in zip(axes, runs.items(), strict=True):
        for ax, frame in zip(row, run["frames"], strict=False):
            _stick(ax, h, frame["poses"], "tab:red" if frame["fell"] else "tab:blue")
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
