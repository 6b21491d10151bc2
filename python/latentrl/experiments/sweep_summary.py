"""The summary of a sweep, per cell and learner over its finished trials: the final return
(mean ± s.d. of each trial's mean over its last 10 % of episodes) and the episodes a trial
took until that running mean first reached the threshold. Written into the sweep directory
as summary.json, summary.md (a table) and sweep.png/pdf (learning curves, final returns)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import matplotlib.pyplot as plt
import numpy as np
from matplotlib.lines import Line2D
from numpy.typing import NDArray

from latentrl.experiments.results import write_json
from latentrl.experiments.runner import load_arrays
from latentrl.experiments.registry import rl_experiments
from latentrl.experiments.sweep_types import Cell, Sweep
from latentrl.plots import running_mean, save_figure

FINAL_SHARE = 0.1
"""Share of a trial's last episodes whose mean return is its 'final return' (as results.json's
`mean_return_last`); also the running-mean window of 'episodes to threshold'."""


def final_window(episodes: int) -> int:
    """Episodes averaged for the final return and the threshold test."""
    return max(1, int(episodes * FINAL_SHARE))


def episodes_to_threshold(returns: NDArray[np.float64], threshold: float, window: int) -> NDArray[np.int64]:
    """Per trial (row of `returns`, (trials, episodes)), the first episode count at which the
    mean return of the last `window` episodes is ≥ `threshold`; −1 where it never is."""
    if returns.shape[1] < window:
        return np.full(len(returns), -1, dtype=np.int64)
    sums = np.cumsum(np.pad(returns, ((0, 0), (1, 0))), axis=1)
    running = (sums[:, window:] - sums[:, :-window]) / window
    hit = running >= threshold
    first = np.where(hit.any(axis=1), hit.argmax(axis=1) + window, -1)
    return first.astype(np.int64)


def write_summary(sweep: Sweep, cells: list[Cell], out: Path) -> dict[str, Any]:
    """Computes the summary of the finished trials in `out`, writes summary.json, summary.md
    and sweep.png/pdf, and returns the summary."""
    learners = rl_experiments()[sweep.experiment].learners
    curves: list[tuple[Cell, str, NDArray[np.float64]]] = []
    for cell in cells:
        try:
            arrays = load_arrays(out / cell.id)
        except (OSError, ValueError):
            continue
        for learner in learners:
            if learner in arrays and f"{learner}_end" in arrays:
                curves.append((cell, learner, arrays[learner][arrays[f"{learner}_end"][:, 0] >= 0]))
    finals = {(c.id, name): r[:, -final_window(r.shape[1]):].mean(axis=1) for c, name, r in curves if len(r)}
    threshold, source = sweep.threshold, "given"
    if threshold is None:
        best = max((float(f.mean()) for f in finals.values()), default=None)
        threshold, source = (None if best is None else 0.5 * best), "half the best final return"
    rows = []
    for cell, learner, returns in curves:
        row: dict[str, Any] = {"cell": cell.id, "overrides": cell.overrides, "learner": learner,
                               "trials": len(returns), "of": cell.preset.trials}
        if len(returns):
            final = finals[(cell.id, learner)]
            row.update(final_return_mean=float(final.mean()), final_return_sd=float(final.std()))
            if threshold is not None:
                reached = episodes_to_threshold(returns, threshold, final_window(returns.shape[1]))
                reached = reached[reached >= 0]
                row["reached_threshold"] = len(reached)
                if len(reached):
                    row.update(episodes_to_threshold_mean=float(reached.mean()),
                               episodes_to_threshold_sd=float(reached.std()))
        rows.append(row)
    summary = {
        "threshold": threshold,
        "threshold_source": source,
        "final_share": FINAL_SHARE,
        "sd": "over trials, ddof 0 (as the figures)",
        "rows": rows,
    }
    write_json(out / "summary.json", summary)
    (out / "summary.md").write_text(_table(sweep, cells, rows, threshold, source))
    if curves:
        _figure(curves, threshold, out)
    return summary


def _table(sweep: Sweep, cells: list[Cell], rows: list[dict[str, Any]], threshold: float | None,
           source: str) -> str:
    fields = list(dict.fromkeys(k for c in cells for k in c.overrides))
    when = f"≥ {threshold:.4g} ({source})" if threshold is not None else "(no finished trial)"
    head = ["cell", *fields, "learner", "trials", "final return", f"episodes to {when}"]
    lines = [
        f"# Sweep of {sweep.experiment}: {len(cells)} cells",
        "",
        f"Final return: each trial's mean return over its last {FINAL_SHARE:.0%} of episodes, mean ± s.d.",
        "over the finished trials; episodes to the threshold: until that running mean first reached it",
        "(mean ± s.d. over the trials that did, and how many did).",
        "",
        "| " + " | ".join(head) + " |",
        "|" + "---|" * len(head),
    ]
    overrides = {c.id: c.overrides for c in cells}
    for row in rows:
        values = [str(overrides[row["cell"]].get(k, "")) for k in fields]
        final = "—"
        if "final_return_mean" in row:
            final = f"{row['final_return_mean']:.1f} ± {row['final_return_sd']:.1f}"
        reach = "—"
        if "episodes_to_threshold_mean" in row:
            reach = f"{row['episodes_to_threshold_mean']:.0f} ± {row['episodes_to_threshold_sd']:.0f}"
        if "reached_threshold" in row:
            reach += f" ({row['reached_threshold']}/{row['trials']})"
        lines.append("| " + " | ".join([row["cell"], *values, row["learner"], f"{row['trials']}/{row['of']}",
                                        final, reach]) + " |")
    return "\n".join(lines) + "\n"


def _figure(curves: list[tuple[Cell, str, NDArray[np.float64]]], threshold: float | None, out: Path) -> None:
    """Left: mean learning curve (running mean over the final window) of every cell (colour)
    and learner (line style); right: final return mean ± s.d. per cell, by its number."""
    fig, (left, right) = plt.subplots(1, 2, figsize=(12, 4.5))
    ids = list(dict.fromkeys(cell.id for cell, _, _ in curves))
    learners = list(dict.fromkeys(name for _, name, _ in curves))
    colours = {cell_id: plt.cm.viridis(i / max(len(ids) - 1, 1)) for i, cell_id in enumerate(ids)}
    styles = dict(zip(learners, ("-", "--", ":", "-.")))
    for cell, learner, returns in curves:
        if not len(returns):
            continue
        window = final_window(returns.shape[1])
        mean = running_mean(returns, window).mean(axis=0)
        left.plot(np.arange(1, mean.size + 1), mean, color=colours[cell.id], ls=styles.get(learner, "-"))
        final = returns[:, -window:].mean(axis=1)
        x = ids.index(cell.id) + 0.15 * (learners.index(learner) - (len(learners) - 1) / 2)
        right.errorbar(x, final.mean(), yerr=final.std(), fmt="o", color=colours[cell.id], capsize=3,
                       mfc="white" if learners.index(learner) else None)
    handles = [Line2D([], [], color=colours[cell_id], label=cell_id) for cell_id in ids]
    handles += [Line2D([], [], color="grey", ls=styles[name], label=name) for name in learners]
    if threshold is not None:
        left.axhline(threshold, color="k", lw=0.8, ls=":")
        handles.append(Line2D([], [], color="k", lw=0.8, ls=":", label=f"threshold {threshold:.4g}"))
    left.set_xlabel("episode")
    left.set_ylabel("return (running mean)")
    right.set_xticks(range(len(ids)), [cell_id.split("_")[0] for cell_id in ids])
    right.set_xlabel("cell")
    filled = f" (filled: {learners[0]}, open: {', '.join(learners[1:])})" if len(learners) > 1 else ""
    right.set_ylabel("final return, mean ± s.d." + filled)
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=min(3, len(handles)),
               fontsize=8, frameon=False)
    fig.suptitle("sweep: learning curves and final returns per cell")
    save_figure(fig, out, "sweep")
