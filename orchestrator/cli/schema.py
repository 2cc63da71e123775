"""``ftcsim schema scenario|campaign|arena|design [--out FILE]``: the JSON Schema (draft 2020-12) of a file format,
generated from the declaration ftcsim checks those files with (``orchestrator/scenario/declared.py``). The
same four files ship with the package (``orchestrator/schemas/NAME.schema.json``) for editors
(docs/file-formats.md); ``tests/orchestrator/test_schemas.py`` fails when they differ from what the
declarations generate (``python -m orchestrator.tools.schemas`` writes them again)."""
from __future__ import annotations

import json
from pathlib import Path

from orchestrator.campaign.spec import campaign_format
from orchestrator.common.errors import InputError
from orchestrator.common.jsonio import load_json_object
from orchestrator.common.outputs import OutputFile
from orchestrator.scenario.overrides import design_format
from orchestrator.scenario.shipped import application
from orchestrator.scenario.toml import scenario_format

FORMATS = {"scenario": scenario_format, "campaign": campaign_format, "arena": lambda: application("arena-format")(),
           "design": design_format}  # name -> its declaration (cached)
SHIPPED = Path(__file__).resolve().parents[1] / "schemas"  # orchestrator/schemas/NAME.schema.json


def schema_text(name: str) -> str:
    """The JSON Schema of format ``name`` as the text of its file, from a declaration built now (a cached one
    may hold a registry a test had changed)."""
    declaration = FORMATS[name]
    if name == "arena":
        declaration = application("arena-format")
    return json.dumps(getattr(declaration, "__wrapped__", declaration)().json_schema(), indent=2, ensure_ascii=False) + "\n"


def shipped_file(name: str) -> Path:
    return SHIPPED / f"{name}.schema.json"


def _written_by_ftcsim(path: Path) -> bool:
    """True if ``path`` is a schema file ``ftcsim schema`` wrote (its ``$comment`` says so)."""
    try:
        return "by `ftcsim schema " in str(load_json_object(path, "schema file").get("$comment", ""))
    except InputError:
        return False


def cmd_schema(args) -> int:
    text = schema_text(args.format)
    if args.out is None:
        print(text, end="")
        return 0
    out = OutputFile(args.out, "a schema file", _written_by_ftcsim, args.overwrite,
                     foreign="was not written by `ftcsim schema`").check()
    try:
        out.write(lambda tmp: tmp.write_text(text, encoding="utf-8"))
    finally:
        out.release()
    print(f"wrote the {args.format} schema to {args.out}")
    return 0


def register(sub) -> None:
    p = sub.add_parser("schema", help="print (or write) the JSON Schema of a file format, for editors")
    p.add_argument("format", choices=sorted(FORMATS), help="the file format: scenario, campaign, arena or design")
    p.add_argument("--out", help="write it to this file (.json) instead of printing it; an existing file is replaced "
                                 "only if `ftcsim schema` wrote it and --overwrite is given")
    p.add_argument("--overwrite", action="store_true", help="replace a schema file ftcsim wrote at --out")
    p.set_defaults(func=cmd_schema)
