"""A minimal NumPy forward kinematics of a URDF tree, independent of the native side (and of
rapier): the tests' reference for `TaskPlant.pose_links` / `link_poses` and the support margin.

It reads the URDF with `xml.etree`, composes the joint origins (URDF rpy: R = Rz·Ry·Rx) and
turns each revolute/continuous joint about its axis (Rodrigues), each prismatic joint along
it. Only what the tests need: links, actuated joints and their limits, inertials (mass,
centre) and box collision shapes (the soles). The package itself has no URDF parser.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

Matrix = NDArray[np.float64]


def rpy(r: float, p: float, y: float) -> Matrix:
    """URDF roll-pitch-yaw: R = Rz(y) · Ry(p) · Rx(r)."""
    cr, sr, cp, sp, cy, sy = np.cos(r), np.sin(r), np.cos(p), np.sin(p), np.cos(y), np.sin(y)
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    return rz @ ry @ rx


def axis_angle(axis: Matrix, q: float) -> Matrix:
    """Rotation by `q` about `axis` (Rodrigues)."""
    a = axis / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + np.sin(q) * k + (1 - np.cos(q)) * k @ k


def quaternion_matrix(q: Matrix) -> Matrix:
    """Rotation matrix of the unit quaternion (x, y, z, w)."""
    x, y, z, w = np.asarray(q, dtype=np.float64) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
        [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
        [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
    ])


def pose_matrix(pose7: Matrix) -> Matrix:
    """4×4 transform of a pose (7,): position, quaternion (x, y, z, w)."""
    t = np.eye(4)
    t[:3, :3] = quaternion_matrix(pose7[3:7])
    t[:3, 3] = pose7[:3]
    return t


def _origin(element: ET.Element | None) -> Matrix:
    t = np.eye(4)
    if element is not None:
        t[:3, 3] = [float(v) for v in element.get("xyz", "0 0 0").split()]
        t[:3, :3] = rpy(*[float(v) for v in element.get("rpy", "0 0 0").split()])
    return t


@dataclass(frozen=True)
class Joint:
    name: str
    kind: str
    parent: str
    child: str
    origin: Matrix
    axis: Matrix


@dataclass(frozen=True)
class Robot:
    """A URDF tree: links (URDF order), joints, the actuated joints' names and limits,
    inertials `{link: (mass, centre in the link frame)}` and box shapes `{link: (origin, size)}`."""

    links: tuple[str, ...]
    root: str
    joints: tuple[Joint, ...]
    joint_names: tuple[str, ...]
    lower: Matrix
    upper: Matrix
    inertials: dict[str, tuple[float, Matrix]]
    boxes: dict[str, tuple[Matrix, Matrix]]

    @classmethod
    def parse(cls, path: str | Path) -> Robot:
        tree = ET.parse(path).getroot()
        links = tuple(link.get("name", "") for link in tree.findall("link"))
        joints, names, lower, upper = [], [], [], []
        for j in tree.findall("joint"):
            kind = j.get("type", "")
            axis_el = j.find("axis")
            axis = np.array([float(v) for v in (axis_el.get("xyz", "1 0 0") if axis_el is not None else "1 0 0").split()])
            joint = Joint(j.get("name", ""), kind, j.find("parent").get("link"), j.find("child").get("link"),
                          _origin(j.find("origin")), axis)
            joints.append(joint)
            if kind != "fixed":
                limit = j.find("limit")
                names.append(joint.name)
                continuous = kind == "continuous" or limit is None
                lower.append(-np.inf if continuous else float(limit.get("lower", "0")))
                upper.append(np.inf if continuous else float(limit.get("upper", "0")))
        inertials, boxes = {}, {}
        for link in tree.findall("link"):
            name = link.get("name", "")
            inertial = link.find("inertial")
            if inertial is not None:
                inertials[name] = (float(inertial.find("mass").get("value")), _origin(inertial.find("origin"))[:3, 3])
            for collision in link.findall("collision"):
                box = collision.find("geometry/box")
                if box is not None:
                    boxes[name] = (_origin(collision.find("origin")), np.array([float(v) for v in box.get("size").split()]))
        children = {j.child for j in joints}
        root = next(name for name in links if name not in children)
        return cls(links, root, tuple(joints), tuple(names), np.array(lower), np.array(upper), inertials, boxes)

    def link_poses(self, posture: Matrix, base: Matrix | None = None) -> dict[str, Matrix]:
        """World 4×4 pose of every link at `posture` (D,) with the root at `base` (4×4)."""
        q = dict(zip(self.joint_names, np.asarray(posture, dtype=np.float64), strict=True))
        poses = {self.root: np.eye(4) if base is None else np.asarray(base, dtype=np.float64)}
        pending = list(self.joints)
        while pending:
            rest = []
            for j in pending:
                if j.parent not in poses:
                    rest.append(j)
                    continue
                motion = np.eye(4)
                if j.kind in ("revolute", "continuous"):
                    motion[:3, :3] = axis_angle(j.axis, q[j.name])
                elif j.kind == "prismatic":
                    motion[:3, 3] = q[j.name] * j.axis / np.linalg.norm(j.axis)
                poses[j.child] = poses[j.parent] @ j.origin @ motion
            if len(rest) == len(pending):
                raise ValueError(f"joints not connected to the root {self.root!r}: {[j.name for j in rest]}")
            pending = rest
        return poses

    def link_pose_rows(self, posture: Matrix, base: Matrix | None = None) -> Matrix:
        """Positions (L, 3) of every link in URDF order (the rows of `TaskPlant.link_poses`)."""
        poses = self.link_poses(posture, base)
        return np.array([poses[name][:3, 3] for name in self.links])

    def standing(self, posture: Matrix, sole: str) -> dict[str, Matrix]:
        """Link poses at `posture` with the box of link `sole` flat on the ground z = 0 (the
        placement of `Sim.reset_on_ground` without its clearance)."""
        poses = self.link_poses(posture)
        origin, _ = self.boxes[sole]
        base = np.linalg.inv(poses[sole] @ origin)  # the sole box's frame becomes the world's
        poses = self.link_poses(posture, base)
        base[2, 3] -= self.box_corners(poses, sole)[:, 2].min()
        return self.link_poses(posture, base)

    def box_corners(self, poses: dict[str, Matrix], link: str) -> Matrix:
        """World corners (8, 3) of the box collision shape of `link`."""
        origin, size = self.boxes[link]
        signs = np.array([[sx, sy, sz] for sx in (-0.5, 0.5) for sy in (-0.5, 0.5) for sz in (-0.5, 0.5)])
        return np.array([(poses[link] @ origin @ np.append(s * size, 1.0))[:3] for s in signs])

    def mass(self) -> float:
        return float(sum(m for m, _ in self.inertials.values()))

    def center_of_mass(self, poses: dict[str, Matrix]) -> Matrix:
        """Whole-body centre of mass (3,) from the URDF inertials."""
        moments = [m * (poses[name] @ np.append(c, 1.0))[:3] for name, (m, c) in self.inertials.items()]
        return np.sum(moments, axis=0) / self.mass()

    def support_margin(self, poses: dict[str, Matrix], soles: tuple[str, ...], tolerance: float = 2e-3) -> float:
        """Signed distance (m, positive inside) of the centre of mass's ground projection to the
        convex hull of the sole corners within `tolerance` of the lowest one."""
        corners = np.vstack([self.box_corners(poses, s) for s in soles])
        touching = corners[corners[:, 2] <= corners[:, 2].min() + tolerance]
        return hull_margin(self.center_of_mass(poses)[:2], touching[:, :2])


def _cross(a: Matrix, b: Matrix) -> float:
    return float(a[0] * b[1] - a[1] * b[0])


def hull_margin(p: Matrix, pts: Matrix) -> float:
    """Signed distance from `p` to the convex hull of the 2-D points `pts` (positive inside)."""
    pts = np.unique(np.round(pts, 12), axis=0)
    pts = pts[np.lexsort((pts[:, 1], pts[:, 0]))]

    def chain(seq: Matrix) -> list[Matrix]:
        out: list[Matrix] = []
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
        inside &= _cross(e, p - a) >= 0
    return dist if inside else -dist


def task_robot(task) -> Robot:
    """The reference model of a `latentrl.Task`'s URDF."""
    return Robot.parse(task.urdf_path)
