"""Progress bars that read well in a terminal and in a log: tqdm's bar on a terminal; when
stderr is not one (a file, CI, a pipe), one plain line every `LOG_INTERVAL_S` seconds
(done/total, rate, ETA) and one at the end, instead of a carriage-return redraw per update."""

from __future__ import annotations

import sys
from typing import Any, TextIO

from tqdm import tqdm

LOG_INTERVAL_S = 10.0
"""Seconds between two progress lines in a log."""


class LogLines(tqdm):  # type: ignore[type-arg]  # tqdm's stubs leave it generic
    """tqdm writing whole lines, at most one per `mininterval` (the final state at close)."""

    def display(self, msg: str | None = None, pos: int | None = None) -> None:
        if msg is None:  # a line per display; tqdm calls it at most once per `mininterval`
            print(self.format_meter(**self.format_dict), file=self.fp, flush=True)

    def close(self) -> None:
        if not self.disable and self.n != self.last_print_n:
            self.display()
        self.disable = True  # tqdm's own close would redraw the bar
        super().close()


def progress_bar(*, disable: bool = False, file: TextIO | None = None, **kwargs: Any) -> tqdm:  # type: ignore[type-arg]
    """A tqdm bar (keyword arguments as tqdm's) on a terminal, else `LogLines` every 10 s; none
    with stderr closed (`2>&-`: `sys.stderr` is None)."""
    stream = file if file is not None else sys.stderr
    if stream is None:
        return tqdm(disable=True, **kwargs)
    if stream.isatty():
        return tqdm(disable=disable, file=stream, **kwargs)
    kwargs.setdefault("bar_format", "{desc}: {n_fmt}/{total_fmt} {unit} [{elapsed} elapsed, {remaining} left, {rate_fmt}]")
    return LogLines(disable=disable, file=stream, mininterval=LOG_INTERVAL_S, maxinterval=LOG_INTERVAL_S, **kwargs)
