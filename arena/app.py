"""``ftcsim arena FILE --out DIR``: the arena's cells as one plan on the campaign engine, measured and
ranked on one page (issues 26 and 33). The orchestrator reaches this module by the string in the
registry (``papers/registry.py: applications``); it uses the orchestrator's public face only.

Steps: the arena file is checked with the command line's overrides (``arena/arenafile.py``) and
every cell's scenario derived and loaded (``arena/plan.py``) before anything is written; the
folder is then published (or resumed) with ``arena.json``, a copy of the arena file and, per cell
and hardware, ``cells/<method>_on_<plant>.<hardware>/`` (``scenario.toml``, ``cell.json``, its
campaign files and folders). Every campaign's missing runs then go to one cluster in one pass
(``orchestrator.api.campaigns``: Dask workers, an existing scheduler or client, or this process
with ``workers=0``), longest first. Each stored run's trajectory is measured (``arena/measure.py``)
into ``tables/runs.parquet``; the verdicts (``arena/verdicts.py``) and the page
(``arena/leaderboard.py``) are written beside it.

Resume: rerunning on the same folder computes only the runs not stored; the tables and the page
are written again from everything stored. A cell whose inputs changed since its folder was written
(its digest, ``arena/plan.py``) is refused, naming what changed, or recomputed with ``overwrite``;
cells in the folder that the arena no longer lists are left as they are and left off the page. A
signal stops every campaign at once: the page is written from what is stored, and the same command
resumes. A folder that is not an arena folder (and not empty) is refused.
"""
from __future__ import annotations

import json
import math
import os
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import tomli_w

from orchestrator import api

from . import plan as P
from .arenafile import Arena, load
from .measure import measure

MARKER = "arena.json"
KIND = "ftcsim-arena"
VERSION = 2


@dataclass
class Outcome:
    folder: Path
    planned: int  # runs the plan computes (deterministic classes once per cell)
    stored: int
    failed: int  # stored runs with no result (never ranked)
    wall_s: float
    page: Path | None
    interrupted: int = 0  # signal number (0: none)
    lost: int = 0  # runs no worker could finish (a rerun retries them)
    recomputed: list = field(default_factory=list)  # cells replaced because their inputs changed (overwrite)
    phases: dict = field(default_factory=dict)  # wall time (s) of plan, runs, measure, page (and *_cpu: this process's CPU)


def run_arena(file, out, *, workers: int | None = None, scheduler: str | None = None, scheduler_file=None,
              client=None, cluster=None, draws=None, stop=None, faults=None, hardware=None, only=None, mode=None,
              time_limit=None, overwrite: bool = False, progress: bool = False, **engine) -> Outcome:
    """Run (or resume) an arena into ``out`` and write its leaderboard (module docstring).

    ``workers``: local Dask worker processes (default: the cores; 0: in this process); or an existing
    cluster: ``scheduler`` (address), ``scheduler_file``, ``client`` (a ``distributed.Client``, left
    open) or ``cluster``. ``draws``, ``stop`` (s), ``faults``, ``hardware``, ``only`` (cell names such
    as ``"fasmc_on_li2023"``), ``mode`` ("inprocess" or "fmu"): instead of the arena file's;
    ``time_limit``: s of wall time per run (0: none); ``overwrite``: recompute the cells whose inputs
    changed. Other keywords go to ``orchestrator.api.campaigns``."""
    started, cpu0 = time.perf_counter(), time.process_time()
    arena = load(file, draws=draws, stop=stop, faults=faults, hardware=hardware, only=only, mode=mode)
    if time_limit is not None:
        if isinstance(time_limit, bool) or not isinstance(time_limit, (int, float)) or not math.isfinite(time_limit) \
                or time_limit < 0:
            raise api.InputError("command line", "--time-limit", f"expected a number of seconds >= 0, got {time_limit!r}")
        arena.time_limit = float(time_limit)
        arena.overrides["time_limit"] = float(time_limit)
    plans = P.build(arena)  # every check before anything is written
    out = Path(out)
    api.check_target(out)  # a name with room for the staging folder, writable, not /proc: before anything
    if scheduler is not None:  # reached before anything is written: an unreachable scheduler leaves nothing
        scheduler = api.reach_scheduler(scheduler)
    elif scheduler_file is not None:
        api.reach_scheduler(api.scheduler_file_address(scheduler_file), key="--scheduler-file")
    recompute = check_folder(arena, plans, out, overwrite)
    try:
        publish(arena, plans, out, recompute)
    except OSError as e:  # a full disk while the folder is written: one line
        raise api.InputError("command line", "--out", f"cannot write {out}: {e.strerror or e}") from None
    phases = {"plan": time.perf_counter() - started, "plan_cpu": time.process_time() - cpu0}
    items = [(out / "cells" / p.name / f"{g.kind}.toml", out / "cells" / p.name / g.kind, None)
             for p in plans for g in p.groups]
    where = {k: v for k, v in (("scheduler", scheduler), ("scheduler_file", scheduler_file), ("client", client),
                               ("cluster", cluster)) if v is not None}
    # the time limit decides no result (a run over it is failed, and recomputed on a rerun): not in the digest
    results = api.campaigns(items, workers=workers, progress=progress, name=f"arena {arena.name}",
                            time_limit=arena.time_limit, **where, **engine)
    phases["runs"] = time.perf_counter() - started - phases["plan"]
    t0, c0 = time.perf_counter(), time.process_time()
    runs, statistics = measure_all(arena, plans, out)
    phases["measure"], phases["measure_cpu"] = time.perf_counter() - t0, time.process_time() - c0
    outcomes = [o for _, o in results]
    o = Outcome(out, sum(x.total for x in outcomes), sum(x.stored for x in outcomes), 0, 0.0, None,
                interrupted=max((x.interrupted for x in outcomes), default=0), lost=sum(x.lost for x in outcomes),
                recomputed=[p.name for p in recompute], phases=phases)
    if not runs.empty:
        from . import leaderboard

        t0, c0 = time.perf_counter(), time.process_time()
        o.page = leaderboard.write(arena, runs, statistics, out, api.write_table)
        o.failed = int((runs["outcome"] == "failed").sum())
        phases["page"], phases["page_cpu"] = time.perf_counter() - t0, time.process_time() - c0
    o.wall_s = time.perf_counter() - started
    if progress:
        print(f"arena {arena.name}: measured and ranked {len(runs)} runs", file=sys.stderr, flush=True)
    return o


# -- the folder ----------------------------------------------------------------------------------------------------
def _read_json(path: Path):
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def check_folder(arena: Arena, plans: list, out: Path, overwrite: bool) -> list:
    """Refuse what cannot be written (nothing is written here); return the cells to recompute."""
    if out.is_symlink() or (out.exists() and not out.is_dir()):
        raise api.InputError("command line", "--out", f"{out} is not a folder of ours (a file or a symbolic link): "
                                                      "choose another folder")
    if not out.exists():
        return []
    marker = _read_json(out / MARKER)
    if marker is None:
        if any(out.iterdir()):
            raise api.InputError("command line", "--out", f"{out} exists and is not an arena folder: choose another "
                                                          "folder (nothing there is replaced)")
        return []
    if marker.get("kind") != KIND or marker.get("version") != VERSION:
        raise api.InputError("command line", "--out", f"{out} holds an arena folder of another ftcsim version: choose "
                                                      "another folder (nothing there is replaced)")
    cells = out / "cells"
    if cells.is_symlink():
        raise api.InputError("command line", "--out", f"{cells} is a symbolic link: refused")
    stale, recompute = [], []
    for p in plans:
        d = cells / p.name
        if d.is_symlink():
            raise api.InputError("command line", "--out", f"{d} is a symbolic link: refused")
        if not d.exists():
            continue
        what = P.changed(_read_json(d / "cell.json"), p)
        if what:
            (recompute if overwrite else stale).append((p, what))
    if stale:
        p, what = stale[0]
        more = f" (and {len(stale) - 1} more cells: {', '.join(q.name for q, _ in stale[1:4])}...)" if len(stale) > 1 else ""
        raise api.InputError("command line", "--out", f"{out}: cell {p.name} was computed from other inputs "
                                                      f"({', '.join(what)} changed){more}: pass --overwrite to "
                                                      "recompute them, or choose another folder")
    return [p for p, _ in recompute]


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def publish(arena: Arena, plans: list, out: Path, recompute: list) -> None:
    """Create the arena folder (through a staging folder) or add what it lacks: new cells, cells to
    recompute (replaced whole: they are ours), the session in ``arena.json``."""
    new = not out.exists()
    if new or not (out / MARKER).is_file():
        staging = out.parent / f".{out.name}.tmp-{os.getpid()}"
        try:
            (staging / "cells").mkdir(parents=True)
            (staging / MARKER).write_text(json.dumps({"kind": KIND, "version": VERSION, "arena": arena.name,
                                                      "sessions": []}, indent=1), encoding="utf-8")
            if out.exists():
                out.rmdir()  # empty (checked)
            os.replace(staging, out)
        except BaseException:
            shutil.rmtree(staging, ignore_errors=True)
            raise
    cells = out / "cells"
    cells.mkdir(exist_ok=True)
    for p in recompute:
        shutil.rmtree(cells / p.name)
    for p in plans:
        d = cells / p.name
        if d.exists():
            continue
        staging = cells / f".{p.name}.tmp-{os.getpid()}"
        try:
            staging.mkdir()
            (staging / "scenario.toml").write_text(tomli_w.dumps(p.scenario), encoding="utf-8")
            for g in p.groups:
                (staging / f"{g.kind}.toml").write_text(tomli_w.dumps(p.campaigns[g.kind]), encoding="utf-8")
            (staging / "cell.json").write_text(json.dumps(P.cell_record(arena, p), indent=1), encoding="utf-8")
            os.replace(staging, d)
        except BaseException:
            shutil.rmtree(staging, ignore_errors=True)
            raise
    _write_atomic(out / "arena.toml", arena.text)
    marker = _read_json(out / MARKER) or {"kind": KIND, "version": VERSION, "arena": arena.name, "sessions": []}
    marker.setdefault("sessions", []).append({"started": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "arena": arena.name,
                                              "file": str(arena.path), "arena_sha256": arena.digest,
                                              "overrides": arena.overrides, "cells": [p.name for p in plans],
                                              "recomputed": [p.name for p in recompute]})
    _write_atomic(out / MARKER, json.dumps(marker, indent=1))


# -- measuring -----------------------------------------------------------------------------------------------------
def measure_all(arena: Arena, plans: list, out: Path) -> tuple:
    """Every stored run of the plan's campaigns in ``out`` measured: (runs table, {row index: (t, s)}
    of the detector statistic of the runs with an estimate)."""
    import pandas as pd

    rows, statistics = [], {}
    for p in plans:
        for g in p.groups:
            folder = out / "cells" / p.name / g.kind
            summary = folder / "summary.parquet"
            if summary.is_file():
                rows += measure_cell(arena, p, folder, api.read_table(summary), statistics, offset=len(rows))
    return pd.DataFrame(rows), statistics


def measure_cell(arena: Arena, p, run_folder: Path, summary, statistics: dict, offset: int) -> list:
    """One row per stored run of a cell's campaign: identity, draw, status, outcome, metrics; the
    detector statistic of each run with an estimate goes into ``statistics`` under its row index."""

    from plant.hardware.datasheets import WHEELS

    from . import cells as C

    cell, hw = p.cell, p.hardware
    sig = C.metric_signals(p.scenario, cell)
    target = C.target(p.scenario)
    plant = arena.plants[cell.plant]
    method = arena.methods[cell.method]
    rows = []
    for rec in summary.to_dict("records"):
        status = rec.get("status") or "failed"
        traj = api.trajectory_file(run_folder, rec)
        df = _trajectory(traj) if traj.is_file() else None
        fault = rec["variant"]
        onset = rec.get("requested:faults.onset")
        m = measure(df, sig, band=plant.band, status=status, error=rec.get("error"), t_end=rec.get("t_end"),
                    fault_class=fault, onset=onset if fault not in ("none", "markov") else None,
                    manoeuvres=p.manoeuvres, target=target, nominal=cell.nominal, estimate_from=cell.estimate_from,
                    wheels=WHEELS, ideal=hw == "ideal")
        stat = m.pop("statistic")
        if stat is not None:
            statistics[offset + len(rows)] = stat
        rows.append({"cell": cell.name, "method": cell.method, "method_label": method.label, "paper": method.paper,
                     "plant": cell.plant, "gains": cell.gains, "hardware": hw, "fault": fault,
                     "within_claims": method.claims_class(fault), "deterministic": C.deterministic(hw, fault),
                     "draw": int(rec["draw"]), "run_id": int(rec["run_id"]), "status": status,
                     "error": rec.get("error"), "mission": arena.mission(cell), "estimate_from": cell.estimate_from,
                     "loss": rec.get("requested:faults.loss"), "channel": rec.get("requested:faults.channel"),
                     "wall_time_s": rec.get("wall_time_s"), "cpu_time_s": rec.get("cpu_time_s"), **m})
    return rows


def _trajectory(path: Path) -> dict:
    """A stored trajectory as {column: numpy array} (read with pyarrow directly: a pandas DataFrame
    costs more to build and index than the measuring itself)."""
    import pyarrow.parquet as pq

    api.check_readable(path)  # the one reader's checks (a regular file of bounded size), then pyarrow directly
    with pq.ParquetFile(path) as f:
        t = f.read()
    return {n: t.column(n).to_numpy() for n in t.column_names}


command = run_arena  # the registry's entry (papers/registry.py: APPLICATIONS)
