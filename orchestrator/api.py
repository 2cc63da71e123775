"""The Python API for notebooks and scripts (``import ftcsim``).

>>> import ftcsim
>>> ftcsim.scenarios()                                   # the shipped scenarios
>>> r = ftcsim.run("li2023_fasmc", stop=60, step=0.01,
...                parameters={"plant.fault_scale": 0.2}, mode="inprocess")
>>> r.df["ctrl.u[1]"].plot()                             # pandas DataFrame indexed by time (s)
>>> r.metrics["final_attitude_error"]

``run`` takes a shipped scenario name, a ``.toml`` file or an ``.ssp`` package, applies the
overrides (start/stop/step in s, parameters as ``{"instance.parameter": value}`` with arrays
for vector and matrix parameters, design files as ``gains``), runs it and returns a
:class:`Result`. Nothing is written to disk unless ``out`` is given (then exactly what
``ftcsim run --out`` writes). Bad input raises :class:`orchestrator.common.errors.InputError`.

``campaign(file, out)`` runs (or resumes) a campaign like ``ftcsim campaign`` and returns its
summary table (docs/campaigns.md).
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from orchestrator.common.errors import InputError

__all__ = ["Result", "campaign", "load", "run", "scenarios"]


@dataclass
class Result:
    """One run: ``df`` (time index in s, one column per recorded signal), ``metrics`` (the dict
    of metrics.json), ``complete`` and ``error``, and the raw :class:`RunResult` and scenario."""

    df: object
    metrics: dict
    raw: object
    scenario: object

    @property
    def complete(self) -> bool:
        return self.raw.complete

    @property
    def error(self):
        return self.raw.error


def scenarios():
    """The shipped scenarios as a DataFrame: name (index), paper, description, file."""
    import pandas as pd

    from orchestrator.scenario.toml import describe
    from papers.registry import scenario_files

    rows = []
    for name, path in scenario_files().items():
        paper, description = describe(path)
        rows.append({"name": name, "paper": paper, "description": description, "file": str(path)})
    return pd.DataFrame(rows).set_index("name")


def load(scenario, *, mode="fmu", fmu_dir=None, start=None, stop=None, step=None, parameters=None, gains=()):
    """A validated scenario with the overrides applied (see the module docstring)."""
    from orchestrator.scenario.checks import check_timing
    from orchestrator.scenario.overrides import apply_gains, expand_parameters
    from orchestrator.scenario.shipped import resolve_scenario
    from orchestrator.scenario.toml import load as load_toml

    path = resolve_scenario(str(scenario))
    in_process = mode == "inprocess"
    if mode not in ("fmu", "inprocess"):
        raise InputError("api", "mode", f"must be 'fmu' or 'inprocess', not {mode!r}")
    if path.suffix == ".ssp":
        from orchestrator.scenario.ssp import load_ssp

        sc = load_ssp(path, in_process=in_process, step=step)
    else:
        sc = load_toml(path, fmu_dir=fmu_dir, in_process=in_process, step=step)
    for key, value in (("start", start), ("stop", stop)):
        if value is not None:
            from orchestrator.scenario.values import number

            setattr(sc, key, number("api", key, value))
    check_timing("api", sc.start, sc.stop, sc.step, key="run")
    for g in [gains] if isinstance(gains, (str, Path)) else gains or ():
        apply_gains(sc, g)
    for ref, value in (parameters or {}).items():
        inst, _, name = str(ref).partition(".")
        if inst not in sc.instances or not name:
            raise InputError("api", f"parameters.{ref}", f"expected 'instance.parameter' with an instance of "
                             f"{', '.join(sc.instances)}")
        i = sc.instances[inst]
        i.parameters.update(expand_parameters("api", f"parameters.{inst}", i.interface, {name: value}))
    return sc


def run(scenario, *, mode="fmu", exchange=None, out=None, overwrite=False, progress=False, **overrides) -> Result:
    """Run a scenario by name or path with overrides; returns a :class:`Result`."""
    import pandas as pd

    from orchestrator.scenario.checks import check_run_size

    from .results import compute_metrics, strict_json, write_results
    from .runner import run_scenario

    sc = load(scenario, mode=mode, **overrides)
    check_run_size(sc)
    folder = None
    if out is not None:
        from orchestrator.common.outputs import OutputFolder

        folder = OutputFolder(out, "run", overwrite=overwrite, source="api", key="out").check()
    try:
        raw = run_scenario(sc, mode=mode, exchange=exchange, progress=progress)
    except BaseException:
        if folder is not None:
            folder.discard()
        raise
    if folder is not None:
        metrics, _ = write_results(folder, raw, sc, plots=False)
    else:
        metrics = strict_json(compute_metrics(raw, sc))
    df = pd.DataFrame(raw.data, index=pd.Index(raw.time, name="time"), columns=raw.columns)
    return Result(df=df, metrics=metrics, raw=raw, scenario=sc)


def campaign(campaign_file, out, *, workers=None, scheduler=None, overwrite=False, only=None, progress=False):
    """Run or resume a campaign (``ftcsim campaign``) into ``out``; returns the summary table
    (a pandas DataFrame, one row per stored run). ``workers=0``: in this process, without Dask."""
    import pandas as pd

    from .campaign_run import SUMMARY, run_campaign

    o = run_campaign(campaign_file, out, workers=workers, scheduler=scheduler, overwrite=overwrite, only=only,
                     progress=progress)
    return pd.read_parquet(o.folder / SUMMARY)
