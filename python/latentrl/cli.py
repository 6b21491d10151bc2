"""The `latentrl` command: run an experiment or a sweep of it (locally or on a Ray cluster), fit
a model to demonstrations, redraw the figures of a results directory, show versions.

Exit codes: 0 done, 1 bad values or a failed run (the message says what), 2 bad arguments
(argparse), 130 interrupted (finished trials are kept; `latentrl run EXP --resume DIR`
continues).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from latentrl.experiments.presets import field_docs
from latentrl.experiments.registry import experiments
from latentrl.experiments.results import environment, read_json


def saved_run(out_dir: Path) -> tuple[str, Any]:
    """(experiment name, preset) of the RL run in `out_dir`, from its results.json; ValueError if
    the directory holds none, or the preset does not fit this version."""
    meta_path = out_dir / "results.json"
    if not meta_path.is_file():
        raise ValueError(f"{out_dir}: no results.json there, so no run of an RL experiment")
    fields = dict(read_json(meta_path).get("preset") or {})
    preset_name = fields.pop("name", None)
    found = [
        (name, exp.preset) for name, exp in experiments().items() if exp.rl and exp.preset.__name__ == preset_name
    ]
    if not found:
        raise ValueError(f"{out_dir}: results.json names no RL experiment's preset (found {preset_name!r})")
    name, preset_cls = found[0]
    unknown = sorted(set(fields) - {f.name for f in dataclasses.fields(preset_cls)})
    if unknown:
        raise ValueError(f"{out_dir}: its preset has fields this version does not know: {unknown}")
    return name, preset_cls(**fields)


def _add_preset_flags(parser: argparse.ArgumentParser, preset_cls: type) -> None:
    """One `--field-name` flag per scalar preset field, its help the field's docstring."""
    docs = field_docs(preset_cls)
    for field in dataclasses.fields(preset_cls):
        kind = type(field.default) if field.default is not dataclasses.MISSING else None
        if kind not in (int, float, str, bool):
            continue
        flag = "--" + field.name.replace("_", "-")
        # argparse %-formats help strings: a literal "%" in a docstring must be doubled.
        help_text = f"{docs.get(field.name, '')} (default: {field.default})".replace("%", "%%")
        if kind is bool:
            parser.add_argument(flag, dest=field.name, action=argparse.BooleanOptionalAction, default=None, help=help_text)
        else:
            parser.add_argument(flag, dest=field.name, type=kind, default=None, help=help_text)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand and flag."""
    parser = argparse.ArgumentParser(prog="latentrl", description=__doc__)
    sub = parser.add_subparsers(dest="command", required=True)
    run = sub.add_parser("run", help="run an experiment and write its results directory")
    run_sub = run.add_subparsers(dest="experiment", required=True)
    for name, exp in experiments().items():
        cmd = run_sub.add_parser(name, help=(exp.preset.__doc__ or "").strip().splitlines()[0])
        cmd.add_argument("--out", type=Path, help=f"results directory (default: results/{name})")
        cmd.add_argument("--quick", action="store_true", help="the small smoke-test preset")
        if exp.rl:
            cmd.add_argument(
                "--resume", type=Path, metavar="DIR",
                help="continue the interrupted run in DIR with its own preset (no other preset flags)",
            )
        cmd.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
        _add_preset_flags(cmd, exp.preset)
    fit = sub.add_parser("fit", help="fit a PCA or GPLVM to a demonstration file and save it (NPZ)")
    fit.add_argument("demos", type=Path, help="demonstrated postures: .csv (header of joint names), .npz or .json")
    fit.add_argument("--model", choices=("gplvm", "pca"), default="gplvm", help="the model (default: gplvm)")
    fit.add_argument("--n-components", type=int, default=2, help="latent dimension d (default: 2)")
    fit.add_argument("--seed", type=int, default=0, help="random_state of the GPLVM (default: 0)")
    fit.add_argument("--max-iter", type=int, default=1000, help="L-BFGS iteration cap of the GPLVM (default: 1000)")
    fit.add_argument("--out", type=Path, required=True, help="the model file to write (.npz; load with GPLVM.load)")
    plot = sub.add_parser("plot", help="redraw the figures of a results directory (finished trials only)")
    plot.add_argument("results", type=Path, help="a results directory of `latentrl run exp1|exp2|exp3`")
    plot.add_argument("--out", type=Path, help="where to write the figures (default: the results directory)")
    sweep = sub.add_parser("sweep", help="run an RL experiment over a grid of preset values, here or on a Ray cluster")
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
    sub.add_parser("info", help="print versions, git revision and thread count as JSON")
    return parser


def _run(args: argparse.Namespace) -> int:
    exp = experiments()[args.experiment]
    overrides = {
        f.name: getattr(args, f.name) for f in dataclasses.fields(exp.preset) if getattr(args, f.name, None) is not None
    }
    resume = getattr(args, "resume", None)
    if resume is not None and (overrides or args.quick or args.out):
        flags = ["--quick"] * args.quick + ["--out"] * bool(args.out)
        flags += ["--" + name.replace("_", "-") for name in overrides]
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
        preset = dataclasses.replace(base, **overrides)
    try:
        exp.run(preset, out, progress=args.progress)
    except KeyboardInterrupt:
        print(
            f"interrupted; finished trials are in {out}; continue with: latentrl run {args.experiment} --resume {out}",
            file=sys.stderr,
        )
        return 130
    return 0


def _fit(args: argparse.Namespace) -> int:
    from latentrl import GPLVM, PCA, load_demos

    demos = load_demos(args.demos, min_postures=args.n_components + 1)
    if args.model == "pca":
        model: Any = PCA(n_components=args.n_components)
    else:
        model = GPLVM(n_components=args.n_components, max_iter=args.max_iter, random_state=args.seed)
    model.fit(demos.postures)
    model.save(args.out)
    summary = {"model": type(model).__name__, "file": str(args.out), "postures": len(demos.postures),
               "joint_names": list(demos.joint_names), **model.get_params()}
    if args.model == "gplvm":
        summary.update(nll=model.nll_, converged=model.converged_, n_iter=model.n_iter_, theta=model.theta_.tolist())
    print(json.dumps(summary, indent=2))
    return 0


def _plot(args: argparse.Namespace) -> int:
    from latentrl.experiments.runner import finished_trials, load_arrays

    name, preset = saved_run(args.results)
    arrays, done = finished_trials(load_arrays(args.results))
    if not done:
        raise ValueError(f"{args.results}: no finished trial to plot")
    rl = experiments()[name].rl
    assert rl is not None  # saved_run finds RL experiments only
    out = args.out or args.results
    rl.figures(preset, arrays, out)
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


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `latentrl` console script."""
    args = build_parser().parse_args(argv)
    if args.command == "info":
        print(json.dumps(environment(), indent=2))
        return 0
    command = {"run": _run, "fit": _fit, "plot": _plot, "sweep": _sweep}[args.command]
    try:
        return command(args)
    except (ValueError, OSError) as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1
    except ModuleNotFoundError as err:
        if err.name != "matplotlib":
            raise
        print("latentrl: error: figures need matplotlib: pip install 'latentrl[plot]'", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
