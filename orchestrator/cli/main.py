"""Command line: ``ftcsim build | validate | scenarios | run | design | verify | report | export-ssp |
campaign | campaign-report | compare | host-env``.

Exit status: 0 success; 1 a run that an FMU stopped (what it recorded is kept, marked
incomplete), a failed post-processing step (results.csv kept), a failed design or check;
2 bad input (scenario, parameters, FMU or SSP files, gains, arguments: one line naming the
file, the key and the problem, nothing written); 130 / 143 a run stopped by SIGINT / SIGTERM
(the rows so far are written, marked incomplete). Nothing prints a traceback unless
``FTCSIM_DEBUG=1``.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

from fmus.build import BuildError, build_all, build_block, default_folder, validate
from fmus.contract import ContractError
from fmus.export_library import ExportLibraryError
from fmus.host_env import HostEnvError, host_environment, shell_lines
from orchestrator import api
from orchestrator.cli import campaign, design, report, ssp
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import Interrupted
from orchestrator.common.outputs import OutputFolder, safe_name
from orchestrator.common.process_exit import finish
from orchestrator.common.watchdog import check_limit
from orchestrator.scenario.fmu_checks import check_fmu, toolbox_problems
from orchestrator.scenario.shipped import DEFAULT_FMU_DIR, catalog, scenario_files
from orchestrator.scenario.toml import describe


def cmd_build(args) -> int:
    try:
        return _build(args)
    except ExportLibraryError as e:
        print(f"ftcsim: build failed: {_one_line(e)}", file=sys.stderr)
        return 1


def _build(args) -> int:
    if args.block:
        return _build_block(args)
    for opt in ("path", "probe_step"):
        if getattr(args, opt):
            raise InputError("command line", f"--{opt.replace('_', '-')}", "only with --block")
    known = catalog()
    names = args.names or list(known)
    unknown = [n for n in names if n not in known]
    if unknown:
        raise InputError("command line", "build", f"unknown FMU {unknown[0]!r} (known: {', '.join(known)})")
    out = Path(args.out) if args.out else default_folder(args.fmi)
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", f"{out} exists and is not a directory")
    status = 0
    for path in build_all(out, [known[n] for n in names], fmi=args.fmi, library=args.export_library):
        problems = validate(path)
        print(f"built {path}" + ("" if not problems else f"  INVALID: {'; '.join(problems)}"))
        status |= bool(problems)
    return status


def _build_block(args) -> int:
    """``ftcsim build --block pkg.module:Class``: contract check, build, fix-up, validation."""
    if args.names:
        raise InputError("command line", "--block", f"give either FMU names ({' '.join(args.names)}) or --block, not both")
    if args.probe_step is not None and not (args.probe_step > 0 and args.probe_step < float("inf")):
        raise InputError("command line", "--probe-step", f"must be a finite number > 0, got {args.probe_step:g}")
    try:
        built = build_block(args.block, out=args.out, fmi=args.fmi, paths=args.path or (), probe_step=args.probe_step,
                            reserved=tuple(catalog()), library=args.export_library)
    except (BuildError, ContractError) as e:
        raise InputError("command line", "--block", str(e)) from None
    for w in built.warnings:
        print(f"warning: {args.block}: {w}")
    problems = check_fmu(built.path)
    toolbox = toolbox_problems(built.path)
    problems += [f"fmu-manipulation-toolbox: {m}" for m in toolbox or []]
    print(f"built {built.path} (model {built.model}, FMI {args.fmi}, embeds {', '.join(built.embedded) or 'no module'} "
          "of the block's own)")
    checks = "fmpy" + (", fmu-manipulation-toolbox" if toolbox is not None else "")
    print(f"  {'INVALID: ' + '; '.join(problems) if problems else 'valid'} ({checks})")
    return int(bool(problems))


def cmd_host_env(args) -> int:
    """``ftcsim host-env``: ``export`` lines to paste before a non-Python host's command."""
    try:
        env = host_environment()
    except HostEnvError as e:
        print(f"ftcsim: error: {_one_line(e)}", file=sys.stderr)
        return 1
    print(json.dumps(env) if args.json else "\n".join(shell_lines(env)))
    return 0


def cmd_validate(args) -> int:
    paths = [Path(p) for p in args.fmus] or sorted(Path(args.dir).glob("*.fmu"))
    if not paths:
        raise InputError("command line", "validate", f"no FMUs given and none in {args.dir}")
    status = 0
    for p in paths:
        if not p.is_file():
            raise InputError(p, "-", "FMU file not found")
        problems = check_fmu(p)
        print(f"{p}: " + ("valid" if not problems else "; ".join(problems)))
        status |= bool(problems)
    return status


def cmd_scenarios(args) -> int:
    for name, path in scenario_files().items():
        paper, description = describe(path)
        print(f"{name:28s} {paper:4s} {description}")
    return 0


def cmd_run(args) -> int:
    """``ftcsim run``: :func:`orchestrator.api.run` with the results written, then a summary printed."""
    if args.step is not None and (not math.isfinite(args.step) or args.step <= 0):
        raise InputError("command line", "--step", f"must be a finite number > 0, got {args.step:g}")
    time_limit = None if args.time_limit is None else (check_limit(args.time_limit) or 0)
    scenario = api.load(args.scenario, mode=args.mode, fmu_dir=args.fmu_dir, step=args.step, gains=args.gains or ())
    out = Path(args.out) if args.out else Path("results") / safe_name(scenario.name, scenario.path)
    r = api.run(scenario, exchange=args.exchange, out=OutputFolder(out, "run", overwrite=args.overwrite),
                progress=not args.quiet, plots=not args.no_plots, signals=True, time_limit=time_limit)
    result, metrics = r.raw, r.metrics
    if not args.quiet:
        print(f"{scenario.name}: {result.steps} steps in {result.wall_time:.2f} s "
              f"(real-time factor {metrics.get('real_time_factor') or 0:.0f}), results in {out}")
        for k in ("final_attitude_error", "final_rate_error", "control_energy", "max_abs_u"):
            if isinstance(metrics.get(k), float):
                print(f"  {k} = {metrics[k]:.6g}")
    if result.interrupted:
        raise Interrupted(f"{result.error}; results so far kept in {out}, marked incomplete",
                          128 + result.interrupted)
    if not result.complete:
        raise SimulationError(f"{result.error}; results up to t = {metrics.get('t_end')} s kept in {out}, "
                              "marked incomplete")
    if r.errors:
        raise SimulationError(f"post-processing failed ({'; '.join(r.errors)}); results.csv kept in {out}")
    return 0


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``ftcsim: error: command line: ...``), exit status 2."""

    def error(self, message):
        print(f"ftcsim: error: command line: {' '.join(message.split())} (see `{self.prog} --help`)", file=sys.stderr)
        sys.exit(2)


def parser() -> argparse.ArgumentParser:
    p = _Parser(prog="ftcsim", description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser)

    b = sub.add_parser("build", help="build the FMUs into a folder and fix their modelDescription")
    b.add_argument("names", nargs="*", help="FMU model names (default: all)")
    b.add_argument("--out", help="output folder (default build/fmus, with --fmi 3 build/fmus/fmi3); with --block the "
                                 "FMU file")
    b.add_argument("--fmi", choices=["2", "3"], default="2", help="FMI version: 2 (pythonfmu) or 3 (pythonfmu3)")
    b.add_argument("--block", metavar="MODULE:CLASS",
                   help="build your own block (a class or factory without arguments keeping plant/block.py's contract) "
                        "into one FMU; --out is then the FMU file (default ./<model_name>.fmu)")
    b.add_argument("--path", action="append", metavar="DIR", help="with --block: folder to import it from (repeatable)")
    b.add_argument("--probe-step", type=float, metavar="S",
                   help="with --block: communication step of the contract probes (default: 0.01, 0.001 or 1e-4 s, "
                        "the first the block accepts)")
    b.add_argument("--export-library", choices=["ftcsim", "stock"], default="ftcsim",
                   help="the FMUs' native library: ftcsim (default: pythonfmu's without its exit-time double release, "
                        "fmus/native/README.md) or stock (the package's own)")
    b.set_defaults(func=cmd_build)

    e = sub.add_parser("host-env", help="print the environment (LD_PRELOAD, PYTHONPATH) a non-Python host needs to run "
                                        "the FMUs (OMSimulator, Ecos's CLI, a C program)")
    e.add_argument("--json", action="store_true", help="one JSON object instead of shell export lines")
    e.set_defaults(func=cmd_host_env)

    v = sub.add_parser("validate", help="check FMUs: fmpy.validate_fmu and whether they can load here")
    v.add_argument("fmus", nargs="*", help="FMU files (default: every FMU in --dir)")
    v.add_argument("--dir", default=str(DEFAULT_FMU_DIR))
    v.set_defaults(func=cmd_validate)

    s = sub.add_parser("scenarios", help="list the shipped scenarios (names usable with `ftcsim run`)")
    s.set_defaults(func=cmd_scenarios)

    r = sub.add_parser("run", help="run a scenario (a shipped name, a .toml file or an .ssp package)")
    r.add_argument("scenario", help="shipped scenario name, scenario file (.toml) or SSP package (.ssp)")
    r.add_argument("--out", help="results folder (default results/<scenario name>)")
    r.add_argument("--overwrite", action="store_true", help="replace a previous ftcsim result in --out")
    r.add_argument("--mode", choices=["fmu", "inprocess"], default="fmu", help="FMUs through fmpy, or the blocks in-process")
    r.add_argument("--exchange", choices=["ordered", "jacobi"], help="override the scenario's exchange scheme")
    r.add_argument("--step", type=float, help="override the communication step [s]")
    r.add_argument("--gains", action="append", help="design file (JSON) overriding FMU parameters; repeatable")
    r.add_argument("--fmu-dir", help="folder of built FMUs (default build/fmus)")
    r.add_argument("--no-plots", action="store_true")
    r.add_argument("--time-limit", type=float, metavar="SECONDS", help="wall-time limit of the run's stepping "
                       "(default: the scenario's [timing] time_limit, else none; 0: none); over it the run stops, "
                       "results kept, exit 1")
    r.add_argument("--quiet", action="store_true")
    r.set_defaults(func=cmd_run)

    for register in _extensions():
        register(sub)
    return p


def _extensions():
    """The other subcommands, one module each: design/verify, report/campaign-report, export-ssp,
    campaign/compare."""
    return [design.register, report.register, ssp.register, campaign.register]


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    try:
        return args.func(args)
    except InputError as e:
        print(f"ftcsim: error: {_one_line(e)}", file=sys.stderr)
        return 2
    except SimulationError as e:
        print(f"ftcsim: run failed: {_one_line(e)}", file=sys.stderr)
        return 1
    except Interrupted as e:
        print(f"ftcsim: stopped: {_one_line(e)}", file=sys.stderr)
        return e.exit_status
    except KeyboardInterrupt:
        print("ftcsim: interrupted", file=sys.stderr)
        return 130
    except Exception as e:  # a bug: one line, the traceback on request
        if os.environ.get("FTCSIM_DEBUG"):
            raise
        print(f"ftcsim: internal error: {type(e).__name__}: {_one_line(e)} (FTCSIM_DEBUG=1 shows the traceback)",
              file=sys.stderr)
        return 1


def _one_line(e) -> str:
    return " ".join(str(e).split())


def entry() -> None:
    """The ``ftcsim`` command: ``main``, then exit without pythonfmu's teardown once an FMU has
    run here (see orchestrator/common/process_exit.py; every file ftcsim writes is closed and published
    by then)."""
    finish(main())


if __name__ == "__main__":  # pragma: no cover
    entry()
