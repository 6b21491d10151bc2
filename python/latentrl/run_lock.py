"""One writer per run folder: `latentrl run`, `train`, `sweep` and `rollout` hold an OS lock
(`fcntl.flock`) on `FOLDER/.lock` while they write there, so a second writer into the same
folder stops at once naming the first (before, both exited 0 and one run was lost). The kernel
drops the lock when its process ends, however it ends, so a lock left by a killed run is no
lock: the next writer takes it."""

from __future__ import annotations

import contextlib
import fcntl
import os
from collections.abc import Iterator
from pathlib import Path

LOCK_FILE = ".lock"
"""The lock's file in a run folder (it holds the writer's pid, for the message)."""


@contextlib.contextmanager
def run_lock(folder: Path | str) -> Iterator[None]:
    """Holds `folder`'s lock for the block (creating the folder); a ValueError naming the holder if
    another process holds it. A folder this call created and nothing else wrote to is removed
    again, so a run that failed before writing leaves nothing."""
    folder = Path(folder)
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / LOCK_FILE
    fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW, 0o644)
    try:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode(errors="replace").strip() or "unknown"
            raise ValueError(f"{folder}: another latentrl process (pid {holder}) is writing there; wait for it "
                             "or choose another folder") from None
        os.ftruncate(fd, 0)
        os.pwrite(fd, str(os.getpid()).encode(), 0)
        yield
    finally:
        os.close(fd)
        if created and [p.name for p in folder.iterdir()] == [LOCK_FILE]:
            path.unlink()
            folder.rmdir()
