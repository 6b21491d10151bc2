"""Progress in a log (issue #23): with stderr not a terminal, whole lines at most every
LOG_INTERVAL_S and one at the end, never a carriage-return redraw."""

import io
import subprocess
import sys
import time

from latentrl.progress import LOG_INTERVAL_S, LogLines, progress_bar


def test_a_log_gets_a_line_per_interval_and_the_final_count():
    stream = io.StringIO()
    bar = progress_bar(total=40, unit="ep", desc="episodes", file=stream)
    assert isinstance(bar, LogLines) and bar.mininterval == LOG_INTERVAL_S == 10.0
    bar.mininterval = bar.maxinterval = 0.05  # the interval, shortened for the test
    for _ in range(40):
        time.sleep(0.005)
        bar.update(1)
    bar.close()
    text = stream.getvalue()
    lines = text.splitlines()
    assert "\r" not in text
    assert 2 <= len(lines) <= 10, lines  # ~0.2 s of updates at one line per 0.05 s, not 40 lines
    assert lines[-1].startswith("episodes: 40/40 ep"), lines[-1]


def test_a_terminal_keeps_the_tqdm_bar():
    class Terminal(io.StringIO):
        def isatty(self) -> bool:
            return True

    bar = progress_bar(total=3, file=Terminal())
    assert not isinstance(bar, LogLines)
    bar.close()


def test_a_closed_stderr_gets_no_bar(monkeypatch):
    """`2>&-` leaves `sys.stderr` None: the bar asked it whether it is a terminal and the run
    stopped with an AttributeError after its fit."""
    monkeypatch.setattr(sys, "stderr", None)
    with progress_bar(total=3, unit="ep", desc="episodes") as bar:
        bar.update(3)
    assert bar.disable


def test_a_run_logged_to_a_file_has_no_carriage_returns(tmp_path):
    log = tmp_path / "log.txt"
    with log.open("w") as out:
        result = subprocess.run(
            [sys.executable, "-m", "latentrl", "run", "exp1", "--quick", "--trials", "2", "--episodes", "30",
             "--plant.max-steps", "50", "--out", str(tmp_path / "run")],
            stdout=out, stderr=subprocess.STDOUT, timeout=300,
        )
    text = log.read_text()
    assert result.returncode == 0, text
    assert "\r" not in text and "episodes: 120/120 ep" in text, text
