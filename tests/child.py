"""A `latentrl` command in a child process that can be stopped at a known point, for the Ctrl-C
and kill -9 tests: synchronised on files the child creates, not on time."""

import time

# Ctrl-C must reach the child even where the test runner was started with SIGINT ignored
# (a background job of a non-interactive shell): the child restores Python's handler. Two test
# hooks synchronise on files instead of time: LATENTRL_TEST_HOLD_AFTER_SAVE=path makes the child
# hold (sleep) right after it saved its first trial, having created `path`; and
# LATENTRL_TEST_NATIVE_STARTED=path creates `path` from inside the first native trial call.
CHILD = """
import os, signal, sys, time
from pathlib import Path
signal.signal(signal.SIGINT, signal.default_int_handler)
from latentrl import _native
from latentrl.experiments import runner
hold, started = os.environ.get("LATENTRL_TEST_HOLD_AFTER_SAVE"), os.environ.get("LATENTRL_TEST_NATIVE_STARTED")
if hold:
    save = runner._save
    def save_then_hold(*args):
        save(*args)
        Path(hold).touch()
        time.sleep(3600)
    runner._save = save_then_hold
if started:
    run = _native.run_bimanual_trials
    def run_and_report(**kwargs):
        report = kwargs.get("progress")
        def progress(done, total):
            Path(started).touch()
            if report is not None:
                report(done, total)
        return run(**{**kwargs, "progress": progress})
    _native.run_bimanual_trials = run_and_report
from latentrl.cli import main
sys.exit(main(sys.argv[1:]))
"""


def wait_for(marker, proc, timeout=240):
    """Until the child creates `marker` (a generous timeout against a hung child, not a speed bound)."""
    deadline = time.monotonic() + timeout
    while not marker.exists():
        assert proc.poll() is None, proc.communicate()[1]
        assert time.monotonic() < deadline, f"the child never created {marker}"
        time.sleep(0.02)
