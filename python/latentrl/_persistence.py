"""Saved files: written atomically (a temporary file renamed over the target, so an interrupted
write leaves no half-written file), NPZ archives read back without pickles and under a size cap,
and the format and version a saved latentrl file must hold."""

from __future__ import annotations

import contextlib
import os
import struct
import uuid
import zlib
from collections.abc import Callable, Collection, Iterator, Mapping
from pathlib import Path
from typing import IO, Any

import numpy as np
from numpy.typing import NDArray

from latentrl._files import open_regular

#: Version of the NPZ layout written by `Estimator.save`; `load` refuses any other.
FORMAT_VERSION = 1

PathLike = str | os.PathLike[str]


@contextlib.contextmanager
def naming_os_errors(path: Path) -> Iterator[None]:
    """An OSError raised inside (a full disk, a read-only folder) names `path`, unless it already
    does: `cannot write PATH: No space left on device` (issue #38)."""
    try:
        yield
    except OSError as err:
        if str(path) in str(err):
            raise
        raise type(err)(err.errno, f"cannot write {path}: {err.strerror or err}") from err


NAME_KEPT = 32
"""The most characters of the name written that its temporary file's name keeps: a name of 218
to 255 characters (legal) was refused after the work, its temporary's 38 more too long."""


def atomic_write(path: PathLike, write: Callable[[IO[bytes]], object]) -> None:
    """Calls `write` (its result is ignored) on a temporary file beside `path` (creating
    missing parent directories), flushes it to disk, then renames it over `path`, so an
    interrupted write never leaves a half-written file. A process killed mid-write leaves
    only `.{name}.<hex>.tmp` behind (the name cut to `NAME_KEPT` characters). An OSError names
    `path` (`naming_os_errors`)."""
    path = Path(path)
    tmp = path.with_name(f".{path.name[:NAME_KEPT]}.{uuid.uuid4().hex}.tmp")
    try:
        with naming_os_errors(path):
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(tmp, "xb") as fh:
                write(fh)
                fh.flush()
                os.fsync(fh.fileno())
            os.replace(tmp, path)
    except BaseException:
        _remove(tmp)
        raise


@contextlib.contextmanager
def atomic_path(path: PathLike) -> Iterator[Path]:
    """A temporary file name beside `path` (missing parent directories are made, as by
    `atomic_write`; its stem cut to `NAME_KEPT` characters) that keeps its suffix (for writers that
    take a name and choose the format by it: imageio, rerun), renamed over `path` when the block
    ends and removed if it raises, so such a writer never leaves a half-written `path`; an
    OSError in the block names `path` (`naming_os_errors`)."""
    path = Path(path)
    tmp = path.with_name(f".{path.stem[:NAME_KEPT]}.{uuid.uuid4().hex}.tmp{path.suffix}")
    try:
        with naming_os_errors(path):
            path.parent.mkdir(parents=True, exist_ok=True)
            yield tmp
            os.replace(tmp, path)
    finally:
        _remove(tmp)


def _remove(tmp: Path) -> None:
    """Removes the temporary file of a write that failed, if it can: on a read-only file system
    even a missing file's unlink is EROFS, which hid the write's own error (naming the temporary
    file, not the one written)."""
    with contextlib.suppress(OSError):
        tmp.unlink(missing_ok=True)


MAX_NPZ_BYTES = 2**30
"""The most bytes an NPZ file read by latentrl (a model, a run's returns) may have, and the most
bytes of arrays it may unpack to."""


class _TooLarge(ValueError):
    """An NPZ archive refused for its size, not for being corrupt."""


def _check_npz_sizes(fh: IO[bytes]) -> None:
    """Refuses, before anything is unpacked, an archive that would unpack to more than
    MAX_NPZ_BYTES (a zip bomb) or a member whose header declares more data than the member
    holds (an array of 10¹² elements in a small file)."""
    import zipfile  # loaded by the first read, not by `import latentrl`

    with zipfile.ZipFile(fh) as archive:
        members = archive.infolist()
        total = sum(m.file_size for m in members)
        if total > MAX_NPZ_BYTES:
            raise _TooLarge(f"it unpacks to {total} bytes, more than the {MAX_NPZ_BYTES} latentrl reads")
        for member in members:
            with archive.open(member) as item:
                version = np.lib.format.read_magic(item)
                read_header = np.lib.format.read_array_header_1_0 if version == (1, 0) else np.lib.format.read_array_header_2_0
                shape, _, dtype = read_header(item)
                declared = int(np.prod(shape, dtype=object)) * dtype.itemsize
                if declared > member.file_size:
                    raise _TooLarge(f"{member.filename}: its header declares {declared} bytes of data, the "
                                    f"member holds {member.file_size}")


def read_npz(path: PathLike, keys: Collection[str] | None = None) -> dict[str, NDArray[Any]]:
    """Every array of the NPZ file at `path` (those named in `keys` if given), read eagerly
    without pickles; a file that is not a regular file of at most MAX_NPZ_BYTES
    (`latentrl._files`) or not a readable NPZ is a ValueError."""
    import tokenize  # with zipfile: loaded by the first read, not by `import latentrl`
    import zipfile

    with open_regular(path, MAX_NPZ_BYTES, "an NPZ file") as fh:
        magic = fh.read(6)
        if magic.startswith(b"\x93NUMPY"):
            raise ValueError("not a readable NPZ file: it holds a single array (.npy), not an NPZ archive")
        if not magic.startswith(b"PK\x03\x04"):
            raise ValueError("not a readable NPZ file: it has no zip archive header (latentrl writes models and results as .npz)")
        fh.seek(0)
        try:
            _check_npz_sizes(fh)
            fh.seek(0)
            npz = np.load(fh, allow_pickle=False)
            if not isinstance(npz, np.lib.npyio.NpzFile):
                raise ValueError("it holds a single array, not an NPZ archive")
            with npz:
                return {key: npz[key] for key in npz.files if keys is None or key in keys}
        except _TooLarge as err:
            raise ValueError(f"refused NPZ file: {err}") from None
        # Issue #38: a flipped byte can also name an unknown compression method (NotImplementedError),
        # spoil an array header (tokenize's TokenError, SyntaxError) or a zip record (struct.error).
        except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error, NotImplementedError, SyntaxError,
                tokenize.TokenError, struct.error) as err:
            raise ValueError(f"not a readable NPZ file (corrupt or truncated?): {err}") from err


def check_format(arrays: Mapping[str, Any], expected: str, path: str) -> None:
    """ValueError naming `path` unless `arrays` (a saved file's) hold the format `expected` (e.g.
    "latentrl.GPLVM") at this latentrl's `FORMAT_VERSION`."""
    found = str(arrays["format"]) if "format" in arrays else None
    if found != expected:
        raise ValueError(f"{path}: holds {found or 'no latentrl file'}, expected {expected}")
    version = arrays.get("format_version")
    if version is None or version.ndim != 0 or version.dtype.kind != "i" or int(version) != FORMAT_VERSION:
        shown = "missing" if version is None else f"{version.tolist()!r} ({version.dtype})"
        raise ValueError(f"{path}: format_version {shown} is not supported (this latentrl reads the integer "
                         f"{FORMAT_VERSION})")

