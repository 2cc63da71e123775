"""``ftcsim fdir calibrate CAMPAIGN --detector INSTANCE --rate R --draws DIR --out FILE.json``: a change
detector's threshold from fault-free draws for a stated false-alarm rate per hour
(:mod:`orchestrator.campaign.calibrate`, docs/fdir.md)."""
from __future__ import annotations

import shlex

from orchestrator import api
from orchestrator.cli.campaign import add_cluster_options, campaign_logging, cluster_options
from orchestrator.common.errors import InputError

KEYS = {"campaign": "CAMPAIGN", "detector": "--detector", "rate_per_hour": "--rate", "level": "--level", "out": "--out",
        "draws": "--draws", "runs": "--runs"}


def command_line(args) -> str:
    """The command as written into the calibration file: what decides the result (not where it ran)."""
    words = ["ftcsim", "fdir", "calibrate", args.campaign, "--detector", args.detector, "--rate", f"{args.rate:g}"]
    words += ["--level", f"{args.level:g}"] if args.level != 0.95 else []
    words += ["--runs", str(args.runs)] if args.runs is not None else []
    words += ["--draws", args.draws, "--out", args.out] + (["--overwrite"] if args.overwrite else [])
    return " ".join(shlex.quote(str(w)) for w in words)


def cmd_calibrate(args) -> int:
    cluster = cluster_options(args)
    if args.runs is not None and args.runs < 1:
        raise InputError("command line", "--runs", f"must be >= 1, got {args.runs}")
    with campaign_logging(args.quiet):
        doc = api.fdir_calibrate(args.campaign, detector=args.detector, rate_per_hour=args.rate, level=args.level,
                                 draws=args.draws, out=args.out, overwrite=args.overwrite, runs=args.runs,
                                 progress=not args.quiet, command=command_line(args), src="command line", keys=KEYS,
                                 **cluster)
    s, p = doc["statistics"], doc["parameter_set"]
    print(f"{doc['detector']['instance']} ({doc['detector']['model']}): h = {p['h']:.6g} from {s['runs']} fault-free draws "
          f"({s['exposure_hours']:.3g} h), none alarms at h: first false alarms at most {s['upper_bound_per_hour']:.3g} "
          f"per hour at {doc['target']['level']:g}; target {doc['target']['false_alarms_per_hour']:g} per hour "
          f"{'certified' if doc['certified'] else 'NOT certified (too little exposure)'}; wrote {args.out}")
    return 0


def register(sub) -> None:
    f = sub.add_parser("fdir", help="the FDIR decision layer: calibrate a detector's threshold (docs/fdir.md)")
    fsub = f.add_subparsers(dest="fdir_command", required=True, parser_class=type(f), metavar="ACTION")
    c = fsub.add_parser("calibrate", help="set a detector's threshold from fault-free Monte Carlo draws for a stated "
                                          "false-alarm rate per hour")
    c.add_argument("campaign", help="campaign file (.toml) or shipped campaign name: the fault-free draws, storing the "
                                    "detector's input as a trajectory at its sample period")
    c.add_argument("--detector", required=True, metavar="INSTANCE", help="the detector instance of the campaign's scenario")
    c.add_argument("--rate", required=True, type=float, metavar="PER_HOUR", help="false alarms per hour to stay under")
    c.add_argument("--level", type=float, default=0.95, help="confidence of the bound on the rate (default 0.95)")
    c.add_argument("--draws", required=True, metavar="DIR", help="campaign folder of the draws (created, or resumed)")
    c.add_argument("--out", required=True, metavar="FILE.json", help="calibration file to write")
    c.add_argument("--runs", type=int, help="number of draws instead of the campaign file's")
    c.add_argument("--overwrite", action="store_true", help="replace a previous calibration file (and draws folder of "
                                                            "another campaign) ftcsim wrote")
    c.add_argument("-q", "--quiet", action="store_true", help="print nothing but warnings and errors")
    add_cluster_options(c)
    c.set_defaults(func=cmd_calibrate)
