"""The `latentrl` command's argument parser: every subcommand and flag, built from the presets'
fields and the native schema's task keys; a subcommand's flags are added when it is used
(`LazyParser`), so `latentrl --help` imports no experiment, no preset and no SciPy."""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from latentrl import _native
from latentrl.lazy_parser import LazyParser
from latentrl.task import by_path, run_default
from latentrl.train import POLICIES

DESCRIPTION = """The `latentrl` command: run an experiment or a sweep of it (locally or on a Ray cluster), train
a latent policy on a task of your own and roll it out, fit a model to demonstrations, redraw
the figures of a results directory, show versions.

Exit codes: 0 done, 1 bad values, a bad file or a failed run (the message says what), 2 bad
arguments (argparse), 3 `check` found that the task will not learn, 130 interrupted (finished
trials are kept; `--resume` continues). Every output (--out, --rerun) is checked before any
work; the folders missing on its path are made.
"""
"""The description `latentrl --help` starts with."""

DEMOS_HELP = ("demonstrated postures: .csv (header of joint names), .npz or .json; or a recording: a LeRobot dataset "
              "folder, robomimic .hdf5/.h5, a ROS 1 .bag or ROS 2 bag folder (the [lerobot], [hdf5], [rosbag] extras; "
              "docs/demos.md)")

TASK_PREFIX = "task:"
"""Prefix of the argparse destinations of task keys (`task:learner.alpha`)."""


def _add_preset_flags(parser: argparse.ArgumentParser, preset_cls: type, exclude: tuple[str, ...] = ()) -> None:
    """One `--field-name` flag per scalar preset field but `exclude`, its help the field's docstring."""
    from latentrl.experiments.presets import field_docs

    docs = field_docs(preset_cls)
    group = parser.add_argument_group("run options")
    for field in dataclasses.fields(preset_cls):
        kind = type(field.default) if field.default is not dataclasses.MISSING else None
        if kind not in (int, float, str, bool) or field.name in exclude:
            continue
        flag = "--" + field.name.replace("_", "-")
        # argparse %-formats help strings: a literal "%" in a docstring must be doubled.
        help_text = f"{docs.get(field.name, '')} (default: {field.default})".replace("%", "%%")
        if kind is bool:
            group.add_argument(flag, dest=field.name, action=argparse.BooleanOptionalAction, default=None, help=help_text)
        else:
            group.add_argument(flag, dest=field.name, type=kind, default=None, help=help_text)


def _value_parser(kind: str) -> tuple[Callable[[str], Any], list[str] | None]:
    """How a task key's flag reads its value: by the native kind (float, int, str, bool, a
    choice "a | b", "… or none", lists and tables as JSON)."""
    optional = kind.endswith(" or none")
    base = kind.removesuffix(" or none")
    scalar: dict[str, Callable[[str], Any]] = {"float": float, "int": int, "str": str}

    def parse(text: str) -> Any:
        if optional and text.lower() in ("none", "null"):
            return None
        if base in scalar:
            return scalar[base](text)
        if base == "bool":
            if text.lower() not in ("true", "false"):
                raise argparse.ArgumentTypeError(f"expected true or false, got {text!r}")
            return text.lower() == "true"
        if "|" in base:
            return text
        try:
            return json.loads(text)
        except json.JSONDecodeError as err:
            raise argparse.ArgumentTypeError(f"expected {kind} as JSON, e.g. [0.1, 0.0, 0.0]: {err}") from err

    parse.__name__ = kind  # argparse names the type in its errors
    choices = [c.strip() for c in base.split("|")] if "|" in base else None
    return parse, choices


def _add_task_flags(
    parser: argparse.ArgumentParser, schema: Sequence[dict[str, Any]], task: dict[str, Any] | None = None
) -> None:
    """One `--table.key` flag per key of a task table (the native schema: one name, doc, rule and
    default per parameter), grouped by table; the default shown is `task`'s value where given (an
    experiment's task file), else the schema's. The `[run]` keys are the preset's fields
    (`--trials`, `--encoder`, …)."""
    groups: dict[str, Any] = {}
    for entry in schema:
        key = entry["key"]
        if not by_path(entry) or entry["kind"].startswith("table") or key.startswith("run."):
            continue
        table, _, name = key.rpartition(".")
        group = groups.setdefault(table, parser.add_argument_group(f"[{table}] (task keys)"))
        parse, choices = _value_parser(entry["kind"])
        rule = "" if entry["rule"] == "any value" else f"; {entry['rule']}"
        default = entry["default"]
        if task is not None:
            node: Any = task
            for part in key.split("."):
                node = node.get(part) if isinstance(node, dict) else None
            default = node if node is not None or table not in task else default
        help_text = f"{entry['doc']} ({entry['kind']}{rule}; default: {default})".replace("%", "%%")
        group.add_argument(f"--{table}.{name.replace('_', '-')}", dest=TASK_PREFIX + key, type=parse,
                           choices=choices, default=None, metavar=entry["kind"].upper().split()[0], help=help_text)


def _path(text: str) -> Path:
    """A path argument; an empty one (an unset shell variable) is refused, not taken as "."."""
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path (an unset variable?)")
    return Path(text)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand and flag; a subcommand's flags are added when it
    is used (`LazyParser`), so `latentrl --help` imports no experiment or its preset."""
    parser = argparse.ArgumentParser(prog="latentrl", description=DESCRIPTION)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=LazyParser)
    sub.add_parser("run", help="run an experiment and write its results directory", fill=_run_flags)
    sub.add_parser("train", help="train a latent policy on a task file from demonstrations; writes DIR/policy.npz",
                   fill=_train_flags)
    sub.add_parser("check", help="before training: will the task learn from these demos? (exit 3 if not)",
                   fill=_check_flags)
    sub.add_parser("report", help="the verdict on a trained policy: learnt, still or stopped improving below "
                                  "the target, or never reached it, with what to try next", fill=_report_flags)
    sub.add_parser("rollout", help="run a trained policy frozen (greedy, soft-max, and the random control from "
                                   "the same starts) and write OUT/rollout.json", fill=_rollout_flags)
    sub.add_parser("fit", help="fit a PCA or GPLVM to a demonstration file and save it (NPZ)", fill=_fit_flags)
    sub.add_parser("plot", help="redraw the figures of a results directory (finished trials only)", fill=_plot_flags)
    sub.add_parser("sweep", help="run an RL experiment over a grid of preset values, here or on a Ray cluster",
                   fill=_sweep_flags)
    sub.add_parser("info", help="print versions, git revision and thread count as JSON")
    sub.add_parser("replay", help="render a recorded episode of an Exp 1, Exp 2, Exp 3 or latentrl train run to a GIF or MP4 (the [video] extra) or a Rerun recording (the [viewer] extra)",
                   fill=_replay_flags)
    sub.add_parser("urdf-info", help="what a URDF holds as the physics loads it: joints, links, collision shapes, mass",
                   fill=_urdf_info_flags)
    return parser


def _run_flags(run: argparse.ArgumentParser) -> None:
    """`run`'s subcommands, one per experiment (each adding its flags when used)."""
    from latentrl.experiments import experiments

    run_sub = run.add_subparsers(dest="experiment", required=True)
    for name, exp in experiments().items():
        run_sub.add_parser(name, help=(exp.preset.__doc__ or "").strip().splitlines()[0],
                           fill=functools.partial(_experiment_flags, name))


def _experiment_flags(name: str, cmd: argparse.ArgumentParser) -> None:
    """`run NAME`'s flags: its preset's fields and, for an RL experiment, its task's keys (the
    defaults shown: its task file's)."""
    from latentrl.experiments import experiments, task_schema

    exp = experiments()[name]
    cmd.add_argument("--out", type=_path, help=f"results directory (default: results/{name})")
    cmd.add_argument("--quick", action="store_true", help="the small smoke-test preset")
    if exp.rl:
        cmd.add_argument(
            "--resume", type=_path, metavar="DIR",
            help="continue the interrupted run in DIR with its own preset (no other preset flags)",
        )
    cmd.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
    _add_preset_flags(cmd, exp.preset)
    if exp.rl:
        _add_task_flags(cmd, task_schema(name), exp.rl.task(exp.preset()))


def _train_flags(train: argparse.ArgumentParser) -> None:
    train.add_argument("--out", type=_path, required=True, help="results directory (results.json, returns.npz, policy.npz)")
    train.add_argument("--resume", action="store_true", help="continue the interrupted run in --out (same arguments)")
    _add_training_flags(train, "a short run (TrainPreset.quick)")


def _check_flags(check: argparse.ArgumentParser) -> None:
    check.add_argument("--json", action="store_true", help="print the findings as JSON instead of a table")
    _add_training_flags(check, "cost the short run (TrainPreset.quick) instead of the default")


def _report_flags(report: argparse.ArgumentParser) -> None:
    report.add_argument("results", type=_path, help="a directory of `latentrl train` (with policy.npz)")
    report.add_argument("--json", action="store_true", help="print it as JSON")


def _rollout_flags(rollout: argparse.ArgumentParser) -> None:
    rollout.add_argument("results", type=_path, help="a directory of `latentrl train` (with policy.npz), or a policy.npz")
    rollout.add_argument("--out", type=_path, required=True, help="where to write rollout.json and rollout.npz (a folder of its own, e.g. RUN/rollout)")
    rollout.add_argument("--episodes", type=int, default=20, help="episodes per trial and policy (default: 20)")
    rollout.add_argument("--trial", type=int, help="only this trial's policy (default: every trial)")
    rollout.add_argument("--seed", type=int, default=0, help="base seed of the starts and draws (default: 0)")
    rollout.add_argument("--starts", choices=("test", "train"), default="test",
                         help="test: where the task's frozen tests start (episode.test_start); train: as its training "
                              "episodes (default: test)")
    rollout.add_argument("--policy", type=_policies, default=list(POLICIES), metavar="P[,P…]",
                         help="which of greedy, softmax (the learner's soft-max, as the frozen tests draw) and random "
                              "(the control: uniform moves, cannot learn) to run (default: all three)")
    rollout.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")


def _fit_flags(fit: argparse.ArgumentParser) -> None:
    from latentrl.recorded.options import DemoOptions

    fit.add_argument("demos", type=_path, help=DEMOS_HELP)
    fit.add_argument("--model", choices=("gplvm", "pca"), default="gplvm", help="the model (default: gplvm)")
    fit.add_argument("--n-components", type=_dimension, default=2,
                     help="latent dimension d, or auto (GPLVM: chosen by ARD relevance, docs/encoders.md; default: 2)")
    seed, max_iter = run_default("seed"), run_default("gplvm_max_iter")  # the [run] table's
    fit.add_argument("--seed", type=int, default=seed, help=f"random_state of the GPLVM (default: {seed})")
    fit.add_argument("--max-iter", type=int, default=max_iter, help=f"L-BFGS iteration cap of the GPLVM (default: {max_iter})")
    fit.add_argument("--inducing", type=int, metavar="M", help="fit the sparse GPLVM through M inducing inputs, "
                     "for many postures (docs/method.md#sparse-gplvm; default: the exact GPLVM, at most 16384 postures)")
    fit.add_argument("--spacing", choices=("fit", "even"), default="fit",
                     help="GPLVM latent points as fitted, or evenly spaced along each axis (docs/encoders.md#latent-spacing; "
                          "default: fit; `latentrl train` fits with even)")
    fit.add_argument("--out", type=_path, required=True, help="the model file to write (.npz; load with GPLVM.load)")
    _add_preset_flags(fit, DemoOptions)


def _plot_flags(plot: argparse.ArgumentParser) -> None:
    plot.add_argument("results", type=_path, help="a results directory of `latentrl run exp1|exp2|exp3` or `latentrl train`")
    plot.add_argument("--out", type=_path, help="where to write the figures (default: the results directory)")


def _sweep_flags(sweep: argparse.ArgumentParser) -> None:
    sweep.add_argument("file", type=_path, help="the sweep: a .toml file (or .yaml with PyYAML); see examples/sweep.toml")
    sweep.add_argument("--backend", choices=("local", "ray"), default="local",
                       help="local: trials in this process (rayon); ray: one Ray task per trial (default: local)")
    sweep.add_argument("--address", metavar="ADDR",
                       help="with --backend ray: 'auto' (the cluster `ray start --head` runs here), HOST:6379, or "
                            "ray://HOST:10001 (Ray Client); default: a local Ray instance")
    sweep.add_argument("--batch", type=int, default=1, help="with --backend ray: trials per Ray task (default: 1)")
    sweep.add_argument("--out", type=_path, help="sweep directory (default: results/<FILE's name>)")
    sweep.add_argument("--resume", action="store_true", help="continue the sweep in --out; finished trials are kept")
    sweep.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")


def _replay_flags(replay: argparse.ArgumentParser) -> None:
    from latentrl.render import CAMERA, VIEWS

    replay.add_argument("results", type=_path, help="a results directory of latentrl run exp1|exp2|exp3, latentrl train "
                                                     "or latentrl rollout")
    replay.add_argument("--out", type=_path, help="the video: FILE.gif or FILE.mp4")
    replay.add_argument("--rerun", type=_path, help="a Rerun recording FILE.rrd (view it with `rerun FILE.rrd`)")
    which = replay.add_mutually_exclusive_group(required=True)
    which.add_argument("--episode", type=int, help="a recorded training episode (the first, 10 %%, 50 %% and the last three)")
    which.add_argument("--test", type=int, help="a recorded frozen test episode (the first ten)")
    replay.add_argument("--trial", type=int, default=0, help="the trial (default 0)")
    replay.add_argument("--fps", type=int, default=20, help="frames per second (default 20)")
    replay.add_argument("--width", type=int, default=960, help="frame width in pixels, height half of it (default 960)")
    replay.add_argument("--max-frames", type=int, default=400, help="at most this many frames, evenly spaced over the episode (default 400)")
    replay.add_argument("--policy", choices=POLICIES, default="greedy",
                        help="of a rollout directory: which policy's episode (default: greedy)")
    replay.add_argument("--view", choices=tuple(VIEWS),
                        help="the robot seen from the top (x-y), the side (x-z), the front (y-z) or in 3d (perspective, "
                             f"elevation {CAMERA[0]:g}°, azimuth {CAMERA[1]:g}°); default: the side of a floating robot, "
                             "else the plane its links and target spread over most")


def _urdf_info_flags(urdf: argparse.ArgumentParser) -> None:
    urdf.add_argument("urdf", type=_path, help="the robot's URDF file")
    urdf.add_argument("--json", action="store_true", help="print it as JSON instead of a table")
    urdf.add_argument("--balance-inertia", action="store_true",
                      help="repair inertias the physics refuses (triangle inequality, all zero), naming each link")


def _add_training_flags(cmd: argparse.ArgumentParser, quick: str) -> None:
    """What `train` and `check` share: the task file, the demos, a saved model, --quick, the
    preset fields and every task key as flags (defaults: the task file's, else the schema's)."""
    from latentrl.experiments.training import TrainRun

    cmd.add_argument("task", type=_path, help="the task file (TOML; docs/tasks.md)")
    cmd.add_argument("--demos", type=_path, required=True, help=DEMOS_HELP)
    cmd.add_argument("--model", type=_path, help="a saved GPLVM (`latentrl fit`) instead of fitting one (d = 2); fitted to the task's joints in its order")
    cmd.add_argument("--quick", action="store_true", help=quick)
    cmd.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
    _add_preset_flags(cmd, TrainRun, exclude=("task_file", "demos", "model"))
    _add_task_flags(cmd, _native.task_schema())


def _dimension(text: str) -> int | str:
    """`--n-components`: an integer, or "auto"."""
    if text == "auto":
        return text
    try:
        return int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer or auto, got {text!r}") from None


def _policies(text: str) -> list[str]:
    """`--policy`: a comma-separated subset of `POLICIES`, in their order."""
    chosen = [p.strip() for p in text.split(",") if p.strip()]
    unknown = [p for p in chosen if p not in POLICIES]
    if unknown or not chosen:
        raise argparse.ArgumentTypeError(f"expected some of {', '.join(POLICIES)}, got {text!r}")
    return [p for p in POLICIES if p in chosen]
