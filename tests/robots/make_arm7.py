"""Writes tests/robots/arm7_description: a 7-DoF arm with a two-finger gripper laid out as a
ROS description package, the shapes real robot descriptions have (issue #17):

- collision meshes in every format the loader reads: binary STL, ASCII STL, OBJ, COLLADA;
- `package://arm7_description/...` paths and paths relative to the URDF's folder;
- revolute joints with effort limits, a continuous wrist joint, prismatic fingers, the second
  finger a `<mimic>` of the first;
- visual meshes beside the collision ones;
- `arm7_primitives.urdf`: the same arm with cylinders and boxes instead of meshes (the speed
  benchmark's reference and the forward-kinematics cross-check).

The kinematics are the Franka Panda's published joint offsets; the shapes are plain prisms.
The files are committed; re-run only to change them (needs trimesh and pycollada, dev-only):

    pip install trimesh pycollada && python tests/robots/make_arm7.py
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parent / "arm7_description"
PI2 = np.pi / 2

# name, joint origin xyz, rpy, joint type, limits, effort, collision format, path style
JOINTS = [
    ("joint1", (0, 0, 0.333), (0, 0, 0), "revolute", (-2.8973, 2.8973), 87, "stl"),
    ("joint2", (0, 0, 0), (-PI2, 0, 0), "revolute", (-1.7628, 1.7628), 87, "stl"),
    ("joint3", (0, -0.316, 0), (PI2, 0, 0), "revolute", (-2.8973, 2.8973), 87, "stl_ascii"),
    ("joint4", (0.0825, 0, 0), (PI2, 0, 0), "revolute", (-3.0718, -0.0698), 87, "obj"),
    ("joint5", (-0.0825, 0.384, 0), (-PI2, 0, 0), "revolute", (-2.8973, 2.8973), 12, "obj"),
    ("joint6", (0, 0, 0), (PI2, 0, 0), "revolute", (-0.0175, 3.7525), 12, "dae"),
    ("joint7", (0.088, 0, 0), (PI2, 0, 0), "continuous", None, 12, "dae"),
]
EXT = {"stl": "stl", "stl_ascii": "stl", "obj": "obj", "dae": "dae"}
LINK_RADIUS, LINK_LENGTH, SECTIONS = 0.06, 0.12, 24


def link_mesh() -> trimesh.Trimesh:
    """A 24-sided prism along z, centred on the link frame."""
    return trimesh.creation.cylinder(radius=LINK_RADIUS, height=LINK_LENGTH, sections=SECTIONS)


def inertial(mass: float, r: float, h: float) -> str:
    """A solid cylinder's inertia about its centre (axis z)."""
    ixx = mass * (3 * r * r + h * h) / 12
    izz = mass * r * r / 2
    return (
        f'<inertial><origin xyz="0 0 0"/><mass value="{mass}"/>'
        f'<inertia ixx="{ixx:.6g}" ixy="0" ixz="0" iyy="{ixx:.6g}" iyz="0" izz="{izz:.6g}"/></inertial>'
    )


def write_mesh(mesh: trimesh.Trimesh, name: str, fmt: str) -> str:
    """Writes `name` in `fmt` under meshes/collision and returns its file name."""
    folder = ROOT / "meshes" / "collision"
    folder.mkdir(parents=True, exist_ok=True)
    file = f"{name}.{EXT[fmt]}"
    if fmt == "stl_ascii":
        mesh.export(folder / file, file_type="stl_ascii")
    elif fmt == "dae":
        # Robot packages write Z_UP (pycollada's default is Y_UP): the vertices are as given.
        text = trimesh.exchange.dae.export_collada(mesh).decode()
        (folder / file).write_text(text.replace("<up_axis>Y_UP</up_axis>", "<up_axis>Z_UP</up_axis>"))
    else:
        mesh.export(folder / file)
    return file


def mesh_ref(file: str, relative: bool) -> str:
    """How the URDF names a mesh: relative to urdf/ or by package:// path."""
    return f"../meshes/collision/{file}" if relative else f"package://arm7_description/meshes/collision/{file}"


def link(name: str, mass: float, geometry: str | None, visual: str | None) -> str:
    """One <link>: inertial, optional collision and visual geometry."""
    parts = [f'<link name="{name}">', inertial(mass, LINK_RADIUS, LINK_LENGTH)]
    if visual:
        parts.append(f"<visual><geometry>{visual}</geometry></visual>")
    if geometry:
        parts.append(f"<collision><geometry>{geometry}</geometry></collision>")
    parts.append("</link>")
    return "".join(parts)


def urdf(meshes: bool) -> str:
    """The arm's URDF, with mesh or primitive collision shapes."""
    cylinder = f'<cylinder radius="{LINK_RADIUS}" length="{LINK_LENGTH}"/>'
    out = ['<?xml version="1.0"?>', f'<robot name="{"arm7" if meshes else "arm7_primitives"}">']
    names = ["link0"] + [f"link{i}" for i in range(1, 8)]
    formats = ["stl"] + [j[6] for j in JOINTS]
    for i, (name, fmt) in enumerate(zip(names, formats)):
        if meshes:
            file = write_mesh(link_mesh(), name, fmt)
            ref = mesh_ref(file, relative=i in (2, 5))
            geometry = f'<mesh filename="{ref}"/>'
        else:
            geometry = cylinder
        out.append(link(name, 4.0 if i < 4 else 1.5, geometry, geometry if meshes else None))
    for i, (name, xyz, rpy, kind, limits, effort, _) in enumerate(JOINTS):
        limit = f'<limit effort="{effort}" velocity="2.5"/>'
        if limits:
            limit = f'<limit lower="{limits[0]}" upper="{limits[1]}" effort="{effort}" velocity="2.5"/>'
        out.append(
            f'<joint name="{name}" type="{kind}"><parent link="link{i}"/><child link="link{i + 1}"/>'
            f'<origin xyz="{" ".join(map(str, xyz))}" rpy="{" ".join(f"{v:.10g}" for v in rpy)}"/>'
            f'<axis xyz="0 0 1"/>{limit}<dynamics damping="0.5" friction="0.1"/></joint>'
        )
    hand_box = trimesh.creation.box(extents=(0.06, 0.2, 0.06))
    finger = trimesh.creation.box(extents=(0.02, 0.02, 0.05))
    if meshes:
        hand_geometry = f'<mesh filename="{mesh_ref(write_mesh(hand_box, "hand", "dae"), False)}"/>'
        finger_geometry = f'<mesh filename="{mesh_ref(write_mesh(finger, "finger", "obj"), False)}"/>'
    else:
        hand_geometry = '<box size="0.06 0.2 0.06"/>'
        finger_geometry = '<box size="0.02 0.02 0.05"/>'
    out.append(link("hand", 0.7, hand_geometry, None))
    out.append(
        '<joint name="flange" type="fixed"><parent link="link7"/><child link="hand"/>'
        '<origin xyz="0 0 0.107" rpy="0 0 -0.785398163397"/></joint>'
    )
    for side, sign in (("left", 1), ("right", -1)):
        out.append(link(f"{side}_finger", 0.02, finger_geometry, None))
        mimic = '<mimic joint="finger_joint1" multiplier="1" offset="0"/>' if side == "right" else ""
        name = "finger_joint1" if side == "left" else "finger_joint2"
        out.append(
            f'<joint name="{name}" type="prismatic"><parent link="hand"/><child link="{side}_finger"/>'
            f'<origin xyz="0 0 0.0584"/><axis xyz="0 {sign} 0"/>'
            f'<limit lower="0" upper="0.04" effort="20" velocity="0.2"/>{mimic}</joint>'
        )
    out.append('<link name="tcp"/>')
    out.append(
        '<joint name="tcp_joint" type="fixed"><parent link="hand"/><child link="tcp"/>'
        '<origin xyz="0 0 0.1034"/></joint>'
    )
    out.append("</robot>")
    return "\n".join(out) + "\n"


def main() -> None:
    (ROOT / "urdf").mkdir(parents=True, exist_ok=True)
    (ROOT / "package.xml").write_text(
        '<?xml version="1.0"?>\n<package format="3"><name>arm7_description</name>'
        "<version>0.1.0</version><description>Test robot for latentrl (issue #17).</description>"
        "<maintainer email=\"latentrl@example.invalid\">latentrl</maintainer><license>MIT</license></package>\n"
    )
    (ROOT / "urdf" / "arm7.urdf").write_text(urdf(meshes=True))
    (ROOT / "urdf" / "arm7_primitives.urdf").write_text(urdf(meshes=False))


if __name__ == "__main__":
    main()
