"""Temporary folders ftcsim creates in a process (extracted FMUs, SSP packages being read), removed
when the process ends (also through ``orchestrator/common/process_exit.py``, which runs the exit
handlers before it bypasses the interpreter's teardown)."""
from __future__ import annotations

import atexit
import shutil

_FOLDERS: list[str] = []


def remove_at_exit(folder: str) -> str:
    """Register ``folder`` (which this process created) for removal at exit; returns it."""
    _FOLDERS.append(str(folder))
    return str(folder)


@atexit.register
def _remove_all() -> None:
    for folder in _FOLDERS:
        shutil.rmtree(folder, ignore_errors=True)
