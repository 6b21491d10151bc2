"""Accuracy against cost of the rapier3d sim (`latentrl._native.Sim`) and of MuJoCo on the same
URDFs (issue #20): each plant follows a demonstrated path at a grid of physics settings, and
each run is compared with a fine-step reference of its own engine and of the other one.

Run it in the bench venv (MuJoCo and matplotlib are never dependencies of latentrl itself):

    bash benches/setup_bench_env.sh
    benches/.venv-bench/bin/python benches/bench_accuracy.py [--quick]

Writes `benches/results/bench_accuracy.json` and `docs/figures/accuracy-{arms,humanoid,glass_arm}.png`;
docs/performance.md reads them (`--quick`: `bench_accuracy-quick.json` and the figures in
benches/results/).

The models are bench_sim.py's (`RapierRobot`, `MujocoRobot`: same URDF, servo gains and caps,
friction, no self-collisions), built here at other time steps and solver settings:

- arms: `two_arms.urdf`, fixed root, kp 5000, kd 50, cap 1000 N·m. The servo targets follow
  the joint-space line through 5 demonstrated postures (`arm_postures(5, default_rng(0))`),
  0.5 s per segment, then hold the last one 0.5 s: 2.5 s, from rest at the first posture.
- humanoid: `khr1hv.urdf`, floating root on the floor, kp 8, kd 0.1, cap 1.2 N·m (the
  `humanoid_lift` task's `[servo]`). It stands at its home posture (every joint 0; placed by
  `Sim.reset_on_ground`, soles 0.5 mm above the floor, MuJoCo's base at the same height) for
  0.5 s, then goes to the shipped lift demos 6, 5 and 6, 1 s each: the targets move along the
  joint-space line in the first 0.25 s, then hold. 3.5 s.
- glass_arm: the README's own-robot tutorial (`examples/glass_arm/`, a task file beside its
  URDF): fixed root, 3 joints, kp 2000, kd 20, cap 100 N·m (the URDF's effort); the line through
  5 of its demos spread over `demos.csv`, 0.5 s per segment, hold 0.5 s: 2.5 s. Tracked: `glass`.

The targets change once per RL step (0.05 s, every sample); in between the engine takes
0.05 s / dt physics steps in one call. Sampled after every RL step: the joint positions and
the tracked points, the two hand frames (arms `left_hand`, `right_hand`; humanoid `l_hand`,
`r_hand`) and for the humanoid the base (root link origin).

References, at dt 1/16000 s: rapier at 4 solver iterations × 4 PGS passes, MuJoCo with its
default solver (Newton, tolerance 1e-8) and the `implicitfast` integrator (at dt 1/4000 the
humanoid's had not converged; each reference is checked against its engine at twice the step
and at other solver settings). The grid: dt 1/120, 1/240, 1/480, 1/960 s and, to see where the
humanoid gets near the tolerance, 1/1920 and 1/3840 s; rapier (solver iterations, PGS passes) (1, 1), (1, 4), (2, 1), (2, 4), (3, 4),
(4, 1), (4, 4); MuJoCo `implicitfast` and `discrete`. Per setting: position error = the largest
distance of a tracked point from the same point of the reference over the samples, hand error
(hands only), joint error (largest joint-angle difference), against the engine's own
reference and against the other engine's; a run that yields a non-finite value has diverged,
a humanoid whose base falls below half its start height has fallen.

The JSON names the cheapest setting per engine within 1 mm (the tolerance), 5 mm and 10 mm,
and the cheapest MuJoCo setting as close to its reference as rapier at the task file's setting.

Cost: CPU time of the calling thread (`time.thread_time`, as bench_sim) spent in the step
calls, per simulated second; the median of several runs of the whole path (at least 3, more
for cheap settings until ≥ 0.3 s is timed), each in a freshly built world, which also checks
that a run repeats bit for bit.
"""

from __future__ import annotations

import argparse
import datetime
import math
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from bench_sim import (
    ARMS,
    CLEARANCE,
    DT,
    FRICTION,
    SUBSTEPS,
    MujocoRobot,
    RapierRobot,
    machine,
    mujoco,
    mujoco_integrators,
)
from latentrl import LatentrlError
from latentrl.datasets import arm_postures
from latentrl.demos import load_demos
from latentrl.envs import shipped_demos
from latentrl.results import write_json
from latentrl.robot_info import urdf_info
from latentrl.task import Task

ROOT = Path(__file__).resolve().parent.parent
RL_DT = DT * SUBSTEPS  # 0.05 s: one sample, one change of the targets
# The time steps, and two finer ones to see where the humanoid gets near 1 mm.
DTS = (1 / 120, 1 / 240, 1 / 480, 1 / 960, 1 / 1920, 1 / 3840)
RAPIER_ITERATIONS = ((1, 1), (1, 4), (2, 1), (2, 4), (3, 4), (4, 1), (4, 4))  # (solver iterations, PGS passes)
# At dt 1/4000 the humanoid's references had not converged (rapier 1.3 mm from its 1/8000 run,
# MuJoCo 11 mm from its 1/16000 one), so both engines' references take dt 1/16000.
REFERENCE_DT = 1 / 16000
# rapier's path follows its TGS sub-step dt / solver iterations (8 × 4 at 1/4000 and 4 × 4 at
# 1/8000 agree within 0.03 mm on the humanoid): this one's sub-step is 1/64000 s.
RAPIER_REFERENCE = (4, 4)
MUJOCO_REFERENCE = "implicitfast"
# Checks of the references themselves: rapier at twice the step or half the iterations; MuJoCo
# at twice the step or with the other integrators (its default, explicit Euler, included).
RAPIER_REFERENCE_CHECKS = ((2 * REFERENCE_DT, 4, 4), (REFERENCE_DT, 2, 4))
MUJOCO_REFERENCE_CHECKS = (
    (2 * REFERENCE_DT, "implicitfast"),
    (REFERENCE_DT, "discrete"),
    (REFERENCE_DT, "euler"),
)
TOLERANCE = 1e-3  # m: every tracked point within 1 mm of the reference at every sample
TOLERANCES = (TOLERANCE, 5e-3, 1e-2)  # the cheapest settings are also given at looser ones
GLASS_ARM = ROOT / "examples" / "glass_arm"  # the README's own-robot tutorial
# The task of each plant: a shipped one by name, or a task file
TASKS: dict[str, str | Path] = {
    "arms": "two_arms",
    "humanoid": "humanoid_lift",
    "glass_arm": GLASS_ARM / "glass_arm.toml",
}
FELL = Task.shipped("humanoid_lift").to_dict()["fall"]["base_height_fraction"]
MIN_REPEATS, MAX_REPEATS, MIN_TIMED_S = 3, 20, 0.3
FIGURES = ROOT / "docs" / "figures"


# ---------------------------------------------------------------------------------------------
# Plants and their paths


@dataclass(frozen=True)
class Plant:
    """A URDF robot, its servo and the path its targets follow."""

    name: str
    urdf: Path
    gains: dict[str, float]
    start: np.ndarray  # (D,) posture at rest at t = 0
    plan: np.ndarray  # (steps, D): the targets of RL step k, held for RL_DT
    hands: tuple[str, ...]  # the hand frames compared (the task's effectors)
    root: str | None = None  # the floating root link (its origin is tracked too), or None

    @property
    def duration(self) -> float:
        return len(self.plan) * RL_DT


def line(points: np.ndarray, knots: np.ndarray, times: np.ndarray) -> np.ndarray:
    """The piecewise-linear path through `points` (K, D) at `knots` (K,), at `times` (T,)."""
    return np.stack([np.interp(times, knots, points[:, j]) for j in range(points.shape[1])], axis=1)


def task_of(plant: str) -> Task:
    name = TASKS[plant]
    return Task.load(name) if isinstance(name, Path) else Task.shipped(name)


def through(name: str, postures: np.ndarray, gains: dict[str, float]) -> Plant:
    """A fixed-root plant whose targets follow the line through `postures`, 0.5 s per segment,
    then hold the last one 0.5 s."""
    task = task_of(name)
    knots = 0.5 * np.arange(len(postures))
    # RL step k aims at the path's point at its end, (k + 1) RL_DT
    times = RL_DT * np.arange(1, round((knots[-1] + 0.5) / RL_DT) + 1)
    return Plant(
        name, task.urdf_path, gains, postures[0], line(postures, knots, times), tuple(task.effectors)
    )


def arms_plant() -> Plant:
    return through("arms", arm_postures(5, np.random.default_rng(0)), ARMS)


def glass_arm_plant() -> Plant:
    """The tutorial's arm through 5 of its demos spread over the file (those physics_check's
    default path visits, there in faster moves), at its task's gains and its URDF's effort limit (the cap rapier applies; MuJoCo's
    force range)."""
    task = task_of("glass_arm")
    demos = load_demos(GLASS_ARM / "demos.csv", expected_joints=task.joint_names).postures
    efforts = {j["effort"] for j in urdf_info(task.urdf_path)["joints"] if j["name"] in task.joint_names}
    assert len(efforts) == 1, f"one force range for all joints expected, got {efforts}"
    servo = task.to_dict()["servo"]
    gains = {"kp": servo["kp"], "kd": servo["kd"], "max_force": min(servo["max_force"], *efforts)}
    return through("glass_arm", demos[np.linspace(0, len(demos) - 1, 5).round().astype(int)], gains)


def humanoid_plant() -> Plant:
    task = task_of("humanoid")
    demos = shipped_demos("humanoid_lift")
    home = np.zeros(len(task.joint_names))
    poses = [home, home, demos[6], demos[6], demos[5], demos[5], demos[6], demos[6]]
    knots = np.array([0.0, 0.5, 0.75, 1.5, 1.75, 2.5, 2.75, 3.5])
    times = RL_DT * np.arange(1, round(knots[-1] / RL_DT) + 1)
    children = {child for _, child in task.edges}
    root = next(parent for parent, _ in task.edges if parent not in children)
    return Plant(
        "humanoid",
        task.urdf_path,
        task.to_dict()["servo"],
        home,
        line(np.array(poses), knots, times),
        tuple(task.effectors),
        root,
    )


# ---------------------------------------------------------------------------------------------
# Building the robots, reading the tracked points


def substeps(dt: float) -> int:
    n = round(RL_DT / dt)
    assert math.isclose(n * dt, RL_DT), f"dt {dt} does not divide the RL step"
    return n


def rapier(plant: Plant, dt: float, iterations: int, pgs: int) -> Callable[[], Any]:
    def make() -> RapierRobot:
        robot = RapierRobot(
            plant.urdf,
            floating=plant.root is not None,
            gains=plant.gains,
            iterations=iterations,
            pgs_iterations=pgs,
            floor=0.0 if plant.root else None,
            sole="l_foot" if plant.root else None,
            dt=dt,
            substeps=substeps(dt),
        )
        robot.unstable = lambda: False  # a blown-up rapier world shows as non-finite values
        robot.points = lambda: np.array(
            [robot.sim.frame_position(h) for h in plant.hands]
            + ([robot.sim.base_position()] if plant.root else [])
        )
        return robot

    return make


def start_height(plant: Plant) -> float:
    """Base height rapier's `reset_on_ground` gives the start posture (MuJoCo starts there)."""
    robot = rapier(plant, DT, 1, 1)()
    robot.reset(plant.start)
    return robot.base_height()


def mujoco_robot(plant: Plant, dt: float, integrator: str, height: float) -> Callable[[], Any]:
    # A URDF's body-less hand links are fused into their parent at compile time: read each hand
    # frame's place in its parent from the spec.
    spec = mujoco.MjSpec.from_file(str(plant.urdf))
    frames = [(spec.body(h).parent.name, np.array(spec.body(h).pos)) for h in plant.hands]

    def make() -> MujocoRobot:
        robot = MujocoRobot(
            plant.urdf,
            names(plant),
            gains=plant.gains,
            integrator=integrator,
            floating_body=plant.root,
            floor=plant.root is not None,
            start_height=height,
            dt=dt,
        )
        ids = [robot.model.body(parent).id for parent, _ in frames]

        def points() -> np.ndarray:
            mujoco.mj_kinematics(robot.model, robot.data)  # xpos after mj_step is one step old
            d = robot.data
            out = [d.xpos[i] + d.xmat[i].reshape(3, 3) @ p for i, (_, p) in zip(ids, frames)]
            return np.array(out + ([d.xpos[robot.body]] if plant.root else []))

        robot.points = points
        # MuJoCo resets a world whose accelerations blow up (and warns): the run has diverged
        robot.unstable = lambda: robot.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0
        return robot

    return make


_NAMES: dict[str, list[str]] = {}


def names(plant: Plant) -> list[str]:
    """latentrl's joint order (MuJoCo's actuator i drives joint i of it)."""
    if plant.name not in _NAMES:
        _NAMES[plant.name] = list(rapier(plant, DT, 1, 1)().joint_names)
    return _NAMES[plant.name]


# ---------------------------------------------------------------------------------------------
# Runs


@dataclass
class Run:
    """One setting: samples of its first run and the cost of every run."""

    q: np.ndarray  # (steps + 1, D) joint positions, t = 0 and after each RL step
    p: np.ndarray  # (steps + 1, P, 3) tracked points
    cpu_s: list[float]  # step-call CPU time per run of the whole path
    simulated_s: float  # how far the first run got (the whole path unless it diverged)
    status: str  # "ok", "fell", "diverged" or "error: ..."
    repeatable: bool


def run_once(
    plant: Plant, make: Callable[[], Any], n: int
) -> tuple[np.ndarray, np.ndarray, float, str, float]:
    """One run of the path from a fresh world: samples, step-call CPU time, status, simulated s."""
    robot = make()
    robot.reset(plant.start)
    steps, dof = plant.plan.shape
    q = np.full((steps + 1, dof), np.nan)
    p = np.full((steps + 1, len(plant.hands) + (plant.root is not None), 3), np.nan)
    q[0], p[0] = robot.joint_positions(), robot.points()
    spent, status = 0.0, "ok"
    try:
        for k, targets in enumerate(plant.plan):
            robot.set_targets(targets)
            c0 = time.thread_time()
            robot.step(n)
            spent += time.thread_time() - c0
            q[k + 1], p[k + 1] = robot.joint_positions(), robot.points()
            if robot.unstable() or not (
                np.isfinite(q[k + 1]).all() and np.isfinite(p[k + 1]).all()
            ):
                q[k + 1], p[k + 1] = np.nan, np.nan
                return q, p, spent, "diverged", (k + 1) * RL_DT
    except LatentrlError as err:  # a native error from a blown-up world
        return q, p, spent, f"error: {type(err).__name__}: {err}", (k + 1) * RL_DT
    if plant.root is not None and p[:, -1, 2].min() < FELL * p[0, -1, 2]:
        status = "fell"
    return q, p, spent, status, plant.duration


def rollout(plant: Plant, make: Callable[[], Any], dt: float, *, repeats: int | None = None) -> Run:
    n = substeps(dt)
    q, p, spent, status, simulated = run_once(plant, make, n)
    cpu = [spent]
    repeatable = True
    if status in ("ok", "fell"):
        total = repeats or min(
            MAX_REPEATS, max(MIN_REPEATS, math.ceil(MIN_TIMED_S / max(spent, 1e-9)))
        )
        for _ in range(total - 1):
            q2, p2, s2, _, _ = run_once(plant, make, n)
            cpu.append(s2)
            repeatable &= bool(np.array_equal(q, q2) and np.array_equal(p, p2))
    return Run(q, p, cpu, simulated, status, repeatable)


def errors(run: Run, ref: Run, hands: int) -> dict[str, float | None]:
    """Largest errors over the samples against `ref` (None where `run` diverged)."""
    if not (np.isfinite(run.q).all() and np.isfinite(run.p).all()):
        return {
            "position_m": None,
            "hands_m": None,
            "base_m": None,
            "joint_rad": None,
            "worst_t_s": None,
        }
    d = np.linalg.norm(run.p - ref.p, axis=-1)  # (samples, points)
    return {
        "position_m": float(d.max()),
        "worst_t_s": RL_DT * int(d.max(axis=1).argmax()),  # when the position error peaks
        "hands_m": float(d[:, :hands].max()),
        "base_m": float(d[:, hands:].max()) if d.shape[1] > hands else None,
        "joint_rad": float(np.abs(run.q - ref.q).max()),
    }


def row(engine: str, dt: float, setting: dict[str, Any], run: Run, plant: Plant) -> dict[str, Any]:
    cost = statistics.median(run.cpu_s) / run.simulated_s
    return {
        "engine": engine,
        "dt": dt,
        "steps_per_s": round(1 / dt),
        **setting,
        "status": run.status,
        "ms_per_simulated_s": 1e3 * cost,
        "runs": len(run.cpu_s),
        "simulated_s": run.simulated_s,
        "repeatable": run.repeatable,
        "base_height_min_m": float(np.nanmin(run.p[:, -1, 2]))
        if plant.root and run.status != "diverged"
        else None,
    }


def label(r: dict[str, Any]) -> str:
    tail = (
        f"{r['solver_iterations']}×{r['pgs_iterations']}"
        if r["engine"] == "rapier"
        else r["integrator"]
    )
    return f"{r['engine']} 1/{r['steps_per_s']} {tail}"


def case(plant: Plant, *, quick: bool) -> dict[str, Any]:
    height = start_height(plant) if plant.root else 0.0
    hands = len(plant.hands)
    dts = DTS[1:3] if quick else DTS
    ref_dt = 8 * REFERENCE_DT if quick else REFERENCE_DT
    print(f"{plant.name}: {len(plant.plan)} RL steps ({plant.duration:.2f} s simulated)")

    refs = {
        "rapier": rollout(plant, rapier(plant, ref_dt, *RAPIER_REFERENCE), ref_dt, repeats=1),
        "mujoco": rollout(
            plant, mujoco_robot(plant, ref_dt, MUJOCO_REFERENCE, height), ref_dt, repeats=1
        ),
    }
    other = {"rapier": "mujoco", "mujoco": "rapier"}
    references: dict[str, Any] = {
        "dt": ref_dt,
        "rapier": {"solver_iterations": RAPIER_REFERENCE[0], "pgs_iterations": RAPIER_REFERENCE[1]},
        "mujoco": {"integrator": MUJOCO_REFERENCE, "solver": "Newton (default), tolerance 1e-8"},
        "status": {e: r.status for e, r in refs.items()},
        "ms_per_simulated_s": {e: 1e3 * r.cpu_s[0] / plant.duration for e, r in refs.items()},
        "rapier_vs_mujoco": errors(refs["rapier"], refs["mujoco"], hands),
        "start_points_rapier_vs_mujoco_m": float(
            np.linalg.norm(refs["rapier"].p[0] - refs["mujoco"].p[0], axis=-1).max()
        ),
        "checks": {},
        "points": {e: r.p for e, r in refs.items()},  # (samples, points, 3)
        "joints": {e: r.q for e, r in refs.items()},
    }
    print(
        f"  references ({references['status']}), rapier vs MuJoCo: {fmt(references['rapier_vs_mujoco'])}"
    )
    checks = (
        []
        if quick
        else [
            *(
                ("rapier", d, rapier(plant, d, it, pgs), f"rapier dt 1/{round(1 / d)} {it}×{pgs}")
                for d, it, pgs in RAPIER_REFERENCE_CHECKS
            ),
            *(
                ("mujoco", d, mujoco_robot(plant, d, i, height), f"mujoco dt 1/{round(1 / d)} {i}")
                for d, i in MUJOCO_REFERENCE_CHECKS
            ),
        ]
    )
    for engine, d, make, name in checks:
        run = rollout(plant, make, d, repeats=1)
        references["checks"][name] = {"status": run.status, **errors(run, refs[engine], hands)}
        print(
            f"  check {name:32s} vs its reference: {run.status}, {fmt(references['checks'][name])}"
        )

    settings: list[tuple[str, float, dict[str, Any], Callable[[], Any]]] = []
    for dt in dts:
        for it, pgs in RAPIER_ITERATIONS:
            cfg = {"solver_iterations": it, "pgs_iterations": pgs}
            settings.append(("rapier", dt, cfg, rapier(plant, dt, it, pgs)))
        for integrator in mujoco_integrators():
            settings.append(
                (
                    "mujoco",
                    dt,
                    {"integrator": integrator},
                    mujoco_robot(plant, dt, integrator, height),
                )
            )
    rows = []
    for engine, dt, cfg, make in settings:
        run = rollout(plant, make, dt)
        r = row(engine, dt, cfg, run, plant)
        r["own"] = errors(run, refs[engine], hands)
        r["other"] = errors(run, refs[other[engine]], hands)
        rows.append(r)
        print(
            f"  {label(r):30s} {r['ms_per_simulated_s']:8.2f} ms/s ({r['runs']} runs) {r['status']:8s} "
            f"own: {fmt(r['own'])}; other: {fmt(r['other'])}"
        )
    return {
        "plan": {
            "duration_s": plant.duration,
            "rl_step_s": RL_DT,
            "samples": len(plant.plan) + 1,
            "start": plant.start,
            "targets": plant.plan,
            "points": [*plant.hands, *([f"{plant.root} (base)"] if plant.root else [])],
        },
        "gains": plant.gains,
        "tolerance_m": task_of(plant.name).to_dict()["physics"]["tolerance"],
        "start_base_height_m": height if plant.root else None,
        "references": references,
        "rows": rows,
        "cheapest_within": {f"{1e3 * t:g} mm": cheapest(rows, t) for t in TOLERANCES},
        "shipped": shipped(plant.name, rows),
    }


def fmt(e: dict[str, float | None]) -> str:
    if e["position_m"] is None:
        return "diverged"
    return f"pos {1e3 * e['position_m']:.3g} mm, joint {1e3 * e['joint_rad']:.3g} mrad"


def cheapest(rows: list[dict[str, Any]], tolerance: float) -> dict[str, Any]:
    """Per engine and reference: the cheapest setting that stood with every tracked point within
    `tolerance` (m) of the reference at every sample, and the cost ratio rapier / MuJoCo."""
    out: dict[str, Any] = {}
    for engine in ("rapier", "mujoco"):
        for ref in ("own", "other"):
            ok = [r for r in rows if r["engine"] == engine and within(r, ref, tolerance)]
            best = min(ok, key=lambda r: r["ms_per_simulated_s"]) if ok else None
            out[f"{engine}_{ref}"] = (
                None
                if best is None
                else {
                    "setting": label(best),
                    "ms_per_simulated_s": best["ms_per_simulated_s"],
                    "position_m": best[ref]["position_m"],
                    "joint_rad": best[ref]["joint_rad"],
                }
            )
    for ref in ("own", "other"):
        a, b = out[f"rapier_{ref}"], out[f"mujoco_{ref}"]
        out[f"cost_ratio_rapier_over_mujoco_{ref}"] = (
            a["ms_per_simulated_s"] / b["ms_per_simulated_s"] if a and b else None
        )
    return out


def within(r: dict[str, Any], ref: str, tolerance: float) -> bool:
    e = r[ref]["position_m"]
    return r["status"] == "ok" and e is not None and e <= tolerance


def shipped(plant: str, rows: list[dict[str, Any]]) -> dict[str, Any]:
    """The task file's rapier setting: its errors, and the cheapest MuJoCo setting at least as
    close to its own reference (and its cost over that one's)."""
    physics = task_of(plant).to_dict()["physics"]
    dt, it, pgs = physics["dt"], physics["solver_iterations"], physics["pgs_iterations"]
    r = next(
        r
        for r in rows
        if r["engine"] == "rapier"
        and (r["solver_iterations"], r["pgs_iterations"]) == (it, pgs)
        and math.isclose(r["dt"], dt)
    )
    out = {"setting": label(r), "within_tolerance": within(r, "own", TOLERANCE)}
    out |= {k: r[k] for k in ("ms_per_simulated_s", "status", "own", "other")}
    if r["own"]["position_m"] is not None:
        peers = [
            m for m in rows if m["engine"] == "mujoco" and within(m, "own", r["own"]["position_m"])
        ]
        best = min(peers, key=lambda m: m["ms_per_simulated_s"]) if peers else None
        out["mujoco_as_accurate"] = (
            None
            if best is None
            else {
                "setting": label(best),
                "ms_per_simulated_s": best["ms_per_simulated_s"],
                "position_m": best["own"]["position_m"],
                "cost_ratio_rapier_over_mujoco": r["ms_per_simulated_s"]
                / best["ms_per_simulated_s"],
            }
        )
    return out


# ---------------------------------------------------------------------------------------------
# Figures


def front(points: list[tuple[float, float]]) -> list[tuple[float, float]]:
    """The Pareto front of (error, cost) points: none other is both more accurate and cheaper."""
    out: list[tuple[float, float]] = []
    for e, c in sorted(points):
        if not out or c < out[-1][1]:
            out.append((e, c))
    return out


def figure(name: str, data: dict[str, Any], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    style = {
        ("rapier", None): ("C0", "o", "rapier (latentrl)"),
        ("mujoco", "implicitfast"): ("C3", "s", "MuJoCo implicitfast"),
        ("mujoco", "discrete"): ("C3", "D", "MuJoCo discrete"),
    }
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharey=True)
    refs = data["references"]
    titles = {"own": "against its own reference", "other": "against the other engine's reference"}
    for ax, ref in zip(axes, ("own", "other")):
        for engine, colour in (("rapier", "C0"), ("mujoco", "C3")):
            rows = [
                r
                for r in data["rows"]
                if r["engine"] == engine and r[ref]["position_m"] is not None
            ]
            for (eng, integrator), (c, marker, text) in style.items():
                if eng != engine:
                    continue
                sel = [r for r in rows if integrator is None or r.get("integrator") == integrator]
                ok = [r for r in sel if r["status"] == "ok"]
                bad = [r for r in sel if r["status"] != "ok"]
                ax.scatter(
                    [r[ref]["position_m"] for r in ok],
                    [r["ms_per_simulated_s"] for r in ok],
                    color=c,
                    marker=marker,
                    s=28,
                    label=text,
                    zorder=3,
                )
                if bad:
                    ax.scatter(
                        [r[ref]["position_m"] for r in bad],
                        [r["ms_per_simulated_s"] for r in bad],
                        facecolors="none",
                        edgecolors=c,
                        marker=marker,
                        s=28,
                        zorder=3,
                        label=f"{text}, fell",
                    )
            pts = front(
                [
                    (r[ref]["position_m"], r["ms_per_simulated_s"])
                    for r in rows
                    if r["status"] == "ok"
                ]
            )
            if pts:
                e, c = zip(*pts)
                ax.plot(
                    [*e, max(e) * 3],
                    [*c, c[-1]],
                    drawstyle="steps-post",
                    color=colour,
                    lw=1.2,
                    alpha=0.8,
                )
                done: list[tuple[float, float]] = []
                for r in rows:
                    xy = (r[ref]["position_m"], r["ms_per_simulated_s"])
                    if (
                        r["status"] != "ok"
                        or xy not in pts
                        or any(
                            abs(math.log10(xy[0] / a)) < 0.12 and abs(math.log10(xy[1] / b)) < 0.12
                            for a, b in done
                        )
                    ):
                        continue
                    done.append(xy)
                    short = (
                        label(r)
                        .split(" ", 1)[1]
                        .replace("implicitfast", "if")
                        .replace("discrete", "disc")
                    )
                    ax.annotate(
                        short,
                        xy,
                        textcoords="offset points",
                        xytext=(4, 3),
                        fontsize=6.5,
                        color=colour,
                    )
        s = data["shipped"]
        if s and s[ref]["position_m"] is not None:
            ax.scatter(
                [s[ref]["position_m"]],
                [s["ms_per_simulated_s"]],
                s=140,
                facecolors="none",
                edgecolors="k",
                lw=1.0,
                zorder=4,
                label=f"rapier shipped ({s['setting'].split(' ', 1)[1]})",
            )
        ax.axvline(TOLERANCE, color="0.4", ls="--", lw=1, label="tolerance 1 mm")
        if ref == "other" and refs["rapier_vs_mujoco"]["position_m"] is not None:
            ax.axvline(
                refs["rapier_vs_mujoco"]["position_m"],
                color="0.4",
                ls=":",
                lw=1,
                label="rapier ref. vs MuJoCo ref.",
            )
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(
            "largest position error over the run (m)"
            + (", hands and base" if name == "humanoid" else ", hands")
        )
        ax.set_title(titles[ref], fontsize=10)
        ax.grid(True, which="both", alpha=0.25)
    gone = [label(r) for r in data["rows"] if r["own"]["position_m"] is None]
    if gone:
        axes[0].text(
            0.02,
            0.02,
            "not shown, diverged: " + ", ".join(gone),
            transform=axes[0].transAxes,
            fontsize=7,
        )
    axes[0].set_ylabel("CPU ms per simulated second")
    axes[1].legend(fontsize=7, loc="upper right")
    fig.suptitle(
        f"{name}: accuracy against cost (dt 1/120–1/3840 s; reference dt 1/{round(1 / refs['dt'])} s)",
        fontsize=11,
    )
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=130)
    plt.close(fig)


# ---------------------------------------------------------------------------------------------


def cpu_model() -> str | None:
    try:
        out = subprocess.run(["lscpu"], capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError):
        return None
    return next(
        (
            line.split(":", 1)[1].strip()
            for line in out.splitlines()
            if line.startswith("Model name")
        ),
        None,
    )


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out", type=Path, help="the JSON (default results/bench_accuracy[-quick].json)"
    )
    parser.add_argument(
        "--figures",
        type=Path,
        help="where accuracy-<plant>.png go (default docs/figures; with --quick, next to the JSON)",
    )
    parser.add_argument(
        "--quick", action="store_true", help="2 time steps, coarse references (smoke run)"
    )
    args = parser.parse_args(argv)
    results = Path(__file__).resolve().parent / "results"
    out = args.out or results / f"bench_accuracy{'-quick' if args.quick else ''}.json"
    figures = args.figures or (out.parent if args.quick else FIGURES)
    if mujoco is None:
        print("bench_accuracy needs MuJoCo: run benches/setup_bench_env.sh", file=sys.stderr)
        return 1

    # MuJoCo's warnings (a blown-up world) are counted per run from MjData.warning; kept here
    # instead of printed and appended to MUJOCO_LOG.TXT in the working directory
    mujoco_warnings: list[str] = []
    mujoco.set_mju_user_warning(mujoco_warnings.append)
    env = machine() | {"cpu_model": cpu_model()}
    v = env["versions"]
    print(
        f"latentrl {v['latentrl']} (rapier3d {v['rapier3d']}), MuJoCo {v['mujoco']}, NumPy {v['numpy']}; "
        f"{env['cpu_model']}, {env['cpu_count']} CPUs, load average {env['load_average'][0]:.2f}"
    )
    started = time.perf_counter()
    cases = {p.name: case(p, quick=args.quick) for p in (arms_plant(), humanoid_plant(), glass_arm_plant())}
    for name, data in cases.items():
        figure(name, data, figures / f"accuracy-{name}.png")
        for tol, c in data["cheapest_within"].items():
            shown = [
                f"{b['setting']} ({b['ms_per_simulated_s']:.3g} ms/s)" if b else f"{e} none"
                for e, b in ((e, c[f"{e}_own"]) for e in ("rapier", "mujoco"))
            ]
            print(f"{name}: cheapest within {tol} of its own reference: {'; '.join(shown)}")
        s = data["shipped"]
        peer = s.get("mujoco_as_accurate")
        print(
            f"{name}: shipped {s['setting']}: {'PASS' if s['within_tolerance'] else 'MISS'} 1 mm "
            f"({fmt(s['own'])}, {s['ms_per_simulated_s']:.3g} ms/s); MuJoCo as accurate: "
            + (f"{peer['setting']} ({peer['ms_per_simulated_s']:.3g} ms/s)" if peer else "none")
        )
    payload = {
        "bench": "bench_accuracy",
        "date": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "command": " ".join(
            ["benches/bench_accuracy.py", *(argv if argv is not None else sys.argv[1:])]
        ),
        "machine": env,
        "settings": {
            "rl_step_s": RL_DT,
            "dts": list(DTS),
            "rapier_iterations_pgs": [list(p) for p in RAPIER_ITERATIONS],
            "mujoco_integrators": mujoco_integrators(),
            "reference_dt": REFERENCE_DT,
            "rapier_reference": list(RAPIER_REFERENCE),
            "mujoco_reference": MUJOCO_REFERENCE,
            "tolerance_m": TOLERANCE,
            "tolerances_m": list(TOLERANCES),
            "friction": FRICTION,
            "clearance_m": CLEARANCE,
            "fell_below_base_height_fraction": FELL,
            "cost": "median CPU time of the calling thread in the step calls per simulated second",
        },
        "quick": args.quick,
        "wall_time_s": time.perf_counter() - started,
        "cases": cases,
        "mujoco_warnings": sorted(set(mujoco_warnings)),
    }
    write_json(out, payload)
    print(f"\nwrote {out} ({payload['wall_time_s']:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
