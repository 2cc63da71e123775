"""The shipped arena (arena/ftc_arena.toml) against the acceptance list, and the realistic-hardware
rewrite of every cell's loop (arena/cells.py) checked on its connections: what reads the plant reads
a sensor, what reaches the plant comes from the wheels, the command is held."""
import dataclasses

import pytest

from arena import cells as C
from arena.arenafile import load
from arena.plan import build as plan
from tests.arena.reduced import ROOT

SHIPPED = ROOT / "arena" / "ftc_arena.toml"


@pytest.fixture(scope="module")
def shipped():
    return load(SHIPPED)


def test_shipped_arena_meets_the_acceptance_list(shipped):
    a = shipped
    paper = {c.plant: a.methods[c.method].paper for c in a.cells if c.gains == "own"}
    assert sorted(paper.values()) == ["000", "001", "002", "003", "004"]  # every paper's own pair
    cross = [c for c in a.cells if a.methods[c.method].paper != paper[c.plant]]
    assert len(cross) >= 6 and all(c.gains in ("redesigned", "published") for c in cross)
    assert all(c.gains == "own" for c in a.cells if c not in cross)
    assert len([f for f in a.faults if f != "none"]) >= 3 and "none" in a.faults  # fault-free draws: false alarms
    assert a.draws >= 20 and a.hardware == ["ideal", "realistic"]


def test_every_cell_with_each_hardware_loads(shipped):
    cells = plan(dataclasses.replace(shipped, mode="inprocess"))
    assert len(cells) == 2 * len(shipped.cells)


def _readers(conns, src):
    return [b for a, b in conns if a == src]


@pytest.mark.parametrize("index", range(17))
def test_realistic_rewrite_puts_sensors_wheels_and_a_hold_in_the_loop(shipped, index):
    if index >= len(shipped.cells):
        pytest.skip("fewer cells")
    cell = shipped.cells[index]
    ideal = C.cell_scenario(shipped, cell, "ideal")
    real = C.cell_scenario(shipped, cell, "realistic")
    conns = real["connections"]
    hw = shipped.plants[cell.plant].hardware
    insts = real["instances"]
    assert insts["wheels"]["parameter_set"] == hw["wheels"] and insts["zoh"]["parameter_set"] == hw["hold"]
    assert insts["gyro"]["parameter_set"] == hw["gyro"]
    if C.family(ideal) == "3-axis":  # issue 32: the plant carries the wheels' momentum, the wheels add no torque of it
        assert insts["plant"]["parameters"]["wheel_momentum"] == 1.0 and insts["wheels"]["parameters"]["gyroscopic"] == 0.0
    # the plant's rate reaches the method only through the gyro
    rate = "plant.theta_dot" if C.family(ideal) == "pitch" else "plant.omega"
    assert set(_readers(conns, rate)) <= {"gyro.omega", "wheels.omega"} and "gyro.omega" in _readers(conns, rate)
    # the attitude only through the star tracker / angle sensor
    for att in ("plant.q", "plant.theta", "plant.sigma"):
        for r in _readers(conns, att):
            assert r.split(".")[0] in ("st", "att", "st_e2q", "e2q"), (att, r)
    if "e2q" in insts:
        assert _readers(conns, "e2q.q") == ["st.q"]
    # the catalog's delivered torque goes to the wheels only; the wheels feed what the catalog fed
    assert set(_readers(conns, "faults.u_f")) <= {"wheels.u_c", "ralloc.u"}
    before = set(_readers(ideal["connections"], "faults.u_f"))
    after = {b for a, b in conns if a in ("wheels.tau", "wheels.u_wheel")}
    assert before == after, (before, after)
    # the command is held: its former readers read zoh.y
    cmd = next(a for a, b in conns if b == "zoh.u")
    assert _readers(conns, cmd) == ["zoh.u"]
    assert set(_readers(conns, "zoh.y")) == set(_readers(ideal["connections"], cmd))
    # the metrics' signals are recorded
    assert set(C.metric_signals(real, cell).values()) <= set(real["record"]["variables"])


@pytest.mark.parametrize("name", ["fasmc_on_zhang2019", "hinf_on_hang2023"])
def test_sampled_hardware_at_its_sample_period_gives_the_same_numbers(shipped, name):
    """The realistic rewrite steps the hold and the sensors at their sample period (a multirate run):
    every recorded signal equals the run with every instance at the communication step, bit for bit."""
    import copy
    import tempfile
    from pathlib import Path

    import numpy as np
    import tomli_w

    import ftcsim

    cell = next(c for c in shipped.cells if c.name == name)
    doc = C.cell_scenario(dataclasses.replace(shipped, stop=1.0), cell, "realistic")
    slow = {k for k, i in doc["instances"].items() if "step" in i}
    assert "zoh" in slow and ("st" in slow or "att" in slow)  # 10 Hz and 5 Hz on a 100 Hz communication step
    base = copy.deepcopy(doc)
    for inst in base["instances"].values():
        inst.pop("step", None)
    par = {"faults.fault_class": 3.0, "faults.onset": 0.33, "faults.magnitude": 0.05, "gyro.seed": 5.0}
    with tempfile.TemporaryDirectory() as tmp:
        runs = []
        for d in (doc, base):
            f = Path(tmp) / f"{len(runs)}.toml"
            f.write_text(tomli_w.dumps(d), encoding="utf-8")
            runs.append(ftcsim.run(str(f), mode="inprocess", parameters=par))
    a, b = runs
    assert a.info["step_statistics"]["policy"] == "multirate" and b.info["step_statistics"]["policy"] == "fixed"
    assert list(a.df.columns) == list(b.df.columns)
    assert np.array_equal(a.df.to_numpy(), b.df.to_numpy(), equal_nan=True)


def test_a_worker_can_warm_a_cell_with_sampled_hardware(shipped, tmp_path):
    """Workers of a remote cluster run a few steps of each base scenario first (campaign/shipping.py):
    with the sampled hardware on its own step, the warm-up ends on the slowest instance's grid."""
    import tomli_w

    from orchestrator.api import load as load_scenario
    from orchestrator.campaign.shipping import warm_span
    from orchestrator.cosim.runner import run_scenario
    from orchestrator.scenario.overrides import with_overrides

    cell = next(c for c in shipped.cells if c.name == "asmftc_on_hang2023")
    f = tmp_path / "real.toml"
    f.write_text(tomli_w.dumps(C.cell_scenario(shipped, cell, "realistic")), encoding="utf-8")
    sc = load_scenario(str(f), mode="inprocess")
    assert warm_span(sc) == pytest.approx(0.2)  # 3 steps of 0.5 ms, rounded up to the 5 Hz angle sensor
    assert run_scenario(with_overrides(sc, stop=sc.start + warm_span(sc))).complete
