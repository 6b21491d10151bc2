"""What a physics step of the humanoid costs along the paths the RL loop drives and through the
task's own plant, against the accuracy bench's kind of path (issue #20: where an Exp 3 RL step's
time goes beyond bench_accuracy's per-simulated-second figure).

    .venv/bin/python benches/bench_rl_paths.py [--out benches/results/bench_rl_paths.json]

The `humanoid_lift` task's robot, servo and physics, one thread, CPU time of the step calls per
physics step. Paths, 120 RL steps per episode:
- `squats`: from the home posture, demos 6, 5, 6, 4 in turn, each held 20 RL steps (the kind of
  path bench_accuracy times);
- `random`: from a random demo, the targets move to another random demo every RL step, as the
  learner's change every RL step.
Plants: `sim` (`_native.Sim` as bench_sim builds it: robot and floor only), `task` (`Task.plant`: the Exp 3 plant with
its obstacle block and end rules, stepped on after a rule fires), `task_no_block` (the same
without the block). The cases are interleaved over ROUNDS rounds of EPISODES episodes and the
median of the rounds is reported: on a 2-core VM single runs of a few seconds vary by ±15 %.
"""

from __future__ import annotations

import argparse
import statistics
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from bench_sim import RapierRobot
from latentrl import Task
from latentrl.envs import shipped_demos
from latentrl.results import environment, write_json

ROUNDS, EPISODES, STEPS = 8, 8, 120

Path_ = Callable[[np.ndarray, np.random.Generator], tuple[np.ndarray, list[np.ndarray]]]


def squats(demos: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, list[np.ndarray]]:
    order = demos[[6, 5, 6, 4]]
    return np.zeros(demos.shape[1]), [order[(k // 20) % 4] for k in range(STEPS)]


def random(demos: np.ndarray, rng: np.random.Generator) -> tuple[np.ndarray, list[np.ndarray]]:
    picks = rng.integers(len(demos), size=STEPS + 1)
    return demos[picks[0]], [demos[i] for i in picks[1:]]


class SimPlant:
    """bench_sim's `RapierRobot` with the task's robot, servo and physics, driven like a plant."""

    def __init__(self, task: Task) -> None:
        t = task.to_dict()
        physics = t["physics"]
        self.robot = RapierRobot(task.urdf_path, floating=True, gains=t["servo"],
                                 iterations=physics["solver_iterations"], pgs_iterations=physics["pgs_iterations"],
                                 floor=0.0, sole="l_foot", dt=physics["dt"], substeps=physics["substeps"])
        self.substeps = physics["substeps"]
        self.reset = self.robot.reset

    def step(self, target: np.ndarray) -> None:
        self.robot.set_targets(target)
        self.robot.step(self.substeps)


def round_cost(make: Callable[[], Any], path: Path_, seed: int, substeps: int) -> float:
    """µs of CPU per physics step over EPISODES episodes of `path` from a fresh plant."""
    demos = shipped_demos("humanoid_lift")
    plant, rng = make(), np.random.default_rng(seed)
    spent = 0.0
    for _ in range(EPISODES):
        start, targets = path(demos, rng)
        plant.reset(np.ascontiguousarray(start))
        for target in targets:
            target = np.ascontiguousarray(target)
            c0 = time.thread_time()
            plant.step(target)
            spent += time.thread_time() - c0
    return 1e6 * spent / (EPISODES * STEPS * substeps)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path(__file__).parent / "results" / "bench_rl_paths.json")
    args = parser.parse_args()
    task = Task.shipped("humanoid_lift")
    demos = shipped_demos("humanoid_lift")
    substeps = task.to_dict()["physics"]["substeps"]
    no_block = task.replace({"obstacles": []})
    plants = {"sim": lambda: SimPlant(task), "task": lambda: task.plant(demos),
              "task_no_block": lambda: no_block.plant(demos)}
    cases = {(p, q): [] for p in plants for q in ("squats", "random")}
    paths = {"squats": squats, "random": random}
    for r in range(ROUNDS):
        for (p, q), costs in cases.items():
            costs.append(round_cost(plants[p], paths[q], r, substeps))
    out = {}
    for (p, q), costs in cases.items():
        out[f"{p}/{q}"] = {"us_per_physics_step_median": statistics.median(costs),
                           "us_per_physics_step_rounds": costs}
        print(f"{p:14s} {q:7s} median {statistics.median(costs):6.1f} µs per physics step "
              f"(rounds {min(costs):.1f}–{max(costs):.1f})")
    write_json(args.out, {"bench": "bench_rl_paths", "environment": environment(),
                          "physics": task.to_dict()["physics"], "rounds": ROUNDS, "episodes": EPISODES,
                          "rl_steps": STEPS, "cases": out})
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
