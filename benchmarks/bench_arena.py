"""Benchmark of the arena (``make bench``): the wall time of the full shipped arena on this machine, and
its estimate on a cluster of ``--cores`` cores from the measured task spread.

``--full`` (what ``make bench`` runs; about an hour on 2 cores): ``ftcsim arena arena/ftc_arena.toml``
on ``--workers`` local workers (default 2), timed, into ``--folder`` (default build/bench/arena-full,
which must not exist: a measurement starts from nothing; ``--resume`` accepts a stored one). The
report: the wall time and its phases (plan, runs, measure, page), the runs' task times (CPU and wall
per run, from the campaigns' summaries), and the estimate on ``--cores``: the serial phases as
measured plus the makespan of the measured task times scheduled longest first on ``--cores`` workers
(the arena submits them in that order), never less than the longest task.

Without ``--full``: a slice (every cell, both hardware sets, every fault class, ``--draws`` draws,
missions cut to ``--stop`` s) is run and each run extrapolated to its cell's mission: a run that
reached the slice's stop costs its set-up (task wall minus stepping) plus its stepping x mission /
stop (stepping is linear in the simulated time at a fixed step); a run that stopped earlier (an FMU
stopped it) costs what it cost. The full arena's tasks (deterministic classes once per cell, the
others ``draws`` times) are then scheduled longest first on 2 and on ``--cores`` workers, with the
efficiency the slice measured (its predicted makespan over its measured one); the serial phases are
scaled (the plan as measured, measuring by the trajectory rows). An estimate, stated as such; the
measurement is ``--full``.

The machine is shared: the load average is printed; numbers taken under load are upper bounds.
"""
from __future__ import annotations

import argparse
import heapq
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))
SHIPPED = ROOT / "arena" / "ftc_arena.toml"


def makespan(tasks, workers: int) -> float:
    """Wall time of ``tasks`` (s) on ``workers`` taken longest first, each by the first free worker."""
    free = [0.0] * max(1, workers)
    for t in sorted(tasks, reverse=True):
        heapq.heappush(free, heapq.heappop(free) + t)
    return max(free)


def task_times(out: Path):
    """Every stored run of an arena folder: its cell, hardware, fault, task wall and CPU time, stepping
    time and end time (pandas)."""
    import pandas as pd

    rows = []
    for f in sorted(out.glob("cells/*/*/summary.parquet")):
        cols = ["variant", "status", "wall_time_s", "cpu_time_s", "sim_time_s", "t_end"]
        s = pd.read_parquet(f)
        s = s[[c for c in cols if c in s.columns]].copy()
        s["cell"] = f.parent.parent.name
        rows.append(s)
    return pd.concat(rows, ignore_index=True)


def full(args) -> dict:
    from arena.app import run_arena

    out = Path(args.folder)
    if out.exists() and not args.resume:
        raise SystemExit(f"bench_arena: {out} exists: delete it for a fresh measurement (or pass --resume)")
    t0 = time.perf_counter()
    o = run_arena(SHIPPED, out, workers=args.workers, progress=True)
    wall = time.perf_counter() - t0
    tasks = task_times(out)
    serial = o.phases.get("plan", 0.0) + o.phases.get("measure", 0.0) + o.phases.get("page", 0.0)
    walls = tasks["wall_time_s"].dropna().to_list()
    est = {n: serial + makespan(walls, n) for n in (args.workers, args.cores)}
    return {"mode": "full", "workers": args.workers, "runs": o.stored, "wall_s": wall, "phases": o.phases,
            "task_wall_sum_s": float(sum(walls)), "task_cpu_sum_s": float(tasks["cpu_time_s"].sum()),
            "longest_task_s": float(max(walls)), "predicted_here_s": est[args.workers],
            f"estimate_{args.cores}_cores_s": est[args.cores], "failed": o.failed}


def slice_(args) -> dict:
    from arena.app import run_arena
    from arena.arenafile import load
    from arena.plan import build

    shipped = load(SHIPPED)
    plans = build(shipped)
    mission = {p.name: shipped.mission(p.cell) for p in plans}
    count = {}  # (cell.hw, fault) -> runs in the full arena
    for p in plans:
        for g in p.groups:
            for f in g.faults:
                count[(p.name, f)] = g.runs
    with tempfile.TemporaryDirectory(prefix="bench-arena-") as tmp:
        out = Path(args.slice_folder) if args.slice_folder else Path(tmp) / "slice"
        t0 = time.perf_counter()
        o = run_arena(SHIPPED, out, workers=args.workers, stop=args.stop, draws=args.draws, progress=True)
        wall = time.perf_counter() - t0
        tasks = task_times(out)
    full_tasks, full_cpu, slice_tasks, full_rows = [], [], [], 0.0
    for r in tasks.itertuples():
        slice_tasks.append(r.wall_time_s)
        reached = r.status == "ok" or (r.t_end is not None and r.t_end >= args.stop - 1e-6)
        setup = max(0.0, r.wall_time_s - (r.sim_time_s or 0.0))
        cost = setup + (r.sim_time_s or 0.0) * mission[r.cell] / args.stop if reached else r.wall_time_s
        n = max(1, round(count[(r.cell, r.variant)] / args.draws))
        full_tasks += [cost] * n
        # the same run in CPU seconds (a loaded machine stretches wall times, far less the CPU a run needs)
        full_cpu += [cost * r.cpu_time_s / max(r.wall_time_s, 1e-9)] * n
        full_rows += n * mission[r.cell] / shipped.trajectory_step
    predicted = makespan(slice_tasks, args.workers)
    efficiency = min(1.0, predicted / max(o.phases["runs"], 1e-9))
    slice_rows = len(tasks) * args.stop / shipped.trajectory_step
    measure = o.phases["measure"] * full_rows / slice_rows  # reading and measuring trajectories: per row
    serial = o.phases["plan"] + measure + o.phases.get("page", 0.0) * len(full_tasks) / len(tasks)
    here = serial + makespan(full_tasks, 2) / efficiency
    cluster = serial + makespan(full_tasks, args.cores) / efficiency
    ph = o.phases
    serial_cpu = ph.get("plan_cpu", 0.0) + ph.get("measure_cpu", 0.0) * full_rows / slice_rows \
        + ph.get("page_cpu", 0.0) * len(full_tasks) / len(tasks)
    here_cpu = serial_cpu + makespan(full_cpu, 2)
    cluster_cpu = serial_cpu + makespan(full_cpu, args.cores)
    return {"mode": "slice", "stop": args.stop, "draws": args.draws, "workers": args.workers, "slice_runs": len(tasks),
            "slice_wall_s": wall, "slice_phases": o.phases, "efficiency": efficiency, "full_runs": len(full_tasks),
            "full_task_sum_s": float(sum(full_tasks)), "longest_task_s": float(max(full_tasks)),
            "serial_s": serial, "estimate_2_workers_s": here, f"estimate_{args.cores}_cores_s": cluster,
            "full_cpu_sum_s": float(sum(full_cpu)), "longest_task_cpu_s": float(max(full_cpu)),
            "serial_cpu_s": serial_cpu, "estimate_2_workers_cpu_s": here_cpu,
            f"estimate_{args.cores}_cores_cpu_s": cluster_cpu}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="run and time the full shipped arena (about an hour here)")
    ap.add_argument("--folder", default=str(ROOT / "build" / "bench" / "arena-full"), help="--full: the arena folder")
    ap.add_argument("--resume", action="store_true", help="--full: accept an existing folder (its stored runs count)")
    ap.add_argument("--stop", type=float, default=20.0, help="slice: simulated seconds per run (default 20)")
    ap.add_argument("--draws", type=int, default=1, help="slice: draws per cell and fault class (default 1)")
    ap.add_argument("--slice-folder", help="slice: keep (and resume) the slice's arena folder here")
    ap.add_argument("--workers", type=int, default=2, help="local Dask workers (default 2)")
    ap.add_argument("--cores", type=int, default=64, help="cluster size of the estimate (default 64)")
    ap.add_argument("--out", help="write the numbers as JSON here")
    args = ap.parse_args(argv)
    print(f"load average before: {os.getloadavg()}", flush=True)
    result = full(args) if args.full else slice_(args)
    result["load_average_after"] = os.getloadavg()
    for k, v in result.items():
        print(f"{k}: {v:.1f}" if isinstance(v, float) else f"{k}: {v}", flush=True)
    if args.full:
        print(f"full shipped arena: {result['runs']} runs in {result['wall_s'] / 60:.1f} min on {args.workers} workers; "
              f"{args.cores} cores: about {result[f'estimate_{args.cores}_cores_s'] / 60:.1f} min", flush=True)
    else:
        print(f"estimate (slice x missions), from wall times: {result['estimate_2_workers_s'] / 60:.0f} min on 2 "
              f"workers, {result[f'estimate_{args.cores}_cores_s'] / 60:.1f} min on {args.cores} cores; from CPU times "
              f"(what a quiet machine gives): {result['estimate_2_workers_cpu_s'] / 60:.0f} min on 2 workers, "
              f"{result[f'estimate_{args.cores}_cores_cpu_s'] / 60:.1f} min on {args.cores} cores", flush=True)
    if args.out:
        Path(args.out).parent.mkdir(parents=True, exist_ok=True)
        Path(args.out).write_text(json.dumps(result, indent=1, default=float), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
