"""The README's "What reproduces" table from the reports ``make demo`` writes (each ``report_<key>/report.json``
holds its paper's counts, computed by :func:`papers.reproduction.summarize` from the runs):

    python -m papers.reproduction_counts results                      # print the table
    python -m papers.reproduction_counts results --check README.md    # exit 1 if README's table differs
    python -m papers.reproduction_counts results --write README.md    # replace README's table

README's table sits between the markers ``<!-- reproduction-counts -->`` and ``<!-- /reproduction-counts -->``.
"""
from __future__ import annotations

import argparse
import json
import re
import sys
from pathlib import Path

from papers.reproduction import readme_table

BEGIN, END = "<!-- reproduction-counts -->", "<!-- /reproduction-counts -->"


def summaries(results: Path) -> dict:
    """paper id -> the summary of ``results/report_<key>/report.json``, for every registered paper with a report."""
    from papers.registry import papers

    out = {}
    for p in papers():
        f = Path(results) / f"report_{p.key}" / "report.json"
        if not p.report:
            continue
        if not f.is_file():
            raise FileNotFoundError(f"{f}: no report of paper {p.id} (make demo writes it)")
        data = json.loads(f.read_text(encoding="utf-8"))
        out[p.id] = data["reproduction"]["summary"]
    return out


def replace_block(text: str, table: str) -> str:
    pattern = re.compile(re.escape(BEGIN) + r"\n.*?" + re.escape(END), re.S)
    if not pattern.search(text):
        raise ValueError(f"no {BEGIN} ... {END} block")
    return pattern.sub(lambda _: f"{BEGIN}\n{table}{END}", text)


def readme_block(text: str) -> str:
    m = re.search(re.escape(BEGIN) + r"\n(.*?)" + re.escape(END), text, re.S)
    if not m:
        raise ValueError(f"no {BEGIN} ... {END} block")
    return m.group(1)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m papers.reproduction_counts", description=__doc__.splitlines()[0])
    ap.add_argument("results", help="the folder make demo wrote (results)")
    g = ap.add_mutually_exclusive_group()
    g.add_argument("--check", metavar="README", help="exit 1 if this file's table differs")
    g.add_argument("--write", metavar="README", help="replace this file's table")
    args = ap.parse_args(argv)
    try:
        table = readme_table(summaries(Path(args.results)))
    except (FileNotFoundError, KeyError, json.JSONDecodeError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.check:
        same = readme_block(Path(args.check).read_text(encoding="utf-8")) == table
        print("README table matches the reports" if same else "README table differs from the reports:\n" + table)
        return 0 if same else 1
    if args.write:
        p = Path(args.write)
        p.write_text(replace_block(p.read_text(encoding="utf-8"), table), encoding="utf-8")
    print(table, end="")
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
