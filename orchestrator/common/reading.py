"""The one reader of user files: every file ftcsim reads that a user could have written or replaced
(scenario, campaign, arena, design and gains files, Dask scheduler files, SSP packages and FMUs,
a run's ``metrics.json`` and results, Parquet tables, the targets of ``extends``) is opened here.

:func:`open_regular` is the door. Before it opens anything it refuses:

* a name holding a NUL byte (no file can have one);
* anything but a regular file: a folder, a FIFO (opening it would wait for a writer for ever), a
  device (``/dev/zero`` behind a symbolic link never ends), a socket; a symbolic link loop;
* a file larger than the bound of its kind (:data:`MAX_TEXT_BYTES` for the text files,
  :data:`MAX_DATA_BYTES` for tables and archives), checked on the open descriptor, and read no
  further than that bound whatever the file claims.

The text readers then check the encoding (UTF-8; a leading byte-order mark is dropped; NUL
characters refused) and the parsers bound the nesting depth (:data:`MAX_DEPTH` levels of tables
and arrays in TOML and JSON). :func:`referenced` resolves a file that another file names (an
``extends`` base, an arena cell's scenario, a folder of FMUs): symbolic links are followed, and the
result must stay inside the folder the name was relative to, so a link never leads a file out of
its folder. Every problem is one ``InputError(file, key, problem)``.

Standard library only (plus pyarrow for :func:`read_parquet`, imported when called).
"""
from __future__ import annotations

import errno
import json
import os
import stat
import tomllib
from pathlib import Path

from orchestrator.common.errors import InputError

MAX_TEXT_BYTES = 16 * 2**20  # a scenario, campaign, arena, design, scheduler or metrics file
MAX_DATA_BYTES = 16 * 2**30  # a Parquet table, a results CSV, an FMU or SSP package
MAX_DEPTH = 32  # nesting of tables and arrays in a TOML or JSON document (a 3-D array is 4 levels)

_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def kind_of(mode: int) -> str:
    """What a file of ``st_mode`` ``mode`` is, in words (``"a regular file"`` for one)."""
    for test, what in _KINDS:
        if test(mode):
            return what
    return "a regular file" if stat.S_ISREG(mode) else "not a regular file"


def _path_text(path, source, key) -> str:
    p = os.fspath(path)
    if isinstance(p, bytes):
        p = os.fsdecode(p)
    if "\x00" in p:
        raise InputError(source, key, f"{p!r}: a file name cannot hold a NUL byte")
    return p


def _refuse_os(source, key, path, e: OSError, what: str):
    if isinstance(e, FileNotFoundError):
        return InputError(source, key, f"{what} not found: {path}" if str(source) != str(path) else f"{what} not found")
    if e.errno == errno.ELOOP:
        return InputError(source, key, f"{path}: a loop of symbolic links")
    if e.errno == errno.ENAMETOOLONG:
        return InputError(source, key, f"{path}: name too long")
    return InputError(source, key, f"cannot read {path}: {e.strerror or e}")


def check_regular(path, what: str = "file", source=None, key: str = "-", limit: int | None = None) -> os.stat_result:
    """The ``stat`` of ``path`` (symbolic links followed) if it is a regular file of at most
    ``limit`` bytes; otherwise one ``InputError`` saying what it is. Opens nothing."""
    p = _path_text(path, source or path, key)
    source = p if source is None else source
    try:
        st = os.stat(p)
    except OSError as e:
        raise _refuse_os(source, key, p, e, what) from None
    if not stat.S_ISREG(st.st_mode):
        raise InputError(source, key, f"{p} is {kind_of(st.st_mode)}, not a {what}" if str(source) != p
                         else f"is {kind_of(st.st_mode)}, not a {what}")
    if limit is not None and st.st_size > limit:
        raise InputError(source, key, f"{p} holds {st.st_size} bytes, more than the {limit} a {what} may have")
    return st


def open_regular(path, what: str = "file", source=None, key: str = "-", limit: int | None = MAX_TEXT_BYTES):
    """A binary file object of ``path`` once it is known to be a regular file of at most ``limit``
    bytes (see the module docstring); the checks are made again on the open descriptor, so a file
    swapped in between is refused too."""
    p = _path_text(path, source or path, key)
    source = p if source is None else source
    check_regular(p, what, source, key, limit)
    try:
        fd = os.open(p, os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0))
    except OSError as e:
        raise _refuse_os(source, key, p, e, what) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise InputError(source, key, f"{p} is {kind_of(st.st_mode)}, not a {what}")
        if limit is not None and st.st_size > limit:
            raise InputError(source, key, f"{p} holds {st.st_size} bytes, more than the {limit} a {what} may have")
        os.set_blocking(fd, True)
    except BaseException:
        os.close(fd)
        raise
    return os.fdopen(fd, "rb")


def read_bytes(path, what: str = "file", source=None, key: str = "-", limit: int = MAX_TEXT_BYTES) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit``; see :func:`open_regular`)."""
    source = source if source is not None else _path_text(path, path, key)
    with open_regular(path, what, source, key, limit) as f:
        try:
            data = f.read(limit + 1)
        except OSError as e:
            raise _refuse_os(source, key, os.fspath(path), e, what) from None
    if len(data) > limit:  # grew while read
        raise InputError(source, key, f"more than the {limit} bytes a {what} may have")
    return data


def decode_text(source, key: str, raw: bytes) -> str:
    """``raw`` as UTF-8 text (a leading byte-order mark dropped); invalid bytes and NUL characters refused."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise InputError(source, key, f"not UTF-8 text (byte {e.start})") from None
    if text.startswith("\ufeff"):
        text = text[1:]
    if "\x00" in text:
        raise InputError(source, key, f"holds a NUL character (offset {text.index(chr(0))}): not a text file")
    return text


def read_text(path, what: str = "file", source=None, key: str = "-", limit: int = MAX_TEXT_BYTES) -> str:
    """The UTF-8 text of the regular file ``path`` (see the module docstring)."""
    source = source if source is not None else _path_text(path, path, key)
    return decode_text(source, key, read_bytes(path, what, source, key, limit))


def depth_of(doc) -> int:
    """Nesting depth of dicts and lists in ``doc`` (a scalar: 0), without recursion."""
    deepest, stack = 0, [(doc, 1)]
    while stack:
        x, d = stack.pop()
        if isinstance(x, dict):
            items = x.values()
        elif isinstance(x, (list, tuple)):
            items = x
        else:
            continue
        deepest = max(deepest, d)
        if d <= MAX_DEPTH + 1:  # deeper than that is refused anyway
            stack.extend((v, d + 1) for v in items)
    return deepest


def check_depth(source, key: str, doc, limit: int = MAX_DEPTH):
    """``doc`` if its tables and arrays nest at most ``limit`` deep, else an ``InputError``."""
    if depth_of(doc) > limit:
        raise InputError(source, key, f"nested too deeply (more than {limit} levels of tables and arrays)")
    return doc


def parse_toml(source, text: str, key: str = "-") -> dict:
    """The TOML document ``text`` (from ``source``); invalid or too deeply nested TOML is one error."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        raise InputError(source, key, f"not valid TOML: {' '.join(str(e).split())}") from None
    except RecursionError:
        raise InputError(source, key, f"nested too deeply (more than {MAX_DEPTH} levels of tables and arrays)") from None
    return check_depth(source, key, doc)


def parse_json(source, key: str, text: str, strict: bool = True):
    """The JSON document ``text``; ``strict``: NaN / Infinity refused (else read as None); too deep,
    invalid or anything but a JSON object is one ``InputError`` naming ``key``."""

    def constant(c):
        if strict:
            raise InputError(source, key, f"{c} is not a number (strict JSON)")

    try:
        doc = json.loads(text, parse_constant=constant)
    except json.JSONDecodeError as e:
        raise InputError(source, key, f"not valid JSON: {e.msg} at line {e.lineno}") from None
    except RecursionError:
        raise InputError(source, key, f"nested too deeply (more than {MAX_DEPTH} levels of objects and arrays)") from None
    except ValueError as e:  # e.g. an integer of more digits than int() takes
        raise InputError(source, key, f"not valid JSON: {' '.join(str(e).split())[:200]})") from None
    if not isinstance(doc, dict):
        raise InputError(source, key, "not a JSON object")
    return check_depth(source, key, doc)


def read_toml(path, what: str = "TOML file", source=None, key: str = "-") -> tuple[str, dict]:
    """(text, document) of a TOML file through the door."""
    source = source if source is not None else _path_text(path, path, key)
    text = read_text(path, what, source, key)
    return text, parse_toml(source, text, key)


def read_json(path, what: str = "JSON file", source=None, key: str = "-", strict: bool = True) -> dict:
    """A JSON object from a file through the door (``strict``: see :func:`parse_json`)."""
    source = source if source is not None else _path_text(path, path, key)
    return parse_json(source, key, read_text(path, what, source, key), strict=strict)


def referenced(folder, name, source, key: str, what: str = "file", outside_ok: bool = False,
               whose: str = "") -> Path:
    """The file ``name`` that ``source`` names, relative to ``folder``, with symbolic links resolved.
    A name that lies in ``folder`` lexically must still lie in it once its links are followed (a link
    never leads out); ``outside_ok=False`` refuses any name that leaves ``folder`` (absolute, ``..``);
    ``whose``: the folder's owner in the message (``"scenario's"``)."""
    if not isinstance(name, str) or not name:
        raise InputError(source, key, f"expected a {what} name, got {name!r}")
    if "\x00" in name:
        raise InputError(source, key, f"{name!r}: a file name cannot hold a NUL byte")
    root = os.path.realpath(os.fspath(folder))
    lexical = os.path.normpath(os.path.join(root, name))
    target = os.path.realpath(lexical)  # never raises on a loop: the open that follows says so
    inside_lexically = os.path.commonpath([root, lexical]) == root
    inside = os.path.commonpath([root, target]) == root
    if not inside and (inside_lexically or not outside_ok):
        via = " through a symbolic link" if inside_lexically else ""
        raise InputError(source, key, f"{name!r} lies outside the {whose + ' ' if whose else ''}folder {root}{via}; "
                                      "refused")
    return Path(target)


def read_parquet(path, columns=None, what: str = "Parquet table", source=None, key: str = "-"):
    """A pyarrow Table of the Parquet file ``path`` through the door (regular, bounded); a damaged
    or foreign file is one ``InputError``."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    source = source if source is not None else _path_text(path, path, key)
    with open_regular(path, what, source, key, MAX_DATA_BYTES) as f:
        try:
            return pq.read_table(f, columns=columns)
        except (pa.ArrowException, OSError, ValueError, KeyError, IndexError) as e:
            raise InputError(source, key, f"unreadable: not a {what} ({' '.join(str(e).split())[:200]})") from None
