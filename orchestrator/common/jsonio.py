"""Reading and writing the project's text files safely: UTF-8 text with one clear error per
problem, strict JSON (no NaN/Infinity: any strict parser reads what we write), atomic writes.
Import-light (stdlib and numpy), so the LMI layer and the FMU-free tools can use it too."""
from __future__ import annotations

import json
import math
import os
import tempfile

import numpy as np

from orchestrator.common.reading import parse_json, read_json, read_text
from orchestrator.common.reading import parse_toml as _parse_toml


def read_utf8(path, what: str = "file") -> str:
    """The text of ``path`` through the one reader (:mod:`orchestrator.common.reading`): a missing
    file, a folder, a FIFO or device, a file too large, unreadable or non-UTF-8 bytes are each one
    ``InputError`` naming the file."""
    return read_text(path, what)


def parse_toml(src, text: str) -> dict:
    """The TOML document ``text`` (read from ``src``); invalid or too deeply nested TOML is one
    ``InputError`` naming the file."""
    return _parse_toml(src, text)


def parse_json_object(src, key: str, text: str) -> dict:
    """The JSON object ``text`` (the content of ``key`` in ``src``), NaN / Infinity read as None;
    invalid JSON, too deep, or anything but an object is one ``InputError`` naming the key."""
    return parse_json(src, key, text, strict=False)


def load_json_object(path, what: str = "JSON file") -> dict:
    """A JSON object from ``path``, strict (NaN / Infinity refused), through the one reader."""
    return read_json(path, what, strict=True)


def strict_json(x):
    """``x`` with every non-finite float replaced by None, numpy scalars and arrays as plain
    numbers and lists, complex numbers as {"re", "im"}: what ``json.dumps(allow_nan=False)`` takes."""
    if isinstance(x, dict):
        return {str(k): strict_json(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [strict_json(v) for v in x]
    if isinstance(x, np.ndarray):
        return strict_json(x.tolist())
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, (complex, np.complexfloating)):
        return {"re": strict_json(x.real), "im": strict_json(x.imag)}
    return x


def write_json_atomic(path, data) -> None:
    """Strict JSON, written through a temporary file in the same folder and a rename (normal
    file permissions)."""
    path = os.fspath(path)
    folder = os.path.dirname(os.path.abspath(path))
    os.makedirs(folder, exist_ok=True)
    text = json.dumps(strict_json(data), indent=2, allow_nan=False) + "\n"
    fd, tmp = tempfile.mkstemp(prefix=".tmp-", suffix=".json", dir=folder)
    umask = os.umask(0)
    os.umask(umask)
    try:
        os.chmod(tmp, 0o666 & ~umask)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
