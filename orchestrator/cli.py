"""Command line: ``ftcsim build | validate | run | ...``.

Bad input (scenario, parameters, FMU files, arguments) prints one message naming the
file, the key and the problem, exits with status 2 and writes nothing. A run that an FMU
stops keeps what it recorded, marked incomplete, and exits with status 1.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from .errors import InputError, SimulationError

ROOT = Path(__file__).resolve().parent.parent


def cmd_build(args) -> int:
    from fmus.build import build_all, validate
    from fmus.catalog import CATALOG

    names = args.names or list(CATALOG)
    unknown = [n for n in names if n not in CATALOG]
    if unknown:
        raise InputError("command line", "build", f"unknown FMU {unknown[0]!r} (known: {', '.join(CATALOG)})")
    out = Path(args.out) if args.out else ROOT / "build" / "fmus"
    if args.fmi == "3":  # FMI 3.0 with pythonfmu3 (fmus/build_fmi3.py), default build/fmus/fmi3
        from fmus.build_fmi3 import build_all3 as build_all

        out = Path(args.out) if args.out else ROOT / "build" / "fmus" / "fmi3"
    status = 0
    for path in build_all(out, names):
        problems = validate(path)
        print(f"built {path}" + ("" if not problems else f"  INVALID: {'; '.join(problems)}"))
        status |= bool(problems)
    return status


def cmd_validate(args) -> int:
    from fmus.build import validate

    paths = [Path(p) for p in args.fmus] or sorted(Path(args.dir).glob("*.fmu"))
    if not paths:
        raise InputError("command line", "validate", f"no FMUs given and none in {args.dir}")
    status = 0
    for p in paths:
        if not p.is_file():
            raise InputError(p, "-", "FMU file not found")
        problems = validate(p)
        print(f"{p}: " + ("valid" if not problems else "; ".join(problems)))
        status |= bool(problems)
    return status


def cmd_run(args) -> int:
    from .results import write_results
    from .runner import run_scenario
    from .scenario import apply_gains, load

    out = Path(args.out) if args.out else None
    if out is not None and out.exists() and not out.is_dir():
        raise InputError("command line", "--out", f"{out} exists and is not a directory")
    if args.step is not None and not args.step > 0:
        raise InputError("command line", "--step", f"must be > 0, got {args.step:g}")
    if str(args.scenario).endswith(".ssp"):  # an SSP package (orchestrator/ssp.py)
        from .ssp import load_ssp

        scenario = load_ssp(args.scenario, in_process=(args.mode == "inprocess"), step=args.step)
    else:
        scenario = load(args.scenario, fmu_dir=args.fmu_dir, in_process=(args.mode == "inprocess"), step=args.step)
    for g in args.gains or []:
        apply_gains(scenario, g)
    out = out or ROOT / "results" / scenario.name
    result = run_scenario(scenario, mode=args.mode, exchange=args.exchange, progress=not args.quiet)
    metrics = write_results(out, result, scenario, plots=not args.no_plots)
    if not args.quiet:
        print(f"{scenario.name}: {result.steps} steps in {result.wall_time:.2f} s "
              f"(real-time factor {metrics.get('real_time_factor') or 0:.0f}), results in {out}")
        for k in ("final_attitude_error", "final_rate_error", "control_energy", "max_abs_u"):
            if k in metrics:
                print(f"  {k} = {metrics[k]:.6g}")
    if not result.complete:
        raise SimulationError(f"{result.error}; results up to t = {metrics.get('t_end')} s kept in {out}, marked incomplete")
    return 0


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="ftcsim", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)

    b = sub.add_parser("build", help="build the FMUs into a folder and fix their modelDescription")
    b.add_argument("names", nargs="*", help="FMU model names (default: all)")
    b.add_argument("--out", help="output folder (default build/fmus, with --fmi 3 build/fmus/fmi3)")
    b.add_argument("--fmi", choices=["2", "3"], default="2", help="FMI version: 2 (pythonfmu) or 3 (pythonfmu3)")
    b.set_defaults(func=cmd_build)

    v = sub.add_parser("validate", help="run fmpy.validate_fmu on FMUs")
    v.add_argument("fmus", nargs="*", help="FMU files (default: every FMU in --dir)")
    v.add_argument("--dir", default=str(ROOT / "build" / "fmus"))
    v.set_defaults(func=cmd_validate)

    r = sub.add_parser("run", help="run a scenario")
    r.add_argument("scenario", help="scenario file (.toml) or SSP package (.ssp)")
    r.add_argument("--out", help="results folder (default results/<scenario name>)")
    r.add_argument("--mode", choices=["fmu", "inprocess"], default="fmu", help="FMUs through fmpy, or the blocks in-process")
    r.add_argument("--exchange", choices=["ordered", "jacobi"], help="override the scenario's exchange scheme")
    r.add_argument("--step", type=float, help="override the communication step [s]")
    r.add_argument("--gains", action="append", help="design file (JSON) overriding FMU parameters; repeatable")
    r.add_argument("--fmu-dir", help="folder of built FMUs (default build/fmus)")
    r.add_argument("--no-plots", action="store_true")
    r.add_argument("--quiet", action="store_true")
    r.set_defaults(func=cmd_run)

    for register in _extensions():
        register(sub)
    return p


def _extensions():
    """Subcommands contributed by other modules (design/verify, report, ...), if present."""
    regs = []
    for mod in ("orchestrator.design_commands", "orchestrator.report", "orchestrator.ssp"):
        try:
            m = __import__(mod, fromlist=["register"])
        except ModuleNotFoundError as e:
            if e.name == mod:
                continue
            raise
        regs.append(m.register)
    return regs


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except InputError as e:
        print(f"ftcsim: error: {e}", file=sys.stderr)
        return 2
    except SimulationError as e:
        print(f"ftcsim: run failed: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
