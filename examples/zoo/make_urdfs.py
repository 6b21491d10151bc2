"""Writes the zoo's URDFs (robot.urdf in each robot's folder) from the dimensions below.

    python examples/zoo/make_urdfs.py

Every robot is primitive shapes (capsules, spheres, boxes): none of them has published meshes
here, and the arms "in the style of" a real one take its joint layout, link lengths, masses,
limits and torque ratings (from the manufacturers' data sheets / public description packages)
but approximate its links by capsules. Frames: z up, x forward.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from _zoo import Joint, Link, Shape, write_urdf  # noqa: E402

PI = math.pi
HALF = PI / 2


def iiwa() -> None:
    """KUKA LBR iiwa 14 R820 style: 7 revolute joints z, y, z, y, z, y, z; 0.36 + 0.42 + 0.40 +
    0.126 m along the arm stretched up (reach 0.82 m from the shoulder); link masses of the
    published description (22.6 kg arm); limits ±170°/±120°/±170°/±120°/±170°/±120°/±175°,
    torque 320/320/176/176/110/40/40 N·m. A 0.30 × 0.20 m tray (0.8 kg, payload included) is
    fixed on the flange with its normal (+z of `tray`) opposite the flange axis."""
    offsets = [0.1575, 0.2025, 0.2045, 0.2155, 0.1845, 0.2155, 0.081, 0.045]  # link_k -> joint k+1
    masses = [5.0, 4.0, 4.0, 3.0, 2.7, 1.7, 1.8, 0.3]
    radii = [0.08, 0.07, 0.07, 0.065, 0.065, 0.06, 0.055, 0.045]
    axes = [(0, 0, 1), (0, 1, 0), (0, 0, 1), (0, -1, 0), (0, 0, 1), (0, 1, 0), (0, 0, 1)]
    limits = [170, 120, 170, 120, 170, 120, 175]
    efforts = [320, 320, 176, 176, 110, 40, 40]
    links, joints = [], []
    for k in range(8):
        length = offsets[k]
        links.append(Link(f"iiwa_link_{k}", masses[k], (0, 0, length / 2),
                          shapes=[Shape((0, 0, 0), (0, 0, length), radii[k])]))
    for k in range(7):
        lim = math.radians(limits[k])
        joints.append(Joint(f"iiwa_joint_{k + 1}", f"iiwa_link_{k}", f"iiwa_link_{k + 1}", (0, 0, offsets[k]),
                            axis=axes[k], lower=-lim, upper=lim, effort=efforts[k], velocity=1.5))
    links.append(Link("tray", 0.8, (0, 0, 0), shapes=[Shape((0, 0, 0.01), size=(0.30, 0.20, 0.01))]))
    joints.append(Joint("tray_mount", "iiwa_link_7", "tray", (0, 0, offsets[7] + 0.01), rpy=(PI, 0, 0), axis=None))
    write_urdf(HERE / "iiwa_tray" / "robot.urdf", "iiwa_tray", iiwa.__doc__ or "", links, joints)


def ur() -> None:
    """Universal Robots UR5 style, after ur_description's kinematics: shoulder 0.089 m up and
    0.136 m out, upper arm 0.425 m, forearm 0.392 m, wrists 0.109 / 0.095 / 0.082 m (reach
    0.85 m); masses 3.7 / 8.39 / 2.28 / 1.22 / 1.22 / 0.19 kg; torque 150 N·m (shoulder,
    elbow) and 28 N·m (wrists); limits ±178° (the real ones are ±360°)."""
    names = ["shoulder_pan_joint", "shoulder_lift_joint", "elbow_joint", "wrist_1_joint", "wrist_2_joint",
             "wrist_3_joint"]
    lk = ["base_link", "shoulder_link", "upper_arm_link", "forearm_link", "wrist_1_link", "wrist_2_link",
          "wrist_3_link"]
    xyz = [(0, 0, 0.089159), (0, 0.13585, 0), (0, -0.1197, 0.425), (0, 0, 0.39225), (0, 0.093, 0),
           (0, 0, 0.09465)]
    rpy = [(0, 0, 0), (0, HALF, 0), (0, 0, 0), (0, HALF, 0), (0, 0, 0), (0, 0, 0)]
    axes = [(0, 0, 1), (0, 1, 0), (0, 1, 0), (0, 1, 0), (0, 0, 1), (0, 1, 0)]
    efforts = [150, 150, 150, 28, 28, 28]
    # each link's capsule runs from its joint to the next joint (upper arm and forearm along z)
    spans = [(0, 0, 0.089159), (0, 0.13585, 0), (0, 0, 0.425), (0, 0, 0.39225), (0, 0.093, 0), (0, 0, 0.09465),
             (0, 0.0823, 0)]
    masses = [4.0, 3.7, 8.393, 2.275, 1.219, 1.219, 0.1879]
    radii = [0.075, 0.065, 0.06, 0.05, 0.045, 0.045, 0.04]
    links = [Link(lk[k], masses[k], tuple(x / 2 for x in spans[k]), shapes=[Shape((0, 0, 0), spans[k], radii[k])])
             for k in range(7)]
    joints = [Joint(names[k], lk[k], lk[k + 1], xyz[k], rpy[k], axes[k], -3.1, 3.1, efforts[k], 3.0)
              for k in range(6)]
    links.append(Link("tool0"))
    joints.append(Joint("tool0_fixed", "wrist_3_link", "tool0", (0, 0.0823, 0), (-HALF, 0, 0), axis=None))
    write_urdf(HERE / "ur_reach" / "robot.urdf", "ur_reach", ur.__doc__ or "", links, joints)


def panda() -> None:
    """Franka Emika Panda style, after franka_description's kinematics (0.333 / 0.316 / 0.0825 /
    0.384 / 0.088 / 0.107 m, reach 0.855 m) with a 0.103 m hand; link masses 2.9 (base), 2.74,
    2.74, 2.38, 2.38, 2.74, 1.55, 0.54, hand 0.73 kg; the published limits and torques (87 N·m
    joints 1-4, 12 N·m joints 5-7). The tool frame `tcp` has +z along the fingers."""
    q = [(-2.8973, 2.8973), (-1.7628, 1.7628), (-2.8973, 2.8973), (-3.0718, -0.0698), (-2.8973, 2.8973),
         (-0.0175, 3.7525), (-2.8973, 2.8973)]
    xyz = [(0, 0, 0.333), (0, 0, 0), (0, -0.316, 0), (0.0825, 0, 0), (-0.0825, 0.384, 0), (0, 0, 0),
           (0.088, 0, 0)]
    rpy = [(0, 0, 0), (-HALF, 0, 0), (HALF, 0, 0), (HALF, 0, 0), (-HALF, 0, 0), (HALF, 0, 0), (HALF, 0, 0)]
    masses = [2.9, 2.74, 2.74, 2.38, 2.38, 2.74, 1.55, 0.54]
    radii = [0.075, 0.065, 0.065, 0.06, 0.06, 0.055, 0.055, 0.045]
    spans = [xyz[0], xyz[1], xyz[2], xyz[3], xyz[4], xyz[5], xyz[6], (0, 0, 0.107)]
    links = []
    for k in range(8):
        span = spans[k]  # link k runs to joint k + 1 (the flange for link 7)
        links.append(Link(f"panda_link{k}", masses[k], tuple(x / 2 for x in span),
                          shapes=[Shape((0, 0, 0), span, radii[k])]))
    joints = [Joint(f"panda_joint{k + 1}", f"panda_link{k}", f"panda_link{k + 1}", xyz[k], rpy[k], (0, 0, 1),
                    q[k][0], q[k][1], 87 if k < 4 else 12, 2.0) for k in range(7)]
    links.append(Link("panda_hand", 0.73, (0, 0, 0.04), shapes=[Shape((0, 0, 0.04), size=(0.06, 0.2, 0.08))]))
    joints.append(Joint("panda_hand_joint", "panda_link7", "panda_hand", (0, 0, 0.107), (0, 0, -PI / 4), axis=None))
    links.append(Link("tcp"))
    joints.append(Joint("tcp_joint", "panda_hand", "tcp", (0, 0, 0.1034), axis=None))
    write_urdf(HERE / "panda_bins" / "robot.urdf", "panda_bins", panda.__doc__ or "", links, joints)


def bimanual() -> None:
    """Two planar 3-link arms (joints about z, in the plane z = 0, gravity along -z) with
    shoulders at (∓0.12, 0): links 0.30 / 0.25 / 0.08 m (reach 0.63 m), 0.8 / 0.6 / 0.2 kg.
    Each hand frame sits at the tip of its 0.08 m hand link, which points at the held object."""
    links = [Link("torso", 2.0, (0, -0.05, 0), shapes=[Shape((0, -0.06, 0), size=(0.34, 0.06, 0.06))])]
    joints = []
    for side, sx in (("l", -0.12), ("r", 0.12)):
        lens, masses, radii = (0.30, 0.25, 0.08), (0.8, 0.6, 0.2), (0.022, 0.018, 0.015)
        parts = [f"{side}_upper", f"{side}_fore", f"{side}_palm"]
        elbow = (-3.0, 0.3) if side == "l" else (-0.3, 3.0)
        lims = [(-1.2, 4.3), elbow, (-4.5, 4.5)]
        parent, origin = "torso", (sx, 0, 0)
        for k, name in enumerate(("shoulder", "elbow", "wrist")):
            links.append(Link(parts[k], masses[k], (lens[k] / 2, 0, 0),
                              shapes=[Shape((0, 0, 0), (lens[k], 0, 0), radii[k])]))
            joints.append(Joint(f"{side}_{name}", parent, parts[k], origin, axis=(0, 0, 1), lower=lims[k][0],
                                upper=lims[k][1], effort=200, velocity=3.0))
            parent, origin = parts[k], (lens[k], 0, 0)
        links.append(Link(f"{side}_hand"))
        joints.append(Joint(f"{side}_hand_frame", parent, f"{side}_hand", origin, axis=None))
    write_urdf(HERE / "bimanual_box" / "robot.urdf", "bimanual_box", bimanual.__doc__ or "", links, joints)


def snake() -> None:
    """A redundant planar 6-link arm (joints about z, plane z = 0, gravity along -z): six links
    of 0.05 m (reach 0.30 m), 0.06 kg each, capsules of radius 8 mm; every joint ±2.6 rad."""
    links = [Link("base", 0.5, (0, 0, 0), shapes=[Shape((0, 0, 0), radius=0.015)])]
    joints = []
    parent, origin = "base", (0, 0, 0)
    for k in range(6):
        links.append(Link(f"seg{k + 1}", 0.06, (0.025, 0, 0), shapes=[Shape((0, 0, 0), (0.05, 0, 0), 0.008)]))
        joints.append(Joint(f"j{k + 1}", parent, f"seg{k + 1}", origin, axis=(0, 0, 1), lower=-2.6, upper=2.6,
                            effort=20, velocity=4.0))
        parent, origin = f"seg{k + 1}", (0.05, 0, 0)
    links.append(Link("tip"))
    joints.append(Joint("tip_frame", parent, "tip", origin, axis=None))
    write_urdf(HERE / "snake_planar" / "robot.urdf", "snake_planar", snake.__doc__ or "", links, joints)


def biped() -> None:
    """A 1.2 m, 29 kg biped (10 joints, all pitch, about y): a 12 kg torso box, legs 0.30 + 0.30 m
    (thigh 3 kg, shin 2 kg) on 0.24 × 0.10 m box feet (1 kg, ankle 0.06 m above the sole), arms
    0.28 + 0.25 m (1.5 / 1.0 kg) from shoulders 0.45 m above the hips. Positive pitch swings a
    limb backwards; the home posture (all zero) stands straight, arms down."""
    links = [Link("pelvis", 12.0, (0, 0, 0.25), shapes=[Shape((0, 0, 0.25), size=(0.16, 0.30, 0.50))])]
    joints = []
    for side, y in (("l", 0.1), ("r", -0.1)):
        links += [Link(f"{side}_thigh", 3.0, (0, 0, -0.15), shapes=[Shape((0, 0, -0.04), (0, 0, -0.26), 0.045)]),
                  Link(f"{side}_shin", 2.0, (0, 0, -0.15), shapes=[Shape((0, 0, -0.04), (0, 0, -0.26), 0.04)]),
                  Link(f"{side}_foot", 1.0, (0.03, 0, -0.045), inertia=(1e-3, 5e-3, 5e-3),
                       shapes=[Shape((0.03, 0, -0.045), size=(0.24, 0.10, 0.03))])]
        joints += [Joint(f"{side}_hip", "pelvis", f"{side}_thigh", (0, y, 0), axis=(0, 1, 0), lower=-1.6, upper=0.6,
                         effort=300, velocity=3.0),
                   Joint(f"{side}_knee", f"{side}_thigh", f"{side}_shin", (0, 0, -0.3), axis=(0, 1, 0), lower=-0.05,
                         upper=2.4, effort=300, velocity=3.0),
                   Joint(f"{side}_ankle", f"{side}_shin", f"{side}_foot", (0, 0, -0.3), axis=(0, 1, 0), lower=-1.2,
                         upper=0.8, effort=300, velocity=3.0)]
    for side, y in (("l", 0.2), ("r", -0.2)):
        links += [Link(f"{side}_upper_arm", 1.5, (0, 0, -0.14), shapes=[Shape((0, 0, -0.05), (0, 0, -0.25), 0.035)]),
                  Link(f"{side}_forearm", 1.0, (0, 0, -0.125), shapes=[Shape((0, 0, -0.03), (0, 0, -0.22), 0.03)]),
                  Link(f"{side}_hand")]
        joints += [Joint(f"{side}_shoulder", "pelvis", f"{side}_upper_arm", (0, y, 0.45), axis=(0, 1, 0), lower=-3.0,
                         upper=0.8, effort=100, velocity=3.0),
                   Joint(f"{side}_elbow", f"{side}_upper_arm", f"{side}_forearm", (0, 0, -0.28), axis=(0, 1, 0),
                         lower=-2.4, upper=0.1, effort=100, velocity=3.0),
                   Joint(f"{side}_hand_frame", f"{side}_forearm", f"{side}_hand", (0, 0, -0.25), axis=None)]
    write_urdf(HERE / "biped_pick" / "robot.urdf", "biped_pick", biped.__doc__ or "", links, joints)


def main() -> None:
    for name in ("iiwa_tray", "ur_reach", "panda_bins", "bimanual_box", "snake_planar", "biped_pick"):
        (HERE / name).mkdir(exist_ok=True)
    iiwa(), ur(), panda(), bimanual(), snake(), biped()


if __name__ == "__main__":
    main()
