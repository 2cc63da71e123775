"""Physical meaning of parameter values, the same rules for every block family (pitch-axis, three-axis,
wheels, sensors, third-party FMUs that use the same names and units).

A rule applies to a parameter by its base name and its unit, so a block's own checks at
``initialize`` and the orchestrator's checks before any FMU starts (``orchestrator/scenario/physical.py``)
agree: an inertia tensor ``J`` [kg.m2] must be symmetric and positive definite (not checked: the
triangle inequality of the principal moments, I_3 <= I_1 + I_2, which every rigid body satisfies but
paper 001's published J does not: moments 11.87, 23.97, 40.16 kg.m2; :func:`implausible` reports it,
and the orchestrator shows it as one warning line while the run goes on, so that a paper printing
such a J can still be reproduced); natural frequencies, time constants, sample periods, step bounds and
capacities must be > 0; damping ratios, friction coefficients, noise densities, frequencies of
disturbances and saturation levels (0: none, where blocks allow it) >= 0; effectiveness, loss and duty
fractions lie in [0, 1]. The coupling of a flexible spacecraft, J - delta^T delta (000 (1)), must
stay positive definite too. numpy only (floor 0).
"""
from __future__ import annotations

import numpy as np

# (base name, unit) -> rule; units as blocks declare them (plant/units.py)
RULES = {
    ("J", "kg.m2"): "inertia",
    ("I_w", "kg.m2"): "positive",
    ("omega_n", "rad/s"): "positive",
    ("zeta", "1"): "nonnegative",
    ("viscous", "N.m.s"): "nonnegative",
    ("coulomb", "N.m"): "nonnegative",
    ("u_max", "N.m"): "nonnegative",
    ("tau_max", "N.m"): "positive",
    ("tau_max", "s"): "positive",
    ("tau_min", "s"): "positive",
    ("h_max", "s"): "positive",
    ("h_int", "s"): "positive",
    ("h_max", "N.m.s"): "positive",
    ("omega_max", "rad/s"): "positive",
    ("theta_dot_max", "rad/s"): "positive",
    ("time_constant", "s"): "positive",
    ("sample_period", "s"): "positive",
    ("bi_tau", "s"): "positive",
    ("arw", "rad/s"): "nonnegative",
    ("rrw", "rad/s"): "nonnegative",
    ("bi_sigma", "rad/s"): "nonnegative",
    ("sigma_cross", "rad"): "nonnegative",
    ("sigma_roll", "rad"): "nonnegative",
    ("dJ_freq", "rad/s"): "nonnegative",
    ("Td_freq", "rad/s"): "nonnegative",
    ("freq", "rad/s"): "nonnegative",
    ("dist_n0", "rad/s"): "nonnegative",
    ("effectiveness", "1"): "fraction",
    ("effectiveness_before", "1"): "fraction",
    ("loss", "1"): "fraction",
    ("duty", "1"): "fraction",
}
WHAT = {"positive": "must be > 0", "nonnegative": "must be >= 0", "fraction": "must lie in [0, 1]"}
REL_TOL = 1e-9  # symmetry, relative to the largest element


def _split(name: str):
    """``'J[1,2]'`` -> ``('J', (1, 2))``; ``(name, None)`` for a name whose indices are not whole numbers
    (a third-party FMU's own naming): no rule applies to it."""
    base, _, rest = name.partition("[")
    try:
        idx = tuple(int(i) for i in rest.rstrip("]").split(",")) if rest else ()
    except ValueError:
        return name, None
    return base, idx


def _arrays(values: dict) -> dict:
    """{'J[1,1]': .., 'J[1,2]': .., 'u_max': ..} -> {'J': 2-D array, 'u_max': 0-D array} (1-based or
    0-based indices, as declared)."""
    groups = {}
    for name, x in values.items():
        base, idx = _split(name)
        if idx is not None:
            groups.setdefault(base, []).append((idx, float(x)))
    out = {}
    for base, items in groups.items():
        if len(items) == 1 and items[0][0] == ():
            out[base] = np.array(items[0][1])
            continue
        if len({len(i) for i, _ in items}) != 1 or () in [i for i, _ in items]:
            continue  # a scalar and elements under one name, or mixed ranks: not an array to judge
        idx = np.array([i for i, _ in items])
        lo = idx.min(axis=0)
        a = np.full(tuple(idx.max(axis=0) - lo + 1), np.nan)
        for i, x in items:
            a[tuple(np.array(i) - lo)] = x
        out[base] = a
    return out


def _eigenvalues(M: np.ndarray):
    """Ascending eigenvalues of the symmetric ``M``, or None when they cannot be computed (values so
    large that they overflow)."""
    if not np.isfinite(M).all():
        return None
    try:
        with np.errstate(all="ignore"):
            w = np.linalg.eigvalsh(M)
    except (np.linalg.LinAlgError, ValueError):
        return None
    return w if np.isfinite(w).all() else None


def inertia_problem(J: np.ndarray) -> str | None:
    """Why ``J`` [kg.m2] is not an inertia (scalar: > 0; matrix: symmetric, positive definite), or None."""
    J = np.asarray(J, dtype=float)
    if J.ndim == 0 or J.size == 1:
        return None if float(J.ravel()[0]) > 0 else f"= {float(J.ravel()[0]):g} kg.m2: an inertia must be > 0"
    if J.ndim != 2 or J.shape[0] != J.shape[1] or np.isnan(J).any():
        return None  # not a tensor: nothing physical to say here
    scale = float(np.max(np.abs(J))) or 1.0
    asym = np.abs(J - J.T)
    if asym.max() > REL_TOL * scale:
        i, j = np.unravel_index(int(np.argmax(asym)), J.shape)
        return (f"is not symmetric: J[{i + 1},{j + 1}] = {J[i, j]:g} but J[{j + 1},{i + 1}] = {J[j, i]:g} kg.m2 "
                "(an inertia tensor is symmetric)")
    moments = _eigenvalues(0.5 * (J + J.T))
    if moments is None:
        return "is too large to be an inertia (its eigenvalues overflow)"
    if moments[0] <= 0:
        return (f"is not positive definite: principal moments {', '.join(f'{m:.6g}' for m in moments)} kg.m2 "
                "(each must be > 0)")
    return None


TRIANGLE_TOL = 1e-9  # relative to the largest principal moment


def triangle_problem(J: np.ndarray) -> str | None:
    """Why the principal moments of the symmetric, positive definite ``J`` (kg.m2) cannot be a rigid
    body's (the largest exceeds the sum of the two others: I_3 <= I_1 + I_2 for every mass
    distribution), or None."""
    J = np.asarray(J, dtype=float)
    if J.ndim != 2 or J.shape != (3, 3) or inertia_problem(J):
        return None
    m = _eigenvalues(0.5 * (J + J.T))
    if m is None or m[2] <= (m[0] + m[1]) * (1.0 + TRIANGLE_TOL):
        return None
    return (f"principal moments {m[0]:.6g}, {m[1]:.6g}, {m[2]:.6g} kg.m2 break the triangle inequality "
            f"({m[2]:.6g} > {m[0]:.6g} + {m[1]:.6g}): no rigid body has this inertia (Basilisk refuses it)")


def implausible(values: dict, units: dict) -> list[tuple[str, str]]:
    """``[(parameter, problem)]`` for the values a model runs with although no physical system has them
    (today: an inertia ``J`` [kg.m2] whose principal moments break the triangle inequality); the
    orchestrator warns, it does not refuse (paper 001 publishes such a J)."""
    J = _arrays({k: v for k, v in values.items() if _split(k)[0] == "J"}).get("J")
    unit = next((units.get(k, "1") for k in values if _split(k)[0] == "J"), None)
    if J is None or unit != "kg.m2":
        return []
    p = triangle_problem(J)
    return [("J", f"J {p}")] if p else []


def problems(values: dict, units: dict) -> list[tuple[str, str]]:
    """``[(parameter, problem)]`` for the values (structured scalar names -> float) that no physical
    system has, by :data:`RULES`; ``units``: structured name -> unit."""
    out = []
    arrays = _arrays(values)
    unit_of = {}
    for name in values:
        unit_of.setdefault(_split(name)[0], units.get(name, "1"))
    for base, a in arrays.items():
        rule = RULES.get((base, unit_of[base]))
        if rule is None:
            continue
        if rule == "inertia":
            p = inertia_problem(a)
            if p:
                out.append((base, f"{base} {p}"))
            continue
        flat = a.ravel()
        ok = {"positive": flat > 0, "nonnegative": flat >= 0, "fraction": (flat >= 0) & (flat <= 1)}[rule]
        bad = ~ok & ~np.isnan(flat)
        if bad.any():
            k = int(np.argmax(bad))
            shown = f"{base} = {flat[k]:g}" if a.ndim == 0 else f"{base} has {flat[k]:g} (element {k + 1} of {a.size})"
            out.append((base, f"{shown} {unit_of[base]}: {WHAT[rule]}"))
    J, delta = arrays.get("J"), arrays.get("delta")
    if (J is not None and delta is not None and unit_of.get("J") == "kg.m2" and J.ndim == 2 and delta.ndim == 2
            and J.shape == (3, 3) and delta.shape[1] == 3 and not inertia_problem(J)):
        with np.errstate(all="ignore"):
            m = _eigenvalues(J - delta.T @ delta)
        if m is not None and m[0] <= 0:
            out.append(("delta", f"J - delta^T delta (the hub's inertia without the appendages, 000 (1)) is not positive "
                                 f"definite: eigenvalues {', '.join(f'{x:.6g}' for x in m)} kg.m2"))
    return out
