"""Bounded wall time per run, and stops that reach a call stuck inside a component.

A run stops at the next communication point once its wall-time limit (:func:`guarded`, counted
from the start of stepping: :func:`start_clock`) has passed or a SIGINT / SIGTERM was received
(:mod:`orchestrator.common.interrupt`): the stepping loops check :func:`run_deadline` and the
stop request once per step. A component call that does not return (a hung block or FMU
``doStep``) never reaches that check, so :data:`GRACE` seconds after the stop was due the
watchdog raises :class:`Hung` into the thread running it: in the main thread from a SIGALRM
handler (which also breaks a blocking ``time.sleep`` or read), in another thread (a Dask
worker's) with ``PyThreadState_SetAsyncExc`` (delivered at the next Python bytecode the call
runs). The exception is raised only while the thread is inside :func:`guarded` (a run), never
into the code that writes results. A call blocked inside C code that never returns to Python
cannot be interrupted in-process; it ends with the process (the campaign's worker).
"""
from __future__ import annotations

import contextlib
import ctypes
import math
import numbers
import signal
import threading
import time

from orchestrator.common.errors import InputError

GRACE = 1.0  # s a component call gets to return to the stepping loop after a stop is due
# s: the largest wall-time limit, timeout or wait ftcsim takes (a year): above it a limit is no limit, and
# the platform's timers overflow (threading.TIMEOUT_MAX, time_t); larger values are refused, not clamped
MAX_SECONDS = 365 * 86400.0


def check_limit(x, source="command line", key="--time-limit") -> float | None:
    """A wall-time limit argument: None or 0 (none) or a finite number of seconds in (0, MAX_SECONDS]
    (Python and numpy numbers alike; booleans refused)."""
    real = isinstance(x, numbers.Real) and not isinstance(x, bool) and type(x).__name__ != "bool_"
    if x is None or (real and float(x) == 0):
        return None
    try:
        v = float(x) if real else math.nan
    except (OverflowError, ValueError):
        v = math.inf
    if not math.isfinite(v) or v < 0:
        raise InputError(source, key, f"must be a number of seconds > 0 (0: no limit), got {x!r}")
    if v > MAX_SECONDS:
        raise InputError(source, key, f"{v:g} s is more than the {MAX_SECONDS:g} s (a year) a limit may be; "
                                      "give 0 for no limit")
    return v


class Hung(BaseException):
    """Raised into a component call that did not return within GRACE s of a due stop. A
    BaseException: component wrappers that turn ``Exception`` into errors let it through."""

    def __init__(self, *args):
        if not args:  # raised by class from another thread (PyThreadState_SetAsyncExc): the run says why
            r = _ACTIVE.get(threading.get_ident())
            args = (r.fired,) if r is not None and r.fired else ("a component call was interrupted",)
        super().__init__(*args)


class _Run:
    __slots__ = ("deadline", "limit", "fired", "thread", "timer", "done")

    def __init__(self):
        self.deadline = None  # time.monotonic() s after which the run must stop
        self.limit = None  # s
        self.fired = None  # why Hung was raised (None: not raised)
        self.thread = threading.get_ident()
        self.timer = None
        self.done = False


_LOCK = threading.Lock()
_ACTIVE: dict = {}  # thread id -> _Run of the run that thread is in (inside guarded())
_MAIN = threading.main_thread().ident


def current():
    return _ACTIVE.get(threading.get_ident())


def run_deadline() -> float | None:
    """time.monotonic() s at which this thread's run must stop (None: no limit)."""
    r = _ACTIVE.get(threading.get_ident())
    return None if r is None else r.deadline


def forced_stop() -> str | None:
    """Why Hung was raised into this thread's run (None: it was not)."""
    r = _ACTIVE.get(threading.get_ident())
    return None if r is None else r.fired


def timed_out() -> bool:
    """True if this thread's run is past its time limit (checked once per step)."""
    r = _ACTIVE.get(threading.get_ident())
    return r is not None and r.deadline is not None and time.monotonic() > r.deadline


def stop_reason(request, t: float) -> tuple[str, int, bool] | None:
    """(error, signal number, timed out) if the run must stop at communication point ``t``
    (a stop request or the time limit), else None. Called once per step by the stepping loops."""
    if request:
        return f"interrupted by {request.name} at t = {t:.6g} s", request.signum, False
    if timed_out():
        r = current()
        return f"time limit of {r.limit:g} s (wall time) exceeded at t = {t:.6g} s", 0, True
    return None


def _raise_in(run: _Run, reason: str) -> None:
    """Raise Hung(reason) in the thread of ``run`` if it is still inside it."""
    with _LOCK:
        if _ACTIVE.get(run.thread) is not run or run.fired or run.done:
            return
        run.fired = reason
        if run.thread == _MAIN:
            signal.pthread_kill(run.thread, signal.SIGALRM)  # the handler raises (breaks a blocking call)
        else:
            ctypes.pythonapi.PyThreadState_SetAsyncExc(ctypes.c_ulong(run.thread), ctypes.py_object(Hung))


def _on_alarm(signum, frame):
    r = _ACTIVE.get(_MAIN)
    if r is not None and r.fired and not r.done:
        raise Hung(r.fired)


def force_stop_later(reason: str, delay: float = GRACE) -> None:
    """After ``delay`` s, raise Hung(reason) into the current thread's run if it is still in one
    (a signal handler calls this for the main thread's run)."""
    r = _ACTIVE.get(_MAIN if threading.current_thread() is threading.main_thread() else threading.get_ident())
    if r is None:
        return
    t = threading.Timer(delay, _raise_in, (r, reason))
    t.daemon = True
    t.start()


def start_clock() -> None:
    """Start the time limit of this thread's run (the runner calls it when stepping begins: set-up,
    which imports and compiles in a fresh process, is not limited, and an import is never cut)."""
    run = _ACTIVE.get(threading.get_ident())
    if run is None or run.limit is None or run.deadline is not None:
        return
    run.deadline = time.monotonic() + run.limit
    run.timer = threading.Timer(run.limit + GRACE, _raise_in,
                                (run, f"time limit of {run.limit:g} s (wall time) exceeded inside a component call"))
    run.timer.daemon = True
    run.timer.start()


@contextlib.contextmanager
def guarded(limit: float | None = None):
    """The frame of one run in this thread: its wall-time limit (s; None or 0: none; counted from
    :func:`start_clock`) and the watchdog that raises :class:`Hung` into a call still running
    GRACE s after a stop was due. Yields the run's record (``.fired``: why Hung was raised, or None)."""
    run = _Run()
    prev = _ACTIVE.get(run.thread)
    main = run.thread == _MAIN
    old_handler = None
    if main:
        old_handler = signal.signal(signal.SIGALRM, _on_alarm)
        old_handler = None if old_handler is _on_alarm else old_handler
    run.limit = float(limit) if limit else None
    _ACTIVE[run.thread] = run
    try:
        yield run
    finally:
        while True:  # a Hung arriving while this frame is left is dropped: the run is over anyway
            try:
                run.done = True
                if run.timer is not None:
                    run.timer.cancel()
                with _LOCK:  # no Hung is sent to this thread after this
                    if prev is None:
                        _ACTIVE.pop(run.thread, None)
                    else:
                        _ACTIVE[run.thread] = prev
                if main and callable(old_handler):  # else ours stays: it only acts for a run that fired
                    signal.signal(signal.SIGALRM, old_handler)
                break
            except Hung:
                continue
