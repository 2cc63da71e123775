"""``ftcsim campaign CAMPAIGN.toml --out DIR`` (see :mod:`orchestrator.campaign.run`) and ``ftcsim compare
CONTROLLER.fmu --out DIR`` (see :mod:`orchestrator.campaign.compare`)."""
from __future__ import annotations

import math
import sys
from pathlib import Path

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


def cmd_campaign(args) -> int:
    if args.workers is not None and args.workers < 0:
        raise InputError("command line", "--workers", f"must be >= 0, got {args.workers}")
    if args.workers is not None and args.scheduler:
        raise InputError("command line", "--workers", "give --workers or --scheduler, not both")
    if not math.isfinite(args.connect_timeout) or args.connect_timeout <= 0:
        raise InputError("command line", "--connect-timeout", "must be a number > 0")
    time_limit = _time_limit(args)
    c = load_campaign(args.campaign)
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
    o = run_campaign(c, args.out, workers=args.workers, scheduler=args.scheduler, overwrite=args.overwrite,
                     only=args.run, progress=not args.quiet, connect_timeout=args.connect_timeout,
                     time_limit=time_limit)
    if not args.quiet:
        print(f"{c.name}: {o.stored} of {o.total} runs stored in {o.folder} ({o.computed} computed now, "
              f"{o.skipped} found stored, {o.failed} not ok); summary: {o.folder / SUMMARY}")
    if o.interrupted:
        raise Interrupted(f"campaign stopped by a signal; {o.stored} of {o.total} runs stored in {o.folder}; "
                          "rerun the same command to compute the rest", 128 + o.interrupted)
    if o.lost:
        raise SimulationError(f"{o.lost} runs could not be computed (their workers died); rerun the same command "
                              "to retry them")
    return 0


def _time_limit(args):
    """--time-limit: None (the campaign's), 0 (none) or seconds."""
    return None if args.time_limit is None else (check_limit(args.time_limit) or 0)


def _time_limit_option(p) -> None:
    p.add_argument("--time-limit", type=float, metavar="SECONDS",
                   help=f"wall-time limit per run (default: the campaign file's time_limit, else "
                        f"{DEFAULT_TIME_LIMIT:g}; 0: none); a run over it is stored with status timeout")


def register_campaign(sub) -> None:
    p = sub.add_parser("campaign", help="run a campaign (Monte Carlo, sweep, method comparison) on Dask, resumably")
    p.add_argument("campaign", help="campaign file (.toml); see docs/campaigns.md")
    p.add_argument("--out", required=True, help="campaign folder (created, or resumed if it holds this campaign)")
    p.add_argument("--workers", type=int, help="local worker processes, one thread each (default: the cores; "
                                               "0: run in this process without Dask)")
    p.add_argument("--scheduler", help="address of an existing Dask scheduler (tcp://host:port) instead")
    p.add_argument("--connect-timeout", type=float, default=5.0, help="seconds to reach --scheduler (default 5)")
    p.add_argument("--overwrite", action="store_true", help="replace a folder holding another campaign")
    p.add_argument("--run", type=int, action="append", help="compute only this run id (repeatable)")
    p.add_argument("--replay", type=int, metavar="RUN", help="run RUN alone as an `ftcsim run` folder at --out")
    _time_limit_option(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_campaign)


def cmd_compare(args) -> int:
    if args.runs is not None and args.runs < 1:
        raise InputError("command line", "--runs", f"must be >= 1, got {args.runs}")
    if args.stop is not None and not (math.isfinite(args.stop) and args.stop > 0):
        raise InputError("command line", "--stop", f"must be a finite number of seconds > 0, got {args.stop:g}")
    if args.workers is not None and args.workers < 0:
        raise InputError("command line", "--workers", f"must be >= 0, got {args.workers}")
    time_limit = _time_limit(args)
    base = campaign_file(args.campaign)
    c, variant = load_comparison(base, Path(args.controller), scenario=args.scenario, instance=args.instance,
                                 name=args.name, runs=args.runs, stop=args.stop)
    out = Path(args.out)
    c.path = out / CAMPAIGN_COPY  # what the manifest and the report's replay commands name
    for v in c.variants:
        for inst, names in v.dropped.items():
            print(f"ftcsim: note: variant {v.name}: {inst}'s FMU swap drops parameters {', '.join(names)}",
                  file=sys.stderr)
    o = run_campaign(c, out, workers=args.workers, overwrite=args.overwrite, progress=not args.quiet,
                     time_limit=time_limit)
    if o.interrupted or o.lost or o.stored < o.total:
        if o.interrupted:
            raise Interrupted(f"comparison stopped by a signal; {o.stored} of {o.total} runs stored in {out}; rerun "
                              "the same command to compute the rest", 128 + o.interrupted)
        raise SimulationError(f"{o.total - o.stored} runs could not be computed; rerun the same command to retry them")
    report = OutputFolder(out / "report", "campaign-report", overwrite=True).check()
    data = report.fill(lambda staging: make_report(out, staging))
    if not args.quiet:
        _print_table(data, variant)
        print(f"{c.name}: {o.stored} runs ({len(c.variants)} variants x {c.runs} draws; {o.computed} computed now, "
              f"{o.skipped} found stored, {o.failed} not ok) in {out} ({SUMMARY}); report: {out / 'report' / 'report.md'}")
    return 0


def _print_table(data, variant, metrics=("final_attitude_error", "final_rate_error", "control_energy",
                                         "settling_time", "max_abs_u")) -> None:
    """Mean (n) of the key metrics per variant, the user's variant last."""
    rows = {}
    for r in data["statistics"]:
        if r["metric"] in metrics:
            rows.setdefault(r["variant"], {})[r["metric"]] = r
    shown = [m for m in metrics if any(m in v for v in rows.values())]
    print("variant".ljust(12) + "".join(m.rjust(22) for m in shown))
    for name in sorted(rows, key=lambda n: n == variant):
        cells = []
        for m in shown:
            r = rows[name].get(m)
            cells.append("-" if r is None or r["mean"] is None else f"{r['mean']:.4g} ({r['n']}/{r['of']})")
        print(name.ljust(12) + "".join(c.rjust(22) for c in cells))


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
    p.add_argument("--workers", type=int, help="local worker processes (default: the cores; 0: in this process)")
    p.add_argument("--overwrite", action="store_true", help="replace a folder holding another campaign")
    _time_limit_option(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_compare)


def register(sub) -> None:
    register_campaign(sub)
    register_compare(sub)
