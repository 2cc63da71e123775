"""Benchmark of the paper 002 and 003 loops: µs per macro step at the scenario step.

Cases (shipped scenarios, shortened with --stop so that a run takes seconds, not minutes):
  002: zhang2014_hinf_w1, 2 FMUs (Zhang2014Plant, Zhang2014Hinf), 10 ms
  003: hang2023_asmftc_f04, 3 FMUs (Hang2023Plant, Hang2023TSFDO, Hang2023ASMFTC), 0.5 ms
each through our master with the FMUs (fmpy) and with the same blocks in-process, ``--repeat``
times; the median is reported with the real-time factor. Needs the FMUs (``ftcsim build``).

    .venv/bin/python benchmarks/bench_zhang2014_hang2023.py [--repeat 3] [--json out.json]
"""
from __future__ import annotations

import argparse
import json
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from orchestrator.cosim.runner import run_scenario  # noqa: E402
from orchestrator.scenario.overrides import with_overrides  # noqa: E402
from orchestrator.scenario.toml import load  # noqa: E402

CASES = [
    # label, scenario, stop (s)
    ("002 zhang2014_hinf_w1, 2 FMUs, 10 ms", "papers/p002_zhang2014/scenarios/zhang2014_hinf_w1.toml", 100.0),
    ("003 hang2023_asmftc_f04, 3 FMUs, 0.5 ms", "papers/p003_hang2023/scenarios/hang2023_asmftc_f04.toml", 10.0),
]


def one(path, stop, mode):
    sc = with_overrides(load(ROOT / path, in_process=(mode == "inprocess")), stop=stop)
    t0 = time.perf_counter()
    r = run_scenario(sc)
    wall = time.perf_counter() - t0
    if not r.complete:
        raise RuntimeError(f"{path}: {r.error}")
    return wall, sc.n_steps, sc.step


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", help="write the numbers here")
    a = ap.parse_args(argv)
    rows = []
    for label, path, stop in CASES:
        for mode in ("fmu", "inprocess"):
            walls = []
            for _ in range(a.repeat):
                wall, n, h = one(path, stop, mode)
                walls.append(wall)
            med = statistics.median(walls)
            row = {"case": label, "mode": mode, "steps": n, "step": h, "wall_s": med,
                   "us_per_step": 1e6 * med / n, "real_time_factor": n * h / med}
            rows.append(row)
            print(f"{label:45s} {mode:9s} {row['us_per_step']:9.1f} us/step  RTF {row['real_time_factor']:8.2f}"
                  f"  ({n} steps, median of {a.repeat})", flush=True)
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=2) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
