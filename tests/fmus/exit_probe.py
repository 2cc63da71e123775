"""A host process that loads, runs, frees and exits with FMUs, the way a user's script does.

    python tests/fmus/exit_probe.py [--keep-library] [--binary LIB] [--import MODULE] [--repeat N] FMU...

Each FMU is extracted, instantiated through fmpy, set up, stepped 5 times by 1 ms, terminated and
freed (``fmi2FreeInstance`` / ``fmi3FreeInstance``, then fmpy unloads the library unless
``--keep-library``); the process then ends with a plain ``sys.exit(0)``: the interpreter's own
teardown and glibc's exit handlers run, which is where pythonfmu's exit-time double release
wrote into freed memory. ``--binary LIB`` replaces every FMU's Linux binary by LIB after
extraction (to compare export libraries on the same FMUs); ``--repeat N`` runs each FMU N times
(a new instance each time, one extraction); ``--import MODULE`` imports a module
first (``scipy.linalg`` puts libgfortran's exit-time frees after the FMUs' library). Used by
tests/fmus/test_host_exit.py and, under valgrind, by hand (docs/external-tools.md)."""
import argparse
import importlib
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

from fmpy import read_model_description


def extract(path: str, work: Path, binary: str | None):
    md = read_model_description(path)
    folder = Path(tempfile.mkdtemp(prefix="probe_", dir=work))
    zipfile.ZipFile(path).extractall(folder)
    if binary:
        for so in folder.glob(f"binaries/*linux*/{md.coSimulation.modelIdentifier}.so"):
            shutil.copyfile(binary, so)
    return md, folder


def run(md, folder: Path, keep_library: bool) -> None:
    ident = md.coSimulation.modelIdentifier
    v3 = md.fmiVersion.startswith("3")
    if v3:
        from fmpy.fmi3 import FMU3Slave as Slave
    else:
        from fmpy.fmi2 import FMU2Slave as Slave
    fmu = Slave(guid=md.guid, unzipDirectory=str(folder), modelIdentifier=ident, instanceName=md.modelName)
    fmu.instantiate(loggingOn=True)
    if v3:
        fmu.enterInitializationMode(startTime=0.0)
    else:
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
    fmu.exitInitializationMode()
    t = 0.0
    for _ in range(5):
        fmu.doStep(t, 0.001)
        t += 0.001
    fmu.terminate()
    if keep_library:  # free the instance, keep the library loaded until the process ends
        fmu.fmi3FreeInstance(fmu.component) if v3 else fmu.fmi2FreeInstance(fmu.component)
    else:
        fmu.freeInstance()  # fmpy also unloads the library (dlclose)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("fmus", nargs="+")
    ap.add_argument("--binary")
    ap.add_argument("--keep-library", action="store_true")
    ap.add_argument("--import", dest="imports", action="append", default=[])
    ap.add_argument("--repeat", type=int, default=1)
    args = ap.parse_args()
    for name in args.imports:
        importlib.import_module(name)
    work = Path(tempfile.mkdtemp(prefix="ftcsim_exit_probe_"))
    try:
        for path in args.fmus:
            md, folder = extract(path, work, args.binary)
            for _ in range(args.repeat):
                run(md, folder, args.keep_library)
        print("ran", len(args.fmus), "FMUs", args.repeat, "times", flush=True)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    sys.exit(0)


if __name__ == "__main__":
    main()
