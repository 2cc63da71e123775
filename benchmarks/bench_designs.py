"""Time per LMI design (median of several runs, each including its post-solve checks and
independent verification) and the solver that produced the accepted solution.

    python benchmarks/bench_designs.py [--repeat N]
"""
import argparse
import statistics
import time
import warnings


def _designs():
    from controller import design_li2023 as dc
    from estimator import design_li2023 as de
    from papers.p002_zhang2014 import design as dz
    from papers.p003_hang2023 import design as dh

    return [
        ("li2023-observer", de.design, lambda r: (r["solver"], f"gamma_1 = {r['performance']['gamma_1']:.4f}")),
        ("li2023-controller", dc.design, lambda r: (r["solver"], f"gamma_2 = {r['performance']['gamma_2']:.4f}")),
        ("zhang2014-hinf", dz.design, lambda r: (r["solver"], "J* = " + ", ".join(
            f"{c['J_star']:.4f}" for c in r["cases"]) + " (3 cases, kappa search)")),
        ("hang2023-tsfdo", dh.design, lambda r: (r["solver"], f"alpha*beta = "
                                                 f"{r['performance']['alpha'] * r['performance']['beta']:.4f} (search)")),
    ]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args(argv)
    warnings.simplefilter("ignore")
    rows = []
    for name, fn, info in _designs():
        times = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            r = fn()
            times.append(time.perf_counter() - t0)
        solver, perf = info(r)
        rows.append((name, statistics.median(times), min(times), max(times), solver, perf))
    print(f"{'design':<20}{'median s':>10}{'min s':>8}{'max s':>8}  {'solver':<10}result")
    for name, med, lo, hi, solver, perf in rows:
        print(f"{name:<20}{med:>10.2f}{lo:>8.2f}{hi:>8.2f}  {solver:<10}{perf}")
    return rows


if __name__ == "__main__":
    main()
