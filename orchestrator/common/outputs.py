"""Output folders that never destroy what ftcsim did not create.

Every command that writes a folder (``run``, ``report``, ``campaign``...) goes through
:class:`OutputFolder`:

* the target is checked **before** any work starts (:meth:`OutputFolder.check`): it must not
  be a symbolic link, a file, or below a file; its nearest existing parent must be a writable
  folder; an existing folder is refused unless it carries the marker file ftcsim writes
  (:data:`MARKER`, of the same kind) **and** ``overwrite`` was asked for;
* an exclusive lock (``fcntl.flock`` on ``.<name>.ftcsim-lock`` beside the target) is held
  from the check until the folder is published, so two commands writing the same folder at
  once cannot both succeed: the second is refused at its start;
* the content is written into a fresh hidden sibling ``.<name>.tmp-XXXX`` and published with
  one ``rename``; a previous result (marker checked again) is moved aside first and removed
  only after the new one is in place. If the target appeared meanwhile (another program), the
  new result is kept where it was written and the error says where;
* a command that grows its folder in place (``campaign``: each finished run is written at once,
  so that nothing computed is lost when the command is killed) publishes the folder at its
  start with ``publish(keep_lock=True)``, and a later run of the same command resumes it:
  ``resume(path)`` tells :meth:`OutputFolder.check` that an existing folder of the same kind may
  be continued without ``overwrite`` (:attr:`OutputFolder.resuming`).

Names that become paths (a scenario's ``name``, an instance name) go through
:func:`safe_name` first: no separators, no ``..``, no control characters, bounded length.
"""
from __future__ import annotations

import fcntl
import json
import os
import re
import shutil
import tempfile
import time
from pathlib import Path

from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.reading import read_json

MARKER = ".ftcsim.json"
MAX_NAME = 100
_SAFE = re.compile(r"^[A-Za-z0-9_][A-Za-z0-9_.+-]*$")


def safe_name(name, source="scenario", key="scenario.name") -> str:
    """``name`` if it can be used as one path component, else an ``InputError``."""
    if not isinstance(name, str) or not name:
        raise InputError(source, key, f"must be a non-empty string, got {name!r}")
    if len(name) > MAX_NAME:
        raise InputError(source, key, f"longer than {MAX_NAME} characters ({len(name)})")
    if name in (".", "..") or ".." in name or not _SAFE.match(name):
        raise InputError(source, key, f"{name!r} cannot be used as a file name: use letters, digits, "
                                      "'_', '-', '.' and '+' only (no path separators, no '..', no spaces)")
    return name


def is_result_folder(path: Path, kind: str | None = None) -> bool:
    """True if ``path`` is a folder ftcsim wrote (its marker file parses, of ``kind`` if given)."""
    try:  # the one reader: a FIFO or a device named like the marker is never waited on
        info = read_json(Path(path) / MARKER, "marker file")
    except InputError:
        return False
    return isinstance(info, dict) and info.get("tool") == "ftcsim" and (kind is None or info.get("kind") == kind)


class OutputFolder:
    """One output folder of kind ``kind`` at ``path``; see the module docstring."""

    def __init__(self, path, kind: str, overwrite: bool = False, source="command line", key="--out", resume=None):
        self.path = Path(path)
        self.kind = kind
        self.overwrite = overwrite
        self.resume = resume  # None, or path -> bool: may this existing folder be continued in place?
        self.resuming = False
        self.source, self.key = source, key
        self._lock_fd = None
        self._lock_path = None
        self.tmp: Path | None = None

    # -- before the work ----------------------------------------------------------------------
    def check(self) -> OutputFolder:
        """Refuse a target that cannot or must not be written; take the lock. Creates nothing
        but the target's missing parent folders and the lock file."""
        p = self.path
        if p.name in ("", ".", ".."):
            raise InputError(self.source, self.key, f"{p}: give a folder name, not {p.name or '/'!r}")
        if p.is_symlink():
            raise InputError(self.source, self.key, f"{p} is a symbolic link; give the real folder")
        if p.exists():
            if not p.is_dir():
                raise InputError(self.source, self.key, f"{p} exists and is not a directory")
            if not is_result_folder(p):
                raise InputError(self.source, self.key, f"{p} exists and was not written by ftcsim: nothing in it "
                                                        "is touched; choose a new folder")
            if not is_result_folder(p, self.kind):
                raise InputError(self.source, self.key, f"{p} holds another kind of ftcsim result, not a {self.kind}")
            self.resuming = not self.overwrite and self.resume is not None and bool(self.resume(p))
            if not self.overwrite and not self.resuming:
                raise InputError(self.source, self.key, f"{p} holds a previous ftcsim {self.kind}; "
                                                        "pass --overwrite to replace it")
        parent = p.absolute().parent
        existing = parent
        while not existing.exists():
            if existing.is_symlink():  # a dangling link in the path
                raise InputError(self.source, self.key, f"{existing} is a broken symbolic link")
            existing = existing.parent
        if not existing.is_dir():
            raise InputError(self.source, self.key, f"{existing} is a file, so {p} cannot be created below it")
        if not os.access(existing, os.W_OK | os.X_OK):
            raise InputError(self.source, self.key, f"{existing} is not writable")
        try:
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise InputError(self.source, self.key, f"cannot create {parent}: {e.strerror or e}") from None
        self._lock()
        return self

    def _lock(self):
        self._lock_path = self.path.absolute().parent / f".{self.path.name}.ftcsim-lock"
        for _ in range(10):
            fd = os.open(self._lock_path, os.O_RDWR | os.O_CREAT, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                os.close(fd)
                raise InputError(self.source, self.key, f"another ftcsim command is writing {self.path} right now") from None
            try:
                same = os.fstat(fd).st_ino == os.stat(self._lock_path).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)  # the previous holder removed the file meanwhile: lock the new one
        else:  # pragma: no cover
            raise InputError(self.source, self.key, f"cannot lock {self._lock_path}")
        os.truncate(fd, 0)
        os.write(fd, f"{os.getpid()}\n".encode())
        self._lock_fd = fd

    # -- writing -----------------------------------------------------------------------------
    def staging(self) -> Path:
        """A fresh hidden folder beside the target to write into (created on first call)."""
        if self.tmp is None:
            parent = self.path.absolute().parent
            self.tmp = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.tmp-", dir=parent))
            os.chmod(self.tmp, 0o777 & ~_umask())
            (self.tmp / MARKER).write_text(json.dumps({
                "tool": "ftcsim", "kind": self.kind, "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
            }) + "\n", encoding="utf-8")
        return self.tmp

    def publish(self, keep_lock: bool = False) -> Path:
        """Move the staging folder into place (atomically); replaces a previous result of the
        same kind only if ``overwrite``. Releases the lock unless ``keep_lock`` (then the caller
        writes into the published folder and calls :meth:`release`)."""
        tmp = self.staging()
        p = self.path
        old = None
        try:
            if p.exists() or p.is_symlink():
                if not (self.overwrite and not p.is_symlink() and is_result_folder(p, self.kind)):
                    raise SimulationError(f"{p} appeared while this command ran and is not a result it may "
                                          f"replace; the new result is kept in {tmp}")
                old = Path(tempfile.mkdtemp(prefix=f".{p.name}.old-", dir=p.absolute().parent))
                os.rename(p, old / "previous")
            try:
                os.rename(tmp, p)
            except OSError as e:
                raise SimulationError(f"cannot move the result into {p} ({e.strerror or e}); "
                                      f"it is kept in {tmp}") from None
            self.tmp = None
        finally:
            if old is not None:
                if (old / "previous").exists() and not p.exists():
                    os.rename(old / "previous", p)  # put the previous result back
                shutil.rmtree(old, ignore_errors=True)
            if not keep_lock:
                self.release()
        return p

    def fill(self, write):
        """``write(staging folder)`` then :meth:`publish`; if ``write`` raises (or is interrupted),
        :meth:`discard` and re-raise. Returns what ``write`` returned."""
        try:
            value = write(self.staging())
        except BaseException:
            self.discard()
            raise
        self.publish()
        return value

    def discard(self) -> None:
        """Remove the staging folder (nothing computed in it) and release the lock."""
        if self.tmp is not None:
            shutil.rmtree(self.tmp, ignore_errors=True)
            self.tmp = None
        self.release()

    def release(self) -> None:
        if self._lock_fd is not None:
            try:
                self._lock_path.unlink(missing_ok=True)
            except OSError:
                pass
            os.close(self._lock_fd)
            self._lock_fd = None


def _umask() -> int:
    u = os.umask(0)
    os.umask(u)
    return u
