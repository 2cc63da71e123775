"""The shipped JSON Schemas (orchestrator/schemas/) as an editor would apply them: ``errors(format, document)``,
and ``check_design_file`` for the designs' tests (no design file ships: what ``ftcsim design`` writes is
validated where it is written)."""
from __future__ import annotations

import functools
import json
from pathlib import Path

from jsonschema import Draft202012Validator

from orchestrator.cli.schema import shipped_file
from orchestrator.common.jsonio import strict_json


@functools.cache
def validator(name: str) -> Draft202012Validator:
    return Draft202012Validator(json.loads(shipped_file(name).read_text()))


def errors(name: str, doc) -> list:
    """The schema errors of ``doc`` against format ``name``'s shipped schema, in path order."""
    return sorted(validator(name).iter_errors(doc), key=lambda e: [str(p) for p in e.absolute_path])


def check_design_file(design) -> None:
    """Assert that a design file (a path, or a design's result as ``ftcsim design`` writes it) meets the shipped
    design schema."""
    doc = json.loads(Path(design).read_text()) if isinstance(design, (str, Path)) else \
        json.loads(json.dumps(strict_json(design), allow_nan=False))
    found = errors("design", doc)
    assert not found, [(list(e.absolute_path), e.message[:200]) for e in found]
