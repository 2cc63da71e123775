"""SIGINT / SIGTERM during a run: stop at the next communication point, keep what was computed.

While :func:`handling_signals` is active, the first SIGINT or SIGTERM only sets
:data:`REQUEST` (no exception is raised inside an FMU's Python code, which would leave the FMU in
an error state); the master checks it once per step, ends the run as incomplete and the command
writes the rows so far, terminates the FMUs, removes its temporary folders and exits with 130
(SIGINT) or 143 (SIGTERM). A second signal of the same kind interrupts at once.
"""
from __future__ import annotations

import contextlib
import signal
import threading

from orchestrator.common.watchdog import GRACE, force_stop_later


class StopRequest:
    __slots__ = ("signum",)

    def __init__(self):
        self.signum = 0  # 0: keep going

    def __bool__(self) -> bool:
        return self.signum != 0

    @property
    def name(self) -> str:
        return signal.Signals(self.signum).name if self.signum else ""

    @property
    def exit_status(self) -> int:
        return 128 + self.signum if self.signum else 0


REQUEST = StopRequest()


class Interrupted(Exception):
    """Raised after a run that a signal stopped has been written; carries the exit status."""

    def __init__(self, message: str, exit_status: int):
        super().__init__(message)
        self.exit_status = exit_status


@contextlib.contextmanager
def handling_signals():
    """Route SIGINT and SIGTERM into :data:`REQUEST` for the duration of the block."""
    REQUEST.signum = 0

    def handler(signum, frame):
        if REQUEST.signum == signum:  # second time: stop now
            raise KeyboardInterrupt
        REQUEST.signum = signum
        # a run stuck inside a component call never sees REQUEST: the watchdog interrupts the call
        force_stop_later(f"interrupted by {REQUEST.name}: a component call did not return within {GRACE:g} s")

    if threading.current_thread() is not threading.main_thread():  # signals reach the main thread only
        yield REQUEST
        return
    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield REQUEST
    finally:
        for s, h in previous.items():
            signal.signal(s, h)
