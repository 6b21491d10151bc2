"""The `latentrl` command: run an experiment, fit a model to demonstrations, redraw the figures
of a results directory, show versions.

Exit codes: 0 done, 1 bad values or a failed run (the message says what), 2 bad arguments
(argparse), 130 interrupted (finished trials are kept; `latentrl run EXP --resume DIR`
continues).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NamedTuple

from latentrl.experiments.presets import field_docs
from latentrl.experiments.results import environment, read_json


class Experiment(NamedTuple):
    """One `latentrl run` experiment."""

    preset: type
    """Its frozen preset dataclass; every scalar field becomes a `--flag`."""
    run: Callable[..., Any]
    """`run(preset, out_dir, progress=...)`."""
    figures: Callable[..., None] | None
    """`figures(preset, arrays, out_dir)` for the RL experiments, whose runs results.json keeps
    trial by trial: they can be resumed and re-plotted. None for the others."""


def _experiments() -> dict[str, Experiment]:
    """Experiment name → its preset, runner and figures."""
    from latentrl.experiments import exp1, exp2, exp3, table1

    return {
        "table1": Experiment(table1.Table1Preset, table1.run_table1, None),
        "exp1": Experiment(exp1.Exp1Preset, exp1.run_exp1, exp1.figures),
        "exp2": Experiment(exp2.Exp2Preset, exp2.run_exp2, exp2.figures),
        "exp3": Experiment(exp3.Exp3Preset, exp3.run_exp3, exp3.figures),
    }


def saved_run(out_dir: Path) -> tuple[str, Any]:
    """(experiment name, preset) of the RL run in `out_dir`, from its results.json; ValueError if
    the directory holds none, or the preset does not fit this version."""
    meta_path = out_dir / "results.json"
    if not meta_path.is_file():
        raise ValueError(f"{out_dir}: no results.json there, so no run of an RL experiment")
    fields = dict(read_json(meta_path).get("preset") or {})
    preset_name = fields.pop("name", None)
    found = [name for name, exp in _experiments().items() if exp.figures and exp.preset.__name__ == preset_name]
    if not found:
        raise ValueError(f"{out_dir}: results.json names no RL experiment's preset (found {preset_name!r})")
    preset_cls = _experiments()[found[0]].preset
    unknown = sorted(set(fields) - {f.name for f in dataclasses.fields(preset_cls)})
    if unknown:
        raise ValueError(f"{out_dir}: its preset has fields this version does not know: {unknown}")
    return found[0], preset_cls(**fields)


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
    for name, exp in _experiments().items():
        cmd = run_sub.add_parser(name, help=(exp.preset.__doc__ or "").strip().splitlines()[0])
        cmd.add_argument("--out", type=Path, help=f"results directory (default: results/{name})")
        cmd.add_argument("--quick", action="store_true", help="the small smoke-test preset")
        if exp.figures:
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
    sub.add_parser("info", help="print versions, git revision and thread count as JSON")
    return parser


def _run(args: argparse.Namespace) -> int:
    exp = _experiments()[args.experiment]
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
        preset = dataclasses.replace(exp.preset.quick() if args.quick else exp.preset(), **overrides)
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
    figures = _experiments()[name].figures
    assert figures is not None  # saved_run finds RL experiments only
    out = args.out or args.results
    figures(preset, arrays, out)
    counts = ", ".join(f"{learner} {n} of {preset.trials}" for learner, n in done.items())
    print(f"figures of {name} ({counts} trials) in {out}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `latentrl` console script."""
    args = build_parser().parse_args(argv)
    if args.command == "info":
        print(json.dumps(environment(), indent=2))
        return 0
    command = {"run": _run, "fit": _fit, "plot": _plot}[args.command]
    try:
        return command(args)
    except (ValueError, OSError) as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
