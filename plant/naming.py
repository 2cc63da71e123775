"""A block's variables and their structured FMI names (``omega[1]``, ``J[1,2]``, ``K[r,i,j]``):
:class:`Variable`, splitting names, the variables of a vector, matrix or stack of rule matrices, and the
one place that turns arrays into structured names (parameter sets, gain files)."""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

_INDEXED = re.compile(r"^(?P<base>[A-Za-z_][A-Za-z0-9_]*)\[(?P<idx>[0-9]+(?:,[0-9]+)*)\]$")


@dataclass(frozen=True)
class Variable:
    """One scalar of a block's interface. ``unit`` is an SI unit string ("1" if none)."""

    name: str
    unit: str = "1"
    description: str = ""
    start: float = 0.0


def split_name(name: str) -> tuple[str, tuple[int, ...]]:
    """``'J[1,2]'`` -> ``('J', (1, 2))``; ``'k_p'`` -> ``('k_p', ())``."""
    m = _INDEXED.match(name)
    if not m:
        return name, ()
    return m["base"], tuple(int(i) for i in m["idx"].split(","))


def vector(base: str, n: int, unit: str = "1", description: str = "", start=None, first: int = 1):
    """Variables ``base[first] .. base[first+n-1]`` with optional start values."""
    starts = [0.0] * n if start is None else [float(v) for v in np.ravel(start)]
    if len(starts) != n:
        raise ValueError(f"{base}: {len(starts)} start values for {n} elements")
    return [Variable(f"{base}[{first + i}]", unit, description, starts[i]) for i in range(n)]


def matrix(base: str, values, unit: str = "1", description: str = ""):
    """Variables ``base[i,j]`` (1-based) holding the entries of a 2-D array."""
    a = np.atleast_2d(np.asarray(values, dtype=float))
    return [
        Variable(f"{base}[{i + 1},{j + 1}]", unit, description, float(a[i, j]))
        for i in range(a.shape[0])
        for j in range(a.shape[1])
    ]


def rule_tensor(base: str, values, unit: str = "1", description: str = ""):
    """Variables ``base[r,i,j]`` (1-based; r = rule) for an (r, m, k) array of rule matrices."""
    a = np.asarray(values, dtype=float)
    return [
        Variable(f"{base}[{r + 1},{i + 1},{j + 1}]", unit, description, float(a[r, i, j]))
        for r in range(a.shape[0])
        for i in range(a.shape[1])
        for j in range(a.shape[2])
    ]


def scalar(name: str, value: float, unit: str = "1", description: str = ""):
    return [Variable(name, unit, description, float(value))]


def structured_values(base: str, value) -> dict:
    """``{'J[1,1]': .., 'J[1,2]': ..}`` for an array (1-based indices; a scalar gives ``{base: x}``).
    The one place that turns arrays into structured FMI names (parameter sets, gain files)."""
    a = np.asarray(value, dtype=float)
    if a.ndim == 0:
        return {base: float(a)}
    return {f"{base}[{','.join(str(i + 1) for i in idx)}]": float(a[idx]) for idx in np.ndindex(*a.shape)}
