"""Ending a process that has run pythonfmu FMUs.

Once an FMU has run in a process, the interpreter's own teardown can abort in pythonfmu's native
code ("corrupted double-linked list", exit -6) after every result is written. :func:`finish`
runs the exit handlers (which remove the extracted FMU folders), flushes the streams and ends
with ``os._exit`` in that case; otherwise it is ``sys.exit``. Callers must have closed and
published every file they write before calling it."""
import atexit
import os
import sys


def fmus_loaded() -> bool:
    """True once a pythonfmu / pythonfmu3 slave (ours: ``ftcsim_*``, ``ftcsim3_*``) is imported."""
    return any(m.split(".")[0] in ("pythonfmu", "pythonfmu3") or m.startswith(("ftcsim_", "ftcsim3_"))
               for m in list(sys.modules))


def finish(code: int | None) -> None:
    """End the process with ``code``, bypassing the interpreter's teardown if FMUs ran here."""
    if fmus_loaded():
        atexit._run_exitfuncs()  # our clean-ups (extracted FMU folders) still run
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code or 0)
    sys.exit(code)
