"""The registry of papers: every command that iterates papers (``ftcsim scenarios``, ``build``,
``design``, ``verify``, ``report``, the benchmarks) reads it from here.

A new paper adds one line to :data:`PAPER_MODULES` and a folder ``papers/pNNN_<key>/`` with its
``paper.py`` (a :class:`papers.paper.Paper`), data modules, designs, metrics, report, README
and ``scenarios/``.
"""
from __future__ import annotations

from functools import cache
from pathlib import Path

from diagnosis.catalog import FMUS as DIAGNOSIS_FMUS

from .paper import FMUSpec, Paper, resolve

PAPER_MODULES = (
    "papers.p000_li2023.paper",
    "papers.p001_zhang2019.paper",
    "papers.p002_zhang2014.paper",
    "papers.p003_hang2023.paper",
    "papers.p004_xu2024.paper",
)

# FMUs that belong to no paper (scenario sources as an FMU, for SSP packages; the decision layer and
# the sensor faults, diagnosis/catalog.py)
GENERIC_FMUS = (
    FMUSpec("PiecewiseConstantSource", "plant.signals:PiecewiseConstantSource",
            "piecewise-constant signal source (scenario sources in SSP packages)"),
    # the Basilisk bridge's plant (orchestrator/interop/basilisk/spacecraft.py): a string, as every factory here;
    # built only where the optional extra ftcsim[basilisk] (bsk) is installed
    FMUSpec("BasiliskSpacecraft4", "orchestrator.interop.basilisk.spacecraft:basilisk_spacecraft_4",
            "Basilisk spacecraft: hub, 4 reaction wheels (momentum, limits, friction), gravity gradient", requires="Basilisk"),
    *(FMUSpec(model, factory, description) for model, factory, description in DIAGNOSIS_FMUS),
)

# calibrated decision thresholds shipped as parameter sets (``ftcsim fdir calibrate`` wrote the files):
# set name -> "module:ATTR" (the attribute reads the calibration file, docs/fdir.md)
FDIR_SETS = {"zhang2019_fdir_wheel_loss": "papers.p001_zhang2019.fdir:ZHANG2019_FDIR_WHEEL_LOSS"}


# applications on top of the orchestrator that it reaches by name (floor 5): command -> "module:function"
APPLICATIONS = {"arena": "arena.app:command", "arena-format": "arena.arenafile:arena_format"}  # and its file format


@cache
def papers() -> tuple[Paper, ...]:
    return tuple(resolve(m + ":PAPER") for m in PAPER_MODULES)


def paper(ident: str) -> Paper:
    """A paper by id ("000") or key ("li2023"); ``KeyError`` lists the known ones."""
    for p in papers():
        if ident in (p.id, p.key):
            return p
    raise KeyError(f"unknown paper {ident!r} (known: {', '.join(p.id + ' ' + p.key for p in papers())})")


def folder(p: Paper) -> Path:
    return Path(resolve(p.package).__file__).parent


def fmu_specs() -> dict[str, FMUSpec]:
    """FMU model name -> spec, generic FMUs first, then every paper's, in registry order, then the
    arena's (adapters, fault catalog, hardware: ``arena/catalog.py``)."""
    from arena.catalog import fmu_specs as arena_fmus

    out = {s.model: s for s in GENERIC_FMUS}
    for owner, specs in [(f"paper {p.id}", p.fmus) for p in papers()] + [("the arena", arena_fmus())]:
        for s in specs:
            if s.model in out:
                raise ValueError(f"FMU model {s.model!r} registered twice ({owner})")
            out[s.model] = s
    return out


def block_factory(model: str):
    """The callable returning a fresh, configured block for FMU model ``model`` (``KeyError`` if not ours)."""
    return resolve(fmu_specs()[model].factory)


def parameter_sets() -> dict[str, str]:
    """Parameter-set name -> ``"module:ATTR"`` reference: every paper's, the shipped FDIR calibrations
    (:data:`FDIR_SETS`), then the arena's
    (cross-application models and gains, hardware data sheets: ``arena/parameters.py``)."""
    from arena.catalog import parameter_sets as arena_sets

    out = {}
    for p in papers():
        out.update(p.parameter_sets)
    for name, ref in [*FDIR_SETS.items(), *arena_sets().items()]:
        if name in out:
            raise ValueError(f"parameter set {name!r} registered twice (the arena or FDIR_SETS)")
        out[name] = ref
    return out


ARENA_SCENARIOS = Path(__file__).resolve().parents[1] / "arena" / "scenarios"


def scenario_files() -> dict[str, Path]:
    """Shipped scenario name (file stem) -> path, over every paper's ``scenarios/``, then the arena's
    cross-applied scenarios (``arena/scenarios/``)."""
    out = {}
    folders = [folder(p) / "scenarios" for p in papers()] + [ARENA_SCENARIOS]
    for d in folders:
        for f in sorted(d.glob("*.toml")):
            if f.stem in out:
                raise ValueError(f"scenario name {f.stem!r} shipped twice ({out[f.stem]} and {f})")
            out[f.stem] = f
    return out


def designs() -> dict:
    """Design name -> (paper, DesignSpec)."""
    return {d.name: (p, d) for p in papers() for d in p.designs}
