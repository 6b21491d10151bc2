"""latentrl's rapier3d physics (`latentrl._native.Sim`) against MuJoCo on the same URDFs, in one
process: physics steps/s of the two planar arms (Exp 2) and of the 19-DoF humanoid standing on a
floor (the fall check's plant), with checks that both simulations do the same thing.

Run it in the bench venv (MuJoCo is never a dependency of latentrl itself):

    bash benches/setup_bench_env.sh
    benches/.venv-bench/bin/python benches/bench_sim.py [--quick] [--out benches/results/bench_sim.json]

Without MuJoCo installed the MuJoCo rows are skipped (the rapier rows still run).

Models and settings (one thread each; rapier3d is built without its `parallel` feature and
MuJoCo's `mj_step` runs on the calling thread):

- arms: `two_arms.urdf`, fixed root, gravity −z (normal to the arm plane), dt 1/240 s,
  12 physics steps per RL step, PD servos kp 5000 N·m/rad, kd 50 N·m·s/rad, torque cap the URDF
  effort (1000 N·m); rapier at 2 solver iterations (Exp 2) and 4 (rapier's default). Held at a
  demonstrated posture (`latentrl.datasets.arm_postures`, seed 0). No contacts (the arms' links
  do not collide with each other in either simulation).
- humanoid: `khr1hv.urdf`, floating root on a floor plane, gravity, dt 1/240 s, servos kp 8,
  kd 0.1, torque cap ±1.2 N·m (`[servo]` of the shipped `humanoid_lift` task); rapier at 1 solver
  iteration of 4 PGS passes (its `[physics]`) and at rapier's default, 4 iterations of 1. Stands at its home posture (every joint 0,
  the posture the Rust stand test holds for 10 s), soles 0.5 mm above the floor at the start.
  Only robot–floor contacts (no self-collisions in either simulation); friction 0.5 (rapier's
  default) on every shape in both.
- MuJoCo: `MjSpec.from_file(urdf)`, then a free joint on the humanoid's root body, a floor plane,
  and one `position` actuator per URDF joint (kp, kv = kd, forcerange = the torque cap, ctrlrange
  = the joint limits, as rapier clamps its targets), joint damping and armature 0 as in the
  URDF (rapier: `joint_damping` 0), MuJoCo's default Newton solver. Two integrators, each a row:
  `implicitfast` (MuJoCo's recommended one: kv implicit, kp explicit; with explicit Euler the
  arms' kd 50 diverges at dt 1/240) and `discrete` (MuJoCo ≥ 3.13: damping and stiffness both
  implicit, like rapier's motor constraint). With implicitfast the humanoid's light leg links
  chatter under kp 8 at dt 1/240 (`joint_speed_rms_rad_s` ≈ 0.2–0.5 rad/s while standing);
  with discrete it comes to rest.

Timing: warm-up, then the median (and best) of 5 timed loops of many physics steps in one call
(`Sim.step(n)` / `mujoco.mj_step(m, d, nstep=n)`); the simulations take turns loop by loop, so
a load change on the shared machine hits them alike. The figures (`us_per_*`, ratios) are CPU
time of the calling thread, which leaves out time spent waiting for a core on a busy machine;
wall times are reported beside them (`wall_*`). The arms' RL step (set targets, 12 physics
steps, read the posture) is timed from Python in both. The humanoid stands through every loop,
and its base height is read after each one (`checks`).
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
import tomllib
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

import latentrl
from latentrl._native import Sim
from latentrl.datasets import arm_postures
from latentrl.task import Task
from latentrl.results import write_json

try:
    import mujoco
except ImportError:  # the rapier rows still run
    mujoco = None

ROOT = Path(__file__).resolve().parent.parent
DT = 1.0 / 240.0
SUBSTEPS = 12
ARMS = {"kp": 5000.0, "kd": 50.0, "max_force": 1000.0}  # cap = two_arms.urdf effort
ARMS_ITERATIONS = (2, 4)  # Exp 2 uses 2; rapier's default is 4
# (solver iterations, PGS passes): the humanoid_lift task's [physics], and rapier's default
HUMANOID_PHYSICS = ((1, 4), (4, 1))
FRICTION = 0.5  # rapier's default collider friction, used in MuJoCo too
CLEARANCE = 5e-4  # soles above the floor at the start (Sim.reset_on_ground)
STEP = 0.1  # rad, the tracking check's target step on every arm joint
STANDING = 0.9  # the humanoid stands while its base height keeps this fraction of the start
REPEATS = 5  # timed loops per row (median and best reported), after one warm-up loop
# MuJoCo integrators compared: implicitfast (MuJoCo's recommended one; kv implicit, kp explicit)
# and discrete (MuJoCo >= 3.13; damping and stiffness implicit, as rapier's motor constraint).
MUJOCO_INTEGRATORS = ("implicitfast", "discrete")


# ---------------------------------------------------------------------------------------------
# The two simulations behind one small interface


class RapierRobot:
    """latentrl's rapier3d world (`_native.Sim`) with a floor at z = `floor` (or none)."""

    def __init__(
        self,
        urdf: Path,
        *,
        floating: bool,
        gains: dict[str, float],
        iterations: int,
        pgs_iterations: int = 1,
        floor: float | None = None,
        sole: str | None = None,
        dt: float = DT,
        substeps: int = SUBSTEPS,
    ) -> None:
        physics = {"dt": dt, "substeps": substeps, "solver_iterations": iterations, "pgs_iterations": pgs_iterations}
        self.sim = Sim(urdf, root="floating" if floating else "fixed", floor=floor, physics=physics, servo=gains)
        self.floor = 0.0 if floor is None else floor
        self.floating = floating
        self.sole = sole
        self.joint_names = self.sim.joint_names

    def reset(self, posture: np.ndarray) -> None:
        if self.sole is None:
            self.sim.reset(posture)
        else:
            self.sim.reset_on_ground(posture, self.sole, CLEARANCE)

    def set_targets(self, targets: np.ndarray) -> None:
        self.sim.set_targets(targets)

    def step(self, n: int) -> None:
        self.sim.step(n)

    def joint_positions(self) -> np.ndarray:
        return self.sim.joint_positions()

    def joint_velocities(self) -> np.ndarray:
        return self.sim.joint_velocities()

    def base_height(self) -> float:
        return float(self.sim.base_position()[2] - self.floor)

    def base_xy(self) -> np.ndarray:
        return self.sim.base_position()[:2].copy()


class MujocoRobot:
    """The same URDF in MuJoCo: position actuators per joint, optional free root and floor."""

    def __init__(
        self,
        urdf: Path,
        joint_names: list[str],
        *,
        gains: dict[str, float],
        integrator: str = "implicitfast",
        floating_body: str | None = None,
        floor: bool = False,
        start_height: float = 0.0,
        dt: float = DT,
    ) -> None:
        spec = mujoco.MjSpec.from_file(str(urdf))
        spec.option.timestep = dt
        spec.option.gravity = [0.0, 0.0, -9.81]
        spec.option.integrator = getattr(mujoco.mjtIntegrator, f"mjINT_{integrator.upper()}")
        for geom in spec.geoms:  # robot shapes touch the floor only (no self-collisions)
            geom.contype, geom.conaffinity = 1, 0
            geom.friction = [FRICTION, geom.friction[1], geom.friction[2]]
        for joint in spec.joints:
            joint.damping, joint.armature = [0.0, 0.0, 0.0], 0.0
        if floating_body is not None:
            spec.body(floating_body).add_freejoint()
        if floor:
            plane = spec.worldbody.add_geom()
            plane.type = mujoco.mjtGeom.mjGEOM_PLANE
            plane.size = [0.0, 0.0, 1.0]  # infinite
            plane.contype, plane.conaffinity = 0, 1
            plane.friction = [FRICTION, plane.friction[1], plane.friction[2]]
        for name in joint_names:  # actuator i drives joint i of latentrl's order
            joint = spec.joint(name)
            act = spec.add_actuator()
            act.name = name
            act.target = name
            act.trntype = mujoco.mjtTrn.mjTRN_JOINT
            act.set_to_position(kp=gains["kp"], kv=gains["kd"])
            act.forcelimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.forcerange = [-gains["max_force"], gains["max_force"]]
            act.ctrllimited = mujoco.mjtLimited.mjLIMITED_TRUE
            act.ctrlrange = list(joint.range)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        self.joint_names = joint_names
        self.qadr = np.array([self.model.joint(n).qposadr[0] for n in joint_names])
        self.vadr = np.array([self.model.joint(n).dofadr[0] for n in joint_names])
        self.floating = floating_body is not None
        self.start_height = start_height
        self.floor = 0.0
        self.body = self.model.body(floating_body).id if self.floating else None
        self.lower = self.model.actuator_ctrlrange[:, 0].copy()
        self.upper = self.model.actuator_ctrlrange[:, 1].copy()

    def reset(self, posture: np.ndarray) -> None:
        mujoco.mj_resetData(self.model, self.data)
        if self.floating:
            self.data.qpos[:7] = [0.0, 0.0, self.start_height, 1.0, 0.0, 0.0, 0.0]
        self.data.qpos[self.qadr] = posture
        self.data.ctrl[:] = posture
        mujoco.mj_forward(self.model, self.data)

    def set_targets(self, targets: np.ndarray) -> None:
        self.data.ctrl[:] = np.clip(targets, self.lower, self.upper)

    def step(self, n: int) -> None:
        mujoco.mj_step(self.model, self.data, nstep=n)

    def joint_positions(self) -> np.ndarray:
        return self.data.qpos[self.qadr].copy()

    def joint_velocities(self) -> np.ndarray:
        return self.data.qvel[self.vadr].copy()

    def base_height(self) -> float:
        return float(self.data.xpos[self.body][2] - self.floor)

    def base_xy(self) -> np.ndarray:
        return self.data.xpos[self.body][:2].copy()

    def solver_state(self) -> dict[str, Any]:
        """Contacts and solver iterations of the last step (MuJoCo stops at its tolerance)."""
        opt = self.model.opt
        return {
            "contacts": int(self.data.ncon),
            "solver_iterations_used": int(self.data.solver_niter[0]),
            "solver": mujoco.mjtSolver(opt.solver).name,
            "max_iterations": int(opt.iterations),
            "tolerance": float(opt.tolerance),
            "cone": mujoco.mjtCone(opt.cone).name,
        }


# ---------------------------------------------------------------------------------------------
# Timing and checks


def interleaved(
    runs: dict[str, Callable[[], None]],
    *,
    repeats: int = REPEATS,
    after: dict[str, Callable[[], None]] | None = None,
) -> dict[str, dict[str, float]]:
    """Median and best time per simulation of `repeats` timed calls of its `runs` entry, after
    one warm-up call each: CPU time of this thread (`median_s`, `best_s`; both simulations step
    on the calling thread) and wall time (`wall_median_s`). The simulations take turns loop by
    loop, so a load change on the shared machine hits them alike; CPU time leaves out the time
    spent waiting for a core. `after[name]` runs (untimed) after each call."""
    after = after or {}
    cpu: dict[str, list[float]] = {name: [] for name in runs}
    wall: dict[str, list[float]] = {name: [] for name in runs}
    for k in range(repeats + 1):
        for name, run in runs.items():
            c0, t0 = time.thread_time(), time.perf_counter()
            run()
            t1, c1 = time.perf_counter(), time.thread_time()
            if k > 0:
                cpu[name].append(c1 - c0)
                wall[name].append(t1 - t0)
            if name in after:
                after[name]()
    return {
        name: {
            "median_s": statistics.median(cpu[name]),
            "best_s": min(cpu[name]),
            "wall_median_s": statistics.median(wall[name]),
            "wall_best_s": min(wall[name]),
            "repeats": repeats,
        }
        for name in runs
    }


def physics_rows(
    robots: dict[str, Any], posture: np.ndarray, steps: int
) -> dict[str, dict[str, Any]]:
    """µs per physics step holding `posture`, `steps` per loop; a floating robot's base height
    is read after every loop (warm-up included): it has to stand throughout."""
    heights: dict[str, list[float]] = {}
    xy0 = {}
    for name, robot in robots.items():
        robot.reset(posture)
        if robot.floating:
            heights[name] = [robot.base_height()]
            xy0[name] = robot.base_xy()
    runs = {name: (lambda r=robot: r.step(steps)) for name, robot in robots.items()}
    after = {
        name: (lambda r=robots[name], h=h: h.append(r.base_height())) for name, h in heights.items()
    }
    times = interleaved(runs, after=after)
    rows = {}
    for name, robot in robots.items():
        t = times[name]
        row: dict[str, Any] = {
            "steps_per_loop": steps,
            "us_per_step": 1e6 * t["median_s"] / steps,
            "best_us_per_step": 1e6 * t["best_s"] / steps,
            "wall_us_per_step": 1e6 * t["wall_median_s"] / steps,
            "steps_per_s": steps / t["median_s"],
            "simulated_s": (t["repeats"] + 1) * steps * DT,
            "hold_error_max_rad": float(np.abs(robot.joint_positions() - posture).max()),
        }
        if hasattr(robot, "solver_state"):
            row["mujoco_last_step"] = robot.solver_state()
        if name in heights:
            h = heights[name]
            row["base_height_start_m"] = h[0]
            row["base_height_min_m"] = min(h)
            row["base_height_end_m"] = h[-1]
            row["base_xy_drift_m"] = float(np.linalg.norm(robot.base_xy() - xy0[name]))
            row["stood"] = bool(min(h) >= STANDING * h[0])
        row["joint_speed_rms_rad_s"] = joint_speed_rms(robot)  # after the loops, untimed
        rows[name] = row
    return rows


def joint_speed_rms(robot: Any, steps: int = 240) -> float:
    """RMS joint speed (rad/s) over the next `steps` physics steps (untimed): ~0 for a robot at
    rest, larger when the servos chatter."""
    v = np.empty((steps, len(robot.joint_names)))
    for k in range(steps):
        robot.step(1)
        v[k] = robot.joint_velocities()
    return float(np.sqrt(np.mean(v**2)))


def rl_rows(robots: dict[str, Any], posture: np.ndarray, steps: int) -> dict[str, dict[str, Any]]:
    """µs per RL step from Python: alternate targets ±0.05 rad, 12 physics steps, read posture."""
    wiggle = [posture + 0.05 * np.array([1, -1, 1, 1]), posture - 0.05 * np.array([1, -1, 1, 1])]

    def run(robot: Any) -> None:
        for k in range(steps):
            robot.set_targets(wiggle[k & 1])
            robot.step(SUBSTEPS)
            robot.joint_positions()

    for robot in robots.values():
        robot.reset(posture)
    times = interleaved({name: (lambda r=robot: run(r)) for name, robot in robots.items()})
    return {
        name: {
            "rl_steps_per_loop": steps,
            "us_per_rl_step": 1e6 * t["median_s"] / steps,
            "best_us_per_rl_step": 1e6 * t["best_s"] / steps,
            "wall_us_per_rl_step": 1e6 * t["wall_median_s"] / steps,
            "rl_steps_per_s": steps / t["median_s"],
        }
        for name, t in times.items()
    }


def step_response(robot: Any, posture: np.ndarray, steps: int) -> np.ndarray:
    """Joint positions (steps, D) after each physics step of a +STEP rad step on every joint."""
    robot.reset(posture)
    robot.set_targets(posture + STEP)
    out = np.empty((steps, len(posture)))
    for k in range(steps):
        robot.step(1)
        out[k] = robot.joint_positions()
    return out


# ---------------------------------------------------------------------------------------------
# Cases


def arms_case(*, quick: bool) -> dict[str, Any]:
    urdf = Task.shipped("two_arms").urdf_path
    posture = arm_postures(1, np.random.default_rng(0))[0]
    steps, rl_steps = (1200, 100) if quick else (12000, 1000)
    robots: dict[str, Any] = {
        f"rapier_it{it}": RapierRobot(urdf, floating=False, gains=ARMS, iterations=it)
        for it in ARMS_ITERATIONS
    }
    names = next(iter(robots.values())).joint_names
    for integrator in mujoco_integrators():
        robots[f"mujoco_{integrator}"] = MujocoRobot(urdf, names, gains=ARMS, integrator=integrator)
    physics, rl = physics_rows(robots, posture, steps), rl_rows(robots, posture, rl_steps)
    rows = {label: physics[label] | rl[label] for label in robots}
    responses = {
        label: step_response(robot, posture, 5 * SUBSTEPS) for label, robot in robots.items()
    }
    for label, r in rows.items():
        print(
            f"  arms {label:19s} {r['us_per_step']:8.2f} µs/step (wall {r['wall_us_per_step']:.2f}, "
            f"{r['steps_per_s']:.3g} steps/s), {r['us_per_rl_step']:8.1f} µs/RL step "
            f"(wall {r['wall_us_per_rl_step']:.1f})"
        )
    target = posture + STEP
    checks: dict[str, Any] = {"posture": posture.tolist(), "step_rad": STEP}
    for label, q in responses.items():
        err = np.abs(q - target).max(axis=1)
        checks[label] = {
            "error_after_0.05s_mrad": 1e3 * float(err[SUBSTEPS - 1]),
            "error_after_0.25s_mrad": 1e3 * float(err[-1]),
            "overshoot_mrad": 1e3 * float(max(0.0, (q - target).max())),
            "tracked_0.05s": bool(err[SUBSTEPS - 1] < 5e-3),
        }
    for label in rows:
        for peer in rows:
            if label.startswith("rapier") and peer.startswith("mujoco"):
                diff = np.abs(responses[label] - responses[peer])
                checks[f"{label}_vs_{peer}_max_diff_mrad"] = 1e3 * float(diff.max())
    return {"joints": names, "rows": rows, "checks": checks, "ratios": ratios(rows)}


def humanoid_case(*, quick: bool) -> dict[str, Any]:
    task = Task.shipped("humanoid_lift")
    urdf, servo = task.urdf_path, task.to_dict()["servo"]
    children = {child for _, child in task.edges}
    root = next(parent for parent, _ in task.edges if parent not in children)
    posture = np.zeros(len(task.joint_names))  # home: every joint 0, within all limits
    probe = RapierRobot(urdf, floating=True, gains=servo, iterations=1, floor=0.0, sole="l_foot")
    probe.reset(posture)
    start_height = probe.base_height()  # base above the floor, soles CLEARANCE above it
    steps = 240 if quick else 2400
    robots: dict[str, Any] = {
        f"rapier_it{it}_pgs{pgs}": RapierRobot(
            urdf,
            floating=True,
            gains=servo,
            iterations=it,
            pgs_iterations=pgs,
            floor=0.0,
            sole="l_foot",
        )
        for it, pgs in HUMANOID_PHYSICS
    }
    names = next(iter(robots.values())).joint_names
    for integrator in mujoco_integrators():
        robots[f"mujoco_{integrator}"] = MujocoRobot(
            urdf,
            names,
            gains=servo,
            integrator=integrator,
            floating_body=root,
            floor=True,
            start_height=start_height,
        )
    rows = physics_rows(robots, posture, steps)
    for label, r in rows.items():
        print(
            f"  humanoid {label:19s} {r['us_per_step']:8.1f} µs/step (wall "
            f"{r['wall_us_per_step']:.1f}, {r['steps_per_s']:.3g} steps/s); base "
            f"{1e3 * r['base_height_start_m']:.1f} → min {1e3 * r['base_height_min_m']:.1f} mm "
            f"over {r['simulated_s']:.0f} s, stood: {r['stood']}; joint speed rms "
            f"{r['joint_speed_rms_rad_s']:.3f} rad/s"
        )
    checks = {
        label: {
            k: r[k]
            for k in (
                "simulated_s",
                "base_height_start_m",
                "base_height_min_m",
                "base_height_end_m",
                "base_xy_drift_m",
                "hold_error_max_rad",
                "joint_speed_rms_rad_s",
                "stood",
            )
        }
        for label, r in rows.items()
    }
    return {"joints": names, "rows": rows, "checks": checks, "ratios": ratios(rows)}


def ratios(rows: dict[str, Any]) -> dict[str, float]:
    """rapier time per step over MuJoCo's (> 1: MuJoCo faster), per rapier setting and MuJoCo
    integrator, from the median CPU times (`*_wall`: from the median wall times)."""
    out = {}
    for label, row in rows.items():
        for peer_label, peer in rows.items():
            if not (label.startswith("rapier") and peer_label.startswith("mujoco")):
                continue
            for kind in ("step", "rl_step"):
                if f"us_per_{kind}" in row:
                    key = f"{label}_over_{peer_label}_{kind}"
                    out[key] = row[f"us_per_{kind}"] / peer[f"us_per_{kind}"]
                    out[f"{key}_wall"] = row[f"wall_us_per_{kind}"] / peer[f"wall_us_per_{kind}"]
    return out


def mujoco_integrators() -> list[str]:
    """The MUJOCO_INTEGRATORS this MuJoCo has (none without MuJoCo)."""
    if mujoco is None:
        return []
    return [i for i in MUJOCO_INTEGRATORS if hasattr(mujoco.mjtIntegrator, f"mjINT_{i.upper()}")]


# ---------------------------------------------------------------------------------------------
# Output


def rapier_version() -> str | None:
    try:
        deps = tomllib.loads((ROOT / "Cargo.toml").read_text())["workspace"]["dependencies"]
        return str(deps["rapier3d"]).lstrip("=")
    except (OSError, KeyError, tomllib.TOMLDecodeError):
        return None


def machine() -> dict[str, Any]:
    return {
        "python": platform.python_version(),
        "platform": platform.platform(),
        "cpu_count": os.cpu_count(),
        "threads": "1 (rapier3d without `parallel`; MuJoCo's mj_step on the calling thread)",
        "load_average": os.getloadavg(),
        "versions": {
            "latentrl": latentrl.__version__,
            "rapier3d": rapier_version(),
            "numpy": np.__version__,
            "mujoco": getattr(mujoco, "__version__", None),
        },
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--out", type=Path, default=Path(__file__).resolve().parent / "results" / "bench_sim.json"
    )
    parser.add_argument("--quick", action="store_true", help="10× fewer steps (smoke run)")
    args = parser.parse_args(argv)

    env = machine()
    v = env["versions"]
    print(
        f"latentrl {v['latentrl']} (rapier3d {v['rapier3d']}), MuJoCo {v['mujoco']}, "
        f"NumPy {v['numpy']}; {env['cpu_count']} CPUs, threads: {env['threads']}; "
        f"load average {env['load_average'][0]:.2f}"
    )
    if mujoco is None:
        print(
            "MuJoCo not importable: MuJoCo rows skipped (run benches/setup_bench_env.sh)",
            file=sys.stderr,
        )

    started = time.perf_counter()
    cases = {"arms": arms_case(quick=args.quick), "humanoid": humanoid_case(quick=args.quick)}
    for name, case in cases.items():
        if case["ratios"]:
            shown = ", ".join(
                f"{k} {x:.3g}" for k, x in case["ratios"].items() if not k.endswith("_wall")
            )
            print(f"  {name} ratios (CPU time): {shown}")

    agreement = {
        "arms_track_step_0.05s": all(
            c["tracked_0.05s"] for k, c in cases["arms"]["checks"].items() if isinstance(c, dict)
        ),
        "humanoid_stands": all(c["stood"] for c in cases["humanoid"]["checks"].values()),
    }
    targets = {}
    r = cases["humanoid"]["ratios"]
    for integrator in mujoco_integrators():
        for it, pgs in HUMANOID_PHYSICS:
            label = (
                f"humanoid within 3x of MuJoCo's step rate (rapier {it} solver iterations × {pgs} "
                f"PGS passes, MuJoCo {integrator})"
            )
            targets[label] = bool(r[f"rapier_it{it}_pgs{pgs}_over_mujoco_{integrator}_step"] <= 3.0)
    for label, ok in {**agreement, **targets}.items():
        print(f"{'PASS' if ok else 'MISS'}  {label}")

    payload = {
        "bench": "bench_sim",
        "machine": env,
        "settings": {
            "dt": DT,
            "substeps_per_rl_step": SUBSTEPS,
            "arms_gains": ARMS,
            "arms_rapier_solver_iterations": list(ARMS_ITERATIONS),
            "humanoid_gains": Task.shipped("humanoid_lift").to_dict()["servo"],
            "humanoid_rapier_solver_iterations_pgs_passes": [list(p) for p in HUMANOID_PHYSICS],
            "friction": FRICTION,
            "mujoco": "MjSpec.from_file(urdf); position actuators kp, kv=kd, forcerange=cap, "
            "ctrlrange=joint limits; integrators implicitfast and discrete; default Newton solver; robot "
            "geoms contype 1 / conaffinity 0 (no self-collisions); humanoid free joint + plane",
        },
        "quick": args.quick,
        "wall_time_s": time.perf_counter() - started,
        "cases": cases,
        "agreement": agreement,
        "targets": targets,
    }
    write_json(args.out, payload)
    print(f"\nwrote {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
