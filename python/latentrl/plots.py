"""Paper figures: learning curves (mean ± s.d. over trials), hand trajectories and value functions
over a latent space, saved as PNG + PDF."""

from __future__ import annotations

import io
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path
from typing import Any

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from latentrl import _native  # noqa: E402
from latentrl._persistence import atomic_write  # noqa: E402


def running_mean(values: NDArray[np.float64], window: int) -> NDArray[np.float64]:
    """Trailing running mean along the last axis (shorter windows at the start)."""
    if window <= 1:
        return values
    cumsum = np.cumsum(values, axis=-1)
    out = np.empty_like(cumsum)
    out[..., :window] = cumsum[..., :window] / np.arange(1, min(window, values.shape[-1]) + 1)
    out[..., window:] = (cumsum[..., window:] - cumsum[..., :-window]) / window
    return out


def learning_curves(ax: Axes, returns: Mapping[str, NDArray[np.float64]], window: int = 1) -> None:
    """Mean ± s.d. over trials of the (running-averaged) return per episode, one line per learner.
    Where the stopping rule ended trials (NaN returns after), the mean stops at the last episode
    every trial ran and each trial goes on as a thin line to where it stopped: a mean over fewer
    and fewer trials would jump at each stop and narrow its band, as if learning had settled."""
    for name, per_trial in returns.items():
        smooth = running_mean(np.asarray(per_trial, dtype=float), window)
        ran = np.isfinite(smooth).all(axis=0)
        shared = int(np.argmin(ran)) if not ran.all() else ran.size  # episodes every trial ran
        mean, std = smooth[:, :shared].mean(axis=0), smooth[:, :shared].std(axis=0)
        episodes = np.arange(1, smooth.shape[1] + 1)
        label = f"{name}: mean ± s.d. of {len(smooth)} trials" if len(smooth) > 1 else name
        (line,) = ax.plot(episodes[:shared], mean, label=label)
        ax.fill_between(episodes[:shared], mean - std, mean + std, color=line.get_color(), alpha=0.25, lw=0)
        if shared < smooth.shape[1]:
            for k, trial in enumerate(smooth):
                ax.plot(episodes, trial, color=line.get_color(), lw=0.6, alpha=0.6,
                        label=f"{name}: each trial, to where it stopped" if k == 0 else None)
    ax.set_xlabel("episode")
    ax.set_ylabel("cumulative reward" + (f" (running mean, {window})" if window > 1 else ""))
    ax.legend(fontsize=8)


def hand_paths(
    ax: Axes,
    paths: NDArray[np.float64],
    *,
    target: NDArray[np.float64],
    discs: tuple[tuple[float, float, float], ...] = (),
    labels: Sequence[str] = (),
) -> None:
    """Paths of both hands, `paths` (K, steps, 4) as (x_L, y_L, x_R, y_R), NaN-padded; discs (x, y, r);
    with `labels` (one per path) a legend of the paths beside the axes."""
    for x, y, r in discs:
        ax.add_patch(Circle((x, y), r, color="0.6", alpha=0.6))
    for k, path in enumerate(paths):
        path = path[np.isfinite(path).all(axis=1)]
        if path.size == 0:
            continue
        shade = plt.cm.viridis(k / max(len(paths) - 1, 1))
        ax.plot(path[:, 0], path[:, 1], color=shade, lw=1, label=labels[k] if labels else None)
        ax.plot(path[:, 2], path[:, 3], color=shade, lw=1, ls="--")
        ax.plot(path[0, [0, 2]], path[0, [1, 3]], "o", color=shade, ms=3)
    ax.plot(target[[0, 2]], target[[1, 3]], "r*", ms=10, label="target")
    if labels:
        ax.legend(fontsize=7, loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")


#: Draws an experiment's regions on a latent panel: `regions(ax, g0, g1, postures)` with the
#: grid's coordinates g0, g1 (grid, grid) and the decoded postures (grid², D), row by row.
Regions = Callable[[Axes, NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]], None]


def variance_shade(variance: NDArray[np.float64]) -> NDArray[np.float64]:
    """GPLVM variances as shades in [0, 1] (darkest the highest), on a log scale: the variance
    spans orders of magnitude from the demonstrations to the corners of the latent box."""
    log_var: NDArray[np.float64] = np.log(np.maximum(variance, 1e-300))
    shade: NDArray[np.float64] = (log_var - log_var.min()) / max(float(np.ptp(log_var)), 1e-12)
    return shade


def latent_value_grid(
    weights: NDArray[np.float64] | None,
    low: NDArray[np.float64],
    high: NDArray[np.float64],
    model: Any,
    *,
    learner: Mapping[str, Any],
    grid: int,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """The learner's V of `weights` (None: before learning) on a `grid` × `grid` mesh over the latent box [low, high]
    (rows from low z2 to high): the mesh (g0, g1), V on it, and the decoded postures (grid²,
    D) and GPLVM variances (grid²,) of its points, row by row."""
    g0, g1 = np.meshgrid(np.linspace(low[0], high[0], grid), np.linspace(low[1], high[1], grid))
    points = np.column_stack([g0.ravel(), g1.ravel()])
    postures, variance = model.decoder_.predict(points)
    value = _native.learner_values(dict(learner), list(low), list(high), None if weights is None else np.asarray(weights, dtype=np.float64), points)
    return g0, g1, value.reshape(g0.shape), postures, variance


def latent_value_panel(
    ax: Axes,
    weights: NDArray[np.float64] | None,
    low: NDArray[np.float64],
    high: NDArray[np.float64],
    model: Any,
    *,
    learner: Mapping[str, Any],
    regions: Regions | None = None,
    grid: int = 120,
) -> None:
    """V over the 2-D latent box [low, high] (the learner's own V of `weights`, native; None: w₀), the GPLVM
    variance of `model.decoder_` shaded (darker = higher, log scale), the experiment's `regions`
    and the demonstrations' latent points `model.Z_` (white dots) (paper Fig. 6b/d, 7b/c)."""
    g0, g1, value, postures, variance = latent_value_grid(weights, low, high, model, learner=learner, grid=grid)
    shape = g0.shape
    extent = (low[0], high[0], low[1], high[1])
    flat = np.ptp(value) <= 1e-9 * max(1.0, float(np.abs(value).max()))  # w₀ everywhere: rounding, not structure
    level = float(value.mean())
    image = ax.imshow(np.full_like(value, level) if flat else value, origin="lower", extent=extent, aspect="auto",
                      cmap="viridis", vmin=level - 1.0 if flat else None, vmax=level + 1.0 if flat else None)
    ax.figure.colorbar(image, ax=ax, label=f"V: expected discounted return (γ = {learner['gamma']:g})")
    if flat:
        ax.text(0.5, 0.5, f"V = {level:g} everywhere", transform=ax.transAxes, ha="center", va="center",
                color="w", fontsize=11)
    shade = variance_shade(variance).reshape(shape)
    overlay = np.zeros((*shape, 4))
    overlay[..., 3] = 0.6 * shade
    ax.imshow(overlay, origin="lower", extent=extent, aspect="auto")
    ax.fill_between([], [], color="k", alpha=0.5, label="darker: GPLVM variance (far from the demos)")
    if regions is not None:
        regions(ax, g0, g1, postures)
    ax.plot(model.Z_[:, 0], model.Z_[:, 1], ".", color="w", mec="0.4", mew=0.3, ms=3, label="demos (latent points)")
    ax.set_xlabel("z1")
    ax.set_ylabel("z2")
    ax.legend(fontsize=7, loc="lower right")


def latent_run_figures(
    preset: Any,
    arrays: Mapping[str, np.ndarray],
    out_dir: Path,
    *,
    names: tuple[str, str, str],
    title: str,
    panel: Callable[[Axes, NDArray[np.float64] | None], None],
) -> None:
    """A latent learner's return curve (`names[0]`: mean ± s.d. over trials, running mean of
    min(`curve_window`, episodes // 5)) and its value function before (`names[1]`: the
    initial weight everywhere) and after learning (`names[2]`: trial 1), each drawn by
    `panel(ax, weights)` (None: before learning); the latter only if the run kept its
    weights."""
    fig, ax = plt.subplots(figsize=(6, 4))
    window = max(1, min(preset.curve_window, preset.episodes // 5))
    learning_curves(ax, {"latent": arrays["latent"]}, window=window)
    ax.set_title(title)
    save_figure(fig, out_dir, names[0])
    weights = arrays.get("latent_weights")
    drawn = [(names[1], None, "before learning")]
    if weights is not None:
        drawn.append((names[2], np.asarray(weights)[0], "after learning (trial 1)"))
    for name, w, when in drawn:
        fig, ax = plt.subplots(figsize=(6, 5))
        panel(ax, w)
        ax.set_title(f"value function {when}")
        save_figure(fig, out_dir, name)


def shown_paths(arrays: Mapping[str, np.ndarray]) -> tuple[np.ndarray | None, str, str]:
    """The recorded paths to draw: the frozen test episodes' if any, else the recorded training
    episodes'; what they are; and the key of their returns."""
    tests = arrays.get("latent_test_paths")
    if tests is not None:
        return tests, "frozen test episodes", "latent_test"
    return arrays.get("latent_paths"), "recorded training episodes", "latent"


def side_view_stick(
    ax: Axes,
    edges: Sequence[tuple[str, str]],
    positions: Mapping[str, NDArray[np.float64]],
    colour: str,
    dx: float = 0.0,
) -> None:
    """A robot's kinematic tree as a stick figure in the x–z plane: one segment per (parent,
    child) link of `edges` between their world `positions` (x, y, z), shifted by `dx`."""
    for parent, child in edges:
        a, b = positions[parent], positions[child]
        ax.plot([dx + a[0], dx + b[0]], [a[2], b[2]], "o-", color=colour, lw=2, ms=2)


def box_corners(link_pose: NDArray[np.float64], shape: Mapping[str, Any]) -> NDArray[np.float64]:
    """World corners (8, 3) of a box collision shape (`Task.collision_shapes` entry) of a link at
    `link_pose` (7,: position, quaternion x, y, z, w); corner k has bit 1 / 2 / 4 set for +x / +y / +z."""
    from scipy.spatial.transform import Rotation

    signs = np.array([[(k >> b & 1) - 0.5 for b in range(3)] for k in range(8)])
    local = signs * np.asarray(shape["size"])
    origin = np.asarray(shape["origin"])
    in_link = Rotation.from_quat(origin[3:]).apply(local) + origin[:3]
    return Rotation.from_quat(link_pose[3:]).apply(in_link) + link_pose[:3]


def link_positions(names: Sequence[str], poses: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
    """Link name → world position, from native link poses (L, 7) in `names` order."""
    return {name: pose[:3] for name, pose in zip(names, poses)}


def save_figure(fig: Figure, out_dir: Path, name: str) -> list[Path]:
    """Writes `name.png` and `name.pdf` into `out_dir` atomically and closes the figure."""
    written = []
    for ext in ("png", "pdf"):
        buffer = io.BytesIO()
        fig.savefig(buffer, format=ext, dpi=150, bbox_inches="tight")
        path = Path(out_dir) / f"{name}.{ext}"
        atomic_write(path, lambda f: f.write(buffer.getvalue()))  # noqa: B023 (called here)
        written.append(path)
    plt.close(fig)
    return written
