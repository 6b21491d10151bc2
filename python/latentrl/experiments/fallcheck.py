"""The humanoid fall check (docs/method.md §Experiment 3, paper Fig. 7a): does decoding the lift
demos through PCA or the GPLVM (d = 2) keep the KHR-1HV-like robot balanced and the grip closed?

For each method — PCA, GPLVM, and plain joint interpolation (the control) — the check

1. decodes every demo pose (encode → decode; the control returns the demo), clips it to
   the joint limits, stands the robot in it and holds it for `pose_hold` s;
2. walks straight lines between consecutive demos *within one style* (in latent space for
   PCA and the GPLVM, in joint space for the control): `path_points` targets per line,
   each held `path_hold` s, starting from the decoded first pose.

Each row reports the rms and largest joint error (deg; paths: against joint interpolation
at the same fraction), the grip error and support margin of the decoded pose(s) standing at
rest (the task's plant), and the simulated smallest support margin, largest |grip error| and
whether it fell (the Rust fall check). PCA falls are reported as observed: the effect depends
on how close to the heel the demos balance (docs/humanoid.md). The robot, its servos, physics,
soles and grip are those of the humanoid lift task (`tasks/humanoid_lift.toml`).

Its picture (paper Fig. 7a, `fallcheck_frames`: the `[plot]` extra, matplotlib imported when it is
drawn): frames of the PCA and GPLVM runs of one segment side by side, recorded by the Rust check
itself (`fall_check(record_times=...)`: base pose and joints) and drawn through the native
kinematics of the task's plant.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import TYPE_CHECKING, Any, NamedTuple

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.demos import load_demos
from latentrl.experiments.exp3 import demos_path
from latentrl.gplvm import GPLVM
from latentrl.pca import PCA
from latentrl.task import Task

if TYPE_CHECKING:  # matplotlib (the [plot] extra) is imported when a figure is drawn
    from matplotlib.axes import Axes

#: Style of each row of the shipped demo files: 4 straight-arm hip-hinge + 3 knee-squat poses.
STYLES = (0, 0, 0, 0, 1, 1, 1)
METHODS = ("PCA", "GPLVM", "joint")


@dataclass(frozen=True)
class FallCheckPreset:
    """Parameters of the fall check (our choices; the paper gives none)."""

    demos: str | None = None
    """Demo file; None = the shipped heel-side set (CoM 2 cm ahead of the heels)."""
    styles: tuple[int, ...] = STYLES
    """Style label of each demo; latent lines never cross styles."""
    pose_hold: float = 2.0
    """Seconds each decoded demo pose is held (the demos themselves hold ≥ 2 s)."""
    path_points: int = 6
    """Targets per straight line between consecutive demos (end points included)."""
    path_hold: float = 0.25
    """Seconds each target of a line is held."""
    random_state: int = 0
    """Seed of the GPLVM fit."""


@cache
def humanoid() -> Task:
    """The humanoid lift task: the robot, servos, physics, soles and grip of the check."""
    return Task.shipped("humanoid_lift")


class FallCheck(NamedTuple):
    """What `fall_check` saw."""

    segments: NDArray[np.float64]
    """(M, 7), one row per target: fell, min support margin, final support margin, grip
    error at the end, max |grip error| (m), final base height (m), time of the fall (s since
    the start; NaN while standing)."""
    frames: NDArray[np.float64]
    """(K, 9 + D), one per reached `record_times` entry, taken at the first check at or
    after it: time (s), fell, base position (3), base quaternion (x, y, z, w), joints (D)."""


def fall_check(
    start: NDArray[np.float64], targets: NDArray[np.float64], *, hold: float = 1.0, record_times: Sequence[float] = ()
) -> FallCheck:
    """Physics fall check (Rust `sim::fallcheck`) in the humanoid lift task's world: stand at
    `start`, hold each row of `targets` for `hold` s, checking every 4 physics steps; records the
    robot at `record_times` (s) for pictures."""
    start = np.ascontiguousarray(start, dtype=np.float64)
    targets = np.ascontiguousarray(np.atleast_2d(targets), dtype=np.float64)
    times = [float(t) for t in record_times]
    table, frames = _native.fall_check(humanoid()._native, start, targets, hold=hold, record_times=times)
    return FallCheck(table, frames)


def _rms_max(a: NDArray[np.float64], b: NDArray[np.float64]) -> tuple[float, float]:
    d = np.degrees(a - b)
    return float(np.sqrt(np.mean(d**2))), float(np.abs(d).max())


#: Per method: the latent point of every demo (N, d) and its decoder (clipped to the joint limits).
Coders = dict[str, tuple[NDArray[np.float64], Callable[[NDArray[np.float64]], NDArray[np.float64]]]]


def fit_coders(preset: FallCheckPreset | None = None) -> tuple[NDArray[np.float64], Coders]:
    """The demo postures X (N, D) and, per method of `METHODS`, the demos' latent points and a
    decoder of latent points (M, d) to postures (M, D) clipped to the joint limits."""
    p = preset or FallCheckPreset()
    h = humanoid()
    demos = load_demos(
        Path(p.demos) if p.demos else demos_path(heel=True), expected_joints=h.joint_names
    )
    X = demos.postures
    if len(p.styles) != len(X):
        raise ValueError(f"styles: {len(p.styles)} labels for {len(X)} demos")
    pca = PCA(n_components=2).fit(X)
    gplvm = GPLVM(n_components=2, random_state=p.random_state).fit(X)
    raw: dict[str, tuple[NDArray[np.float64], Any]] = {
        "PCA": (pca._encode(X), pca.inverse_transform),
        "GPLVM": (gplvm.Z_, gplvm.inverse_transform),
        "joint": (X, lambda z: np.asarray(z, dtype=float)),
    }

    def clipped(f: Any) -> Callable[[NDArray[np.float64]], NDArray[np.float64]]:
        def decode(z: NDArray[np.float64]) -> NDArray[np.float64]:
            out: NDArray[np.float64] = np.clip(f(np.atleast_2d(z)), h.lower, h.upper)
            return out

        return decode

    return X, {m: (latent, clipped(f)) for m, (latent, f) in raw.items()}


def segments(preset: FallCheckPreset | None = None) -> list[str]:
    """Names of the checked segments: "pose i" per demo, then "line i-j" per pair of
    consecutive demos of one style."""
    styles = (preset or FallCheckPreset()).styles
    lines = [f"line {i}-{i + 1}" for i in range(len(styles) - 1) if styles[i] == styles[i + 1]]
    return [f"pose {i}" for i in range(len(styles))] + lines


def segment_targets(
    X: NDArray[np.float64], coder: tuple[NDArray[np.float64], Any], segment: str,
    preset: FallCheckPreset | None = None,
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Servo targets (M, D) of `segment` (a name of `segments`) decoded by `coder` (an entry of
    `fit_coders`), the joint-space reference (M, D) and the hold per target (s); the check
    starts standing at the first target."""
    p = preset or FallCheckPreset()
    latent, decode = coder
    kind, index = segment.split()
    if kind == "pose":
        i = int(index)
        return decode(latent[i]), X[i][None], p.pose_hold
    i, j = (int(k) for k in index.split("-"))
    s = np.linspace(0.0, 1.0, p.path_points)[:, None]
    return decode((1 - s) * latent[i] + s * latent[j]), (1 - s) * X[i] + s * X[j], p.path_hold


def run_fallcheck(preset: FallCheckPreset | None = None) -> list[dict[str, Any]]:
    """Runs the check; one dict per (method, pose or line) with the keys of `COLUMNS`."""
    p = preset or FallCheckPreset()
    X, coders = fit_coders(p)
    plant = humanoid().plant(X)
    rows: list[dict[str, Any]] = []
    for method in METHODS:
        for segment in segments(p):
            targets, control, hold = segment_targets(X, coders[method], segment, p)
            sim = fall_check(targets[0], targets, hold=hold).segments
            rows.append(_row(method, segment, targets, control, sim, plant))
    return rows


#: Keys of every row of `run_fallcheck`.
COLUMNS = (
    "method", "segment", "rms_deg", "max_deg", "grip_error", "margin", "sim_margin",
    "sim_grip_error", "fell",
)


def at_rest(plant: _native.TaskPlant, posture: NDArray[np.float64]) -> tuple[float, float]:
    """Grip error (m, hand distance − width) and support margin (m) of `posture` standing at rest."""
    plant.reset(posture)
    return float(plant.constraint_errors()[0]), float(plant.support_margin())


def _row(method: str, segment: str, poses: NDArray[np.float64], reference: NDArray[np.float64],
         sim: NDArray[np.float64], plant: _native.TaskPlant) -> dict[str, Any]:
    grips, margins = zip(*(at_rest(plant, q) for q in poses))
    rms, worst = _rms_max(poses, reference)
    return {
        "method": method,
        "segment": segment,
        "rms_deg": rms,
        "max_deg": worst,
        "grip_error": float(grips[int(np.argmax(np.abs(grips)))]),
        "margin": float(min(margins)),
        "sim_margin": float(sim[:, 1].min()),
        "sim_grip_error": float(sim[:, 4].max()),
        "fell": bool(sim[:, 0].max() > 0.5),
    }


def format_table(rows: Sequence[dict[str, Any]]) -> str:
    """A Markdown table of `rows` (lengths in mm, angles in degrees)."""
    head = ("| method | segment | rms joint err (°) | max (°) | grip err (mm) | margin (mm) "
            "| sim min margin (mm) | sim max grip err (mm) | fell |")
    lines = [head, "|" + "---|" * 9]
    for r in rows:
        lines.append(
            f"| {r['method']} | {r['segment']} | {r['rms_deg']:.2f} | {r['max_deg']:.1f} "
            f"| {1e3 * r['grip_error']:+.1f} | {1e3 * r['margin']:.1f} "
            f"| {1e3 * r['sim_margin']:.1f} "
            f"| {1e3 * r['sim_grip_error']:.1f} | {'yes' if r['fell'] else 'no'} |"
        )
    return "\n".join(lines)


# --- figures (Fig. 7a) ------------------------------------------------------------------------


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
    from latentrl.plots import box_corners, link_positions, side_view_stick

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
    import matplotlib.pyplot as plt

    from latentrl.plots import save_figure

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
