"""Checks of single values in scenario and campaign files: numbers, tables, strings, keys.

:func:`number` is the one numeric gate: every number ftcsim takes from a user (command-line options,
scenario, campaign, arena and SSP files, API arguments, grid points and draws, design options) passes
it. It takes Python and numpy numbers alike (``np.int64(2)``, ``np.float32(0.5)``), refuses booleans,
strings and non-finite values, and checks the range it is given (``positive``, ``lower``,
``upper``, ``integer``), naming the file or option and the key. Each problem is one
``InputError(file, key, problem)``; an unknown key names the closest known one."""
from __future__ import annotations

import difflib
import math
import numbers

from orchestrator.common.errors import InputError
from orchestrator.common.watchdog import MAX_SECONDS


def is_number(x) -> bool:
    """A real number of Python or numpy (``numbers.Real``), not a boolean."""
    return isinstance(x, numbers.Real) and not isinstance(x, bool) and type(x).__name__ != "bool_"


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


def number(src, key, x, positive=False, *, lower=None, upper=None, integer=False) -> float:
    """``x`` as a float if it is a finite real number (numpy scalars too) in the range given: > 0 with
    ``positive``, >= ``lower``, <= ``upper``, a whole number with ``integer``; else one ``InputError``."""
    if not is_number(x):
        raise InputError(src, key, f"expected a number, got {type(x).__name__} {short(x)}")
    try:
        x = float(x)
    except (OverflowError, ValueError):
        raise InputError(src, key, "number too large") from None
    if not math.isfinite(x):
        raise InputError(src, key, f"must be finite, got {x}")
    if positive and x <= 0:
        raise InputError(src, key, f"must be > 0, got {x:g}")
    if lower is not None and x < lower:
        raise InputError(src, key, f"must be >= {lower:g}, got {x:g}")
    if upper is not None and x > upper:
        raise InputError(src, key, f"must be <= {upper:g}, got {x:g}")
    if integer and x != math.floor(x):
        raise InputError(src, key, f"must be a whole number, got {x:g}")
    return x


def whole(src, key, x, lower=None, upper=None) -> int:
    """``x`` as an int if it is an integer of Python or numpy (not a boolean, not a float) in
    [``lower``, ``upper``]; else one ``InputError``."""
    if not isinstance(x, numbers.Integral) or isinstance(x, bool) or type(x).__name__ == "bool_":
        raise InputError(src, key, f"expected a whole number, got {type(x).__name__} {short(x)}")
    x = int(x)
    if lower is not None and x < lower:
        raise InputError(src, key, f"must be >= {lower}, got {x}")
    if upper is not None and x > upper:
        raise InputError(src, key, f"must be <= {upper}, got {x if abs(x) < 10**20 else f'a number of {len(str(x))} digits'}")
    return x


def seconds(src, key, x, zero_means_none=False, upper=MAX_SECONDS) -> float | None:
    """A duration in seconds (a time limit, a timeout): finite, > 0 and at most ``upper`` (a year);
    with ``zero_means_none`` None and 0 give None (no limit)."""
    if zero_means_none and (x is None or (is_number(x) and float(x) == 0.0)):
        return None
    what = " (0: no limit)" if zero_means_none else ""
    if not is_number(x):
        raise InputError(src, key, f"expected a number of seconds{what}, got {type(x).__name__} {short(x)}")
    try:
        v = float(x)
    except (OverflowError, ValueError):
        v = math.inf
    if not math.isfinite(v):
        raise InputError(src, key, f"must be > 0 (s) and must be finite{what}, got {v:g}")
    if v <= 0:
        raise InputError(src, key, f"must be > 0 (s){what}, got {v:g}")
    if v > upper:
        raise InputError(src, key, f"{v:g} s is more than the {upper:g} s ftcsim takes (a year){what}")
    return v


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
