"""Benchmark of the compiled kernels (plant/kernels), run by ``make bench``.

1. Loops at their step, kernels on (numba) and off (the numpy reference: the code before
   issue 16), each through our master with the FMUs and in-process, in this one process:
   li2023_fasmc (3 FMUs, 10 ms), 001 zhang2019_fontsm (3 FMUs, no kernels: the reference path
   twice), 002 zhang2014_hinf_w1 (2 FMUs) and 003 hang2023_asmftc_f04 (3 FMUs) at 1 ms, shortened
   with their ``stop`` (001's Grünwald-Letnikov sums grow with the run: its first 10 s are cheaper
   per step than the 60 s run). µs per macro step (median of ``--repeat``)
   and the speed-up off/on measured in this run.
2. Paper 000's three blocks alone (a hand-written loop over BlockSession, no master), CPU time.
3. Start-up: time to the first macro step in a fresh process, with an empty compile cache
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

from orchestrator.cosim.runner import run_scenario  # noqa: E402
from orchestrator.scenario.overrides import with_overrides  # noqa: E402
from orchestrator.scenario.toml import load  # noqa: E402
from plant import kernels  # noqa: E402

LOOPS = [  # label, scenario name, step (None: the scenario's), stop (s)
    ("000 li2023_fasmc, 3 FMUs, 10 ms", "li2023_fasmc", None, 200.0),
    ("001 zhang2019_fontsm, 3 FMUs, 1 ms", "zhang2019_fontsm", 0.001, 10.0),
    ("002 zhang2014_hinf_w1, 2 FMUs, 1 ms", "zhang2014_hinf_w1", 0.001, 20.0),
    ("003 hang2023_asmftc_f04, 3 FMUs, 1 ms", "hang2023_asmftc_f04", 0.001, 10.0),
]


def loadavg() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "n/a"


def one(path, step, stop, mode):
    sc = with_overrides(load(path, in_process=(mode == "inprocess"), step=step), stop=stop)
    r = run_scenario(sc)
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


def blocks_alone(steps=20000, h=0.01):
    """CPU µs per step of paper 000's three blocks (plant, FAFEO, FASMC) driven by a hand-written
    loop over BlockSession objects, without the master: what the blocks themselves cost, kernels
    off (reference) and on. Faults and disturbance on, so that the plant's stage torques vary."""
    import numpy as np

    from papers.p000_li2023 import blocks as b
    from plant.block import BlockSession

    out = {}
    for on in (False, True):
        kernels.set_enabled(on)
        p, e, c = b.flexible_spacecraft(), b.fafeo(), b.fasmc()
        p.set_parameters({"fault_scale": 1.0, "disturbance_scale": 1.0, "q_init[1]": 0.3, "q_init[2]": 0.2})
        for blk in (p, e, c):
            blk.initialize(0.0)
        sp, se, sc = BlockSession(p), BlockSession(e), BlockSession(c)
        ii, oi = (lambda blk, names: np.array([blk.input_index[x] for x in names])), \
            (lambda blk, names: np.array([blk.output_index[x] for x in names]))
        q, om, u = [f"q[{i}]" for i in range(4)], [f"omega[{i}]" for i in (1, 2, 3)], [f"u[{i}]" for i in (1, 2, 3)]
        f, d2 = [f"f_hat[{i}]" for i in (1, 2, 3)], [f"d2_hat[{i}]" for i in range(1, 9)]
        p_qom, e_om, e_u, p_u = oi(p, q + om), ii(e, om), ii(e, u), ii(p, u)
        e_fd, c_in, c_u = oi(e, f + d2), ii(c, q + om + f + d2), oi(c, u)
        p_om = oi(p, om)
        n = steps if on else steps // 10
        c0 = None
        for k in range(n + 50):  # the first 50 steps load (or compile) the kernels: not timed
            if k == 50:
                c0 = time.process_time()
            t = k * h
            yp = sp.outputs()
            se.set_inputs(e_om, yp[p_om])
            ye = se.outputs()
            sc.set_inputs(c_in, np.concatenate((yp[p_qom], ye[e_fd])))
            yc = sc.outputs()
            sp.set_inputs(p_u, yc[c_u])
            se.set_inputs(e_u, yc[c_u])
            sp.outputs()
            for s in (sp, se, sc):
                s.t = t
                s.advance(t, h)
        out["kernels" if on else "reference"] = (time.process_time() - c0) / n * 1e6
    kernels.set_enabled(True)
    print(f"paper 000 blocks alone (plant + FAFEO + FASMC, no master): reference {out['reference']:.1f} CPU us/step, "
          f"kernels {out['kernels']:.1f} CPU us/step (x{out['reference'] / out['kernels']:.1f})", flush=True)
    return out


_FIRST_STEP = r'''
import sys, time, json
t0 = time.perf_counter()
sys.path.insert(0, sys.argv[1])
from plant import kernels
t_import = time.perf_counter() - t0
from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.toml import load
from papers.registry import scenario_files
from orchestrator.scenario.overrides import with_overrides
sc = load(scenario_files()["li2023_fasmc"], in_process=sys.argv[2] == "inprocess")
sc = with_overrides(sc, stop=sc.start + sc.step)  # one macro step
t1 = time.perf_counter()
r = run_scenario(sc)
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
    report = {"blocks_alone_cpu_us_per_step": blocks_alone(), "loops": loops(a.repeat), "startup": startup()}
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
