"""Time per LMI design of every registered paper (median of several runs, each including its
post-solve checks and independent verification) and the solver that produced the solution.

    python benchmarks/bench_designs.py [--repeat N] [--only NAME ...]
"""
import argparse
import statistics
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))


def main(argv=None):
    from papers.paper import resolve
    from papers.registry import designs

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--only", nargs="*", help="design names (default: every registered design)")
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    rows = []
    for name, (_paper, spec) in designs().items():
        if args.only and name not in args.only:
            continue
        module = resolve(spec.module)
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            _, summary = module.run_design()
            times.append(time.perf_counter() - t0)
        rows.append((name, statistics.median(times), min(times), max(times), summary))
    print(f"{'design':<22}{'median s':>10}{'min s':>8}{'max s':>8}  result")
    for name, med, lo, hi, summary in rows:
        print(f"{name:<22}{med:>10.2f}{lo:>8.2f}{hi:>8.2f}  {summary[:150]}")
    return rows


if __name__ == "__main__":
    main()
