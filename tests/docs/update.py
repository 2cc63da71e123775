"""Write what the commands print now into the pages' shown outputs: the numbers of every shown line
whose text still matches a printed line (tests/docs/blocks.py ``compare``); lines that no longer
match are listed, not touched.

    .venv/bin/python -m tests.docs.update [--long] [DOC ...]

Runs the blocks as the docs test does (tests/docs/reader.py: one working folder; ``--long`` every
block, ``make demo`` included; default the fast ones), then rewrites the pages in the project.
Review the diff: a changed number is a changed result.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from tests.docs.reader import DOCS, ROOT, Reader


def apply(doc: str, fixes: dict) -> int:
    """Replace, in ``doc``, each shown line (document line -> (old text, new text)); returns how many."""
    path = ROOT / doc
    lines = path.read_text(encoding="utf-8").split("\n")
    n = 0
    for at, (old, new) in sorted(fixes.items()):
        old_s = old.strip()
        if old_s and old_s in lines[at]:
            lines[at] = lines[at].replace(old_s, new.strip(), 1)
            n += 1
    path.write_text("\n".join(lines), encoding="utf-8")
    return n


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python -m tests.docs.update", description=__doc__.splitlines()[0])
    ap.add_argument("docs", nargs="*", help=f"pages (default all, in reading order: {' '.join(DOCS)})")
    ap.add_argument("--long", action="store_true", help="every block, make demo included (minutes)")
    ap.add_argument("--fmu-dir", default=str(ROOT / "build" / "fmus"))
    args = ap.parse_args(argv)
    wanted = args.docs or DOCS
    left = []
    with tempfile.TemporaryDirectory(prefix="ftcsim-docs-") as tmp:
        reader = Reader(Path(tmp), Path(args.fmu_dir), long=args.long)
        for doc in DOCS:  # every page in order (a later page may use an earlier one's results)
            outcomes = reader.run_doc(doc)
            for o in outcomes:
                if not o.block.file:
                    print(f"  {o.block.where}: {o.seconds:.1f} s, {o.cpu:.1f} s of CPU"
                          + (f", cost marker {o.block.cost!r}" if o.block.cost else ""), flush=True)
            if doc not in wanted:
                continue
            fixes = {k: v for o in outcomes for k, v in o.fixes.items()}
            n = apply(doc, fixes) if fixes else 0
            print(f"{doc}: {n} shown line(s) rewritten")
            for o in outcomes:
                left += [p for p in o.problems if "printed with other numbers" not in p]
                if any("printed with other numbers" not in p for p in o.problems):
                    left += [f"{o.block.where}: printed:\n{text}" for text in o.printed]
                left += [f"{o.block.where}: {c} took {s:.0f} s of CPU (no cost marker)" for c, s in o.slow]
    for p in left:
        print(p, file=sys.stderr)
    return 1 if left else 0


if __name__ == "__main__":
    sys.exit(main())
