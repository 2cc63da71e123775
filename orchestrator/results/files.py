"""The files of a run and their reader.

A run folder holds (:func:`write_results`):

* ``results.parquet`` (default) or ``results.csv`` (``format="csv"``): a ``time`` column (s) and
  one float64 column per recorded signal, every recorded row (or every ``record_step``). Parquet
  (zstd, BYTE_STREAM_SPLIT: lossless float64) carries each column's unit as field metadata ``b"unit"``; a CSV is plain (``pandas.read_csv``
  reads it, 17 significant digits, lossless; before pandas 3.1, the cap of the optional extra
  ftcsim[basilisk], with ``float_precision="round_trip"``) with its units beside it in ``results.units.csv``
  (columns ``signal,unit``);
* ``metrics.json``: ``{"metrics": {name: value}, "units": {name: unit}, "info": {...}}`` — the
  values measured in the run, their units where known, and what describes the run (scenario,
  completeness, timing, step statistics, signals, the SHA-256 of every FMU that ran, ...);
* with ``plots``, one PNG per instance (axes labelled with units).

Publishing is all-or-nothing: every file is written into the staging folder, flushed and its size
checked on disk; a failed write (full disk, file-size limit) publishes nothing, so a previous
result replaced with ``--overwrite`` stays as it was (:class:`WriteFailed` says so). A failure of a
computation after the run (metrics, a plot) is recorded in ``info.post_processing_errors`` and the
folder is still published, never losing the rows.

:class:`Run` reads a folder back (this layout, and the older flat ``metrics.json`` with
``results.csv``).
"""
from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import os
from pathlib import Path

import numpy as np

from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.jsonio import strict_json
from orchestrator.common.outputs import is_result_folder
from orchestrator.common.reading import MAX_DATA_BYTES, decode_text, open_regular, read_json, read_text
from orchestrator.cosim.master import RunResult
from orchestrator.results.metrics import base_metrics, compute_metrics, metric_units, signal_units, split_metrics

FORMATS = {"parquet": "results.parquet", "csv": "results.csv"}
# a row is on the record grid if (t - t0) / record_step is within this of a whole number
GRID_TOLERANCE = 1e-6
UNITS_CSV = "results.units.csv"


class WriteFailed(InputError):
    """A file of a run could not be written completely (full disk, a size limit); nothing was published.
    An output problem like any other the file system reports: exit status 2, naming ``--out``."""


def check_format(fmt, source="api", key="format") -> str:
    if fmt not in FORMATS:
        raise InputError(source, key, f"{fmt!r} is not a result format; use {' or '.join(map(repr, FORMATS))}")
    return fmt


def file_sha256(path) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def fmu_digests(scenario) -> dict:
    """instance -> {"file", "sha256"} of every FMU the scenario runs (empty in-process)."""
    return {name: {"file": Path(inst.fmu).name, "sha256": file_sha256(inst.fmu)}
            for name, inst in scenario.instances.items() if inst.fmu is not None}


def thin(result, t0: float, record_step: float | None):
    """``result`` with only the rows at ``t0 + k * record_step`` (s) and its last row (the end of
    the run, or where it stopped); ``record_step`` None: ``result`` itself."""
    if record_step is None or len(result.time) == 0:
        return result
    q = (result.time - t0) / record_step
    keep = np.abs(q - np.round(q)) <= GRID_TOLERANCE
    keep[-1] = True
    return dataclasses.replace(result, time=result.time[keep], data=result.data[keep])


# -- writing, each file flushed and size-checked ---------------------------------------------------
def _write_bytes(path: Path, data: bytes) -> None:
    """``data`` into ``path``, flushed to disk; an ``OSError`` unless the file on disk has every byte."""
    with open(path, "wb") as fh:
        fh.write(data)
        fh.flush()
        os.fsync(fh.fileno())
    if os.stat(path).st_size != len(data):
        raise OSError(f"{path.name}: {os.stat(path).st_size} of {len(data)} bytes on disk")


def table_bytes_csv(time, columns, data) -> bytes:
    buf = io.StringIO()
    table = np.column_stack([time, data]) if len(time) else np.zeros((0, 1 + len(columns)))
    np.savetxt(buf, table, delimiter=",", header=",".join(["time"] + list(columns)), comments="", fmt="%.17g")
    return buf.getvalue().encode("utf-8")


def write_csv(path: Path, result, units: dict | None = None) -> None:
    """``results.csv`` (and, with ``units``, ``results.units.csv`` beside it)."""
    path = Path(path)
    _write_bytes(path, table_bytes_csv(result.time, result.columns, result.data))
    if units is not None:
        rows = "".join(f"{c},{units.get(c, '1')}\n" for c in ["time"] + list(result.columns))
        _write_bytes(path.parent / UNITS_CSV, ("signal,unit\n" + rows).encode("utf-8"))


def frame(time, columns, data, units: dict | None = None):
    """A DataFrame indexed by time (s), one column per signal, ``df.attrs["units"]``."""
    import pandas as pd

    df = pd.DataFrame(data, index=pd.Index(np.asarray(time, dtype=float), name="time"), columns=list(columns))
    df.attrs["units"] = dict(units or {})
    return df


def write_parquet(path: Path, time, columns, data, units: dict) -> None:
    """A Parquet table: ``time`` then one float64 column per signal, units as field metadata
    (``orchestrator.common.parquet``), zstd-compressed with the BYTE_STREAM_SPLIT encoding (each
    float's bytes grouped by position: a third of plain float64 for smooth signals, lossless),
    flushed and size-checked."""
    import pyarrow.parquet as pq

    from orchestrator.common.parquet import to_table

    table = to_table(frame(time, columns, data).reset_index(), units=units)
    buf = io.BytesIO()
    pq.write_table(table, buf, compression="zstd", use_dictionary=False,
                   column_encoding=dict.fromkeys(table.column_names, "BYTE_STREAM_SPLIT"))
    path = Path(path)
    tmp = path.with_name(f".tmp-{os.getpid()}-{path.name}")  # then renamed: a reader sees the old file or the new
    try:
        _write_bytes(tmp, buf.getvalue())
        os.replace(tmp, path)
    finally:
        tmp.unlink(missing_ok=True)


def read_results_table(folder) -> tuple[list[str], np.ndarray, dict]:
    """(header with "time" first, data with time in column 0, units) of a run folder's results
    file (Parquet or CSV)."""
    folder = Path(folder)
    if (folder / FORMATS["parquet"]).is_file():
        from orchestrator.common.parquet import read_table

        df = read_table(folder / FORMATS["parquet"])
        units = dict(df.attrs.get("units", {}))
        header = [str(c) for c in df.columns]
        return header, df.to_numpy(dtype=float).reshape(len(df), len(header)), units
    header, data = read_csv(folder / FORMATS["csv"])
    units = {}
    sidecar = folder / UNITS_CSV
    if os.path.lexists(sidecar):
        lines = read_text(sidecar, "units file").splitlines()[1:]
        units = dict(line.split(",", 1) for line in lines if "," in line)
    return header, data, units


def read_csv(path) -> tuple[list[str], np.ndarray]:
    path = Path(path)
    with open_regular(path, "results file", limit=MAX_DATA_BYTES) as fh:  # the one reader
        header = decode_text(path, "header", fh.readline()).strip().split(",")
        data = np.loadtxt(io.TextIOWrapper(fh, encoding="utf-8"), delimiter=",", ndmin=2)
    return header, data


def signal_figure(time, columns, data, units: dict, title: str, instance: str | None = None):
    """A matplotlib figure, one panel per recorded vector signal (of ``instance``, or all), its
    y axis labelled with the signal's unit, the x axis ``time [s]``."""
    import matplotlib.pyplot as plt

    groups: dict[str, list[int]] = {}
    for k, col in enumerate(columns):
        inst, var = col.split(".", 1) if "." in col else ("", col)
        if instance is None or inst == instance:
            groups.setdefault(col.split("[")[0], []).append(k)
    n = max(1, len(groups))
    height = 2.0 * n + 0.5
    # fixed margins (inches) instead of tight_layout, which drew every tick label twice (a third of
    # the figure's time; make demo draws 80 of them)
    fig, axes = plt.subplots(n, 1, figsize=(8, height), sharex=True, squeeze=False,
                             gridspec_kw={"left": 0.95 / 8, "right": 1 - 0.15 / 8, "top": 1 - 0.45 / height,
                                          "bottom": 0.5 / height, "hspace": 0.3})
    for ax, (base, cols) in zip(axes[:, 0], groups.items()):
        for k in cols:
            ax.plot(time, data[:, k], lw=0.8, label=columns[k].split(".", 1)[-1])
        unit = units.get(columns[cols[0]], "1")
        label = base.split(".", 1)[1] if instance is not None and "." in base else base
        ax.set_ylabel(f"{label} [{unit}]")
        ax.grid(True, lw=0.3)
        if len(cols) <= 8:
            ax.legend(fontsize=6, loc="upper right", ncol=min(4, len(cols)))
    axes[-1, 0].set_xlabel("time [s]")
    fig.suptitle(title, y=1 - 0.08 / height, va="top")
    return fig


def plot(result, scenario, out_dir: Path, units: dict | None = None) -> list[str]:
    """One PNG per instance: every recorded vector signal of it in its own panel, with units."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from orchestrator.results.html import plain_text  # jinja2 and markdown-it: only when plotting

    units = units if units is not None else signal_units(scenario, result.columns)
    files = []
    for inst in dict.fromkeys(c.split(".", 1)[0] for c in result.columns):
        fig = signal_figure(result.time, result.columns, result.data, units,
                            f"{scenario.name}: {inst}" + ("" if result.complete else " (INCOMPLETE)"), inst)
        name = f"{inst}.png"
        buf = io.BytesIO()
        plain_text(fig).savefig(buf, dpi=110, format="png")  # names and units from the FMUs as plain text
        plt.close(fig)
        _write_bytes(out_dir / name, buf.getvalue())
        files.append(name)
    return files


def write_json(path: Path, data) -> None:
    """Strict JSON (``orchestrator.common.jsonio``), flushed and size-checked."""
    _write_bytes(Path(path), (json.dumps(strict_json(data), indent=2, allow_nan=False) + "\n").encode("utf-8"))


def summary(result, scenario, info: dict | None = None) -> tuple[dict, list[str]]:
    """(the metrics.json document, errors): the metrics of the run split into values and info,
    the values' units. A failure to compute the metrics keeps the run's description and says why."""
    errors = []
    try:
        flat = compute_metrics(result, scenario)
    except Exception as e:  # a bug or an unforeseen signal shape: keep the run, say what failed
        flat = base_metrics(result, scenario)
        errors.append(f"metrics: {type(e).__name__}: {e}")
    flat = strict_json(flat)
    values, run_info = split_metrics(flat)
    run_info.update(info or {})
    units = metric_units(values, scenario, signal_units(scenario, result.columns))
    if errors:
        run_info["post_processing_errors"] = errors
    return {"metrics": values, "units": units, "info": run_info}, errors


def write_results(folder, result, scenario, plots: bool = True, fmt: str = "parquet",
                  info: dict | None = None, record_step: float | None = None) -> tuple[dict, list[str]]:
    """Write a run into ``folder`` (an :class:`orchestrator.common.outputs.OutputFolder`, checked
    before the run) and publish it when every file is complete (see the module docstring). The
    metrics come from every row of ``result``; the results file and plots hold the rows of
    :func:`thin` (``record_step``). Returns (the metrics.json document, post-processing errors);
    raises :class:`WriteFailed` when a file could not be written (nothing published)."""
    check_format(fmt)
    tmp = folder.staging()
    units = signal_units(scenario, result.columns)
    info = {"format": fmt, "record_step": record_step, **(info or {})}
    if "fmus" not in info:  # the caller did not take them before the run (a campaign's replay)
        info["fmus"] = fmu_digests(scenario)
    doc, errors = summary(result, scenario, info)
    result = thin(result, scenario.start, record_step)
    current = FORMATS[fmt]
    try:
        if fmt == "parquet":
            write_parquet(tmp / current, result.time, result.columns, result.data, units)
        else:
            write_csv(tmp / current, result, units)
        doc["info"]["results_sha256"] = file_sha256(tmp / current)  # Run checks it: metrics.json and rows agree
        if not result.complete:
            current = "INCOMPLETE"
            _write_bytes(tmp / current, ((result.error or "run did not finish") + "\n").encode("utf-8"))
        if plots and len(result.time) > 1:
            current = "plots"
            try:
                doc["info"]["plots"] = plot(result, scenario, tmp, units)
            except OSError:
                raise
            except Exception as e:
                errors.append(f"plots: {type(e).__name__}: {e}")
                doc["info"]["post_processing_errors"] = errors
        current = "metrics.json"
        write_json(tmp / current, doc)
        _sync_folder(tmp)
    except OSError as e:
        folder.discard()
        previous = ("the previous result there is unchanged" if is_result_folder(folder.path)
                    else "nothing was written there")
        why = e.strerror or " ".join(str(e).split())
        raise WriteFailed(folder.source, folder.key, f"cannot write {current} for {folder.path} ({why}): nothing "
                                                     f"published, {previous}") from None
    except BaseException:
        folder.discard()
        raise
    folder.publish()
    return doc, errors


def _sync_folder(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


class Run:
    """One result folder of ``ftcsim run``, checked: a readable results file (Parquet or CSV)
    with a ``time`` column and numbers, a metrics object, signals that name columns. The one
    reader of a run folder (reports, papers, ``ftcsim.open``): ``metrics`` (the values),
    ``metric_units``, ``info`` (what describes the run), ``metrics_config`` (the scenario's
    [metrics] table), ``header`` and ``data`` (time first), ``units`` (column -> unit), ``t``,
    ``signals``, :attr:`result` (a RunResult)."""

    def __init__(self, folder: Path):
        folder = Path(folder)
        self.folder = folder
        if not folder.is_dir():
            raise InputError(folder, "-", "result folder not found")
        data_file = next((folder / f for f in FORMATS.values() if (folder / f).is_file()), None)
        if data_file is None:
            raise InputError(folder, "results.parquet", "missing (nor results.csv): not a result folder of `ftcsim run`")
        if not os.path.lexists(folder / "metrics.json"):
            raise InputError(folder, "metrics.json", "missing: not a result folder of `ftcsim run`")
        # the one reader: a regular file, bounded, UTF-8, nested at most MAX_DEPTH deep (NaN read as None)
        doc = read_json(folder / "metrics.json", "metrics.json", strict=False)
        if isinstance(doc.get("metrics"), dict) and isinstance(doc.get("info"), dict):
            self.metrics, self.info = doc["metrics"], doc["info"]
            self.metric_units = doc.get("units") if isinstance(doc.get("units"), dict) else {}
        else:  # the flat metrics.json of earlier versions
            self.metrics, self.info = split_metrics(doc)
            self.metric_units = {}
        try:
            self.header, self.data, self.units = read_results_table(folder)
        except InputError:
            raise
        except (ValueError, UnicodeDecodeError, OSError) as e:
            raise InputError(data_file, "-", f"unreadable: {' '.join(str(e).split())[:200]}") from None
        except Exception as e:  # pyarrow's own errors on a damaged file
            raise InputError(data_file, "-", f"unreadable: {' '.join(str(e).split())[:200]}") from None
        if not self.header or self.header[0] != "time" or self.data.ndim != 2 or self.data.shape[1] != len(self.header):
            raise InputError(data_file, "header", "expected 'time' then one column per signal")
        if self.data.shape[0] == 0:
            raise InputError(data_file, "-", "no rows")
        self.name = str(self.info.get("scenario") or folder.name)
        self.paper = self.info.get("paper")
        signals = self.info.get("signals", {})
        if not isinstance(signals, dict) or not all(isinstance(v, str) for v in signals.values()):
            raise InputError(folder / "metrics.json", "signals", "expected an object of 'instance.variable' names")
        self.signals = signals
        self._check_against_metrics(data_file)
        self.t = self.data[:, 0]
        config = self.info.get("metrics_config", {})
        self.metrics_config = dict(config) if isinstance(config, dict) else {}
        self.ftcsim_folder = is_result_folder(folder, "run")

    def _check_against_metrics(self, data_file: Path) -> None:
        """The results file and metrics.json describe the same run: the time column is finite and
        increasing, ``complete`` is a boolean, the run ends where metrics.json says (``t_end``), and the
        file's SHA-256 is the one written beside it (``results_sha256``, when the folder records it)."""
        mj = self.folder / "metrics.json"
        t = self.data[:, 0]
        if not np.isfinite(t).all():
            raise InputError(data_file, "time", f"not finite at row {int(np.argmin(np.isfinite(t)))}")
        if len(t) > 1 and not (np.diff(t) > 0).all():
            raise InputError(data_file, "time", f"not increasing at row {int(np.argmin(np.diff(t) > 0)) + 1}")
        complete = self.info.get("complete", True)
        if not isinstance(complete, bool):
            raise InputError(mj, "info.complete", f"expected true or false, got {complete!r}")
        t_end = self.info.get("t_end")
        if t_end is not None:
            if isinstance(t_end, bool) or not isinstance(t_end, (int, float)):
                raise InputError(mj, "info.t_end", f"expected a number of seconds, got {t_end!r}")
            if abs(t[-1] - t_end) > 1e-9 * max(1.0, abs(t_end)):
                raise InputError(data_file, "time", f"ends at {t[-1]:.9g} s but {mj.name} says t_end = {t_end:.9g} s: "
                                                    "the results of another run?")
        digest = self.info.get("results_sha256")
        if digest is not None and digest != file_sha256(data_file):
            raise InputError(data_file, "-", f"is not the file {mj.name} was written with (SHA-256 differs): "
                                             "the results of another run?")
        missing = [s for s in self.signals.values() if not any(h == s or h.startswith(s + "[") for h in self.header)]
        if missing:
            raise InputError(mj, "info.signals", f"{missing[0]} is not a column of {data_file.name}")

    @property
    def complete(self) -> bool:
        return bool(self.info.get("complete", True))

    @property
    def result(self):
        """The run as a :class:`orchestrator.cosim.master.RunResult` (what the metrics functions take)."""
        m = self.info
        return RunResult(self.header[1:], self.t, self.data[:, 1:], bool(m.get("complete", True)), m.get("error"),
                         float(m.get("wall_time_s") or 0.0), int(m.get("steps") or len(self.t) - 1),
                         str(m.get("exchange", "ordered")), str(m.get("mode", "fmu")))

    def has(self, key) -> bool:
        return key in self.signals and any(h.startswith(self.signals[key] + "[") for h in self.header)

    def vec(self, key) -> np.ndarray:
        base = self.signals[key] + "["
        return self.data[:, [i for i, h in enumerate(self.header) if h.startswith(base)]]


def read_results(folder) -> tuple[list[str], np.ndarray]:
    """(header, data) of a run folder's results file, ``time`` first (Parquet or CSV)."""
    header, data, _ = read_results_table(folder)
    return header, data


def metrics_and_info(folder) -> dict:
    """A run folder's metrics.json as one flat dict: its info, then its metric values."""
    r = read_json(Path(folder) / "metrics.json", "metrics.json", strict=False)
    return {**r.get("info", {}), **r.get("metrics", {})} if "info" in r else r
