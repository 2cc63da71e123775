"""003's failure-factor ordering (Figs. 9-10) with a thinner boundary layer, gamma3 = 0.01 in (3.21)
(printed: 1; the delivered-torque reading ships 0.1): six 60 s runs at 0.5 ms in process (minutes),
stored in ``gamma3_study.json`` with this command, read by the report:

    python -m papers.p003_hang2023.gamma3_study --out papers/p003_hang2023/gamma3_study.json

For both observer inputs (the command u as printed, the delivered torque rho u) and the factors 0.4,
0.8, 1.0: max |theta| and max |theta'| over the last 10 s (the steady-state accuracy 003's text speaks
of), peak |theta| over [20, 25] s and |theta(20 s)|.
"""
from __future__ import annotations

import sys
from datetime import date
from pathlib import Path

import numpy as np

from papers import stored_study

STUDY = Path(__file__).with_name("gamma3_study.json")
COMMAND = "python -m papers.p003_hang2023.gamma3_study --out papers/p003_hang2023/gamma3_study.json"
GAMMA3 = 0.01
READINGS = {"command": "hang2023_asmftc_f{}", "delivered": "hang2023_asmftc_delivered_f{}"}
FACTORS = {0.4: "04", 0.8: "08", 1.0: "10"}


def measures(time, theta, theta_dot, onset=20.0) -> dict:
    t, th, w = np.asarray(time), np.asarray(theta), np.asarray(theta_dot)
    last = t >= t[-1] - 10.0 - 1e-9
    tr = (t >= onset - 1e-9) & (t <= onset + 5.0 + 1e-9)
    return {"theta_max_last_10s": float(np.abs(th[last]).max()), "theta_dot_max_last_10s": float(np.abs(w[last]).max()),
            "theta_peak_20_25s": float(np.abs(th[tr]).max()), "theta_20s": float(abs(np.interp(onset, t, th)))}


def study(gamma3: float = GAMMA3) -> dict:
    from orchestrator import api

    scen = Path(__file__).with_name("scenarios")
    out = {}
    for reading, pattern in READINGS.items():
        for f, tag in FACTORS.items():
            name = pattern.format(tag)
            r = api.run(scen / f"{name}.toml", mode="inprocess", parameters={"ctrl.gamma3": gamma3}).raw
            if not r.complete:
                raise RuntimeError(f"{name} with gamma3 = {gamma3:g} stopped: {r.error}")
            out.setdefault(reading, {})[f"{f:g}"] = {"scenario": name, **measures(r.time, r.column("plant.theta"),
                                                                                    r.column("plant.theta_dot"))}
    return {"source": "003 (3.21) with gamma3 = 0.01; papers/p003_hang2023/gamma3_study.py", "date": date.today().isoformat(),
            "command": COMMAND, "gamma3": gamma3, "runs": out}


def load() -> dict | None:
    """The stored study (None if the file is missing)."""
    return stored_study.load(STUDY)


def main(argv=None) -> int:
    return stored_study.main("python -m papers.p003_hang2023.gamma3_study", __doc__, study, STUDY, argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
