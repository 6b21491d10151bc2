"""The `latentrl` command: run an experiment, show versions.

Exit codes: 0 done, 1 the run failed, 2 bad arguments (argparse), 130 interrupted (finished
trials are kept; `latentrl run EXP --resume DIR` continues).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import sys
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from latentrl.experiments.presets import field_docs
from latentrl.experiments.results import environment, read_json

RESUMABLE = ("exp1", "exp2")
"""Experiments whose runs are kept trial by trial in results.json and can be continued."""


def _experiments() -> dict[str, tuple[type, Callable[..., Any]]]:
    """Experiment name → (preset class, run function)."""
    from latentrl.experiments.exp1 import Exp1Preset, run_exp1
    from latentrl.experiments.exp2 import Exp2Preset, run_exp2
    from latentrl.experiments.table1 import Table1Preset, run_table1

    return {
        "table1": (Table1Preset, run_table1),
        "exp1": (Exp1Preset, run_exp1),
        "exp2": (Exp2Preset, run_exp2),
    }


def saved_preset(preset_cls: type, out_dir: Path) -> Any:
    """The preset of the run in `out_dir` (its results.json), for `--resume`; ValueError if the
    directory holds no run, or a run of another experiment."""
    meta_path = out_dir / "results.json"
    if not meta_path.is_file():
        raise ValueError(f"--resume {out_dir}: no results.json there, so no run to continue")
    fields = dict(read_json(meta_path).get("preset") or {})
    name = fields.pop("name", None)
    if name != preset_cls.__name__:
        raise ValueError(f"--resume {out_dir}: it holds a run of {name}, not of {preset_cls.__name__}")
    known = {f.name: f for f in dataclasses.fields(preset_cls)}
    unknown = sorted(set(fields) - set(known))
    if unknown:
        raise ValueError(f"--resume {out_dir}: its preset has fields this version does not know: {unknown}")
    return preset_cls(**fields)


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
    for name, (preset_cls, _) in _experiments().items():
        exp = run_sub.add_parser(name, help=(preset_cls.__doc__ or "").strip().splitlines()[0])
        exp.add_argument("--out", type=Path, help=f"results directory (default: results/{name})")
        exp.add_argument("--quick", action="store_true", help="the small smoke-test preset")
        if name in RESUMABLE:
            exp.add_argument(
                "--resume", type=Path, metavar="DIR",
                help="continue the interrupted run in DIR with its own preset (no other preset flags)",
            )
        exp.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
        _add_preset_flags(exp, preset_cls)
    sub.add_parser("info", help="print versions, git revision and thread count as JSON")
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `latentrl` console script."""
    args = build_parser().parse_args(argv)
    if args.command == "info":
        print(json.dumps(environment(), indent=2))
        return 0
    preset_cls, run = _experiments()[args.experiment]
    overrides = {
        f.name: getattr(args, f.name)
        for f in dataclasses.fields(preset_cls)
        if getattr(args, f.name, None) is not None
    }
    resume = getattr(args, "resume", None)
    if resume is not None and (overrides or args.quick or args.out):
        flags = ["--quick"] * args.quick + ["--out"] * bool(args.out)
        flags += ["--" + name.replace("_", "-") for name in overrides]
        print(f"latentrl: error: --resume takes the saved run's preset and directory; drop {' '.join(flags)}",
              file=sys.stderr)
        return 2
    out = resume or args.out or Path("results") / args.experiment
    try:
        if resume is not None:
            preset = saved_preset(preset_cls, resume)
        else:
            preset = dataclasses.replace(preset_cls.quick() if args.quick else preset_cls(), **overrides)
        run(preset, out, progress=args.progress)
    except KeyboardInterrupt:
        print(
            f"interrupted; finished trials are in {out}; continue with: latentrl run {args.experiment} --resume {out}",
            file=sys.stderr,
        )
        return 130
    except (ValueError, OSError) as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
