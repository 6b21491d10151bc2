"""Shared helpers of the robot zoo: writing primitive-shape URDFs, and inverse kinematics through the
project's own plant (`latentrl.Task.plant`), so that every demo posture is checked by the same
kinematics and rules the learner uses.

Nothing here is tuned per robot: a robot's folder holds its URDF, its `make_demos.py` (which
imports this module) and its task file.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares

# ------------------------------------------------------------------------------------------------
# URDF writing
# ------------------------------------------------------------------------------------------------


def _f(x: float) -> str:
    return f"{x:.6g}"


def _v(v: Sequence[float]) -> str:
    return " ".join(_f(float(x)) for x in v)


def rpy_of(R: NDArray[np.float64]) -> tuple[float, float, float]:
    """URDF roll-pitch-yaw (R = Rz(y) Ry(p) Rx(r)) of a rotation matrix."""
    pitch = math.asin(-max(-1.0, min(1.0, R[2, 0])))
    if abs(math.cos(pitch)) > 1e-9:
        roll = math.atan2(R[2, 1], R[2, 2])
        yaw = math.atan2(R[1, 0], R[0, 0])
    else:
        roll, yaw = math.atan2(-R[1, 2], R[1, 1]), 0.0
    return roll, pitch, yaw


def z_to(d: NDArray[np.float64]) -> NDArray[np.float64]:
    """A rotation taking +z onto the unit vector d."""
    d = d / np.linalg.norm(d)
    z = np.array([0.0, 0.0, 1.0])
    v = np.cross(z, d)
    c = float(z @ d)
    if np.linalg.norm(v) < 1e-12:
        return np.eye(3) if c > 0 else np.diag([1.0, -1.0, -1.0])
    vx = np.array([[0, -v[2], v[1]], [v[2], 0, -v[0]], [-v[1], v[0], 0]])
    return np.eye(3) + vx + vx @ vx * (1 / (1 + c))


@dataclass
class Shape:
    """A collision shape: a capsule from p0 to p1, a sphere at p0 (p1 None, radius), or a box
    (size given) centred at p0."""

    p0: Sequence[float]
    p1: Sequence[float] | None = None
    radius: float = 0.02
    size: Sequence[float] | None = None

    def xml(self) -> str:
        p0 = np.asarray(self.p0, float)
        if self.size is not None:
            return f'<collision><origin xyz="{_v(p0)}"/><geometry><box size="{_v(self.size)}"/></geometry></collision>'
        if self.p1 is None or np.linalg.norm(np.asarray(self.p1, float) - p0) < 1e-6:
            return f'<collision><origin xyz="{_v(p0)}"/><geometry><sphere radius="{_f(self.radius)}"/></geometry></collision>'
        p1 = np.asarray(self.p1, float)
        d = p1 - p0
        length = float(np.linalg.norm(d))
        cyl = max(length - 2 * self.radius, 1e-3)  # the capsule's caps end at p0 and p1
        rpy = rpy_of(z_to(d))
        return (f'<collision><origin xyz="{_v((p0 + p1) / 2)}" rpy="{_v(rpy)}"/>'
                f'<geometry><capsule radius="{_f(self.radius)}" length="{_f(cyl)}"/></geometry></collision>')


@dataclass
class Link:
    """A link: mass (kg) with its centre of mass, an inertia (diagonal, kg m²) and collision shapes."""

    name: str
    mass: float = 0.0
    com: Sequence[float] = (0.0, 0.0, 0.0)
    inertia: Sequence[float] | None = None
    shapes: list[Shape] = field(default_factory=list)

    def xml(self) -> str:
        if self.mass <= 0:
            return f'  <link name="{self.name}"/>'
        inertia = self.inertia or rod_inertia(self.mass, self.shapes)
        parts = [f'  <link name="{self.name}">',
                 f'    <inertial><origin xyz="{_v(self.com)}"/><mass value="{_f(self.mass)}"/>'
                 f'<inertia ixx="{_f(inertia[0])}" ixy="0" ixz="0" iyy="{_f(inertia[1])}" iyz="0" izz="{_f(inertia[2])}"/></inertial>']
        parts += [f"    {s.xml()}" for s in self.shapes]
        parts.append("  </link>")
        return "\n".join(parts)


def rod_inertia(mass: float, shapes: Sequence[Shape]) -> tuple[float, float, float]:
    """Diagonal inertia of a uniform rod along the first shape (a sphere or a box otherwise)."""
    if not shapes:
        i = 1e-4 * mass
        return (i, i, i)
    s = shapes[0]
    if s.size is not None:
        x, y, z = s.size
        return (mass * (y * y + z * z) / 12, mass * (x * x + z * z) / 12, mass * (x * x + y * y) / 12)
    r = s.radius
    if s.p1 is None or np.linalg.norm(np.asarray(s.p1, float) - np.asarray(s.p0, float)) < 1e-6:
        i = 0.4 * mass * r * r
        return (i, i, i)
    d = np.asarray(s.p1, float) - np.asarray(s.p0, float)
    length = float(np.linalg.norm(d))
    axial, across = 0.5 * mass * r * r, mass * (3 * r * r + length * length) / 12
    u = np.abs(d / length)
    # rotate diag(across, across, axial) onto the rod and keep the diagonal (the rods of the zoo
    # lie along a link axis, where this is exact)
    return tuple(float(across + (axial - across) * u[k] ** 2) for k in range(3))  # type: ignore[return-value]


@dataclass
class Joint:
    name: str
    parent: str
    child: str
    xyz: Sequence[float] = (0.0, 0.0, 0.0)
    rpy: Sequence[float] = (0.0, 0.0, 0.0)
    axis: Sequence[float] | None = (0.0, 0.0, 1.0)  # None: fixed
    lower: float = -math.pi
    upper: float = math.pi
    effort: float = 100.0
    velocity: float = 2.0

    def xml(self) -> str:
        kind = "fixed" if self.axis is None else "revolute"
        s = (f'  <joint name="{self.name}" type="{kind}"><origin xyz="{_v(self.xyz)}" rpy="{_v(self.rpy)}"/>'
             f'<parent link="{self.parent}"/><child link="{self.child}"/>')
        if self.axis is not None:
            s += (f'<axis xyz="{_v(self.axis)}"/><limit lower="{_f(self.lower)}" upper="{_f(self.upper)}" '
                  f'effort="{_f(self.effort)}" velocity="{_f(self.velocity)}"/>')
        return s + "</joint>"


def write_urdf(path: Path, name: str, comment: str, links: Sequence[Link], joints: Sequence[Joint]) -> None:
    body = ['<?xml version="1.0"?>', f"<!-- {comment.strip()}\n     Written by examples/zoo/make_urdfs.py. -->",
            f'<robot name="{name}">']
    body += [link.xml() for link in links]
    body += [j.xml() for j in joints]
    body.append("</robot>\n")
    path.write_text("\n".join(body))


# ------------------------------------------------------------------------------------------------
# Kinematics through the plant
# ------------------------------------------------------------------------------------------------


def rot(quat: NDArray[np.float64]) -> NDArray[np.float64]:
    """Rotation matrix of a quaternion (x, y, z, w)."""
    x, y, z, w = quat
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


class Kin:
    """Forward kinematics of a task's robot by its plant: link poses at a posture."""

    def __init__(self, task) -> None:  # noqa: ANN001 - a latentrl.Task
        self.task = task
        # a "demo" start needs the demos this plant is used to make: kinematics and rules at rest
        # do not depend on the start rule
        self.plant = task.replace({"episode.start": "uniform"}).plant()
        self.links = list(task.link_names)
        self.lower, self.upper = np.asarray(task.lower), np.asarray(task.upper)

    def poses(self, q: NDArray[np.float64]) -> NDArray[np.float64]:
        self.plant.reset(np.asarray(q, float))
        return np.asarray(self.plant.link_poses())

    def pos(self, poses: NDArray[np.float64], link: str) -> NDArray[np.float64]:
        return poses[self.links.index(link), :3]

    def axis(self, poses: NDArray[np.float64], link: str, axis: Sequence[float]) -> NDArray[np.float64]:
        return rot(poses[self.links.index(link), 3:]) @ np.asarray(axis, float)

    def classify(self, Q: NDArray[np.float64]) -> NDArray[np.int8]:
        codes, _, _ = self.plant.classify(np.asarray(Q, float))
        return np.asarray(codes)


def box_penetration(p: NDArray[np.float64], lo: Sequence[float], hi: Sequence[float], inflate: float) -> float:
    """How deep the point p lies inside the box [lo, hi] widened by `inflate` (0 outside)."""
    lo_, hi_ = np.asarray(lo) - inflate, np.asarray(hi) + inflate
    depth = np.minimum(p - lo_, hi_ - p)
    return float(max(0.0, depth.min()))


def pose_residual(kin: Kin, poses: NDArray[np.float64], link: str, goal: NDArray[np.float64], axis_to: Sequence[float],
                  chain: Sequence[str], boxes: Sequence[tuple[Sequence[float], Sequence[float]]], inflate: float,
                  q: NDArray[np.float64], nominal: NDArray[np.float64]) -> NDArray[np.float64]:
    """The IK residual of a carried or placed tool: `link` at `goal` (per mm), its z axis along
    `axis_to` (per 0.01), the `chain` clear of the `boxes` widened by `inflate` (per mm), and the
    joints near `nominal` (weight 0.1)."""
    pen = [box_penetration(p, lo, hi, inflate) for p in chain_points(kin, poses, chain) for lo, hi in boxes]
    return np.concatenate([(kin.pos(poses, link) - goal) / 0.001, (kin.axis(poses, link, [0, 0, 1]) - axis_to) / 0.01,
                           np.array(pen) / 0.001, 0.1 * (q - nominal)])


def solve_ik(residual: Callable[[NDArray[np.float64]], NDArray[np.float64]], q0: NDArray[np.float64],
             lower: NDArray[np.float64], upper: NDArray[np.float64]) -> tuple[NDArray[np.float64], float]:
    """Least squares of `residual` within the joint limits from q0: (q, the residual's norm)."""
    lo, hi = lower + 1e-3, upper - 1e-3
    r = least_squares(residual, np.clip(q0, lo, hi), bounds=(lo, hi), xtol=1e-8, ftol=1e-10, max_nfev=400, diff_step=1e-4)  # poses are f32
    return r.x, float(np.linalg.norm(r.fun))


def grid_order(points: NDArray[np.float64]) -> NDArray[np.int64]:
    """An order visiting the points as a nearest-neighbour chain from the first, so that each IK
    starts from a neighbour's solution (one branch of the redundancy throughout)."""
    left = list(range(1, len(points)))
    order = [0]
    while left:
        last = points[order[-1]]
        k = int(np.argmin([np.linalg.norm(points[i] - last) for i in left]))
        order.append(left.pop(k))
    return np.array(order)


def chain_points(kin: Kin, poses: NDArray[np.float64], chain: Sequence[str], per_segment: int = 4) -> NDArray[np.float64]:
    """Points along the straight segments between consecutive links' origins of `chain`."""
    p = np.array([kin.pos(poses, name) for name in chain])
    t = np.linspace(0.0, 1.0, per_segment, endpoint=False)
    pts = [a + (b - a) * s for a, b in zip(p[:-1], p[1:]) for s in t]
    return np.array(pts + [p[-1]])


def keep_admissible(kin: Kin, Q: NDArray[np.float64], n_max: int) -> NDArray[np.float64]:
    """The first n_max postures of Q that break no rule at rest (classify code 0), and a report."""
    codes = kin.classify(Q)
    counts = {int(c): int((codes == c).sum()) for c in np.unique(codes)}
    print(f"classify: {counts} (0 = admissible) of {len(Q)} IK solutions")
    return Q[codes == 0][:n_max]


def generator(here: Path) -> tuple[np.random.Generator, Any, Kin]:
    """A demo generator's start: its `--seed` flag (default 0) as a NumPy generator, the task file
    beside it (`here / "task.toml"`) and that task's kinematics."""
    from latentrl import Task

    parser = argparse.ArgumentParser(description="writes demos.csv beside this script")
    parser.add_argument("--seed", type=int, default=0)
    rng = np.random.default_rng(parser.parse_args().seed)
    task = Task.load(here / "task.toml")
    return rng, task, Kin(task)


def write_demos(kin: Kin, postures: NDArray[np.float64], most: int, here: Path) -> None:
    """`here / "demos.csv"`: the `postures` every rule of the task admits at rest, at most
    `most` of them (`keep_admissible`), with the task's joint names."""
    from latentrl import Demonstrations, save_demos

    kept = keep_admissible(kin, np.asarray(postures), most)
    save_demos(Demonstrations(kept, kin.task.joint_names), here / "demos.csv")
    print(f"{len(kept)} demos -> {here / 'demos.csv'}")

