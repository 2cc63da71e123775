"""References to instance variables (``"ctrl.u"``, ``"plant.q[0]"``): expansion to scalar names, the
checks of a reference, a connection (both ends, element counts, units) and an announced instant, and
the short summaries the messages use."""
from __future__ import annotations

import re

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.scenario.model import Interface
from orchestrator.scenario.values import article, hint, short
from plant.block import split_name
from plant.units import mismatch

REF = re.compile(r"^(?P<inst>[A-Za-z_][A-Za-z0-9_]*)\.(?P<var>.+)$")


def expand(interface: Interface, name: str, causality=None) -> list[str]:
    """Scalar names behind ``name``: itself if scalar, ``name[...]`` elements in index
    order if it is a vector/matrix base name. Empty list if unknown."""
    if name in interface.causality:
        names = [name]
    else:
        items = [(split_name(n)[1], n) for n in interface.causality if split_name(n)[0] == name and "[" in n]
        names = [n for _, n in sorted(items)]
    if causality is not None:
        names = [n for n in names if interface.causality[n] == causality]
    return names


def shape_of(names) -> tuple:
    idx = np.array([split_name(n)[1] for n in names])
    if idx.size == 0 or idx.ndim == 1:
        return ()
    return tuple(int(x) for x in (idx.max(axis=0) - idx.min(axis=0) + 1))


def summary(names, limit=12) -> str:
    """``q[0], q[1], .., omega[1..3]`` -> ``'q[0..3], omega[1..3]'`` (structured names grouped by base)."""
    groups = {}
    for n in names:
        base, idx = split_name(n)
        groups.setdefault(base, []).append(idx)
    parts = []
    for base, idx in groups.items():
        if idx == [()]:
            parts.append(base)
        elif all(len(i) == 1 for i in idx):
            lo, hi = min(i[0] for i in idx), max(i[0] for i in idx)
            parts.append(f"{base}[{lo}..{hi}]" if len(idx) == hi - lo + 1 else f"{base}[{len(idx)} elements]")
        else:  # a matrix or tensor: its shape
            shape = (max(i[d] for i in idx) - min(i[d] for i in idx) + 1 for d in range(len(idx[0])))
            parts.append(f"{base}[{'x'.join(map(str, shape))}]")
    more = f" and {len(parts) - limit} more" if len(parts) > limit else ""
    return ", ".join(parts[:limit]) + more if parts else "none"


def instance_label(inst, itf) -> str:
    return f"instance '{inst}' ({itf.model_name}{', ' + itf.origin if itf.origin else ''})"


def reference(src, key, ref, instances):
    """'inst.var' -> (inst, var) or InputError for a malformed reference or an unknown instance."""
    if not isinstance(ref, str):
        raise InputError(src, key, f"expected 'instance.variable', got {short(ref)}")
    m = REF.match(ref)
    if not m:
        raise InputError(src, key, f"{short(ref)} is not of the form 'instance.variable'")
    if m["inst"] not in instances:
        raise InputError(src, key, f"unknown instance '{m['inst']}'{hint(m['inst'], instances)} (instances: "
                                   f"{', '.join(instances)})")
    return m["inst"], m["var"]


def end_problem(inst, var, itf, names, causality) -> str | None:
    """Why ``inst.var`` (scalar ``names``) cannot be used as ``causality``, or None."""
    if not names:
        hint = f"its {causality}s" if causality else "its inputs and outputs"
        pool = itf.names(causality) if causality else itf.names("input") + itf.names("output")
        return f"{instance_label(inst, itf)} has no variable {short(var)} ({hint}: {summary(pool)})"
    if causality is not None:
        bad = [n for n in names if itf.causality[n] != causality]
        if bad:
            return f"'{inst}.{bad[0]}' is {article(itf.causality[bad[0]])}, expected {article(causality)}"
    return None


def resolve_ref(src, key, ref, instances, causality=None):
    """'inst.var' -> (inst, [scalar names])."""
    inst, var = reference(src, key, ref, instances)
    itf = instances[inst].interface
    names = expand(itf, var)
    problem = end_problem(inst, var, itf, names, causality)
    if problem:
        raise InputError(src, key, problem)
    return inst, names


def connection(src, key, pair, instances):
    """A connection ``[from, to]`` -> (s_inst, s_names, d_inst, d_names, problems): the problems
    name both ends (a missing variable, causality, element counts, units)."""
    (s_inst, s_var), (d_inst, d_var) = (reference(src, key, r, instances) for r in pair)
    s_itf, d_itf = instances[s_inst].interface, instances[d_inst].interface
    s_names, d_names = expand(s_itf, s_var), expand(d_itf, d_var)
    problems = [p for p in (end_problem(s_inst, s_var, s_itf, s_names, "output"),
                            end_problem(d_inst, d_var, d_itf, d_names, "input")) if p]
    if s_names and d_names and all(s_itf.causality[n] == "output" for n in s_names) and \
            all(d_itf.causality[n] == "output" for n in d_names):
        problems[-1] += " (an output wired to an output)"
    if not problems and len(s_names) != len(d_names):
        problems.append(f"{pair[0]} has {len(s_names)} elements, {pair[1]} has {len(d_names)}")
    if s_names and d_names and len(s_names) == len(d_names):
        units = {}
        for sn, dn in zip(s_names, d_names):
            su, du = s_itf.units.get(sn, "1"), d_itf.units.get(dn, "1")
            why = mismatch(su, s_itf.unit_definitions, du, d_itf.unit_definitions)
            if why:
                units.setdefault(why, []).append((sn, dn))
        for why, pairs in units.items():
            problems.append(f"unit mismatch, {why}: {s_inst}.{summary([a for a, _ in pairs])} ({s_itf.model_name} output) "
                            f"drives {d_inst}.{summary([b for _, b in pairs])} ({d_itf.model_name} input)")
    return s_inst, s_names, d_inst, d_names, problems


def check_announces(src, key, names, itf: Interface) -> list[str]:
    """``announces = ["t_next_sample"]``: outputs of the instance holding its next instant (s)."""
    if isinstance(names, str):
        names = [names]
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        raise InputError(src, key, f"expected a list of output names, got {short(names)}")
    for n in names:
        c = itf.causality.get(n)
        if c != "output":
            what = "no such variable" if c is None else f"it is {'an' if c[0] in 'aeiou' else 'a'} {c}"
            raise InputError(src, key, f"{n!r} is not an output of {itf.model_name} ({what}); announced instants "
                                       "are outputs holding the next time to step to (s)")
    return list(dict.fromkeys(names))
