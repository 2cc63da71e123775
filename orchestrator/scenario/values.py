"""Checks of single values in scenario and campaign files: numbers, tables, strings, keys.

Each problem is one ``InputError(file, key, problem)``; an unknown key names the closest known one."""
from __future__ import annotations

import difflib
import math

from orchestrator.common.errors import InputError


def is_number(x) -> bool:
    return isinstance(x, (int, float)) and not isinstance(x, bool)


def closest(name, known) -> str | None:
    """The known name closest to ``name`` (difflib), or None: what every "did you mean" of ftcsim
    suggests (keys, scenario names, instances, parameters, commands, metrics)."""
    close = difflib.get_close_matches(str(name), [str(k) for k in known], n=1)
    return close[0] if close else None


def hint(name, known) -> str:
    """``" (did you mean 'x'?)"`` for the name closest to ``name``, or ``""``."""
    close = closest(name, known)
    return f" (did you mean {close!r}?)" if close else ""


def unknown_key(src, key, name, known) -> InputError:
    """The error for an unknown key ``name`` of table ``key``, with the closest known one."""
    close = closest(name, known)
    where = f"{key}.{name}" if key else str(name)
    hint = f"did you mean {close!r}? " if close else ""
    what = "key" if key else "section"
    return InputError(src, where, f"unknown {what} ({hint}known: {', '.join(map(str, known))})")


def check_keys(src, key, table: dict, known) -> None:
    for k in table:
        if k not in known:
            raise unknown_key(src, key, k, known)


def number(src, key, x, positive=False) -> float:
    if not is_number(x):
        raise InputError(src, key, f"expected a number, got {type(x).__name__} {short(x)}")
    try:
        x = float(x)
    except OverflowError:
        raise InputError(src, key, "number too large") from None
    if not math.isfinite(x):
        raise InputError(src, key, f"must be finite, got {x}")
    if positive and x <= 0:
        raise InputError(src, key, f"must be > 0, got {x:g}")
    return x


def short(x, n=60) -> str:
    r = repr(x)
    return r if len(r) <= n else r[: n - 3] + "..."


def table(src, key, x) -> dict:
    if x is None:
        raise InputError(src, key, "missing")
    if not isinstance(x, dict):
        raise InputError(src, key, f"expected a table, got {type(x).__name__}")
    return x


def string(src, key, x) -> str:
    if not isinstance(x, str) or not x:
        raise InputError(src, key, f"expected a non-empty string, got {short(x)}")
    return x


def article(word: str) -> str:
    """``'an output'``, ``'a parameter'``."""
    return f"{'an' if word[:1] in 'aeiou' else 'a'} {word}"
