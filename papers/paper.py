"""What a paper declares about itself (its ``paper.py`` holds one :class:`Paper`).

Strings of the form ``"package.module:attribute"`` are resolved lazily (:func:`resolve`), so
reading the registry imports nothing heavy: an FMU, a design or a report is imported only
when it is used.
"""
from __future__ import annotations

import dataclasses
import importlib
from dataclasses import dataclass, field


def resolve(ref: str):
    """``"pkg.mod:attr"`` -> the attribute (``"pkg.mod"`` -> the module)."""
    module, _, attr = ref.partition(":")
    m = importlib.import_module(module)
    return getattr(m, attr) if attr else m


@dataclass(frozen=True)
class FMUSpec:
    """One FMU of the paper: its model name and the factory returning its configured block."""

    model: str  # FMU model name, e.g. "FAFEO" (also the file name build/fmus/FAFEO.fmu)
    factory: str  # "papers.p000_li2023.blocks:fafeo": a function returning a fresh block
    description: str = ""
    requires: str = ""  # a module of an optional extra the block needs ("Basilisk": ftcsim[basilisk]); "" none

    def available(self) -> bool:
        """False if the optional module the block needs is not installed (``ftcsim build`` then skips it)."""
        import importlib.util

        return not self.requires or importlib.util.find_spec(self.requires) is not None


@dataclass(frozen=True)
class OptionSpec:
    """A command-line option of a design (``ftcsim design NAME --OPTION ...``)."""

    name: str  # python name, e.g. "omega_hat" (CLI --omega-hat)
    help: str
    nargs: str | None = None  # "+" for a list of floats
    check: str = "finite"  # finite | positive | unit_interval (0, 1] | fraction [0, 1)


@dataclass(frozen=True)
class DesignSpec:
    """An LMI design: ``module.run_design(**options) -> (result, summary)`` (``ftcsim design`` writes the
    result after every check passed), ``module.gains_from_file(get) -> gains`` and
    ``module.verify_report(gains or None, source) -> (ok, title, {check: holds})``."""

    name: str  # CLI name, e.g. "li2023-observer"
    module: str  # "papers.p000_li2023.design_observer"
    title: str  # "000 Theorem 1, (23)-(24)"
    options: tuple = ()  # OptionSpec, ...


@dataclass(frozen=True)
class Paper:
    id: str  # "000"
    key: str  # "li2023": prefix of its scenario names and parameter sets
    title: str
    package: str  # "papers.p000_li2023"
    fmus: tuple = ()  # FMUSpec, ...
    parameter_sets: dict = field(default_factory=dict)  # name -> "module:ATTR" (dict base name -> array)
    designs: tuple = ()  # DesignSpec, ...
    metrics: str | None = None  # "module:function(result, cfg) -> dict" of paper-specific metrics
    report: str | None = None  # "module:function(runs, out) -> dict" drawing the paper's figures
    demo: tuple = ()  # scenario names `make demo` runs
    benchmarks: tuple = ()  # (scenario name, step override or None, repeats), for `make bench`


def declare(id: str, key: str, title: str, *, fmus, parameters: str, designs=(), demo=(), benchmarks=(),
            report: bool = True) -> Paper:
    """The :class:`Paper` of a folder laid out as README.md says, ``papers/p<id>_<key>/``:

    * ``fmus``: ``(model, factory, description), ...`` with ``factory`` a function of its ``blocks.py``;
    * ``parameters``: the attribute of its ``parameters.py`` holding its parameter set (named ``key``);
    * ``designs``: :class:`DesignSpec`, whose ``module`` may be relative to the package (``".design_cli"``);
    * its metrics ``metrics.py:metrics`` and, unless ``report=False`` (a paper still without
      one: ``ftcsim report`` then says so), its report ``report.py:make_report``.
    """
    package = f"papers.p{id}_{key}"
    return Paper(
        id=id, key=key, title=title, package=package,
        fmus=tuple(FMUSpec(model, f"{package}.blocks:{factory}", description) for model, factory, description in fmus),
        parameter_sets={key: f"{package}.parameters:{parameters}"},
        designs=tuple(dataclasses.replace(d, module=package + d.module) if d.module.startswith(".") else d for d in designs),
        metrics=f"{package}.metrics:metrics", report=f"{package}.report:make_report" if report else None, demo=tuple(demo),
        benchmarks=tuple(benchmarks),
    )
