"""The Python API for notebooks and scripts (``import ftcsim``), and the one path that runs a scenario:
``ftcsim run`` calls :func:`run` too.

>>> import ftcsim
>>> ftcsim.scenarios()                                   # the shipped scenarios
>>> r = ftcsim.run("li2023_fasmc", stop=60, step=0.01,
...                parameters={"plant.fault_scale": 0.2}, mode="inprocess")
>>> r.df["ctrl.u[1]"].plot()                             # pandas DataFrame indexed by time (s)
>>> r.metrics["final_attitude_error"]

``run`` takes a shipped scenario name, a ``.toml`` file or an ``.ssp`` package (or a scenario
from :func:`load`), applies the overrides (start/stop/step in s, parameters as
``{"instance.parameter": value}`` with arrays for vector and matrix parameters, design files as
``gains``), runs it and returns a :class:`Result`. Nothing is written to disk unless ``out`` is
given (then exactly what ``ftcsim run --out`` writes). Bad input raises
:class:`orchestrator.common.errors.InputError`.

``campaign(file, out)`` runs (or resumes) a campaign like ``ftcsim campaign`` and returns its
summary table (docs/campaigns.md).
"""
from __future__ import annotations

import contextlib
from dataclasses import dataclass, field

from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.store import SUMMARY
from orchestrator.common.errors import InputError
from orchestrator.common.interrupt import handling_signals
from orchestrator.common.jsonio import strict_json
from orchestrator.common.outputs import OutputFolder
from orchestrator.common.watchdog import check_limit
from orchestrator.cosim.runner import run_scenario
from orchestrator.results.files import write_results
from orchestrator.results.metrics import compute_metrics
from orchestrator.scenario.loading import load_scenario
from orchestrator.scenario.model import Scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.shipped import scenario_files
from orchestrator.scenario.toml import describe

__all__ = ["InputError", "Result", "campaign", "load", "run", "scenarios"]


@dataclass
class Result:
    """One run: ``df`` (time index in s, one column per recorded signal), ``metrics`` (the dict
    of metrics.json), ``complete`` and ``error``, and the raw :class:`RunResult` and scenario;
    ``errors``: what failed after the run (metrics, plots) when it was written to a folder."""

    df: object
    metrics: dict
    raw: object
    scenario: object
    errors: list = field(default_factory=list)

    @property
    def complete(self) -> bool:
        return self.raw.complete

    @property
    def error(self):
        return self.raw.error


def scenarios():
    """The shipped scenarios as a DataFrame: name (index), paper, description, file."""
    import pandas as pd

    rows = []
    for name, path in scenario_files().items():
        paper, description = describe(path)
        rows.append({"name": name, "paper": paper, "description": description, "file": str(path)})
    return pd.DataFrame(rows).set_index("name")


def load(scenario, *, mode="fmu", fmu_dir=None, start=None, stop=None, step=None, parameters=None, gains=()) -> Scenario:
    """A validated scenario with the overrides applied (see the module docstring)."""
    return load_scenario(scenario, mode=mode, fmu_dir=fmu_dir, start=start, stop=stop, step=step,
                         parameters=parameters, gains=gains, src="api")


def run(scenario, *, mode="fmu", exchange=None, out=None, overwrite=False, progress=False, plots=False,
        signals=False, time_limit=None, **overrides) -> Result:
    """Run a scenario by name or path with overrides (or a scenario from :func:`load`, with start,
    stop, parameters or gains overrides); returns a :class:`Result`.

    ``out``: a results folder to write (``results.csv``, ``metrics.json``, with ``plots`` one PNG per
    instance), or an :class:`orchestrator.common.outputs.OutputFolder` not yet checked;
    ``signals``: SIGINT / SIGTERM stop the run at the next communication point, the rows so far kept
    (``ftcsim run``); ``time_limit``: s of wall time of the stepping, then the run ends incomplete
    (None: the scenario's ``[timing] time_limit``, if any; 0: none)."""
    limit = None if time_limit is None else check_limit(time_limit, "api", "time_limit")
    if isinstance(scenario, Scenario):
        for key in ("step", "fmu_dir"):
            if overrides.get(key) is not None:
                raise InputError("api", key, "applies when a scenario is loaded: give it to ftcsim.load")
        sc = with_overrides(scenario, **{k: v for k, v in overrides.items() if k not in ("step", "fmu_dir")})
    else:
        sc = load(scenario, mode=mode, **overrides)
    folder = None
    if out is not None:
        folder = out if isinstance(out, OutputFolder) else OutputFolder(out, "run", overwrite=overwrite, source="api",
                                                                          key="out")
        folder.check()
    try:
        with handling_signals() if signals else contextlib.nullcontext():
            raw = run_scenario(sc, exchange=exchange, progress=progress,
                               time_limit=sc.time_limit if time_limit is None else limit)
    except BaseException:
        if folder is not None:
            folder.discard()
        raise
    errors = []
    if folder is not None:
        metrics, errors = write_results(folder, raw, sc, plots=plots)
    else:
        metrics = strict_json(compute_metrics(raw, sc))
    import pandas as pd  # 0.4 s: not on the command line's path

    df = pd.DataFrame(raw.data, index=pd.Index(raw.time, name="time"), columns=raw.columns)
    return Result(df=df, metrics=metrics, raw=raw, scenario=sc, errors=errors)


def campaign(campaign_file, out, *, workers=None, scheduler=None, overwrite=False, only=None, progress=False,
             time_limit=None):
    """Run or resume a campaign (``ftcsim campaign``) into ``out``; returns the summary table
    (a pandas DataFrame, one row per stored run). ``workers=0``: in this process, without Dask.
    ``time_limit``: s of wall time per run (default: the campaign file's, else 3600 s; 0: none)."""
    import pandas as pd

    o = run_campaign(campaign_file, out, workers=workers, scheduler=scheduler, overwrite=overwrite, only=only,
                     progress=progress, time_limit=time_limit if time_limit is None
                     else check_limit(time_limit, "api", "time_limit") or 0)
    return pd.read_parquet(o.folder / SUMMARY)
