"""Shared fixtures: the built FMUs (rebuilt if any source is newer) and scenario paths."""
import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
FMU_DIR = ROOT / "build" / "fmus"
SCENARIOS = ROOT / "scenarios"


def _stale(names) -> bool:
    sources = [p for d in ("plant", "estimator", "controller", "fmus", "papers") for p in (ROOT / d).rglob("*.py")]
    newest = max(p.stat().st_mtime for p in sources)
    for n in names:
        f = FMU_DIR / f"{n}.fmu"
        if not f.is_file() or f.stat().st_mtime < newest:
            return True
    return False


@pytest.fixture(scope="session")
def fmu_dir() -> Path:
    """build/fmus with every FMU of the catalog, built now if missing or stale."""
    from fmus.build import build_all
    from fmus.catalog import CATALOG

    if _stale(CATALOG):
        build_all(FMU_DIR, list(CATALOG))
    os.environ["FTCSIM_FMU_DIR"] = str(FMU_DIR)
    return FMU_DIR


@pytest.fixture(scope="session")
def scenarios() -> Path:
    return SCENARIOS
