"""A recorded episode as a Rerun recording (`latentrl replay --rerun FILE.rrd`, the `[viewer]`
extra; view it with `rerun FILE.rrd`): on the timeline `step`, the robot's collision shapes as
3-D solids (boxes, spheres, cylinders, capsules, and a mesh link as the convex hull the physics
collides with), the
kinematic tree, the effectors' paths so far, the obstacles, floor and target; and beside it the
learnt V over the latent box (GPLVM variance shaded, as in the figures) as an image with the
latent path on it. Exp 1's toy is drawn in its plane (z = 0)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from latentrl._persistence import atomic_path

#: Pixels per side of the value map image.
VALUE_PIXELS = 200


def check_rerun_output(out: Path) -> None:
    """`out` is an .rrd name and rerun-sdk is installed; else a ValueError saying what to do."""
    if out.suffix.lower() != ".rrd":
        raise ValueError(f"--rerun {out}: write a .rrd file")
    try:
        import rerun  # noqa: F401
    except ImportError:
        raise ValueError("Rerun recordings need rerun-sdk: pip install 'latentrl[viewer]'") from None


def value_image(episode: Any) -> NDArray[np.uint8]:
    """V over the latent box as RGB (rows from high z2 to low, as an image is read), darkened
    where the GPLVM variance is high (log scale), the shading of `plots.latent_value_panel`."""
    from matplotlib import colormaps

    from latentrl.plots import latent_value_grid, variance_shade

    g0, _, value, _, variance = latent_value_grid(episode.weights, episode.low, episode.high, episode.model,
                                                  learner=episode.learner, grid=VALUE_PIXELS)
    span = max(float(np.ptp(value)), 1e-12)
    rgb: NDArray[np.float64] = colormaps["viridis"]((value - value.min()) / span)[..., :3]
    rgb *= 1 - 0.6 * variance_shade(variance).reshape(g0.shape)[..., None]
    return (255 * np.flipud(rgb)).round().astype(np.uint8)  # image rows run from high z2 down


def to_pixels(episode: Any, z: NDArray[np.float64]) -> NDArray[np.float64]:
    """Latent points (K, 2) in the value image's pixel coordinates (x right, y down)."""
    unit = (z - episode.low) / (episode.high - episode.low)
    return np.column_stack([unit[:, 0], 1 - unit[:, 1]]) * (VALUE_PIXELS - 1)


def hull_mesh(points: NDArray[np.float64]) -> tuple[NDArray[np.float64], NDArray[np.int64]]:
    """The convex hull of `points` (K, 3) as vertices and triangles (indices into them)."""
    from scipy.spatial import ConvexHull

    hull = ConvexHull(points)
    return points, np.asarray(hull.simplices, dtype=np.int64)


def _log_static(rec: Any, episode: Any) -> None:
    """What does not move: obstacles, floor, target, the value map and the demos on it (a
    2-D latent space's, `Recorded.value_map`)."""
    import rerun as rr

    from latentrl.render import _corners

    rec.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    if episode.scene is not None:
        config = episode.scene.config
        boxes = [_corners(box) for box in config["obstacles"]]
        if boxes:
            rec.log("world/obstacles", rr.Boxes3D(mins=[lo for lo, _ in boxes], sizes=[hi - lo for lo, hi in boxes],
                                                  colors=[150, 150, 150], fill_mode="solid"), static=True)
        if config["floor"] is not None:
            rec.log("world/floor", rr.Boxes3D(centers=[[0, 0, config["floor"]["height"] - 0.005]],
                                              half_sizes=[[1, 1, 0.005]], colors=[90, 90, 90]), static=True)
        target = episode.scene.target
    else:
        toy = episode.toy
        centre = [*toy["obstacle_centre"], 0.0]
        rec.log("world/obstacles", rr.Ellipsoids3D(centers=[centre], half_sizes=[[toy["obstacle_radius"]] * 3],
                                                   colors=[150, 150, 150], fill_mode="solid"), static=True)
        target = np.column_stack([np.asarray(toy["target"]).reshape(2, 2), np.zeros(2)])
    rec.log("world/target", rr.Points3D(target, colors=[0, 160, 0], radii=0.01), static=True)
    if not episode.value_map:
        return
    rec.log("latent/value", rr.Image(value_image(episode)), static=True)
    rec.log("latent/demos", rr.Points2D(to_pixels(episode, episode.model.Z_), colors=[255, 255, 255], radii=1.5),
            static=True)


def _log_robot(rec: Any, episode: Any, step: int) -> None:
    """The robot's collision shapes and kinematic tree at `step`."""
    import rerun as rr

    from latentrl.render import shape_world_pose

    scene = episode.scene
    pose_of = dict(zip(scene.link_names, episode.poses[step]))
    solids: dict[str, list[Any]] = {"box": [], "sphere": [], "cylinder": [], "capsule": [], "mesh": []}
    for shape in scene.shapes:
        if shape["kind"] in solids and np.all(np.isfinite(pose_of[shape["link"]])):
            centre, rotation = shape_world_pose(pose_of[shape["link"]], shape)
            size = np.asarray(shape["points"] if shape["kind"] == "mesh" else shape["size"], dtype=np.float64)
            solids[shape["kind"]].append((centre, rotation, size))
    blue = [60, 110, 200]
    hulls = [hull_mesh(rotation.apply(points) + centre) for centre, rotation, points in solids["mesh"]
             if len(points) >= 4]
    if hulls:
        offsets = np.cumsum([0] + [len(v) for v, _ in hulls[:-1]])
        rec.log("world/robot/meshes", rr.Mesh3D(vertex_positions=np.vstack([v for v, _ in hulls]),
                                                triangle_indices=np.vstack([t + o for (_, t), o in zip(hulls, offsets)]),
                                                albedo_factor=blue))
    if solids["box"]:
        c, r, s = zip(*solids["box"])
        rec.log("world/robot/boxes", rr.Boxes3D(centers=c, half_sizes=[x / 2 for x in s],
                                                quaternions=[q.as_quat() for q in r], colors=blue, fill_mode="solid"))
    if solids["sphere"]:
        c, _, s = zip(*solids["sphere"])
        rec.log("world/robot/spheres", rr.Ellipsoids3D(centers=c, half_sizes=[[x[0]] * 3 for x in s], colors=blue,
                                                       fill_mode="solid"))
    if solids["cylinder"]:
        c, r, s = zip(*solids["cylinder"])
        rec.log("world/robot/cylinders", rr.Cylinders3D(centers=c, radii=[x[0] for x in s], lengths=[x[1] for x in s],
                                                        quaternions=[q.as_quat() for q in r], colors=blue))
    if solids["capsule"]:
        c, r, s = zip(*solids["capsule"])
        # Rerun's capsule runs from its translation along +z; ours is centred on its origin.
        starts = [centre - rot.apply([0, 0, size[1] / 2]) for centre, rot, size in solids["capsule"]]
        rec.log("world/robot/capsules", rr.Capsules3D(translations=starts, radii=[x[0] for x in s],
                                                      lengths=[x[1] for x in s], quaternions=[q.as_quat() for q in r],
                                                      colors=blue))
    finite = {name: pose[:3] for name, pose in pose_of.items() if np.all(np.isfinite(pose))}
    sticks = [[finite[a], finite[b]] for a, b in scene.edges if a in finite and b in finite]
    rec.log("world/robot/tree", rr.LineStrips3D(sticks, colors=[30, 60, 140]))


def write_rerun(episode: Any, out: Path) -> None:
    """Writes the recorded `episode` (a `replay.Recorded`) to the Rerun file `out` through a
    temporary file, so a failed or interrupted write leaves nothing half-written."""
    import rerun as rr

    rec = rr.RecordingStream("latentrl")
    with atomic_path(out) as temp:
        rec.save(temp)
        _log_static(rec, episode)
        latent = to_pixels(episode, episode.latent) if episode.value_map else episode.latent
        for step in range(len(episode.latent)):
            rec.set_time("step", sequence=step)
            if episode.poses is not None:
                _log_robot(rec, episode, step)
            else:
                rec.log("world/robot/hands", rr.LineStrips3D([episode.effectors[step]], colors=[60, 110, 200]))
            for k in range(episode.effectors.shape[1]):
                rec.log(f"world/effectors/{k}", rr.LineStrips3D([episode.effectors[: step + 1, k]], colors=[220, 90, 40]))
            if episode.value_map:
                rec.log("latent/path", rr.LineStrips2D([latent[: step + 1]], colors=[255, 255, 255]))
                rec.log("latent/point", rr.Points2D(latent[step : step + 1], colors=[255, 0, 0], radii=3))
        rec.flush()
        rec.disconnect()
