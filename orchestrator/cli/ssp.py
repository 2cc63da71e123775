"""``ftcsim export-ssp SCENARIO --out FILE.ssp``: a scenario as an SSP 1.0 package
(:mod:`orchestrator.scenario.ssp`)."""
from __future__ import annotations

import zipfile

from orchestrator import api
from orchestrator.scenario.ssp import export_ssp


def cmd_export_ssp(args) -> int:
    scenario = api.load(args.scenario, fmu_dir=args.fmu_dir, gains=args.gains or ())
    out = export_ssp(scenario, args.out, fmu_dir=args.fmu_dir, overwrite=args.overwrite)
    if not args.quiet:
        with zipfile.ZipFile(out) as z:
            names = z.namelist()
        print(f"wrote {out}: {sum(n.endswith('.fmu') for n in names)} FMUs, "
              f"{sum(n.endswith('.ssv') for n in names)} parameter sets, SystemStructure.ssd (validated)")
    return 0


def register(subparsers) -> None:
    e = subparsers.add_parser("export-ssp", help="write a scenario as an SSP 1.0 package (.ssp)")
    e.add_argument("scenario", help="shipped scenario name or scenario file (.toml)")
    e.add_argument("--out", required=True, help="package to write (.ssp)")
    e.add_argument("--overwrite", action="store_true", help="replace an existing package at --out")
    e.add_argument("--fmu-dir", help="folder of built FMUs (default build/fmus)")
    e.add_argument("--gains", action="append", help="design file (JSON) overriding FMU parameters; repeatable")
    e.add_argument("--quiet", action="store_true")
    e.set_defaults(func=cmd_export_ssp)
