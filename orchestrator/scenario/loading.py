"""Any scenario argument to a validated scenario: a shipped name, a ``.toml`` file or an ``.ssp``
package, loaded for FMUs or in-process blocks, with the overrides applied (start, stop and step in s,
parameters, design files). What ``ftcsim run``, ``ftcsim.run`` and every campaign run load through."""
from __future__ import annotations

import logging
import os

from orchestrator.common.errors import InputError
from orchestrator.scenario.model import Scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.shipped import resolve_scenario
from orchestrator.scenario.ssp import load_ssp
from orchestrator.scenario.toml import load as load_toml
from orchestrator.scenario.values import number

MODES = ("fmu", "inprocess")
log = logging.getLogger("ftcsim.scenario")


def load_scenario(scenario, *, mode="fmu", fmu_dir=None, start=None, stop=None, step=None, parameters=None, gains=(),
                  src="api", option="parameters") -> Scenario:
    """The validated scenario ``scenario`` (a shipped name or a path) for ``mode`` (``"fmu"``: the FMUs of
    ``fmu_dir``; ``"inprocess"``: the blocks), with the overrides of :func:`with_overrides`; ``step``
    replaces the communication step before the file is checked. Problems are ``InputError``s."""
    flag = option.startswith("--")
    if not isinstance(scenario, (str, os.PathLike)):
        raise InputError(src, "scenario", f"expected a shipped scenario name or a path, got {type(scenario).__name__}")
    if fmu_dir is not None and not isinstance(fmu_dir, (str, os.PathLike)):
        raise InputError(src, "--fmu-dir" if flag else "fmu_dir", f"expected a folder, got {type(fmu_dir).__name__}")
    if mode not in MODES:
        raise InputError(src, "--mode" if flag else "mode", f"must be 'fmu' or 'inprocess', not {mode!r}")
    path = resolve_scenario(os.fspath(scenario))
    in_process = mode == "inprocess"
    if step is not None:
        step = number(src, "--step" if flag else "step", step, positive=True)
    try:
        if path.suffix == ".ssp":
            sc = load_ssp(path, in_process=in_process, step=step)
        else:
            sc = load_toml(path, fmu_dir=fmu_dir, in_process=in_process, step=step)
    except InputError as e:  # a step count made wrong by the step given here: named as that option
        if step is None or e.key not in ("timing.step", "timing.stop") or e.source != str(path) \
                or "step" not in e.problem:
            raise
        raise InputError(src, "--step" if flag else "step", e.problem) from None
    if start is not None or stop is not None or parameters or gains:
        sc = with_overrides(sc, start=start, stop=stop, parameters=parameters, gains=gains, src=src, option=option)
    log.debug("loaded %s from %s (%s): %d instances, %g to %g s, step %g s, %d recorded variables", sc.name, sc.path,
              mode, len(sc.instances), sc.start, sc.stop, sc.step, len(sc.record))
    return sc
