"""Compile and cache the blocks' numba kernels ahead of use (``python -m orchestrator.warm``).

The kernels (plant/kernels) compile on first call and are cached in the user's cache folder
(``plant.kernels.cache_root()``); a cold cache costs about 20 s of CPU per paper's loop on first
use. This runs each paper's demo scenarios (``Paper.demo`` in the registry) in-process for a few
steps, which calls every kernel with the types a run uses, so later runs, FMUs in other processes
and pytest workers find them compiled. `make test` runs it beside the FMU builds."""
from __future__ import annotations

import sys
import time


def warm(steps: int = 5) -> list[tuple[str, float]]:
    """Run every demo scenario in-process for ``steps`` steps; (name, seconds) per scenario."""
    from papers.registry import papers

    from .api import load, run

    done = []
    for paper in papers():
        for name in paper.demo:
            t = time.perf_counter()
            sc = load(name, mode="inprocess")
            run(name, mode="inprocess", stop=sc.start + steps * sc.step)
            done.append((name, time.perf_counter() - t))
    return done


def main(argv=None) -> int:
    from plant import kernels

    if not kernels.enabled():
        print("kernels are off (FTCSIM_KERNELS=0 or numba missing): nothing to compile")
        return 0
    t = time.perf_counter()
    done = warm()
    print(f"kernels compiled and cached in {kernels.cache_root()}: {len(done)} scenarios, "
          f"{time.perf_counter() - t:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
