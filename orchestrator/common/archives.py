"""Zip archives (FMUs, SSP packages) treated as possibly hostile.

:func:`check_members` refuses, before anything is extracted, an archive with an entry whose
name is absolute, climbs out (``..``), carries a drive or a backslash, is a symbolic link, or
would expand beyond :data:`MAX_UNPACKED` bytes; :func:`safe_extract` extracts only after that
check, into a folder it is given. Every problem is an ``InputError`` naming the file and the
entry.
"""
from __future__ import annotations

import stat
import zipfile
from pathlib import Path, PurePosixPath

from orchestrator.common.errors import InputError
from orchestrator.common.reading import MAX_DATA_BYTES, open_regular

MAX_UNPACKED = 4 * 2**30  # bytes; a larger FMU or package is refused (zip bombs)
MAX_MEMBERS = 100_000


def check_members(path, source=None, key="-") -> list[zipfile.ZipInfo]:
    """The members of the zip ``path`` after checking every entry name (see module docstring)."""
    source = str(source or path)
    try:  # the one reader first: a FIFO or a device is refused, never waited on
        with open_regular(path, "zip archive", source, key, MAX_DATA_BYTES) as f, zipfile.ZipFile(f) as z:
            infos = z.infolist()
    except (zipfile.BadZipFile, OSError, ValueError) as e:
        raise InputError(source, key, f"{path} is not a readable zip archive: {e}") from None
    if len(infos) > MAX_MEMBERS:
        raise InputError(source, key, f"{path} holds {len(infos)} entries (at most {MAX_MEMBERS})")
    total = 0
    for info in infos:
        name = info.filename
        p = PurePosixPath(name)
        if (name.startswith("/") or "\\" in name or (len(name) > 1 and name[1] == ":") or ".." in p.parts
                or "\x00" in name):
            raise InputError(source, key, f"{path}: entry {name!r} points outside the archive folder; refused")
        mode = info.external_attr >> 16
        if stat.S_ISLNK(mode):
            raise InputError(source, key, f"{path}: entry {name!r} is a symbolic link; refused")
        total += info.file_size
    if total > MAX_UNPACKED:
        raise InputError(source, key, f"{path} would unpack to {total / 2**30:.1f} GiB (at most "
                                      f"{MAX_UNPACKED / 2**30:.0f} GiB)")
    return infos


def safe_extract(path, dest, source=None, key="-") -> Path:
    """Extract the checked archive ``path`` into the existing folder ``dest``; returns ``dest``."""
    check_members(path, source, key)
    dest = Path(dest)
    with open_regular(path, "zip archive", str(source or path), key, MAX_DATA_BYTES) as f, zipfile.ZipFile(f) as z:
        root = dest.resolve()
        for info in z.infolist():
            target = (dest / info.filename).resolve()
            if not target.is_relative_to(root):  # belt and braces after check_members
                raise InputError(str(source or path), key, f"{path}: entry {info.filename!r} escapes the folder")
            z.extract(info, dest)
    return dest


def member_names(path) -> set[str]:
    with zipfile.ZipFile(path) as z:
        return set(z.namelist())
