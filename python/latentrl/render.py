"""Pictures of a task's robot from the native plant's link poses (`render_mode="rgb_array"`):
the kinematic tree, the effectors' target, the obstacles and the floor, seen from the top, the
side or the front (by default the side of a floating robot, and for a fixed one the plane its
links and target spread over most) or in 3-D (mplot3d); needs matplotlib (the `[plot]` extra)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.task import Task


def _canvas(size: int = 400, view: tuple[int, ...] = (0, 1)) -> tuple[Any, Any]:
    """A matplotlib Figure on an Agg canvas (no pyplot, no display) and its axes for `view`."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=(size / 100, size / 100), dpi=100)
    FigureCanvasAgg(fig)
    return fig, view_subplot(fig, view)


def view_subplot(fig: Any, view: tuple[int, ...], *position: int) -> Any:
    """An axes of `fig` (at subplot `position`) drawing the world axes `view`: 3-D seen from
    `CAMERA` for all three, else 2-D with equal aspect."""
    if len(view) == 3:
        return fig.add_subplot(*position, projection="3d", elev=CAMERA[0], azim=CAMERA[1])
    return fig.add_subplot(*position, aspect="equal")


def _pixels(fig: Any) -> NDArray[np.uint8]:
    fig.canvas.draw()
    return np.asarray(fig.canvas.buffer_rgba())[..., :3].copy()


VIEWS: dict[str, tuple[int, ...]] = {"top": (0, 1), "side": (0, 2), "front": (1, 2), "3d": (0, 1, 2)}
"""The views by name: the world axes each draws (top x–y, side x–z, front y–z, 3d all three in
perspective from `CAMERA`)."""

CAMERA = (20.0, -60.0)
"""The 3d view's camera: elevation 20° above the x–y plane and azimuth −60° (matplotlib's
default azimuth: x runs to the lower right, y to the upper right, z up), fixed so that every
frame of a video and every image of a task is seen from the same place."""


def checked_view(view: str) -> str:
    """`view` if it names one of `VIEWS`, else a ValueError listing them."""
    if view not in VIEWS:
        raise ValueError(f"view must be one of {', '.join(VIEWS)}, got {view!r}")
    return view


def view_axes(task: Task, points: NDArray[np.float64], target: NDArray[np.float64], view: str | None = None) -> tuple[int, ...]:
    """The world axes drawn: `view`'s (`VIEWS`), or by default the side view (x–z) of a floating
    robot and, for a fixed one, the two axes along which its links (`points`, (K, 3): where they
    are, or go over an episode) and the target spread most: a planar arm in its plane, an arm that
    lifts from the side, so the motion that matters is seen."""
    if view is not None:
        return VIEWS[checked_view(view)]
    if task.to_dict()["root"] == "floating":
        return VIEWS["side"]
    every = np.vstack([points[np.isfinite(points).all(axis=1)], target])
    spread = every.max(axis=0) - every.min(axis=0)
    kept = sorted(np.argsort(spread)[1:].tolist())
    return int(kept[0]), int(kept[1])


def draw_task(task: Task, plant: _native.TaskPlant, size: int = 400, view: str | None = None) -> NDArray[np.uint8]:
    """An RGB image (size, size, 3) of the task's robot as the plant holds it now, in `view`
    (`view_axes`)."""
    poses = np.asarray(plant.link_poses())
    scene = Scene.of(task, plant, poses[:, :3], view)
    fig, ax = _canvas(size, scene.view)
    draw_scene(ax, scene, poses)
    return _pixels(fig)


@dataclass(frozen=True)
class Scene:
    """What a drawing of a task needs besides the link poses, read from the task once (a video
    draws many frames of one scene)."""

    view: tuple[int, ...]
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


Limits = tuple[tuple[float, float], ...]
"""Axis limits: (low, high) per drawn axis."""


def view_limits(points: NDArray[np.float64], *, square: bool = True) -> Limits:
    """Limits around `points` (K, N), one (low, high) per column, with a margin: square (every
    axis the largest span, at least ±0.2 m) or each axis its own span (at least ±0.1 m and a
    quarter of the largest span, so that a planar robot keeps some depth)."""
    low, high = points.min(axis=0), points.max(axis=0)
    centre, span = (low + high) / 2, high - low
    largest = float(span.max())
    half = np.full_like(span, max(0.2, 0.6 * largest)) if square else np.maximum(span / 2 + 0.1 * largest,
                                                                                   max(0.1, 0.25 * largest))
    return tuple((float(c - h), float(c + h)) for c, h in zip(centre, half))


def scene_limits(scene: Scene, points: NDArray[np.float64]) -> Limits:
    """The limits of `scene.view` that fit the finite `points` (K, 3) and the target (the
    obstacles may reach beyond them): square in 2-D; in 3-D each axis its own span, down to the
    floor."""
    every = np.vstack([points[np.isfinite(points).all(axis=1)], scene.target])
    if len(scene.view) == 3 and scene.config["floor"] is not None:
        every = np.vstack([every, [*every[-1, :2], scene.config["floor"]["height"]]])
    return view_limits(every[:, list(scene.view)], square=len(scene.view) == 2)


def draw_scene(ax: Any, scene: Scene, poses: NDArray[np.float64], limits: Limits | None = None) -> None:
    """The scene's robot at link poses `poses` (L, 7) on `ax`: its box, sphere, cylinder, capsule
    and mesh collision shapes as solids, the kinematic tree as sticks, the obstacles, the floor
    and the target, in `scene.view`; the view fits robot and target unless `limits` are given."""
    draw_backdrop(ax, scene, scene_limits(scene, poses[:, :3]) if limits is None else limits)
    RobotArtists.of(ax, scene).update(poses)


def draw_backdrop(ax: Any, scene: Scene, limits: Limits) -> None:
    """What does not move in a drawing of the scene: the view, obstacles, floor and target."""
    if len(scene.view) == 3:
        draw_room_3d(ax, scene.config, limits)
    else:
        draw_room_2d(ax, scene.config, scene.view, limits)
    ax.plot(*scene.target[:, list(scene.view)].T, "g*", ms=10)


def draw_room_2d(ax: Any, config: Mapping[str, Any], view: tuple[int, ...], limits: Limits) -> None:
    """The 2-D view's `limits`, the obstacles' rectangles and the floor's line (side and front)."""
    from matplotlib.patches import Rectangle

    a, b = view
    ax.set(xlim=limits[0], ylim=limits[1])
    for box in config["obstacles"]:
        lo, hi = _corners(box)
        ax.add_patch(Rectangle((lo[a], lo[b]), hi[a] - lo[a], hi[b] - lo[b], color="0.6"))
    if config["floor"] is not None and b == 2:
        ax.axhline(config["floor"]["height"], color="0.4", lw=2)


def draw_room_3d(ax: Any, config: Mapping[str, Any], limits: Limits) -> None:
    """The 3-D view's `limits` at one scale on every axis (`set_box_aspect` from their spans),
    the obstacles as solid boxes and the floor as a plane, both cut to the limits (mplot3d does
    not clip)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    low, high = np.array(limits).T
    ax.set(xlim=limits[0], ylim=limits[1], zlim=limits[2])
    ax.set_box_aspect(high - low)
    ax.tick_params(labelsize=7)
    for box in config["obstacles"]:
        lo, hi = (np.clip(corner, low, high) for corner in _corners(box))
        if np.all(hi > lo):
            ax.add_collection3d(Poly3DCollection(hull_triangles(lo + _CUBE * (hi - lo)), color="0.6", alpha=0.6, lw=0))
    if config["floor"] is not None and low[2] <= config["floor"]["height"] <= high[2]:
        (x0, x1), (y0, y1), _ = limits
        z = config["floor"]["height"]
        ax.add_collection3d(Poly3DCollection([[(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)]], color="0.4",
                                             alpha=0.3, lw=0))


class RobotArtists:
    """The robot's moving artists on a 2-D `ax` (a solid per collision shape, the kinematic tree
    as one stick line), moved by `update`: a video changes them, not the whole figure."""

    def __init__(self, ax: Any, scene: Scene, *, animated: bool = False) -> None:
        self.scene = scene
        self.solids = self.add_solids(ax, animated)
        self.sticks, = ax.plot(*[[]] * len(scene.view), "o-", color="C0", lw=2, ms=3, animated=animated)

    @staticmethod
    def of(ax: Any, scene: Scene, *, animated: bool = False) -> RobotArtists:
        """The robot's artists for `scene.view`: `RobotArtists3D` in the 3d view."""
        return (RobotArtists3D if len(scene.view) == 3 else RobotArtists)(ax, scene, animated=animated)

    @property
    def artists(self) -> list[Any]:
        return [*self.solids, self.sticks]

    def add_solids(self, ax: Any, animated: bool) -> list[Any]:
        """A polygon per collision shape."""
        from matplotlib.patches import Polygon

        return [ax.add_patch(Polygon(np.zeros((3, 2)), closed=True, color="C0", alpha=0.35, lw=0, animated=animated))
                for _ in self.scene.shapes]

    def update(self, poses: NDArray[np.float64]) -> None:
        """Moves the artists to link poses `poses` (L, 7); a link with a non-finite pose is left out."""
        pose_of = dict(zip(self.scene.link_names, poses))
        self.move_solids(pose_of)
        self.move_sticks(stick_line(self.scene.edges, pose_of)[:, list(self.scene.view)].T)

    def move_solids(self, pose_of: Mapping[str, NDArray[np.float64]]) -> None:
        """Each shape's polygon to its outline (`shape_outline`), hidden where it has none."""
        for solid, shape in zip(self.solids, self.scene.shapes):
            outline = shape_outline(pose_of[shape["link"]], shape, self.scene.view)
            solid.set_visible(outline is not None)
            if outline is not None:
                solid.set_xy(outline)

    def move_sticks(self, coordinates: NDArray[np.float64]) -> None:
        """The stick line to `coordinates` (2, K)."""
        self.sticks.set_data(*coordinates)


class RobotArtists3D(RobotArtists):
    """The robot's moving artists on a 3-D `ax`: one collection of every collision shape's hull
    triangles (mplot3d orders them by depth) and the stick line."""

    def add_solids(self, ax: Any, animated: bool) -> list[Any]:
        """One triangle collection for all shapes."""
        from mpl_toolkits.mplot3d.art3d import Poly3DCollection

        solids = Poly3DCollection([], facecolor="C0", edgecolor="C0", alpha=0.35, lw=0.2, animated=animated)
        ax.add_collection3d(solids)
        return [solids]

    def move_solids(self, pose_of: Mapping[str, NDArray[np.float64]]) -> None:
        """The collection to the shapes' hull triangles (`shape_triangles`), projected for drawing."""
        triangles = [shape_triangles(pose_of[shape["link"]], shape) for shape in self.scene.shapes]
        kept = [t for t in triangles if t is not None]
        self.solids[0].set_verts(np.concatenate(kept) if kept else np.zeros((0, 3, 3)))
        if self.solids[0].axes.M is not None:  # drawn before (a blitted frame skips the axes' projection pass)
            self.solids[0].do_3d_projection()

    def move_sticks(self, coordinates: NDArray[np.float64]) -> None:
        """The stick line to `coordinates` (3, K)."""
        self.sticks.set_data_3d(*coordinates)


def stick_line(edges: tuple[tuple[str, str], ...], pose_of: Mapping[str, NDArray[np.float64]]) -> NDArray[np.float64]:
    """The kinematic tree as one line (K, 3): each edge between finite link poses, NaN between edges."""
    finite = {name: pose[:3] for name, pose in pose_of.items() if np.all(np.isfinite(pose))}
    gap = np.full(3, np.nan)
    line = [point for parent, child in edges if parent in finite and child in finite
            for point in (finite[parent], finite[child], gap)]
    return np.array(line).reshape(-1, 3)


#: 16 points on the unit circle in the x–y plane, and those circles in the three axis planes
#: (a sphere's outline seen from any axis); the unit cube's corners (corner k has bit i of k as
#: coordinate i).
_ANGLES = np.linspace(0, 2 * np.pi, 16, endpoint=False)
_RING = np.column_stack([np.cos(_ANGLES), np.sin(_ANGLES), np.zeros_like(_ANGLES)])
_BALL = np.vstack([_RING, _RING[:, [0, 2, 1]], _RING[:, [2, 0, 1]]])
_CUBE = np.array([[k >> i & 1 for i in range(3)] for k in range(8)], dtype=np.float64)


def shape_outline(link_pose: NDArray[np.float64], shape: Mapping[str, Any], view: tuple[int, ...]) -> NDArray[np.float64] | None:
    """The outline (K, 2) of a collision shape of a link at `link_pose` projected on the `view`
    axes: the convex hull of its `shape_points` there; None for a shape seen edge-on (or a mesh
    without its hull)."""
    points = shape_points(link_pose, shape)
    if points is None:
        return None
    flat = points[:, list(view)]
    hull = _hull(flat)
    return None if hull is None else flat[hull.vertices]


def shape_triangles(link_pose: NDArray[np.float64], shape: Mapping[str, Any]) -> NDArray[np.float64] | None:
    """The convex hull (T, 3, 3) of a collision shape of a link at `link_pose` as triangles
    (`hull_triangles` of its `shape_points`); None for a flat shape (or a mesh without its hull)."""
    points = shape_points(link_pose, shape)
    return None if points is None else hull_triangles(points)


def hull_triangles(points: NDArray[np.float64]) -> NDArray[np.float64] | None:
    """The convex hull of `points` (K, 3) as triangles (T, 3, 3); None if they span no volume."""
    hull = _hull(points)
    return None if hull is None else points[hull.simplices]


def _hull(points: NDArray[np.float64]) -> Any:
    """The scipy `ConvexHull` of `points`, or None where they span no area (2-D) or volume (3-D)."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        return ConvexHull(points)
    except QhullError:
        return None


def shape_points(link_pose: NDArray[np.float64], shape: Mapping[str, Any]) -> NDArray[np.float64] | None:
    """World points (K, 3) whose convex hull is a collision shape of a link at `link_pose`: a
    box's corners, points on a sphere's axis circles, on a cylinder's end circles (a capsule's end
    spheres), or a mesh's hull vertices; None for a link pose that is not finite or a mesh
    without its hull (or another kind)."""
    if not np.all(np.isfinite(link_pose)):
        return None
    size = np.asarray(shape["size"], dtype=np.float64)
    if shape["kind"] == "box":
        local = (_CUBE - 0.5) * size
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
    world: NDArray[np.float64] = rotation.apply(local) + centre
    return world


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
