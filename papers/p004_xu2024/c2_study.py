"""004's c2 under the readings side by side: Theorem 2 (45)-(50) minimised for one mode (Case I,
Pi_1) and three modes (Pi_1), with the rigorous averaging of (45) (the four Omega terms / 4, ours)
and the printed "/2", at alpha = 0.1 (ours) and 0.02.

    python -m papers.p004_xu2024.c2_study --out papers/p004_xu2024/c2_study.json [--quick]

The printed numbers are c2 = 6.0114 (one mode, "Case I") and 5.7741 (three modes). Every design goes
through ``design.design_case`` (every LMI checked by its eigenvalues, the gains by ``design.verify``);
the result is written atomically with the settings, timings and versions. ``--quick`` runs the one-mode
designs only. The nonhomogeneous three-mode case (216 LMIs of 45 x 45, ~5 min per design) is not
part of the study: ``benchmarks/bench_xu2024.py`` runs it for our reading (c2 = 17.4836).

The report (``report.py``) reads the stored file and computes the verdicts of the c2 items from it;
``tests/papers/p004_xu2024/test_xu2024_c2.py`` recomputes the printed-order one-mode entry.
"""
from __future__ import annotations

import argparse
import datetime
import json
import sys
import time
from pathlib import Path

from orchestrator.results.files import write_json

STORED = Path(__file__).with_name("c2_study.json")

# label -> Theorem 2 overrides; "literal" marks the printed averaging factor
READINGS = {
    "rigorous /4, alpha = 0.1": {"average": 0.25, "alpha": 0.1},
    "rigorous /4, alpha = 0.02": {"average": 0.25, "alpha": 0.02},
    "printed /2, alpha = 0.1": {"average": 0.5, "alpha": 0.1},
    "printed /2, alpha = 0.02": {"average": 0.5, "alpha": 0.02},
}
CASES = {"one_mode": "one mode (Case I, Pi_1)", "three_homogeneous": "three modes (Pi_1)"}


def run_one(case: str, overrides: dict) -> dict:
    from .design import design_case

    t0 = time.perf_counter()
    r = design_case(case, **overrides)
    return {"case": case, "overrides": overrides, "c2": r["c2"], "c2_optimum": r["c2_optimum"],
            "c2_lower_bound": r["c2_lower_bound"], "mu": r["mu"], "lmi_checks_passed": r["lmi_checks_passed"],
            "n_lmi": r["n_lmi"], "worst_lmi_margin": r["worst_lmi_margin"], "verify_all_hold": r["checks_passed"],
            "solver": r["solver"], "status": r["status"], "wall_s": time.perf_counter() - t0,
            "versions": r["versions"]}


def study(cases=tuple(CASES), readings=tuple(READINGS), log=print) -> dict:
    out = {"source": "004 Theorem 2, (45)-(50), papers/p004_xu2024/design.py", "date": datetime.date.today().isoformat(),
           "command": "python -m papers.p004_xu2024.c2_study --out papers/p004_xu2024/c2_study.json",
           "printed": {"one_mode": 6.0114, "three_modes": 5.7741}, "designs": {}}
    for label in readings:
        for case in cases:
            r = run_one(case, READINGS[label])
            out["designs"][f"{label} | {case}"] = {"reading": label, **r}
            log(f"{label:28s} {case:18s} c2 = {r['c2']:.6g}  ({r['wall_s']:.0f} s)")
    return out


def load(path=STORED) -> dict | None:
    """The stored study, or None if there is none."""
    p = Path(path)
    return json.loads(p.read_text(encoding="utf-8")) if p.is_file() else None


def c2(data: dict, reading: str, case: str):
    d = (data or {}).get("designs", {}).get(f"{reading} | {case}")
    return None if d is None else d["c2"]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m papers.p004_xu2024.c2_study", description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="JSON file to write (atomically)")
    ap.add_argument("--quick", action="store_true", help="the one-mode designs only")
    args = ap.parse_args(argv)
    data = study(cases=("one_mode",) if args.quick else tuple(CASES))
    write_json(args.out, data)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
