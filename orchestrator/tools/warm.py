"""Compile and cache the blocks' numba kernels ahead of use (``python -m orchestrator.tools.warm``).

The kernels (plant/kernels) compile on first call and are cached in the user's cache folder
(``plant.kernels.cache_root()``); a cold cache costs about 20 s of CPU per paper's loop on first
use. This runs each paper's demo scenarios (``Paper.demo`` in the registry) in-process for a few
steps, which calls every kernel with the types a run uses, so later runs, FMUs in other processes
and pytest workers find them compiled. `make test` runs it in two halves beside the FMU builds."""
from __future__ import annotations

import argparse
import sys
import time

from orchestrator.api import load, run
from orchestrator.scenario.shipped import papers
from plant import kernels


def warm_detectors() -> float:
    """Compile the change detectors' kernels (diagnosis/kernels/detectors.py) with the types a run
    uses: a few samples through each detector. Seconds taken."""
    import numpy as np

    from diagnosis.detectors import Chi2Detector, CusumDetector, GlrDetector

    t = time.perf_counter()
    for cls in (CusumDetector, GlrDetector, Chi2Detector):
        b = cls(3)
        b.initialize(0.0)
        b.process(np.zeros((3, 3)), np.arange(3) * 0.01, np.zeros(3))
    return time.perf_counter() - t


def warm(steps: int = 5, part: int = 0, parts: int = 1) -> list[tuple[str, float]]:
    """Run the demo scenarios in-process for ``steps`` steps; (name, seconds) per scenario.
    ``part`` of ``parts``: only every parts-th paper from the part-th (to warm in parallel); the
    first part also compiles the change detectors' kernels."""
    done = [("diagnosis detectors", warm_detectors())] if part == 0 else []
    for paper in papers()[part::parts]:
        for name in paper.demo:
            t = time.perf_counter()
            sc = load(name, mode="inprocess")
            run(sc, stop=sc.start + steps * sc.step)
            done.append((name, time.perf_counter() - t))
    if part == 0:
        done += warm_wheel_momentum()
    return done


def warm_wheel_momentum() -> list[tuple[str, float]]:
    """The plants' kernels with the wheel momenta as states (``wheel_momentum`` = 1, no demo scenario
    uses them), and Basilisk's bytecode when the optional extra is installed (its first import
    compiles about 10 s of Python; the cross-checks of tests/orchestrator/test_basilisk_*.py import it)."""
    import importlib.util

    import numpy as np

    from plant.flexible import FlexibleSpacecraft
    from plant.rigid_wheels import RigidSpacecraftWheels

    t = time.perf_counter()
    for block, u in ((RigidSpacecraftWheels(4), np.zeros(4)), (FlexibleSpacecraft(4), np.zeros(3))):
        block.set_parameter("wheel_momentum", 1.0)
        block.initialize(0.0)
        block.advance(0.0, 0.01, u)
        block.outputs_at(0.01, u)
    done = [("wheel momentum kernels", time.perf_counter() - t)]
    if importlib.util.find_spec("Basilisk") is not None:
        t = time.perf_counter()
        for m in ("Basilisk.architecture.messaging", "Basilisk.simulation.spacecraft",
                  "Basilisk.simulation.reactionWheelStateEffector", "Basilisk.simulation.hingedRigidBodyStateEffector",
                  "Basilisk.simulation.imuSensor", "Basilisk.simulation.starTracker", "Basilisk.utilities.SimulationBaseClass",
                  "Basilisk.utilities.simIncludeRW"):
            importlib.import_module(m)
        done.append(("Basilisk bytecode", time.perf_counter() - t))
    return done


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m orchestrator.tools.warm", description=__doc__.splitlines()[0])
    ap.add_argument("--part", default="1/1", help="K/N: the K-th of N interleaved shares of the papers")
    args = ap.parse_args(argv)
    try:
        k, n = (int(x) for x in args.part.split("/"))
        if not 1 <= k <= n:
            raise ValueError
    except ValueError:
        print(f"ftcsim: error: command line: --part: expected K/N with 1 <= K <= N, got {args.part!r}", file=sys.stderr)
        return 2

    if not kernels.enabled():
        print("kernels are off (FTCSIM_KERNELS=0 or numba missing): nothing to compile")
        return 0
    t = time.perf_counter()
    done = warm(part=k - 1, parts=n)
    print(f"kernels compiled and cached in {kernels.cache_root()}: {len(done)} scenarios, "
          f"{time.perf_counter() - t:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
