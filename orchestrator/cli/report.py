"""``ftcsim report DIR... --out DIR`` (a paper's figures and tables from result folders, see
:mod:`orchestrator.results.report`) and ``ftcsim campaign-report DIR [--out REPORT]`` (what a campaign found,
see :mod:`orchestrator.campaign.report`)."""
from __future__ import annotations

from pathlib import Path

from orchestrator.campaign.report import load_folder, make_report
from orchestrator.common.errors import InputError
from orchestrator.common.outputs import OutputFolder
from orchestrator.results.files import Run
from orchestrator.results.report import make_reports


def cmd_report(args) -> int:
    runs = [Run(Path(f)) for f in args.folders]  # every folder checked before anything is written
    names = [r.name for r in runs]
    dup = sorted({n for n in names if names.count(n) > 1})
    if dup:
        raise InputError("command line", "folders", f"two folders hold runs of the same scenario {dup[0]!r}")
    folder = OutputFolder(args.out, "report", overwrite=args.overwrite).check()
    done = folder.fill(lambda staging: make_reports(runs, staging))
    n_fig = sum(len(d.get("figures", [])) for d in done.values())
    print(f"report of {len(runs)} run(s) in {args.out}: {n_fig} figures, report.md, report.json")
    return 0


def register_report(sub) -> None:
    p = sub.add_parser("report", help="draw a paper's figures and tables from result folders")
    p.add_argument("folders", nargs="+", help="result folders of `ftcsim run`")
    p.add_argument("--out", default="results/report", help="output folder (default results/report)")
    p.add_argument("--overwrite", action="store_true", help="replace a previous report in --out")
    p.set_defaults(func=cmd_report)


def cmd_campaign_report(args) -> int:
    folder = Path(args.folder)
    load_folder(folder)  # refuse a bad folder before creating anything
    out = Path(args.out) if args.out else folder / "report"
    target = OutputFolder(out, "campaign-report", overwrite=args.overwrite).check()
    data = target.fill(lambda staging: make_report(folder, staging))
    print(f"campaign report of {data['runs']} runs in {out} (report.md, {', '.join(data['plots']) or 'no plots'})")
    return 0


def register_campaign_report(sub) -> None:
    p = sub.add_parser("campaign-report", help="statistics, requirements, worst runs and plots of a campaign folder")
    p.add_argument("folder", help="campaign folder written by `ftcsim campaign`")
    p.add_argument("--out", help="report folder (default FOLDER/report)")
    p.add_argument("--overwrite", action="store_true", help="replace a previous report in --out")
    p.set_defaults(func=cmd_campaign_report)


def register(sub) -> None:
    register_report(sub)
    register_campaign_report(sub)
