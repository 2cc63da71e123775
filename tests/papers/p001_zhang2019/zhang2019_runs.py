"""Short in-process runs of paper 001's shipped scenarios with overrides, cached per session."""
from __future__ import annotations

import dataclasses
from pathlib import Path

from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.toml import load

SCENARIOS = Path(__file__).resolve().parents[3] / "papers" / "p001_zhang2019" / "scenarios"
_CACHE: dict = {}


def scenario(name: str, stop: float | None = None, onset: float | None = None, overrides: dict | None = None,
             in_process: bool = True, fmu_dir=None):
    """The shipped scenario ``name`` with its stop time, fault onset (all wheels) and parameters
    ({instance: {structured name: value}}) overridden."""
    s = load(SCENARIOS / f"{name}.toml", in_process=in_process, fmu_dir=fmu_dir)
    values = {}
    if onset is not None:
        values["plant"] = {f"{kind}_onset[{j}]": onset for j in range(1, 5) for kind in ("effectiveness", "bias")}
        s = dataclasses.replace(s, metrics=dict(s.metrics, fault_onset=onset))
    for inst, v in (overrides or {}).items():
        values.setdefault(inst, {}).update(v)
    return with_overrides(s, stop=stop, parameters=values)


def run(name: str, stop: float | None = None, onset: float | None = None, overrides: dict | None = None, mode="inprocess"):
    key = (name, stop, onset, tuple(sorted((k, tuple(sorted(v.items()))) for k, v in (overrides or {}).items())), mode)
    if key not in _CACHE:
        s = scenario(name, stop, onset, overrides, in_process=(mode == "inprocess"))
        _CACHE[key] = (s, run_scenario(s))
    return _CACHE[key]
