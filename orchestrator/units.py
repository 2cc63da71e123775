"""Units of connected variables: does an output's unit match the input's it drives?

Two unit strings match if they are equal, or if both have a definition (an FMU's
``UnitDefinitions``, else the build's table ``fmus/build.py: UNITS``) with the same SI base-unit
exponents, factor and offset (``"Nm"`` defined as kg.m2.s-2 matches ``"N.m"``). A variable
without a unit is dimensionless (``"1"``), as in our FMUs, which write no unit for ``"1"``.
Nothing is converted: a match is required, a mismatch is refused.
"""
from __future__ import annotations

BASE = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def canonical(base: dict) -> tuple:
    """(exponents of BASE..., factor, offset) from a ``{"kg": 1, "m": 2, "s": -2, "factor": ..}`` table."""
    return tuple(int(base.get(k, 0)) for k in BASE) + (float(base.get("factor", 1.0)), float(base.get("offset", 0.0)))


def known_units() -> dict:
    """The build's unit table as canonical definitions."""
    from fmus.build import UNITS

    return {name: canonical(base) for name, base in UNITS.items()}


def fmu_unit_definitions(md) -> dict:
    """Unit name -> canonical definition, from an fmpy model description's UnitDefinitions."""
    out = {}
    for u in getattr(md, "unitDefinitions", None) or []:
        b = u.baseUnit
        if b is not None:
            out[u.name] = canonical({k: getattr(b, k, 0) or 0 for k in BASE}
                                    | {"factor": b.factor if b.factor is not None else 1.0,
                                       "offset": b.offset if b.offset is not None else 0.0})
    return out


def variable_unit(v) -> str:
    """An fmpy variable's unit (its own, else its declared type's), ``"1"`` if none."""
    unit = getattr(v, "unit", None) or getattr(getattr(v, "declaredType", None), "unit", None)
    return unit or "1"


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
