"""Benchmark of the compiled kernels (plant/kernels), run by ``make bench``.

1. Loops at their step, kernels on (numba) and off (the numpy reference: the code before
   issue 16), each through our master with the FMUs and in-process, in this one process:
   li2023_fasmc (3 FMUs, 10 ms), 002 zhang2014_hinf_w1 (2 FMUs) and 003 hang2023_asmftc_f04
   (3 FMUs) at 1 ms, shortened with their ``stop``. µs per macro step (median of ``--repeat``)
   and the speed-up off/on measured in this run.
2. Start-up: time to the first macro step in a fresh process, with an empty compile cache
   (cold: every kernel is compiled) and again with the cache it left (warm), in-process and
   with the FMUs; also the time to import numba and the kernels.

Machine load (``/proc/loadavg``) and this process's CPU time are printed with the numbers: the
machine is shared, so wall times are upper bounds; ratios are measured in the same run.

    .venv/bin/python benchmarks/bench_kernels.py [--repeat 3] [--json build/bench/kernels.json]
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from orchestrator.runner import run_scenario  # noqa: E402
from orchestrator.scenario import load  # noqa: E402
from plant import kernels  # noqa: E402

LOOPS = [  # label, scenario name, step (None: the scenario's), stop (s)
    ("000 li2023_fasmc, 3 FMUs, 10 ms", "li2023_fasmc", None, 200.0),
    ("002 zhang2014_hinf_w1, 2 FMUs, 1 ms", "zhang2014_hinf_w1", 0.001, 20.0),
    ("003 hang2023_asmftc_f04, 3 FMUs, 1 ms", "hang2023_asmftc_f04", 0.001, 10.0),
]


def loadavg() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "n/a"


def one(path, step, stop, mode):
    sc = load(path, in_process=(mode == "inprocess"), step=step)
    sc.stop = stop
    r = run_scenario(sc, mode=mode)
    if not r.complete:
        raise RuntimeError(f"{path}: {r.error}")
    return r.wall_time / r.steps * 1e6, r.steps


def loops(repeat):
    from papers.registry import scenario_files

    files = scenario_files()
    rows = []
    for label, name, step, stop in LOOPS:
        res = {}
        for on in (False, True):
            kernels.set_enabled(on)
            for mode in ("fmu", "inprocess"):
                us = [one(files[name], step, stop, mode) for _ in range(repeat)]
                res[(on, mode)] = statistics.median(u for u, _ in us)
                n = us[0][1]
        kernels.set_enabled(True)
        row = {"case": label, "steps": n}
        for mode in ("fmu", "inprocess"):
            off, on = res[(False, mode)], res[(True, mode)]
            row[mode] = {"reference_us_per_step": off, "kernels_us_per_step": on, "speedup": off / on}
            print(f"{label:40s} {mode:9s} reference {off:9.1f} us/step   kernels {on:8.1f} us/step   x{off / on:5.1f}",
                  flush=True)
        rows.append(row)
    return rows


_FIRST_STEP = r'''
import sys, time, json
t0 = time.perf_counter()
sys.path.insert(0, sys.argv[1])
from plant import kernels
t_import = time.perf_counter() - t0
from orchestrator.runner import run_scenario
from orchestrator.scenario import load
from papers.registry import scenario_files
sc = load(scenario_files()["li2023_fasmc"], in_process=sys.argv[2] == "inprocess")
sc.stop = sc.start + sc.step  # one macro step
t1 = time.perf_counter()
r = run_scenario(sc, mode=sys.argv[2])
assert r.complete, r.error
print(json.dumps({"import_kernels_s": t_import, "first_step_s": time.perf_counter() - t1,
                  "process_to_first_step_s": time.perf_counter() - t0, "kernels": kernels.enabled()}))
'''


def startup():
    out = {}
    with tempfile.TemporaryDirectory(prefix="ftcsim_cold_cache_") as cache:
        env = {**os.environ, "FTCSIM_CACHE_DIR": cache}
        for mode in ("inprocess", "fmu"):
            for state in ("cold", "warm"):
                if state == "cold":  # empty the cache: every kernel compiles
                    for p in sorted(Path(cache).rglob("*"), reverse=True):
                        p.unlink() if p.is_file() else p.rmdir()
                res = subprocess.run([sys.executable, "-c", _FIRST_STEP, str(ROOT), mode], capture_output=True,
                                     text=True, env=env, cwd=str(ROOT), timeout=600)
                if res.returncode not in (0, -6, 134) or not res.stdout.strip():
                    raise RuntimeError(res.stderr[-2000:])
                d = json.loads(res.stdout.strip().splitlines()[-1])
                out[f"{mode}, {state} cache"] = d
                print(f"start-up {mode:9s} {state} cache: first macro step {d['first_step_s']:6.2f} s "
                      f"(process start to first step {d['process_to_first_step_s']:6.2f} s, "
                      f"import numba + kernels {d['import_kernels_s']:.2f} s)", flush=True)
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", default=str(ROOT / "build" / "bench" / "kernels.json"))
    a = ap.parse_args(argv)
    if not kernels.enabled():
        print(f"kernels are off ({kernels.REASON}): nothing to compare")
        return 1
    cpu0, wall0, load0 = time.process_time(), time.perf_counter(), loadavg()
    print(f"load average at start {load0}", flush=True)
    report = {"loops": loops(a.repeat), "startup": startup()}
    report["load_average"] = {"start": load0, "end": loadavg()}
    report["process_cpu_s"] = time.process_time() - cpu0
    report["wall_s"] = time.perf_counter() - wall0
    print(f"load average at end {report['load_average']['end']}; this process: {report['process_cpu_s']:.1f} s CPU "
          f"in {report['wall_s']:.1f} s wall (start-up probes run in child processes)")
    out = Path(a.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"written {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
