"""004's scenario files: they load, state their departures, carry the published gains exactly,
and bad parameters reach the user as one message naming the instance."""
import dataclasses
import re
from pathlib import Path

import numpy as np
import pytest

from orchestrator.common.errors import InputError
from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.toml import load
from papers.p004_xu2024.gains import published_tensor
from papers.p004_xu2024.metrics import metrics

SCEN = Path(__file__).resolve().parents[3] / "papers" / "p004_xu2024" / "scenarios"
NAMES = sorted(p.stem for p in SCEN.glob("*.toml"))


def test_scenario_names():
    assert NAMES == ["xu2024_flexible", "xu2024_network_printed", "xu2024_ts", "xu2024_ts_published"]


@pytest.mark.parametrize("name", NAMES)
def test_scenarios_load_and_state_departures(name):
    sc = load(SCEN / f"{name}.toml", in_process=True)
    assert sc.name == name and sc.paper == "004" and len(sc.departures) >= 1
    assert sc.step == 0.001 and sc.exchange == "ordered"
    assert {i.model_name for i in sc.instances.values()} >= {"Xu2024MarkovFaults", "Xu2024SampledFTC",
                                                            "Xu2024FaultActuator", "Xu2024Disturbance"}


def test_published_scenario_carries_the_published_gains_exactly():
    sc = load(SCEN / "xu2024_ts_published.toml", in_process=True)
    p = sc.instances["ctrl"].parameters
    K = np.array([[[[p[f"K[{r},{j},{a},{b}]"] for b in range(1, 7)] for a in range(1, 4)] for j in range(1, 4)]
                  for r in range(1, 4)])
    assert np.array_equal(K, published_tensor(sign_fix=True))


def test_printed_network_scenario_commands_nothing():
    sc = with_overrides(load(SCEN / "xu2024_network_printed.toml", in_process=True), stop=0.3)
    r = run_scenario(sc)
    assert r.complete and np.abs(r.vector("ctrl.u")).max() < 1e-9
    assert abs(r.column("ctrl.network_gain")[0]) < 1e-15
    m = metrics(r, sc)
    assert m["max_abs_u"] < 1e-9 and m["n_samples"] >= 3


@pytest.mark.parametrize("inst, params, words", [
    ("ctrl", {"tau_min": 0.2}, "tau_min = 0.2 s > tau_max = 0.1 s"),
    ("faults", {"Pi[1,2,3]": 5.0}, "Pi vertex 1: row 2 sums to 1 1/s, not 0"),
])
def test_bad_parameters_fail_the_run_with_one_message(inst, params, words):
    base = load(SCEN / "xu2024_ts.toml", in_process=True)
    # refused before anything runs, in the block's own words (issue 35: its initialize is run in-process)
    with pytest.raises(InputError, match=re.escape(words)):
        with_overrides(base, stop=0.01, parameters={inst: params})
    # and the block refuses it itself when a host hands it over (the checks bypassed): one message naming both
    sc = with_overrides(base, stop=0.01)
    i = dataclasses.replace(sc.instances[inst], parameters={**sc.instances[inst].parameters, **params})
    r = run_scenario(dataclasses.replace(sc, instances={**sc.instances, inst: i}))
    assert not r.complete and f"instance '{inst}'" in r.error and words in r.error, r.error
