"""Helpers to derive scenario variants from the shipped li2023_pd scenario's text."""
from pathlib import Path

from papers.registry import scenario_files

ROOT = Path(__file__).resolve().parent.parent
PD = scenario_files()["li2023_pd"].read_text()


def write(tmp_path: Path, text: str, name: str = "case.toml") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def variant(replacements: dict, base: str = PD) -> str:
    text = base
    for old, new in replacements.items():
        assert old in text, f"{old!r} not in the base scenario"
        text = text.replace(old, new, 1)
    return text
