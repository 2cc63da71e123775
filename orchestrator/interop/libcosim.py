"""Run an SSP package in libcosim (Open Simulation Platform, ``pip install libcosimpy``).

libcosim is an independent FMI engine: it reads the package's ``SystemStructure.ssd``
(step from the OSP ``FixedStepAlgorithm`` annotation), loads the FMUs with FMI Library,
applies the SSV parameter sets and steps with its fixed-step (Jacobi) algorithm. We
record with a time-series observer: sample 0 is taken after initialisation (t0), sample
k after step k, the same points as our master's rows. A component with a step-size hint
(multirate: decimation factor m) is observed only after its own steps (every m base steps);
between them its values hold, and so does our row there (sampled data), so its samples are
held over the base steps in between.

Run it in its own process (``run_libcosim_subprocess``): the FMUs run Python inside the
host, and a process that already loaded the same pythonfmu FMUs through fmpy must not
load them again through another engine. Command line::

    python -m orchestrator.interop.libcosim PACKAGE.ssp --out result.npz [--steps N]

The ``.npz`` holds ``time`` (s), ``data`` (rows x columns), ``columns`` and ``wall``
(seconds spent in libcosim's stepping, for the benchmark).
"""
from __future__ import annotations

import argparse
import ctypes
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from orchestrator.scenario.ssp import load_ssp


def run_libcosim(ssp_path, record=None, steps=None, log_level="WARNING"):
    """Run ``ssp_path`` in libcosim in this process. ``record``: [(instance, variable)]
    (default: the package's record list, from its ftcsim annotation, else all outputs);
    ``steps``: number of macro steps (default: the DefaultExperiment's stop time).
    Returns ``(columns, time, data, wall_seconds)``."""
    from libcosimpy._internal import get_last_error_message, libcosimc
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver

    scenario = load_ssp(ssp_path)  # the record list, the times; validates the package
    record = list(record or scenario.record)
    n = steps if steps is not None else scenario.n_steps
    log_output_level(getattr(CosimLogLevel, log_level))
    ex = CosimExecution.from_ssp_file(str(Path(ssp_path).resolve()))
    refs = {}
    for info in ex.slave_infos():
        idx = info.index
        refs[info.name.decode()] = (idx, {v.name.decode(): v.reference for v in ex.slave_variables(idx)})
    obs = CosimObserver.create_time_series(buffer_size=n + 1)
    ex.add_observer(obs)
    targets = []
    for inst, var in record:
        idx, names = refs[inst]
        vr = names[var]
        if not obs.start_time_series(idx, vr, CosimVariableType.REAL):
            raise RuntimeError(f"libcosim: cannot observe {inst}.{var}: {get_last_error_message()}")
        targets.append((idx, vr))
    t0 = time.perf_counter()
    if not ex.step(n):
        raise RuntimeError(f"libcosim: step failed: {get_last_error_message()}")
    wall = time.perf_counter() - t0

    get = libcosimc().cosim_observer_slave_get_real_samples
    m = n + 1
    values = (ctypes.c_double * m)()
    step_numbers = (ctypes.c_int64 * m)()
    times = (ctypes.c_int64 * m)()
    get.argtypes = [ctypes.c_void_p, ctypes.c_int, ctypes.c_uint32, ctypes.c_int64, ctypes.c_size_t,
                    ctypes.c_double * m, ctypes.c_int64 * m, ctypes.c_int64 * m]
    get.restype = ctypes.c_int64
    obs_ptr = ctypes.cast(obs.ptr(), ctypes.c_void_p)
    data = np.empty((m, len(record)))
    t_ns = None
    for j, (idx, vr) in enumerate(targets):
        got = get(obs_ptr, idx, vr, 0, m, values, step_numbers, times)
        steps_seen = np.frombuffer(step_numbers, dtype=np.int64)[:got].copy()
        if got < 1 or steps_seen[0] != 0 or np.any(np.diff(steps_seen) <= 0) or steps_seen[-1] >= m:
            raise RuntimeError(f"libcosim: {got} samples of {record[j][0]}.{record[j][1]} at steps "
                               f"{steps_seen[:5].tolist()}...: expected steps 0..{m - 1} from step 0")
        # hold each sample until the next one (a decimated component is observed at its own steps)
        held = np.searchsorted(steps_seen, np.arange(m), side="right") - 1
        data[:, j] = np.frombuffer(values, dtype=np.float64)[:got][held]
        if got == m and t_ns is None:
            t_ns = np.frombuffer(times, dtype=np.int64).copy()
    if t_ns is None:  # every recorded component is decimated: the base grid from the package
        t_ns = np.round(scenario.start * 1e9) + np.round(scenario.step * 1e9) * np.arange(m, dtype=np.int64)
        t_ns = t_ns.astype(np.int64)
    columns = [f"{i}.{v}" for i, v in record]
    return columns, t_ns / 1e9, data, wall


def run_libcosim_subprocess(ssp_path, out_npz, steps=None, timeout=600):
    """``run_libcosim`` in a fresh Python process; returns the loaded ``.npz`` as a dict."""
    return npz_from_subprocess("orchestrator.interop.libcosim", [str(ssp_path)], out_npz, "libcosim", steps, timeout=timeout)


def npz_from_subprocess(module: str, args, out_npz, what: str, steps=None, extra=(), timeout=600) -> dict:
    """Run ``python -m module *args --out out_npz [--steps N] *extra`` with this project first on
    the path and return the ``.npz`` it wrote as a dict; ``RuntimeError`` with its output if it fails."""
    cmd = [sys.executable, "-m", module, *args, "--out", str(out_npz)]
    if steps is not None:
        cmd += ["--steps", str(int(steps))]
    cmd += list(extra)
    root = Path(__file__).resolve().parents[2]  # the project
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]))
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    if p.returncode != 0:
        raise RuntimeError(f"{what} run failed ({p.returncode}):\n{p.stdout[-2000:]}\n{p.stderr[-4000:]}")
    with np.load(out_npz, allow_pickle=False) as z:
        return {k: z[k] for k in z.files}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m orchestrator.interop.libcosim", description=__doc__.splitlines()[0])
    ap.add_argument("ssp")
    ap.add_argument("--out", required=True, help=".npz file to write")
    ap.add_argument("--steps", type=int, help="number of macro steps (default: to the stop time)")
    args = ap.parse_args(argv)
    columns, t, data, wall = run_libcosim(args.ssp, steps=args.steps)
    np.savez(args.out, time=t, data=data, columns=np.array(columns), wall=np.array(wall))
    print(json.dumps({"steps": len(t) - 1, "wall": wall}))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
