"""Ending a process that has run FMUs.

FMUs built by ftcsim carry an export library without pythonfmu's exit-time double release
(fmus/export_library.py): a process that ran them ends like any other, with ``sys.exit``
(measured: docs/external-tools.md, "Hosts exit cleanly"). An FMU that still carries pythonfmu's
own library (a third-party pythonfmu FMU, or ``ftcsim build --export-library stock``) writes into
freed memory when the process exits, which can abort it after every result is written; the
components that load such an FMU call :func:`avoid_teardown`, and :func:`finish` then runs the
exit handlers (which remove the extracted FMU folders), flushes the streams and ends with
``os._exit``. Callers must have closed and published every file they write before calling it."""
import atexit
import os
import sys

_REASONS: list[str] = []  # why this process must not run the interpreter's teardown


def avoid_teardown(reason: str) -> None:
    """Ask :func:`finish` to end without the interpreter's teardown (``reason``: which FMU, why)."""
    if reason not in _REASONS:
        _REASONS.append(reason)


def teardown_avoided() -> list[str]:
    """The reasons given so far (empty: :func:`finish` ends with ``sys.exit``)."""
    return list(_REASONS)


def finish(code: int | None) -> None:
    """End the process with ``code``; without the interpreter's teardown if a stock pythonfmu
    library ran here."""
    if _REASONS:
        atexit._run_exitfuncs()  # our clean-ups (extracted FMU folders) still run
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code or 0)
    sys.exit(code)
