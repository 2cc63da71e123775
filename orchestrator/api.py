"""The Python API for notebooks and scripts (``import ftcsim``), and the one path that runs a scenario:
``ftcsim run`` calls :func:`run` too.

>>> import ftcsim
>>> ftcsim.scenarios()                                   # the shipped scenarios
>>> r = ftcsim.run("li2023_fasmc", stop=60, step=0.01,
...                parameters={"plant.fault_scale": 0.2}, mode="inprocess")
>>> r.df["ctrl.u[1]"].plot()                             # pandas DataFrame indexed by time (s)
>>> r.metrics["final_attitude_error"], r.units["ctrl.u[1]"]  # values only; settings in r.info
>>> r.plot(["ctrl.u"])                                   # matplotlib, axes with units
>>> r = ftcsim.run("li2023_fasmc", out="results/fasmc")  # results.parquet + metrics.json
>>> ftcsim.open("results/fasmc")                         # the same Result, read back

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
import html
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from orchestrator.campaign.multi import run_campaigns
from orchestrator.campaign.run import run_campaign
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.campaign.store import SUMMARY, TRAJECTORIES, run_file
from orchestrator.common.digest import digest, file_digest, source_digest  # what decides a stored result (arena)
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import Interrupted, handling_signals
from orchestrator.common.outputs import OutputFolder, check_target
from orchestrator.common.parquet import read_table, write_table
from orchestrator.common.reading import read_toml, referenced  # the one reader, for the arena's files
from orchestrator.common.watchdog import check_limit
from orchestrator.cosim.runner import run_scenario
from orchestrator.results.files import Run, check_format, fmu_digests, frame, signal_figure, summary, thin, write_parquet, write_results
from orchestrator.results.metrics import signal_units
from orchestrator.scenario import declared  # the vocabulary of declared file formats (the arena's file)
from orchestrator.scenario.loading import load_scenario
from orchestrator.scenario.model import Scenario
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.shipped import campaign_file as shipped_campaign_file
from orchestrator.scenario.shipped import scenario_files
from orchestrator.scenario.toml import describe
from orchestrator.scenario.values import is_number, number, seconds, whole
from plant.units import pretty

__all__ = ["InputError", "Result", "campaign", "campaigns", "check_readable", "check_target", "declared", "digest",
           "fdir_calibrate", "file_digest", "load", "open", "output_folder", "plan_campaign", "reach_scheduler",
           "read_table", "read_toml", "referenced", "run", "scenarios", "scheduler_file_address", "source_digest",
           "start_local_cluster", "trajectory_file", "write_table"]


def output_folder(path, kind: str, overwrite: bool = False, source: str = "api", key: str = "out") -> OutputFolder:
    """A checked output folder for a tool that writes one (a study, a report): refused before any work
    if it exists and ftcsim did not write it (or wrote another ``kind``), or without ``overwrite``;
    write with ``.fill(write)`` (staged, published atomically). ``orchestrator.common.outputs``."""
    return OutputFolder(path, kind, overwrite=overwrite, source=source, key=key).check()


@dataclass(eq=False)
class Result:
    """One run, as :func:`run` returns it and :func:`open` reads it back from its folder.

    ``df``: pandas DataFrame indexed by time (s), one column per recorded signal,
    ``df.attrs["units"]``; ``units``: column -> unit (the FMU's or block's declaration, "time": "s");
    ``metrics``: the values measured in the run (metrics.json's "metrics"), ``metric_units`` their
    units where known; ``info``: what describes the run (scenario, complete, error, mode, step
    statistics, signals, FMU SHA-256, ...); ``raw``: the :class:`RunResult`; ``scenario``: the
    scenario that ran (None when read from a folder); ``errors``: what failed after the run
    (metrics, plots) when it was written to a folder; ``folder``: where it was written, if it was."""

    df: object
    metrics: dict
    raw: object
    scenario: object = None
    errors: list = field(default_factory=list)
    units: dict = field(default_factory=dict)
    metric_units: dict = field(default_factory=dict)
    info: dict = field(default_factory=dict)
    folder: object = None

    def __eq__(self, other) -> bool:
        """Equal recorded rows (time and values, bit for bit), units, metrics and info."""
        if not isinstance(other, Result):
            return NotImplemented
        a, b = self.df, other.df
        return (list(a.columns) == list(b.columns) and a.shape == b.shape
                and bool((a.index.to_numpy() == b.index.to_numpy()).all())
                and bool(((a.to_numpy() == b.to_numpy()) | (a.isna().to_numpy() & b.isna().to_numpy())).all())
                and self.units == other.units and self.metrics == other.metrics
                and self.metric_units == other.metric_units and self.info == other.info)

    __hash__ = None

    @property
    def complete(self) -> bool:
        return self.raw.complete

    @property
    def error(self):
        return self.raw.error

    @property
    def name(self) -> str:
        return str(self.info.get("scenario") or getattr(self.scenario, "name", ""))

    def plot(self, signals=None, instance=None):
        """A matplotlib figure: one panel per recorded vector signal (``signals``: their names, e.g.
        ``["ctrl.u"]``; ``instance``: only that instance's), axes labelled with units."""
        cols = list(self.df.columns)
        if signals is not None:
            wanted = [signals] if isinstance(signals, str) else list(signals)
            unknown = [w for w in wanted if not any(c == w or c.startswith(w + "[") for c in cols)]
            if unknown:
                raise InputError("api", "signals", f"no recorded signal {unknown[0]!r}; recorded: "
                                                   f"{', '.join(dict.fromkeys(c.split('[')[0] for c in cols))}")
            cols = [c for c in cols if any(c == w or c.startswith(w + "[") for w in wanted)]
        data = self.df[cols].to_numpy()
        title = self.name + ("" if self.complete else " (INCOMPLETE)")
        return signal_figure(self.df.index.to_numpy(), cols, data, self.units, title, instance)

    def to_parquet(self, path) -> None:
        """The recorded signals as one Parquet file (``time`` then the signals; units in the fields'
        metadata), written atomically; ``path`` is a file, replaced if it exists."""
        write_parquet(path, self.df.index.to_numpy(), list(self.df.columns), self.df.to_numpy(), self.units)

    def _repr_html_(self) -> str:
        e = html.escape
        t = self.df.index
        head = (f"<b>{e(self.name)}</b>: {len(t)} rows x {len(self.df.columns)} signals, "
                f"t = {t[0] if len(t) else 0:g} .. {t[-1] if len(t) else 0:g} s, "
                + ("complete" if self.complete else f"<b>INCOMPLETE</b>: {e(str(self.error))}"))
        rows = "".join(f"<tr><td>{e(k)}</td><td>{e(_short(v))}</td><td>{e(pretty(self.metric_units.get(k)) or '')}</td></tr>"
                       for k, v in self.metrics.items())
        table = f"<table><tr><th>metric</th><th>value</th><th>unit</th></tr>{rows}</table>" if rows else ""
        where = f"<br>folder: {e(str(self.folder))}" if self.folder is not None else ""
        return f"<div>{head}{where}{table}</div>"


def _short(v) -> str:
    return f"{v:.6g}" if isinstance(v, float) else str(v)


def scenarios():
    """The shipped scenarios as a DataFrame: name (index), paper ("" for an arena scenario), source
    (the paper's id, or "arena" for the arena's cross-applied scenarios), description, file."""
    import pandas as pd

    rows = []
    for name, path in scenario_files().items():
        paper, description = describe(path)
        rows.append({"name": name, "paper": paper, "source": scenario_source(path, paper), "description": description,
                     "file": str(path)})
    return pd.DataFrame(rows).set_index("name")


def scenario_source(path, paper: str) -> str:
    """Where a shipped scenario comes from: its paper's id, or "arena" (``arena/scenarios/``)."""
    return "arena" if Path(path).parent.parent.name == "arena" else (paper or "-")


def load(scenario, *, mode="fmu", fmu_dir=None, start=None, stop=None, step=None, parameters=None, gains=()) -> Scenario:
    """A validated scenario with the overrides applied (see the module docstring)."""
    return load_scenario(scenario, mode=mode, fmu_dir=fmu_dir, start=start, stop=stop, step=step,
                         parameters=parameters, gains=gains, src="api")


def run(scenario, *, start=None, stop=None, step=None, parameters=None, gains=(), mode="fmu", fmu_dir=None,
        exchange=None, record_step=None, out=None, overwrite=False, format="parquet", plots=False, progress=False,
        signals=False, time_limit=None) -> Result:
    """Run a scenario by name or path (or a scenario from :func:`load`) and return a :class:`Result`.

    ``start``, ``stop``, ``step`` (s), ``parameters`` (``{"instance.parameter": value}``),
    ``gains`` (design files), ``mode`` ("fmu" or "inprocess"), ``fmu_dir``: see :func:`load`
    (``step``, ``mode`` and ``fmu_dir`` only for a name or path); ``exchange``: "ordered" or
    "jacobi" instead of the scenario's; ``record_step`` (s): keep every row on that grid only (a
    whole multiple of the step; the last row is always kept; the metrics come from every step
    all the same); None: every row, except that a run written to ``out`` with ``step`` finer than
    the file's records on the file's step (:func:`default_record_step`); ``out``: a results
    folder to write (``results.parquet``, or ``results.csv`` with ``format="csv"``,
    ``metrics.json``, with ``plots`` one PNG per instance), replacing a previous ftcsim result
    only with ``overwrite``; ``signals``: SIGINT / SIGTERM stop the run at the next
    communication point, the rows so far kept (``ftcsim run``); ``time_limit``: s of wall time of
    the stepping, then the run ends incomplete (None: the scenario's ``[timing] time_limit``, if
    any; 0: none)."""
    check_format(format)
    limit = None if time_limit is None else check_limit(time_limit, "api", "time_limit")
    if isinstance(scenario, Scenario):
        for key, value in (("step", step), ("fmu_dir", fmu_dir)):
            if value is not None:
                raise InputError("api", key, "applies when a scenario is loaded: give it to ftcsim.load")
        sc = with_overrides(scenario, start=start, stop=stop, parameters=parameters, gains=gains)
    else:
        sc = load(scenario, mode=mode, fmu_dir=fmu_dir, start=start, stop=stop, step=step, parameters=parameters,
                  gains=gains)
    record_step = check_record_step(record_step, sc)
    if record_step is None and out is not None and not isinstance(scenario, Scenario) and step is not None:
        record_step = default_record_step(sc, load(scenario, mode=mode, fmu_dir=fmu_dir))
    folder = None
    if out is not None:
        folder = out if isinstance(out, OutputFolder) else OutputFolder(out, "run", overwrite=overwrite, source="api",
                                                                          key="out")
        folder.check()
    try:
        digests = fmu_digests(sc)
        with handling_signals() if signals else contextlib.nullcontext():
            raw = run_scenario(sc, exchange=exchange, progress=progress,
                               time_limit=sc.time_limit if time_limit is None else limit)
    except BaseException:
        if folder is not None:
            folder.discard()
        raise
    info = {"fmus": digests}
    errors = []
    if folder is not None and len(raw.time) == 0:  # failed before its first row: nothing to publish, nothing replaced
        folder.discard()
        previous = "the previous result there is unchanged" if folder.path.exists() else "nothing was written"
        message = f"{raw.error or 'the run recorded no row'}; no row was recorded, so {previous} ({folder.path})"
        if raw.interrupted:
            raise Interrupted(message, 128 + raw.interrupted)
        raise SimulationError(message)
    if folder is not None:
        doc, errors = write_results(folder, raw, sc, plots=plots, fmt=format, info=info, record_step=record_step)
    else:
        doc, _ = summary(raw, sc, {"record_step": record_step, **info})
    raw = thin(raw, sc.start, record_step)  # after the metrics: they come from every row
    units = signal_units(sc, raw.columns)
    df = frame(raw.time, raw.columns, raw.data, units)
    return Result(df=df, metrics=doc["metrics"], raw=raw, scenario=sc, errors=errors, units=units,
                  metric_units=doc["units"], info=doc["info"], folder=None if folder is None else folder.path)


def open(folder) -> Result:  # noqa: A001 (ftcsim.open, like pandas.read_*: the reader of a run folder)
    """The :class:`Result` of a run folder that ``ftcsim run`` or ``run(..., out=folder)`` wrote:
    equal to the one ``run`` returned (time, values, units, metrics, info). Bad folders raise
    :class:`InputError`."""
    if not isinstance(folder, (str, os.PathLike)):
        raise InputError("api", "folder", f"expected a run folder (a path), got {type(folder).__name__}")
    r = Run(Path(folder))
    units = {"time": "s", **r.units} if r.units else {}
    df = frame(r.t, r.header[1:], r.data[:, 1:], units)
    return Result(df=df, metrics=r.metrics, raw=r.result, scenario=None, units=units, metric_units=r.metric_units,
                  info=r.info, folder=Path(folder))


def default_record_step(scenario, as_declared):
    """The record step of a written run when none is given: the step ``as_declared`` (the scenario
    as its file declares it) records at, if the run's step was refined below it (a finer
    ``--step`` does not multiply the files; the metrics still come from every step), else None
    (every row)."""
    declared, h = as_declared.output_step, scenario.output_step
    k = declared / h
    if k > 1 + 1e-9 and abs(k - round(k)) <= 1e-9 * k:
        return float(declared)
    return None


def check_record_step(record_step, scenario):
    """``record_step`` as a float (None: every row); an :class:`InputError` unless it is a finite
    number that is a whole multiple of the recorded grid's step."""
    if record_step is None:
        return None
    if not is_number(record_step) or not math.isfinite(float(record_step)) or record_step <= 0:
        raise InputError("api", "record_step", f"must be a finite number of seconds > 0, got {record_step!r}")
    record_step = float(record_step)
    h = scenario.output_step
    if record_step > scenario.stop - scenario.start:
        raise InputError("api", "record_step", f"{record_step:g} s is longer than the run ({scenario.stop - scenario.start:g} s)")
    k = record_step / h
    if round(k) < 1 or abs(k - round(k)) > 1e-9 * max(1.0, k):
        raise InputError("api", "record_step", f"{record_step:g} s is not a whole multiple of the step {h:g} s")
    return float(record_step)


def campaign(campaign_file, out, *, workers=None, scheduler=None, overwrite=False, only=None, progress=False,
             runs=None, stop=None, time_limit=None, client=None, cluster=None, scheduler_file=None, **options):
    """Run or resume a campaign (``ftcsim campaign``) into ``out``; returns the summary table
    (a pandas DataFrame, one row per stored run). ``workers=0``: in this process, without Dask;
    ``runs``, ``stop`` (s): instead of the file's (``ftcsim campaign --runs/--stop``);
    ``time_limit``: s of wall time per run (default: the campaign file's, else 3600 s; 0: none).
    On an existing cluster: ``client`` (a ``distributed.Client``, left open), ``cluster`` (a
    ``LocalCluster``, dask-jobqueue ``SLURMCluster``, dask-kubernetes ``KubeCluster``: anything with
    ``scheduler_address``), ``scheduler`` (address) or ``scheduler_file``; no global Dask
    configuration is changed. ``options``: further keywords of
    :func:`orchestrator.campaign.run.run_campaign` (``connect_timeout``, ``batch``, ...)."""

    if workers is not None:
        whole("api", "workers", workers, lower=0)
    if runs is not None:
        runs = whole("api", "runs", runs, lower=1)
    if stop is not None:
        stop = number("api", "stop", stop, positive=True)
    c = campaign_file
    if runs is not None or stop is not None:
        if isinstance(c, (str, Path)) and not Path(c).is_file():
            c = shipped_campaign_file(str(c))  # a shipped campaign's name
        c = load_campaign(c, runs=runs, stop=stop)
    limit = None if time_limit is None else check_limit(time_limit, "api", "time_limit") or 0
    o = run_campaign(c, out, workers=workers, scheduler=scheduler, overwrite=overwrite, only=only, progress=progress,
                     time_limit=limit, client=client, cluster=cluster, scheduler_file=scheduler_file, **options)
    return read_table(o.folder / SUMMARY)  # the one reader: a folder of any name


def fdir_calibrate(campaign_file, *, detector, rate_per_hour, draws, out, level=0.95, overwrite=False, runs=None,
                   workers=None, progress=False, **options) -> dict:
    """``ftcsim fdir calibrate``: the threshold of the change detector ``detector`` (an instance of the
    campaign's scenario) for at most ``rate_per_hour`` false alarms per hour at confidence ``level``,
    from the campaign's fault-free draws (run into the campaign folder ``draws``, resumed if it holds
    them); writes the calibration file ``out`` (.json: a parameter set, its gains-file form and the
    statistics behind it) and returns its content. The rule: docs/fdir.md,
    :mod:`orchestrator.campaign.calibrate`. ``options``: ``scheduler``, ``client``, ... as :func:`campaign`."""
    from orchestrator.campaign.calibrate import calibrate

    return calibrate(campaign_file, detector=detector, rate_per_hour=rate_per_hour, draws=draws, out=out, level=level,
                     overwrite=overwrite, runs=runs, workers=workers, progress=progress, **options)


def campaigns(items, *, workers=None, scheduler=None, overwrite=False, progress=False, time_limit=None, client=None,
              cluster=None, scheduler_file=None, **options) -> list:
    """Run or resume several campaigns as one plan (``items``: [(campaign file, out folder, run ids
    or None)]): each keeps its folder and summary as :func:`campaign` writes them, their runs share
    one pass over one cluster, longest first (:mod:`orchestrator.campaign.multi`). Returns
    [(summary table or None when nothing is stored, outcome)] in the order of ``items``; an outcome
    has ``total``, ``stored``, ``computed``, ``lost`` and ``interrupted`` (signal number)."""
    import pandas as pd

    limit = None if time_limit is None else check_limit(time_limit, "api", "time_limit") or 0
    outs = run_campaigns(items, workers=workers, scheduler=scheduler, overwrite=overwrite, progress=progress,
                         time_limit=limit, client=client, cluster=cluster, scheduler_file=scheduler_file, **options)
    return [(pd.read_parquet(o.folder / SUMMARY) if o.stored else None, o) for o in outs]


def trajectory_file(folder, row) -> Path:
    """The stored trajectory file of one campaign run (``row``: a summary row with ``run_id`` and
    ``key``) in the campaign folder ``folder``; it exists when the campaign stored trajectories."""
    return Path(folder) / TRAJECTORIES / run_file(row)


# -- for applications on top of the orchestrator (the arena): the checks a command makes before it writes ----------
def plan_campaign(campaign_file) -> int:
    """Load and expand a campaign file without running it (every check of ``ftcsim campaign``: the file,
    the base scenarios, the timing, the seed, every run's key); returns the number of runs planned.
    Problems are :class:`InputError`."""
    from orchestrator.campaign.expand import expand

    return len(expand(load_campaign(campaign_file)))


def reach_scheduler(address, timeout: float = 5.0, key: str = "--scheduler") -> str:
    """The checked address of a Dask scheduler that answers within ``timeout`` s (refused otherwise, as
    ``ftcsim campaign --scheduler`` refuses it, before anything is written)."""
    from orchestrator.campaign.cluster import check_address, probe

    address = check_address(address, key)
    probe(address, seconds("api", "timeout", timeout), key)
    return address


def scheduler_file_address(path, key: str = "--scheduler-file") -> str:
    """The checked scheduler address in a Dask scheduler file (read through the one reader)."""
    from orchestrator.campaign.cluster import read_scheduler_file

    return read_scheduler_file(path, key)


def check_readable(path, what: str = "Parquet table") -> None:
    """The one reader's checks of a file before a library reads it directly: a regular file (no FIFO,
    device or link loop) of bounded size; problems are :class:`InputError`."""
    from orchestrator.common.reading import MAX_DATA_BYTES, check_regular

    check_regular(path, what, limit=MAX_DATA_BYTES)


def start_local_cluster(workers=None):
    """A LocalCluster of ``workers`` single-threaded processes as ``ftcsim campaign`` starts it (its
    scratch space in a temporary folder removed by ``.close()``, SIGINT honoured while it starts); the
    returned connection has ``.cluster.scheduler_address`` and ``.close()``."""
    from orchestrator.campaign.cluster import MAX_WORKERS, local_cluster

    if workers is not None:
        whole("api", "workers", workers, lower=0, upper=MAX_WORKERS)
    return local_cluster(workers or None, dashboard=False)
