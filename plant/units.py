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
