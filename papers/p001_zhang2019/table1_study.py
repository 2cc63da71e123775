"""Measurements behind the differences between our runs and 001's Table 1 (in-process, short runs).

    python -m papers.p001_zhang2019.table1_study --out results/table1_study.json

1. Switching and step size: sign(s) at h = 1, 0.5, 0.25 ms and sat(s/0.01) at 1 ms (2 s memory,
   no faults): max |omega_i| and max |sigma_i| over [4, 5] s. At a fixed step a discontinuous
   eps_1 sign(s) makes omega chatter by about eps_1 h / 2 (0.043 deg/s at 1 ms).
2. Fractional memory: sat(s/0.01) at 1 ms, no faults, memory 0.5 s, 2 s and full: max |sigma_i| at
   [9, 10] s. The GL tails of D^0.01 and I^0.01 decay slowly with the full memory.
3. The reading of sigma(0), omega(0) in degrees (001 prints no unit): stabilisation time.
"""
from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

from orchestrator import api

SCEN = Path(__file__).resolve().parent / "scenarios"
NO_FAULT = {f"{k}_onset[{j}]": 1e3 for k in ("effectiveness", "bias") for j in range(1, 5)}


def _run(stop, step, ctrl, plant=None, name="zhang2019_fontsm"):
    values = {"plant": NO_FAULT | {"h_max": step} | (plant or {}), "est": {"h_max": step}, "ctrl": {"fo_step": step} | ctrl}
    r = api.run(SCEN / f"{name}.toml", mode="inprocess", step=step, stop=stop,
                parameters={f"{inst}.{k}": v for inst, p in values.items() for k, v in p.items()}).raw
    assert r.complete, r.error
    return r


def _max_deg(r, sig, t0, t1):
    m = (r.time >= t0 - 1e-9) & (r.time <= t1 + 1e-9)
    return np.degrees(np.abs(r.vector(sig)[m])).max(axis=0).tolist()


def switching_and_step():
    rows = []
    for label, step, phi in (("sign, h = 1 ms", 1e-3, 0.0), ("sign, h = 0.5 ms", 5e-4, 0.0),
                             ("sign, h = 0.25 ms", 2.5e-4, 0.0), ("sat(s/0.01), h = 1 ms", 1e-3, 0.01)):
        r = _run(5.0, step, {"boundary_layer": phi, "fo_memory": 2.0})
        rows.append({"case": label, "h": step, "max_omega_deg_s_4_5s": _max_deg(r, "plant.omega", 4, 5),
                     "max_sigma_deg_4_5s": _max_deg(r, "plant.sigma", 4, 5),
                     "eps1_h_over_2_deg_s": float(np.degrees(1.5 * step / 2)) if phi == 0 else None})
    return rows


def memory():
    rows = []
    for label, mem in (("0.5 s", 0.5), ("2 s", 2.0), ("full", 1000.0)):
        r = _run(10.0, 1e-3, {"boundary_layer": 0.01, "fo_memory": mem})
        rows.append({"memory": label, "max_sigma_deg_9_10s": _max_deg(r, "plant.sigma", 9, 10),
                     "max_omega_deg_s_9_10s": _max_deg(r, "plant.omega", 9, 10),
                     "max_sigma_deg_at_3s": _max_deg(r, "plant.sigma", 3, 3), "max_sigma_deg_at_10s": _max_deg(r, "plant.sigma", 10, 10)})
    return rows


def degree_reading():
    deg = {f"sigma_init[{i + 1}]": float(np.radians(x)) for i, x in enumerate((-0.6, 0.5, 0.5))}
    deg |= {f"omega_init[{i + 1}]": float(np.radians(x)) for i, x in enumerate((0.9, 0.6, -0.4))}
    out = {}
    for label, plant in (("rad, rad/s (our reading)", {}), ("deg, deg/s", deg)):
        r = _run(5.0, 1e-3, {"boundary_layer": 0.01, "fo_memory": 2.0},
                 plant, name="zhang2019_fontsm")
        err = np.degrees(np.abs(r.vector("plant.sigma"))).max(axis=1)
        from .metrics import stabilization_time

        out[label] = {b: stabilization_time(r.time, err, b) for b in (1e-2, 1e-4)}
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results/table1_study.json")
    args = ap.parse_args(argv)
    rep = {"switching_and_step": switching_and_step(), "memory": memory(), "initial_state_units": degree_reading()}
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps(rep, indent=2) + "\n")
    print(json.dumps(rep, indent=2))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
