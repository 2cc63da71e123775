"""Write the shipped JSON Schemas of the file formats (``orchestrator/schemas/NAME.schema.json``) from their
declarations: ``python -m orchestrator.tools.schemas`` (``tests/orchestrator/test_schemas.py`` fails until the
shipped files are what the declarations generate)."""
from __future__ import annotations

from orchestrator.cli.schema import FORMATS, schema_text, shipped_file


def main() -> None:
    for name in FORMATS:
        path = shipped_file(name)
        path.parent.mkdir(exist_ok=True)
        path.write_text(schema_text(name), encoding="utf-8")
        print(f"wrote {path}")


if __name__ == "__main__":
    main()
