"""A paper's stored study: a slow computation (LMI certificates, long runs) whose result ships as JSON
beside the paper, so that reports read it instead of recomputing it, and its command line
(``python -m papers.pNNN_key.NAME --out FILE``) that writes it again. Used by 000's appendix study,
002's certificate study and 003's gamma3 study."""
from __future__ import annotations

import argparse
import json
from pathlib import Path

from orchestrator.results.files import write_json


def load(path: Path) -> dict | None:
    """The stored study at ``path`` (None if the file is missing)."""
    return json.loads(path.read_text(encoding="utf-8")) if path.is_file() else None


def main(prog: str, doc: str, study, default: Path, argv=None) -> int:
    """The study's command: compute ``study()``, write it to ``--out`` (default ``default``) and print it."""
    ap = argparse.ArgumentParser(prog=prog, description=doc.splitlines()[0])
    ap.add_argument("--out", default=str(default))
    args = ap.parse_args(argv)
    data = study()
    write_json(args.out, data)
    print(json.dumps(data, indent=2))
    return 0
