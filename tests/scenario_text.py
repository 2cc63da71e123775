"""Helpers to derive scenario variants from the shipped li2023_pd scenario's text."""
from pathlib import Path

from papers.registry import scenario_files

ROOT = Path(__file__).resolve().parent.parent
# the engine tests below were written against li2023_pd with the per-axis saturation (the default of the 000
# scenarios until issue 21 made it the printed ||u||_1): their variants keep it
PD = scenario_files()["li2023_pd"].read_text().replace("saturation_mode = 1", "saturation_mode = 0")


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
