"""Real robot descriptions (issue #17): forward kinematics against Pinocchio, load time with and
without the hull cache, and the physics step of a mesh robot against the same robot built from
primitive shapes. Writes benches/results/bench_urdf.json.

Run it in the bench venv (Pinocchio is never a dependency of latentrl itself):

    bash benches/setup_bench_env.sh
    benches/.venv-bench/bin/python benches/bench_urdf.py [--stock DIR] [--quick]

Robots: the test arm `tests/robots/arm7_description` (meshes in STL, OBJ and COLLADA, a mimic
finger, a continuous joint) and its primitive twin, the shipped two arms and humanoid, and with
`--stock DIR` stock descriptions from a checkout of example-robot-data placed at
`DIR/example-robot-data` (so `package://example-robot-data/...` resolves): Panda with its
mimic gripper, UR5 with a gripper, Kinova j2s6s200 with COLLADA meshes. They are not committed.

- FK: 200 random postures within the limits (continuous joints in ±π), every link's world
  position from `Sim.reset` + `Sim.frame_position` against Pinocchio's `oMf` of the body frame;
  mimic joints set to `multiplier · q_leader + offset` in Pinocchio's q.
- Load: `Sim(urdf)` with an empty cache folder (first load: parse, hull, store) and again (from
  the cache), median of 5 each, wall time.
- Hold (arms): drift of the link farthest from the base over 2 s under gravity at the middle of the joint
  ranges, servos kp 20000, kd 200, capped at the URDF efforts.
- Step: 2400 physics steps (10 s) driving the arm between two postures, one thread, µs per
  physics step, median of 5; self-collisions off (the default) and on.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from latentrl._native import Sim, urdf_info

ROOT = Path(__file__).resolve().parent.parent
ARM7 = ROOT / "tests" / "robots" / "arm7_description" / "urdf"
DATA = ROOT / "python" / "latentrl" / "data"
STOCK = {
    "panda": "example-robot-data/robots/panda_description/urdf/panda.urdf",
    "ur5_gripper": "example-robot-data/robots/ur_description/urdf/ur5_gripper.urdf",
    "kinova": "example-robot-data/robots/kinova_description/robots/kinova.urdf",
}


def robots(stock: Path | None) -> dict[str, Path]:
    """The URDFs to measure, by name."""
    out = {"arm7": ARM7 / "arm7.urdf", "arm7_primitives": ARM7 / "arm7_primitives.urdf",
           "two_arms": DATA / "two_arms.urdf", "khr1hv": DATA / "khr1hv.urdf"}
    if stock is not None:
        out.update({name: stock / rel for name, rel in STOCK.items()})
    return out


def box(info: dict) -> tuple[np.ndarray, np.ndarray]:
    """Sampling bounds of the actuated joints (continuous ones in ±π)."""
    actuated = [j for j in info["joints"] if j["mimic"] is None]
    lo = np.array([-math.pi if math.isinf(j["lower"]) else j["lower"] for j in actuated])
    hi = np.array([math.pi if math.isinf(j["upper"]) else j["upper"] for j in actuated])
    return lo, hi


def fk_error(urdf: Path, n: int) -> dict:
    """Largest link position error (m) of our FK against Pinocchio's over `n` postures."""
    import pinocchio as pin

    info = urdf_info(urdf)
    model = pin.buildModelFromUrdf(str(urdf))
    data = model.createData()
    sim = Sim(urdf)
    lo, hi = box(info)
    rng = np.random.default_rng(0)
    links = [link for link in info["links"] if model.existFrame(link)]
    worst = 0.0
    for _ in range(n):
        posture = rng.uniform(lo, hi)
        sim.reset(posture)
        value = dict(zip(sim.joint_names, posture))
        for j in info["joints"]:
            if j["mimic"] is not None:
                m = j["mimic"]
                value[j["name"]] = min(max(m["multiplier"] * value[m["leader"]] + m["offset"], j["lower"]), j["upper"])
        q = pin.neutral(model)
        for jid in range(1, model.njoints):
            name, joint = model.names[jid], model.joints[jid]
            if joint.nq == 2:  # continuous joint: (cos, sin)
                q[joint.idx_q:joint.idx_q + 2] = [math.cos(value[name]), math.sin(value[name])]
            else:
                q[joint.idx_q] = value[name]
        pin.framesForwardKinematics(model, data, q)
        for link in links:
            ours = sim.frame_position(link)
            theirs = data.oMf[model.getFrameId(link)].translation
            worst = max(worst, float(np.linalg.norm(ours - theirs)))
    return {"postures": n, "links": len(links), "max_position_error_mm": worst * 1e3}


def load_times(urdf: Path, repeats: int) -> dict:
    """Wall time (ms) of `Sim(urdf)` with an empty hull cache, then from the cache."""
    first, cached = [], []
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as cache:
            os.environ["LATENTRL_CACHE_DIR"] = cache
            t = time.perf_counter()
            Sim(urdf)
            first.append(time.perf_counter() - t)
            t = time.perf_counter()
            Sim(urdf)
            cached.append(time.perf_counter() - t)
    os.environ.pop("LATENTRL_CACHE_DIR")
    return {"first_ms": statistics.median(first) * 1e3, "cached_ms": statistics.median(cached) * 1e3}


def hold_drift(urdf: Path) -> float:
    """How far (m) the link farthest from the base moves in 2 s of gravity while the servos (kp 20000, kd 200,
    capped at the URDF efforts) hold the middle of the joint ranges."""
    info = urdf_info(urdf)
    lo, hi = box(info)
    sim = Sim(urdf, servo={"kp": 20000.0, "kd": 200.0})
    sim.reset(lo + 0.5 * (hi - lo))
    far = max(info["links"], key=lambda link: float(np.linalg.norm(sim.frame_position(link))))
    start = sim.frame_position(far)
    sim.step(480)
    return float(np.linalg.norm(sim.frame_position(far) - start))


def step_cost(urdf: Path, self_collisions: bool, steps: int, repeats: int) -> float:
    """µs per physics step while the servos drive the robot between two postures."""
    info = urdf_info(urdf)
    lo, hi = box(info)
    sim = Sim(urdf, physics={"self_collisions": self_collisions})
    a, b = lo + 0.4 * (hi - lo), lo + 0.6 * (hi - lo)
    times = []
    for _ in range(repeats):
        sim.reset(a)
        t = time.process_time()
        for k in range(steps // 240):
            sim.set_targets(b if k % 2 == 0 else a)
            sim.step(240)
        times.append(time.process_time() - t)
    return statistics.median(times) / steps * 1e6


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stock", type=Path, help="folder holding example-robot-data/ (stock URDFs)")
    parser.add_argument("--quick", action="store_true", help="20 postures, 1 repeat")
    parser.add_argument("--out", type=Path, default=ROOT / "benches" / "results" / "bench_urdf.json")
    args = parser.parse_args()
    n, repeats = (20, 1) if args.quick else (200, 5)
    rows = {}
    for name, urdf in robots(args.stock).items():
        row = {"urdf": str(urdf.relative_to(args.stock) if args.stock and args.stock in urdf.parents else
                           urdf.relative_to(ROOT)), **fk_error(urdf, n), **load_times(urdf, repeats)}
        if name not in ("two_arms", "khr1hv"):
            row["hold_drift_mm"] = hold_drift(urdf) * 1e3
            row["us_per_step"] = step_cost(urdf, False, 2400, repeats)
            row["us_per_step_self_collisions"] = step_cost(urdf, True, 2400, repeats)
        rows[name] = row
        print(name, json.dumps(row))
    mesh, prim = rows["arm7"], rows["arm7_primitives"]
    summary = {"arm7_mesh_over_primitives_step": mesh["us_per_step"] / prim["us_per_step"],
               "arm7_mesh_over_primitives_step_self_collisions":
                   mesh["us_per_step_self_collisions"] / prim["us_per_step_self_collisions"]}
    import pinocchio

    result = {"robots": rows, "summary": summary, "pinocchio": pinocchio.__version__, "threads": 1}
    args.out.write_text(json.dumps(result, indent=2) + "\n")
    print(json.dumps(summary))


if __name__ == "__main__":
    main()
