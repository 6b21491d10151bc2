"""Balanced poses between the two lift styles (docs/exp3.md, issue #18): at chosen hand heights,
postures part way from the straight-arm hip hinge to the knee squat, found with the native plant
only under the rules every shipped demo keeps (no task rule broken at rest, the 0.10 m grip,
the hands behind the block, the centre of mass 0.045 m inside the soles' support).

    python style_bridges.py OUT.csv [--heights 0.10,0.145,0.18] [--blends 0.33,0.67] [--floor 0.085,0.12]

OUT.csv: the shipped demos, then the floor-level squats (`--floor`, as floor_squat_poses.py),
then the bridges (blend t of the straight-arm and the squat pose at each height).
"""
import argparse

import numpy as np
from scipy.optimize import minimize

from latentrl import Task
from latentrl.demos import Demonstrations, load_demos, save_demos
from latentrl.experiments.exp3 import demos_path

task = Task.shipped("humanoid_lift")
demos = load_demos(demos_path(), expected_joints=task.joint_names).postures  # the paper's 7
plant = task.plant(demos)
J = {n: i for i, n in enumerate(task.joint_names)}
PARAMS = ("shoulder_pitch", "shoulder_roll", "elbow", "hip_pitch", "knee", "ankle_pitch")


def posture(p):
    """The symmetric posture of the 6 parameters (left side; the right mirrors the roll)."""
    q = np.zeros(len(J))
    for side, sign in (("l", 1), ("r", -1)):
        for name, value in zip(PARAMS, p):
            q[J[f"{side}_{name}"]] = -sign * value if name == "shoulder_roll" else value
    return np.clip(q, task.lower, task.upper)


def params(q):
    return np.array([-q[J["l_shoulder_roll"]] if n == "shoulder_roll" else q[J[f"l_{n}"]] for n in PARAMS])


def hands_of(q):
    code = plant.reset(q)
    return code, plant.effectors(), plant.support_margin()


def cost(p, height, near, weight):
    q = posture(p)
    code, h, margin = hands_of(q)
    grip = np.linalg.norm(h[3:] - h[:3])
    z = max(h[2], h[5])
    c = 50 * (z - height) ** 2 + 2000 * (grip - 0.10) ** 2 + 500 * (margin - 0.045) ** 2
    c += 1000 * max(0.0, h[0] - 0.14) ** 2 + weight * np.sum((p - near) ** 2)
    return c + (1.0 if code is not None else 0.0)


def solve(height, near, weight=1e-3):
    best = minimize(cost, near, args=(height, near, weight), method="Nelder-Mead",
                    options={"maxiter": 4000, "xatol": 1e-5, "fatol": 1e-10})
    q = posture(best.x)
    code, h, margin = hands_of(q)
    ends = {plant.step(q)[1] for _ in range(40)}  # held 2 s
    return q, code, h, margin, ends


def chain(points):
    """(hand height, params) of a style's poses, sorted by height: interpolated params at a height."""
    heights = np.array([z for z, _ in points])
    ps = np.array([p for _, p in points])
    order = np.argsort(heights)
    return lambda z: np.array([np.interp(z, heights[order], ps[order, k]) for k in range(len(PARAMS))])


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("out")
    parser.add_argument("--heights", default="0.10,0.145,0.18")
    parser.add_argument("--blends", default="0.33,0.67")
    parser.add_argument("--floor", default="0.085,0.12")
    args = parser.parse_args()
    height = {i: max(hands_of(d)[1][[2, 5]]) for i, d in enumerate(demos)}
    straight = chain([(height[i], params(demos[i])) for i in range(4)])
    squat_points = [(height[i], params(demos[i])) for i in range(4, 7)]
    found = []
    for z in [float(v) for v in args.floor.split(",") if v]:
        q, code, h, margin, ends = solve(z, chain(squat_points)(z) + [0, 0, 0, -0.2, 0.25, -0.1], weight=0)
        print(f"floor squat {z}: code {code} hands x,z {np.round(h[[0, 2]], 3)} margin {margin:.3f} ends {ends}")
        if code is None and ends == {None}:
            found.append(q)
            squat_points.append((max(h[2], h[5]), params(q)))
    squat = chain(squat_points)
    for z in [float(v) for v in args.heights.split(",") if v]:
        for t in [float(v) for v in args.blends.split(",") if v]:
            near = (1 - t) * straight(z) + t * squat(z)
            q, code, h, margin, ends = solve(z, near)
            print(f"bridge z {z} t {t}: code {code} hands x,z {np.round(h[[0, 2]], 3)} margin {margin:.3f} "
                  f"ends {ends} params {np.round(params(q), 3).tolist()}")
            if code is None and ends == {None}:
                found.append(q)
    save_demos(Demonstrations(np.vstack([demos, *found]), task.joint_names), args.out)
    print(f"wrote {args.out}: {len(demos)} shipped + {len(found)} poses")


if __name__ == "__main__":
    main()
