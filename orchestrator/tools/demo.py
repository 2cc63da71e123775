"""``make demo``: every paper's demo scenarios (``Paper.demo``), then each paper's report.

    python -m orchestrator.tools.demo [--out results] [--overwrite] [--paper 000]

Runs go to ``OUT/<scenario>``, reports to ``OUT/report_<paper key>`` (``report.md`` is printed;
``report.html`` beside it is the same report as one page), and ``OUT/index.html`` links them all
(its path is printed last). Folders of an earlier demo are replaced (they carry ftcsim's marker); anything else in the way
stops the demo with a clear message and is left untouched.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from orchestrator.cli.main import main as ftcsim
from orchestrator.common.errors import InputError
from orchestrator.common.process_exit import finish
from orchestrator.results.report import write_index
from orchestrator.scenario.shipped import papers


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m orchestrator.tools.demo", description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="results")
    ap.add_argument("--paper", action="append", help="only these papers (id or key); default all")
    args = ap.parse_args(argv)
    out = Path(args.out)
    for p in papers():
        if args.paper and p.id not in args.paper and p.key not in args.paper:
            continue
        if not p.demo:
            continue
        folders = []
        for name in p.demo:
            folder = out / name
            rc = ftcsim(["run", name, "--out", str(folder), "--overwrite", "--quiet"])
            if rc != 0:
                return rc
            folders.append(str(folder))
            print(f"ran {name} -> {folder}")
        if p.report:
            report = out / f"report_{p.key}"
            rc = ftcsim(["report", *folders, "--out", str(report), "--overwrite"])
            if rc != 0:
                return rc
            print((report / "report.md").read_text())
    try:
        index = write_index(out)
    except InputError as e:
        print(f"ftcsim: error: {e}", file=sys.stderr)
        return 2
    print(f"index of every run and report: {index.resolve()}")
    return 0


if __name__ == "__main__":  # pragma: no cover
    finish(main())
