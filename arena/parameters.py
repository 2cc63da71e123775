"""The arena's parameter sets (``parameter_set = NAME`` on a scenario instance; numpy only).

A set maps parameter base names to values; an instance takes the entries its FMU declares and
ignores the others (``orchestrator/scenario/toml.py``), so one set serves a method's observer and
controller together.

Cross-application sets, ``arena_<method's paper>_on_<plant's paper>``: the method's model of the
target plant and the gains re-designed for it (``arena/gains.py``, from ``arena/design.py``):

* ``arena_li2023_on_xu2024``: 004's craft (J, delta, modes) with the FASMC K_c of 000 Theorem 2
  and the FAFEO K, F1, G1 of 000 Theorem 1 (disk O(-20, 20)) re-designed on it (FASMC, AISMC, PD's
  model, FAFEO);
* ``arena_li2023_on_zhang2019``: 001's rigid craft (its J, delta = 0, fictitious decoupled modes,
  arena/design.py) with K_c and K, F1, G1 re-designed on it;
* ``arena_xu2024_on_li2023``, ``arena_xu2024_on_zhang2019``: 004's K_rj of Theorem 2 re-designed on
  000's and 001's T-S models;
* ``arena_zhang2014_on_hang2023``: 002's K (all three omega_hat cases) re-designed on 003's pitch
  axis, with its case bank;
* ``arena_hang2023_on_zhang2014``: 003's L1 re-designed on 002's pitch axis, with 002's J, F (the
  model of TSFDO and ASMFTC).

Methods without an LMI (001's ASMFEO + FONTSM, 000's PD, 003's ASMFTC gains) take the target's
model from the papers' own sets (``parameter_set = "li2023"``, ``"zhang2014"``, ...) and keep
their published gains. Hardware sets: ``plant/hardware/datasheets.py`` (``wheels_hr12_12``,
``gyro_stim300``, ``st_small``, ...).
"""
from __future__ import annotations

import numpy as np

from papers.p001_zhang2019.parameters import ZHANG2019
from papers.p002_zhang2014.parameters import PARAMETER_SET as ZHANG2014_SET
from papers.p004_xu2024.parameters import XU2024
from plant.hardware.datasheets import ALL as HARDWARE

from .gains import REDESIGNED

RIGID_MODES = {"omega_n": np.full(4, 10.0), "zeta": np.full(4, 0.7)}  # as arena/design.py: RIGID_MODES


def _a(x) -> np.ndarray:
    return np.asarray(x, dtype=float)


def _observer(name: str) -> dict:
    g = REDESIGNED[name]
    return {"K": _a(g["K"]), "F1": _a(g["F1"]), "G1": _a(g["G1"])}


def _hinf_bank(name: str) -> dict:
    cases = REDESIGNED[name]["cases"]
    return {"K": _a([c["K"] for c in cases]), "case_omega_hat": _a([c["omega_hat"] for c in cases])}


SETS = {
    "arena_li2023_on_xu2024": {**{k: _a(XU2024[k]) for k in ("J", "delta", "omega_n", "zeta")},
                               "K_c": _a(REDESIGNED["fasmc@xu2024"]["K_c"]), **_observer("fafeo@xu2024")},
    "arena_li2023_on_zhang2019": {"J": _a(ZHANG2019["J"]), "delta": np.zeros((4, 3)), **RIGID_MODES,
                                  "K_c": _a(REDESIGNED["fasmc@zhang2019"]["K_c"]), **_observer("fafeo@zhang2019")},
    "arena_zhang2014_on_hang2023": _hinf_bank("hinf@hang2023"),
    "arena_hang2023_on_zhang2014": {"J": ZHANG2014_SET["J"], "F": _a(ZHANG2014_SET["F"]),
                                    "L1": _a(REDESIGNED["tsfdo@zhang2014"]["L1"])},
    **{f"arena_xu2024_on_{target}": {"K": _a(REDESIGNED[f"sftc@{target}"]["K"])}
       for target in ("li2023", "zhang2019") if f"sftc@{target}" in REDESIGNED},
    **HARDWARE,
}


def structured(name: str) -> dict:
    """A set as structured scalar names (``K_c[1,1,1]``: ...), for tests and tools."""
    from plant.block import structured_values

    out = {}
    for base, value in SETS[name].items():
        out.update(structured_values(base, value))
    return out


# the registry resolves "module:ATTRIBUTE": one attribute per set
for _name, _values in SETS.items():
    globals()[_name.upper()] = _values
del _name, _values
