"""Output folders that never destroy what ftcsim did not create.

Every command that writes a folder (``run``, ``report``, ``campaign``...) goes through
:class:`OutputFolder`:

* the target is checked **before** any work starts (:meth:`OutputFolder.check`): it must not
  be a symbolic link, a file, or below a file; its nearest existing parent must be a writable
  folder; an existing folder is refused unless it carries the marker file ftcsim writes
  (:data:`MARKER`, of the same kind) **and** ``overwrite`` was asked for;
* the target's name must leave room for the siblings ftcsim writes beside it (the lock and the
  staging folder: :data:`SIBLING_OVERHEAD` bytes more than the name, within the file system's
  NAME_MAX), be encodable as a file name, and lie outside the kernel's pseudo file systems
  (``/proc``, ``/sys``); every ``OSError`` of the checks and of the writing becomes one
  ``InputError`` naming ``--out`` (exit 2), with the previous result unchanged;
* an exclusive lock (the ``filelock`` library's ``FileLock`` on ``.<name>.ftcsim-lock`` beside the
  target, removed when released) is held from the check until the folder is published, so two
  commands writing the same folder at once cannot both succeed: the second is refused at its start
  (the atomic publish below is what protects a result; the lock makes the refusal early);
* the content is written into a fresh hidden sibling ``.<name>.tmp-XXXX`` and published with
  one ``rename``; a previous result (marker checked again) is moved aside first and removed
  only after the new one is in place. If the target appeared meanwhile (another program), the
  new result is kept where it was written and the error says where;
* a command that grows its folder in place (``campaign``: each finished run is written at once,
  so that nothing computed is lost when the command is killed) publishes the folder at its
  start with ``publish(keep_lock=True)``, and a later run of the same command resumes it:
  ``resume(path)`` tells :meth:`OutputFolder.check` that an existing folder of the same kind may
  be continued without ``overwrite`` (:attr:`OutputFolder.resuming`).

A command that writes one file (``design``, ``export-ssp``, ``build --block``) goes through
:class:`OutputFile`: the same checks and lock, the file written beside its target and renamed into
place, an existing file replaced only if ftcsim wrote it (the caller says how to tell) and
``overwrite`` was given. Inside a folder it grows (a campaign's ``runs/``), :func:`store_folder`
refuses a sub-folder that is a symbolic link or not a folder: nothing is written through a link.

Names that become paths (a scenario's ``name``, an instance name) go through
:func:`safe_name` first: no separators, no ``..``, no control characters, bounded length.
"""
from __future__ import annotations

import json
import os
import re
import shutil
import stat
import tempfile
import time
from pathlib import Path

import filelock

from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.reading import read_json

MARKER = ".ftcsim.json"
MAX_NAME = 100
LOCK_SUFFIX = ".ftcsim-lock"
# bytes the longest sibling of a target adds to its name: ".<name>.tmp-XXXXXXXX" (tempfile's 8 characters)
SIBLING_OVERHEAD = max(len(f"..{LOCK_SUFFIX}"), len("..tmp-") + 8, len("..old-") + 8)
PSEUDO_FILE_SYSTEMS = ("/proc", "/sys")
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


def _name_max(folder) -> int:
    try:
        return os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return 255


def check_target(path, source="command line", key="--out") -> Path:
    """Refuse an output path that cannot be written whatever the command (see the module docstring):
    no name, a name that is not encodable or leaves no room for the siblings ftcsim writes beside it,
    a NUL byte, a path below a file or a broken link, a pseudo file system, a parent that is not a
    writable folder. Returns the nearest existing parent. Creates nothing."""
    text = os.fspath(path)
    if "\x00" in text:
        raise InputError(source, key, f"{text!r}: a path cannot hold a NUL byte")
    p = Path(text)
    if p.name in ("", ".", ".."):
        raise InputError(source, key, f"{p}: give a name, not {p.name or '/'!r}")
    try:
        encoded = os.fsencode(p.name)
    except UnicodeEncodeError:
        raise InputError(source, key, f"{p.name!r} cannot be encoded as a file name") from None
    existing = p.absolute().parent
    try:
        while not existing.exists():
            if existing.is_symlink():  # a dangling link in the path
                raise InputError(source, key, f"{existing} is a broken symbolic link")
            existing = existing.parent
        real = os.path.realpath(existing)
        if any(real == fs or real.startswith(fs + os.sep) for fs in PSEUDO_FILE_SYSTEMS):
            raise InputError(source, key, f"{p} lies in {real}, a kernel file system: results cannot be written there")
        if not existing.is_dir():
            raise InputError(source, key, f"{existing} is a file, so {p} cannot be created below it")
        limit = _name_max(existing)
        if len(encoded) + SIBLING_OVERHEAD > limit:
            raise InputError(source, key, f"the name {p.name[:40]!r}... is {len(encoded)} bytes long: at most "
                                          f"{limit - SIBLING_OVERHEAD} (ftcsim writes '.NAME{LOCK_SUFFIX}' and "
                                          f"'.NAME.tmp-XXXXXXXX' beside it, within the {limit} bytes of a file name)")
        if not os.access(existing, os.W_OK | os.X_OK):
            raise InputError(source, key, f"{existing} is not writable")
    except OSError as e:
        raise InputError(source, key, f"{p}: {e.strerror or e}") from None
    return existing


def store_folder(store, name: str, create: bool = True) -> Path:
    """``store / name``, a sub-folder of a folder ftcsim grows in place (a campaign's ``runs/``): a real
    folder, never a symbolic link or a file (an ``InputError``: nothing is written through it);
    created if missing and ``create``."""
    p = Path(store) / name
    try:
        st = os.lstat(p)
    except FileNotFoundError:
        if create:
            p.mkdir()
        return p
    if stat.S_ISLNK(st.st_mode):
        raise InputError(p, "-", "is a symbolic link inside a folder ftcsim writes: nothing is written through it; "
                                 "remove the link or start a new folder")
    if not stat.S_ISDIR(st.st_mode):
        raise InputError(p, "-", "is not a folder (ftcsim writes one there): the folder is damaged; remove it or "
                                 "start a new folder")
    return p


class _Lock:
    """The ``filelock`` lock ``.<name>.ftcsim-lock`` beside a target, taken without waiting."""

    def __init__(self, target: Path, source, key):
        self.path = target.absolute().parent / f".{target.name}{LOCK_SUFFIX}"
        self.source, self.key, self.target = source, key, target
        self.lock = None

    def take(self) -> None:
        lock = filelock.FileLock(self.path, timeout=0)
        try:
            lock.acquire()
        except filelock.Timeout:
            raise InputError(self.source, self.key, f"another ftcsim command is writing {self.target} right now") from None
        except OSError as e:
            raise InputError(self.source, self.key, f"cannot lock {self.path}: {e.strerror or e}") from None
        self.lock = lock

    def release(self) -> None:
        if self.lock is None:
            return
        try:
            self.lock.release()
        finally:
            self.lock = None
            try:
                self.path.unlink(missing_ok=True)  # no lock file left behind (the publish is what is atomic)
            except OSError:
                pass


class OutputFolder:
    """One output folder of kind ``kind`` at ``path``; see the module docstring."""

    def __init__(self, path, kind: str, overwrite: bool = False, source="command line", key="--out", resume=None):
        self.path = Path(path)
        self.kind = kind
        self.overwrite = overwrite
        self.resume = resume  # None, or path -> bool: may this existing folder be continued in place?
        self.resuming = False
        self.source, self.key = source, key
        self._lock = None
        self.tmp: Path | None = None

    # -- before the work ----------------------------------------------------------------------
    def check(self) -> OutputFolder:
        """Refuse a target that cannot or must not be written; take the lock. Creates nothing
        but the target's missing parent folders and the lock file."""
        p = self.path
        check_target(p, self.source, self.key)
        try:
            if p.is_symlink():
                raise InputError(self.source, self.key, f"{p} is a symbolic link; give the real folder")
            if p.exists():
                if not p.is_dir():
                    raise InputError(self.source, self.key, f"{p} exists and is not a directory")
                if not is_result_folder(p):
                    raise InputError(self.source, self.key, f"{p} exists and was not written by ftcsim: nothing in "
                                                            "it is touched; choose a new folder")
                if not is_result_folder(p, self.kind):
                    raise InputError(self.source, self.key, f"{p} holds another kind of ftcsim result, not a "
                                                            f"{self.kind}")
                self.resuming = not self.overwrite and self.resume is not None and bool(self.resume(p))
                if not self.overwrite and not self.resuming:
                    raise InputError(self.source, self.key, f"{p} holds a previous ftcsim {self.kind}; "
                                                            "pass --overwrite to replace it")
            parent = p.absolute().parent
            parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise InputError(self.source, self.key, f"{p}: {e.strerror or e}") from None
        self._lock = _Lock(p, self.source, self.key)
        self._lock.take()
        return self

    # -- writing -----------------------------------------------------------------------------
    def staging(self) -> Path:
        """A fresh hidden folder beside the target to write into (created on first call)."""
        if self.tmp is None:
            parent = self.path.absolute().parent
            try:
                self.tmp = Path(tempfile.mkdtemp(prefix=f".{self.path.name}.tmp-", dir=parent))
                os.chmod(self.tmp, 0o777 & ~_umask())
                (self.tmp / MARKER).write_text(json.dumps({
                    "tool": "ftcsim", "kind": self.kind, "created": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                }) + "\n", encoding="utf-8")
            except OSError as e:
                self.discard()
                raise InputError(self.source, self.key, f"cannot write beside {self.path}: {e.strerror or e}; "
                                                        "nothing written") from None
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
        except OSError as e:  # a full disk, a file-size limit: one line, nothing published
            self.discard()
            raise InputError(self.source, self.key, f"cannot write {self.path}: {e.strerror or e}; nothing published, "
                                                    f"{_previous(self.path)}") from None
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
        if self._lock is not None:
            self._lock.release()
            self._lock = None


def _previous(path: Path) -> str:
    return "the previous result there is unchanged" if path.exists() else "nothing was written there"


def _umask() -> int:
    u = os.umask(0)
    os.umask(u)
    return u


class OutputFile:
    """One output file at ``path`` (see the module docstring): ``ours(path) -> bool`` tells whether an
    existing file is one ftcsim wrote of this kind; only such a file is replaced, and only with
    ``overwrite``. :meth:`check` before the work, :meth:`write` (``writer(staging file path)``) after."""

    def __init__(self, path, what: str, ours, overwrite: bool = False, source="command line", key="--out",
                 suffix: str | None = None, foreign: str | None = None):
        self.path = Path(path)
        self.what, self.ours, self.overwrite = what, ours, overwrite
        self.foreign = foreign or f"was not written by ftcsim as {what}"  # says why an existing file is not ours
        self.source, self.key, self.suffix = source, key, suffix
        self._lock = None

    def _refuse_existing(self) -> None:
        p = self.path
        if p.is_symlink():
            raise InputError(self.source, self.key, f"{p} is a symbolic link; give the real file")
        if p.is_dir():
            raise InputError(self.source, self.key, f"{p} is a directory; give a file name")
        if p.exists():
            if not p.is_file() or not self.ours(p):
                raise InputError(self.source, self.key, f"{p} exists and {self.foreign}: nothing is touched; choose "
                                                        "a new file")
            if not self.overwrite:
                raise InputError(self.source, self.key, f"{p} exists; pass --overwrite to replace it")

    def check(self) -> OutputFile:
        """Refuse a target that cannot or must not be written; take the lock (creates the missing
        parent folders and the lock file only)."""
        if "\x00" in os.fspath(self.path):
            raise InputError(self.source, self.key, f"{os.fspath(self.path)!r}: a path cannot hold a NUL byte")
        if self.suffix is not None and self.path.suffix != self.suffix:
            raise InputError(self.source, self.key, f"{self.path}: {self.what} must end in {self.suffix}")
        try:
            self._refuse_existing()
            check_target(self.path, self.source, self.key)
            self.path.absolute().parent.mkdir(parents=True, exist_ok=True)
        except OSError as e:
            raise InputError(self.source, self.key, f"{self.path}: {e.strerror or e}") from None
        self._lock = _Lock(self.path, self.source, self.key)
        self._lock.take()
        return self

    def write(self, writer):
        """``writer(tmp)`` writes the whole file at ``tmp`` (beside the target); it is then renamed into
        place. Any ``OSError`` (full disk, size limit) is one ``InputError``: nothing published, a
        previous file unchanged. Releases the lock. Returns what ``writer`` returned."""
        if self._lock is None:
            self.check()
        parent = self.path.absolute().parent
        tmp = None
        try:
            fd, tmp = tempfile.mkstemp(prefix=f".{self.path.name}.tmp-", dir=parent)
            os.close(fd)
            os.chmod(tmp, 0o666 & ~_umask())
            value = writer(Path(tmp))
            self._refuse_existing()  # again: the work took a while, and a file may have appeared meanwhile
            os.replace(tmp, self.path)
            tmp = None
            return value
        except OSError as e:
            raise InputError(self.source, self.key, f"cannot write {self.path}: {e.strerror or e}; nothing "
                                                    f"published, {_previous(self.path)}") from None
        finally:
            if tmp is not None:
                try:
                    os.unlink(tmp)
                except OSError:
                    pass
            self.release()

    def release(self) -> None:
        if self._lock is not None:
            self._lock.release()
            self._lock = None
