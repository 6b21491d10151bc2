"""What the experiments' presets share beyond `latentrl.run_settings` (`LatentRun`, the part of
every latent RL run, and how the `[run]` table and overrides apply live there, public, for
`latentrl.check` and training): the field docs the CLI shows, a preset's description for the
results metadata, and a checked read of a typed value."""

from __future__ import annotations

import ast
import contextlib
import dataclasses
import inspect
import re
import sys
import textwrap
from functools import cache
from typing import Any

from latentrl.task import run_settings


@cache
def field_docs(preset_cls: type) -> dict[str, str]:
    """The attribute docstrings of a dataclass and its dataclass bases (the string literal under
    each field; a subclass's own wins); a run setting without one has the `[run]` key's doc."""
    docs = {name: entry["doc"] for name, entry in run_settings().items()}
    for cls in reversed(preset_cls.__mro__):
        if not dataclasses.is_dataclass(cls):
            continue
        body = _class_body(cls)
        for item, doc in zip(body, body[1:]):
            if (
                isinstance(item, ast.AnnAssign)
                and isinstance(item.target, ast.Name)
                and isinstance(doc, ast.Expr)
                and isinstance(doc.value, ast.Constant)
                and isinstance(doc.value.value, str)
            ):
                docs[item.target.id] = " ".join(doc.value.value.split())
    return docs


def _class_body(cls: type) -> list[ast.stmt]:
    """The statements of `cls`'s definition. A class at the top of its module is parsed alone: its
    lines from `class Name` to the next line at column 0 (`inspect.getsource` parses the whole
    module, ten times slower; `train --help` reads four). Where that cut is not the whole class
    (it fell in a string or brackets: a SyntaxError), or the class is nested: `inspect.getsource`."""
    source = inspect.getsource(sys.modules[cls.__module__])
    block = re.search(rf"^class {cls.__name__}\b.*?(?=^[^\s#]|\Z)", source, re.M | re.S)
    tree = None
    if block and cls.__qualname__ == cls.__name__:
        with contextlib.suppress(SyntaxError):
            tree = ast.parse(block.group(0))
    tree = tree or ast.parse(textwrap.dedent(inspect.getsource(cls)))
    definition = tree.body[0]
    assert isinstance(definition, ast.ClassDef)
    return definition.body


def describe(preset: Any) -> dict[str, Any]:
    """Every field of a preset with its value, for the results metadata."""
    return {"name": type(preset).__name__, **dataclasses.asdict(preset)}


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
