"""Balanced knee-squat poses with the hands at chosen heights (floor level), found with the
native plant only: at rest a pose must break no task rule, hold the 0.10 m grip, keep the
hands behind the block and its centre of mass 0.045 m inside the soles' support, as every
shipped demo. docs/exp3.md, "Why the lift from the floor fails".

    python floor_squat_poses.py 0.085 0.12 [--out demos9.csv]   # the shipped demos + these poses
"""
import sys
import numpy as np
from scipy.optimize import minimize
from latentrl import Task
from latentrl.demos import load_demos
from latentrl.experiments.exp3 import demos_path

task = Task.shipped("humanoid_lift")
demos = load_demos(demos_path(), expected_joints=task.joint_names).postures  # the paper's 7
plant = task.plant(demos)
J = {n: i for i, n in enumerate(task.joint_names)}


def posture(p):
    sp, sr, el, hip, knee, ank = p
    q = np.zeros(len(J))
    for side, sgn in (("l", 1), ("r", -1)):
        q[J[f"{side}_shoulder_pitch"]] = sp
        q[J[f"{side}_shoulder_roll"]] = -sgn * sr
        q[J[f"{side}_elbow"]] = el
        q[J[f"{side}_hip_pitch"]] = hip
        q[J[f"{side}_knee"]] = knee
        q[J[f"{side}_ankle_pitch"]] = ank
    return np.clip(q, task.lower, task.upper)


LOW = {"knee": 2.3, "ankle": -1.1}


def evaluate(p, height):
    q = posture(p)
    over = max(0.0, p[4] - LOW["knee"]) + max(0.0, LOW["ankle"] - p[5]) + max(0.0, -1.9 - p[3])
    code = plant.reset(q)
    h = plant.effectors()
    grip = np.linalg.norm(h[3:] - h[:3])
    margin = plant.support_margin()
    z = max(h[2], h[5])
    cost = 50 * (z - height) ** 2 + 2000 * (grip - 0.10) ** 2 + 500 * (margin - 0.045) ** 2
    cost += 10 * max(0.0, h[0] - 0.13) ** 2 * 100  # hands behind the block (x < 0.165)
    cost += 100 * over ** 2
    if code is not None:
        cost += 1.0
    return cost, code, h, grip, margin


def find(height, start):
    best = minimize(lambda p: evaluate(p, height)[0], start, method="Nelder-Mead",
                    options={"maxiter": 3000, "xatol": 1e-5, "fatol": 1e-9})
    return best.x, evaluate(best.x, height)


d4 = demos[4]
start = np.array([d4[J["l_shoulder_pitch"]], -d4[J["l_shoulder_roll"]], d4[J["l_elbow"]], -1.6, 2.35, -1.0])
for i in range(7):
    plant.reset(demos[i])
    print("demo", i, "hands z", np.round(plant.effectors()[[2, 5]], 3), "margin", round(plant.support_margin(), 4))
args = sys.argv[1:]
out = args[args.index("--out") + 1] if "--out" in args else None
heights = [float(a) for a in args if a != "--out" and a != out] or [0.085, 0.12]
found = []
for height in heights:
    p, (cost, code, h, grip, margin) = find(height, start)
    print(f"height {height}: cost {cost:.2e} code {code} hands {np.round(h, 3)} grip {grip:.4f} margin {margin:.4f}")
    print("  params", np.round(p, 4).tolist())
    print("  posture", np.round(posture(p), 6).tolist())
    q = posture(p)
    plant.reset(q)
    ends = [plant.step(q)[1] for _ in range(40)]
    h2 = plant.effectors()
    print("  held 2 s: ends", set(ends), "hands moved", np.round(np.abs(h2 - h).max(), 4), "margin", round(plant.support_margin(), 4))
    found.append(posture(p))
    start = p
if out:
    from latentrl.demos import Demonstrations, save_demos
    save_demos(Demonstrations(np.vstack([demos, *found]), task.joint_names), out)
    print("wrote", out)
