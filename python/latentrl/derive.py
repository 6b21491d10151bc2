"""Settings derived from the demonstrations and the task where the task file and the flags are
silent (`latentrl train`, `train_latent_policy` on a Task): the paper set its scale parameters by
hand per experiment; a tool for any robot sets them from what it is given. Each derived value
comes with its rule; results.json records them (`setup.derived`) and `train` prints them. A key
the task file or a flag gives always wins; the shipped experiments name theirs.

The rules (docs/tasks.md, "Settings derived from the data"):

- `servo.kp`, `servo.kd` (unless any `servo.*` key is given): the defaults times the first of
  `SERVO_SCALES` (kd also times one of `SERVO_DAMPING`) whose servos hold 5 demo postures
  within `physics.tolerance` (1 cm if none) after moving there (`physics_check.servo_error`,
  the check's servo finding), else the pair that came closest;
- `learner.initial_weight` = 1 / (1 − γ): optimistic, the largest return of rewards ≤ 1, so
  unvisited states look worth visiting (the quick presets' choice, made a rule);
- `learner.step`: the largest of 1, 1/2, 1/4, 1/8, 1/16 RBF spacings at which the target region
  (admissible latent points within `target.reach_radius`, `latentrl check`'s survey) spans at
  least `SPAN` steps across, so a move can land inside it and stay — unless 95 % of the starts
  would then need more than 1/`FIT` of `episode.max_steps` moves to reach it: then the smallest
  step at which they need at most that (reaching the target first, landing in it second);
- `latent_spacing` (with `latent_spacing = "auto"`, `latentrl train`'s default): "even" (the
  GPLVM's points evenly spaced along each axis, `GPLVM(spacing="even")`) when the fit's own points
  leave no step above at which the target region spans `SPAN` steps and 95 % of the starts reach
  it within 1/`FIT` of an episode — the fit packed the demos near the target into a cluster no one
  step suits — and the step then derived on the evenly spaced points;
- `episode.max_steps` = `SLACK` × the moves that 95 % of admissible starts need to the target at
  that step (at least `MIN_STEPS`, at most the schema's default);
- `episode.stop_window` = `STOP_WINDOW`: a trial stops once 3 windows of that many episodes in a
  row raised neither its reach count nor its mean return by 1 % (`latent_core::stopping`), so
  the episode budget is a ceiling.
"""

from __future__ import annotations

import itertools
from collections.abc import Callable
from dataclasses import dataclass
from functools import lru_cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.task import Task, schema

STEPS = (1.0, 0.5, 0.25, 0.125, 0.0625)
"""Learner steps tried, in RBF spacings, largest first."""

SPAN = 3.0
"""Learner steps the target region must span across (the side of a square of its points)."""

FIT = 2
"""An episode holds at least this many times the moves 95 % of starts need at the learner's step:
a step so small that the path fills the episode leaves no room to explore (the zoo's 7-DoF arms
at 1/8 RBF spacing needed 158–164 of their 200 steps and never learnt; at 1/4, 79–82)."""

SLACK = 3
"""Episode length over the moves 95 % of starts need at rest: room to explore and to hold."""

MIN_STEPS = 50
"""The shortest derived episode."""

SERVO_SCALES = (1.0, 4.0, 16.0, 64.0)
"""Multiples of the default servo gains tried, both kp and kd: gains scaled with the inertia they
move keep the servos' natural frequency and damping ratio, so this ladder fits the default's
response to robots 4, 16 and 64 times heavier."""

SERVO_DAMPING = (1.0, 2.0, 4.0)
"""Extra kd factors tried at each scale: a longer or floating robot (more inertia per stiffness)
needs a larger kd / kp to stay critically damped."""

STOP_WINDOW = 100
"""Episodes per window of the stopping rule: a window's reach count moves by whole episodes, so
a window of 100 sees a 1 % change of the reach rate."""


@dataclass(frozen=True)
class Derived:
    """A setting derived where nothing gave it: its key, value and the rule that chose it."""

    key: str
    value: Any
    rule: str

    def to_dict(self) -> dict[str, Any]:
        """As recorded in results.json."""
        return {"key": self.key, "value": self.value, "rule": self.rule}


def derive(task: Task, model: Any, low: NDArray[np.float64], high: NDArray[np.float64],
           demos: NDArray[np.float64], given: set[str], even: Callable[[], Any] | None = None) -> list[Derived]:
    """The settings of the module docs that `given` (the keys the task file and the flags set)
    leaves open, for `task` in the latent box [`low`, `high`] of `model`. With `even` (the same
    GPLVM fitted with `spacing="even"`, made when called), the latent spacing too: the caller
    trains on `even()` if the result holds `SPACING`."""
    out = []
    config = task.to_dict()
    if not any(key.startswith("servo.") for key in given):
        out += servo_gains(task, demos)
        task = applied(task, out)  # the surveys below run moves through these servos
    if "learner.initial_weight" not in given:
        w0 = 1.0 / (1.0 - config["learner"]["gamma"])
        out.append(Derived("learner.initial_weight", w0, f"1 / (1 − γ) with γ = {config['learner']['gamma']:g}: "
                                                          "optimistic, the largest return of rewards ≤ 1"))
    step = config["learner"]["step"]
    survey = None
    if "learner.step" in given:  # surveyed as given: one too small to survey the box is refused before training
        survey = survey_at_step(task, model, low, high, demos)
    else:
        budget = config["episode"]["max_steps"] if "episode.max_steps" in given else _default("episode.max_steps")

        def step_on(m: Any) -> tuple[float, dict[str, Any], str, bool] | None:
            return learner_step(lambda s: survey_at_step(task.replace({"learner.step": s}, task.origin), m, low, high, demos), budget)

        spaced = even is not None and getattr(model, "spacing", "fit") == "even"  # a run's model, read back
        found = None if spaced else step_on(model)
        if even is not None and (spaced or found is None or not found[3]):
            model = model if spaced else even()
            out.append(Derived(SPACING, "even", SPACING_RULE))
            found = step_on(model)
        if found is not None:
            step, survey, rule, _ = found
            out.append(Derived("learner.step", step, rule))
    if "episode.max_steps" not in given:
        survey = survey or survey_at_step(task.replace({"learner.step": step}, task.origin), model, low, high, demos)
        needed = moves95(survey)
        if needed is not None:
            default = _default("episode.max_steps")
            value = int(min(default, max(MIN_STEPS, SLACK * needed)))
            out.append(Derived("episode.max_steps", value, f"{SLACK} × the {needed} moves 95 % of admissible starts "
                                                           f"need to the target at rest (in [{MIN_STEPS}, {default}])"))
    if "episode.stop_window" not in given:
        out.append(Derived("episode.stop_window", STOP_WINDOW,
                           f"stop a trial after {config['episode']['stop_patience']} windows of {STOP_WINDOW} episodes "
                           "in a row without a higher reach count or a mean return 1 % higher (the budget is a ceiling)"))
    return out


def learner_step(survey_at: Callable[[float], dict[str, Any]],
                 budget: int) -> tuple[float, dict[str, Any], str, bool] | None:
    """`learner.step` (module docs): the largest of `STEPS` at which the target region spans
    `SPAN` steps, unless 95 % of the starts then need more than `budget` / `FIT` moves — then the
    smallest step at which they need at most that, if any; with its survey (`survey_at(step)`),
    rule and whether the starts reach the region within `budget` / `FIT` moves at it. None if the
    target region spans `SPAN` steps at no candidate."""
    spans = f"the largest of {', '.join(f'{s:g}' for s in STEPS)} RBF spacings at which the target region spans ≥ {SPAN:g} steps"
    fitting = None
    for candidate in STEPS:
        found = survey_at(candidate)
        span, moves = region_span(found), moves95(found)
        fits = moves is not None and FIT * moves <= budget
        if fits:
            fitting = (candidate, found, span, moves)
        if span < SPAN:
            continue
        if fits or fitting is None:
            return candidate, found, f"{spans} (it spans {span:.1f})", fits
        step, found, span, moves = fitting
        return step, found, (f"{spans} would be {candidate:g}, where 95 % of the starts need more than 1/{FIT:g} of "
                             f"an episode's {budget} steps to reach it: the smallest step at which they need at most "
                             f"that ({moves} moves; the region spans {span:.1f} steps)"), True
    return None


SPACING = "latent_spacing"
"""The run setting (not a task key) the spacing rule derives: `GPLVM.spacing` of the fit."""

SPACING_RULE = (f"the fit's own latent points leave no learner step at which the target region spans ≥ {SPAN:g} steps "
                f"and 95 % of the starts reach it within 1/{FIT:g} of an episode: the GPLVM's points evenly spaced "
                "along each axis (GPLVM(spacing='even'), docs/encoders.md)")


def even_twin(model: Any, latent_spacing: str) -> Callable[[], Any] | None:
    """The `even` argument of `derive` for `model`, a GPLVM fitted here with the run setting
    `latent_spacing`: its evenly spaced twin, made once when asked, where the spacing is derived
    ("auto"); None where it is not, or where the points cannot move (back-constrained)."""
    if latent_spacing != "auto" or model.encoder == "back_constrained":
        return None
    return lambda: _evenly_spaced(model)


@lru_cache(maxsize=1)
def _evenly_spaced(model: Any) -> Any:
    """`model.evenly_spaced()`, once per fit (a run's validation, setup and check share it)."""
    return model.evenly_spaced()


def servo_gains(task: Task, demos: NDArray[np.float64]) -> list[Derived]:
    """`servo.kp` and `servo.kd` (module docs): the first of `SERVO_SCALES` × the default gains
    whose servos hold the demos within the tolerance (`physics_check.servo_error`), else the one
    that came closest."""
    from latentrl.physics_check import servo_error, servo_tolerance

    kp0, kd0 = _default("servo.kp"), _default("servo.kd")
    tolerance, tried = servo_tolerance(task), []
    for scale, damping in itertools.product(SERVO_SCALES, SERVO_DAMPING):
        gains = {"servo.kp": kp0 * scale, "servo.kd": kd0 * scale * damping}
        error = servo_error(task.replace(gains, task.origin), demos)
        if error is None:
            return []
        tried.append((error, scale, damping, gains))
        if error <= tolerance:
            break
    # The first pair that holds is also the closest: every pair before it missed the tolerance.
    error, scale, damping, gains = min(tried, key=lambda t: t[0])
    held = "they hold" if error <= tolerance else "none held; these came closest"
    rule = (f"(kp, kd) = ({kp0:g}, {kd0:g}) × {scale:g}, kd × {damping:g}: the first of the scales "
            f"{', '.join(f'{s:g}' for s in SERVO_SCALES)} (each with kd × {', '.join(f'{d:g}' for d in SERVO_DAMPING)})"
            f" whose servos hold 5 demo postures within {tolerance * 1000:g} mm; {held} ({error * 1000:.3g} mm)")
    return [Derived(key, value, rule) for key, value in gains.items()]


def applied(task: Task, derived: list[Derived] | tuple[Derived, ...]) -> Task:
    """`task` with the `derived` settings set (its origin kept, for error messages)."""
    return task.replace({d.key: d.value for d in derived if d.key != SPACING}, origin=task.origin)


def _default(key: str) -> Any:
    """The schema's default of task key `key`."""
    return next(e["default"] for e in schema() if e["key"] == key)


def survey_at_step(task: Task, model: Any, low: NDArray[np.float64], high: NDArray[np.float64],
                   demos: NDArray[np.float64]) -> dict[str, Any]:
    """`latentrl check`'s survey of the latent box [`low`, `high`] at `task`'s `learner.step`:
    which points decode to admissible postures, reach the target, and in how many moves."""
    return _native.latent_survey(task._native, decoder=model.decoder_, latent_low=low, latent_high=high, demos=demos)


def moves95(survey: dict[str, Any]) -> int | None:
    """The moves to the target that 95 % of the admissible starts with a path need (None: no path)."""
    moves = np.asarray(survey["moves"])
    moves = moves[moves >= 0]
    return int(np.percentile(moves, 95)) if len(moves) else None


def region_span(survey: dict[str, Any]) -> float:
    """Learner steps the target region spans across: the side of a square (cube…) of its points
    one learner step apart (`region_points`, counted at the learner's step even where the
    survey's grid is coarser)."""
    return float(survey["region_points"] ** (1 / len(survey["shape"])))
