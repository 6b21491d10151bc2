"""After training: did it learn, and if not, what next? (`latentrl train` ends with it and writes
`report.json`; `latentrl report DIR` prints it again.)

The measure is the saved policy's rollouts from the task's test starts (`LatentPolicy.rollout`):
greedy, by the learner's soft-max, and the random control that cannot learn, from the same
starts. A task "succeeds" in an episode that ends as its success (`target.hold_steps`) or, without
such a rule, that comes within the reach radius at some step. One of four verdicts:

- **learnt**: the better of greedy and soft-max succeeds in at least `LEARNT` of the rollouts,
  and more often than the control;
- **never reached it**: no training episode came within the reach radius;
- **still improving below the target**: anything between, the reach rate still rising over the
  last tenth of training (`RISING`) when the budget or the stopping rule ended it;
- **stopped improving below the target**: anything between, no longer rising.

A greedy policy that succeeds less often than the control from the same starts is said so,
whatever the verdict: it has learnt nothing usable from them.

With the verdict come the endings of the last fifth of the training episodes each trial ran, whether the reach
rate was still rising there (more episodes may help), and the next things to try, taken from how
the greedy rollouts that failed ended (the policy `act()` runs, not training's exploring
soft-max: the zoo's snake failed training episodes mostly on the wall, its greedy rollouts mostly
by hovering beside the target) and from `latentrl check`'s findings.
"""

from __future__ import annotations

from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl.task import end_counts, end_reasons
from latentrl.rollout_summary import format_ends
from latentrl.train import format_rollout

LEARNT = 0.8
"""Success share of the rollouts (greedy or soft-max) from which a policy has "learnt"."""

RISING = 0.05
"""A reach rate that rose by more than this between the last two tenths of training is still rising."""

NEAR = 0.5
"""Mean reward per step (of at most 1) from which timed-out episodes count as hovering near the
target: the reward exp(−θ ‖(h − h*)/ℓ‖²) is ½ at ‖h − h*‖ = ℓ √(ln 2 / θ), 1.4 ℓ at θ = 0.35."""

ADVICE = {
    "obstacle": "learner.move_correction = true (moves that meet an obstacle on the way), or more servo damping "
                "(servo.kd): the arm swings into it between postures that keep clear (the zoo's snake, 8 trials: "
                "kd 2 → 8 took greedy reach from 42 to 70 %, move corrections to 28 %)",
    "drop": "a smaller learner.step or stiffer servos (the check's servos finding): the constraint breaks on the way",
    "fall": "a smaller learner.step, or demos that keep the robot balanced (fall.min_start_margin)",
    "box_exit": "a larger --latent-margin: the learner presses against the latent box's edge",
    "variance_gate": "a higher learner.variance_threshold, or none",
}
"""The next thing to try when most failing greedy rollouts end this way."""


@dataclass(frozen=True)
class Verdict:
    """The verdict on a trained policy, with the numbers behind it and what to try next."""

    verdict: str
    rollouts: dict[str, dict[str, Any]]
    late_ends: dict[str, int]
    late_ends_reached: dict[str, int]
    reach_late: float
    rising: bool
    next: list[str] = field(default_factory=list)
    per_trial: dict[str, list[float]] = field(default_factory=dict)
    """Each policy's success share per trial: trials of one run may lie far apart (the zoo's
    snake: 0–70 % greedy), which the pooled share hides."""
    below_control: str | None = None
    """Said when the greedy policy succeeds less often than the random control (a real run:
    greedy 0 %, soft-max 15 %, control 8 %, and the verdict did not say so)."""

    @classmethod
    def from_dict(cls, saved: dict[str, Any]) -> Verdict:
        """The verdict as `to_dict` wrote it (report.json; keys it lacks from an earlier version
        take their defaults)."""
        names = {f.name for f in fields(cls)}
        return cls(**{k: v for k, v in saved.items() if k in names})

    def to_dict(self) -> dict[str, Any]:
        """As written to report.json."""
        return {"verdict": self.verdict, "rollouts": self.rollouts, "late_ends": self.late_ends,
                "late_ends_reached": self.late_ends_reached, "reach_late": self.reach_late, "rising": self.rising,
                "next": self.next, "per_trial": self.per_trial, "below_control": self.below_control}

    def __str__(self) -> str:
        lines = [f"verdict: {self.verdict}"]
        lines += [f"  {kind:8s} {format_rollout(summary)}" for kind, summary in self.rollouts.items()]
        if self.below_control is not None:
            lines.append(f"  {self.below_control}")
        if len(self.per_trial.get("greedy", ())) > 1:
            lines += [f"  {kind} per trial: {', '.join(f'{v:.0%}' for v in shares)}"
                      for kind, shares in self.per_trial.items() if kind != "random"]
        ends = format_ends(self.late_ends, self.late_ends_reached)
        lines.append(f"  last fifth of training: reached {self.reach_late:.0%}{' (still rising)' if self.rising else ''};"
                     f" ends: {ends}")
        lines += [f"  next: {step}" for step in self.next]
        return "\n".join(lines)


def success_share(summary: dict[str, Any]) -> float:
    """The share of a rollout's episodes that succeeded: ended as a success, or, without a success
    rule, came within the reach radius."""
    return float(summary["reached_any_step"] if summary["success"] is None else summary["success"])


def succeeded(run: dict[str, Any], summary: dict[str, Any]) -> NDArray[np.bool_]:
    """Per episode of a rollout `run` (flattened over its trials), whether it succeeded as
    `success_share` counts: ended as a success, or, without a success rule, reached the target."""
    if summary["success"] is None:
        return np.asarray(run["reached"], dtype=bool).ravel()
    success: NDArray[np.bool_] = np.asarray(run["ends"]).ravel() == end_reasons().index("success")
    return success


def end_advice(worst: str, learner: dict[str, Any]) -> str | None:
    """`ADVICE` for the ending most failing greedy rollouts had, under the `learner` settings
    they ran with (move corrections already on: servo damping and the step are left to try)."""
    if worst == "obstacle" and learner["move_correction"]:
        return "more servo damping (servo.kd), or a smaller learner.step (move corrections are on)"
    return ADVICE.get(worst)


def timeout_advice(policy: Any, returns: NDArray[np.float64]) -> str:
    """What to try when most failing greedy rollouts time out, by their mean reward per step
    (`returns` of those rollouts over `episode.max_steps`): at least `NEAR` hovers near the
    target, less wanders away from it. A region too narrow for the step is the check's target
    finding, which joins the advice; beside a region it finds wide enough, a smaller step did not
    help (the zoo's snake: 28 % greedy at a quarter spacing, 40 % at half), more episodes a little
    (8 trials: 42 % at the defaults, 49 % with 6000 episodes run to the end)."""
    per_step = float(np.mean(returns)) / policy.task.to_dict()["episode"]["max_steps"]
    if per_step >= NEAR:
        return (f"failing greedy rollouts time out near the target (mean reward {per_step:.2f} per step): "
                "the policy hovers beside the target region, where the learnt values differ by less than "
                "their errors; more --episodes with --episode.stop-window 0 may help a little (the zoo's "
                "snake, 8 trials: 42 % greedy at the defaults, 49 % with 6000 episodes)")
    return (f"failing greedy rollouts time out away from the target (mean reward {per_step:.2f} per step): "
            "the learnt value is flat where they wander (latentrl rollout DIR --out DIR/rollout keeps their "
            "paths, latentrl replay DIR/rollout --episode N draws one; failures.png is where trial 0's late "
            "training episodes failed); more --episodes, or starts through there")


def stop_advice(reached: NDArray[np.bool_], runs: NDArray[np.int_]) -> str | None:
    """What to try when the stopping rule ended a trial below where another got (`reached`: the
    training record, trials × budget; `runs`: the episodes each trial ran): a trial that stopped
    short of the budget and reached the target in the last tenth of its episodes more than
    `RISING` less often than the best trial did in its own was read as a plateau in a dip. The
    zoo's snake: two of four trials stopped at 900 episodes (23 and 16 %) while one ran on to
    58 %; with every episode run (`--episode.stop-window 0`) greedy reach went from 31 to 45 %."""
    late = np.array([row[r - max(1, r // 10):r].mean() for row, r in zip(reached, runs)])
    behind = (runs < reached.shape[1]) & (late < late.max() - RISING)
    if not behind.any():
        return None
    return (f"the stopping rule ended {int(behind.sum())} of {len(runs)} trials below the best one, at "
            f"{', '.join(str(int(r)) for r in runs[behind])} episodes, reaching the target in "
            f"{', '.join(f'{v:.0%}' for v in late[behind])} of their last tenth, where another trial reached "
            f"{late.max():.0%}: --episode.stop-window 0 runs every episode of the budget")


def training_verdict(policy: Any, *, episodes: int = 20, seed: int = 0, findings: Any = None) -> Verdict:
    """The verdict of the module docs on `policy` (a LatentPolicy with its training record), from
    `episodes` rollouts per trial and policy; `findings`: a `check.CheckReport` whose advice joins."""
    runs_of = {kind: policy.rollout(episodes, seed=seed, policy=kind) for kind in ("greedy", "softmax", "random")}
    rollouts = {kind: run["summary"] for kind, run in runs_of.items()}
    per_trial = {kind: [float(v) for v in succeeded(run, rollouts[kind]).reshape(np.shape(run["reached"])).mean(axis=1)]
                 for kind, run in runs_of.items()}  # trials × episodes
    greedy_share = success_share(rollouts["greedy"])
    best = max(greedy_share, success_share(rollouts["softmax"]))
    control = success_share(rollouts["random"])
    below_control = None
    if greedy_share < control:
        verb = "reaches the target" if rollouts["greedy"]["success"] is None else "succeeds"
        below_control = (f"greedy {verb} less often than the random control ({greedy_share:.0%} vs {control:.0%}): "
                         "it has learnt nothing usable from these starts")
    reached = np.asarray(policy.record["reached"], dtype=bool)
    ends = np.asarray(policy.record["ends"])
    runs = (ends >= 0).sum(axis=1)  # a trial the stopping rule ended ran fewer (ends −1 after)
    n = int(runs.min())
    fifth, tenth = max(1, n // 5), max(1, n // 10)

    def last(values: NDArray[Any], k: int, skip: int = 0) -> NDArray[Any]:
        """The `k` episodes of every trial before its last `skip` run, pooled."""
        return np.concatenate([row[r - skip - k:r - skip] for row, r in zip(values, runs)])

    reach_late = float(last(reached, fifth).mean())
    rising = n >= 20 and last(reached, tenth).mean() > last(reached, tenth, tenth).mean() + RISING
    if best >= LEARNT and best > control:
        verdict = "learnt"
    elif not reached.any():
        verdict = "never reached it"
    else:
        verdict = f"{'still' if rising else 'stopped'} improving below the target"
    names = end_reasons()
    late = last(ends, fifth)
    late_ends, late_ends_reached = end_counts(late), end_counts(late[last(reached, fifth).astype(bool)])
    steps: list[str] = []
    if verdict != "learnt":
        greedy = runs_of["greedy"]
        missed = ~succeeded(greedy, rollouts["greedy"])
        failing = np.asarray(greedy["ends"]).ravel()[missed]
        if failing.size:
            worst = names[int(np.bincount(failing, minlength=len(names)).argmax())]
            advice = end_advice(worst, policy.task.to_dict()["learner"])
            if advice is not None:
                steps.append(f"most failing greedy rollouts end as {worst}: {advice}")
            elif worst == "timeout":
                returns = np.asarray(greedy["returns"]).ravel()[missed]
                steps.append(timeout_advice(policy, returns[failing == names.index("timeout")]))
        if rising:
            steps.append("the reach rate was still rising at the end: more --episodes")
        stopped = stop_advice(reached, runs)
        if stopped is not None:
            steps.append(stopped)
        if verdict == "never reached it":
            steps.append("run latentrl check: its target and paths findings say whether the target can be reached")
        if findings is not None:
            steps += [f"{f.name}: {f.fix}" for f in findings.findings if f.verdict != "ok" and f.fix]
    return Verdict(verdict, rollouts, late_ends, late_ends_reached, reach_late, bool(rising), steps, per_trial,
                   below_control)
