"""Experiment 3 (paper Sec. IV-C, Fig. 7b–e and 8): the 19-DoF KHR-1HV-like humanoid lifts an
object with both hands, learning in the GPLVM latent space of its lift demonstrations
through a physics simulation (rapier3d, floor, gravity, servo PD).

The task is the shipped task file `latentrl/tasks/humanoid_lift.toml`: reward
`exp(−0.35 ‖(h − h*)/0.1 m‖²)` over both hands, h* the hands of the demo holding them highest
(the top of the squat), measured from the left sole so that it moves with the feet; −1 and the episode ends on a fall, a drop (| ‖h_R − h_L‖ − 0.10 | >
0.02 m) or a contact with the block in front of the robot that the straight-arm lift (upper body
bent over it) touches and the squat lift clears. The GPLVM (d = 2, back-constrained) is fitted
to the shipped lift demos: the paper's 7 (4 straight-arm hip-hinge poses, 3 knee-squat poses)
plus 2 floor-level squats and 5 poses between the styles (docs/exp3.md says why).

Figures: Fig. 7e (return per episode, mean ± s.d. over trials), 7b/7c (value function before
and after learning over the latent box, GPLVM variance shaded, the obstacle, falls at rest
and drops mapped into latent space), 7d (hand paths in the side view x–z with the obstacle),
Fig. 8 (frames of a learnt lift, drawn from the recorded postures by the native kinematics).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from latentrl import _native
from latentrl.envs import shipped_demos
from latentrl.experiments.latent_runs import Fitted, latent_setup, run_fit
from latentrl.run_settings import LatentRun, check_ints
from latentrl.experiments.runner import Setup
from latentrl.task import Task

if TYPE_CHECKING:  # matplotlib (the [plot] extra) is imported when a figure is drawn
    from matplotlib.axes import Axes


FLOOR_LEVEL = 0.10
"""Hands at most this high above the floor (m) start a lift "from the floor" (issue #18's
frozen-test goal counts these starts; `FLOOR_TESTS` draws starts strictly below it)."""

FLOOR_TESTS = {"waypoint.axis": "z", "waypoint.below": FLOOR_LEVEL, "waypoint.above": FLOOR_LEVEL,
               "episode.test_start": "below_waypoint"}
"""Task keys that start every frozen test episode with both hands below `FLOOR_LEVEL`."""


def demos_path(heel: bool = False) -> Path:
    """Path of the paper's 7 lift demos: centred balance, or the heel-side set of the fall check
    (Exp 3 learns on `envs.shipped_demos("humanoid_lift")`, these 7 and 7 more)."""
    name = "khr1hv_lift_demos_heel.csv" if heel else "khr1hv_lift_demos.csv"
    return Path(str(resources.files("latentrl") / "data" / name))


@dataclass(frozen=True)
class Exp3Preset(LatentRun):
    """Exp 3: the KHR-1HV-like humanoid lifts an object, latent-space TD(0) through physics (Fig. 7, 8)."""

    trials: int = 4
    """Independent RL trials (paper: "several"; ours: 4, which fill 2 cores in two rounds)."""
    episodes: int = 6000
    """Training episodes per trial (paper: about 6000)."""
    test_episodes: int = 250
    """Frozen test episodes per trial after training (no TD updates; ours: 250, so that the
    ≈ 6 % of uniform starts with the hands at floor level number ≥ 40 over 4 trials; Fig. 7d
    and 8 draw 10 more from floor-level starts, `floor_level_tests`)."""
    curve_window: int = 500
    """Running-mean window of Fig. 7e (at most episodes // 5 for short runs)."""
    encoder: str = "back_constrained"
    """Posture → latent map of the RL loop (ours: the back-constrained GPLVM, whose encoding of
    a decoded point returns it; the paper's out-of-sample GP drifts into the floor-level band,
    docs/exp3.md)."""
    map_grid: int = 50
    """Grid points per latent dimension where Fig. 7b/7c test the decoded postures at rest for
    obstacle contact, falls and drops in the sim (ours)."""

    def validate(self) -> None:
        """ValueError naming the first impossible field or task key (the task's own rules)."""
        self.check_run()
        check_ints(self, ("curve_window", "map_grid"))
        task_of(self)

    @classmethod
    def quick(cls) -> Exp3Preset:
        """The default test suite's run: 2 trials × 300 episodes × 100 steps, w₀ = 100
        (optimistic), step 0.5 × spacing, 20 frozen test episodes per trial that all start
        with both hands at floor level (≤ 0.10 m: a waypoint on z below which
        `episode.test_start` draws), a 20 × 20 map in Fig. 7b/7c (≈ 1.5 min on 2 cores)."""
        return dataclasses.replace(
            cls(), trials=2, episodes=300, test_episodes=20, map_grid=20,
            task={"episode.max_steps": 100, "learner.initial_weight": 100.0, "learner.step": 0.5,
                  **FLOOR_TESTS},
        )


def task_of(preset: Exp3Preset) -> Task:
    """The shipped humanoid lift task with the preset's overrides (checked by the task's rules)."""
    return Task.shipped("humanoid_lift").replace(preset.task)


def fit(preset: Exp3Preset, run: Path | None = None) -> Fitted:
    """Demos, GPLVM and latent box; the saved ones of the run in directory `run`
    (`latent_runs.run_fit`). Fits are cached on the fields they depend on."""
    return run_fit(run, preset.latent_margin,
                   lambda: _fit(preset.seed, preset.gplvm_max_iter, preset.latent_margin, preset.encoder,
                                preset.latent_spacing))


@lru_cache(maxsize=4)
def _fit(seed: int, max_iter: int, margin: float, encoder: str, spacing: str) -> Fitted:
    demos = shipped_demos("humanoid_lift")
    return Fitted.of(demos, seed=seed, max_iter=max_iter, margin=margin, encoder=encoder, spacing=spacing)


def setup(preset: Exp3Preset, run: Path | None = None) -> Setup:
    """The humanoid lift task, the GPLVM on the lift demos (the run's in directory `run`), its
    latent box and the learner."""
    task = task_of(preset)
    fitted = fit(preset, run)
    return latent_setup(preset, task, fitted.model, (fitted.low, fitted.high), fitted.demos)


def floor_level_tests(preset: Exp3Preset, weights: NDArray[np.float64], run: Path | None = None,
                      episodes: int = 10) -> dict[str, Any]:
    """`episodes` frozen test episodes (the soft-max on the frozen V, no TD updates) of the learnt value `weights`
    from starts with both hands at floor level, all recorded: the native runner's dict
    ("test_trajectories", "test_returns", "test_reached", "test_ends", …). Seeded by the
    preset (after one frozen episode from the training start rule, which the runner needs), in
    the latent space of the run in directory `run`; what Fig. 7d and 8 draw."""
    task = task_of(preset).replace(FLOOR_TESTS)
    fitted = fit(preset, run)
    return _native.run_task_trials(
        task._native, decoder=fitted.model.decoder_, encoder=fitted.model.loop_encoder_, latent_low=fitted.low,
        latent_high=fitted.high, demos=fitted.demos, n_trials=1, episodes=1, base_seed=preset.seed,
        weights=np.asarray(weights, dtype=np.float64).reshape(1, -1), rollout="greedy", test_episodes=episodes,
        record_test_episodes=list(range(episodes)),
    )


STYLES = {"straight-arm": (0, 1, 2, 3), "squat": (4, 5, 6, 7, 8), "between": (9, 10, 11, 12, 13)}
"""The lift styles of the shipped demos (rows of `khr1hv_lift_demos_bridged.csv`): the paper's
straight-arm hip hinge (0–3) and knee squat (4–6) with the two floor-level squats (7, 8), and
the poses between the styles (9–13)."""


def episode_styles(mean_states: NDArray[np.float64], demo_latent: NDArray[np.float64]) -> NDArray[np.int64]:
    """The style of each episode (index into `STYLES`, −1 where not run): the style of the demo
    whose latent point lies nearest the episode's mean latent state (`latent_mean_state`),
    i.e. the side of the latent space the episode spent its steps on."""
    group = np.empty(len(demo_latent), dtype=np.int64)
    for k, rows in enumerate(STYLES.values()):
        group[list(rows)] = k
    flat = mean_states.reshape(-1, mean_states.shape[-1])
    nearest = np.argmin(((flat[:, None, :] - demo_latent[None]) ** 2).sum(-1), axis=1)
    out = np.where(np.isfinite(flat).all(axis=1), group[nearest], -1)
    return out.reshape(mean_states.shape[:-1])


# --- figures ----------------------------------------------------------------------------------


def figures(preset: Exp3Preset, arrays: Mapping[str, np.ndarray], run: Path, out: Path) -> None:
    """Fig. 7b, 7c, 7d, 7e, 7f (ours: the styles) and 8 of the run in directory `run` into `out`
    (PNG + PDF)."""
    import matplotlib.pyplot as plt

    from latentrl.plots import latent_run_figures, save_figure

    fitted = fit(preset, run)
    task = task_of(preset)
    config = task.to_dict()
    maps: dict[str, Any] = {}
    latent_run_figures(
        preset, arrays, out, names=("fig7e", "fig7b", "fig7c"), title="Exp 3: humanoid lift, mean ± s.d. over trials",
        panel=lambda ax, w: _latent_panel(ax, preset, task, fitted, w, maps),
    )
    _style_counts(preset, arrays, fitted, out)
    floor = floor_level_tests(preset, np.asarray(arrays["latent_weights"])[0], run)
    paths = floor["test_trajectories"][0]
    fig, ax = plt.subplots(figsize=(5, 5))
    _side_view(ax, config)
    plant, rows = task.plant(fitted.demos), task.row_slices()
    base = np.r_[rows["base_position"], rows["base_quaternion"]]
    for k, path in enumerate(paths):
        path = path[np.isfinite(path).all(axis=1)]
        shade = plt.cm.viridis(k / max(len(paths) - 1, 1))
        ax.plot(path[:, 0], path[:, 2], color=shade, lw=1)
        ax.plot(path[:, 3], path[:, 5], color=shade, lw=1, ls="--")
        ax.plot(path[0, 0], path[0, 2], "o", color=shade, ms=3)
        # h* where this episode's start stands it (it moves with `target.relative_to`).
        plant.pose_links(path[0, base], path[0, rows["joints"]])
        h_star = plant.target_position()
        ax.plot(h_star[:, 0], h_star[:, 2], "*", color=shade, mec="r", ms=10)
    reached = int(((floor["test_ends"] == 0) & floor["test_reached"]).sum())
    ax.set(xlim=(-0.05, 0.32), ylim=(-0.01, 0.36), xlabel="x (m, forward)", ylabel="z (m, up)")
    ax.set_aspect("equal")
    ax.set_title(f"hand paths of {len(paths)} frozen lifts from floor-level starts\n(trial 1's policy; "
                 f"{reached} reach h*; dashed: right hand; stars: h*)", fontsize=9)
    save_figure(fig, out, "fig7d")
    _fig8(floor, out, task, fitted.demos)


def _style_counts(preset: Exp3Preset, arrays: Mapping[str, np.ndarray], fitted: Fitted, out: Path) -> None:
    """Fig. 7f (ours): successful training episodes (reached h*, ended by the step limit) per
    window of `curve_window` episodes, summed over the trials and split by the style whose
    demos lie nearest the episode's mean latent state (`exp3.episode_styles`)."""
    import matplotlib.pyplot as plt

    from latentrl.plots import save_figure

    ok = (np.asarray(arrays["latent_end"]) == 0) & np.asarray(arrays["latent_reached"])
    style = episode_styles(np.asarray(arrays["latent_mean_state"]), fitted.model.Z_)
    window = max(1, min(preset.curve_window, preset.episodes // 5))
    edges = np.arange(0, preset.episodes + window, window)[: preset.episodes // window + 1]
    fig, ax = plt.subplots(figsize=(6, 3.5))
    bottom = np.zeros(len(edges) - 1)
    for k, name in enumerate(STYLES):
        counts = np.array([(ok & (style == k))[:, a:b].sum() for a, b in zip(edges[:-1], edges[1:])])
        ax.bar(edges[:-1], counts, width=window, bottom=bottom, align="edge", label=f"{name} ({counts.sum()})")
        bottom += counts
    ax.set(xlabel="episode", ylabel=f"successful episodes per {window}\n(all trials)")
    ax.set_title("Exp 3: the style of each successful training episode\n(demos nearest its mean latent state)",
                 fontsize=9)
    ax.legend(fontsize=8)
    save_figure(fig, out, "fig7f")


def _side_view(ax: Axes, config: Mapping[str, Any], dx: float = 0.0) -> None:
    """The floor and the task's obstacles in the x–z plane."""
    from matplotlib.patches import Rectangle

    for box in config["obstacles"]:
        (cx, _, cz), (hx, _, hz) = box["center"], box["half_extents"]
        ax.add_patch(Rectangle((dx + cx - hx, cz - hz), 2 * hx, 2 * hz, color="0.5", alpha=0.5))
    ax.axhline(0.0, color="0.3", lw=1.5)


def _latent_panel(
    ax: Axes, preset: Exp3Preset, task: Task, fitted: Fitted, weights: NDArray[np.float64] | None, maps: dict[str, Any]
) -> None:
    """`plots.latent_value_panel` on a `map_grid` grid with the decoded postures (clipped to the
    joint limits) that, standing at rest, break a rule of the task (the native plant's
    `classify`): touch the obstacle (black), fall (grey) or break the grip (red); and the target
    region (dashed white: the admissible points of the native survey within 2 reach radii of h*,
    standing). `maps` caches the classification and the survey between the panels."""
    from latentrl.derive import survey_at_step
    from latentrl.plots import latent_value_panel

    config = task.to_dict()

    def regions(ax: Axes, g0: NDArray[np.float64], g1: NDArray[np.float64], postures: NDArray[np.float64]) -> None:
        if "rest" not in maps:
            plant = task.plant(fitted.demos)
            maps["rest"] = plant.classify(np.clip(postures, task.lower, task.upper))[0]
            maps["survey"] = survey_at_step(task, fitted.model, fitted.low, fitted.high, fitted.demos)
        rest, survey = maps["rest"].reshape(g0.shape), maps["survey"]
        for code, colour in ((1, "k"), (4, "0.6"), (3, "tab:red")):
            if (rest == code).any():
                ax.contourf(g0, g1, (rest == code).astype(float), levels=[0.5, 1.5], colors=colour, alpha=0.8)
        near = 2 * config["target"]["reach_radius"]  # a wider ring than success's: standing at rest
        distance = np.where(survey["codes"] == 0, survey["distance"], survey["distance"].max())  # admissible only
        z0, z1 = survey["points"].T
        ax.tricontour(z0, z1, distance, levels=[near], colors="w", linestyles="--", linewidths=1)

    latent_value_panel(ax, weights, fitted.low, fitted.high, fitted.model, learner=config["learner"], regions=regions,
                       grid=preset.map_grid)
    for i, (z0, z1) in enumerate(fitted.model.Z_):
        ax.annotate(str(i), (z0, z1), color="w", fontsize=7, xytext=(3, 3), textcoords="offset points")


def _fig8(floor: Mapping[str, Any], out: Path, task: Task, demos: NDArray[np.float64], frames: int = 6) -> None:
    """Frames of a learnt lift from the floor: of the floor-level frozen tests (`floor`) that
    reached h* without an ending (all, if none did), the one whose hands rose most; frames from
    its start to where the hands are 95 % of the way up, and its last step. Side view, drawn
    from the recorded base poses and joint angles by the native kinematics
    (`TaskPlant.pose_links`)."""
    import matplotlib.pyplot as plt

    from latentrl.plots import link_positions, save_figure, side_view_stick

    fig, ax = plt.subplots(figsize=(10, 3))
    paths = floor["test_trajectories"][0]
    returns, ok = floor["test_returns"][0], (floor["test_ends"][0] == 0) & floor["test_reached"][0]
    heights = [_hand_height(path) for path in paths]
    rise = np.array([z.max() - z[0] for z in heights])
    candidates = np.flatnonzero(ok) if ok.any() else np.arange(len(paths))
    best = int(candidates[np.argmax(rise[candidates])])
    path = paths[best][np.isfinite(paths[best]).all(axis=1)]
    z = heights[best]
    top = int(np.argmax(z >= z[0] + 0.95 * rise[best]))
    picks = np.unique(np.r_[np.linspace(0, top, frames - 1).round().astype(int), len(path) - 1])
    plant, rows, config = task.plant(demos), task.row_slices(), task.to_dict()
    base = np.r_[rows["base_position"], rows["base_quaternion"]]
    for k, step in enumerate(picks):
        dx = 0.35 * k
        poses = plant.pose_links(path[step, base], path[step, rows["joints"]])
        _side_view(ax, config, dx)
        side_view_stick(ax, task.edges, link_positions(task.link_names, poses), "C0", dx)
        ax.text(dx + 0.05, 0.33, f"step {step}", fontsize=8, ha="center")
    outcome = "reached h*" if ok[best] else "did not reach h*"
    ax.set_title(f"a learnt lift from the floor: frozen test {best} of trial 1's policy ({outcome}, return "
                 f"{returns[best]:.1f}, hands {1e3 * z[0]:.0f} → {1e3 * z.max():.0f} mm)")
    ax.axhline(0.0, color="0.3", lw=1.5)
    ax.set_aspect("equal")
    ax.set(xlabel="x (m; frames 0.35 m apart)", ylabel="z (m)", ylim=(-0.01, 0.36))
    save_figure(fig, out, "fig8")


def _hand_height(path: NDArray[np.float64]) -> NDArray[np.float64]:
    """Mean height of both hands at every recorded step of a trajectory (NaN rows dropped)."""
    path = path[np.isfinite(path).all(axis=1)]
    return (path[:, 2] + path[:, 5]) / 2
