"""The `latentrl` command: run an experiment or a sweep of it (locally or on a Ray cluster), train
a latent policy on a task of your own and roll it out, fit a model to demonstrations, redraw
the figures of a results directory, show versions.

Exit codes: 0 done, 1 bad values, a bad file or a failed run (the message says what), 2 bad
arguments (argparse), 3 `check` found that the task will not learn, 130 interrupted (finished
trials are kept; `--resume` continues).
"""

from __future__ import annotations

import argparse
import dataclasses
import functools
import json
import os
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from latentrl import _native
from latentrl.experiments.presets import field_docs
from latentrl.run_settings import with_overrides, with_task_run
from latentrl.lazy_parser import LazyParser
from latentrl.run_lock import run_lock
from latentrl.task import by_path, changed_since, run_default
from latentrl.train import POLICIES, format_rollout

DEMOS_HELP = ("demonstrated postures: .csv (header of joint names), .npz or .json; or a recording: a LeRobot dataset "
              "folder, robomimic .hdf5/.h5, a ROS 1 .bag or ROS 2 bag folder (the [lerobot], [hdf5], [rosbag] extras; "
              "docs/demos.md)")

TASK_PREFIX = "task:"
"""Prefix of the argparse destinations of task keys (`task:learner.alpha`)."""


def saved_run(out_dir: Path, *, train: bool = False) -> tuple[str, Any]:
    """(experiment name, preset) of the RL run in `out_dir`, from its results.json — with `train`,
    also ("train", its TrainRun) for a `latentrl train` directory; ValueError if the directory
    holds none, or the preset does not fit this version."""
    from latentrl.experiments import experiments
    from latentrl.experiments.results import RunFolder

    folder = RunFolder(out_dir)
    if not folder.results_path.is_file():
        raise ValueError(f"{out_dir}: no results.json there, so no run of an RL experiment")
    fields = folder.preset()
    preset_name = fields.pop("name", None)
    known = [(name, exp.preset) for name, exp in experiments().items() if exp.rl]
    if train:
        from latentrl.experiments.training import TrainRun

        known.append(("train", TrainRun))
    found = [(name, cls) for name, cls in known if cls.__name__ == preset_name]
    if not found:
        raise ValueError(f"{out_dir}: results.json names no RL experiment's preset (found {preset_name!r})")
    name, preset_cls = found[0]
    unknown = sorted(set(fields) - {f.name for f in dataclasses.fields(preset_cls)})
    if unknown:
        raise ValueError(f"{out_dir}: its preset has fields this version does not know: {unknown}")
    preset = preset_cls(**fields)
    recorded = folder.recorded_task()
    if name == "train" or recorded is None:
        return name, preset
    return name, _as_recorded(out_dir, name, preset, recorded)


def _as_recorded(out_dir: Path, name: str, preset: Any, recorded: dict[str, Any]) -> Any:
    """`preset` with a task override for every key it does not set whose recorded value this
    version's task does not give (a shipped task file changed since the run): its figures, replays and resume
    use the task its trials ran with. A key added since the run takes its default, the
    behaviour before it. A key no override can set is a ValueError."""
    from latentrl.experiments import experiments, task_schema

    rl = experiments()[name].rl
    assert rl is not None
    changed = {k: v for k, v in changed_since(recorded, rl.task(preset)).items() if k not in preset.task}
    settable = {e["key"] for e in task_schema(name) if by_path(e)}
    fixed = sorted(set(changed) - settable)
    if fixed:
        raise ValueError(f"{out_dir}: its trials ran with a task this version cannot rebuild ({', '.join(fixed)} "
                         "differ and no override sets them); use the latentrl version that made it")
    return dataclasses.replace(preset, task={**preset.task, **changed}) if changed else preset


def _add_preset_flags(parser: argparse.ArgumentParser, preset_cls: type, exclude: tuple[str, ...] = ()) -> None:
    """One `--field-name` flag per scalar preset field but `exclude`, its help the field's docstring."""
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


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand and flag; a subcommand's flags are added when it
    is used (`LazyParser`), so `latentrl --help` imports no experiment or its preset."""
    parser = argparse.ArgumentParser(prog="latentrl", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True, parser_class=LazyParser)
    sub.add_parser("run", help="run an experiment and write its results directory", fill=_run_flags)
    sub.add_parser("train", help="train a latent policy on a task file from demonstrations; writes DIR/policy.npz",
                   fill=_train_flags)
    sub.add_parser("check", help="before training: will the task learn from these demos? (exit 3 if not)",
                   fill=_check_flags)
    sub.add_parser("report", help="the verdict on a trained policy: learnt, stopped improving below the "
                                  "target, or never reached it, with what to try next", fill=_report_flags)
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
    cmd.add_argument("--out", type=Path, help=f"results directory (default: results/{name})")
    cmd.add_argument("--quick", action="store_true", help="the small smoke-test preset")
    if exp.rl:
        cmd.add_argument(
            "--resume", type=Path, metavar="DIR",
            help="continue the interrupted run in DIR with its own preset (no other preset flags)",
        )
    cmd.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
    _add_preset_flags(cmd, exp.preset)
    if exp.rl:
        _add_task_flags(cmd, task_schema(name), exp.rl.task(exp.preset()))


def _train_flags(train: argparse.ArgumentParser) -> None:
    train.add_argument("--out", type=Path, required=True, help="results directory (results.json, returns.npz, policy.npz)")
    train.add_argument("--resume", action="store_true", help="continue the interrupted run in --out (same arguments)")
    _add_training_flags(train, "a short run (TrainPreset.quick)")


def _check_flags(check: argparse.ArgumentParser) -> None:
    check.add_argument("--json", action="store_true", help="print the findings as JSON instead of a table")
    _add_training_flags(check, "cost the short run (TrainPreset.quick) instead of the default")


def _report_flags(report: argparse.ArgumentParser) -> None:
    report.add_argument("results", type=Path, help="a directory of `latentrl train` (with policy.npz)")
    report.add_argument("--json", action="store_true", help="print it as JSON")


def _rollout_flags(rollout: argparse.ArgumentParser) -> None:
    rollout.add_argument("results", type=Path, help="a directory of `latentrl train` (with policy.npz), or a policy.npz")
    rollout.add_argument("--out", type=Path, required=True, help="where to write rollout.json and rollout.npz")
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

    fit.add_argument("demos", type=Path, help=DEMOS_HELP)
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
    fit.add_argument("--out", type=Path, required=True, help="the model file to write (.npz; load with GPLVM.load)")
    _add_preset_flags(fit, DemoOptions)


def _plot_flags(plot: argparse.ArgumentParser) -> None:
    plot.add_argument("results", type=Path, help="a results directory of `latentrl run exp1|exp2|exp3` or `latentrl train`")
    plot.add_argument("--out", type=Path, help="where to write the figures (default: the results directory)")


def _sweep_flags(sweep: argparse.ArgumentParser) -> None:
    sweep.add_argument("file", type=Path, help="the sweep: a .toml file (or .yaml with PyYAML); see examples/sweep.toml")
    sweep.add_argument("--backend", choices=("local", "ray"), default="local",
                       help="local: trials in this process (rayon); ray: one Ray task per trial (default: local)")
    sweep.add_argument("--address", metavar="ADDR",
                       help="with --backend ray: 'auto' (the cluster `ray start --head` runs here), HOST:6379, or "
                            "ray://HOST:10001 (Ray Client); default: a local Ray instance")
    sweep.add_argument("--batch", type=int, default=1, help="with --backend ray: trials per Ray task (default: 1)")
    sweep.add_argument("--out", type=Path, help="sweep directory (default: results/<FILE's name>)")
    sweep.add_argument("--resume", action="store_true", help="continue the sweep in --out; finished trials are kept")
    sweep.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")


def _replay_flags(replay: argparse.ArgumentParser) -> None:
    from latentrl.render import CAMERA, VIEWS

    replay.add_argument("results", type=Path, help="a results directory of latentrl run exp1|exp2|exp3, latentrl train "
                                                     "or latentrl rollout")
    replay.add_argument("--out", type=Path, help="the video: FILE.gif or FILE.mp4")
    replay.add_argument("--rerun", type=Path, help="a Rerun recording FILE.rrd (view it with `rerun FILE.rrd`)")
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
    urdf.add_argument("urdf", type=Path, help="the robot's URDF file")
    urdf.add_argument("--json", action="store_true", help="print it as JSON instead of a table")
    urdf.add_argument("--balance-inertia", action="store_true",
                      help="repair inertias the physics refuses (triangle inequality, all zero), naming each link")


def _add_training_flags(cmd: argparse.ArgumentParser, quick: str) -> None:
    """What `train` and `check` share: the task file, the demos, a saved model, --quick, the
    preset fields and every task key as flags (defaults: the task file's, else the schema's)."""
    from latentrl.experiments.training import TrainRun

    cmd.add_argument("task", type=Path, help="the task file (TOML; docs/tasks.md)")
    cmd.add_argument("--demos", type=Path, required=True, help=DEMOS_HELP)
    cmd.add_argument("--model", type=Path, help="a saved GPLVM (`latentrl fit`) instead of fitting one (d = 2)")
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


def _overrides(args: argparse.Namespace, preset_cls: type) -> dict[str, Any]:
    """The preset fields and task keys the command line sets."""
    names = {f.name for f in dataclasses.fields(preset_cls)} - {"task", "task_file", "demos", "model"}
    out = {name: getattr(args, name) for name in names if getattr(args, name, None) is not None}
    out.update({dest[len(TASK_PREFIX):]: v for dest, v in vars(args).items() if dest.startswith(TASK_PREFIX) and v is not None})
    return out


def _flag(key: str) -> str:
    table, _, name = key.rpartition(".")
    return f"--{table + '.' if table else ''}{name.replace('_', '-')}"


def _run(args: argparse.Namespace) -> int:
    from latentrl.experiments import experiments

    exp = experiments()[args.experiment]
    overrides = _overrides(args, exp.preset)
    resume = getattr(args, "resume", None)
    if resume is not None and (overrides or args.quick or args.out):
        flags = ["--quick"] * args.quick + ["--out"] * bool(args.out) + [_flag(k) for k in overrides]
        print(f"latentrl: error: --resume takes the saved run's preset and directory; drop {' '.join(flags)}",
              file=sys.stderr)
        return 2
    out = resume or args.out or Path("results") / args.experiment
    if resume is not None:
        name, preset = saved_run(resume)
        if name != args.experiment:
            raise ValueError(f"{resume} holds a run of {name}, not of {args.experiment}")
    else:
        base = exp.preset.quick() if args.quick else exp.preset()  # type: ignore[attr-defined]
        preset = with_overrides(base, overrides)
    preset.validate()
    return _interruptible(lambda: exp.run(preset, out, progress=args.progress), out,
                          f"latentrl run {args.experiment} --resume {out}")


def _interruptible(work: Callable[[], object], out: Path, resume_command: str) -> int:
    """Runs `work`; Ctrl-C gives exit 130 and, if `out` holds finished trials, how to continue."""
    try:
        work()
    except KeyboardInterrupt:
        if (out / "results.json").is_file():
            print(f"interrupted; finished trials are in {out}; continue with: {resume_command}", file=sys.stderr)
        else:
            print("interrupted before any trial finished; nothing was written", file=sys.stderr)
        return 130
    return 0


def _train(args: argparse.Namespace) -> int:
    import matplotlib.pyplot  # noqa: F401  (the figures' [plot] extra: missing, exit 1 before any work)

    from latentrl.experiments.training import run_training

    # Absolute: the run folder is read back (resume, replay, rollout) from any working directory.
    run = _training_run(args, {"task_file": str(args.task.resolve()), "demos": str(args.demos.resolve()),
                               "model": str(args.model.resolve()) if args.model else ""})
    meta_path = args.out / "results.json"
    if meta_path.is_file() and not args.resume:
        raise ValueError(f"{args.out} holds a run already: add --resume to continue it, or choose another --out")
    run.validate()  # every file, key and column checked before anything is written
    from latentrl.experiments.training import prepared

    task, *_, settings = prepared(run)
    for warning in task.warnings:
        print(f"latentrl: warning: {warning}", file=sys.stderr)
    for found in settings:
        value = found.value if isinstance(found.value, str) else f"{found.value:g}"
        print(f"derived {found.key} = {value}: {found.rule}")
    command = "the same latentrl train command with --resume"
    code = _interruptible(lambda: run_training(run, args.out, progress=args.progress), args.out, command)
    if code == 0:
        print(f"trained {run.trials} trial(s) of {run.episodes} episodes; policy in {args.out / 'policy.npz'}")
        code = _interruptible(lambda: _report_of(args.out, write=True), args.out, command)
    return code


def _training_run(args: argparse.Namespace, files: dict[str, str]) -> Any:
    """The `TrainRun` of `train` and `check`: the preset (`--quick` or not), the task file's
    `[run]` where the preset holds its default, the flags, and `files`."""
    from latentrl.experiments.training import TrainRun
    from latentrl.task import Task

    base = with_task_run(TrainRun.quick() if args.quick else TrainRun(), Task.load(args.task))
    return dataclasses.replace(with_overrides(base, _overrides(args, TrainRun)), **files)


def _report_of(out: Path, *, write: bool = False, as_json: bool = False) -> None:
    """The verdict on the policy in `out` (rollouts from the test starts, the check's advice);
    printed, and with `write` saved as `out/report.json`."""
    from latentrl.check import check_task
    from latentrl.experiments.results import environment, write_json
    from latentrl.train import LatentPolicy
    from latentrl.verdict import training_verdict

    policy = LatentPolicy.load(out / "policy.npz")
    findings = check_task(policy.task, policy.demos, policy.model, policy.latent_low, policy.latent_high)
    found = training_verdict(policy, findings=findings)
    if write:
        with run_lock(out):
            write_json(out / "report.json", {**found.to_dict(), "environment": environment()})
    print(json.dumps(found.to_dict(), indent=2) if as_json else found)


def _report(args: argparse.Namespace) -> int:
    if not (args.results / "policy.npz").is_file():
        raise ValueError(f"{args.results}: no policy.npz there (a directory of latentrl train)")
    _report_of(args.results, as_json=args.json)
    return 0


def _check(args: argparse.Namespace) -> int:
    from latentrl.check import check_task
    from latentrl.run_settings import latent_box
    from latentrl.experiments.results import worker_threads
    from latentrl.experiments.training import fitted
    from latentrl.progress import progress_bar

    run = _training_run(args, {"task_file": str(args.task), "demos": str(args.demos), "model": str(args.model or "")})
    run.validate()  # the same checks of files, keys and columns as train
    task, demos, model = fitted(run)
    low, high = latent_box(model.Z_, run.latent_margin)
    with progress_bar(unit="pt", desc="survey", disable=not args.progress) as bar:
        def report(done: int, total: int) -> None:
            bar.total = total
            bar.update(done - bar.n)

        found = check_task(task, demos, model, low, high, budget=(run.trials, run.episodes),
                           threads=worker_threads(), progress=report)
    print(json.dumps(found.to_dict(), indent=2) if args.json else found)
    return 3 if found.verdict == "will not learn" else 0


def _rollout(args: argparse.Namespace) -> int:
    from latentrl.progress import progress_bar
    from latentrl.train import LatentPolicy

    path = args.results / "policy.npz" if args.results.is_dir() else args.results
    if args.episodes < 1:
        raise ValueError(f"--episodes must be at least 1, got {args.episodes}")
    policy = LatentPolicy.load(path)
    results: dict[str, dict[str, Any]] = {}
    with progress_bar(unit="ep", desc="rollout", disable=not args.progress) as bar:
        for kind in args.policy:
            def report(done: int, total: int) -> None:
                bar.total = total * len(args.policy)
                bar.update(len(results) * total + done - bar.n)

            results[kind] = policy.rollout(args.episodes, trial=args.trial, seed=args.seed, policy=kind,
                                           starts=args.starts, progress=report)
    with run_lock(args.out):
        _write_rollout(args, path, policy, results)
    for kind, r in results.items():
        print(f"{kind:8s} {format_rollout(r['summary'])}")
    return 0


def _write_rollout(args: argparse.Namespace, path: Path, policy: Any, results: dict[str, dict[str, Any]]) -> None:
    from latentrl.experiments.results import environment, write_json, write_npz

    write_npz(args.out / "rollout.npz", {f"{kind}_{k}": r[k] for kind, r in results.items()
                                         for k in ("returns", "ends", "reached", "paths")})
    summary = {"policy": str(path.resolve()), "policy_from_out": os.path.relpath(path.resolve(), args.out.resolve()),
               "task": policy.task.name, "trials": next(iter(results.values()))["trials"],
               "episodes": args.episodes, "seed": args.seed, "starts": args.starts,
               **{kind: r["summary"] for kind, r in results.items()}, "environment": environment()}
    write_json(args.out / "rollout.json", summary)


def _policies(text: str) -> list[str]:
    """`--policy`: a comma-separated subset of `POLICIES`, in their order."""
    chosen = [p.strip() for p in text.split(",") if p.strip()]
    unknown = [p for p in chosen if p not in POLICIES]
    if unknown or not chosen:
        raise argparse.ArgumentTypeError(f"expected some of {', '.join(POLICIES)}, got {text!r}")
    return [p for p in POLICIES if p in chosen]


def _fit(args: argparse.Namespace) -> int:
    from latentrl import GPLVM, PCA, load_demos
    from latentrl.recorded.options import DemoOptions

    if args.out.suffix != ".npz":
        raise ValueError(f"--out {args.out}: a model is saved as NPZ; give a file name ending in .npz")
    auto = args.n_components == "auto"
    if args.inducing is not None and args.model == "pca":
        raise ValueError("--inducing: only --model gplvm has inducing inputs")
    if auto and args.model == "pca":
        raise ValueError("--n-components auto: only --model gplvm chooses its dimension; give PCA an integer")
    given = {f.name: getattr(args, f.name) for f in dataclasses.fields(DemoOptions) if getattr(args, f.name) is not None}
    demos = load_demos(args.demos, min_postures=3 if auto else args.n_components + 1,
                       **DemoOptions(**given).load_kwargs())
    if args.model == "pca":
        model: Any = PCA(n_components=args.n_components)
    else:
        model = GPLVM(n_components=args.n_components, max_iter=args.max_iter, random_state=args.seed,
                      inducing=args.inducing, spacing=args.spacing)
    model.fit(demos.postures)
    model.save(args.out)
    episodes = {} if demos.episodes is None else {"episodes": len(set(demos.episodes.tolist()))}
    summary = {"model": type(model).__name__, "file": str(args.out), "postures": len(demos.postures), **episodes,
               "joint_names": list(demos.joint_names), **model.get_params()}
    if args.model == "gplvm":
        summary.update(nll=model.nll_, converged=model.converged_, n_iter=model.n_iter_, theta=model.theta_.tolist(),
                       fitted_n_components=model.n_components_, relevance=model.relevance_.tolist())
    print(json.dumps(summary, indent=2))
    return 0


def _plot(args: argparse.Namespace) -> int:
    from latentrl.experiments import experiments
    from latentrl.experiments.results import RunFolder

    name, preset = saved_run(args.results, train=True)
    arrays, done = RunFolder(args.results).finished()
    if not done:
        raise ValueError(f"{args.results}: no finished trial to plot")
    out = args.out or args.results
    if name == "train":
        from latentrl.experiments.training import figures

        figures(preset, arrays, args.results, out)
    else:
        rl = experiments()[name].rl
        assert rl is not None  # saved_run finds RL experiments only
        rl.figures(preset, arrays, args.results, out)
    counts = ", ".join(f"{learner} {n} of {preset.trials}" for learner, n in done.items())
    print(f"figures of {name} ({counts} trials) in {out}")
    return 0


def _sweep(args: argparse.Namespace) -> int:
    from latentrl.experiments.ray_backend import RayBackend
    from latentrl.experiments.sweep import SweepError, load_sweep, run_sweep

    if args.backend != "ray" and (args.address is not None or args.batch != 1):
        raise ValueError("--address and --batch are options of --backend ray")
    sweep = load_sweep(args.file)
    out = args.out or Path("results") / args.file.stem
    backend = RayBackend(address=args.address, batch=args.batch) if args.backend == "ray" else "local"
    try:
        run_sweep(sweep, out, backend=backend, resume=args.resume, progress=args.progress)
    except KeyboardInterrupt:
        print(f"interrupted; finished trials are in {out}; continue with: "
              f"latentrl sweep {args.file} --out {out} --resume", file=sys.stderr)
        return 130
    except SweepError as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1
    print((out / "summary.md").read_text(), end="")
    print(f"results of every cell in {out}/<cell>/; summary in {out}/summary.md and sweep.png")
    return 0


def _replay(args: argparse.Namespace) -> int:
    from latentrl.replay import check_request, render, replay, rollout_episode

    if (args.results / "rollout.json").is_file():  # a `latentrl rollout` directory
        if args.episode is None:
            raise ValueError(f"{args.results} holds a rollout: give --episode E (and --policy)")
        check_request(args.out, args.rerun, args.fps, args.width, args.max_frames, args.view)
        drawn = rollout_episode(args.results, args.policy, args.trial, args.episode, args.view)
        print(render(drawn, args.out, args.rerun, fps=args.fps, width=args.width, max_frames=args.max_frames))
        return 0
    name, preset = saved_run(args.results, train=True)
    what = replay(args.results, name, preset, args.out, rerun=args.rerun, trial=args.trial, episode=args.episode,
                  test=args.test, fps=args.fps, width=args.width, max_frames=args.max_frames, view=args.view)
    print(what)
    return 0


def _urdf_info(args: argparse.Namespace) -> int:
    from latentrl.robot_info import format_info, urdf_info

    info = urdf_info(args.urdf, balance_inertia=args.balance_inertia)
    print(json.dumps(info, indent=2) if args.json else format_info(info))
    if args.json:  # the table lists them; JSON on stdout stays one document
        for warning in info["warnings"]:
            print(f"latentrl: warning: {warning}", file=sys.stderr)
    return 0


def _info(args: argparse.Namespace) -> int:
    from latentrl.experiments.results import environment

    text = json.dumps(environment(), indent=2)
    try:
        print(text, flush=True)
    except OSError as err:  # e.g. stdout a full disk: say so once, not again at exit's flush
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        raise OSError(f"cannot write to standard output: {err.strerror}") from None
    return 0


def _check_writable(out: Path, *, file: bool) -> None:
    """`--out` can be written: its nearest existing ancestor is a writable directory (and it is
    not a directory where a file goes, or a file where a directory goes). Checked before any
    fit or trial, so a typo costs nothing."""
    if out.exists() and out.is_dir() == file:
        raise ValueError(f"--out {out}: is {'a directory' if file else 'a file'}, expected {'a file' if file else 'a directory'}")
    parent = (out.parent if file else out).absolute()
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"--out {out}: cannot write under {parent}")


RECORDING_LIBRARIES = ("pyarrow", "h5py", "rosbags")
"""The libraries of the recording extras ([lerobot], [hdf5], [rosbag])."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `latentrl` console script."""
    args = build_parser().parse_args(argv)
    command = {"info": _info, "run": _run, "train": _train, "check": _check, "report": _report, "rollout": _rollout, "fit": _fit, "plot": _plot, "sweep": _sweep,
               "urdf-info": _urdf_info, "replay": _replay}
    try:
        out = getattr(args, "out", None)
        if out is not None:
            _check_writable(out, file=args.command in ("fit", "replay"))
        if getattr(args, "rerun", None) is not None:
            _check_writable(args.rerun, file=True)
        return command[args.command](args)
    except (ValueError, OSError) as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1
    except ModuleNotFoundError as err:
        if err.name in RECORDING_LIBRARIES:  # its message names the extra (latentrl.recorded.libraries)
            print(f"latentrl: error: {err}", file=sys.stderr)
            return 1
        if err.name != "matplotlib":
            raise
        print("latentrl: error: figures need matplotlib: pip install 'latentrl[plot]'", file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # commands that keep work say more themselves (`_interruptible`)
        print("latentrl: interrupted; nothing was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
