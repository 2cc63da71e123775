"""Checks of a whole scenario before anything runs: the time grid, the size of the recorded data and
the step policy against the timing and the instances (see the step policies in ``orchestrator/scenario/toml.py``)."""
from __future__ import annotations

import dataclasses
import difflib
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from orchestrator.common.errors import InputError
from orchestrator.scenario.block_checks import check_block_initialisation
from orchestrator.scenario.model import StepSettings
from orchestrator.scenario.physical import check_physical
from orchestrator.scenario.refs import resolve_ref
from orchestrator.scenario.values import number, short

STEP_POLICIES = ("fixed", "multirate", "adaptive")
ADAPTIVE_KEYS = ("rtol", "atol", "min_step", "max_step", "output_step", "safety", "error_variables")
MAX_STEPS = 100_000_000
MAX_RESULT_BYTES = 4 * 2**30
MAX_SUBSTEPS = 100_000  # internal steps (h_max) per communication step a block may be asked for


def check_timing(src, start: float, stop: float, step: float, key="timing", blame="step") -> int:
    """Number of steps of [start, stop] with ``step`` (at least one); refuses what cannot run. A count
    of steps that is wrong is blamed on ``key.blame`` (the value that was given: ``stop`` when a
    stop time overrides the file's)."""
    if stop <= start:
        raise InputError(src, f"{key}.stop", f"stop ({stop:g}) must be after start ({start:g})")
    with np.errstate(over="ignore"):
        n = (stop - start) / step
    if not n < MAX_STEPS:
        raise InputError(src, f"{key}.{blame}", f"(stop - start) / step = {n:.3g} steps, more than the {MAX_STEPS:.0e} "
                                                "a run may take; use a larger step or a shorter run")
    if round(n) < 1:  # a run of no step would publish the initial values as a result (a stop too early)
        empty = "stop" if blame == "step" else blame
        raise InputError(src, f"{key}.{empty}", f"(stop - start) / step = {n:.3g}: the run would take no step of "
                                                f"{step:g} s; give a stop time at least one step after the start")
    if abs(n - round(n)) > 1e-9 * max(1.0, n):
        raise InputError(src, f"{key}.{blame}", f"(stop - start) / step = {n:g} is not a whole number of steps")
    return int(round(n))


def check_run_size(scenario) -> None:
    """Refuse, before any FMU starts, a run whose recorded data would not fit the limit (the step
    policy resolved: :func:`validate`)."""
    rows = int(round((scenario.stop - scenario.start) / scenario.output_step)) + 1
    size = rows * (len(scenario.record) + 1) * 8
    if size > MAX_RESULT_BYTES:
        raise InputError(scenario.path, "record", f"{rows} rows x {len(scenario.record) + 1} columns would take "
                         f"{size / 2**30:.1f} GiB (at most {MAX_RESULT_BYTES / 2**30:.0f} GiB): record fewer variables "
                         "or use a larger step")


def check_internal_steps(src, scenario) -> None:
    """Refuse step settings that would never finish, before any FMU starts: a block's internal
    step ``h_max`` (plant/integrate.py: ceil(step / h_max) RK4 steps per communication step) more
    than :data:`MAX_SUBSTEPS` times smaller than its communication step, and an adaptive
    ``min_step`` that allows more than :data:`MAX_STEPS` steps over the run."""
    for name, inst in scenario.instances.items():
        h_max = inst.parameters.get("h_max")
        step = inst.step or scenario.step
        if isinstance(h_max, (int, float)) and h_max > 0 and step / h_max > MAX_SUBSTEPS:
            raise InputError(src, f"instances.{name}.parameters.h_max", f"h_max = {h_max:g} s gives {step / h_max:.3g} "
                             f"internal steps per communication step of {step:g} s, more than {MAX_SUBSTEPS}: "
                             "use a larger h_max")
    st = scenario.timing
    if st.policy == "adaptive" and st.min_step and (scenario.stop - scenario.start) / st.min_step > MAX_STEPS:
        raise InputError(src, "timing.min_step", f"min_step = {st.min_step:g} s allows "
                         f"{(scenario.stop - scenario.start) / st.min_step:.3g} steps, more than the {MAX_STEPS:.0e} a "
                         "run may take: use a larger min_step")


def validate(src, scenario):
    """The checks of a whole scenario, once, after its parts were checked on their own: the time grid, the
    step policy (resolved, with the adaptive defaults), the size of the recorded data and the physical
    meaning of every parameter value (``orchestrator/scenario/physical.py``). Returns the
    scenario with the resolved step settings, ready to run."""
    check_timing(src, scenario.start, scenario.stop, scenario.step)
    scenario = dataclasses.replace(scenario, timing=check_step_policy(src, scenario))
    check_run_size(scenario)
    check_physical(src, scenario)
    check_block_initialisation(src, scenario)  # what the blocks themselves would refuse inside the FMUs
    check_internal_steps(src, scenario)
    return scenario


def multiple(x: float, base: float) -> int | None:
    """x / base if it is a whole number >= 1 (to 1e-9 relative), else None."""
    m = x / base
    k = int(round(m))
    return k if k >= 1 and abs(m - k) <= 1e-9 * m else None


def read_step_settings(src, timing: dict, instances: dict) -> StepSettings:
    """The step-policy keys of a [timing] table, each checked on its own (the checks between
    keys and against the instances are :func:`check_step_policy`'s)."""
    st = _editable(StepSettings(given=tuple(k for k in timing if k in ADAPTIVE_KEYS + ("step_policy", "record_announced"))))
    if "step_policy" in timing:
        p = timing["step_policy"]
        if p not in STEP_POLICIES:
            close = difflib.get_close_matches(str(p), STEP_POLICIES, n=1)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise InputError(src, "timing.step_policy", f"unknown policy {short(p)} ({hint}known: {', '.join(STEP_POLICIES)})")
        st.policy = p
    for k in ("rtol", "min_step", "max_step", "output_step", "safety"):
        if k in timing:
            setattr(st, k, number(src, f"timing.{k}", timing[k], positive=True))
    if "atol" in timing:
        st.atol = number(src, "timing.atol", timing["atol"])
        if st.atol < 0:
            raise InputError(src, "timing.atol", f"must be >= 0, got {st.atol:g}")
    if st.safety is not None and st.safety > 1:
        raise InputError(src, "timing.safety", f"must be in (0, 1], got {st.safety:g}")
    if "record_announced" in timing:
        if not isinstance(timing["record_announced"], bool):
            raise InputError(src, "timing.record_announced", f"expected true or false, got {short(timing['record_announced'])}")
        st.record_announced = timing["record_announced"]
    if "error_variables" in timing:
        refs = timing["error_variables"]
        if not isinstance(refs, list) or not refs:
            raise InputError(src, "timing.error_variables", "expected a non-empty list of 'instance.output'")
        for j, ref in enumerate(refs):
            inst, names = resolve_ref(src, f"timing.error_variables[{j}]", ref, instances, "output")
            st.error_variables += [(inst, n) for n in names]
        st.error_variables = list(dict.fromkeys(st.error_variables))
    return StepSettings(**vars(st))


def _editable(st: StepSettings) -> SimpleNamespace:
    """A working copy of ``st`` (StepSettings are frozen) whose lists are its own."""
    return SimpleNamespace(**{f.name: (list(v) if isinstance(v := getattr(st, f.name), list) else v)
                              for f in dataclasses.fields(st)})


def check_step_policy(src, sc) -> StepSettings:
    """Check the step policy of ``sc`` against its timing and instances; returns the step settings
    resolved: the policy, the adaptive defaults and every instance's step multiple (``sc`` itself
    is left as it is)."""
    st = _editable(sc.timing)
    given_policy = st.policy if "step_policy" in st.given else None
    own = {n: i for n, i in sc.instances.items() if i.step is not None and multiple(i.step, sc.step) != 1}
    announcers = {n: i for n, i in sc.instances.items() if i.announces}
    policy = given_policy or ("multirate" if own or announcers else "fixed")
    for name, inst in sc.instances.items():
        key = f"instances.{name}.step"
        if inst.step is None:
            continue
        m = multiple(inst.step, sc.step)
        if m is None:
            raise InputError(src, key, f"{inst.step:g} s is not a whole multiple of the base step timing.step = "
                                       f"{sc.step:g} s (an instance's step is m times the base step, m = 1, 2, ...)")
        if m != 1 and policy != "multirate":
            raise InputError(src, key, f"an instance step of its own ({inst.step:g} s, base {sc.step:g} s) needs "
                                       f"timing.step_policy = 'multirate', not {policy!r}")
        if sc.n_steps % m:
            raise InputError(src, key, f"the run ({sc.stop - sc.start:g} s) is not a whole number of this instance's "
                                       f"steps of {inst.step:g} s")
    for name, inst in announcers.items():
        key = f"instances.{name}.announces"
        if policy == "fixed":
            raise InputError(src, key, "announced instants need timing.step_policy = 'multirate' or 'adaptive', "
                                       "not 'fixed' (a fixed step cannot land on them)")
        if name in own:
            raise InputError(src, key, f"an instance that announces instants runs at the base step: remove its step "
                                       f"({inst.step:g} s) or its announcements")
    if st.record_announced and not announcers:
        raise InputError(src, "timing.record_announced", "no instance announces instants (instances.NAME.announces)")
    if policy != "adaptive":
        for k in ADAPTIVE_KEYS:
            if k in st.given:
                raise InputError(src, f"timing.{k}", f"only used with step_policy = 'adaptive' (this scenario's "
                                                     f"policy is {policy!r})")
    else:
        for name, inst in sc.instances.items():
            caps = inst.capabilities
            for flag, what in (("canGetAndSetFMUstate", "get and set its state (rollback)"),
                               ("canHandleVariableCommunicationStepSize", "vary its communication step")):
                if caps and not caps.get(flag, False):
                    raise InputError(src, f"instances.{name}.fmu", f"{Path(inst.fmu).name} cannot {what}: its "
                                     f"modelDescription has {flag} = false, and step_policy = 'adaptive' needs it")
        st.output_step = st.output_step if "output_step" in st.given else sc.step
        n = (sc.stop - sc.start) / st.output_step
        if abs(n - round(n)) > 1e-9 * max(1.0, n):
            raise InputError(src, "timing.output_step", f"(stop - start) / output_step = {n:g} is not a whole number "
                                                        "of output intervals")
        st.max_step = st.max_step if "max_step" in st.given else st.output_step
        st.min_step = st.min_step if "min_step" in st.given else min(st.output_step * 1e-3, st.max_step)
        if st.min_step > st.max_step:
            raise InputError(src, "timing.min_step", f"min_step = {st.min_step:g} s is larger than max_step = "
                                                     f"{st.max_step:g} s")
        if st.rtol is None:
            st.rtol = 1e-6
        if st.atol is None:
            st.atol = 1e-8
        if st.safety is None:
            st.safety = 0.9
        if not st.error_variables:
            st.error_variables = [(i, v) for i, v in sc.record if sc.instances[i].interface.causality.get(v) == "output"
                                  and not sc.instances[i].interface.feedthrough.get(v)]
            if not st.error_variables:
                raise InputError(src, "timing.error_variables", "no recorded output is a state (every one depends on "
                                 "an input): name the outputs whose error the step control watches")
    if policy == "multirate" or announcers:
        for name, inst in sc.instances.items():
            caps = inst.capabilities
            if announcers and name not in own and caps and not caps.get("canHandleVariableCommunicationStepSize", False):
                raise InputError(src, f"instances.{name}.fmu", f"{Path(inst.fmu).name} cannot vary its communication "
                                 "step (canHandleVariableCommunicationStepSize = false): landing on announced instants "
                                 "shortens the steps of every base-rate instance")
    st.policy = policy
    st.multiples = {name: multiple(inst.step, sc.step) for name, inst in sc.instances.items() if inst.step is not None}
    return StepSettings(**vars(st))
