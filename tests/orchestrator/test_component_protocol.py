"""The component protocol (orchestrator/cosim/component.py) is complete: both kinds of component have
every member it lists, and a run that uses every feature of the engine (ordered exchange, adaptive
steps with rollback, campaign read-back, set-up and release) touches no member it does not list."""
import pytest
from scenario_text import variant, write

from orchestrator.cosim import runner
from orchestrator.cosim.block import BlockComponent
from orchestrator.cosim.component import Component
from orchestrator.cosim.fmu import FMU2Component, FMU3Component
from orchestrator.scenario.toml import load
from papers.registry import scenario_files

FASMC = scenario_files()["li2023_fasmc"].read_text()
ADAPTIVE = {
    "stop = 200.0": "stop = 0.1", "step = 0.01": "step = 0.005",
    'exchange = "ordered"': 'exchange = "ordered"\nstep_policy = "adaptive"\nrtol = 1e-6\natol = 1e-7\noutput_step = 0.01',
}
MEMBERS = set(Component.__annotations__) | {n for n, f in vars(Component).items() if callable(f) and not n.startswith("_")}


class Recording:
    """A component seen through the protocol only: every attribute the engine reads is noted."""

    def __init__(self, inner, seen):
        object.__setattr__(self, "_inner", inner)
        object.__setattr__(self, "_seen", seen)

    def __getattr__(self, name):
        self._seen.add(name)
        return getattr(self._inner, name)


def test_every_kind_of_component_has_every_member(tmp_path, fmu_dir, fmi3_dir):
    sc = load(write(tmp_path, variant(ADAPTIVE, FASMC), "f.toml"))
    for name, inst in sc.instances.items():
        fmu = runner.make_components(sc)[name]
        assert isinstance(fmu, FMU2Component) and isinstance(fmu, Component)
        assert isinstance(FMU3Component(name, fmi3_dir / inst.fmu.name, _md(fmi3_dir / inst.fmu.name)), Component)
        assert isinstance(BlockComponent(name, _factory(inst.model_name)()), Component)
        missing = [m for m in MEMBERS if not hasattr(fmu, m)]
        assert not missing, missing


def _md(path):
    from fmpy import read_model_description

    return read_model_description(str(path))


def _factory(model):
    from orchestrator.scenario.shipped import block_factory

    return block_factory(model)


@pytest.mark.parametrize("in_process", [True, False], ids=["blocks", "fmus"])
def test_the_engine_uses_nothing_outside_the_protocol(tmp_path, monkeypatch, in_process, fmu_dir):
    sc = load(write(tmp_path, variant(ADAPTIVE, FASMC), "a.toml"), in_process=in_process)
    seen: set = set()
    make = runner.make_components
    monkeypatch.setattr(runner, "make_components", lambda s: {n: Recording(c, seen) for n, c in make(s).items()})
    read = {}

    def read_back(comps):
        for n, c in comps.items():
            first = [v for v, info in c.variables.items() if info.causality == "parameter"][:1]
            read[n] = c.read_values(first)

    r = runner.run_scenario(sc, after_setup=read_back)
    assert r.complete, r.error
    assert r.info["step_statistics"]["rollbacks"] > 0  # get_state / set_state / free_state were used
    assert all(len(v) == 1 for v in read.values())
    assert seen - MEMBERS == set()
    assert {"prepare", "read_some", "write_some", "step", "get_state", "set_state", "free_state", "can_roll_back",
            "variable_step", "setup", "terminate", "read_values", "bind", "subset"} <= seen
