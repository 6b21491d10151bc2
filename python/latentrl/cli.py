"""The `latentrl` command: run an experiment, show versions.

Exit codes: 0 done, 1 the run failed, 2 bad arguments (argparse), 130 interrupted (finished
trials are kept; run again with --resume).
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
from latentrl.experiments.results import environment


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


def _add_preset_flags(parser: argparse.ArgumentParser, preset_cls: type) -> None:
    """One `--field-name` flag per scalar preset field, its help the field's docstring."""
    docs = field_docs(preset_cls)
    for field in dataclasses.fields(preset_cls):
        kind = type(field.default) if field.default is not dataclasses.MISSING else None
        if kind not in (int, float, str, bool):
            continue
        flag = "--" + field.name.replace("_", "-")
        help_text = f"{docs.get(field.name, '')} (default: {field.default})"
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
        exp.add_argument("--out", type=Path, default=Path("results") / name, help="results directory")
        exp.add_argument("--quick", action="store_true", help="the small smoke-test preset")
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
    preset = preset_cls.quick() if args.quick else preset_cls()
    overrides = {
        f.name: getattr(args, f.name)
        for f in dataclasses.fields(preset_cls)
        if getattr(args, f.name, None) is not None
    }
    try:
        preset = dataclasses.replace(preset, **overrides)
        run(preset, args.out, progress=args.progress)
    except KeyboardInterrupt:
        print(f"interrupted; finished trials are in {args.out}", file=sys.stderr)
        return 130
    except (ValueError, OSError) as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
