"""Paper figures: learning curves (mean ± s.d. over trials) and hand trajectories, saved as PNG + PDF."""

from __future__ import annotations

import io
from collections.abc import Mapping
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.axes import Axes  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.patches import Circle  # noqa: E402
from numpy.typing import NDArray  # noqa: E402

from latentrl._base import atomic_write  # noqa: E402


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
    """Mean ± s.d. over trials of the (running-averaged) return per episode, one line per learner."""
    for name, per_trial in returns.items():
        smooth = running_mean(np.asarray(per_trial, dtype=float), window)
        mean, std = smooth.mean(axis=0), smooth.std(axis=0)
        episodes = np.arange(1, mean.size + 1)
        (line,) = ax.plot(episodes, mean, label=name)
        ax.fill_between(episodes, mean - std, mean + std, color=line.get_color(), alpha=0.25, lw=0)
    ax.set_xlabel("episode")
    ax.set_ylabel("cumulative reward" + (f" (running mean, {window})" if window > 1 else ""))
    ax.legend()


def hand_paths(
    ax: Axes,
    paths: NDArray[np.float64],
    *,
    target: NDArray[np.float64],
    discs: tuple[tuple[float, float, float], ...] = (),
) -> None:
    """Paths of both hands, `paths` (K, steps, 4) as (x_L, y_L, x_R, y_R), NaN-padded; discs (x, y, r)."""
    for x, y, r in discs:
        ax.add_patch(Circle((x, y), r, color="0.6", alpha=0.6))
    for k, path in enumerate(paths):
        path = path[np.isfinite(path).all(axis=1)]
        if path.size == 0:
            continue
        shade = plt.cm.viridis(k / max(len(paths) - 1, 1))
        ax.plot(path[:, 0], path[:, 1], color=shade, lw=1)
        ax.plot(path[:, 2], path[:, 3], color=shade, lw=1, ls="--")
        ax.plot(path[0, [0, 2]], path[0, [1, 3]], "o", color=shade, ms=3)
    ax.plot(target[[0, 2]], target[[1, 3]], "r*", ms=10, label="target")
    ax.set_aspect("equal")
    ax.set_xlabel("x")
    ax.set_ylabel("y")


def save_figure(fig: Figure, out_dir: Path, name: str) -> list[Path]:
    """Writes `name.png` and `name.pdf` into `out_dir` atomically and closes the figure."""
    written = []
    for ext in ("png", "pdf"):
        buffer = io.BytesIO()
        fig.savefig(buffer, format=ext, dpi=150, bbox_inches="tight")
        path = Path(out_dir) / f"{name}.{ext}"
        atomic_write(path, lambda f: f.write(buffer.getvalue()))
        written.append(path)
    plt.close(fig)
    return written
