"""How far a task's `[physics]` settings put its robot from a fine-step reference (issue #20,
docs/performance.md): the task's plant follows a path through demonstrated postures twice, at
the task's settings and at `REFERENCE`, and the largest distance of an effector (and of a
floating base) between the two runs is the error. Run it on your own task before a long run:

    from latentrl.physics_check import physics_error
    physics_error(task, demos)   # {"position_m": …, "within": …, "joint_rad": …, "settings": …, …}

rapier's path depends on dt / solver iterations, not on the two apart (docs/performance.md), so
the reference refines both: dt 1/16000 s, 4 solver iterations × 4 PGS passes.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.task import Task

REFERENCE = {"dt": 1 / 16000, "solver_iterations": 4, "pgs_iterations": 4}
"""The reference's physics: 1/16000 s steps, 4 solver iterations × 4 PGS passes (the accuracy
bench's rapier reference, benches/bench_accuracy.py)."""


HOLD_S = 0.75
"""Seconds each demo posture is held by the servos before `servo_error` compares its effectors."""

MOVE_S = 0.25
"""Seconds the servos take from one demo posture to the next in `servo_error`."""


def servo_tolerance(task: Task) -> float:
    """The effector error the servos may leave (m): `physics.tolerance`, 1 cm if none."""
    declared = task.to_dict()["physics"]["tolerance"]
    return 0.01 if declared is None else float(declared)


def servo_error(task: Task, demos: NDArray[np.float64]) -> float | None:
    """The largest distance (m) of an effector (from the robot's base) from where it is at rest in
    up to 5 admissible demo postures, after the servos moved there in `MOVE_S` and held it
    `HOLD_S`; None if no demo row is admissible at rest."""
    plant = task.plant(demos)
    codes, _, _ = plant.classify(np.ascontiguousarray(demos))
    admissible = np.flatnonzero(codes == 0)
    if len(admissible) == 0:
        return None
    order = admissible[np.linspace(0, len(admissible) - 1, min(len(admissible), 5)).round().astype(int)].tolist()
    at_rest = np.array([_from_base(task, plant, demos[i]) for i in order])
    plan = demo_path(task, demos, order, move_s=MOVE_S, hold_s=HOLD_S)
    points, _ = track(task, demos, plan)
    held = np.round(np.cumsum([HOLD_S] + [MOVE_S + HOLD_S] * (len(order) - 1)) / task.rl_dt).astype(int)
    held = np.minimum(held, len(points) - 1)
    reached = points[held, :-1] - points[held, -1:]
    return float(np.linalg.norm(reached - at_rest, axis=-1).max())


def _from_base(task: Task, plant: Any, posture: NDArray[np.float64]) -> NDArray[np.float64]:
    """The effectors (E, 3) of `posture` at rest, from the robot's base (a floating robot may
    stand elsewhere after a walk of servo motions)."""
    plant.reset(np.ascontiguousarray(posture))
    row = np.asarray(plant.row())
    slices = task.row_slices()
    return np.asarray(row[slices["effectors"]].reshape(-1, 3) - row[slices["base_position"]])


def demo_path(task: Task, demos: NDArray[np.float64], order: Sequence[int], move_s: float = 0.25,
              hold_s: float = 0.75) -> NDArray[np.float64]:
    """Servo targets per RL step (steps, D): from `demos[order[0]]` along the joint-space line to
    each next demo of `order` in `move_s`, then held `hold_s`; the first posture is held `hold_s`
    first. Each RL step aims at the line's point at its end."""
    demos = np.asarray(demos, dtype=np.float64)
    d = len(task.joint_names)
    if demos.ndim != 2 or demos.shape[1] != d or not np.isfinite(demos).all():
        raise ValueError(f"demos: expected finite postures of shape (N, {d}) for {task.name}, got {demos.shape}")
    order = list(order)
    if not order or not all(isinstance(i, (int, np.integer)) and 0 <= i < len(demos) for i in order):
        raise ValueError(f"order: expected demo rows in 0..{len(demos) - 1}, got {order!r}")
    postures = demos[order]
    per_move = [0.0, hold_s]
    for _ in postures[1:]:
        per_move += [move_s, hold_s]
    knots = np.cumsum(per_move)
    points = np.repeat(postures, 2, axis=0)
    times = task.rl_dt * np.arange(1, round(knots[-1] / task.rl_dt) + 1)
    return np.stack([np.interp(times, knots, points[:, j]) for j in range(points.shape[1])], axis=1)


def reference_of(task: Task) -> Task:
    """`task` with the `REFERENCE` physics at the same RL step."""
    substeps = round(task.rl_dt / REFERENCE["dt"])
    return task.replace({
        "physics.dt": task.rl_dt / substeps,
        "physics.substeps": substeps,
        "physics.solver_iterations": REFERENCE["solver_iterations"],
        "physics.pgs_iterations": REFERENCE["pgs_iterations"],
    })


def track(task: Task, demos: NDArray[np.float64], plan: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The task's plant at rest at `plan`'s first posture, then following `plan`: after the reset
    and after every RL step, the effectors and the base position (steps + 1, effectors + 1, 3)
    and the joint positions (steps + 1, D). The task's end rules do not stop it (the plant keeps
    stepping)."""
    plant = task.plant(demos)
    end = plant.reset(np.ascontiguousarray(plan[0]))
    if end is not None:
        reason = _native.end_reasons()[end]
        raise ValueError(f"the path's first posture cannot start an episode of {task.name}: it breaks the {reason} rule")
    slices = task.row_slices()
    points, joints = [], []

    def sample() -> None:
        row = np.asarray(plant.row())
        points.append(np.concatenate([row[slices["effectors"]], row[slices["base_position"]]]).reshape(-1, 3))
        joints.append(row[slices["joints"]])

    sample()
    for target in plan:
        plant.step(np.ascontiguousarray(target))
        sample()
    return np.array(points), np.array(joints)


def physics_error(task: Task, demos: NDArray[np.float64], order: Sequence[int] | None = None) -> dict[str, Any]:
    """The largest effector (or base) distance and joint-angle difference between the task's
    physics and `REFERENCE` along `demo_path(task, demos, order)` (default: at most 5 demos,
    evenly spaced over the file, in turn); with the settings compared, the task's declared
    `physics.tolerance` and whether the distance is within it (None if none is declared)."""
    if order is None:
        order = np.linspace(0, len(demos) - 1, min(len(demos), 5)).round().astype(int).tolist()
    plan = demo_path(task, demos, order)
    try:
        p, q = track(task, demos, plan)
    except ValueError as e:
        raise ValueError(f"demo row {order[0]}: {e}") from None
    p_ref, q_ref = track(reference_of(task), demos, plan)
    distance = np.linalg.norm(p - p_ref, axis=-1)
    tolerance = task.to_dict()["physics"]["tolerance"]
    return {
        "position_m": float(distance.max()),
        "tolerance_m": tolerance,
        "within": None if tolerance is None else bool(distance.max() <= tolerance),
        "worst_t_s": float(task.rl_dt * distance.max(axis=1).argmax()),
        "joint_rad": float(np.abs(q - q_ref).max()),
        "simulated_s": float(task.rl_dt * len(plan)),
        "settings": task.to_dict()["physics"],
        "reference": reference_of(task).to_dict()["physics"],
    }
