"""The optional libraries of the recording formats, imported when a file of that format is read."""

from __future__ import annotations

import importlib
from types import ModuleType


def needs(module: str, what: str, extra: str) -> ModuleType:
    """`module`, imported; without it a ModuleNotFoundError (`name`: the missing top-level
    package) saying which extra installs it, which the command line prints as one line."""
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as err:
        top = module.partition(".")[0]
        if err.name not in (top, module):  # something else is missing: not ours to explain
            raise
        raise ModuleNotFoundError(f"reading {what} needs {top}: pip install 'latentrl[{extra}]'", name=top) from err
