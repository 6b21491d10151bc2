"""Reading a file latentrl is given: a regular file under a size cap, checked on the opened file
before a byte of it is read (issue #38); the Python twin of the Rust `sim::files`.

A FIFO blocks its reader (and Ctrl-C with it) until someone writes, a device such as
``/dev/zero`` never ends, a directory is no file: each is refused, naming what it is. The file is
opened without blocking (``O_NONBLOCK``: a FIFO without a writer opens at once; ``O_NOCTTY``)
and its kind and size are read from the open descriptor, so a file swapped between a check and
the open is caught too; at most ``cap + 1`` bytes are read, so a file growing while read is
refused as well. The caps are listed in docs/robustness.md ("Files: regular, and bounded").

Refusals are ValueErrors whose message is a sentence without the path ("is not a regular file
(a FIFO)"), for the caller to prefix with the file's name, as the Rust helper's; a file that
cannot be opened raises the OSError of ``os.open`` (it names the file).
"""

from __future__ import annotations

import contextlib
import errno
import os
import stat
from collections.abc import Iterator
from pathlib import Path
from typing import BinaryIO

MAX_TASK_FILE_BYTES = 1 << 20
"""The largest task file read: 1 MiB, as the native reader (`sim::task::MAX_TASK_FILE`)."""

MAX_URDF_BYTES = 16 << 20
"""The largest URDF read: 16 MiB, as the native reader (`sim::MAX_URDF_BYTES`)."""

MAX_MESH_BYTES = 128 << 20
"""The largest collision mesh read: 128 MiB, as the native loader (`sim::urdf::mesh::MAX_MESH_BYTES`)."""

MAX_JSON_BYTES = 64 << 20
"""The largest JSON file of a run read (results.json, rollout.json, a sweep cell's meta): 64 MiB."""

MAX_SWEEP_FILE_BYTES = 1 << 20
"""The largest sweep file (TOML or YAML) read: 1 MiB."""


def _human(n: int) -> str:
    """`n` bytes in the largest binary unit that divides it ("1 MiB"), as the Rust helper."""
    for size, unit in ((1 << 30, "GiB"), (1 << 20, "MiB"), (1 << 10, "KiB")):
        if n >= size and n % size == 0:
            return f"{n // size} {unit}"
    return f"{n} bytes"


def too_large(size: int, cap: int, what: str) -> str:
    """The sentence refusing a file of `size` bytes over `cap` (`what`: "a task file")."""
    return f"is {size} bytes, more than the {cap} bytes ({_human(cap)}) {what} may have"


def not_regular(mode: int) -> str:
    """What a file that is not a regular file is (`mode`: its `st_mode`), as a refusal's sentence."""
    kinds = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
             (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))
    for test, name in kinds:
        if test(mode):
            return f"is not a regular file ({name})"
    return "is not a regular file"


@contextlib.contextmanager
def open_regular(path: str | os.PathLike[str], cap: int, what: str) -> Iterator[BinaryIO]:
    """`path` opened for binary reading if it is a regular file of at most `cap` bytes; else a
    ValueError saying why not (`what` names the kind of file: "a task file")."""
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_NOCTTY", 0) | getattr(os, "O_BINARY", 0)
    fd = os.open(path, flags)
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise ValueError(not_regular(info.st_mode))
        if info.st_size > cap:
            raise ValueError(too_large(info.st_size, cap, what))
        if hasattr(os, "set_blocking"):
            os.set_blocking(fd, True)
        fh = os.fdopen(fd, "rb")
    except BaseException:
        os.close(fd)
        raise
    with fh:
        yield fh


def read_bounded(path: str | os.PathLike[str], cap: int, what: str) -> bytes:
    """The bytes of the regular file `path`, at most `cap` of them (`open_regular`); one more (the
    file grew since it was opened) is refused too."""
    with open_regular(path, cap, what) as fh:
        data = fh.read(cap + 1)
    if len(data) > cap:
        raise ValueError(too_large(len(data), cap, what))
    return data


def read_text(path: str | os.PathLike[str], cap: int, what: str) -> str:
    """`read_bounded` as UTF-8 text (a ValueError naming the line and byte if it is not, as the
    Rust helper)."""
    return utf8(read_bounded(path, cap, what))


def utf8(data: bytes, how: str = "") -> str:
    """`data` decoded as UTF-8, or a ValueError naming the line and byte that are not (a Latin-1
    comment), as an editor shows them; `how`: appended to "save it as UTF-8"."""
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as err:
        line = data.count(b"\n", 0, err.start) + 1
        raise ValueError(f"is not UTF-8 text (line {line} has byte {data[err.start]:#04x}); save it as UTF-8{how}") \
            from None


def absolute(path: str | os.PathLike[str], what: str) -> Path:
    """`path` made absolute with its symbolic links resolved, or a ValueError naming it (`what`:
    how the user gave it, "--demos") if they loop (Python's own error was a RuntimeError)."""
    try:
        return Path(path).resolve()
    except (RuntimeError, OSError) as err:  # Python < 3.13: RuntimeError; 3.13: OSError (ELOOP)
        if isinstance(err, OSError) and err.errno != errno.ELOOP:
            raise
        raise ValueError(f"{what} {path}: is a loop of symbolic links") from None
