"""Without the `[plot]` extra (matplotlib) the core works and figures say what to install."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path


def test_core_without_matplotlib() -> None:
    script = Path(__file__).with_name("core_without_matplotlib.py")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert "core without matplotlib: ok" in done.stdout
