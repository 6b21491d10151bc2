"""Will a task learn from these demonstrations? Measured before any training, in seconds
(`latentrl check`, `latentrl.check.check`): each finding is "ok", "warning" or "will not learn", says what
was measured and, where it can, which key to change to what.

    from latentrl.check import check
    report = check(Task.load("my_robot.toml"), postures)   # a CheckReport
    print(report)                                           # one line per finding
    report.verdict                                          # the worst of them

The findings, in order (docs/tasks.md, "Before training: latentrl check"):

- **demos**: rows outside the joint limits, rows that break a rule of the task at rest (an
  obstacle, a constraint, a fall), and joints whose values look like degrees, by row number;
- **fit**: whether the GPLVM's optimiser converged;
- **latent box**: the share of a grid over the latent box, at the learner's own step, whose
  decoded postures are admissible at rest (the task's plant decides, `sim::task::survey`);
- **target**: the closest any admissible grid point brings the effectors to the target, against
  `target.reach_radius`, and how wide the region within it is against the learner's step;
- **paths**: the share of admissible points from which the learner's own moves reach that
  region without breaking a rule, each move run from rest through the task's physics (a move
  that tips a held object or swings through an obstacle on the way is blocked; the share judged
  at rest beside it), and the moves it takes against `episode.max_steps`;
- **encoder**: how many learner steps a decoded posture encodes away from where it was decoded
  (the learner's state after a move is the encoded reached posture);
- **servos**: how far the effectors are from each demo's posture after the servos held it
  0.75 s, against `physics.tolerance`;
- **cost**: the measured time of an RL step, an episode and the run's budget on this machine.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.derive import FIT
from latentrl.physics_check import HOLD_S, servo_error, servo_tolerance
from latentrl.task import DEGREES, Task, end_reasons

VERDICTS = ("ok", "warning", "will not learn")
"""Each finding's verdict, mildest first."""

BROKEN_SHARE = 0.2
"""Demo rows that break a constraint at rest ("drop"): "will not learn" from this share on, since
the learner moves on the demos' manifold; other rules (an obstacle touched, a fall, the joint
limits) and fewer such rows are warnings: the learner can keep off those postures."""

RULE_NAMES = {"box_exit": "outside the joint limits", "obstacle": "touch an obstacle", "fall": "fall"}
"""How the demos finding names the rule a row breaks at rest (a constraint: `broken_constraints`)."""

ADMISSIBLE_SHARE = 0.25
"""Admissible latent points: a warning below this share of the box ("will not learn" at none)."""

PATH_SHARE = 0.5
"""Admissible points with a path to the target: a warning below this share."""

ROUND_TRIP = 1.0
"""Learner steps a decoded posture may encode away from its latent point (the median over the
grid) before the encoder finding warns: on the zoo the robots that learnt had 0.00–0.18, those
that did not 11–79 (docs/tasks.md)."""

MAX_POINTS = 4096
"""Grid points the check surveys at most: each admissible one is put at rest and every learner
move from it run through the physics, ≈ 30 s of CPU for a humanoid at 2 ms per RL step."""


@dataclass(frozen=True)
class Finding:
    """One measured property of the task, its verdict, what to change and the numbers behind it."""

    name: str
    verdict: str
    message: str
    fix: str | None = None
    values: dict[str, Any] = field(default_factory=dict)

    def to_dict(self) -> dict[str, Any]:
        """As written to JSON."""
        return {"name": self.name, "verdict": self.verdict, "message": self.message, "fix": self.fix,
                "values": self.values}


@dataclass(frozen=True)
class CheckReport:
    """The findings of `check_task`, in order; `verdict` is the worst of them."""

    task: str
    findings: tuple[Finding, ...]

    @property
    def verdict(self) -> str:
        """The worst verdict of the findings."""
        return max((f.verdict for f in self.findings), key=VERDICTS.index, default="ok")

    def to_dict(self) -> dict[str, Any]:
        """As written to JSON."""
        return {"task": self.task, "verdict": self.verdict, "findings": [f.to_dict() for f in self.findings]}

    def __str__(self) -> str:
        width = max(len(f.name) for f in self.findings)
        lines = [f"{self.task}: {self.verdict}"]
        for f in self.findings:
            lines.append(f"  {f.verdict:14s} {f.name:{width}s}  {f.message}")
            if f.fix:
                lines.append(f"  {'':14s} {'':{width}s}  → {f.fix}")
        return "\n".join(lines)


def check(task: Task, demos: Any, model: Any = None, *, latent_margin: float | None = None) -> CheckReport:
    """Will `task` learn from `demos` (N, D postures in its joint order, or a DataFrame whose
    columns name its joints)? The findings of the module docs, with the settings `train` would
    derive where the task is silent; `model`: a fitted GPLVM (default: one fitted here, d = 2,
    as `train` fits); `latent_margin`: the box's margin (default: the task's `[run]`, else
    `TrainPreset`'s)."""
    from latentrl.derive import SPACING, applied, derive, even_twin
    from latentrl.gplvm import GPLVM, check_fitted_gplvm, check_model_joints
    from latentrl.run_settings import TrainPreset, latent_box, with_task_run
    from latentrl.task_schema import check_run

    postures = task.postures_of(demos)
    if latent_margin is not None:
        check_run({"latent_margin": latent_margin})  # its one rule, named as run.latent_margin
    if model is not None:
        check_fitted_gplvm(model)
        check_model_joints(model, task.joint_names, "model")
    preset = with_task_run(TrainPreset(), task)
    even: Callable[[], Any] | None = None
    if model is None:  # fitted as `latentrl train` fits, its latent spacing derived as there
        spacing = "fit" if preset.latent_spacing == "auto" else preset.latent_spacing
        model = GPLVM(n_components=2, random_state=preset.seed, max_iter=preset.gplvm_max_iter,
                      encoder=preset.encoder, spacing=spacing).fit(postures)
        even = even_twin(model, preset.latent_spacing)
    low, high = latent_box(model.Z_, preset.latent_margin if latent_margin is None else latent_margin)
    if demo_finding(task, postures).verdict != "will not learn":  # else nothing to derive from: say why
        derived = derive(task, model, low, high, postures, set(task.given), even)
        if even is not None and any(d.key == SPACING for d in derived):
            model = even()
        task = applied(task, derived)
    return check_task(task, postures, model, low, high, budget=(preset.trials, preset.episodes))


def check_task(task: Task, demos: NDArray[np.float64], model: Any, low: NDArray[np.float64],
               high: NDArray[np.float64], *, budget: tuple[int, int] | None = None, threads: int = 1,
               max_points: int = MAX_POINTS, progress: Any = None) -> CheckReport:
    """The findings of the module docs for `task` with `demos` (N, D) in its joint order, the
    fitted GPLVM `model` and the latent box [`low`, `high`]; `budget` (trials, episodes) is the
    training run costed (default: `TrainPreset`'s), on `threads` threads."""
    from latentrl.run_settings import TrainPreset

    findings = [demo_finding(task, demos), fit_finding(model)]
    if findings[0].verdict == "will not learn":  # the rest would measure a space the task refuses
        return CheckReport(task.name, tuple(findings))
    survey = _native.latent_survey(task._native, decoder=model.decoder_, latent_low=low, latent_high=high,
                                   demos=demos, max_points=max_points, physics=True, progress=progress)
    findings += survey_findings(task, survey)
    findings.append(encoder_finding(model, survey))
    findings.append(servo_finding(task, demos))
    findings.append(cost_finding(task, demos, budget or (TrainPreset.trials, TrainPreset.episodes), threads))
    return CheckReport(task.name, tuple(findings))


def demo_finding(task: Task, demos: NDArray[np.float64]) -> Finding:
    """Degrees, joint limits and the task's rules at rest, row by row."""
    looks_like_degrees = [name for j, name in enumerate(task.joint_names) if np.abs(demos[:, j]).max() > DEGREES]
    if looks_like_degrees:
        worst = float(np.abs(demos).max())
        return Finding("demos", "will not learn",
                       f"values up to {worst:.1f} on {', '.join(looks_like_degrees)}: these look like degrees",
                       "write the demonstrations in radians (np.deg2rad)", {"joints": looks_like_degrees})
    try:
        codes, _, _ = task.plant(demos).classify(np.ascontiguousarray(demos))
    except ValueError as err:  # a home posture episodes start at, outside the joint limits (named by its row)
        return Finding("demos", "will not learn", str(err), "fix the demonstrations (or episode.start_demo)")
    names = end_reasons()
    broken = {names[c]: np.flatnonzero(codes == c).tolist() for c in np.unique(codes) if c != 0}
    rows = sorted(r for rs in broken.values() for r in rs)
    wrapped = wrapped_joints(task, demos)
    wrap = (f"{', '.join(wrapped)}: values on both sides of ±π, as if wrapped into [−π, π]: postures a little "
            "apart lie 2π apart in the latent space's inputs; unwrap each recording (np.unwrap along its frames) "
            "and shift it by a multiple of 2π into ±2π") if wrapped else ""
    if wrapped and not rows:
        return Finding("demos", "warning", wrap, "unwrap those joints' values", {"joints": wrapped})
    if not rows:
        return Finding("demos", "ok", f"all {len(demos)} rows are admissible postures at rest")
    what = "; ".join(f"{RULE_NAMES.get(n, 'break the ' + n + ' rule')}: rows {_rows(r)}" for n, r in broken.items()
                     if n != "drop")
    what = "; ".join(filter(None, [what] + [f"break {c}: rows {_rows(r)}" for c, r in
                                            broken_constraints(task, demos, broken.get("drop", [])).items()]))
    dropped = len(broken.get("drop", [])) / len(demos)
    verdict = "will not learn" if dropped >= BROKEN_SHARE else "warning"
    return Finding("demos", verdict, f"{len(rows)} of {len(demos)} rows {what}" + (f"; {wrap}" if wrap else ""),
                   "remove or fix those rows: the latent space is built from them, and the task refuses them"
                   + (" (the learner moves on the demos' manifold: most of it breaks the constraint)"
                      if verdict == "will not learn" else ""),
                   {"rows": dict(broken)})


def broken_constraints(task: Task, demos: NDArray[np.float64], rows: list[int]) -> dict[str, list[int]]:
    """The demo `rows` (which break a constraint at rest) by the constraint they break, each named
    as the task file writes it (``constraints[0] (plane on tip)``): the task's own rule, asked of
    the plant once per constraint with that constraint alone. A row may break several."""
    if not rows:
        return {}
    picked, drop = np.ascontiguousarray(demos[rows]), end_reasons().index("drop")
    named = {}
    for i, rule in enumerate(task.to_dict()["constraints"]):
        alone = task.replace({"constraints": [rule]})
        codes, _, _ = alone.plant(demos).classify(picked)
        broken = [row for row, code in zip(rows, codes) if code == drop]
        if broken:
            link = rule.get("link") or " and ".join(rule.get("links") or [])
            named[f"constraints[{i}] ({rule['kind']} on {link})"] = broken
    return named


def wrapped_joints(task: Task, demos: NDArray[np.float64]) -> list[str]:
    """The unlimited (continuous) joints whose values, shifted by 2π where negative, span at least
    π less than they do: their values lie near both +π and −π, wrapped into [−π, π]."""
    unlimited = np.isinf(task.lower) & np.isinf(task.upper)
    values = demos[:, unlimited]
    shifted = np.where(values < 0, values + 2 * np.pi, values)
    wraps = np.ptp(shifted, axis=0) <= np.ptp(values, axis=0) - np.pi
    return [str(name) for name, w in zip(np.asarray(task.joint_names)[unlimited], wraps) if w]


def fit_finding(model: Any) -> Finding:
    """Whether the GPLVM fit converged."""
    # The model says how its points were placed, not why: a model given to `check` may be spaced by its user.
    spaced = "; its latent points evenly spaced along each axis (spacing='even')" \
        if getattr(model, "spacing", "fit") == "even" else ""
    if getattr(model, "converged_", True):
        return Finding("fit", "ok", f"the GPLVM converged in {getattr(model, 'n_iter_', '?')} iterations{spaced}")
    return Finding("fit", "warning", f"the GPLVM stopped unconverged after {model.n_iter_} iterations",
                   f"raise --gplvm-max-iter above {model.n_iter_}", {"n_iter": int(model.n_iter_)})


def survey_findings(task: Task, survey: dict[str, Any]) -> list[Finding]:
    """The latent box, the target and the paths to it, from `_native.latent_survey`."""
    config = task.to_dict()
    radius = config["target"]["reach_radius"]
    codes, moves = survey["codes"], survey["moves"]
    admissible = codes == 0
    shape, stride = tuple(survey["shape"]), int(survey["stride"])
    share = float(admissible.mean())
    grid = f"{' × '.join(map(str, shape))} grid at {stride} learner step{'s' if stride > 1 else ''}"
    if not admissible.any():
        box = Finding("latent box", "will not learn", f"no point of a {grid} decodes to an admissible posture",
                      "check the demos against the task's rules (the demos finding) and the latent margin")
        return [box]
    box = Finding("latent box", "ok" if share >= ADMISSIBLE_SHARE else "warning",
                  f"{share:.0%} of a {grid} decode to admissible postures at rest",
                  None if share >= ADMISSIBLE_SHARE else "a smaller --latent-margin, or demos that span the task",
                  {"shape": list(shape), "stride": stride, "admissible": share})
    closest = survey["closest"]
    best = float(closest["distance"])
    where = np.round(closest["point"], 3).tolist()
    effectors = np.round(closest["effectors"], 3).reshape(-1, 3).tolist()
    n_reached = int(survey["region_points"])
    if not n_reached:
        target = Finding(
            "target", "will not learn",
            f"no admissible latent point is within target.reach_radius = {radius:g} m of the target: the closest "
            f"is {best:.3f} m away (z = {where}, effectors at {effectors})",
            f"target.position = {effectors} (reachable), or target.reach_radius = {np.ceil(best * 1000) / 1000:g}, "
            "or demos that reach the target", {"closest_m": best, "closest_z": where})
        return [box, target]
    # About one step wide, a step can jump over the region; a half step is the fix only where the
    # starts would still reach it within 1/FIT of an episode (else `derive`'s step rule has chosen
    # reaching it over landing in it: the zoo's Panda-style arm learnt so, 2 points wide).
    physics = survey["moves_in_physics"]
    reachable = physics[physics >= 0]
    needed = int(np.percentile(reachable if len(reachable) else moves[moves >= 0], 95))
    max_steps = config["episode"]["max_steps"]
    isolated = n_reached <= 2 and FIT * 2 * needed <= max_steps
    target = Finding(
        "target", "warning" if isolated else "ok",
        f"{n_reached} admissible points a learner step apart are within {radius:g} m of the target (closest "
        f"{best * 1000:.1f} mm, best reward {max(float(survey['reward'][admissible].max()), closest['reward']):.3f})"
        + ("; the region is about one learner step wide, so a step can jump over it" if isolated else
           f"; about one learner step wide, kept: at half the step 95 % of the starts would need about {2 * needed} "
           f"moves, more than 1/{FIT} of episode.max_steps = {max_steps} (reaching the region comes first)"
           if n_reached <= 2 else ""),
        f"learner.step = {config['learner']['step'] / 2:g} (half) lands more often inside it" if isolated else None,
        {"reached_points": n_reached, "closest_m": best})
    path_share = float((moves[admissible] >= 0).mean())
    moved_share = float((physics[admissible] >= 0).mean())
    blocked = float(np.asarray(survey["blocked"]).reshape(len(codes), -1)[admissible].mean())
    short = max_steps < needed
    verdict = "warning" if short or moved_share < PATH_SHARE else "ok"
    fix = []
    if short:
        fix.append(f"episode.max_steps = {2 * needed}")
    if moved_share < PATH_SHARE <= path_share:
        fix.append("moves break rules on the way between postures that keep them: a smaller learner.step, stiffer "
                   "servos, or demos closer together (neighbouring demos far apart in a joint swing in transit)")
    elif moved_share < PATH_SHARE:
        fix.append("demos that connect the starts with the target, or episode.start that starts nearer it")
    paths = Finding(
        "paths", verdict,
        f"from {moved_share:.0%} of the admissible points the learner's moves reach the target without breaking a "
        f"rule, each move run from rest through the physics ({path_share:.0%} judged at rest; {blocked:.0%} of "
        f"the moves break a rule on the way); 95 % of those need ≤ {needed} moves, episode.max_steps = {max_steps}",
        "; ".join(fix) or None,
        {"with_path": moved_share, "with_path_at_rest": path_share, "blocked_moves": blocked, "moves_p95": needed,
         "max_steps": max_steps})
    return [box, target, paths]


def encoder_finding(model: Any, survey: dict[str, Any]) -> Finding:
    """How far the encoder maps a decoded posture back from where it was decoded, in learner
    steps (the median over the admissible grid points): the learner's state after a move is the
    encoded reached posture, so a round trip of many steps makes its state jump about."""
    admissible = survey["codes"] == 0
    if not admissible.any():
        return Finding("encoder", "ok", "no admissible point to measure")
    if getattr(model, "encoder", None) == "tracking":
        return Finding("encoder", "ok", "the tracking encoder keeps the commanded point of a tracked move "
                       "(0 learner steps by construction)", None, {"median_steps": 0.0, "p90_steps": 0.0})
    points = survey["points"][admissible]
    back = model._encode(model.inverse_transform(points))
    step = float(np.min(survey["spacing"]) / survey["stride"])
    steps = np.linalg.norm(back - points, axis=1) / step
    median = float(np.median(steps))
    values = {"median_steps": median, "p90_steps": float(np.percentile(steps, 90))}
    message = (f"a decoded posture encodes {median:.2g} learner steps from where it was decoded (median; 90 %: "
               f"{values['p90_steps']:.2g})")
    if median <= ROUND_TRIP:
        return Finding("encoder", "ok", message, None, values)
    return Finding("encoder", "warning", message + ": the learner's state jumps after its moves",
                   "--encoder tracking (a tracked move keeps its commanded point) or --encoder back_constrained "
                   "(encodes the demos exactly; on the zoo each helped a different robot), or a converged fit", values)


def servo_finding(task: Task, demos: NDArray[np.float64]) -> Finding:
    """How far the servos leave the effectors (from the base) from up to 5 admissible demo
    postures after moving there and holding each (`physics_check.servo_error`), against
    `physics.tolerance` (1 cm if none)."""
    error = servo_error(task, demos)
    if error is None:
        return Finding("servos", "warning", "no demo row is an admissible posture to hold", "see the demos finding")
    tolerance = servo_tolerance(task)
    values = {"error_m": error, "tolerance_m": tolerance}
    if error <= tolerance:
        return Finding("servos", "ok", f"the servos hold the demos within {error * 1000:.3g} mm "
                       f"(tolerance {tolerance * 1000:g} mm)", None, values)
    return Finding("servos", "warning", f"after {HOLD_S} s the effectors are {error * 1000:.1f} mm from the demo "
                   f"postures (tolerance {tolerance * 1000:g} mm): the servos do not hold the robot there",
                   "stiffer servos (servo.kp, with servo.kd about 2·sqrt(kp·inertia)) or a higher servo.max_force",
                   values)


def cost_finding(task: Task, demos: NDArray[np.float64], budget: tuple[int, int], threads: int) -> Finding:
    """The time of an RL step measured along the demos, an episode of `episode.max_steps` steps and
    the training budget at most: this thread's CPU time, which other work on the machine does not
    inflate (under a load of 5 on 2 cores the wall clock read the biped's step 1.5–4.4× long)."""
    from latentrl.physics_check import demo_path

    plan = demo_path(task, demos, [0, len(demos) - 1])[:50]
    plant = task.plant(demos)
    plant.reset(np.ascontiguousarray(demos[0]))
    start = time.thread_time()
    for target in plan:
        plant.step(np.ascontiguousarray(target))
    per_step = (time.thread_time() - start) / len(plan)
    max_steps = task.to_dict()["episode"]["max_steps"]
    trials, episodes = budget
    run = per_step * max_steps * episodes * trials / max(1, min(threads, trials))
    return Finding("cost", "ok", f"{per_step * 1e3:.3g} ms per RL step here; an episode ≤ {per_step * max_steps:.3g} s; "
                   f"{trials} × {episodes} episodes ≤ {run / 60:.3g} min on {threads} thread(s) (episodes ending "
                   "early cost less)", None, {"rl_step_s": per_step, "budget_s": run})


def _rows(rows: list[int], most: int = 10) -> str:
    shown = ", ".join(map(str, rows[:most]))
    return shown + (f" … ({len(rows)} rows)" if len(rows) > most else "")
