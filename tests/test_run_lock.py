"""One writer per run folder (issue #38): a second `latentrl train` into a folder another process
writes stops at once naming it; a lock left by a killed process is no lock; a run that failed
before writing leaves no folder."""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from latentrl.run_lock import LOCK_FILE, run_lock

EXAMPLE = Path(__file__).resolve().parents[1] / "examples" / "glass_arm"


def test_a_second_writer_is_refused_naming_the_first(tmp_path):
    out = tmp_path / "run"
    with run_lock(out):
        result = subprocess.run(
            [sys.executable, "-m", "latentrl", "train", str(EXAMPLE / "glass_arm.toml"), "--demos",
             str(EXAMPLE / "demos.csv"), "--out", str(out), "--quick", "--episodes", "2", "--no-progress"],
            capture_output=True, text=True, timeout=300)
        assert result.returncode == 1, result.stderr
        assert f"another latentrl process (pid {os.getpid()}) is writing there" in result.stderr
        assert "Traceback" not in result.stderr
        assert sorted(p.name for p in out.iterdir()) == [LOCK_FILE]
    with pytest.raises(ValueError, match="is writing there"), run_lock(tmp_path / "nested"), run_lock(tmp_path / "nested"):
        pass


def test_a_lock_left_by_a_killed_process_is_taken(tmp_path):
    out, ready = tmp_path / "run", tmp_path / "ready"
    code = (f"from latentrl.run_lock import run_lock\nimport pathlib, time\nwith run_lock({str(out)!r}):\n"
            f"    pathlib.Path({str(ready)!r}).write_text('x')\n    time.sleep(600)\n")
    child = subprocess.Popen([sys.executable, "-c", code])
    try:
        for _ in range(600):
            if ready.exists():
                break
            time.sleep(0.05)
        assert ready.exists()
        with pytest.raises(ValueError, match=f"pid {child.pid}"), run_lock(out):
            pass
    finally:
        child.send_signal(signal.SIGKILL)
        child.wait()
    with run_lock(out):
        assert (out / LOCK_FILE).read_text() == str(os.getpid())


def test_a_run_that_wrote_nothing_leaves_no_folder(tmp_path):
    with pytest.raises(RuntimeError), run_lock(tmp_path / "new"):
        raise RuntimeError("setup failed")
    assert not (tmp_path / "new").exists()
    (tmp_path / "kept").mkdir()
    with run_lock(tmp_path / "kept"):
        (tmp_path / "kept" / "results.json").write_text("{}")
    assert (tmp_path / "kept" / "results.json").exists()
