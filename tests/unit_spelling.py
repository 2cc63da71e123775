"""One spelling per unit in every file and page (issue 36): files (report.md, metrics.json, Parquet
metadata) spell a unit as the FMUs declare it (``N.m``, ``N2.m2.s``), HTML pages for the eye
(``N·m``, ``N²·m²·s``); :func:`misspelt` lists the units in square brackets of a text that are not
in the medium's spelling (plant/units.py)."""
import re

from plant.units import is_unit, pretty, ucum

_BRACKETED = re.compile(r"\[([^\[\]\n<>]{1,24})\](?!\()")


def misspelt(text: str, page: bool) -> list[str]:
    """Units in square brackets of ``text`` spelled otherwise than a page (``page``) or a file spells them."""
    spell = pretty if page else ucum
    return sorted({u for u in _BRACKETED.findall(text) if is_unit(u) and spell(u) != u})


def misspelt_units(units: dict) -> list[str]:
    """Values of a {name: unit} mapping of a file (metrics.json "units", Parquet metadata) not in the file spelling."""
    return sorted({str(u) for u in units.values() if u is not None and ucum(str(u)) != str(u)})
