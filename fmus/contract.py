"""Check that a block keeps the block contract (``plant/block.py``) before it becomes an FMU.

``ftcsim build --block pkg.module:Class`` runs :func:`check_block` on a block it did not write;
each broken rule is one line naming the class and the problem, all of them raised together as
a :class:`ContractError`. What is checked, in order (a later group needs the earlier ones):

1. the interface: every member of :class:`plant.block.BlockProtocol` present, ``model_name`` a
   plain identifier, variable names structured FMI names (``omega[1]``, ``J[1,2]``, ``k_p``)
   and unique, every variable with a unit that the build knows (``plant/units.py: UNITS``;
   ``"1"`` for none), finite start values, ``feedthrough`` naming outputs and inputs only,
   ``param_values`` holding one number per parameter, ``announced_instants`` naming outputs in s;
2. ``initialize(0.0)`` with the defaults, outputs of the declared length, finite, announced
   instants after the current time, and a state that ``json`` serialises as floats (what the
   FMU's serialised state holds);
3. ``outputs_at`` is pure: calling it (at several inputs) changes neither ``get_state()`` nor
   what the block does next (a twin block stepped without those calls stays identical, bit
   for bit), and the same call twice gives the same outputs;
4. the feedthrough probe: each input is perturbed, at the defaults and at random inputs, at
   the initial state and after a few steps; an output that changes is an output that depends
   on that input, and must be declared. A declared dependence the probe never sees (a
   saturated output, a flat point) is only reported as a warning: a probe cannot prove that
   a dependence does not exist;
5. rollback: ``set_state(get_state())`` after a few steps, in the same block and in a fresh
   one (through ``json``, as FMU serialisation does), reproduces the outputs and the state of
   the following steps bit for bit.

Probes use the first communication step of ``PROBE_STEPS_S`` that the block accepts (or the
one given) and a fixed random seed, so a verdict does not change from run to run. Inputs that
``outputs_at`` refuses to see moved (a discrete mode number) are held at their defaults.
"""
from __future__ import annotations

import json
import math
import re

import numpy as np

from plant.block import BlockProtocol
from plant.units import UNITS

PROBE_STEPS_S = (0.01, 0.001, 0.0001)  # s, communication steps the probes try, in this order
PROBE_STEPS = 5  # steps before the probes at an advanced state and before the rollback point
STRUCTURED_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\[[0-9]+(,[0-9]+)*\])?$")
PLAIN_IDENTIFIER = re.compile(r"^[A-Za-z_][A-Za-z0-9_]{0,127}$")
# what plant.block.BlockProtocol requires: its attributes, then its methods
_MEMBERS = tuple(BlockProtocol.__annotations__) + tuple(
    n for n, f in vars(BlockProtocol).items() if callable(f) and not n.startswith("_"))


# characters XML 1.0 allows in text (tab, line feed, carriage return and the printable range, surrogates excluded)
_XML_TEXT = re.compile("[\t\n\r\u0020-\ud7ff\ue000-\ufffd\U00010000-\U0010ffff]*")


class ContractError(ValueError):
    """The block at ``ref`` breaks the contract; ``problems`` lists every broken rule."""

    def __init__(self, ref: str, problems: list[str]):
        self.ref, self.problems = ref, list(problems)
        super().__init__(f"{ref} breaks the block contract (plant/block.py): " + "; ".join(self.problems))


def _bits(x) -> bytes:
    return np.ascontiguousarray(np.asarray(x, dtype=float)).tobytes()


def _list(names, n=6) -> str:
    names = list(names)
    return ", ".join(names[:n]) + (f" and {len(names) - n} more" if len(names) > n else "")


def _call(what: str, f, *args):
    """``f(*args)``; an exception becomes a problem string naming the call."""
    try:
        return f(*args), None
    except Exception as e:
        return None, f"{what} raised {type(e).__name__}: {' '.join(str(e).split())[:300]}"


# -- 1. interface --------------------------------------------------------------------------------
def interface_problems(block, units=None, reserved=()) -> list[str]:
    """Static problems of the interface (no call into the block)."""
    if units is None:
        units = UNITS
    missing = [m for m in _MEMBERS if not hasattr(block, m)]
    if missing:
        return [f"missing members of the block protocol: {', '.join(missing)} (see plant/block.py: BlockProtocol)"]
    problems = []
    name = block.model_name
    if not isinstance(name, str) or not PLAIN_IDENTIFIER.match(name):
        problems.append(f"model_name {name!r} is not a plain identifier (letters, digits, '_'): it names the FMU "
                        "file, its modelIdentifier and its slave class")
    elif name in reserved:
        problems.append(f"model_name {name!r} is the name of a shipped FMU; choose another one")
    texts = [("description", getattr(block, "description", ""))]
    groups = {"inputs": block.inputs, "outputs": block.outputs, "parameters": block.parameters}
    seen, dup, no_unit, bad_unit, not_finite, bad_name = {}, [], [], {}, [], []
    for group, variables in groups.items():
        if not isinstance(variables, (list, tuple)):
            problems.append(f"{group} is a {type(variables).__name__}, not a list of Variable")
            continue
        for v in variables:
            vname, unit, start = getattr(v, "name", None), getattr(v, "unit", None), getattr(v, "start", None)
            if not isinstance(vname, str) or not STRUCTURED_NAME.match(vname):
                bad_name.append(repr(vname))
                continue
            texts.append((f"description of {vname}", getattr(v, "description", "")))
            if vname in seen:
                dup.append(f"{vname} ({seen[vname]} and {group})")
            seen[vname] = group
            if not isinstance(unit, str) or not unit:
                no_unit.append(vname)
            elif unit not in units:
                bad_unit.setdefault(unit, []).append(vname)
            try:
                ok = math.isfinite(float(start))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                not_finite.append(f"{vname} = {start!r}")
    for where, text in texts:  # they go into the modelDescription: XML 1.0 has no control characters
        if text is not None and not isinstance(text, str):
            problems.append(f"the {where} is a {type(text).__name__}, not text")
        elif text and not _XML_TEXT.fullmatch(text):
            bad = next(c for c in text if not _XML_TEXT.fullmatch(c))
            problems.append(f"the {where} holds the control character {bad!r}, which a modelDescription (XML) cannot "
                            "carry; remove it")
    if bad_name:
        problems.append(f"variable names that are not structured FMI names like omega[1], J[1,2] or k_p: {_list(bad_name)}")
    if dup:
        problems.append(f"duplicate variable names: {_list(dup)}")
    if no_unit:
        problems.append(f"variables without a unit: {_list(no_unit)} (declare one; \"1\" if dimensionless)")
    for unit, names in bad_unit.items():
        problems.append(f"unit {unit!r} of {_list(names)} is not one the build knows (known: {', '.join(units)}; "
                        "plant/units.py: UNITS)")
    if not_finite:
        problems.append(f"non-finite default (start) values: {_list(not_finite)}")
    feed = block.feedthrough
    if not isinstance(feed, dict):
        problems.append(f"feedthrough is a {type(feed).__name__}, not a dict output -> inputs")
    else:
        outs = {getattr(v, "name", None) for v in groups["outputs"]}
        ins = {getattr(v, "name", None) for v in groups["inputs"]}
        for out, deps in feed.items():
            if out not in outs:
                problems.append(f"feedthrough names {out!r}, which is not an output")
            unknown = [d for d in (deps if isinstance(deps, (list, tuple, set, frozenset)) else [deps]) if d not in ins]
            if unknown:
                problems.append(f"feedthrough of {out} names {_list(map(repr, unknown))}, not inputs")
    try:
        n_values = len(block.param_values)
    except TypeError:
        n_values = None
    if not problems and isinstance(groups["parameters"], (list, tuple)) and n_values != len(groups["parameters"]):
        problems.append(f"param_values holds {n_values if n_values is not None else 'no sequence of'} values for "
                        f"{len(groups['parameters'])} declared parameters (one float per parameter, in declared order)")
    announced = block.announced_instants
    if isinstance(announced, str) or not isinstance(announced, (list, tuple)):
        problems.append(f"announced_instants is a {type(announced).__name__}, not a tuple of output names")
    else:
        units = {getattr(v, "name", None): getattr(v, "unit", None) for v in groups["outputs"]}
        for name in announced:
            if name not in units:
                problems.append(f"announced_instants names {name!r}, which is not an output")
            elif units[name] != "s":
                problems.append(f"announced instant {name} has unit {units[name]!r}: it is a time, unit 's'")
    return problems


# -- 2.-5. behaviour ----------------------------------------------------------------------------
class _Probe:
    """Calls into one block, with the block's own problems turned into messages."""

    def __init__(self, factory, ref, step):
        self.factory, self.ref, self.step = factory, ref, step

    def fail(self, *problems):
        return ContractError(self.ref, list(problems))

    def fresh(self):
        block, err = _call(f"{self.ref}()", self.factory)
        if err:
            raise self.fail(err)
        _, err = _call("initialize(0.0) with the default parameters", block.initialize, 0.0)
        if err:
            raise self.fail(err)
        return block

    def outputs(self, block, t, u, n_out):
        y, err = _call(f"outputs_at({t:g}, u)", block.outputs_at, t, np.array(u, dtype=float))
        if err:
            raise self.fail(err)
        y = np.asarray(y, dtype=float).ravel()
        if y.size != n_out:
            raise self.fail(f"outputs_at returns {y.size} values for {n_out} declared outputs")
        return y

    def advance(self, block, t, u):
        _, err = _call(f"advance({t:g}, {self.step:g}, u)", block.advance, t, self.step, np.array(u, dtype=float))
        if err:
            raise self.fail(err)

    def state(self, block):
        s, err = _call("get_state()", block.get_state)
        if err:
            raise self.fail(err)
        return s


def _json_state(probe, state):
    try:
        flat = json.loads(json.dumps(list(state)))
    except (TypeError, ValueError) as e:
        raise probe.fail(f"get_state() is not a flat list of floats that JSON serialises (the FMU state is "
                         f"serialised that way): {e}") from None
    bad = [x for x in flat if isinstance(x, bool) or not isinstance(x, (int, float))]
    if bad:
        raise probe.fail(f"get_state() holds non-numbers ({_list(map(repr, bad), 3)}): it must be a flat list of floats")
    return flat


def _perturbation(x):
    return 1e-3 * (1.0 + abs(x))


def _free_inputs(block, u0, ins) -> tuple[np.ndarray, list[str]]:
    """Which inputs the probes may move: those for which ``outputs_at`` accepts a nearby value
    (a discrete input such as a mode number refuses 1.001). Returns (mask, warnings)."""
    free = np.ones(len(ins), dtype=bool)
    for i in range(len(ins)):
        for delta in (_perturbation(u0[i]), 0.1 * (1.0 + abs(u0[i]))):
            u = np.array(u0)
            u[i] += delta
            try:
                ok = np.all(np.isfinite(np.asarray(block.outputs_at(0.0, u), dtype=float)))
            except Exception:
                ok = False
            if not ok:
                free[i] = False
                break
    fixed = [ins[i] for i in np.flatnonzero(~free)]
    warnings = [f"outputs_at refuses values near the defaults of {_list(fixed)} (a discrete input?): the probes hold "
                "them at their defaults, their feedthrough is not probed"] if fixed else []
    return free, warnings


def _step_accepted(probe, drive) -> float:
    """The first of ``PROBE_STEPS_S`` with which the block's ``advance`` takes every probe step
    (some blocks are built for one communication step, or for steps that divide a sample grid)."""
    errors = []
    for h in PROBE_STEPS_S:
        b = probe.fresh()
        err = None
        for k, u in enumerate(drive):
            _, err = _call(f"advance({k * h:g}, {h:g}, u)", b.advance, k * h, h, np.array(u))
            if err:
                break
        if err is None:
            return h
        errors.append(err)
    raise probe.fail(f"{errors[0]} (the probes also tried steps of {', '.join(f'{h:g}' for h in PROBE_STEPS_S[1:])} s; "
                     "give the block's step with --probe-step)")


def check_block(factory, ref: str, reserved=(), step: float | None = None) -> list[str]:
    """Check the block that ``factory()`` returns (``ref`` names it in messages). Raises
    :class:`ContractError` listing the broken rules; returns warnings (declared dependences the
    probe did not see, inputs it could not move). ``step``: the communication step of the
    probes (default: the first of ``PROBE_STEPS_S`` the block accepts)."""
    block, err = _call(f"{ref}()", factory)
    if err:
        raise ContractError(ref, [err + " (a class or factory callable without arguments is required)"])
    problems = interface_problems(block, reserved=reserved)
    if problems:
        raise ContractError(ref, problems)
    ins = [v.name for v in block.inputs]
    outs = [v.name for v in block.outputs]
    n_out = len(outs)

    # 2. initialisation, defaults
    probe = _Probe(factory, ref, step or PROBE_STEPS_S[0])
    block = probe.fresh()
    u0, err = _call("default_inputs()", block.default_inputs)
    if err:
        raise probe.fail(err)
    u0 = np.asarray(u0, dtype=float).ravel()
    if u0.size != len(ins):
        raise probe.fail(f"default_inputs() returns {u0.size} values for {len(ins)} declared inputs")
    y0 = probe.outputs(block, 0.0, u0, n_out)
    if not np.all(np.isfinite(y0)):
        bad = [outs[i] for i in np.flatnonzero(~np.isfinite(y0))]
        raise probe.fail(f"outputs_at(0, default inputs) gives non-finite values for {_list(bad)}")
    early = [f"{n} = {y0[outs.index(n)]!r}" for n in block.announced_instants if not y0[outs.index(n)] > 0.0]
    if early:
        raise probe.fail(f"announced instants not after the current time t = 0: {_list(early)} (an announced instant "
                         "is the next time the block must be stepped to)")
    _json_state(probe, probe.state(block))

    free, warnings = _free_inputs(block, u0, ins)
    rng = np.random.default_rng(0)
    scale = (1.0 + np.abs(u0)) * free

    def near(size):
        return u0 + size * scale * rng.standard_normal(u0.size)

    points = [u0, near(0.01), near(0.1)]  # operating points of the probes (fixed seed)
    drive = [near(0.1) for _ in range(2 * PROBE_STEPS)]  # inputs held over the probe steps
    if step is None:
        probe.step = _step_accepted(probe, drive)
    h = probe.step

    # 3. outputs_at is pure
    problems = []
    twin = probe.fresh()
    s_before = _bits(probe.state(block))
    first = [probe.outputs(block, 0.0, u, n_out) for u in points]
    again = [probe.outputs(block, 0.0, u, n_out) for u in points]
    if _bits(probe.state(block)) != s_before:
        problems.append("outputs_at changes the state returned by get_state(): it must be a pure function of (t, state, u)")
    if any(_bits(a) != _bits(b) for a, b in zip(first, again)):
        problems.append("outputs_at gives different outputs for the same (t, state, u) when called again")
    t = 0.0
    for k in range(0 if problems else PROBE_STEPS):
        for u in points:
            probe.outputs(block, t, u, n_out)
        probe.advance(block, t, drive[k])
        probe.advance(twin, t, drive[k])
        t = (k + 1) * h
        if _bits(probe.state(block)) != _bits(probe.state(twin)) or \
                _bits(probe.outputs(block, t, drive[k], n_out)) != _bits(probe.outputs(twin, t, drive[k], n_out)):
            problems.append(f"calling outputs_at changes what the block does next (a twin block stepped without those "
                            f"calls differs after step {k + 1}): outputs_at must not change any state")
            break
    if problems:
        raise probe.fail(*problems)

    # 4. feedthrough probe, at the initial state and after PROBE_STEPS steps
    declared = {o: set(block.feedthrough.get(o, ())) for o in outs}
    seen = {o: set() for o in outs}
    advanced = probe.fresh()
    for k in range(PROBE_STEPS):
        probe.advance(advanced, k * h, drive[k])
    for b, t in ((probe.fresh(), 0.0), (advanced, PROBE_STEPS * h)):
        for u in points:
            y = probe.outputs(b, t, u, n_out)
            for i in np.flatnonzero(free):
                du = np.array(u)
                du[i] += _perturbation(du[i])
                for j in np.flatnonzero(_changed(y, probe.outputs(b, t, du, n_out))):
                    seen[outs[j]].add(ins[i])
    undeclared = [f"{o} <- {_list(sorted(seen[o] - declared[o], key=ins.index), 4)}" for o in outs if seen[o] - declared[o]]
    if undeclared:
        raise probe.fail(f"undeclared feedthrough: outputs change within the step when these inputs change, but "
                         f"feedthrough does not declare it: {_list(undeclared, 4)}")
    fixed = {ins[i] for i in np.flatnonzero(~free)}
    warnings += [f"{o} is declared to depend on {_list(sorted(declared[o] - seen[o] - fixed, key=ins.index), 4)}, which "
                 "the probe never saw change it (keep it only if the dependence is real)"
                 for o in outs if declared[o] - seen[o] - fixed]

    # 5. rollback
    b = probe.fresh()
    t_save = 0.0
    for k in range(PROBE_STEPS):
        probe.advance(b, k * h, drive[k])
        t_save = (k + 1) * h
    saved = list(probe.state(b))
    flat = _json_state(probe, saved)

    def run(block_):
        rows, tt = [], t_save
        for k in range(PROBE_STEPS, 2 * PROBE_STEPS):
            rows.append(_bits(probe.outputs(block_, tt, drive[k], n_out)))
            probe.advance(block_, tt, drive[k])
            tt += h
        rows.append(_bits(probe.outputs(block_, tt, drive[0], n_out)))
        return rows, _bits(probe.state(block_))

    reference = run(b)
    for label, target, state in (("the same block", b, saved), ("a fresh block (state through JSON)", probe.fresh(), flat)):
        _, err = _call("set_state(get_state())", target.set_state, state)
        if err:
            raise probe.fail(err)
        replay = run(target)
        if replay != reference:
            k = next((k for k, (a, c) in enumerate(zip(replay[0], reference[0])) if a != c), None)
            where = ("the state differs" if k is None else "the outputs differ right after the restore" if k == 0
                     else f"the outputs differ {k} step(s) after the restore")
            raise probe.fail(f"state not restorable: after set_state(get_state()) at t = {t_save:g} s into {label}, the "
                             f"same inputs do not reproduce the run bit for bit ({where}): get_state() must return "
                             "every internal state")
    return warnings


def _changed(y, y2) -> np.ndarray:
    """Elementwise: did the output change (bitwise, NaN-safe)?"""
    a = np.asarray(y, dtype=float).view(np.uint64)
    b = np.asarray(y2, dtype=float).view(np.uint64)
    return a != b
