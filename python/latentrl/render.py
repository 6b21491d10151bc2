"""Pictures of a task's robot from the native plant's link poses (`render_mode="rgb_array"`):
the kinematic tree, the effectors' target, the obstacles and the floor, seen from the top, the
side or the front (by default the side of a floating robot, and for a fixed one the plane its
links and target spread over most); needs matplotlib (the `[plot]` extra)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.task import Task


def _canvas(size: int = 400) -> tuple[Any, Any]:
    """A matplotlib Figure on an Agg canvas (no pyplot, no display) and its axes."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size / 100, size / 100), dpi=100)
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot(aspect="equal")


def _pixels(fig: Any) -> NDArray[np.uint8]:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


VIEWS = {"top": (0, 1), "side": (0, 2), "front": (1, 2)}
"""The views by name: the world axes each draws (top x–y, side x–z, front y–z)."""


def view_axes(task: Task, points: NDArray[np.float64], target: NDArray[np.float64], view: str | None = None) -> tuple[int, int]:
    """The world axes drawn: `view`'s (`VIEWS`), or by default the side view (x–z) of a floating
    robot and, for a fixed one, the two axes along which its links (`points`, (K, 3): where they
    are, or go over an episode) and the target spread most: a planar arm in its plane, an arm that
    lifts from the side, so the motion that matters is seen."""
    if view is not None:
        if view not in VIEWS:
            raise ValueError(f"view must be one of {', '.join(VIEWS)}, got {view!r}")
        return VIEWS[view]
    if task.to_dict()["root"] == "floating":
        return VIEWS["side"]
    every = np.vstack([points[np.isfinite(points).all(axis=1)], target])
    spread = every.max(axis=0) - every.min(axis=0)
    kept = sorted(np.argsort(spread)[1:].tolist())
    return int(kept[0]), int(kept[1])


def draw_task(task: Task, plant: _native.TaskPlant, size: int = 400, view: str | None = None) -> NDArray[np.uint8]:
    """An RGB image (size, size, 3) of the task's robot as the plant holds it now, in `view`
    (`view_axes`)."""
    fig, ax = _canvas(size)
    poses = np.asarray(plant.link_poses())
    draw_scene(ax, Scene.of(task, plant, poses[:, :3], view), poses)
    return _pixels(fig)


@dataclass(frozen=True)
class Scene:
    """What a drawing of a task needs besides the link poses, read from the task once (a video
    draws many frames of one scene)."""

    view: tuple[int, int]
    config: dict[str, Any]
    link_names: tuple[str, ...]
    edges: tuple[tuple[str, str], ...]
    shapes: tuple[dict[str, Any], ...]
    target: NDArray[np.float64]

    @classmethod
    def of(cls, task: Task, plant: _native.TaskPlant, points: NDArray[np.float64], view: str | None = None) -> Scene:
        """The scene of `task`, its target where `plant` holds it now (a target measured from a
        link, `target.relative_to`, moves with it), seen in `view` or the view that shows the
        links' `points` (K, 3) and the target best (`view_axes`)."""
        config = task.to_dict()
        target = np.asarray(plant.target_position(), dtype=np.float64)
        return cls(view_axes(task, points, target, view), config, tuple(task.link_names), tuple(task.edges),
                   tuple(task._native.collision_shapes()), target)


def view_limits(points: NDArray[np.float64]) -> tuple[tuple[float, float], tuple[float, float]]:
    """Square axis limits around 2-D `points` (K, 2), with a margin and at least ±0.2 m."""
    low, high = points.min(axis=0), points.max(axis=0)
    centre = (low + high) / 2
    half = max(0.2, 0.6 * float((high - low).max()))
    return (centre[0] - half, centre[0] + half), (centre[1] - half, centre[1] + half)


def draw_scene(ax: Any, scene: Scene, poses: NDArray[np.float64], limits: tuple[Any, Any] | None = None) -> None:
    """The scene's robot at link poses `poses` (L, 7) on `ax`: its box, sphere, cylinder and
    capsule collision shapes as solids, the kinematic tree as sticks, the obstacles, the floor
    and the target, in `scene.view`; the view fits robot and target unless `limits` are given."""
    if limits is None:
        # The view: the robot and the target (the obstacles may reach beyond it).
        a, b = scene.view
        links = poses[np.isfinite(poses).all(axis=1), :3]
        limits = view_limits(np.vstack([links, scene.target])[:, [a, b]])
    draw_backdrop(ax, scene, limits)
    RobotArtists(ax, scene).update(poses)


def draw_backdrop(ax: Any, scene: Scene, limits: tuple[Any, Any]) -> None:
    """What does not move in a drawing of the scene: the view, obstacles, floor and target."""
    from matplotlib.patches import Rectangle

    a, b = scene.view
    config = scene.config
    ax.set(xlim=limits[0], ylim=limits[1])
    for box in config["obstacles"]:
        lo, hi = _corners(box)
        ax.add_patch(Rectangle((lo[a], lo[b]), hi[a] - lo[a], hi[b] - lo[b], color="0.6"))
    if config["floor"] is not None and b == 2:
        ax.axhline(config["floor"]["height"], color="0.4", lw=2)
    ax.plot(scene.target[:, a], scene.target[:, b], "g*", ms=10)


class RobotArtists:
    """The robot's moving artists on `ax` (a solid per collision shape, the kinematic tree as
    one stick line), moved by `update`: a video changes them, not the whole figure."""

    def __init__(self, ax: Any, scene: Scene, *, animated: bool = False) -> None:
        from matplotlib.patches import Polygon

        self.scene = scene
        self.solids = [ax.add_patch(Polygon(np.zeros((3, 2)), closed=True, color="C0", alpha=0.35, lw=0,
                                            animated=animated)) for _ in scene.shapes]
        self.sticks, = ax.plot([], [], "o-", color="C0", lw=2, ms=3, animated=animated)

    @property
    def artists(self) -> list[Any]:
        return [*self.solids, self.sticks]

    def update(self, poses: NDArray[np.float64]) -> None:
        """Moves the artists to link poses `poses` (L, 7); a link with a non-finite pose is left out."""
        a, b = self.scene.view
        pose_of = dict(zip(self.scene.link_names, poses))
        for solid, shape in zip(self.solids, self.scene.shapes):
            outline = shape_outline(pose_of[shape["link"]], shape, (a, b))
            solid.set_visible(outline is not None)
            if outline is not None:
                solid.set_xy(outline)
        finite = {name: pose[:3] for name, pose in pose_of.items() if np.all(np.isfinite(pose))}
        gap = np.full(3, np.nan)
        line = [point for parent, child in self.scene.edges if parent in finite and child in finite
                for point in (finite[parent], finite[child], gap)]
        xyz = np.array(line).reshape(-1, 3)
        self.sticks.set_data(xyz[:, a], xyz[:, b])


#: 16 points on the unit circle in the x–y plane, and those circles in the three axis planes
#: (a sphere's outline seen from any axis).
_ANGLES = np.linspace(0, 2 * np.pi, 16, endpoint=False)
_RING = np.column_stack([np.cos(_ANGLES), np.sin(_ANGLES), np.zeros_like(_ANGLES)])
_BALL = np.vstack([_RING, _RING[:, [0, 2, 1]], _RING[:, [2, 0, 1]]])


def shape_outline(link_pose: NDArray[np.float64], shape: Mapping[str, Any], view: tuple[int, int]) -> NDArray[np.float64] | None:
    """The outline (K, 2) of a collision shape of a link at `link_pose`, projected on the `view`
    axes (the convex hull of its corners, of points on its end circles, or of a mesh's hull
    vertices); None for a shape seen edge-on (or a mesh without its hull)."""
    from scipy.spatial import ConvexHull, QhullError

    size = np.asarray(shape["size"], dtype=np.float64)
    if shape["kind"] == "box":
        local = np.array([[(k >> i & 1) - 0.5 for i in range(3)] for k in range(8)]) * size
    elif shape["kind"] == "sphere":
        local = _BALL * size[0]
    elif shape["kind"] in ("cylinder", "capsule"):
        radius, length = size
        ends = _BALL if shape["kind"] == "capsule" else _RING
        local = np.vstack([ends * radius + [0, 0, z] for z in (-length / 2, length / 2)])
    elif shape["kind"] == "mesh" and len(shape.get("points") or ()) >= 3:
        local = np.asarray(shape["points"], dtype=np.float64)  # the hull the physics collides with
    else:
        return None
    centre, rotation = shape_world_pose(link_pose, shape)
    flat: NDArray[np.float64] = (rotation.apply(local) + centre)[:, list(view)]
    try:
        hull = ConvexHull(flat)
    except QhullError:
        return None
    return flat[hull.vertices]


def shape_world_pose(link_pose: NDArray[np.float64], shape: Mapping[str, Any]) -> tuple[NDArray[np.float64], Any]:
    """A collision shape's centre in the world and its rotation (a scipy `Rotation`), from its
    link's pose (x, y, z, qx, qy, qz, qw) and its `origin` in the link."""
    from scipy.spatial.transform import Rotation

    origin = np.asarray(shape["origin"], dtype=np.float64)
    link = Rotation.from_quat(link_pose[3:])
    return link.apply(origin[:3]) + link_pose[:3], link * Rotation.from_quat(origin[3:])


def _corners(box: Mapping[str, Any]) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Lower and upper corners of an obstacle table (min/max, or center/half_extents)."""
    if box.get("min") is not None:
        return np.asarray(box["min"]), np.asarray(box["max"])
    c, h = np.asarray(box["center"]), np.asarray(box["half_extents"])
    return c - h, c + h


def draw_bimanual(config: Mapping[str, Any], hands: NDArray[np.float64], size: int = 400) -> NDArray[np.uint8]:
    """An RGB image of Experiment 1's toy: the hands, the target and the disc obstacle."""
    fig, ax = _canvas(size)
    draw_toy_backdrop(ax, config)
    ax.plot(*np.asarray(hands).reshape(2, 2).T, "o-", color="C0", lw=3)
    return _pixels(fig)


def draw_toy_backdrop(ax: Any, config: Mapping[str, Any]) -> None:
    """What does not move in Experiment 1's toy: its state box, the disc obstacle and the target."""
    from matplotlib.patches import Circle

    ax.set(xlim=(config["box_low"], config["box_high"]), ylim=(config["box_low"], config["box_high"]))
    ax.add_patch(Circle(tuple(config["obstacle_centre"]), config["obstacle_radius"], color="0.6"))
    ax.plot(*np.asarray(config["target"]).reshape(2, 2).T, "g*", ms=10)
