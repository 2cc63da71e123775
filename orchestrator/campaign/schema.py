"""The declared Parquet schema of a campaign's tables, fixed before any run: the same columns and
types in every run file of every variant, whatever the runs' outcomes.

Run rows (``runs/*.parquet`` and ``summary.parquet``): ids int64 (run_id, point, draw, seed),
strings (key, variant, status, error, worker), the
dispersed / swept values read back (``inst.name``) and as requested (``requested:inst.name``)
float64, every metric float64 (bool metrics as bool), then the execution record. A metric a run
did not produce (a failed run, no settling) is a null of its declared type. The metric columns
of a variant are those :func:`orchestrator.results.metrics.compute_metrics` gives for its
scenario, found once by computing them on a short all-zero record of the scenario's signals.
Units (``b"unit"`` field metadata, UCUM spelling) come from the FMUs' variables, the metrics' units of a
run (``orchestrator.results.metrics.metric_units``) and :data:`METRIC_UNITS`.

Trajectories: one file per run, ``trajectories/<run file name>``: run_id int64, time (s) and the
recorded signals float64 with their units.
"""
from __future__ import annotations

import functools
import math
import warnings

import numpy as np
import pyarrow as pa

from orchestrator.cosim.master import RunResult
from orchestrator.results.metrics import compute_metrics, metric_units, signal_units

ID_FIELDS = (("run_id", "int64"), ("key", "string"), ("variant", "string"), ("point", "int64"), ("draw", "int64"),
             ("seed", "int64"))
TAIL_FIELDS = (("status", "string"), ("error", "string"), ("wall_time_s", "float64"), ("cpu_time_s", "float64"),
               ("sim_time_s", "float64"), ("worker", "string"))
# metrics of the run summary that are not columns (dicts, names, duplicates of the tail)
DROPPED_METRICS = ("wall_time_s", "real_time_factor", "signals", "scenario", "mode", "exchange", "paper",
                   "complete", "error", "metrics_config", "step_statistics")
# units of the columns every run row has; a metric's unit is the one its run's metrics.json gives
# (orchestrator/results/metrics.py: metric_units, from the scenario's signals)
METRIC_UNITS = {"t_end": "s", "step": "s", "steps": "1", "settling_time": "s", "wall_time_s": "s", "cpu_time_s": "s",
                "sim_time_s": "s", "run_id": "1", "point": "1", "draw": "1", "seed": "1"}
TYPES = {"int64": pa.int64(), "float64": pa.float64(), "string": pa.string(), "bool": pa.bool_()}


def _probe(sc) -> tuple[dict, dict]:
    """(metrics, their units) that :func:`compute_metrics` reports for scenario ``sc`` (computed on
    5 all-zero samples of its recorded signals; nothing runs)."""
    cols = [f"{i}.{v}" for i, v in sc.record]
    t = np.linspace(sc.start, sc.stop, 5)
    probe = RunResult(cols, t, np.zeros((len(t), len(cols))), True, mode=sc.mode)
    with warnings.catch_warnings(), np.errstate(all="ignore"):
        warnings.simplefilter("ignore")
        try:
            m = compute_metrics(probe, sc)
        except Exception:  # a paper metric that needs real data: its columns come from the runs
            m = {}
    return m, metric_units(m, sc, signal_units(sc, cols))


def metric_units_of(sc) -> dict:
    """{metric: unit} of the metrics a run of scenario ``sc`` reports (metrics.json's "units")."""
    return _probe(sc)[1]


def metric_types(sc) -> dict:
    """{metric: "float64" | "bool"} that :func:`compute_metrics` reports for scenario
    ``sc`` (computed on 5 all-zero samples of its recorded signals; nothing runs)."""
    return _types(_probe(sc)[0])


def _types(m: dict) -> dict:
    out = {}
    for k, v in m.items():
        if k in DROPPED_METRICS or isinstance(v, (dict, list, tuple, str)):  # numbers and flags only
            continue
        out[k] = "bool" if isinstance(v, (bool, np.bool_)) else "float64"
    return out


def run_columns(c, requested_refs) -> list:
    """[(name, type, unit)] of a campaign's run rows, in column order (see the module docstring)."""
    cols = [(n, t, METRIC_UNITS.get(n)) for n, t in ID_FIELDS]
    units = {}
    for sc in c.bases:
        for inst, i in sc.instances.items():
            for n, u in (getattr(i.interface, "units", None) or {}).items():
                units.setdefault(f"{inst}.{n}", u)
    cols += [(r, "float64", units.get(r)) for r in requested_refs]
    cols += [(f"requested:{r}", "float64", units.get(r)) for r in requested_refs]
    metrics: dict = {}
    m_units = dict(METRIC_UNITS)
    for sc in c.bases:
        m, u = _probe(sc)
        for k, t in _types(m).items():
            metrics.setdefault(k, t)
        for k, unit in u.items():
            m_units.setdefault(k, unit)
    if c.settling:
        metrics["settling_time"] = "float64"
    taken = {n for n, _, _ in cols} | {n for n, _ in TAIL_FIELDS}
    cols += [(k, t, m_units.get(k)) for k, t in metrics.items() if k not in taken]
    cols += [(n, t, METRIC_UNITS.get(n)) for n, t in TAIL_FIELDS]
    return cols


def schema(columns) -> pa.Schema:
    """The pyarrow schema of [(name, type, unit)] (units as field metadata ``b"unit"``)."""
    return _schema(tuple(tuple(c) for c in columns))


@functools.lru_cache(maxsize=32)
def _schema(columns: tuple) -> pa.Schema:  # once per campaign, not once per stored run
    return pa.schema([pa.field(n, TYPES[t], metadata={b"unit": u.encode()} if u else None) for n, t, u in columns])


def conform(row: dict, columns) -> dict:
    """``row`` with exactly the declared columns: missing ones None, values of the declared type
    (a value that does not fit, e.g. a string where a number is declared, becomes None and is
    named in the row's error)."""
    out, misfits = {}, []
    for n, t, _ in columns:
        v = row.get(n)
        if v is not None:
            try:
                if t == "float64":
                    v = float(v)
                    v = v if math.isfinite(v) else None
                elif t == "int64":
                    v = int(v)
                elif t == "bool":
                    v = bool(v)
                else:
                    v = str(v)
            except (TypeError, ValueError, OverflowError):
                misfits.append(n)
                v = None
        out[n] = v
    extra = [n for n in row if n not in out and row[n] is not None]
    if misfits or extra:
        note = f"not stored (not in the declared schema or not of its type): {', '.join(misfits + extra)}"
        out["error"] = f"{out['error']}; {note}" if out.get("error") else note
    return out


def trajectory_columns(c) -> list:
    """[(name, type, unit)] of a campaign's trajectory files."""
    units = {}
    for sc in c.bases:
        for inst, i in sc.instances.items():
            for n, u in (getattr(i.interface, "units", None) or {}).items():
                units.setdefault(f"{inst}.{n}", u)
    return [("run_id", "int64", "1"), ("time", "float64", "s")] + [(s, "float64", units.get(s)) for s in c.trajectories]
