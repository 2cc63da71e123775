"""Re-design of the papers' LMI gains for the plants of other papers (issue 26 item 2).

Each function calls the paper's own design code (``papers/pNNN_*/design*.py``) with the target
plant's model instead of the paper's, then the paper's own independent verification with the same
model. Nothing here is typed in: the target models come from the papers' parameter sets
(:data:`TARGETS`). ``python -m arena.design --write`` runs every re-design and writes
``arena/gains.py`` (plain Python literals with their provenance), which the arena's parameter sets
(``arena/parameters.py``) and scenarios use; ``tests/arena/test_gains.py`` re-verifies the stored
gains (eigenvalues, H-infinity norms, sampled-loop radii; no solver).

Which design applies where (docs/arena-design.md has the whole matrix):

* 000 Theorem 2 (FASMC K_c, also AISMC's K_c) and 000 Theorem 1 (FAFEO): their LMIs are over the
  T-S model of the 000 (2)-(7) family, which covers 004's flexible craft (other delta, modes) and
  001's rigid craft (delta = 0). For the rigid craft the observer's vibration states are
  unobservable (delta = 0 decouples them): we give them a fictitious, well-damped modal model
  (``RIGID_MODES``: 10 rad/s, damping 0.7, poles inside the disk of (24)), which never touches the
  hub (delta = 0), so that (24) can hold. 004's flexible craft needs a wider disk than
  000's O(-10, 10) for (24): the smallest feasible radius of :data:`FAFEO_DISKS` is used.
* 004 Theorem 2 (sampled-data fuzzy FTC K_rj): over 004's T-S model of (J, delta) on x = [omega,
  q_v]; applies to 000's craft (its delta) and 001's (delta = 0) with 004's scalars, faults and
  rates unchanged.
* 002 Theorem 2 (H-infinity K) and 003 Theorem 1 (TSFDO L1): over the pitch-axis model (J, F);
  applies to the other pitch plant.

001 (ASMFEO + FONTSM), 000's PD and 003's ASMFTC gains come from no LMI: they run with the
published gains (the model parameters J, M, F of the blocks are the target's).
"""
from __future__ import annotations

import argparse
import dataclasses
import datetime
import math
import sys
import time
from pathlib import Path

import numpy as np

RIGID_MODES = {"omega_n": np.full(4, 10.0), "zeta": np.full(4, 0.7)}  # fictitious, decoupled (delta = 0)
FAFEO_DISKS = (10.0, 20.0, 30.0, 50.0)  # radii r of O(-r, r) tried for 000 (24), smallest first
GAINS_FILE = Path(__file__).with_name("gains.py")


def model_000(target: str) -> dict:
    """{J, delta, omega_n, zeta} of a 3-axis target in the form of 000's T-S model."""
    if target == "li2023":
        from papers.p000_li2023.parameters import LI2023 as S
    elif target == "xu2024":
        from papers.p004_xu2024.parameters import XU2024 as S
    elif target == "zhang2019":
        from papers.p001_zhang2019.parameters import ZHANG2019

        return {"J": ZHANG2019["J"], "delta": np.zeros((4, 3)), **RIGID_MODES}
    else:
        raise KeyError(f"unknown 3-axis target {target!r} (li2023, xu2024, zhang2019)")
    return {k: np.asarray(S[k], float) for k in ("J", "delta", "omega_n", "zeta")}


def model_pitch(target: str) -> dict:
    """{J, F, omega, xi} of a pitch-axis target (plant/pitch_axis.py's parameter-set form)."""
    if target == "zhang2014":
        from papers.p002_zhang2014.parameters import ZHANG2014 as S
    elif target == "hang2023":
        from papers.p003_hang2023.parameters import HANG2023 as S
    else:
        raise KeyError(f"unknown pitch-axis target {target!r} (zhang2014, hang2023)")
    return dict(S)


def _provenance(t0: float, **more) -> dict:
    import lmi

    return {"date": datetime.date.today().isoformat(), "wall_s": round(time.perf_counter() - t0, 1),
            "versions": lmi.versions(), **more}


# -- 000 ------------------------------------------------------------------------------------------
def fasmc(target: str) -> dict:
    """000 Theorem 2 (41)-(44) on ``target``'s model, 000 A.2's settings; verified per rule."""
    from papers.p000_li2023 import design_controller as dc

    t0 = time.perf_counter()
    r = dc.design(params=model_000(target))
    v = r["verify"]
    return {"K_c": r["gains"]["K_c"], "gamma_2": r["performance"]["gamma_2"],
            "settings": r["settings"], "verify": {"all_hold": v["all_hold"], "max_abscissa": v["max_abscissa"],
                                                  "max_disk_excess": v["max_disk_excess"], "max_hinf": v["max_hinf"]},
            "provenance": _provenance(t0, solver=r["solver"], status=r["status"], source="000 Theorem 2, (41)-(44)")}


def fafeo(target: str) -> dict:
    """000 Theorem 1 (23)-(24) on ``target``'s model with 000 (68)'s F2, G2, theta; the smallest
    disk radius of :data:`FAFEO_DISKS` for which the design exists and verifies."""
    import lmi
    from papers.p000_li2023 import design_observer as do

    t0 = time.perf_counter()
    tried = []
    for radius in FAFEO_DISKS:
        try:
            r = do.design(phi=-radius, eps=radius, params=model_000(target))
        except lmi.LMIError as e:
            tried.append({"disk": [-radius, radius], "result": str(e).split(";")[0][:200]})
            continue
        v = r["verify"]
        return {"K": r["gains"]["K"], "F1": r["gains"]["F1"], "G1": r["gains"]["G1"],
                "gamma_1": r["performance"]["gamma_1"], "disk": [-radius, radius], "disks_refused": tried,
                "verify": {"all_hold": v["all_hold"], "max_abscissa": v["max_abscissa"],
                           "max_disk_excess": v["max_disk_excess"], "max_hinf": v["max_hinf"]},
                "provenance": _provenance(t0, solver=r["solver"], status=r["status"],
                                          source="000 Theorem 1, (23)-(24)")}
    raise lmi.LMIInfeasible(f"000 Theorem 1 on {target}: no disk of {FAFEO_DISKS} works: {tried}")


# -- 004 ------------------------------------------------------------------------------------------
def sftc_setup(target: str):
    """004's nonhomogeneous Theorem-2 set-up (its scalars, faults, rates) over ``target``'s T-S model."""
    from papers.p004_xu2024 import design as d4
    from papers.p004_xu2024.parameters import OPERATING_POINTS
    from plant.ts_attitude import local_model

    m = model_000(target)
    A, B = local_model(m["J"], m["delta"], OPERATING_POINTS)
    return dataclasses.replace(d4.case_setup("nonhomogeneous"), A=A, B=B, label=f"nonhomogeneous on {target}")


def sftc(target: str) -> dict:
    """004 Theorem 2 (45)-(50), nonhomogeneous case, on ``target``'s T-S model; verified by the
    local and sampled-loop checks of 004's design module."""
    from papers.p004_xu2024 import design as d4

    t0 = time.perf_counter()
    s = sftc_setup(target)
    K, sol, timing = d4.solve(s)
    v = d4.verify(K, s)
    return {"K": K, "c2": float(sol["c2"]), "lmi_checks_passed": all(c.passed for c in sol.checks),
            "verify": {"all_hold": v["all_hold"], "max_local_abscissa": float(np.max(v["local_abscissa"])),
                       "max_sampled_radius": float(np.max(v["sampled_radius_max"]))},
            "provenance": _provenance(t0, solver=sol.solver, status=sol.status, timing=timing,
                                      source="004 Theorem 2, (45)-(50), nonhomogeneous case")}


# -- 002, 003 --------------------------------------------------------------------------------------
def hinf(target: str, omega_hats=(1.0, 0.5, 0.2)) -> dict:
    """002 Theorem 2 (22) on ``target``'s pitch model for each omega_hat (002's gamma, Z, R, x0,
    j = 0.75, kappa searched as 002's design does); verified by 002's checks with that model."""
    import lmi
    from lmi.search import grid_then_golden
    from papers.p002_zhang2014 import design as d2

    params = model_pitch(target)
    t0 = time.perf_counter()
    cases = []
    for w in omega_hats:
        def value(k, w=w):
            try:
                return d2._solve_case(w, k, d2.DEFAULT_J, d2.ZHANG2014_X0, 1e-6, ("CLARABEL",), params=params)[2]
            except lmi.LMIError:
                return math.inf

        best, J_best, _ = grid_then_golden(value, d2.DEFAULT_KAPPAS, iterations=8)
        if not math.isfinite(J_best):
            raise lmi.LMIInfeasible(f"002 (22) on {target}, omega_hat = {w:g}: infeasible for every kappa")
        sol, K, J_star = d2._solve_case(w, best, d2.DEFAULT_J, d2.ZHANG2014_X0, 1e-6, ("CLARABEL", "SCS"),
                                        params=params)
        v = d2.verify(K, J_star, w, d2.DEFAULT_J, params=params)
        cases.append({"omega_hat": w, "K": np.asarray(K).reshape(-1), "J_star": J_star, "kappa": float(best),
                      "verify": {"all_hold": v["all_hold"], "failed": v["failed"], "worst": v["worst"]}})
    return {"cases": cases, "j": d2.DEFAULT_J,
            "provenance": _provenance(t0, source="002 Theorem 2, (22)-(23)")}


def tsfdo(target: str) -> dict:
    """003 Theorem 1 (3.4) on ``target``'s pitch model (003's exosystem W_j, V_j), max decay."""
    from papers.p003_hang2023 import design as d3

    t0 = time.perf_counter()
    r = d3.design(params=model_pitch(target))
    v = r["verify"]
    return {"L1": r["gains"]["L1"], "alpha": r["performance"]["alpha"], "beta": r["performance"]["beta"],
            "verify": {"all_hold": v["all_hold"], "abscissa": v["abscissa"], "blend_abscissa": v["blend_abscissa"]},
            "provenance": _provenance(t0, solver=r["solver"], status=r["status"], source="003 Theorem 1, (3.4)")}


# -- all re-designs -------------------------------------------------------------------------------
REDESIGNS = {
    "fasmc@xu2024": (fasmc, "xu2024"),
    "fasmc@zhang2019": (fasmc, "zhang2019"),
    "fafeo@xu2024": (fafeo, "xu2024"),
    "fafeo@zhang2019": (fafeo, "zhang2019"),
    "hinf@hang2023": (hinf, "hang2023"),
    "tsfdo@zhang2014": (tsfdo, "zhang2014"),
    "sftc@li2023": (sftc, "li2023"),
    "sftc@zhang2019": (sftc, "zhang2019"),
}


def _literal(x):
    """Python literal text of nested dicts / lists / arrays / floats (repr of floats is exact)."""
    if isinstance(x, dict):
        return "{" + ", ".join(f"{k!r}: {_literal(v)}" for k, v in x.items()) + "}"
    if isinstance(x, (list, tuple, np.ndarray)):
        return "[" + ", ".join(_literal(v) for v in np.asarray(x, dtype=object).tolist()) + "]" \
            if isinstance(x, np.ndarray) else "[" + ", ".join(_literal(v) for v in x) + "]"
    if isinstance(x, (bool, np.bool_)):
        return repr(bool(x))
    if isinstance(x, (int, float, np.floating, np.integer)):
        return repr(float(x)) if isinstance(x, (float, np.floating)) else repr(int(x))
    if x is None or isinstance(x, str):
        return repr(x)
    raise TypeError(f"cannot write {type(x).__name__} as a literal")


def write_gains(results: dict, path=GAINS_FILE) -> None:
    """Write ``arena/gains.py``: ``REDESIGNED = {name: result}`` as literals, atomically; entries
    already in the file and not re-designed now are kept."""
    old = {}
    if Path(path).exists():
        ns: dict = {}
        exec(compile(Path(path).read_text(encoding="utf-8"), str(path), "exec"), ns)  # our own generated file
        old = ns.get("REDESIGNED", {})
    merged = {**old, **results}
    lines = ['"""Gains re-designed for the plants of other papers (generated by ``python -m arena.design --write``;',
             "do not edit). Each entry: the gains, the design's figure of merit, the independent verification",
             "summary and the provenance (solver, versions, date). arena/design.py says which LMIs and models.",
             '"""', "# ruff: noqa: E501", "REDESIGNED = {"]
    for name in sorted(merged):
        lines.append(f"    {name!r}: {_literal(merged[name])},")
    lines.append("}")
    tmp = Path(str(path) + ".tmp")
    tmp.write_text("\n".join(lines) + "\n", encoding="utf-8")
    tmp.replace(path)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m arena.design", description=__doc__.splitlines()[0])
    ap.add_argument("names", nargs="*", help=f"re-designs to run (default all: {', '.join(REDESIGNS)})")
    ap.add_argument("--write", action="store_true", help="write arena/gains.py")
    args = ap.parse_args(argv)
    unknown = [n for n in args.names if n not in REDESIGNS]
    if unknown:
        print(f"unknown re-design(s) {unknown}; known: {', '.join(REDESIGNS)}", file=sys.stderr)
        return 2
    results, failed = {}, []
    for name in args.names or list(REDESIGNS):
        fn, target = REDESIGNS[name]
        try:
            r = fn(target)
        except Exception as e:  # a design that fails is a result: reported, nothing written for it
            failed.append(name)
            print(f"{name}: FAILED {type(e).__name__}: {str(e)[:300]}", flush=True)
            continue
        results[name] = r
        print(f"{name}: verified={r.get('verify', {}).get('all_hold', [c['verify']['all_hold'] for c in r.get('cases', [])])} "
              f"({r['provenance']['wall_s']} s)", flush=True)
        if args.write:
            write_gains({name: r})
    return 1 if failed else 0


if __name__ == "__main__":
    raise SystemExit(main())
