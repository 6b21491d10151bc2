"""The KHR-1HV-like humanoid (SPEC §4.3): its URDF, a NumPy forward kinematics of the
whole body, balance (centre of mass, support margin) and grip, and the lift poses.

The kinematics here is independent of rapier: it reads the shipped URDF with
`xml.etree`, composes the joint origins (URDF rpy R = Rz·Ry·Rx) and places the robot with
its left sole flat on the ground, as `sim::humanoid::reset_on_ground` does. The physics
check itself (`fall_check`) runs in Rust.

Frame: x forward, y left, z up; the sagittal plane is x–z. Pitch joints turn about +y, so
a negative pitch swings a hanging limb forward; knees bend with positive angles.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import NamedTuple, TypedDict

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from latentrl import _native

#: Width of the lifted object: the demonstrated hand distance (m).
GRIP_WIDTH = 0.10


class ServoGains(TypedDict):
    """PD servo of every joint: keyword arguments of `Sim` and the fall check."""

    kp: float
    kd: float
    max_force: float


class PhysicsSettings(TypedDict):
    """Physics step (s), solver iterations and PGS passes per iteration: keyword arguments of
    `Sim` and the fall check."""

    dt: float
    solver_iterations: int
    pgs_iterations: int


#: Servo of the humanoid (SPEC §4.3's MuJoCo study): kp N·m/rad, kd N·m·s/rad, cap N·m.
SERVO: ServoGains = {"kp": 8.0, "kd": 0.1, "max_force": 1.2}
#: Physics of the humanoid: dt 1/240 s, 1 rapier solver iteration of 4 PGS passes. Each solver
#: iteration refreshes the multibody's mass matrix (most of a step's cost), PGS passes do not:
#: this stands 10 s (an Exp 3 episode at most) drifting 0.9 mm (4 iterations of 1 pass: 2.3 mm)
#: at 0.3 × the cost; over 60 s it creeps 59 mm (4 × 1: 14 mm; benches/README.md). The Rust side's
#: defaults (`sim::humanoid::sim_options`) are the same SERVO and PHYSICS (tests/test_exp3.py).
PHYSICS: PhysicsSettings = {"dt": 1.0 / 240.0, "solver_iterations": 1, "pgs_iterations": 4}


def urdf_path() -> Path:
    """Path of the shipped KHR-1HV-like URDF (package data)."""
    return Path(str(resources.files("latentrl") / "data" / "khr1hv.urdf"))


def demos_path(heel: bool = False) -> Path:
    """Path of the lift demos: centred balance, or the heel-side set of the fall check."""
    name = "khr1hv_lift_demos_heel.csv" if heel else "khr1hv_lift_demos.csv"
    return Path(str(resources.files("latentrl") / "data" / name))


def _rpy(r: float, p: float, y: float) -> NDArray[np.float64]:
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    rotation: NDArray[np.float64] = rz @ ry @ rx
    return rotation


def _axis_angle(axis: NDArray[np.float64], q: float) -> NDArray[np.float64]:
    a = axis / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    rotation: NDArray[np.float64] = np.eye(3) + np.sin(q) * k + (1 - np.cos(q)) * k @ k
    return rotation


def _attr(element: ET.Element | None, key: str, what: str) -> str:
    """Attribute `key` of `element`; a ValueError naming `what` if either is missing."""
    value = None if element is None else element.get(key)
    if value is None:
        raise ValueError(f"URDF: {what} has no {key!r} attribute")
    return value


def _pose(origin: ET.Element | None) -> NDArray[np.float64]:
    t = np.eye(4)
    if origin is not None:
        t[:3, 3] = [float(v) for v in origin.get("xyz", "0 0 0").split()]
        t[:3, :3] = _rpy(*[float(v) for v in origin.get("rpy", "0 0 0").split()])
    return t


@dataclass(frozen=True)
class Humanoid:
    """Kinematic model of a URDF tree: joints, limits, link inertials and sole boxes."""

    joint_names: tuple[str, ...]
    lower: NDArray[np.float64]
    upper: NDArray[np.float64]
    _joints: tuple[tuple[str, str, str, NDArray[np.float64], NDArray[np.float64] | None], ...]
    _inertials: tuple[tuple[str, float, NDArray[np.float64]], ...]
    _boxes: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]]
    root: str

    @classmethod
    def from_urdf(cls, path: str | Path | None = None) -> Humanoid:
        """Reads the URDF at `path` (default: the shipped robot); a missing element or
        attribute is a ValueError naming it."""
        tree = ET.parse(path or urdf_path()).getroot()
        joints: list[tuple[str, str, str, NDArray[np.float64], NDArray[np.float64] | None]] = []
        names: list[str] = []
        lower: list[float] = []
        upper: list[float] = []
        for j in tree.findall("joint"):
            name = _attr(j, "name", "a <joint>")
            parent = _attr(j.find("parent"), "link", f"the <parent> of joint {name!r}")
            child = _attr(j.find("child"), "link", f"the <child> of joint {name!r}")
            axis = None
            if j.get("type") != "fixed":
                axis_el = j.find("axis")
                xyz = axis_el.get("xyz", "1 0 0") if axis_el is not None else "1 0 0"
                axis = np.array([float(v) for v in xyz.split()])
                lim = j.find("limit")
                names.append(name)
                lower.append(float(_attr(lim, "lower", f"the <limit> of joint {name!r}")))
                upper.append(float(_attr(lim, "upper", f"the <limit> of joint {name!r}")))
            joints.append((name, parent, child, _pose(j.find("origin")), axis))
        inertials: list[tuple[str, float, NDArray[np.float64]]] = []
        boxes: dict[str, tuple[NDArray[np.float64], NDArray[np.float64]]] = {}
        for link in tree.findall("link"):
            link_name = _attr(link, "name", "a <link>")
            inertial = link.find("inertial")
            if inertial is not None:
                mass = float(_attr(inertial.find("mass"), "value", f"the mass of {link_name!r}"))
                centre = _pose(inertial.find("origin"))[:3, 3]
                inertials.append((link_name, mass, centre))
            for col in link.findall("collision"):
                box = col.find("geometry/box")
                if box is not None:
                    size = _attr(box, "size", f"the collision box of {link_name!r}")
                    boxes[link_name] = (
                        _pose(col.find("origin")),
                        np.array([float(v) for v in size.split()]),
                    )
        children = {j[2] for j in joints}
        names_of_links = [_attr(link, "name", "a <link>") for link in tree.findall("link")]
        root = next(n for n in names_of_links if n not in children)
        return cls(
            tuple(names), np.array(lower), np.array(upper), tuple(joints), tuple(inertials),
            boxes, root,
        )

    @property
    def edges(self) -> list[tuple[str, str]]:
        """(parent link, child link) of every joint: the kinematic tree, e.g. to draw it."""
        return [(parent, child) for _, parent, child, _, _ in self._joints]

    def index(self, name: str) -> int:
        """Column of joint `name` in a posture."""
        return self.joint_names.index(name)

    def link_poses(
        self, posture: NDArray[np.float64], base: NDArray[np.float64] | None = None
    ) -> dict[str, NDArray[np.float64]]:
        """World 4×4 poses of every link for `posture` (D,) and root pose `base` (4×4)."""
        q = dict(zip(self.joint_names, np.asarray(posture, dtype=float), strict=True))
        poses = {self.root: np.eye(4) if base is None else base}
        pending = list(self._joints)
        while pending:
            rest = []
            for name, parent, child, origin, axis in pending:
                if parent not in poses:
                    rest.append((name, parent, child, origin, axis))
                    continue
                t = poses[parent] @ origin
                if axis is not None:
                    m = np.eye(4)
                    m[:3, :3] = _axis_angle(axis, q[name])
                    t = t @ m
                poses[child] = t
            pending = rest
        return poses

    def on_ground(
        self, posture: NDArray[np.float64], sole: str = "l_foot"
    ) -> dict[str, NDArray[np.float64]]:
        """Link poses with `sole` flat on the ground (z = 0), as the Rust reset places it."""
        poses = self.link_poses(posture)
        s = poses[sole]
        yaw = np.arctan2(s[1, 0], s[0, 0])
        flat = np.eye(4)
        flat[:3, :3] = _rpy(0.0, 0.0, yaw)
        flat[:2, 3] = s[:2, 3]
        base = flat @ np.linalg.inv(s)
        poses = self.link_poses(posture, base)
        lowest = min(c[2] for c in self.sole_corners(poses, sole))
        base[2, 3] -= lowest
        return self.link_poses(posture, base)

    def sole_corners(
        self, poses: dict[str, NDArray[np.float64]], sole: str
    ) -> list[NDArray[np.float64]]:
        """World corners of the sole box of link `sole`."""
        origin, size = self._boxes[sole]
        half = (-0.5, 0.5)
        signs = np.array([[sx, sy, sz] for sx in half for sy in half for sz in half])
        return [(poses[sole] @ origin @ np.append(s * size, 1.0))[:3] for s in signs]

    def com(self, poses: dict[str, NDArray[np.float64]]) -> NDArray[np.float64]:
        """Whole-body centre of mass (3,) from the URDF inertials."""
        total = sum(m for _, m, _ in self._inertials)
        moments = [m * (poses[n] @ np.append(c, 1.0))[:3] for n, m, c in self._inertials]
        centre: NDArray[np.float64] = np.sum(moments, axis=0) / total
        return centre

    def balance(
        self, posture: NDArray[np.float64], soles: tuple[str, str] = ("l_foot", "r_foot")
    ) -> dict[str, float]:
        """Standing on both soles: support margin (m, CoM projection to the polygon edge,
        positive inside), CoM distance ahead of the heel edge (m), grip error (m: hand
        distance − GRIP_WIDTH) and torso pitch (rad, forward positive)."""
        poses = self.on_ground(posture, soles[0])
        corners = [c for s in soles for c in self.sole_corners(poses, s)]
        low = min(c[2] for c in corners)
        pts = np.array([c[:2] for c in corners if c[2] <= low + 2e-3])
        com = self.com(poses)[:2]
        margin = hull_margin(com, pts)
        hands = np.linalg.norm(poses["l_hand"][:3, 3] - poses["r_hand"][:3, 3])
        torso = poses[self.root][:3, :3]
        return {
            "margin": margin,
            "heel": float(com[0] - pts[:, 0].min()),
            "grip_error": float(hands - GRIP_WIDTH),
            "torso_pitch": float(np.arctan2(torso[0, 2], torso[2, 2])),
            "hands_z": float(poses["l_hand"][2, 3]),
        }


def _cross(a: NDArray[np.float64], b: NDArray[np.float64]) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def hull_margin(p: NDArray[np.float64], pts: NDArray[np.float64]) -> float:
    """Signed distance from `p` to the convex hull of `pts` (positive inside)."""
    pts = np.unique(np.round(pts, 12), axis=0)
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]

    def chain(seq: NDArray[np.float64]) -> list[NDArray[np.float64]]:
        out: list[NDArray[np.float64]] = []
        for q in seq:
            while len(out) >= 2 and _cross(out[-1] - out[-2], q - out[-2]) <= 0:
                out.pop()
            out.append(q)
        return out[:-1]

    hull = chain(pts) + chain(pts[::-1])
    dist, inside = np.inf, True
    for a, b in zip(hull, hull[1:] + hull[:1], strict=True):
        e = b - a
        t = np.clip(np.dot(p - a, e) / np.dot(e, e), 0.0, 1.0)
        dist = min(dist, float(np.linalg.norm(p - (a + t * e))))
        inside &= bool(_cross(e, p - a) >= 0)
    return dist if inside else -dist


@lru_cache(maxsize=1)
def model() -> Humanoid:
    """The shipped robot's kinematic model (cached)."""
    return Humanoid.from_urdf()


class FallCheck(NamedTuple):
    """What `fall_check` saw."""

    segments: NDArray[np.float64]
    """(M, 7), one row per target: fell, min support margin, final support margin, grip
    error at the end, max |grip error| (m), final base height (m), time of the fall (s since
    the start; NaN while standing)."""
    frames: NDArray[np.float64]
    """(K, 9 + D), one per reached `record_times` entry, taken at the first check at or
    after it: time (s), fell, base position (3), base quaternion (x, y, z, w), joints (D)."""

    def link_poses(self, k: int) -> dict[str, NDArray[np.float64]]:
        """World 4×4 pose of every link at frame `k` (the NumPy kinematics at its joints and
        base pose)."""
        frame = self.frames[k]
        base = np.eye(4)
        base[:3, :3] = Rotation.from_quat(frame[5:9]).as_matrix()
        base[:3, 3] = frame[2:5]
        return model().link_poses(frame[9:], base)


def fall_check(
    start: NDArray[np.float64],
    targets: NDArray[np.float64],
    *,
    hold: float = 1.0,
    urdf: str | Path | None = None,
    record_times: Sequence[float] = (),
) -> FallCheck:
    """Physics fall check (Rust `sim::humanoid::run_fall_check`): stand at `start`, hold each
    row of `targets` for `hold` s with the SERVO gains and PHYSICS, checking every 4 physics
    steps; records the robot at `record_times` (s) for pictures."""
    start = np.ascontiguousarray(start, dtype=np.float64)
    targets = np.ascontiguousarray(np.atleast_2d(targets), dtype=np.float64)
    table, frames = _native.humanoid_fall_check(
        str(urdf or urdf_path()), start, targets, hold=hold, grip_width=GRIP_WIDTH,
        record_times=[float(t) for t in record_times], **SERVO, **PHYSICS,
    )
    return FallCheck(table, frames)
