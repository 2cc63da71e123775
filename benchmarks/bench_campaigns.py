"""Benchmark of campaigns on dask.distributed (``make bench``).

* Throughput: ``--runs`` dispersed runs of li2023_pd over ``--stop`` s (20 s, FMUs) and
  ``--runs-long`` over ``--stop-long`` s (200 s) on a LocalCluster of 1 and of 2 worker processes (one
  thread each), measured in this one process: runs per second and per worker (cluster start-up
  excluded, reported apart), parallel efficiency rate(2) / (2 rate(1)); tasks are batches of runs
  (``orchestrator.campaign.run._batch_size``, or ``--batch``).
* Overhead per run beyond the simulation: (a) in the worker, the task time minus the master's
  stepping time (FMU instantiation and set-up, read-back, metrics); (b) outside the task,
  workers x (campaign wall time - fixed costs) minus the sum of the task times, per run
  (scheduling, result transfer, the Parquet row); the fixed costs per campaign (folder, manifest,
  summary) measured by rerunning the finished campaign; (c) the same runs in a plain loop of
  ``run_scenario`` in this process, for comparison with (a) + (b). Utilisation (the share of the
  wall time the workers spent in tasks) and the CPU share the tasks obtained tell scheduling gaps
  from cores taken by other processes.
* A fresh worker's first run (issue 25 item 3): one worker whose kernel cache is empty
  (``FTCSIM_CACHE_DIR`` a new folder), one li2023_fasmc run, without shipping (the worker compiles the
  kernels in its first run) and with it (``orchestrator.campaign.shipping``: this machine's cache
  unpacked and the scenario warmed before the first task): the first run's task time and the time
  from submitting the campaign to its end.
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


def throughput(tmp: Path, runs: int, stop: float, mode: str, workers: int, batch=None) -> dict:
    import pandas as pd

    from orchestrator.campaign.cluster import close, connect
    from orchestrator.campaign.run import run_campaign
    from orchestrator.campaign.store import SUMMARY

    name = f"bench_{workers}_{stop:g}"
    path = tmp / f"{name}.toml"
    path.write_text(CAMPAIGN.format(scenario="li2023_pd", runs=runs, stop=stop, mode=mode))
    t = time.perf_counter()
    client = connect(workers, None, dashboard=False)
    client.run(lambda: __import__("orchestrator.campaign.run"))  # imports done before timing
    startup = time.perf_counter() - t
    try:
        t = time.perf_counter()
        o = run_campaign(path, tmp / f"out_{name}", client=client, batch=batch)
        wall = time.perf_counter() - t
        t = time.perf_counter()
        again = run_campaign(path, tmp / f"out_{name}", client=client)  # nothing to do: the fixed costs
        fixed = time.perf_counter() - t
        assert again.computed == 0
    finally:
        close(client)
    df = pd.read_parquet(tmp / f"out_{name}" / SUMMARY)
    assert o.stored == runs and set(df.status) == {"ok"}, (o, df.error.dropna().head())
    task, sim, cpu = (df[c].to_numpy(float) for c in ("wall_time_s", "sim_time_s", "cpu_time_s"))
    return {"workers": workers, "runs": runs, "stop": stop, "startup_s": startup, "wall_s": wall,
            "runs_per_s": runs / wall, "runs_per_s_per_worker": runs / wall / workers,
            "task_mean_s": float(task.mean()), "task_cpu_mean_s": float(cpu.mean()), "sim_mean_s": float(sim.mean()),
            "in_worker_overhead_s": float((task - sim).mean()), "fixed_s": fixed,
            "outside_task_overhead_s": float(((wall - fixed) * workers - task.sum()) / runs),
            "utilisation": float(task.sum() / (workers * wall)), "cpu_share": float(cpu.sum() / task.sum())}


def first_run(tmp: Path, ship: bool) -> dict:
    """One li2023_fasmc run (FMUs) on a fresh worker whose kernel cache is empty: wall time of the
    campaign (worker set-up included) and the first run's task time."""
    import pandas as pd
    from distributed import LocalCluster

    from orchestrator.campaign.run import run_campaign
    from orchestrator.campaign.store import SUMMARY

    tag = "shipped" if ship else "cold"
    path = tmp / f"first_{tag}.toml"
    path.write_text(CAMPAIGN.format(scenario="li2023_fasmc", runs=1, stop=1.0, mode="fmu"))
    cache = Path(tempfile.mkdtemp(prefix=f"ftcsim-cache-{tag}-", dir=tmp))
    cluster = LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None,
                           env={"FTCSIM_CACHE_DIR": str(cache)}, local_directory=str(tmp / f"scratch_{tag}"))
    try:
        t = time.perf_counter()
        run_campaign(path, tmp / f"out_first_{tag}", cluster=cluster, ship=ship)
        wall = time.perf_counter() - t
    finally:
        cluster.close()
    df = pd.read_parquet(tmp / f"out_first_{tag}" / SUMMARY)
    assert set(df.status) == {"ok"}, list(df.error)
    return {"ship": ship, "campaign_wall_s": wall, "first_task_s": float(df.wall_time_s[0]),
            "first_task_cpu_s": float(df.cpu_time_s[0])}


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

    from orchestrator.campaign.cluster import close, connect
    from orchestrator.campaign.expand import expand
    from orchestrator.campaign.spec import load
    from orchestrator.campaign.worker import execute

    path = tmp / "mem.toml"
    path.write_text(CAMPAIGN.format(scenario="li2023_fasmc", runs=runs, stop=0.02, mode="fmu"))
    plan = expand(load(path))
    client = connect(1, None, dashboard=False)
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
        close(client)
    return {"runs": runs, "rss_after_10_MB": r0, "rss_end_MB": r1, "growth_MB": r1 - r0,
            "per_run_s": wall / (runs - 10)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=256)  # 64: the fixed cost per campaign (0.4 s) weighs 4 %
    ap.add_argument("--stop", type=float, default=20.0)
    ap.add_argument("--runs-long", type=int, default=24)
    ap.add_argument("--stop-long", type=float, default=200.0)
    ap.add_argument("--batch", type=int, help="runs per task (default: the campaign's choice)")
    ap.add_argument("--mode", choices=["fmu", "inprocess"], default="fmu")
    ap.add_argument("--memory-runs", type=int, default=200)
    ap.add_argument("--skip-first-run", action="store_true", help="skip the fresh-worker measurement")
    ap.add_argument("--json", help="write the numbers to this file")
    a = ap.parse_args(argv)
    os.environ.setdefault("FTCSIM_FMU_DIR", str(ROOT / "build" / "fmus"))
    out = {"load_before": loadavg(), "cores": os.cpu_count(), "throughput": []}
    with tempfile.TemporaryDirectory() as d:
        tmp = Path(d)
        for runs, stop in ((a.runs, a.stop), (a.runs_long, a.stop_long)):
            if runs <= 0:
                continue
            pair = [throughput(tmp, runs, stop, a.mode, n, a.batch) for n in (1, 2)]
            # on idle cores a CPU-bound task's wall time is its CPU time: rate_n = n utilisation_n / cpu_n
            estimate = (pair[1]["utilisation"] * pair[0]["task_cpu_mean_s"]) / (
                pair[0]["utilisation"] * pair[1]["task_cpu_mean_s"])
            out["throughput"].append({"stop": stop, "runs": runs, "one_worker": pair[0], "two_workers": pair[1],
                                      "parallel_efficiency": pair[1]["runs_per_s"] / (2 * pair[0]["runs_per_s"]),
                                      "parallel_efficiency_cpu_estimate": estimate})
        out["plain_loop"] = plain_loop(min(a.runs, 4), a.stop, a.mode)
        if not a.skip_first_run:
            out["first_run"] = {"cold": first_run(tmp, ship=False), "shipped": first_run(tmp, ship=True)}
        if a.memory_runs:
            out["memory"] = memory(tmp, a.memory_runs)
    out["load_after"] = loadavg()
    print(f"campaigns: runs of li2023_pd at 10 ms, mode {a.mode}; load {out['load_before']} on {out['cores']} cores")
    for m in out["throughput"]:
        r1, r2 = m["one_worker"], m["two_workers"]
        print(f"  {m['runs']} runs of {m['stop']:g} s:")
        for r in (r1, r2):
            print(f"    {r['workers']} worker(s): {r['runs_per_s']:.3f} runs/s, {r['runs_per_s_per_worker']:.3f} runs/s per "
                  f"worker (wall {r['wall_s']:.1f} s, cluster start {r['startup_s']:.1f} s); task {r['task_mean_s']:.3f} s "
                  f"= simulation {r['sim_mean_s']:.3f} s + set-up etc. {r['in_worker_overhead_s']:.3f} s; outside the "
                  f"task {r['outside_task_overhead_s'] * 1e3:.1f} ms/run, plus {r['fixed_s']:.2f} s per campaign; "
                  f"workers busy {r['utilisation']:.0%}, CPU obtained by the tasks {r['cpu_share']:.0%}")
        print(f"    parallel efficiency on 2 workers: {m['parallel_efficiency']:.2f} (estimated for idle cores from the "
              f"tasks' CPU times and the utilisations: {m['parallel_efficiency_cpu_estimate']:.2f})")
    p = out["plain_loop"]
    print(f"  plain run_scenario loop in this process: {p['per_run_s']:.3f} s/run (simulation {p['sim_mean_s']:.3f} s, "
          f"set-up {p['setup_per_run_s']:.3f} s)")
    if "first_run" in out:
        c, s = out["first_run"]["cold"], out["first_run"]["shipped"]
        print(f"  fresh worker (empty kernel cache), one li2023_fasmc run: first task {c['first_task_s']:.2f} s "
              f"(campaign {c['campaign_wall_s']:.1f} s) without shipping; {s['first_task_s']:.2f} s (campaign "
              f"{s['campaign_wall_s']:.1f} s, set-up included) with the kernel cache shipped and the worker warmed")
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
