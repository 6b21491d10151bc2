"""The description of a sweep (`Sweep`: a grid and/or cells of preset overrides, checked on
construction, from a TOML/YAML file with `load_sweep`), its cells and jobs: what the runner
(`sweep.py`), the Ray backend and the summary share."""

from __future__ import annotations

import dataclasses
import difflib
import importlib
import itertools
import json
import math
import re
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

from latentrl._files import MAX_SWEEP_FILE_BYTES, read_text
from latentrl.experiments.presets import describe, with_overrides
from latentrl.experiments.registry import rl_experiments, task_schema
from latentrl.task import by_path, key_paths

SWEEP_KEYS = ("experiment", "quick", "trials", "seed", "threshold", "base", "grid", "cells")
"""The keys of a sweep file, as the fields of `Sweep`."""


class SweepError(RuntimeError):
    """Some cells of a sweep failed; the others and every finished trial are saved."""


MAX_CELLS = 10_000
"""The most cells of one sweep: counted before the grid is expanded."""

@dataclass(frozen=True)
class Cell:
    """One point of a sweep: a full preset and where its results go."""

    id: str
    """Directory name: index and the overridden values that vary across the sweep."""
    overrides: dict[str, Any]
    """The grid point and/or explicit overrides of this cell (on top of `Sweep.base`)."""
    preset: Any
    """The experiment's preset for this cell."""


@dataclass(frozen=True)
class Sweep:
    """A sweep of one RL experiment: a grid (cartesian product) and/or a list of explicit
    overrides, on top of base overrides, with the trials per cell and the base seed. Every
    value is checked against the preset's fields on construction (ValueError naming it)."""

    experiment: str
    """`exp1` or `exp2`."""
    grid: Mapping[str, Sequence[Any]] = field(default_factory=dict)
    """Preset field → values; the cells are their cartesian product (the last field fastest)."""
    cells: Sequence[Mapping[str, Any]] = ()
    """Explicit overrides, one mapping per cell; with a grid, each is crossed with every point."""
    base: Mapping[str, Any] = field(default_factory=dict)
    """Overrides every cell starts from (the grid and the cells override these)."""
    quick: bool = False
    """Start from the experiment's quick preset instead of the paper's."""
    trials: int | None = None
    """Trials per cell (None: the preset's)."""
    seed: int | None = None
    """Base seed of every cell; trial i of a cell draws from (seed, i) (None: the preset's).
    To repeat the sweep over seeds, put `seed` in the grid."""
    threshold: float | None = None
    """Return that counts as learnt, for 'episodes to threshold' (running mean over the last
    10 % of a cell's episodes); None: half the best final return of the whole sweep."""

    def __post_init__(self) -> None:
        if not isinstance(self.experiment, str) or self.experiment not in rl_experiments():
            known = ", ".join(rl_experiments())
            raise ValueError(f"experiment: unknown experiment {self.experiment!r}; sweeps run {known}")
        check_type("quick", self.quick, bool)
        if self.trials is not None:
            check_type("trials", self.trials, int, minimum=1)
        if self.seed is not None:
            check_type("seed", self.seed, int, minimum=0)
        if self.threshold is not None:
            threshold = check_type("threshold", self.threshold, float)
            if not math.isfinite(threshold):
                raise ValueError(f"threshold: must be finite, got {self.threshold!r}")
            object.__setattr__(self, "threshold", threshold)
        kinds = _field_kinds(rl_experiments()[self.experiment].preset)
        kinds.update(_task_kinds(self.experiment))
        base = _check_overrides("base", key_paths(self.base), kinds)
        for name in ("trials", "seed"):
            if getattr(self, name) is not None and name in base:
                raise ValueError(f"base.{name}: {name} is already set at the top level of the sweep")
        if not isinstance(self.grid, Mapping):
            raise ValueError(f"grid: expected a table of field = [values], got {self.grid!r}")
        grid: dict[str, list[Any]] = {}
        for name, values in key_paths(self.grid).items():
            _check_name(f"grid.{name}", name, kinds)
            if isinstance(values, (str, bytes)) or not isinstance(values, Sequence):
                raise ValueError(f"grid.{name}: expected a list of values, got {values!r}")
            if not values:
                raise ValueError(f"grid.{name}: empty list (give at least one value or leave the field out)")
            checked = [_check_field(f"grid.{name}[{i}]", name, v, kinds) for i, v in enumerate(values)]
            for i, value in enumerate(checked):
                if value in checked[:i]:
                    raise ValueError(f"grid.{name}: {value!r} appears twice")
            grid[name] = checked
        if isinstance(self.cells, (str, bytes, Mapping)) or not isinstance(self.cells, Sequence):
            raise ValueError(f"cells: expected a list of tables of overrides, got {self.cells!r}")
        cells = [_check_overrides(f"cells[{i}]", key_paths(c), kinds) for i, c in enumerate(self.cells)]
        for i, cell in enumerate(cells):
            both = sorted(set(cell) & set(grid))
            if both:
                raise ValueError(f"cells[{i}]: {', '.join(both)} also in the grid (set each field in one place)")
        count = math.prod(len(v) for v in grid.values()) * max(1, len(cells))
        if count > MAX_CELLS:
            sizes = " × ".join([*(str(len(v)) for v in grid.values()), *([str(len(cells))] if cells else [])])
            raise ValueError(f"grid: {sizes} = {count} cells, more than the {MAX_CELLS} a sweep may have "
                             "(each is a full run); split it into several sweeps")
        object.__setattr__(self, "base", base)
        object.__setattr__(self, "grid", grid)
        object.__setattr__(self, "cells", cells)
        self.expand()  # every cell's preset validates and no two are the same

    @classmethod
    def from_mapping(cls, data: Mapping[str, Any], source: str = "") -> Sweep:
        """A sweep from parsed TOML/YAML (keys as the fields); errors are prefixed by `source`."""
        prefix = f"{source}: " if source else ""
        try:
            if not isinstance(data, Mapping):
                raise ValueError(f"expected a table at the top level, got {type(data).__name__}")
            unknown = sorted(set(data) - set(SWEEP_KEYS))
            if unknown:
                raise ValueError(f"unknown key {unknown[0]!r} (a sweep has {', '.join(SWEEP_KEYS)})")
            if "experiment" not in data:
                raise ValueError("no experiment = \"exp1\" or \"exp2\"")
            return cls(**data)
        except ValueError as err:
            raise ValueError(f"{prefix}{err}") from None

    def expand(self) -> list[Cell]:
        """The cells, in order: each explicit cell (or the base alone) crossed with the grid."""
        kind = rl_experiments()[self.experiment]
        start = kind.preset.quick() if self.quick else kind.preset()  # type: ignore[attr-defined]
        top = {name: getattr(self, name) for name in ("trials", "seed") if getattr(self, name) is not None}
        start = with_overrides(start, {**self.base, **top})
        points = [dict(zip(self.grid, values)) for values in itertools.product(*self.grid.values())]
        overrides = [{**cell, **point} for cell in (self.cells or [{}]) for point in points]
        varying = list(dict.fromkeys([*self.grid, *(k for c in self.cells for k in c)]))  # in the ids
        width = max(2, len(str(len(overrides) - 1)))
        cells: list[Cell] = []
        seen: dict[str, str] = {}
        for index, values in enumerate(overrides):
            label = "".join(f"_{k}={_format(values[k])}" for k in varying if k in values)
            cell_id = (f"{index:0{width}d}" + re.sub(r"[^A-Za-z0-9._=+-]", "-", label))[:100]
            try:
                preset = with_overrides(start, values)
                preset.validate()
            except ValueError as err:
                raise ValueError(f"cell {cell_id}: {err}") from None
            key = json.dumps(describe(preset), sort_keys=True, default=str)
            if key in seen:
                raise ValueError(f"cells {seen[key]} and {cell_id} are the same preset")
            seen[key] = cell_id
            cells.append(Cell(cell_id, values, preset))
        return cells

    def describe(self) -> dict[str, Any]:
        """The description as plain JSON values (what sweep.json keeps and `resume` compares)."""
        return json.loads(json.dumps(dataclasses.asdict(self)))  # type: ignore[no-any-return]


def load_sweep(path: Path | str) -> Sweep:
    """A sweep from a TOML file (or YAML, `.yaml`/`.yml`, if PyYAML is installed); a file that
    is not one, or holds a bad value, is a ValueError naming the file and the value."""
    path = Path(path)
    try:
        text = read_text(path, MAX_SWEEP_FILE_BYTES, "a sweep file")
    except ValueError as err:
        raise ValueError(f"{path}: {err}") from None
    if path.suffix.lower() in (".yaml", ".yml"):
        try:
            yaml: Any = importlib.import_module("yaml")
        except ModuleNotFoundError:
            raise ValueError(f"{path}: YAML sweep files need PyYAML (pip install pyyaml), or use TOML") from None
        try:
            data = yaml.safe_load(text)
        except yaml.YAMLError as err:
            raise ValueError(f"{path}: not valid YAML ({err})") from None
    else:
        try:
            data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as err:
            raise ValueError(f"{path}: not valid TOML ({err})") from None
    return Sweep.from_mapping(data, source=str(path))


def _field_kinds(preset_cls: type) -> dict[str, type]:
    """Scalar preset fields (the ones a sweep may set) → their type, from the defaults."""
    fields = dataclasses.fields(preset_cls)
    return {f.name: type(f.default) for f in fields if type(f.default) in (bool, int, float, str)}


_KIND_NAMES = {bool: "true or false", int: "an integer", float: "a number", str: "a string"}


def check_type(where: str, value: Any, kind: type, minimum: int | None = None) -> Any:
    """`value` (named `where` in the error) as a `kind` (an int is a float too, a bool is neither), or a ValueError."""
    ok = isinstance(value, kind) and (kind is bool or not isinstance(value, bool))
    if kind is float and isinstance(value, int) and not isinstance(value, bool):
        value, ok = float(value), True
    if not ok:
        raise ValueError(f"{where}: expected {_KIND_NAMES[kind]}, got {value!r}")
    if minimum is not None and value < minimum:
        raise ValueError(f"{where}: must be >= {minimum}, got {value!r}")
    return value


def _task_kinds(experiment: str) -> dict[str, type]:
    """Scalar task keys of `experiment` (by path) → the type a sweep value must have; choices
    and optional values are strings or numbers checked by the task itself (`object`)."""
    types = {"float": float, "int": int, "bool": bool, "str": str}
    return {e["key"]: types.get(e["kind"], object) for e in task_schema(experiment) if by_path(e)}


def _check_name(where: str, name: str, kinds: Mapping[str, type]) -> None:
    if name not in kinds:
        close = difflib.get_close_matches(name, kinds, n=1)
        fields = [k for k in kinds if "." not in k]
        hint = f"; did you mean {close[0]!r}?" if close else f" (fields: {', '.join(fields)}; task keys by path, e.g. learner.beta)"
        raise ValueError(f"{where}: {name!r} is not a field of the preset or a task key{hint}")


def _check_field(where: str, name: str, value: Any, kinds: Mapping[str, type]) -> Any:
    _check_name(where, name, kinds)
    return value if kinds[name] is object else check_type(where, value, kinds[name])


def _check_overrides(where: str, overrides: Any, kinds: Mapping[str, type]) -> dict[str, Any]:
    if not isinstance(overrides, Mapping):
        raise ValueError(f"{where}: expected a table of field = value, got {overrides!r}")
    return {name: _check_field(f"{where}.{name}", name, v, kinds) for name, v in overrides.items()}


def _format(value: Any) -> str:
    return repr(value) if isinstance(value, float) else str(value)


class Job(NamedTuple):
    """A cell to run: which experiment, the cell, its results directory."""

    experiment: str
    cell: Cell
    out: Path
