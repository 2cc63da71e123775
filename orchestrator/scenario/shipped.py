"""The one door from the orchestrator to what ships with it: the paper registry (shipped scenarios, parameter
sets, metric keys, the in-process blocks) and the repository's folders (built FMUs, shipped campaigns).
Only this module and ``orchestrator/results/`` read ``papers.registry``."""
from __future__ import annotations

import os
from pathlib import Path

from fmus.build import fmu_root
from orchestrator.common.errors import InputError
from orchestrator.scenario.values import closest
from papers.paper import resolve
from papers.registry import APPLICATIONS, designs, fmu_specs, paper, papers, parameter_sets, scenario_files  # noqa: F401 (door)
from plant.block import structured_values

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_FMU_DIR = fmu_root()  # build/fmus of a checkout, else the user's data folder (fmus/build.py)
METRIC_KEYS = {"attitude_error": "signal", "rate_error": "signal", "control": "signal", "u_max": "number"}


def application(name: str):
    """An application the registry names (``papers/registry.py: APPLICATIONS``), e.g. the arena's command."""
    return resolve(APPLICATIONS[name])


def structured_parameter_set(name: str) -> dict:
    """A paper's parameter set (``papers/registry.py``) as structured scalar names (``J[1,2]``)."""
    out = {}
    for base, value in resolve(parameter_sets()[name]).items():
        out.update(structured_values(base, value))
    return out


def metric_keys(paper_id: str) -> dict:
    """[metrics] keys a scenario of ``paper_id`` may use: generic ones and its paper's ``KEYS``."""
    keys = dict(METRIC_KEYS)
    try:
        p = paper(paper_id)
    except KeyError:
        return keys
    if p.metrics:
        keys.update(getattr(resolve(p.metrics.partition(":")[0]), "KEYS", {}))
    return keys


def paper_metrics_of(paper_id: str) -> str | None:
    """The ``module:function`` of the metrics paper ``paper_id`` defines, or None."""
    try:
        return paper(paper_id).metrics
    except KeyError:
        return None


def fmu_folder(given=None) -> Path:
    """The folder of built FMUs: ``given``, else ``$FTCSIM_FMU_DIR``, else ``build/fmus``."""
    return Path(given or os.environ.get("FTCSIM_FMU_DIR") or DEFAULT_FMU_DIR)


def catalog() -> dict:
    """Model name -> ``FMUSpec`` of every shipped FMU (the in-process blocks too)."""
    return fmu_specs()


def block_factory(model: str | None, src="-", key="-", what=None):
    """The factory of the in-process block of FMU model ``model``; an ``InputError`` naming
    ``src`` and ``key`` if no shipped FMU has that model name."""
    known = fmu_specs()
    if model not in known:
        raise InputError(src, key, f"'{what or model}' has no in-process block (known: {', '.join(known)})")
    return resolve(known[model].factory)


def resolve_scenario(arg: str) -> Path:
    """A scenario argument: an existing file, or the name of a shipped scenario."""
    p = Path(arg)
    if p.suffix in (".toml", ".ssp") or os.sep in arg or p.exists():
        return p
    files = scenario_files()
    if arg in files:
        return files[arg]
    close = closest(arg, files)
    hint = f"did you mean {close!r}? " if close else ""
    raise InputError("command line", "SCENARIO", f"{arg!r} is neither a file nor a shipped scenario ({hint}"
                     "`ftcsim scenarios` lists them)")


def campaign_file(arg: str) -> Path:
    """A campaign file: a path, or the name of a shipped one (``campaigns/NAME.toml``)."""
    p = Path(arg)
    if p.suffix == ".toml" or "/" in arg:
        if not p.is_file():
            raise InputError("command line", "--campaign", f"campaign file not found: {p}")
        return p
    shipped = ROOT / "campaigns" / f"{arg}.toml"
    if not shipped.is_file():
        known = sorted(q.stem for q in (ROOT / "campaigns").glob("*.toml"))
        raise InputError("command line", "--campaign", f"no shipped campaign {arg!r} (shipped: {', '.join(known)}; "
                                                      "or give a .toml file)")
    return shipped
