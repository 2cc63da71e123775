"""``ftcsim arena ARENA.toml --out DIR``: every method on every plant it can fly, ranked on one page
(issue 26; docs/arena-design.md). The arena is an application on top of the orchestrator, reached by
its name in the registry (``arena/app.py``)."""
from __future__ import annotations

from orchestrator.campaign.cluster import check_address
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.scenario.shipped import application


def cmd_arena(args) -> int:
    if args.workers is not None and args.workers < 0:
        raise InputError("command line", "--workers", f"must be >= 0, got {args.workers}")
    if args.scheduler is not None:  # a malformed address is one line before any file is read
        check_address(args.scheduler)
    if args.workers is not None and args.scheduler:
        raise InputError("command line", "--workers", "give --workers or --scheduler, not both")
    engine = {"scheduler": args.scheduler} if args.scheduler else {}
    o = application("arena")(args.arena, args.out, workers=args.workers, progress=not args.quiet,
                             overwrite=args.overwrite, **engine)
    if not args.quiet:
        print(f"arena: {o.stored} of {o.planned} runs stored in {o.folder} ({o.failed} failed, never ranked) in "
              f"{o.wall_s:.1f} s; leaderboard: {o.page}")
    if o.stored < o.planned:
        raise SimulationError(f"{o.planned - o.stored} runs could not be computed; rerun the same command to retry them")
    return 0


def register(sub) -> None:
    p = sub.add_parser("arena", help="run an arena (methods x plants x faults x hardware x draws) and rank it on one page")
    p.add_argument("arena", help="arena file (.toml); see docs/arena-design.md (shipped: arena/ftc_arena.toml)")
    p.add_argument("--out", required=True, help="arena folder (created, or resumed if it holds this arena)")
    p.add_argument("--workers", type=int, help="local Dask worker processes, one thread each (default: the cores; "
                                               "0: run in this process without Dask)")
    p.add_argument("--scheduler", help="address of an existing Dask scheduler (tcp://host:port) instead")
    p.add_argument("--overwrite", action="store_true", help="replace an arena folder at --out (this arena's or another's; "
                                                            "nothing else is ever replaced)")
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_arena)
