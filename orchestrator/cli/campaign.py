"""``ftcsim campaign CAMPAIGN.toml --out DIR`` (see :mod:`orchestrator.campaign.run`) and ``ftcsim compare
CONTROLLER.fmu --out DIR`` (see :mod:`orchestrator.campaign.compare`)."""
from __future__ import annotations

import contextlib
import logging
import math
import sys
from pathlib import Path

from orchestrator.campaign.cluster import MAX_WORKERS, check_address, read_scheduler_file
from orchestrator.campaign.compare import DEFAULT_CAMPAIGN, DEFAULT_RUNS, load_comparison
from orchestrator.campaign.report import make_report
from orchestrator.campaign.run import replay, run_campaign
from orchestrator.campaign.spec import DEFAULT_TIME_LIMIT
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.campaign.store import CAMPAIGN_COPY, SUMMARY
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import Interrupted
from orchestrator.common.outputs import OutputFolder
from orchestrator.common.watchdog import check_limit
from orchestrator.scenario.shipped import campaign_file
from orchestrator.scenario.values import seconds, whole
from plant.units import ucum


def add_cluster_options(p) -> None:
    """Where the runs go: --workers, --scheduler, --scheduler-file and their bounds (campaign, compare)."""
    p.add_argument("--workers", type=int, help="local worker processes, one thread each (default: the cores; "
                                               "0: run in this process without Dask)")
    p.add_argument("--force-workers", action="store_true", help="allow --workers above the number of cores")
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler (tcp://host:8786) instead")
    p.add_argument("--scheduler-file", metavar="FILE", help="an existing Dask scheduler named in its scheduler file "
                                                            "(dask scheduler --scheduler-file FILE; SLURM)")
    p.add_argument("--connect-timeout", type=float, default=5.0, metavar="S",
                   help="seconds to reach the scheduler (default 5)")
    p.add_argument("--wait-workers", type=float, default=120.0, metavar="S",
                   help="seconds to wait for a worker when the scheduler has none (default 120)")
    p.add_argument("--batch", type=int, metavar="N", help="runs per Dask task (default: from the runs' length)")
    p.add_argument("--progress-every", type=float, default=30.0, metavar="S",
                   help="seconds between progress lines when stderr is not a terminal (default 30)")


def cluster_options(args) -> dict:
    """The checked cluster options as keywords of ``run_campaign``."""
    if args.workers is not None:
        whole("command line", "--workers", args.workers, lower=0, upper=MAX_WORKERS)
    given = [k for k in ("scheduler", "scheduler_file") if getattr(args, k)]
    if len(given) > 1:
        raise InputError("command line", "--scheduler-file", "give --scheduler or --scheduler-file, not both")
    if args.workers is not None and given:
        raise InputError("command line", "--workers", f"give --workers or --{given[0].replace('_', '-')}, not both")
    for key in ("connect_timeout", "wait_workers", "progress_every"):
        seconds("command line", f"--{key.replace('_', '-')}", getattr(args, key))
    if args.batch is not None and not 1 <= args.batch <= 10_000:
        raise InputError("command line", "--batch", f"must be 1..10000, got {args.batch}")
    if args.scheduler is not None:  # before any file is read: a malformed address is one line
        check_address(args.scheduler)
    if args.scheduler_file is not None:
        read_scheduler_file(args.scheduler_file)
    return {"workers": args.workers, "scheduler": args.scheduler, "scheduler_file": args.scheduler_file,
            "connect_timeout": args.connect_timeout, "wait_workers": args.wait_workers,
            "force_workers": args.force_workers, "batch": args.batch, "progress_every": args.progress_every}


@contextlib.contextmanager
def campaign_logging(quiet: bool):
    """Progress and warnings of ``ftcsim.campaign`` on stderr as plain lines, unless logging is
    configured already (then its handlers decide)."""
    logger = logging.getLogger("ftcsim.campaign")
    if logger.hasHandlers():
        yield
        return
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("ftcsim: %(message)s"))
    level = logger.level
    logger.addHandler(handler)
    logger.setLevel(logging.WARNING if quiet else logging.INFO)
    try:
        yield
    finally:
        logger.removeHandler(handler)
        logger.setLevel(level)


def cmd_campaign(args) -> int:
    cluster = cluster_options(args)
    if args.runs is not None and args.runs < 1:
        raise InputError("command line", "--runs", f"must be >= 1, got {args.runs}")
    if args.stop is not None and not (math.isfinite(args.stop) and args.stop > 0):
        raise InputError("command line", "--stop", f"must be a finite number of seconds > 0, got {args.stop:g}")
    c = _load_with_options(args)
    time_limit = _time_limit(args)
    if args.replay is not None:
        raw, metrics, errors = replay(c, args.replay, args.out, overwrite=args.overwrite, progress=not args.quiet)
        print(f"{c.name}: run {args.replay} written to {args.out}")
        if not raw.complete:
            raise SimulationError(f"{raw.error}; results so far kept in {args.out}, marked incomplete")
        return 0
    for v in c.variants:
        for inst, names in v.dropped.items():
            print(f"ftcsim: note: variant {v.name}: {inst}'s FMU swap drops parameters {', '.join(names)}",
                  file=sys.stderr)
    with campaign_logging(args.quiet):
        o = run_campaign(c, args.out, overwrite=args.overwrite, only=args.run, progress=not args.quiet, time_limit=time_limit, **cluster)
    if not args.quiet:
        print(f"{c.name}: {o.stored} of {o.total} runs stored in {o.folder} ({o.computed} computed now, "
              f"{o.skipped} found stored, {o.failed} not ok); summary: {o.folder / SUMMARY}")
    if o.interrupted:
        raise Interrupted(f"campaign stopped by a signal; {o.stored} of {o.total} runs stored in {o.folder}; "
                          "rerun the same command to compute the rest", 128 + o.interrupted)
    if o.lost:
        raise SimulationError(f"{o.lost} runs could not be computed (the cluster lost them); rerun the same command "
                              "to retry them")
    return 0


def _load_with_options(args):
    """The campaign with ``--runs`` / ``--stop``; a problem they make is named as the option."""
    try:
        return load_campaign(args.campaign if Path(args.campaign).is_file() else campaign_file(args.campaign),
                             runs=args.runs, stop=args.stop)
    except InputError as e:
        raise _as_option(e, args) from None


def _as_option(e: InputError, args) -> InputError:
    """``e`` named as ``--stop`` / ``--runs`` when that option set the key it is about."""
    option = {"campaign.stop": ("--stop", args.stop), "campaign.runs": ("--runs", args.runs)}.get(e.key)
    if option is None or option[1] is None:
        return e
    return InputError("command line", option[0], e.problem)


def _time_limit(args):
    """--time-limit: None (the campaign's), 0 (none) or seconds."""
    return None if args.time_limit is None else (check_limit(args.time_limit) or 0)


def _time_limit_option(p) -> None:
    p.add_argument("--time-limit", type=float, metavar="SECONDS",
                   help=f"wall-time limit per run (default: the campaign file's time_limit, else "
                        f"{DEFAULT_TIME_LIMIT:g}; 0: none); a run over it is stored with status timeout")


def register_campaign(sub) -> None:
    p = sub.add_parser("campaign", help="run a campaign (Monte Carlo, sweep, method comparison) on Dask, resumably")
    p.add_argument("campaign", help="campaign file (.toml) or a shipped campaign's name (li2023_methods, "
                                    "xu2024_seeds); see docs/campaigns.md")
    p.add_argument("--out", required=True, help="campaign folder (created, or resumed if it holds this campaign)")
    add_cluster_options(p)
    p.add_argument("--overwrite", action="store_true", help="replace a folder holding another campaign")
    p.add_argument("--run", type=int, action="append", help="compute only this run id (repeatable)")
    p.add_argument("--replay", type=int, metavar="RUN", help="run RUN alone as an `ftcsim run` folder at --out")
    p.add_argument("--runs", type=int, help="draws per variant and grid point, instead of [campaign] runs")
    p.add_argument("--stop", type=float, metavar="S", help="simulated time of every run, s, instead of the file's")
    _time_limit_option(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_campaign)


def cmd_compare(args) -> int:
    if args.runs is not None and args.runs < 1:
        raise InputError("command line", "--runs", f"must be >= 1, got {args.runs}")
    if args.stop is not None and not (math.isfinite(args.stop) and args.stop > 0):
        raise InputError("command line", "--stop", f"must be a finite number of seconds > 0, got {args.stop:g}")
    cluster = cluster_options(args)
    time_limit = _time_limit(args)
    base = campaign_file(args.campaign)
    try:
        c, variant = load_comparison(base, Path(args.controller), scenario=args.scenario, instance=args.instance,
                                     name=args.name, runs=args.runs, stop=args.stop)
    except InputError as e:  # a problem --stop or --runs made is named as that option
        raise _as_option(e, args) from None
    out = Path(args.out)
    c.path = out / CAMPAIGN_COPY  # what the manifest and the report's replay commands name
    for v in c.variants:
        for inst, names in v.dropped.items():
            print(f"ftcsim: note: variant {v.name}: {inst}'s FMU swap drops parameters {', '.join(names)}",
                  file=sys.stderr)
    with campaign_logging(args.quiet):
        o = run_campaign(c, out, overwrite=args.overwrite, progress=not args.quiet, time_limit=time_limit,
                         **cluster)
    if o.interrupted or o.lost or o.stored < o.total:
        if o.interrupted:
            raise Interrupted(f"comparison stopped by a signal; {o.stored} of {o.total} runs stored in {out}; rerun "
                              "the same command to compute the rest", 128 + o.interrupted)
        raise SimulationError(f"{o.total - o.stored} runs could not be computed; rerun the same command to retry them")
    report = OutputFolder(out / "report", "campaign-report", overwrite=True).check()
    data = report.fill(lambda staging: make_report(out, staging))
    if not args.quiet:
        _print_table(data, variant, [v.name for v in c.variants])
        print(f"{c.name}: {o.stored} runs ({len(c.variants)} variants x {c.runs} draws; {o.computed} computed now, "
              f"{o.skipped} found stored, {o.failed} not ok) in {out} ({SUMMARY}); report: {out / 'report' / 'report.md'}")
    return 0


def _print_table(data, variant, variants, metrics=("final_attitude_error", "final_rate_error", "control_energy",
                                                   "settling_time", "max_abs_u")) -> None:
    """Mean (n) of the key metrics per variant with their units, the user's variant last; a variant without
    statistics (no run finished: the report has no row for it) is listed with "-"."""
    rows = {name: {} for name in variants}
    for r in data["statistics"]:
        if r["metric"] in metrics:
            rows.setdefault(r["variant"], {})[r["metric"]] = r
    shown = [m for m in metrics if any(m in v for v in rows.values())]
    units = data.get("units") or {}
    heads = [m + (f" [{ucum(units[m])}]" if units.get(m) and ucum(units[m]) != "1" else "") for m in shown]
    widths = [max(len(h), 18) + 2 for h in heads]
    first = max(12, *(len(n) + 2 for n in rows))
    print("variant".ljust(first) + "".join(h.rjust(w) for h, w in zip(heads, widths)))
    for name in sorted(rows, key=lambda n: n == variant):
        cells = []
        for m in shown:
            r = rows[name].get(m)
            cells.append("-" if r is None or r["mean"] is None else f"{r['mean']:.4g} ({r['n']}/{r['of']})")
        print(name.ljust(first) + "".join(c.rjust(w) for c, w in zip(cells, widths)))


def register_compare(sub) -> None:
    p = sub.add_parser("compare", help="your controller FMU against the shipped methods on the same fault draws "
                                       "(a campaign variant), with the campaign report")
    p.add_argument("controller", help="your controller FMU (.fmu, e.g. from `ftcsim build --block`)")
    p.add_argument("--out", required=True, help="campaign folder (created, or resumed if it holds this comparison)")
    p.add_argument("--campaign", default=DEFAULT_CAMPAIGN, help="campaign to compare in: a shipped name or a .toml "
                                                                f"file (default {DEFAULT_CAMPAIGN})")
    p.add_argument("--scenario", help="scenario that wires your controller (default: the campaign's last variant's, "
                                      "e.g. li2023_fasmc)")
    p.add_argument("--instance", default="ctrl", help="instance your FMU replaces (default ctrl)")
    p.add_argument("--name", help="name of your variant (default: the FMU file's name)")
    p.add_argument("--runs", type=int, default=DEFAULT_RUNS, help=f"fault draws per variant (default {DEFAULT_RUNS})")
    p.add_argument("--stop", type=float, help="simulated time of every run, s (default: the scenarios')")
    add_cluster_options(p)
    p.add_argument("--overwrite", action="store_true", help="replace a folder holding another campaign")
    _time_limit_option(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_compare)


def register(sub) -> None:
    register_campaign(sub)
    register_compare(sub)
