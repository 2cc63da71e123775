"""``ftcsim arena ARENA.toml --out DIR``: every method on every plant it can fly, ranked on one page
(issues 26 and 33; docs/arena-design.md). The arena is an application on top of the orchestrator, reached by
its name in the registry (``arena/app.py``)."""
from __future__ import annotations

from orchestrator.cli.campaign import add_cluster_options, campaign_logging, cluster_options
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import Interrupted
from orchestrator.scenario.shipped import application


def cmd_arena(args) -> int:
    engine = cluster_options(args)  # checked (a scheduler file read, an address parsed) before anything is written
    if engine.pop("batch") is not None:
        raise InputError("command line", "--batch", "the arena sizes its tasks itself (one run, or a few short ones)")
    with campaign_logging(args.quiet):
        o = application("arena")(args.arena, args.out, progress=not args.quiet, draws=args.draws, stop=args.stop,
                                 faults=args.faults, hardware=args.hardware, only=args.only,
                                 mode="fmu" if args.fmu else None, time_limit=args.time_limit,
                                 overwrite=args.overwrite, **engine)
    if not args.quiet:
        print(f"arena: {o.stored} of {o.planned} runs stored in {o.folder} ({o.failed} failed, never ranked) in "
              f"{o.wall_s:.1f} s; leaderboard: {o.page}")
    if o.interrupted:
        raise Interrupted(f"arena stopped by a signal; {o.stored} of {o.planned} runs stored in {o.folder} (the page "
                          "shows them); rerun the same command to compute the rest", 128 + o.interrupted)
    if o.stored < o.planned:
        raise SimulationError(f"{o.planned - o.stored} runs could not be computed; rerun the same command to retry them")
    return 0


def register(sub) -> None:
    p = sub.add_parser("arena", help="run an arena (methods x plants x faults x hardware x draws) and rank it on one page")
    p.add_argument("arena", help="arena file (.toml); see docs/arena-design.md (shipped: arena/ftc_arena.toml)")
    p.add_argument("--out", required=True, help="arena folder (created, or resumed if it holds an arena)")
    p.add_argument("--draws", type=int, help="draws per cell and fault class instead of the file's")
    p.add_argument("--stop", type=float, help="cut every mission to this time (s): a slice, not the papers' missions")
    p.add_argument("--faults", nargs="+", metavar="CLASS", help="fault classes instead of the file's (none, loe_step, "
                                                                "loe_ramp, bias, intermittent, time_varying, stuck, lost, markov)")
    p.add_argument("--hardware", nargs="+", metavar="SET", help="hardware sets instead of the file's (ideal, realistic)")
    p.add_argument("--only", nargs="+", metavar="CELL", help="only these cells (method_on_plant, e.g. fasmc_on_li2023)")
    p.add_argument("--fmu", action="store_true", help="run the FMUs through fmpy instead of the blocks in process "
                                                      "(the same numbers, slower)")
    p.add_argument("--time-limit", type=float, help="s of wall time per run (0: none); a run over it is failed")
    p.add_argument("--overwrite", action="store_true", help="recompute the cells whose inputs changed since the folder "
                                                            "was written (otherwise they are refused)")
    add_cluster_options(p)
    p.add_argument("--quiet", action="store_true")
    p.set_defaults(func=cmd_arena)
