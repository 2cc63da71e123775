"""Independent FMI engines running our SSP packages, for comparison with our master.

* ``libcosim`` (OSP, ``libcosimpy``): :mod:`orchestrator.interop.libcosim`;
* ``ecos`` (``ecospy``, in-process): the package as it is with Ecos's plain ``init()`` (no parameter
  set: the package's configured FMUs start from the scenario's values, orchestrator/scenario/ssp.py);
  ``parameter_set="default"`` applies the SSV files as well (the same values). Ecos forms its
  times by ``t += h``;
* ``container`` (``fmu-manipulation-toolbox``): the package's FMUs wrapped into one container FMU,
  a compiled C master, by a JSON description built from the package (links, start values of the
  parameters, one container output per recorded variable), then driven by fmpy with
  ``start + k*h`` communication times;
* ``omsimulator`` (OpenModelica's OMSimulator, its Python API, in-process): the package as it is,
  the fixed step set explicitly (OMSimulator does not read the OSP annotation). Its clock is
  ``t += h`` and ``stepUntil(T)`` takes whole steps while ``t < T``, so one macro step is
  ``stepUntil(start + (k + 1/2)*h)`` (``stepUntil(start + (k+1)*h)`` takes an extra step
  whenever the accumulated ``t`` falls one ulp short). OMSimulator is not on PyPI offline: point ``OMSIMULATOR_HOME``
  at an installation (the folder holding ``bin/OMSimulator`` and ``lib/*/OMSimulator/``).

Each runs in its own Python process (:func:`run_engine`): the FMUs run Python inside the host,
and a process that already loaded our pythonfmu FMUs through fmpy must not load them again
through another engine. The result is a ``.npz`` with ``time`` (s), ``data`` (rows x columns),
``columns`` and ``wall`` (seconds spent stepping, recording excluded where the engine allows)::

    python -m orchestrator.interop.engines ENGINE PACKAGE.ssp --out result.npz [--steps N] [--no-record]
"""
from __future__ import annotations

import argparse
import ctypes
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from orchestrator.interop.libcosim import npz_from_subprocess, run_libcosim
from orchestrator.scenario.ssp import load_ssp

ENGINES = ("libcosim", "ecos", "container", "omsimulator")


def _preload_tbb() -> None:
    """ecospy's library needs libtbb.so.12, which the ``tbb`` wheel puts in <prefix>/lib (not on
    the loader's path): load it first, globally."""
    for folder in (Path(sys.prefix) / "lib", Path(sys.base_prefix) / "lib"):
        for name in ("libtbb.so.12", "libtbb.so"):
            if (folder / name).is_file():
                ctypes.CDLL(str(folder / name), mode=ctypes.RTLD_GLOBAL)
                return


def run_ecos(ssp_path, record=None, steps=None, recording=True, parameter_set=None):
    """(columns, time, data, wall) of the package in Ecos (in-process), initialised with
    ``init()`` (``parameter_set``: a named SSV set to apply as well)."""
    _preload_tbb()
    from ecospy import EcosSimulation

    scenario = load_ssp(ssp_path)
    record = list(record or scenario.record)
    n = steps if steps is not None else scenario.n_steps
    ids = [f"{i}::{v}" for i, v in record]
    sim = EcosSimulation(step_size=scenario.step, ssp_path=str(Path(ssp_path).resolve()))
    sim.init(scenario.start, parameter_set=parameter_set)
    rows = n + 1 if recording else 1
    data = np.empty((rows, len(ids)))
    times = np.empty(rows)
    get = sim.get_real

    def sample(k):
        times[k] = sim.get_time()
        data[k] = [get(x) for x in ids]

    sample(0)
    wall = 0.0
    if recording:
        for k in range(1, n + 1):
            t0 = time.perf_counter()
            sim.step(1)
            wall += time.perf_counter() - t0
            sample(k)
    else:
        t0 = time.perf_counter()
        sim.step(n)
        wall = time.perf_counter() - t0
    sim.terminate()
    return [f"{i}.{v}" for i, v in record], times, data, wall


def container_description(scenario, name="system.fmu") -> dict:
    """The fmu-manipulation-toolbox JSON description of a package's system: one embedded FMU per
    instance (``<instance>.fmu``), our connections as links, every parameter as a start value,
    every recorded variable k as a container output ``rec<k>`` (the container names its local
    links ``instance.variable`` already)."""
    return {
        "name": name, "step_size": scenario.step,
        "auto_link": False, "auto_input": False, "auto_output": False, "auto_parameter": False, "auto_local": False,
        "fmu": [f"{i}.fmu" for i in scenario.instances],
        "path": {f"{i}.fmu": Path(inst.fmu).name for i, inst in scenario.instances.items()},
        "link": [[f"{s}.fmu", sv, f"{d}.fmu", dv] for s, sv, d, dv in scenario.connections],
        "start": [[f"{i}.fmu", p, repr(float(v))] for i, inst in scenario.instances.items()
                  for p, v in inst.parameters.items()],
        "output": [[f"{i}.fmu", v, f"rec{k}"] for k, (i, v) in enumerate(scenario.record)],
    }


def build_container(scenario, folder: Path) -> Path:
    """Write the description and the embedded FMUs into ``folder`` and build the container FMU."""
    folder = Path(folder)
    for inst in scenario.instances.values():
        shutil.copy2(inst.fmu, folder / Path(inst.fmu).name)
    desc = folder / "system.json"
    desc.write_text(json.dumps(container_description(scenario)))
    tool = Path(sys.executable).with_name("fmucontainer")
    cmd = [str(tool) if tool.exists() else "fmucontainer", "-container", str(desc), "-fmu-directory", str(folder)]
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    fmu = folder / "system.fmu"
    if p.returncode != 0 or not fmu.is_file():
        raise RuntimeError(f"fmucontainer failed ({p.returncode}): {p.stdout[-2000:]} {p.stderr[-2000:]}")
    return fmu


# what the toolbox's container logs at every start, whatever happens, at status Warning or Error:
# its version, "Solver configure...." (an Error status, although nothing failed: the run goes on and
# its results equal ours to 3e-14), its threading mode; not shown, every other message is
CONTAINER_START_LINES = (re.compile(r"FMUContainer '.*'"), re.compile(r"Solver configure\.*"),
                         re.compile(r"Container use \w+ mode with \w+ thread\.?"))


def _container_callbacks():
    """fmpy callbacks whose logger prints the container's messages to stderr as ``[status] message``,
    except its start-up lines (:data:`CONTAINER_START_LINES`)."""
    from fmpy.fmi2 import defaultCallbacks, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE

    names = {0: "OK", 1: "WARNING", 2: "DISCARD", 3: "ERROR", 4: "FATAL", 5: "PENDING"}

    def logger(env, instance, status, category, message):
        text = (message or b"").decode("utf-8", "replace").strip()
        if not any(p.fullmatch(text) for p in CONTAINER_START_LINES):
            print(f"[{names.get(status, status)}] {text}", file=sys.stderr)

    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(logger)
    cb.allocateMemory = defaultCallbacks.allocateMemory
    cb.freeMemory = defaultCallbacks.freeMemory
    try:  # fmpy's C proxy formats the message's printf arguments before our logger sees it
        from ctypes import byref

        from fmpy.logging import addLoggerProxy

        addLoggerProxy(byref(cb))
    except Exception:  # noqa: BLE001 - without it the messages show their format strings
        pass
    _CALLBACKS.append(cb)  # alive as long as the process: the container may log until it unloads
    return cb


_CALLBACKS: list = []


def run_container(ssp_path, record=None, steps=None, recording=True):
    """(columns, time, data, wall) of the package as a toolbox container FMU driven by fmpy."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    scenario = load_ssp(ssp_path)
    record = list(record or scenario.record)
    if record != list(scenario.record):
        scenario.record = record
    n = steps if steps is not None else scenario.n_steps
    work = Path(tempfile.mkdtemp(prefix="ftcsim_container_"))
    try:
        fmu = build_container(scenario, work)
        md = read_model_description(str(fmu))
        vr = {v.name: v.valueReference for v in md.modelVariables}
        names = [f"{i}.{v}" for i, v in record]
        refs = [vr[f"rec{k}"] for k in range(len(record))]
        slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu), str(work / "unzipped")),
                          modelIdentifier=md.coSimulation.modelIdentifier, instanceName="container")
        cb = _container_callbacks()
        slave.instantiate(callbacks=cb)
        slave.setupExperiment(startTime=scenario.start)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        rows = n + 1 if recording else 1
        data = np.empty((rows, len(refs)))
        times = np.empty(rows)
        times[0], data[0] = scenario.start, slave.getReal(refs)
        h = scenario.step
        wall = 0.0
        t0 = time.perf_counter()
        for k in range(n):
            t = scenario.start + k * h
            if recording:
                t1 = time.perf_counter()
                slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
                wall += time.perf_counter() - t1
                times[k + 1], data[k + 1] = scenario.start + (k + 1) * h, slave.getReal(refs)
            else:
                slave.doStep(currentCommunicationPoint=t, communicationStepSize=h)
        if not recording:
            wall = time.perf_counter() - t0
        slave.terminate()
        return names, times, data, wall
    finally:
        shutil.rmtree(work, ignore_errors=True)


def omsimulator_python_path() -> Path | None:
    """The folder holding OMSimulator's Python package under ``$OMSIMULATOR_HOME``, or None."""
    home = os.environ.get("OMSIMULATOR_HOME")
    if not home:
        return None
    found = sorted(Path(home).glob("lib/*/OMSimulator/__init__.py")) + sorted(Path(home).glob("lib/OMSimulator/__init__.py"))
    return found[0].parent.parent if found else None


def run_omsimulator(ssp_path, record=None, steps=None, recording=True):
    """(columns, time, data, wall) of the package in OMSimulator (its Python API, in-process)."""
    folder = omsimulator_python_path()
    if folder is None:
        raise RuntimeError("OMSimulator not found: set OMSIMULATOR_HOME to its installation folder")
    sys.path.insert(0, str(folder))
    from OMSimulator import SSP, Capi, CRef, Settings

    scenario = load_ssp(ssp_path)
    record = list(record or scenario.record)
    n = steps if steps is not None else scenario.n_steps
    Settings.suppressPath = True
    model = SSP(str(Path(ssp_path).resolve())).instantiate()
    model.setResultFile("")
    model.setStartTime(scenario.start)
    model.setStopTime(scenario.start + n * scenario.step)
    model.setFixedStepSize(scenario.step)
    model.initialize()
    # value paths resolved once (InstantiatedModel.getValue looks the type up on every call)
    paths = []
    for instance, var in record:
        mapped = model.mappedCrefs[".".join(CRef(scenario.name, instance, var).names[:-1])]
        paths.append(f"{mapped}.{var}")

    def sample():
        return [Capi.getReal(p)[0] for p in paths]

    rows = n + 1 if recording else 1
    data = np.empty((rows, len(paths)))
    times = np.empty(rows)
    times[0], data[0] = scenario.start, sample()
    wall = 0.0
    t0 = time.perf_counter()
    for k in range(n):
        target = scenario.start + (k + 0.5) * scenario.step  # exactly one step of OMSimulator's t += h
        if recording:
            t1 = time.perf_counter()
            model.stepUntil(target)
            wall += time.perf_counter() - t1
            times[k + 1], data[k + 1] = scenario.start + (k + 1) * scenario.step, sample()
        else:
            model.stepUntil(target)
    if not recording:
        wall = time.perf_counter() - t0
    model.terminate()
    model.delete()
    return [f"{i}.{v}" for i, v in record], times, data, wall


def run_engine(engine: str, ssp_path, out_npz, steps=None, recording=True, timeout=1800) -> dict:
    """One engine on one package, in a fresh Python process; returns the loaded ``.npz``."""
    if engine not in ENGINES:
        raise ValueError(f"unknown engine {engine!r} (known: {', '.join(ENGINES)})")
    return npz_from_subprocess("orchestrator.interop.engines", [engine, str(ssp_path)], out_npz, engine, steps,
                               extra=() if recording else ("--no-record",), timeout=timeout)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m orchestrator.interop.engines", description=__doc__.splitlines()[0])
    ap.add_argument("engine", choices=ENGINES)
    ap.add_argument("ssp")
    ap.add_argument("--out", required=True, help=".npz file to write")
    ap.add_argument("--steps", type=int, help="number of macro steps (default: to the stop time)")
    ap.add_argument("--no-record", action="store_true", help="time the stepping only (benchmarks)")
    args = ap.parse_args(argv)
    if args.engine == "libcosim":
        columns, t, data, wall = run_libcosim(args.ssp, steps=args.steps)
    else:
        run = {"ecos": run_ecos, "container": run_container, "omsimulator": run_omsimulator}[args.engine]
        columns, t, data, wall = run(args.ssp, steps=args.steps, recording=not args.no_record)
    np.savez(args.out, time=t, data=data, columns=np.array(columns), wall=np.array(wall))
    print(json.dumps({"steps": len(t) - 1, "wall": wall}))
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
