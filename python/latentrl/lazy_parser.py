"""An argparse subcommand whose flags are added only when it is used: `latentrl --help` needs
none of them, `latentrl train --nope` only train's, and building `run`'s imports every
experiment and its preset (issue #39, item 5: a CLI that starts at once)."""

from __future__ import annotations

import argparse
from collections.abc import Callable, Sequence
from typing import Any


class LazyParser(argparse.ArgumentParser):
    """An ArgumentParser that calls `fill(self)` once, before it first parses or formats a usage
    or help; `fill` adds its arguments (and subcommands) as it would have at construction."""

    def __init__(self, *args: Any, fill: Callable[[argparse.ArgumentParser], None] | None = None, **kwargs: Any):
        super().__init__(*args, **kwargs)
        self._fill = fill

    def filled(self) -> LazyParser:
        """This parser with its arguments added."""
        fill, self._fill = self._fill, None
        if fill is not None:
            fill(self)
        return self

    def parse_known_args(  # type: ignore[override]  # the overloads of typeshed, one body
        self, args: Sequence[str] | None = None, namespace: Any = None
    ) -> tuple[Any, list[str]]:
        return super(LazyParser, self.filled()).parse_known_args(args, namespace)

    def format_usage(self) -> str:
        return super(LazyParser, self.filled()).format_usage()

    def format_help(self) -> str:
        return super(LazyParser, self.filled()).format_help()
