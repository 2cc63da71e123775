"""Temporary folders ftcsim creates in a process (extracted FMUs, SSP packages being read), removed
when the process ends (also through ``orchestrator/common/process_exit.py``, which runs the exit
handlers before it bypasses the interpreter's teardown).

A process that dies without its exit handlers (a SIGSEGV inside a third-party FMU, SIGKILL) cannot
remove them; so they are created by :func:`owned_folder`, named after the process (``ftcsim-<pid>_...``),
and the first ftcsim process that creates one in a folder removes there the folders of this user
whose process no longer exists (:func:`sweep`)."""
from __future__ import annotations

import atexit
import os
import re
import shutil
import tempfile

_FOLDERS: list[str] = []
_SWEPT: set = set()
_OWNED = re.compile(r"^ftcsim-(\d+)_")


def remove_at_exit(folder: str) -> str:
    """Register ``folder`` (which this process created) for removal at exit; returns it."""
    _FOLDERS.append(str(folder))
    return str(folder)


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:  # another user's process
        return True
    return True


def sweep(parent: str) -> list[str]:
    """Remove the folders ``ftcsim-<pid>_...`` in ``parent`` that belong to this user and whose process
    is gone (once per folder and process); returns what was removed."""
    parent = os.path.abspath(parent)
    if parent in _SWEPT:
        return []
    _SWEPT.add(parent)
    removed = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return removed
    for e in entries:
        m = _OWNED.match(e.name)
        if not m or int(m[1]) == os.getpid():
            continue
        try:
            st = e.stat(follow_symlinks=False)
        except OSError:
            continue
        if e.is_dir(follow_symlinks=False) and st.st_uid == os.getuid() and not _alive(int(m[1])):
            shutil.rmtree(e.path, ignore_errors=True)
            removed.append(e.path)
    return removed


def owned_folder(prefix: str, parent: str | None = None) -> str:
    """A new folder ``ftcsim-<pid>_<prefix>XXXXXXXX`` in ``parent`` (default: the temporary folder),
    removed at exit, and after a crash by the next ftcsim process that makes one there."""
    parent = parent or tempfile.gettempdir()
    sweep(parent)
    return remove_at_exit(tempfile.mkdtemp(prefix=f"ftcsim-{os.getpid()}_{prefix}", dir=parent))


@atexit.register
def _remove_all() -> None:
    for folder in _FOLDERS:
        shutil.rmtree(folder, ignore_errors=True)
