"""Benchmark of campaigns on dask.distributed (``make bench``).

* Throughput: ``--runs`` dispersed runs of li2023_pd over ``--stop`` s (default 20 s, FMUs) on a
  LocalCluster of 1 and of 2 worker processes (one thread each), measured in this one process:
  runs per second (cluster start-up excluded, reported apart), parallel efficiency
  rate(2) / (2 rate(1)).
* Overhead per run beyond the simulation: (a) in the worker, the task time minus the master's
  stepping time (FMU instantiation and set-up, read-back, metrics); (b) outside the task,
  workers x (campaign wall time - fixed costs) minus the sum of the task times, per run
  (scheduling, result transfer, the Parquet row); the fixed costs per campaign (folder, manifest,
  summary) measured by rerunning the finished campaign; (c) the same runs in a plain loop of
  ``run_scenario`` in this process, for comparison with (a) + (b). Utilisation (the share of the
  wall time the workers spent in tasks) and the CPU share the tasks obtained tell scheduling gaps
  from cores taken by other processes.
* Memory: ``--memory-runs`` FMU runs of li2023_fasmc (three FMI 2.0 FMUs, 20 ms each) in one
  worker: its RSS after 10 warm-up runs and at the end.

The machine is shared: the load average is printed before and after; numbers taken under load
are upper bounds for times and lower bounds for the efficiency.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

CAMPAIGN = """
[campaign]
name = "bench"
scenario = "{scenario}"
runs = {runs}
seed = 1
stop = {stop}
mode = "{mode}"

[dispersions."plant.fault_scale"]
distribution = "uniform"
low = 0.2
high = 1.5
"""


def loadavg() -> str:
    try:
        return Path("/proc/loadavg").read_text().split(" ", 3)[:3].__str__()
    except OSError:
        return "?"


def throughput(tmp: Path, runs: int, stop: float, mode: str, workers: int) -> dict:
    import pandas as pd

    from orchestrator.campaign.cluster import connect
    from orchestrator.campaign.run import run_campaign
    from orchestrator.campaign.store import SUMMARY

    path = tmp / f"bench_{workers}.toml"
    path.write_text(CAMPAIGN.format(scenario="li2023_pd", runs=runs, stop=stop, mode=mode))
    t = time.perf_counter()
    client = connect(workers, None)
    client.run(lambda: __import__("orchestrator.campaign.run"))  # imports done before timing
    startup = time.perf_counter() - t
    try:
        t = time.perf_counter()
        o = run_campaign(path, tmp / f"out_{workers}", client=client)
        wall = time.perf_counter() - t
        t = time.perf_counter()
        again = run_campaign(path, tmp / f"out_{workers}", client=client)  # nothing to do: the fixed costs
        fixed = time.perf_counter() - t
        assert again.computed == 0
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()
    df = pd.read_parquet(tmp / f"out_{workers}" / SUMMARY)
    assert o.stored == runs and set(df.status) == {"ok"}, (o, df.error.dropna().head())
    task, sim, cpu = (df[c].to_numpy(float) for c in ("wall_time_s", "sim_time_s", "cpu_time_s"))
    return {"workers": workers, "runs": runs, "startup_s": startup, "wall_s": wall, "runs_per_s": runs / wall,
            "task_mean_s": float(task.mean()), "task_cpu_mean_s": float(cpu.mean()), "sim_mean_s": float(sim.mean()),
            "in_worker_overhead_s": float((task - sim).mean()), "fixed_s": fixed,
            "outside_task_overhead_s": float(((wall - fixed) * workers - task.sum()) / runs),
            "utilisation": float(task.sum() / (workers * wall)), "cpu_share": float(cpu.sum() / task.sum())}


def plain_loop(runs: int, stop: float, mode: str) -> dict:
    from orchestrator.campaign.expand import expand
    from orchestrator.campaign.spec import load, load_base
    from orchestrator.cosim.runner import run_scenario
    from orchestrator.scenario.overrides import with_overrides

    with tempfile.TemporaryDirectory() as d:
        p = Path(d) / "c.toml"
        p.write_text(CAMPAIGN.format(scenario="li2023_pd", runs=runs, stop=stop, mode=mode))
        c = load(p)
        plan = expand(c)
        base = load_base(plan[0].recipe)[0]
        t = time.perf_counter()
        sims = []
        for s in plan:
            r = run_scenario(with_overrides(base, parameters=s.parameters))
            sims.append(r.wall_time)
        wall = time.perf_counter() - t
    return {"runs": runs, "wall_s": wall, "per_run_s": wall / runs, "sim_mean_s": sum(sims) / runs,
            "setup_per_run_s": (wall - sum(sims)) / runs}


def memory(tmp: Path, runs: int) -> dict:
    import psutil

    from orchestrator.campaign.cluster import connect
    from orchestrator.campaign.expand import expand
    from orchestrator.campaign.spec import load
    from orchestrator.campaign.worker import execute

    path = tmp / "mem.toml"
    path.write_text(CAMPAIGN.format(scenario="li2023_fasmc", runs=runs, stop=0.02, mode="fmu"))
    plan = expand(load(path))
    client = connect(1, None)
    try:
        def rss():
            return psutil.Process().memory_info().rss / 2**20

        def run_all(specs):
            for s in specs:
                assert execute(s)["row"]["status"] == "ok"

        client.submit(run_all, plan[:10], pure=False).result()
        (r0,) = client.run(rss).values()
        t = time.perf_counter()
        client.submit(run_all, plan[10:], pure=False).result()
        wall = time.perf_counter() - t
        (r1,) = client.run(rss).values()
    finally:
        cluster = client.cluster
        client.close()
        cluster.close()
    return {"runs": runs, "rss_after_10_MB": r0, "rss_end_MB": r1, "growth_MB": r1 - r0,
            "per_run_s": wall / (runs - 10)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=64)  # 16 measured mostly each worker's first FMU load
    ap.add_argument("--stop", type=float, default=20.0)
    ap.add_argument("--mode", choices=["fmu", "inprocess"], default="fmu")
    ap.add_argument("--memory-runs", type=int, default=200)
    ap.add_argument("--json", help="write the numbers to this file")
    a = ap.parse_args(argv)
    os.environ.setdefault("FTCSIM_FMU_DIR", str(ROOT / "build" / "fmus"))
    out = {"load_before": loadavg(), "cores": os.cpu_count()}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        out["one_worker"] = throughput(tmp, a.runs, a.stop, a.mode, 1)
        out["two_workers"] = throughput(tmp, a.runs, a.stop, a.mode, 2)
        out["plain_loop"] = plain_loop(min(a.runs, 4), a.stop, a.mode)
        if a.memory_runs:
            out["memory"] = memory(tmp, a.memory_runs)
    out["load_after"] = loadavg()
    r1, r2 = out["one_worker"], out["two_workers"]
    out["parallel_efficiency"] = r2["runs_per_s"] / (2 * r1["runs_per_s"])
    # on idle cores a CPU-bound task's wall time is its CPU time: rate_n = n utilisation_n / cpu_n
    out["parallel_efficiency_cpu_estimate"] = (r2["utilisation"] * r1["task_cpu_mean_s"]) / (
        r1["utilisation"] * r2["task_cpu_mean_s"])
    print(f"campaigns: {a.runs} runs of li2023_pd, {a.stop:g} s at 10 ms, mode {a.mode}; load {out['load_before']}")
    for r in (r1, r2):
        print(f"  {r['workers']} worker(s): {r['runs_per_s']:.3f} runs/s (wall {r['wall_s']:.1f} s, cluster start "
              f"{r['startup_s']:.1f} s); task {r['task_mean_s']:.3f} s = simulation {r['sim_mean_s']:.3f} s + set-up "
              f"etc. {r['in_worker_overhead_s']:.3f} s; outside the task {r['outside_task_overhead_s'] * 1e3:.1f} ms/run, "
              f"plus {r['fixed_s']:.2f} s per campaign (folder, manifest, summary)")
    p = out["plain_loop"]
    print(f"  plain run_scenario loop in this process: {p['per_run_s']:.3f} s/run (simulation {p['sim_mean_s']:.3f} s, "
          f"set-up {p['setup_per_run_s']:.3f} s)")
    print(f"  parallel efficiency on 2 workers: {out['parallel_efficiency']:.2f} (workers busy with tasks "
          f"{r1['utilisation']:.0%} / {r2['utilisation']:.0%} of the wall time; CPU obtained by the tasks "
          f"{r1['cpu_share']:.0%} / {r2['cpu_share']:.0%} of their wall time: below 100 % other processes took the cores)")
    print(f"  estimated on idle cores from the tasks' CPU times ({r1['task_cpu_mean_s']:.3f} s / {r2['task_cpu_mean_s']:.3f} s"
          f" per run) and the utilisations: {out['parallel_efficiency_cpu_estimate']:.2f}")
    if "memory" in out:
        m = out["memory"]
        print(f"  memory: {m['runs']} FMU runs (li2023_fasmc, 3 FMI 2.0 FMUs) in one worker: RSS {m['rss_after_10_MB']:.1f} MB "
              f"after 10 runs, {m['rss_end_MB']:.1f} MB at the end (growth {m['growth_MB']:+.1f} MB), "
              f"{m['per_run_s']:.3f} s/run")
    print(f"  load after: {out['load_after']}")
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
