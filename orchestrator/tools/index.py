"""``python -m orchestrator.tools.index [DIR]``: write ``DIR/index.html`` (default ``results``), one
page linking every report, campaign and run folder ftcsim wrote in ``DIR``, and print its path
(:func:`orchestrator.results.report.write_index`)."""
from __future__ import annotations

import argparse
import sys

from orchestrator.common.errors import InputError
from orchestrator.results.report import write_index


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m orchestrator.tools.index", description=__doc__.splitlines()[0])
    ap.add_argument("folder", nargs="?", default="results", help="a results folder (default results)")
    args = ap.parse_args(argv)
    try:
        print(write_index(args.folder).resolve())
    except InputError as e:
        print(f"ftcsim: error: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
