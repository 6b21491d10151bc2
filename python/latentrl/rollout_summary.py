"""What rollouts of a trained policy did: the share of successes and of episodes that reached the
target, the endings, the mean return; and that summary in one line (`latentrl rollout`)."""

from __future__ import annotations

from typing import Any

from numpy.typing import NDArray

from latentrl.episode_ends import end_counts, end_reasons
from latentrl.task import Task


def rollout_summary(ends: NDArray[Any], reached: NDArray[Any], returns: NDArray[Any], task: Task) -> dict[str, Any]:
    """What rollout episodes of `task` did: "success" (the share that ended as the task's
    success, `target.hold_steps`; None where the task has no such rule), "reached_any_step" (the
    share within the reach radius after some step), the count of each ending and of those that
    came after reaching the target ("ends_after_reaching": a timeout there is a policy that
    arrived and stayed, not one that never got there), the mean return."""
    rule = task.to_dict()["target"]["hold_steps"] > 0
    return {
        "success": float((ends == end_reasons().index("success")).mean()) if rule else None,
        "reached_any_step": float(reached.mean()),
        "ends": end_counts(ends),
        "ends_after_reaching": end_counts(ends[reached.astype(bool)]),
        "mean_return": float(returns.mean()),
    }


def format_ends(ends: dict[str, int], after_reaching: dict[str, int] | None) -> str:
    """Endings with their counts, and how many of each came after reaching the target."""
    reached = after_reaching or {}
    return ", ".join(f"{name} {n}" + (f" ({reached[name]} after reaching)" if reached.get(name) else "")
                     for name, n in ends.items() if n)


def format_rollout(summary: dict[str, Any]) -> str:
    """One line of a rollout summary: success, reached at any step, mean return, endings."""
    success = "-" if summary["success"] is None else f"{summary['success']:.0%}"
    ends = format_ends(summary["ends"], summary.get("ends_after_reaching"))  # a report.json before it has none
    return (f"success {success:>4}  reached (any step) {summary['reached_any_step']:4.0%}  "
            f"mean return {summary['mean_return']:8.2f}  ends: {ends}")
