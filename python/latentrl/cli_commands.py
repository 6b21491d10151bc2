"""What each `latentrl` subcommand does with its parsed arguments (`latentrl.cli_parser` builds
them): run an experiment, train, check, report, roll out, fit, plot, sweep, replay, urdf-info,
info. The experiments and SciPy are imported when a command runs."""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from latentrl.cli_parser import TASK_PREFIX
from latentrl.rollout_summary import format_rollout
from latentrl.run_lock import run_lock
from latentrl.run_settings import with_overrides, with_task_run
from latentrl.saved_runs import saved_run


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
    from latentrl._files import absolute
    from latentrl.experiments.training import check_resumable, prepared, run_training

    # Absolute: the run folder is read back (resume, replay, rollout) from any working directory.
    run = _training_run(args, {"task_file": str(absolute(args.task, "task file")),
                               "demos": str(absolute(args.demos, "--demos")),
                               "model": str(absolute(args.model, "--model")) if args.model else ""})
    meta_path = args.out / "results.json"
    if meta_path.is_file() and not args.resume:
        raise ValueError(f"{args.out} holds a run already: add --resume to continue it, or choose another --out")
    if args.resume:  # the same preset and inputs, before the fit and the derived settings
        check_resumable(run, args.out)
    run.validate()  # every file, key and column checked before anything is written
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
    from latentrl.experiments.training import FIT_SETTINGS, TrainRun
    from latentrl.task import Task

    base = with_task_run(TrainRun.quick() if args.quick else TrainRun(), Task.load(args.task))
    given = _overrides(args, TrainRun)
    fit = sorted(k for k in given if k in FIT_SETTINGS and given[k] != "auto")
    if files.get("model") and fit:  # as train_latent_policy refuses them: a given model is not fitted
        raise ValueError(f"{_flag(fit[0])}: a setting of the GPLVM fit, which --model {args.model} skips; fit the "
                         "model so (latentrl fit --max-iter N, --spacing even) or drop the flag")
    return dataclasses.replace(with_overrides(base, given), **files)


def _report_of(out: Path, *, write: bool = False, as_json: bool = False) -> None:
    """The verdict on the policy in `out` (rollouts from the test starts, the check's advice):
    the one `train` saved in `out/report.json` if it was written for the policy.npz there now,
    else made anew; printed, and with `write` made anew and saved with that policy's digest."""
    from latentrl.check import check_task
    from latentrl.experiments.run_folder import RunFolder
    from latentrl.results import environment, write_json
    from latentrl.train import LatentPolicy
    from latentrl.verdict import Verdict, training_verdict

    folder = RunFolder(out)
    saved = None if write else folder.saved_report()
    if saved is not None:
        found = Verdict.from_dict(saved)
    else:
        policy = LatentPolicy.load(out / "policy.npz")
        findings = check_task(policy.task, policy.demos, policy.model, policy.latent_low, policy.latent_high)
        found = training_verdict(policy, findings=findings)
    if write:
        with run_lock(out):
            write_json(folder.report_path, {**found.to_dict(), "policy_sha256": folder.policy_digest(),
                                            "environment": environment()})
    print(json.dumps(found.to_dict(), indent=2) if as_json else found)


def _report(args: argparse.Namespace) -> int:
    if not (args.results / "policy.npz").is_file():
        raise ValueError(_no_policy(args.results))
    _report_of(args.results, as_json=args.json)
    return 0


def _no_policy(folder: Path) -> str:
    """Why `report` and `rollout` find no policy.npz in `folder`: an unfinished run of `latentrl
    train` (Ctrl-C, a full disk) and the command that finishes it, or no such run."""
    from latentrl.experiments.run_folder import RunFolder

    run_folder = RunFolder(folder)
    if run_folder.holds_run():
        name, run = saved_run(folder, train=True)
        if name == "train":
            done = run_folder.finished()[1].get("latent", 0)
            return (f"{folder}: a run of latentrl train stopped before its policy.npz was written ({done} of "
                    f"{run.trials} trials saved); finish it with: {_resume_command(folder, run)}")
    return f"{folder}: no policy.npz there (a directory of latentrl train)"


def _resume_command(out: Path, run: Any) -> str:
    """The `latentrl train … --resume` command that continues `run` in `out`: its files, and a flag
    for each setting other than the task file gives."""
    import shlex

    from latentrl.experiments.training import TrainRun
    from latentrl.task import Task

    try:
        base = with_task_run(TrainRun(), Task.load(run.task_file))
    except (OSError, ValueError):  # the task file is gone or broken: resume names it
        base = TrainRun()
    words = ["latentrl", "train", run.task_file, "--demos", run.demos, *(["--model", run.model] if run.model else []),
             "--out", str(out), "--resume"]
    for field in dataclasses.fields(TrainRun):
        value = getattr(run, field.name)
        if field.name in ("task", "task_file", "demos", "model") or value == getattr(base, field.name):
            continue
        flag = _flag(field.name)
        words += [flag if value else f"--no-{flag[2:]}"] if isinstance(value, bool) else [flag, str(value)]
    for key, value in run.task.items():
        words += [_flag(key), value if isinstance(value, str) else json.dumps(value)]
    return shlex.join(words)


def _check(args: argparse.Namespace) -> int:
    from latentrl.check import check_task
    from latentrl.run_settings import latent_box
    from latentrl.machine import worker_threads
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
    if args.results.is_dir() and not path.is_file():
        raise ValueError(_no_policy(args.results))
    if (args.out / "results.json").is_file():  # replay would draw the rollout's episodes as the run's
        raise ValueError(f"--out {args.out}: holds a run (results.json); a rollout is written to a folder of its "
                         f"own, e.g. --out {args.out / 'rollout'}")
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
    from latentrl.results import environment, write_json, write_npz

    # An earlier rollout's summary goes first: a kill between the two writes leaves no summary
    # (refused by name) rather than one that describes other episodes than rollout.npz holds.
    (args.out / "rollout.json").unlink(missing_ok=True)
    write_npz(args.out / "rollout.npz", {f"{kind}_{k}": r[k] for kind, r in results.items()
                                         for k in ("returns", "ends", "reached", "paths")})
    summary = {"policy": str(path.resolve()), "policy_from_out": os.path.relpath(path.resolve(), args.out.resolve()),
               "task": policy.task.name, "trials": next(iter(results.values()))["trials"],
               "episodes": args.episodes, "seed": args.seed, "starts": args.starts,
               **{kind: r["summary"] for kind, r in results.items()}, "environment": environment()}
    write_json(args.out / "rollout.json", summary)


def _fit(args: argparse.Namespace) -> int:
    from latentrl import GPLVM, PCA, load_demos
    from latentrl.gplvm import name_joints
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
    name_joints(model, demos.joint_names)
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
    from latentrl.experiments.run_folder import RunFolder

    name, preset = saved_run(args.results, train=True)
    arrays, done = RunFolder(args.results).finished()
    if not done:
        raise ValueError(f"{args.results}: no finished trial to plot")
    out = args.out or args.results
    figures: Callable[[Any, Any, Path, Path], None]
    if name == "train":
        from latentrl.experiments.training import figures as train_figures

        figures = train_figures
    else:
        rl = experiments()[name].rl
        assert rl is not None  # saved_run finds RL experiments only
        figures = rl.figures
    try:
        figures(preset, arrays, args.results, out)
    except KeyboardInterrupt:  # each figure is written whole (atomically): some may be new already
        print(f"latentrl: interrupted; the figures drawn so far are in {out}, the others as they were: "
              f"`latentrl plot {args.results}` draws them all again", file=sys.stderr)
        return 130
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
    from latentrl.results import environment

    print(json.dumps(environment(), indent=2))
    return 0


COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {
    "info": _info, "run": _run, "train": _train, "check": _check, "report": _report, "rollout": _rollout, "fit": _fit,
    "plot": _plot, "sweep": _sweep, "urdf-info": _urdf_info, "replay": _replay,
}
"""Each subcommand's function: its exit code."""
