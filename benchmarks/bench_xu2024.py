"""Paper 004 benchmark: Theorem-2 design times per case, microseconds per macro step of the 004
loop, Monte Carlo runs per second (in-process; optionally on 2 worker processes), and the full
finite-time-bound check (N runs over [0, T = 10 s]).

    .venv/bin/python benchmarks/bench_xu2024.py [--write-gains] [--alpha-scan] [--fmu] [--workers 2]
                                                [--mc-runs 1000] [--skip-designs] [--out FILE]

``--write-gains`` stores the designed gains in papers/p004_xu2024/designed_gains.py (what the FMUs
and scenarios use). Run it on a quiet machine: the full nonhomogeneous design solves 216 LMIs of
45 x 45 (minutes).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

SCEN = ROOT / "papers" / "p004_xu2024" / "scenarios"


def bench_designs(write: bool) -> dict:
    import lmi
    from papers.p004_xu2024 import design as D

    out, results = {}, {}
    for case in D.CASES:
        t0 = time.perf_counter()
        try:
            r = D.design_case(case)
        except (lmi.LMIError, ValueError) as e:
            out[case] = {"error": f"{type(e).__name__}: {e}", "total_s": time.perf_counter() - t0}
            print(f"design {case}: FAILED {e}", flush=True)
            continue
        results[case] = r
        out[case] = {"c2": r["c2"], "c2_optimum": r["c2_optimum"], "mu": r["mu"], "n_lmi": r["n_lmi"],
                     "n_lmi_45": r["timing"]["n_lmi_45"], "build_s": r["timing"]["build_s"],
                     "solve_s": r["timing"]["solve_s"], "total_s": time.perf_counter() - t0, "status": r["status"],
                     "worst_lmi_lambda_max": r["worst_lmi_margin"], "independent_checks": r["checks_passed"],
                     "c2_lower_bound": r["c2_lower_bound"]}
        print(f"design {case}: c2 = {r['c2']:.6g} (optimum {r['c2_optimum']:.6g}), {r['n_lmi']} LMIs, "
              f"build {r['timing']['build_s']:.1f} s + solve {r['timing']['solve_s']:.1f} s, {r['status']}", flush=True)
    if write and len(results) == len(D.CASES):
        D.write_designed_gains(results, ROOT / "papers" / "p004_xu2024" / "designed_gains.py")
        print("wrote papers/p004_xu2024/designed_gains.py")
    return out


def bench_alpha_scan() -> dict:
    """c2*(alpha) for Case I (one mode), and the paper's mismatch bound rho_mm = 1."""
    import lmi
    from papers.p004_xu2024 import design as D

    rows = []
    for kw in [dict(alpha=a) for a in (0.02, 0.05, 0.1, 0.2, 0.4)] + [dict(rho_mm=1.0), dict(rho_mm=0.3),
                                                                       dict(v4_alpha_terms=False),
                                                                       dict(tau_vertex="affine"), dict(average=0.5)]:
        t0 = time.perf_counter()
        try:
            r = D.design_case("one_mode", **kw)
            row = {**kw, "c2": r["c2"], "mu": r["mu"], "status": r["status"], "K11_norm": float(np.linalg.norm(r["gains"]["K"][0, 0])),
                   "lower_bound": r["c2_lower_bound"]}
        except (lmi.LMIError, ValueError) as e:
            row = {**kw, "c2": None, "outcome": f"{type(e).__name__}: {str(e)[:160]}"}
        row["s"] = time.perf_counter() - t0
        rows.append(row)
        print("one_mode", row, flush=True)
    return {"one_mode": rows}


def bench_loop(fmu: bool, stop: float = 10.0) -> dict:
    from orchestrator.cosim.runner import run_scenario
    from orchestrator.scenario.overrides import with_overrides
    from orchestrator.scenario.toml import load

    out = {}
    modes = ["inprocess"] + (["fmu"] if fmu else [])
    if fmu:
        from fmus.build import build_fmu
        from papers.registry import fmu_specs

        fdir = ROOT / "build" / "fmus"
        for name in ("Xu2024TSPlant", "Xu2024FlexiblePlant", "Xu2024MarkovFaults", "Xu2024SampledFTC",
                     "Xu2024FaultActuator", "Xu2024Disturbance"):
            build_fmu(fmu_specs()[name], fdir)
    for scen in ("xu2024_ts", "xu2024_flexible"):
        for mode in modes:
            sc = with_overrides(load(SCEN / f"{scen}.toml", in_process=(mode == "inprocess")), stop=stop)
            r = run_scenario(sc)
            us = 1e6 * r.wall_time / r.steps
            out[f"{scen}/{mode}"] = {"steps": r.steps, "wall_s": r.wall_time, "us_per_macro_step": us,
                                     "real_time_factor": r.steps * sc.step / r.wall_time, "complete": r.complete}
            print(f"loop {scen} {mode}: {us:.0f} us per 1 ms macro step (5 components), RTF {r.steps * sc.step / r.wall_time:.2f}",
                  flush=True)
    return out


def _mc_part(args):
    from papers.p004_xu2024 import montecarlo as M
    from papers.p004_xu2024.gains import DESIGNED

    lo, hi, T = args
    return M.run_batch(DESIGNED["K"], range(lo, hi), T, seed=0, record_every=10)["xHx"]


def bench_mc(n_runs: int, T: float, workers: int) -> dict:
    from papers.p004_xu2024 import montecarlo as M
    from papers.p004_xu2024.gains import DESIGNED

    c2 = DESIGNED["c2"]
    mc = M.monte_carlo(DESIGNED["K"], n_runs, T, seed=0, c2=c2, record_every=10)
    out = {"vectorised": {"n_runs": n_runs, "T": T, "wall_s": mc["wall_s"], "runs_per_s": mc["runs_per_s"],
                          "max_mean_xHx": mc["max_mean"], "max_upper_4sigma": mc["max_upper"], "c2": c2,
                          "bound_holds": mc["bound_holds"], "ratio_to_c2": mc["max_upper"] / c2,
                          "mean_jumps_per_run": mc["mean_jumps"], "tau_range": mc["tau_range"],
                          "max_premise_mismatch": mc["max_premise_mismatch"],
                          "mean_xHx_at_T": float(mc["mean"][-1])}}
    print(f"MC vectorised: {n_runs} runs x {T:g} s in {mc['wall_s']:.1f} s = {mc['runs_per_s']:.1f} runs/s; "
          f"max E[x^T x] = {mc['max_mean']:.4g}, upper 4-sigma {mc['max_upper']:.4g} < c2 = {c2:.4g}: {mc['bound_holds']}",
          flush=True)
    nb = 4
    mb = M.monte_carlo(DESIGNED["K"], nb, T, seed=0, engine="blocks")
    out["blocks"] = {"n_runs": nb, "T": T, "wall_s": mb["wall_s"], "runs_per_s": mb["runs_per_s"]}
    print(f"MC blocks (in-process master): {nb} runs x {T:g} s: {mb['runs_per_s']:.3f} runs/s", flush=True)
    if workers > 1:
        chunks = np.linspace(0, n_runs, workers + 1).astype(int)
        t0 = time.perf_counter()
        with ProcessPoolExecutor(workers) as ex:
            parts = list(ex.map(_mc_part, [(int(a), int(b), T) for a, b in zip(chunks, chunks[1:])]))
        wall = time.perf_counter() - t0
        xhx = np.vstack(parts)
        same = bool(np.array_equal(xhx, mc["xHx"]))
        out[f"vectorised_{workers}_workers"] = {"n_runs": n_runs, "wall_s": wall, "runs_per_s": n_runs / wall,
                                                "identical_to_one_process": same}
        print(f"MC vectorised on {workers} workers: {n_runs / wall:.1f} runs/s (identical to 1 process: {same})", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write-gains", action="store_true")
    ap.add_argument("--alpha-scan", action="store_true")
    ap.add_argument("--skip-designs", action="store_true")
    ap.add_argument("--fmu", action="store_true", help="also time the FMU loop (builds 004's FMUs into build/fmus)")
    ap.add_argument("--workers", type=int, default=1)
    ap.add_argument("--loop-stop", type=float, default=10.0, help="simulated seconds per loop timing run")
    ap.add_argument("--mc-runs", type=int, default=1000)
    ap.add_argument("--mc-T", type=float, default=10.0)
    ap.add_argument("--out", default=str(ROOT / "results" / "bench_xu2024.json"))
    a = ap.parse_args(argv)
    res = {"machine": {"cpus": os.cpu_count(), "load_avg": os.getloadavg()}, "started": time.strftime("%Y-%m-%d %H:%M:%S")}
    if not a.skip_designs:
        res["designs"] = bench_designs(a.write_gains)
    if a.alpha_scan:
        res["alpha_scan"] = bench_alpha_scan()
    res["loop"] = bench_loop(a.fmu, a.loop_stop)
    res["monte_carlo"] = bench_mc(a.mc_runs, a.mc_T, a.workers)
    res["load_avg_end"] = os.getloadavg()
    from orchestrator.common.jsonio import write_json_atomic

    write_json_atomic(a.out, res)
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
