"""Command line: ``ftcsim build | validate | scenarios | run | design | verify | report | export-ssp |
campaign | campaign-report | compare | host-env | params | arena | fdir calibrate | completion``.

Exit status: 0 success; 1 a run that an FMU stopped (what it recorded is kept, marked
incomplete), a failed post-processing step (results.csv kept), a failed design or check;
2 bad input (scenario, parameters, FMU or SSP files, gains, arguments: one line naming the
file, the key and the problem, nothing written); 130 / 143 a run stopped by SIGINT / SIGTERM
(the rows so far are written, marked incomplete); 141 (128 + SIGPIPE) when the reader of the
output went away (``ftcsim scenarios | head``: nothing more is printed, no error). Nothing prints
a traceback unless ``FTCSIM_DEBUG=1``.

Messages go through :mod:`logging` (the library logs to ``ftcsim.*`` loggers, the command line
configures the handlers): ``-v`` shows debug lines, ``-q`` only warnings and errors, ``--log-file
FILE`` appends every line with its time to FILE.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import math
import os
import signal
import stat
import subprocess
import sys
import tempfile
import time
import zipfile
from importlib.metadata import PackageNotFoundError
from importlib.metadata import version as package_version
from pathlib import Path

from fmus.build import BuildError, build_all, build_block, default_folder, validate
from fmus.contract import ContractError
from fmus.export_library import ExportLibraryError
from fmus.host_env import HostEnvError, host_environment, shell_lines
from orchestrator import api
from orchestrator.cli import _interrupted_while_starting, arena, campaign, design, fdir, params, report, schema, ssp
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import Interrupted
from orchestrator.common.outputs import OutputFile, OutputFolder, check_target, safe_name
from orchestrator.common.process_exit import finish
from orchestrator.common.reading import check_regular, kind_of
from orchestrator.common.watchdog import check_limit
from orchestrator.scenario.fmu_checks import check_fmu, toolbox_problems
from orchestrator.scenario.loading import load_scenario
from orchestrator.scenario.shipped import DEFAULT_FMU_DIR, catalog, scenario_files
from orchestrator.scenario.toml import describe
from orchestrator.scenario.values import closest, number
from plant.units import ucum

log = logging.getLogger("ftcsim.cli")
MAX_PROBE_STEP = 3600.0  # s: a contract probe step longer than an hour probes nothing


def cmd_build(args) -> int:
    try:
        return _build(args)
    except ExportLibraryError as e:
        print(f"ftcsim: build failed: {_one_line(e)}", file=sys.stderr)
        return 1


def _build(args) -> int:
    if args.block is not None:
        return _build_block(args)
    for opt in ("path", "probe_step"):
        if getattr(args, opt):
            raise InputError("command line", f"--{opt.replace('_', '-')}", "only with --block")
    known = catalog()
    names = args.names or [n for n in known if known[n].available()]
    unknown = [n for n in names if n not in known]
    if unknown:
        raise InputError("command line", "build", f"unknown FMU {unknown[0]!r} (known: {', '.join(known)})")
    missing = [n for n in names if not known[n].available()]
    if missing:
        raise InputError("command line", "build", f"{missing[0]} needs the optional module {known[missing[0]].requires} "
                                                  "(pip install 'ftcsim[basilisk]')")
    for n, spec in known.items():
        if not args.names and not spec.available():
            print(f"skipped {n}: needs the optional module {spec.requires} (pip install 'ftcsim[basilisk]')")
    out = Path(args.out) if args.out else default_folder(args.fmi)
    if out.exists() and not out.is_dir():
        raise InputError("command line", "--out", f"{out} exists and is not a directory")
    for n in names:  # every target checked before anything is built
        _check_fmu_target(out / f"{n}.fmu")
    status = 0
    quiet = getattr(args, "log_quiet", False)
    built = 0
    for path in build_all(out, [known[n] for n in names], fmi=args.fmi, library=args.export_library):
        problems = validate(path)
        built += 1
        if problems or not quiet:  # -q: only the invalid ones, then the count
            print(f"built {path}" + ("" if not problems else f"  INVALID: {'; '.join(problems)}"))
        status |= bool(problems)
    if quiet:
        print(f"built {built} FMUs (FMI {args.fmi}) into {out}")
    return status


def _build_block(args) -> int:
    """``ftcsim build --block pkg.module:Class``: contract check, build, fix-up, validation."""
    if args.names:
        raise InputError("command line", "--block", f"give either FMU names ({' '.join(args.names)}) or --block, not both")
    if not args.block.strip() or ":" not in args.block:
        raise InputError("command line", "--block", f"expected MODULE:CLASS (e.g. mypkg.blocks:MyController), got "
                                                    f"{args.block!r}")
    if args.probe_step is not None:
        number("command line", "--probe-step", args.probe_step, positive=True, upper=MAX_PROBE_STEP)
    _check_block_sources(args.block, args.path or ())
    out = Path(args.out) if args.out else Path.cwd()
    target = None
    if out.suffix == ".fmu":
        target = _fmu_target(out).check()  # checked and locked before the build
        folder = out.parent
    else:
        if out.exists() and not out.is_dir():
            raise InputError("command line", "--out", f"{out} exists and is neither a folder nor an .fmu file")
        check_target(out)  # a folder that can be created or written
        folder = out
    bytecode = sys.dont_write_bytecode
    sys.dont_write_bytecode = True  # importing the user's module writes no __pycache__ into their folder
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(prefix=".ftcsim-build-", dir=folder) as staging:
            # built beside the target, moved into place once the target is known to be free or ftcsim's
            try:
                built = build_block(args.block, out=Path(staging) / (out.name if out.suffix == ".fmu" else ""),
                                    fmi=args.fmi, paths=args.path or (), probe_step=args.probe_step,
                                    reserved=tuple(catalog()), library=args.export_library)
            except (BuildError, ContractError) as e:
                raise InputError("command line", "--block", str(e)) from None
            if target is None:
                target = _fmu_target(out / built.path.name).check()
            target.write(lambda tmp: os.replace(built.path, tmp))
            built = dataclasses.replace(built, path=target.path)
    except OSError as e:  # a full disk while the FMU is built beside its target: one line, nothing published
        raise InputError("command line", "--out", f"cannot write {out}: {e.strerror or e}; nothing published") from None
    finally:
        sys.dont_write_bytecode = bytecode
        if target is not None:
            target.release()
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


def _check_block_sources(ref: str, paths) -> None:
    """The files that importing ``ref``'s module would open (in ``--path`` folders and the current
    one), through the one reader's check: a FIFO or a device there would block or never end the import."""
    parts = ref.partition(":")[0].split(".")
    for folder in [*paths, "."]:
        for k in range(1, len(parts) + 1):
            base = Path(folder, *parts[:k])
            for candidate in (base.with_suffix(".py"), base / "__init__.py"):
                if os.path.lexists(candidate):
                    check_regular(candidate, "Python module", "command line", "--block")


def _built_by_ftcsim(path: Path) -> bool:
    """True for an FMU that ftcsim built (``resources/ftcsim_build.json`` inside)."""
    try:
        with zipfile.ZipFile(path) as z:
            return "resources/ftcsim_build.json" in z.namelist()
    except (OSError, zipfile.BadZipFile, ValueError):
        return False


def _fmu_target(path: Path) -> OutputFile:
    """The one publisher for an FMU: it may replace an FMU that ftcsim built, and nothing else (any
    other existing file or folder at ``path`` is refused, untouched)."""
    return OutputFile(path, "an FMU", _built_by_ftcsim, overwrite=True, suffix=".fmu", foreign="is not an FMU ftcsim built")


def _check_fmu_target(path: Path) -> None:
    """Refuse, before a build, a target FMU path that cannot be written or is not ftcsim's to replace."""
    _fmu_target(path).check().release()


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
        if not os.path.lexists(p):
            raise InputError(p, "-", "FMU file not found")
        check_regular(p, "FMU file")  # a FIFO or a device is refused before anything opens it
        problems = check_fmu(p)
        print(f"{p}: " + ("valid" if not problems else "; ".join(problems)))
        status |= bool(problems)
    return status


def cmd_scenarios(args) -> int:
    """One line per shipped scenario: name, source (the paper's id, or "arena"), description; the
    columns as wide as the longest name and source (no header: ``cut``, ``awk`` and ``head`` see names).
    Each line is printed as soon as its file is read (``| head`` stops the reading)."""
    files = scenario_files()
    width = max(len(n) for n in files)
    src = max(len(api.scenario_source(p, "000")) for p in files.values())
    for name, path in files.items():
        paper, description = describe(path)
        print(f"{name:{width}s}  {api.scenario_source(path, paper):{src}s}  {description}")
    return 0


def cmd_run(args) -> int:
    """``ftcsim run``: :func:`orchestrator.api.run` with the results written, then a summary printed."""
    scenario = load_scenario(args.scenario, mode=args.mode, fmu_dir=args.fmu_dir, gains=args.gains or (),
                             src="command line", option="--set", **run_overrides(args))
    time_limit = None if args.time_limit is None else (check_limit(args.time_limit) or 0)
    out = Path(args.out) if args.out else Path("results") / safe_name(scenario.name, scenario.path)
    record_step = _record_step(args.record_step, scenario)
    if record_step is None and args.step is not None:  # a refined --step records on the file's own step
        record_step = api.default_record_step(scenario, api.load(args.scenario, mode=args.mode, fmu_dir=args.fmu_dir))
    r = api.run(scenario, exchange=args.exchange, out=OutputFolder(out, "run", overwrite=args.overwrite),
                progress=not args.quiet, plots=not args.no_plots, signals=True, record_step=record_step,
                format=args.format, time_limit=time_limit)
    result, metrics = r.raw, r.metrics
    if not args.quiet:
        print(f"{scenario.name}: {result.steps} steps in {result.wall_time:.2f} s "
              f"(real-time factor {r.info.get('real_time_factor') or 0:.0f}), results in {out}")
        for k in TERMINAL_METRICS:
            if isinstance(metrics.get(k), float):
                print(metric_line(k, metrics[k], r.metric_units.get(k)))
    if result.interrupted:
        raise Interrupted(f"{result.error}; results so far kept in {out}, marked incomplete",
                          128 + result.interrupted)
    if not result.complete:
        raise SimulationError(f"{result.error}; results up to t = {r.info.get('t_end')} s kept in {out}, "
                              "marked incomplete")
    if r.errors:
        raise SimulationError(f"post-processing failed ({'; '.join(r.errors)}); results kept in {out}")
    return 0


# the metrics `ftcsim run` prints (all of them are in metrics.json)
TERMINAL_METRICS = ("final_attitude_error", "final_rate_error", "control_energy", "max_abs_u")


def metric_line(name: str, value: float, unit: str | None) -> str:
    """``  final_attitude_error = 0.000189768 rad``: a metric on the terminal, with its unit in the
    file spelling (metrics.json's, :func:`plant.units.ucum`; none for a dimensionless one)."""
    u = ucum(unit) if unit else None
    return f"  {name} = {value:.6g}" + (f" {u}" if u and u != "1" else "")


def _record_step(value, scenario):
    """``--record-step`` checked like the API's ``record_step``, named as the option."""
    try:
        return api.check_record_step(value, scenario)
    except InputError as e:
        raise InputError("command line", "--record-step", e.problem) from None


def run_overrides(args) -> dict:
    """``--start/--stop/--step`` (s) and ``--set INSTANCE.PARAM=VALUE`` as the keywords of
    :func:`orchestrator.scenario.loading.load_scenario` (and :func:`orchestrator.api.load`)."""
    for opt in ("start", "stop", "step"):
        x = getattr(args, opt, None)
        if x is not None and (not math.isfinite(x) or (opt != "start" and x <= 0)):
            raise InputError("command line", f"--{opt}", f"must be a finite number{' > 0' if opt != 'start' else ''} "
                                                         f"(s), got {x:g}")
    return {"start": args.start, "stop": args.stop, "step": args.step, "parameters": params.set_options(args.set)}


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (``ftcsim: error: command line: ...``), exit status 2."""

    def error(self, message):
        message = " ".join(message.split())
        if message.startswith("argument ") and "invalid choice: " in message:  # a command or a choice misspelt
            given = message.split("invalid choice: ", 1)[1].split(" (choose", 1)[0].strip("'")
            choices = [c for a in self._actions if a.choices for c in a.choices]
            close = closest(given, choices)
            message += f" (did you mean {close!r}?)" if close else ""
        print(f"ftcsim: error: command line: {message} (see `{self.prog} --help`)", file=sys.stderr)
        sys.exit(2)


def parser() -> argparse.ArgumentParser:
    p = _Parser(prog="ftcsim", description="Spacecraft fault estimation and fault-tolerant control as FMI "
                "co-simulation components: build the FMUs, run scenarios and campaigns, design and verify gains, "
                "write reports.", epilog=EPILOG, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--version", action=_VersionAction, help="print the versions of ftcsim, fmpy, pythonfmu, pythonfmu3, "
                   "numpy, Python and the git commit of a source checkout, and exit")
    _global_options(p, top=True)
    sub = p.add_subparsers(dest="command", required=True, parser_class=_Parser, metavar="COMMAND",
                           title="commands (`ftcsim COMMAND --help` for each)")

    b = sub.add_parser("build", help="build the FMUs into a folder and fix their modelDescription")
    b.add_argument("names", nargs="*", help="FMU model names (default: all)")
    b.add_argument("--out", help="output folder (default build/fmus, with --fmi 3 build/fmus/fmi3); with --block the "
                                 "FMU file or its folder. An existing FMU is replaced only if ftcsim built it; any "
                                 "other file is refused")
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
    r.add_argument("-o", "--out", help="results folder (default results/<scenario name>)")
    r.add_argument("--overwrite", action="store_true", help="replace a previous ftcsim result in --out")
    r.add_argument("--mode", choices=["fmu", "inprocess"], default="fmu", help="FMUs through fmpy, or the blocks in-process")
    r.add_argument("--exchange", choices=["ordered", "jacobi"], help="override the scenario's exchange scheme")
    r.add_argument("--start", type=float, metavar="S", help="override the start time, s")
    r.add_argument("--stop", type=float, metavar="S", help="override the stop time, s")
    r.add_argument("--step", type=float, metavar="S", help="override the communication step, s")
    r.add_argument("--set", action="append", metavar="INSTANCE.PARAM=VALUE",
                   help="override a parameter; VALUE is a TOML number or array (0.5, [1, 0, 0], [[1, 0], [0, 1]]); "
                        "repeatable; `ftcsim params SCENARIO` lists the names")
    r.add_argument("--gains", action="append", help="design file (JSON) overriding FMU parameters; repeatable")
    r.add_argument("--fmu-dir", help="folder of built FMUs (default build/fmus)")
    r.add_argument("--record-step", type=float, metavar="S",
                   help="write one row every S seconds (a whole multiple of the step; the last row is always kept; "
                        "the metrics come from every step); default: every step of the scenario's own step, also when "
                        "--step refines it")
    r.add_argument("--format", choices=["parquet", "csv"], default="parquet",
                   help="results.parquet (default; units in the field metadata) or results.csv (units in "
                        "results.units.csv)")
    r.add_argument("--no-plots", action="store_true", help="write no plot")
    r.add_argument("-q", "--quiet", action="store_true", help="print nothing but warnings and errors")
    r.add_argument("--time-limit", type=float, metavar="SECONDS", help="wall-time limit of the run's stepping "
                       "(default: the scenario's [timing] time_limit, else none; 0: none); over it the run stops, "
                       "results kept, exit 1")
    r.set_defaults(func=cmd_run)

    for register in _extensions():
        register(sub)
    c = sub.add_parser("completion", help="print the shell completion script of ftcsim (bash, zsh or tcsh): "
                       "commands, options, choices, shipped scenario names and files", epilog=COMPLETION_EPILOG,
                       formatter_class=argparse.RawDescriptionHelpFormatter)
    c.add_argument("shell", choices=["bash", "zsh", "tcsh"], help="the shell the script is for")
    c.set_defaults(func=lambda args: cmd_completion(args, p))
    for command in sub.choices.values():
        _global_options(command, top=False)
        for action in command._actions:  # a command's own actions (``fdir calibrate``) take them too
            if isinstance(action, argparse._SubParsersAction):
                for nested in action.choices.values():
                    _global_options(nested, top=False)
    _scenario_completion(p)
    return p


COMPLETION_EPILOG = """activation (once; open a new shell afterwards):
  bash: ftcsim completion bash > ~/.local/share/bash-completion/completions/ftcsim
  zsh:  ftcsim completion zsh > ~/.zfunc/_ftcsim   (with fpath+=(~/.zfunc) before compinit in ~/.zshrc)
  tcsh: ftcsim completion tcsh > ~/.ftcsim.completion.csh; echo 'source ~/.ftcsim.completion.csh' >> ~/.tcshrc
or for this shell only: eval "$(ftcsim completion bash)". The script lists the shipped scenarios
of this installation: write it again after an update."""

SCENARIO_ARGS = {"run": "scenario", "params": "scenario", "export-ssp": "scenario"}


def _scenario_completion(p) -> None:
    """``ftcsim run <TAB>`` (and params, export-ssp) completes shipped scenario names, .toml and .ssp files
    (shtab ``complete`` attributes, read only by :func:`cmd_completion`)."""
    sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
    names = " ".join(scenario_files())
    complete = {
        "bash": "_ftcsim_scenario_compgen",
        "zsh": "{_files -g '*.(toml|ssp)'; compadd -- " + names + "}",
        "tcsh": "(" + names + ")",
        "preamble": {"bash": ("_ftcsim_scenario_compgen() {\n"
                              f'  compgen -W "{names}" -- "$1"\n'
                              '  for ext in "*.toml" "*.ssp"; do compgen -f -X "!$ext" -- "$1"; done\n'
                              '  compgen -d -- "$1"\n}\n')},
    }
    for command, dest in SCENARIO_ARGS.items():
        for action in sub.choices[command]._actions if command in sub.choices else ():
            if action.dest == dest:
                action.complete = complete


def cmd_completion(args, root) -> int:
    """``ftcsim completion SHELL``: the completion script (shtab) of this parser."""
    import shtab

    print(shtab.complete(root, shell=args.shell))
    return 0


EPILOG = """exit status: 0 success; 1 a run an FMU stopped, a failed design or check; 2 bad input (one line naming
the file, the key and the problem; nothing written); 130/143 stopped by SIGINT/SIGTERM; 141 output pipe closed.
Set FTCSIM_DEBUG=1 to see the traceback of an internal error. Docs: README.md, docs/."""

_GENERIC_HELP = {"--quiet": "print nothing but warnings and errors", "--dir": "folder of the FMUs to check "
                 f"(default {DEFAULT_FMU_DIR})"}


def _version(package: str = "ftcsim") -> str:
    try:
        return package_version(package)
    except PackageNotFoundError:  # run from a source tree that was not installed
        return "(not installed)"


VERSIONED = ("fmpy", "pythonfmu", "pythonfmu3", "numpy")


def _git_commit(root: Path) -> str | None:
    """The commit of a git checkout at ``root`` (``+ uncommitted changes`` when the tree differs from
    it); None when ``root`` is no checkout or git is missing."""
    if not (root / ".git").exists():
        return None
    try:
        head = subprocess.run(["git", "-C", str(root), "rev-parse", "HEAD"], capture_output=True, text=True, timeout=10)
        if head.returncode != 0:
            return None
        dirty = subprocess.run(["git", "-C", str(root), "status", "--porcelain", "--untracked-files=no"],
                               capture_output=True, text=True, timeout=10)
    except (OSError, subprocess.SubprocessError):
        return None
    return head.stdout.strip() + (" + uncommitted changes" if dirty.returncode == 0 and dirty.stdout.strip() else "")


def version_text() -> str:
    """``ftcsim --version``: ftcsim's version, those of the packages its FMUs and runs depend on, Python,
    and the git commit when ftcsim runs from a checkout."""
    lines = [f"ftcsim {_version()}"]
    lines += [f"{pkg} {_version(pkg)}" for pkg in VERSIONED]
    lines.append(f"python {sys.version.split()[0]}")
    commit = _git_commit(Path(__file__).resolve().parents[2])
    if commit:
        lines.append(f"git commit {commit}")
    return "\n".join(lines)


class _VersionAction(argparse.Action):
    """``--version``: the versions, computed only when asked (git runs then)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0, help=help)

    def __call__(self, parser, namespace, values, option_string=None):
        print(version_text())
        parser.exit()


def _global_options(p, top: bool) -> None:
    """``-v``, ``-q`` and ``--log-file`` on the top-level parser and on every command (so they may
    follow the command); the commands' values are merged in :func:`main`. Also gives the generic
    options a help text where a command left it out."""
    taken = p._option_string_actions
    default = {} if top else {"default": argparse.SUPPRESS}
    if "-v" not in taken:
        p.add_argument("-v", "--verbose", action="count", dest="log_verbose", help="more messages (debug lines)",
                       **({"default": 0} if top else default))
    if "--quiet" in taken and "-q" not in taken:  # the command's own --quiet: -q as its short form
        action = taken["--quiet"]
        action.option_strings.insert(0, "-q")
        taken["-q"] = action
    elif "-q" not in taken:
        p.add_argument("-q", "--quiet", action="store_true", dest="log_quiet",
                       help="print nothing but warnings and errors", **default)
    if "--log-file" not in taken:
        p.add_argument("--log-file", metavar="FILE", dest="log_file", help="append every message, with its time, "
                       "to FILE", **default)
    for action in p._actions:
        if not action.help and action.option_strings:
            action.help = _GENERIC_HELP.get(action.option_strings[-1])


class _StderrHandler(logging.StreamHandler):
    """A handler writing to whatever ``sys.stderr`` is when a line is logged (not when configured)."""

    def __init__(self):
        super().__init__()

    @property
    def stream(self):
        return sys.stderr

    @stream.setter
    def stream(self, _value):
        pass


class _LogFile(logging.FileHandler):
    """``--log-file``: a log file that fails while the command runs (a full disk) is dropped with one
    warning line on stderr, never a traceback, and the command goes on."""

    def __init__(self, path):
        super().__init__(path, encoding="utf-8", errors="backslashreplace")

    def handleError(self, record):  # noqa: N802 (logging's name)
        root = logging.getLogger("ftcsim")
        root.removeHandler(self)
        try:
            self.close()
        except OSError:
            pass
        print(f"ftcsim: warning: --log-file {printable(self.baseFilename)} can no longer be written; "
              "logging there stopped", file=sys.stderr)


def configure_logging(verbose: int, quiet: bool, log_file=None) -> None:
    """Handlers of the ``ftcsim`` loggers: stderr at INFO (``-v``: DEBUG, ``-q``: WARNING) as
    ``ftcsim: message``, and with ``log_file`` every line at DEBUG with its time."""
    root = logging.getLogger("ftcsim")
    for h in list(root.handlers):
        root.removeHandler(h)
        try:
            h.close()
        except OSError:  # a log file that can no longer be written: nothing more to lose
            pass
    root.setLevel(logging.DEBUG)
    root.propagate = False
    err = _StderrHandler()
    err.setLevel(logging.WARNING if quiet else logging.DEBUG if verbose else logging.INFO)
    err.setFormatter(logging.Formatter("ftcsim: %(message)s"))
    root.addHandler(err)
    if log_file:
        if "\x00" in log_file:
            raise InputError("command line", "--log-file", f"{log_file!r}: a path cannot hold a NUL byte")
        try:
            mode = os.stat(log_file).st_mode if os.path.exists(log_file) else stat.S_IFREG
        except OSError as e:
            raise InputError("command line", "--log-file", f"{log_file}: {e.strerror or e}") from None
        if not (stat.S_ISREG(mode) or stat.S_ISCHR(mode)):  # a FIFO would wait for a reader for ever
            raise InputError("command line", "--log-file", f"{log_file} is {kind_of(mode)}, not a file to append to")
        try:
            fh = _LogFile(log_file)
            # one line written at once: a full disk or /dev/full shows here, as one error, not at the first message
            fh.stream.write(f"{time.strftime('%Y-%m-%d %H:%M:%S')} ftcsim {_version()} (pid {os.getpid()}) starts\n")
            fh.stream.flush()
        except OSError as e:
            raise InputError("command line", "--log-file", f"cannot open {log_file} for writing: {e.strerror or e}") from None
        fh.setLevel(logging.DEBUG)
        fh.setFormatter(logging.Formatter("%(asctime)s %(levelname)s %(name)s: %(message)s"))
        root.addHandler(fh)


def _extensions():
    """The other subcommands, one module each: design/verify, report/campaign-report, export-ssp,
    campaign/compare, arena, params, fdir, schema."""
    return [design.register, report.register, ssp.register, campaign.register, arena.register, params.register,
            fdir.register, schema.register]


def main(argv=None) -> int:
    if signal.getsignal(signal.SIGINT) is _interrupted_while_starting:  # the imports are done: Python's handler
        signal.signal(signal.SIGINT, signal.default_int_handler)
    for stream in (sys.stdout, sys.stderr):  # a path of any bytes printed, never an encoding error
        try:
            stream.reconfigure(errors="backslashreplace")
        except (AttributeError, ValueError, OSError):
            pass
    stdout = sys.stdout
    sys.stdout = _Printable(stdout)  # what commands print names files of any name: no escape reaches the terminal
    try:
        return _main(argv)
    finally:
        sys.stdout = stdout


class _Printable:
    """``sys.stdout`` for a command: every line printed through :func:`printable` (line breaks and tabs kept)."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        return self._stream.write("\n".join("\t".join(printable(c) for c in line.split("\t"))
                                            for line in str(text).split("\n")))

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _main(argv) -> int:
    args = parser().parse_args(argv)
    try:
        quiet = bool(getattr(args, "log_quiet", False) or getattr(args, "quiet", False))
        if hasattr(args, "quiet"):
            args.quiet = quiet
        configure_logging(getattr(args, "log_verbose", 0) or 0, quiet, getattr(args, "log_file", None))
        status = args.func(args)
        sys.stdout.flush()  # a closed pipe shows here, not in the interpreter's teardown
        return status
    except BrokenPipeError:
        return _pipe_closed()
    except InputError as e:
        print(f"ftcsim: error: {_one_line(e)}", file=sys.stderr)
        return 2
    except OSError as e:  # the file system refused (full disk, read-only, a size limit): one line, exit 2
        where = printable(e.filename) if e.filename is not None else "-"
        print(f"ftcsim: error: {where}: {_one_line(e.strerror or e)}", file=sys.stderr)
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


def _pipe_closed() -> int:
    """The reader of stdout went away (``ftcsim scenarios | head``): stop printing, no message, exit
    141 = 128 + SIGPIPE, what a Unix tool killed by the signal reports."""
    try:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # the final flush writes nowhere
    except OSError:
        pass
    return 141


def printable(text) -> str:
    """``text`` safe for a terminal: bytes that are not UTF-8 (a file name's surrogates) and control
    characters (an escape sequence in a hostile name) shown as backslash escapes."""
    s = os.fsdecode(text) if isinstance(text, bytes) else str(text)
    s = s.encode("utf-8", "backslashreplace").decode("utf-8")
    return "".join(c if c.isprintable() or c == " " else repr(c)[1:-1] for c in s)


def _one_line(e) -> str:
    return " ".join(printable(str(e).replace("\n", " ").replace("\t", " ")).split())


def entry() -> None:
    """The ``ftcsim`` command: ``main``, then exit without pythonfmu's teardown once an FMU has
    run here (see orchestrator/common/process_exit.py; every file ftcsim writes is closed and published
    by then)."""
    finish(main())


if __name__ == "__main__":  # pragma: no cover
    entry()
