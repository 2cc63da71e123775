"""Benchmark of the arena (``make bench``): runs/s of ``ftcsim arena`` on 1 and 2 Dask workers, and
the full shipped arena's wall time extrapolated here and on a 64-core cluster.

The slice: the shipped arena (arena/ftc_arena.toml) with every cell and both hardware sets, one fault
class (``--fault``, default bias), ``--draws`` draws and every mission cut to ``--stop`` s; run with
``--workers`` 1 and 2 (LocalCluster, one thread each; cluster start-up excluded) in FMU mode (the
shipped arena's mode). Reported: runs/s for each, the speed-up rate(2) / rate(1).

Extrapolation to the full arena (stated, not assumed): each run of the slice reports its set-up time
(task wall time minus the master's stepping time) and its stepping time over ``--stop`` s; a full
run of that cell takes set-up + stepping x (mission stop / ``--stop``) (stepping is linear in the
simulated time at a fixed step). T_full, the full arena's task time, is the sum over its cells,
hardware, fault classes and draws. The arena's own serial time O (checks, one campaign after
another, measuring, the page) is the 1-worker wall time minus the sum of its task times; the
measured efficiency of the tasks on 2 workers is e2 = (T_1 / 2) / (W_2 - O). With N workers:
O + T_full / (N e2) (e2 measured at 2 workers, taken for N: stated), and no less than the arena's
campaigns allow: they run one after another (one per cell and hardware), each in ceil(runs / N)
waves of its cell's run time.

The machine is shared: the load average is printed; numbers taken under load are upper bounds for
times and lower bounds for the speed-up.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))


def slice_file(folder: Path, draws: int, fault: str, stop: float, mode: str) -> Path:
    """The shipped arena cut to the slice, written next to copies of its scenarios."""
    import shutil

    src = ROOT / "arena" / "ftc_arena.toml"
    text = src.read_text(encoding="utf-8")
    text = text.replace("draws = 20", f"draws = {draws}").replace('faults = ["none", "loe_step", "bias", "lost"]',
                                                                  f'faults = ["{fault}"]')
    text = text.replace('mode = "fmu"', f'mode = "{mode}"\nstop = {stop}')
    shutil.copytree(ROOT / "arena" / "scenarios", folder / "arena" / "scenarios")
    path = folder / "arena" / "slice.toml"
    path.write_text(text, encoding="utf-8")
    return path


def run(path: Path, out: Path, workers: int) -> tuple:
    """(wall s of the arena, runs table) with ``workers`` (cluster start-up excluded)."""
    import pandas as pd
    from distributed import LocalCluster

    from arena.app import run_arena

    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None)
    try:
        t0 = time.perf_counter()
        o = run_arena(path, out, scheduler=cluster.scheduler_address)
        wall = time.perf_counter() - t0
    finally:
        cluster.close()
    runs = pd.read_parquet(out / "tables" / "runs.parquet")
    sims = []
    for d in sorted((out / "cells").iterdir()):
        s = pd.read_parquet(d / "run" / "summary.parquet", columns=["wall_time_s", "sim_time_s"])
        s["cell"] = d.name
        sims.append(s)
    return wall, o.stored, runs, pd.concat(sims, ignore_index=True)


def extrapolate(arena_doc: dict, per_cell, stop: float, overhead: float, e2: float, workers: int) -> dict:
    """Full-arena wall time (s) on ``workers`` (module docstring)."""
    runs_per_campaign = len(arena_doc["arena"]["faults"]) * arena_doc["arena"]["draws"]
    tasks, waves = 0.0, 0.0
    for setup, step_s, mission in per_cell.values():
        t_run = setup + step_s * mission / stop
        tasks += runs_per_campaign * t_run
        waves += math.ceil(runs_per_campaign / workers) * t_run
    spread = overhead + tasks / (workers * e2)
    return {"tasks_s": tasks, "spread_s": spread, "waves_s": waves, "estimate_s": max(spread, waves + overhead)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--stop", type=float, default=2.0, help="simulated seconds per run of the slice (default 2)")
    ap.add_argument("--draws", type=int, default=1)
    ap.add_argument("--fault", default="bias")
    ap.add_argument("--mode", default="fmu", choices=("fmu", "inprocess"))
    ap.add_argument("--cores", type=int, default=64, help="cluster size of the extrapolation (default 64)")
    ap.add_argument("--out", help="write the numbers as JSON here")
    args = ap.parse_args(argv)
    from arena.app import plan
    from arena.arenafile import load

    print(f"load average before: {os.getloadavg()}", flush=True)
    shipped = tomllib.loads((ROOT / "arena" / "ftc_arena.toml").read_text(encoding="utf-8"))
    full = load(ROOT / "arena" / "ftc_arena.toml")
    mission = {}
    for cell, hw, doc, _ in plan(full):
        mission[f"{cell.method}_on_{cell.plant}.{hw}"] = float(doc["timing"]["stop"])
    result = {"stop": args.stop, "draws": args.draws, "fault": args.fault, "mode": args.mode}
    with tempfile.TemporaryDirectory(prefix="bench-arena-") as tmp:
        path = slice_file(Path(tmp), args.draws, args.fault, args.stop, args.mode)
        rates, walls, task = {}, {}, {}
        for w in (1, 2):
            wall, n, runs, sims = run(path, Path(tmp) / f"out{w}", w)
            rates[w], walls[w], task[w] = n / wall, wall, float(sims["wall_time_s"].sum())
            print(f"workers {w}: {n} runs in {wall:.1f} s = {rates[w]:.3f} runs/s, task time {task[w]:.1f} s "
                  f"({(runs['outcome'] == 'failed').sum()} failed)", flush=True)
            if w == 1:
                per = sims.assign(setup=sims["wall_time_s"] - sims["sim_time_s"]).groupby("cell")[["setup", "sim_time_s"]].mean()
        overhead = max(0.0, walls[1] - task[1])
        e2 = min(1.0, (task[1] / 2) / max(walls[2] - overhead, 1e-9))
        print(f"speed-up 2 workers / 1 worker: {rates[2] / rates[1]:.2f}; arena serial time {overhead:.1f} s; "
              f"task efficiency on 2 workers e2 = {e2:.2f}", flush=True)
        per_cell = {c: (float(per.loc[c, "setup"]), float(per.loc[c, "sim_time_s"]), mission[c]) for c in per.index}
        one = extrapolate(shipped, per_cell, args.stop, overhead, 1.0, 1)
        here = extrapolate(shipped, per_cell, args.stop, overhead, e2, 2)
        cluster = extrapolate(shipped, per_cell, args.stop, overhead, e2, args.cores)
    n_full = full.n_runs
    print(f"full arena: {n_full} runs; 1 worker {one['estimate_s'] / 3600:.1f} h; here (2 workers) "
          f"{here['estimate_s'] / 3600:.1f} h; {args.cores} cores {cluster['estimate_s'] / 60:.0f} min "
          f"(tasks spread {cluster['spread_s'] / 60:.0f} min, campaign waves {cluster['waves_s'] / 60:.0f} min)", flush=True)
    print(f"load average after: {os.getloadavg()}", flush=True)
    result.update({"runs_per_s": rates, "speedup_2": rates[2] / rates[1], "arena_serial_s": overhead, "e2": e2,
                   "full_runs": n_full, "one_worker": one, "here": here, f"cluster_{args.cores}": cluster,
                   "per_cell": per_cell})
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(result, indent=1), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
