"""Units: the SI definition of every unit string the blocks use (:data:`UNITS`), and whether an
output's unit matches the input's it drives.

:data:`UNITS` is what the FMU build writes into ``UnitDefinitions`` and what the block contract
accepts (``fmus/build.py``, ``fmus/contract.py``). Two unit strings match if they are equal, or if
both have a definition (an FMU's ``UnitDefinitions``, read by
``orchestrator/scenario/interfaces.py``, else :data:`UNITS`) with the same SI base-unit
exponents, factor and offset (``"Nm"`` defined as kg.m2.s-2 matches ``"N.m"``). A variable
without a unit is dimensionless (``"1"``), as in our FMUs, which write no unit for ``"1"``.
Nothing is converted: a match is required, a mismatch is refused.
"""
from __future__ import annotations

BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")

# SI base-unit exponents (and factor) of every unit string the blocks use.
UNITS = {
    "1": {},
    "s": {"s": 1},
    "rad": {"rad": 1},
    "deg": {"rad": 1, "factor": 0.017453292519943295},
    "rad/s": {"rad": 1, "s": -1},
    "rad/s2": {"rad": 1, "s": -2},
    "1/s": {"s": -1},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "N.m.s": {"kg": 1, "m": 2, "s": -1},
    "kg.m2": {"kg": 1, "m": 2},
    "kg": {"kg": 1},
    "m": {"m": 1},
    "N.m/rad": {"kg": 1, "m": 2, "s": -2, "rad": -1},
    "N.m.s/rad": {"kg": 1, "m": 2, "s": -1, "rad": -1},
}


def canonical(base: dict) -> tuple:
    """(exponents of BASE..., factor, offset) from a ``{"kg": 1, "m": 2, "s": -2, "factor": ..}`` table."""
    return tuple(int(base.get(k, 0)) for k in BASE) + (float(base.get("factor", 1.0)), float(base.get("offset", 0.0)))


def known_units() -> dict:
    """:data:`UNITS` as canonical definitions."""
    return {name: canonical(base) for name, base in UNITS.items()}


def mismatch(unit_a: str, defs_a: dict, unit_b: str, defs_b: dict) -> str | None:
    """None if ``unit_a`` (defined by ``defs_a``) matches ``unit_b``; else why not, in words."""
    a, b = unit_a or "1", unit_b or "1"
    if a == b:
        return None
    table = known_units()
    ca, cb = defs_a.get(a) or table.get(a), defs_b.get(b) or table.get(b)
    if ca is not None and ca == cb:
        return None
    if ca is not None and cb is not None and ca[:len(BASE)] == cb[:len(BASE)]:
        return f"{a} against {b} (same dimension, another scale: no conversion is made)"
    return f"{a} against {b}"


# --- spelling: one formatter for every output --------------------------------------------------
# Files (metrics.json, Parquet field metadata, CSV, report.md, the terminal) spell a unit in the UCUM
# style the FMUs declare ("N.m", "N2.m2.s", "rad/s2"); HTML pages spell it for the eye ("N·m",
# "N²·m²·s", "rad/s²"). Both come from one parsed form, so a unit has one spelling per medium.

_SUPERSCRIPT = str.maketrans("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")
_SUPER_BACK = {v: k for k, v in zip("0123456789-", "⁰¹²³⁴⁵⁶⁷⁸⁹⁻")}


def _factor(text: str, sign: int) -> list[tuple[str, int]]:
    """``"m2"`` -> [("m", 2)], ``"(N.m)2"`` -> [("N", 2), ("m", 2)]; exponents times ``sign``."""
    import re

    text = "".join(_SUPER_BACK.get(c, c) for c in text.strip())
    m = re.fullmatch(r"\((.*)\)(-?\d*)", text)
    if m:
        e = int(m.group(2) or 1)
        return [(s, sign * e * x) for s, x in terms(m.group(1))]
    m = re.fullmatch(r"([A-Za-z_%°µ]+)(-?\d*)", text)
    if not m:
        raise ValueError(f"cannot read unit factor {text!r}")
    return [(m.group(1), sign * int(m.group(2) or 1))]


def terms(unit: str) -> list[tuple[str, int]]:
    """A unit string as [(symbol, exponent)], in order of first appearance, equal symbols merged
    (``"N.m"``, ``"N·m"``, ``"(N.m)2.s"``, ``"N²·m²·s"``, ``"rad/s2"``, ``"kg.m2.s-1"``; ``"1"`` and ``""``: [])."""
    unit = (unit or "").strip().replace("·", ".").replace("*", ".").replace(" ", ".")
    if unit in ("", "1"):
        return []
    num, slash, den = unit.partition("/")
    found: dict[str, int] = {}
    depth, start, parts = 0, 0, []
    for i, c in enumerate(num):  # split at dots outside parentheses
        depth += (c == "(") - (c == ")")
        if c == "." and depth == 0:
            parts.append(num[start:i])
            start = i + 1
    parts.append(num[start:])
    pieces = [(p, 1) for p in parts if p and p != "1"]
    if slash:
        den = den[1:-1] if den.startswith("(") and den.endswith(")") else den
        pieces += [(p, -1) for p in den.split(".") if p]
    for p, sign in pieces:
        for s, e in _factor(p, sign):
            found[s] = found.get(s, 0) + e
    return [(s, e) for s, e in found.items() if e != 0]


def _join(items, pretty: bool) -> str:
    dot = "·" if pretty else "."
    return dot.join(s + ("" if e == 1 else (str(e).translate(_SUPERSCRIPT) if pretty else str(e))) for s, e in items)


def spell(items, pretty: bool = False) -> str:
    """[(symbol, exponent)] as one unit string: UCUM style (``"N2.m2.s"``, ``"rad/s2"``) or, with
    ``pretty``, for a page (``"N²·m²·s"``, ``"rad/s²"``); dimensionless: ``"1"``."""
    pos = [(s, e) for s, e in items if e > 0]
    neg = [(s, -e) for s, e in items if e < 0]
    if not pos and not neg:
        return "1"
    if not neg:
        return _join(pos, pretty)
    den = _join(neg, pretty)
    return (_join(pos, pretty) if pos else "1") + "/" + (f"({den})" if len(neg) > 1 else den)


def ucum(unit: str | None) -> str | None:
    """The file spelling of ``unit`` (UCUM style, as the FMUs declare units): ``"(N.m)2.s"``,
    ``"N²·m²·s"`` -> ``"N2.m2.s"``; None stays None; a string it cannot read is returned as it is."""
    if unit is None:
        return None
    try:
        return spell(terms(unit))
    except ValueError:
        return str(unit)


def pretty(unit: str | None) -> str | None:
    """The page spelling of ``unit`` (HTML): ``"N.m"`` -> ``"N·m"``, ``"N2.m2.s"`` -> ``"N²·m²·s"``,
    ``"rad/s2"`` -> ``"rad/s²"``; None stays None."""
    if unit is None:
        return None
    try:
        return spell(terms(unit), pretty=True)
    except ValueError:
        return str(unit)


def product(*units: str) -> str:
    """The UCUM spelling of the product of ``units`` (``product("N2.m2", "s")`` -> ``"N2.m2.s"``)."""
    found: dict[str, int] = {}
    for u in units:
        for s, e in terms(u):
            found[s] = found.get(s, 0) + e
    return spell([(s, e) for s, e in found.items() if e])


def power(unit: str, n: int) -> str:
    """The UCUM spelling of ``unit`` to the integer power ``n`` (``power("N.m", 2)`` -> ``"N2.m2"``)."""
    return spell([(s, e * n) for s, e in terms(unit)])


# symbols a unit in square brackets of a label may use (``[N.m]``, ``[rad/s]``, ``[deg]``): what tells a unit
# apart from an index (``q[0]``) or a link text in :func:`respell_bracketed`
SYMBOLS = frozenset({"N", "m", "s", "kg", "rad", "deg", "A", "K", "Hz", "W", "J", "g", "mol", "cd", "min", "h", "%"})


def is_unit(text: str) -> bool:
    """True if ``text`` reads as a unit of :data:`SYMBOLS` (``"N.m"``, ``"N²·m²·s"``, ``"rad/s2"``, ``"1"``)."""
    try:
        return text.strip() == "1" or bool(terms(text)) and all(sym in SYMBOLS for sym, _ in terms(text))
    except ValueError:
        return False


def respell_bracketed(text: str, pretty_units: bool) -> str:
    """``text`` with every unit in square brackets (a label's ``[N.m]``) spelled for a page
    (``pretty_units``: ``[N·m]``) or for a file (``[N.m]``); other brackets kept as they are."""
    import re

    spell = pretty if pretty_units else ucum
    return re.sub(r"\[([^\[\]\n]{1,24})\](?!\()", lambda m: f"[{spell(m.group(1))}]" if is_unit(m.group(1)) else m.group(0),
                  str(text))
