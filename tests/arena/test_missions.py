"""Each plant's mission in the shipped arena is long enough for the paper's own method to settle: the
own pair, ideal hardware, no fault, over the plant's mission, measured as the arena measures it,
flies (inside the plant's band at the end) and enters the band for good before the last 15 % of the
mission (a mission that cut the method off mid-manoeuvre would decide its verdict; issue 33: 000's
FASMC enters 0.01 rad at about 121 s, so a 120 s mission read "cannot fly")."""
import tempfile
from pathlib import Path

import pytest
import tomli_w

import ftcsim
from arena import cells as C
from arena.arenafile import load
from arena.measure import measure
from plant.hardware.datasheets import WHEELS
from tests.arena.reduced import ROOT

ARENA = load(ROOT / "arena" / "ftc_arena.toml")
OWN = {c.plant: c for c in ARENA.cells if c.gains == "own"}
TAIL = 0.15  # the share of the mission the method must spend inside the band at the end


@pytest.mark.parametrize("plant", sorted(ARENA.plants))
def test_the_papers_own_method_settles_within_its_plants_mission(plant):
    cell = OWN[plant]
    doc = C.cell_scenario(ARENA, cell, "ideal")
    mission = ARENA.plants[plant].mission
    assert doc["timing"]["stop"] == mission
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "own.toml"
        f.write_text(tomli_w.dumps(doc), encoding="utf-8")
        r = ftcsim.run(str(f), mode="inprocess", parameters={"faults.fault_class": 0.0},
                       record_step=ARENA.trajectory_step)
    df = r.df.reset_index()
    df = df.rename(columns={df.columns[0]: "time"})
    m = measure(df, C.metric_signals(doc, cell), band=ARENA.plants[plant].band, status="ok", error=None, t_end=None,
                fault_class="none", onset=None, manoeuvres=C.manoeuvres(doc), target=C.target(doc), wheels=WHEELS)
    assert m["outcome"] == "flies", (plant, m["outcome"], m["final_attitude_error"])
    settled_at = m["settle_from"] + m["time_to_band"]
    assert settled_at <= (1.0 - TAIL) * mission, (plant, settled_at, mission)
