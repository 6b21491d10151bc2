"""The `latentrl` console script: parses the arguments (`latentrl.cli_parser`), checks that the
outputs can be written, runs the subcommand (`latentrl.cli_commands`) and turns its errors into
exit codes (`latentrl.cli_parser.DESCRIPTION` lists them)."""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import sys
import warnings
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from latentrl.cli_commands import COMMANDS
from latentrl.cli_parser import build_parser

if TYPE_CHECKING:
    from _typeshed import ReadableBuffer

__all__ = ["build_parser", "main"]


NAME_MAX = 255
"""The most bytes of a file or folder name (ext4, XFS, Btrfs, APFS, tmpfs)."""


def _check_writable(flag: str, out: Path, *, file: bool) -> None:
    """The output `out` of `flag` can be written: its nearest existing ancestor is a writable
    directory (missing folders are made, for a file as for a folder) and it is not a directory
    where a file goes, or a file where a directory goes. Checked before any fit, trial or
    frame, so a typo costs nothing. No name on its path may be longer than `NAME_MAX` bytes."""
    long = next((part for part in out.parts if len(os.fsencode(part)) > NAME_MAX), None)
    if long is not None:
        raise ValueError(f"{flag} {out}: the name {long[:24]}… is {len(os.fsencode(long))} bytes long, more than "
                         f"the {NAME_MAX} a file or folder name may have")
    if out.exists() and out.is_dir() == file:
        raise ValueError(f"{flag} {out}: is {'a directory' if file else 'a file'}, expected {'a file' if file else 'a directory'}")
    if not file and out.is_symlink() and not out.exists():  # no folder can be made there (File exists, after the work)
        raise ValueError(f"{flag} {out}: is a symbolic link to nothing (its target is missing, or the links loop)")
    parent = (out.parent if file else out).absolute()
    while not parent.exists():
        parent = parent.parent
    if not parent.is_dir() or not os.access(parent, os.W_OK | os.X_OK):
        raise ValueError(f"{flag} {out}: cannot write under {parent}")


OUTPUTS = {"out": "--out", "rerun": "--rerun"}
"""The path arguments a command writes, by their `args` name, with their flags."""

FILE_OUTPUTS = {("fit", "out"), ("replay", "out"), ("replay", "rerun")}
"""The outputs that are files (the others are folders), by command and `args` name."""


INPUTS = {"task": "task file", "demos": "--demos", "model": "--model", "results": "results", "file": "sweep file",
          "urdf": "URDF", "resume": "--resume"}
"""The path arguments a command reads, by their `args` name, with how the user wrote them."""


def _check_inputs(args: object) -> None:
    """Every path a command reads exists: named as the user gave it, before any work."""
    for name, label in INPUTS.items():
        path = getattr(args, name, None)
        if isinstance(path, Path) and not path.exists() and not path.is_symlink():  # a link: its reader says how it fails
            given = "demos" if getattr(args, "command", None) == "fit" and name == "demos" else label  # fit's is positional
            raise ValueError(f"{given} {path}: no such file or directory")


RECORDING_LIBRARIES = ("pyarrow", "h5py", "rosbags")
"""The libraries of the recording extras ([lerobot], [hdf5], [rosbag])."""


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the `latentrl` console script."""
    _tolerant_streams()
    with _kept_going() as stdout:
        args = build_parser().parse_args(argv)
        with warnings.catch_warnings():
            warnings.showwarning = _show_warning
            code = _run(args)
        if stdout is not None:
            sys.stdout.flush()
            if stdout.failed is not None:
                print(f"latentrl: error: cannot write to standard output: {stdout.failed}", file=sys.stderr)
                code = 1
    return code


def _tolerant_streams() -> None:
    """stdout and stderr write a character their encoding lacks as its escape (``\\u2212``)
    instead of failing: on an ASCII or Latin-1 terminal (PYTHONIOENCODING, the locale) `train`
    failed after its fit printing "−", `--help` on "…". A closed stderr (`2>&-`) becomes
    os.devnull: Python leaves it None, and a message printed to None went to stdout."""
    if sys.stderr is None:
        sys.stderr = open(os.devnull, "w")  # for the life of the process
    for stream in (sys.stdout, sys.stderr):
        if isinstance(stream, io.TextIOWrapper):
            stream.reconfigure(errors="backslashreplace")


class _KeepGoing(io.FileIO):
    """A standard stream's file descriptor whose failure ends the printing, not the command: a
    reader gone (`latentrl train … | head -2`: the train ran, then exited 1 without report.json)
    or a full disk points it at os.devnull (Python's recipe for a closed pipe), and the command
    finishes and writes its files. A failure other than a closed pipe is kept in `failed`."""

    failed: OSError | None = None

    def write(self, data: ReadableBuffer) -> int:
        try:
            return super().write(data)
        except OSError as err:
            if not isinstance(err, BrokenPipeError):
                self.failed = err
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, self.fileno())
            os.close(devnull)
            return memoryview(data).nbytes


@contextlib.contextmanager
def _kept_going() -> Iterator[_KeepGoing | None]:
    """While a command runs, sys.stdout and sys.stderr write through a `_KeepGoing` each
    (`_keep_going`), flushed and put back at the end (a caller in this process, a test, reads
    what follows as before); yields stdout's, None if it has no file descriptor."""
    saved = sys.stdout, sys.stderr
    files = {name: _keep_going(name) for name in ("stdout", "stderr")}
    try:
        yield files["stdout"]
    finally:
        for name, file in files.items():
            if file is not None:
                getattr(sys, name).flush()
        sys.stdout, sys.stderr = saved


def _keep_going(name: str) -> _KeepGoing | None:
    """`sys.<name>` (stdout, stderr) written through a `_KeepGoing`, its encoding and buffering
    kept; None where it has no file descriptor (closed, or a stream in memory), left as it is."""
    stream = getattr(sys, name)
    if not isinstance(stream, io.TextIOWrapper):
        return None
    try:
        fd = stream.fileno()
    except OSError:  # io.UnsupportedOperation: a stream in memory
        return None
    stream.flush()
    raw = _KeepGoing(fd, "w", closefd=False)
    setattr(sys, name, io.TextIOWrapper(io.BufferedWriter(raw), encoding=stream.encoding, errors=stream.errors,
                                        line_buffering=stream.line_buffering, write_through=stream.write_through))
    return raw


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int,
                  file: Any = None, line: str | None = None) -> None:
    """A warning as a CLI user reads it: one line, without the source line that raised it."""
    print(f"latentrl: warning: {message}", file=sys.stderr)


def _run(args: argparse.Namespace) -> int:
    """Runs the command of `args`; an error is one line on stderr and an exit code."""
    try:
        for name, flag in OUTPUTS.items():
            if getattr(args, name, None) is not None:
                _check_writable(flag, getattr(args, name), file=(args.command, name) in FILE_OUTPUTS)
        _check_inputs(args)
        return COMMANDS[args.command](args)
    except (ValueError, OSError) as err:
        print(f"latentrl: error: {err}", file=sys.stderr)
        return 1
    except ModuleNotFoundError as err:
        if err.name in RECORDING_LIBRARIES:  # its message names the extra (latentrl.recorded.libraries)
            print(f"latentrl: error: {err}", file=sys.stderr)
            return 1
        if err.name != "matplotlib":
            raise
        print("latentrl: error: figures need matplotlib: pip install 'latentrl[plot]'", file=sys.stderr)
        return 1
    except KeyboardInterrupt:  # commands that keep work say more themselves (`_interruptible`)
        print("latentrl: interrupted; nothing was written", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
