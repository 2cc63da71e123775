"""Benchmark of the co-simulation master (``make bench``).

For each case: (a) our master driving the FMUs, (b) a minimal hand-written loop over the
same FMUs with fmpy's public FMU2Slave API (same exchanges, same recorded variables),
(c) our master driving the blocks in-process. Each is run ``--repeat`` times in this one
process and the median is reported: µs per macro step, real-time factor, and the ratios
a/b and a/c measured in this run. CPU time of this process per step, with the set-up (loading
the FMUs) and without it ("loop cpu": for a and c the CPU time of a one-step run is
subtracted, for b the loop is timed alone): on a shared machine the loop CPU time is the
number that does not count waiting for a core.

    .venv/bin/python benchmarks/bench_master.py [--quick] [--repeat 3] [--only li2023_fasmc]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from orchestrator.cosim.fmu import release_fmu  # noqa: E402
from orchestrator.cosim.host import prepare_process  # noqa: E402
from orchestrator.cosim.runner import run_scenario  # noqa: E402
from orchestrator.scenario.overrides import with_overrides  # noqa: E402
from orchestrator.scenario.toml import load  # noqa: E402


def cases():
    """(label, scenario file, step override, stop override, repeats) from every paper's
    ``Paper.benchmarks`` (papers/registry.py)."""
    from papers.registry import papers, scenario_files

    files = scenario_files()
    out = []
    for p in papers():
        for name, step, repeats in p.benchmarks:
            sc = load(files[name], step=step)
            label = f"{name}, {len(sc.instances)} FMUs, {sc.step * 1e3:g} ms"
            out.append((label, str(files[name]), step, None, repeats))
    return out


def _loadavg() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "n/a"


def minimal_fmpy_loop(scenario) -> float:
    """Wall time of a plain fmpy loop: getReal/setReal/doStep in dependency order."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    prepare_process()  # as our master does before it loads an FMU
    fmus, vrs = {}, {}
    for name, inst in scenario.instances.items():
        md = read_model_description(str(inst.fmu))
        f = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(inst.fmu)),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        f.instantiate()
        f.setupExperiment(startTime=scenario.start, stopTime=scenario.stop)
        vr = {v.name: v.valueReference for v in md.modelVariables}
        if inst.parameters:
            f.setReal([vr[k] for k in inst.parameters], list(inst.parameters.values()))
        f.enterInitializationMode()
        f.exitInitializationMode()
        fmus[name], vrs[name] = f, vr
    # ordered like the master's plan: connections grouped by the feedthrough level of their source
    from orchestrator.cosim.fmu import fmu_component
    from orchestrator.cosim.plan import feedthrough_levels

    conns = scenario.connections
    comps = {n: fmu_component(n, i.fmu, read_model_description(str(i.fmu))) for n, i in scenario.instances.items()}
    source_of = {(d, dv): (s, sv) for s, sv, d, dv in conns}
    level = feedthrough_levels(comps, conns, source_of, sorted({(s, sv) for s, sv, _, _ in conns}))

    def wiring(cs):
        src = {}
        for s, sv, d, dv in cs:
            src.setdefault((s, d), ([], []))
            src[(s, d)][0].append(vrs[s][sv])
            src[(s, d)][1].append(vrs[d][dv])
        return list(src.items())

    stages = [wiring([c for c in conns if level[(c[0], c[1])] == lev]) for lev in sorted(set(level.values()))]
    rec = {}
    for i, v in scenario.record:
        rec.setdefault(i, []).append(vrs[i][v])
    h = scenario.step
    n = scenario.n_steps
    srcs = [(s, fmus[s.targets[0][0]], [vrs[i][v] for i, v in s.targets]) for s in scenario.sources]
    rows = []
    c0 = time.process_time()
    t0 = time.perf_counter()
    seg = [-1] * len(srcs)
    for k in range(n):
        t = scenario.start + k * h
        for j, (src, dst, dst_vr) in enumerate(srcs):
            s = max([i for i, ti in enumerate(src.times) if ti <= t + 1e-12] or [0])
            if s != seg[j]:
                dst.setReal(dst_vr, list(src.values[s]))
                seg[j] = s
        for stage in stages:
            for (a, b), (out, inp) in stage:
                fmus[b].setReal(inp, fmus[a].getReal(out))
        rows.append([x for i, r in rec.items() for x in fmus[i].getReal(r)])
        for f in fmus.values():
            f.doStep(currentCommunicationPoint=t, communicationStepSize=h)
    wall = time.perf_counter() - t0
    minimal_fmpy_loop.loop_cpu = time.process_time() - c0  # the loop alone, without the set-up
    for f in fmus.values():
        release_fmu(f)
    assert len(rows) == n and np.isfinite(rows[-1]).all()
    return wall


def _setup_cpu(path, step, inproc) -> float:
    """CPU time of a one-step run of our master (loading, set-up, one step, release): subtracted
    from a full run's CPU time, what is left is the loop's own CPU time."""
    sc = _scenario(path, step, None, inproc)
    sc = with_overrides(sc, stop=sc.start + sc.step)
    c0 = time.process_time()
    r = run_scenario(sc)
    assert r.complete, r.error
    return time.process_time() - c0


def _scenario(path, step, stop, in_process=False):
    sc = load(path, in_process=in_process, step=step)
    return with_overrides(sc, stop=stop) if stop else sc


def measure(path, step, stop, repeat):
    """Median wall time of each path, and (key + "_cpu") the median CPU time of this process
    over the same runs (the machine is shared: CPU time does not count waiting for a core).
    The paths alternate a, b, c within each repeat so that load changes hit all of them."""
    path = Path(path)
    walls = {"a": [], "b": [], "c": []}
    cpus = {"a": [], "b": [], "c": []}
    loop_cpus = {"a": [], "b": [], "c": []}
    for _ in range(repeat):
        for label in ("a", "b", "c"):
            c0 = time.process_time()
            if label == "b":
                wall = minimal_fmpy_loop(_scenario(path, step, stop))
                loop_cpu = minimal_fmpy_loop.loop_cpu
            else:
                inproc = label == "c"
                r = run_scenario(_scenario(path, step, stop, inproc))
                assert r.complete, r.error
                wall = r.wall_time
            cpus[label].append(time.process_time() - c0)
            if label != "b":
                loop_cpu = cpus[label][-1] - _setup_cpu(path, step, inproc)
            walls[label].append(wall)
            loop_cpus[label].append(loop_cpu)
    results = {k: statistics.median(v) for k, v in walls.items()}
    results.update({f"{k}_cpu": statistics.median(v) for k, v in cpus.items()})
    results.update({f"{k}_loop_cpu": statistics.median(v) for k, v in loop_cpus.items()})
    return results, _scenario(path, step, stop)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3, help="at most this many runs per path")
    ap.add_argument("--quick", action="store_true", help="skip the 1 ms case")
    ap.add_argument("--only", help="only the cases whose label contains this text")
    ap.add_argument("--json", default=str(ROOT / "build" / "bench" / "master.json"))
    args = ap.parse_args(argv)
    report = []
    cpu0 = time.process_time()
    load0 = _loadavg()
    print(f"load average at start: {load0}")
    print(f"{'case':34s} {'path':10s} {'us/step':>9s} {'RTF':>7s} {'cpu us/step':>12s} {'loop cpu':>12s}")
    for label, path, step, stop, repeat in cases():
        if args.quick and step is not None and step < 0.005:
            continue
        if args.only and args.only not in label:
            continue
        res, sc = measure(path, step, stop, min(repeat, args.repeat))
        n = sc.n_steps
        sim = sc.stop - sc.start
        row = {"case": label, "steps": n, "sim_time_s": sim}
        for key, name in (("a", "master+FMU"), ("b", "fmpy loop"), ("c", "in-process")):
            us = res[key] / n * 1e6
            rtf = sim / res[key]
            cpu_us = res[f"{key}_cpu"] / n * 1e6  # includes set-up (loading the FMUs), so an upper bound
            loop_us = res[f"{key}_loop_cpu"] / n * 1e6  # the loop alone (a, c: minus a one-step run)
            row[key] = {"wall_s": res[key], "us_per_step": us, "real_time_factor": rtf, "cpu_us_per_step": cpu_us,
                        "loop_cpu_us_per_step": loop_us}
            print(f"{label:34s} {name:10s} {us:9.1f} {rtf:7.1f} {cpu_us:12.1f} {loop_us:12.1f}")
        row["a_over_b"] = res["a"] / res["b"]
        row["a_over_c"] = res["a"] / res["c"]
        row["a_over_b_loop_cpu"] = res["a_loop_cpu"] / res["b_loop_cpu"]
        print(f"{label:34s} ratios: a/b = {row['a_over_b']:.3f}, a/c = {row['a_over_c']:.3f}, "
              f"a/b of loop CPU = {row['a_over_b_loop_cpu']:.3f}")
        report.append(row)
    load1 = _loadavg()
    cpu = time.process_time() - cpu0
    print(f"load average at end: {load1}; this process used {cpu:.1f} s of CPU")
    report.append({"load_average": {"start": load0, "end": load1}, "process_cpu_s": cpu})
    out = Path(args.json)
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=2) + "\n")
    print(f"written {out}")


if __name__ == "__main__":
    main()
