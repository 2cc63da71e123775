"""``ftcsim arena FILE --out DIR``: the arena's cells as campaigns on the campaign engine, measured and
ranked on one page (issue 26 item 6). The orchestrator reaches this module by the string in the
registry (``papers/registry.py: applications``); it uses the orchestrator's public face only.

Steps: the arena file is checked (``arena/arenafile.py``) and every cell's scenario derived and
loaded (``arena/cells.py``) before anything is written; the folder is then published with a copy
of the arena file and, per cell and hardware, ``cells/<method>@<plant>.<hardware>/`` holding the
derived ``scenario.toml``, its ``campaign.toml`` and the campaign folder ``run/``
(``orchestrator.api.campaign``: Dask workers or this process, resumable). Each stored run's
trajectory is measured (``arena/measure.py``) into ``tables/runs.parquet``; the leaderboard
(``arena/leaderboard.py``) writes its tables beside it and ``leaderboard.html``.

Rerunning the same command on the same folder resumes: the campaigns compute only the runs they
have not stored, and the tables and page are written again from everything stored. A campaign that
comes back incomplete (a signal stopped it, or workers lost runs) ends the arena there: the page is
written from what is stored and the command says how many runs are missing. A folder
holding another arena (or anything else) is refused.
"""
from __future__ import annotations

import json
import os
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import tomli_w

from orchestrator import api

from . import cells as C
from .arenafile import Arena, load
from .measure import METRICS, UNITS, measure

MARKER = "arena.json"


@dataclass
class Outcome:
    folder: Path
    planned: int
    stored: int
    failed: int  # stored runs with no result (never ranked)
    wall_s: float
    page: Path | None


def cell_id(cell, hardware) -> str:
    return f"{cell.method}_on_{cell.plant}.{hardware}"


def plan(arena: Arena) -> list:
    """[(cell, hardware, scenario doc, campaign doc)] in the arena's order; every derived scenario
    loaded (checked) through ``orchestrator.api.load``."""
    import tempfile

    try:
        return _plan(arena, tempfile)
    except OSError as e:  # the checks' temporary files (TMPDIR full, a size limit): one line
        raise api.InputError(tempfile.gettempdir(), "-", f"cannot write the arena's check files there: "
                             f"{e.strerror or e}") from None


def _plan(arena: Arena, tempfile) -> list:
    out = []
    with tempfile.TemporaryDirectory(prefix="ftcsim-arena-check-") as tmp:
        for cell in arena.cells:
            for hw in arena.hardware:
                key = f"cells[{arena.cells.index(cell)}]"
                try:
                    doc = C.cell_scenario(arena, cell, hw)
                except (ValueError, KeyError) as e:
                    raise api.InputError(arena.path, f"{key}.scenario", f"{cell.name} ({hw}): {e}") from None
                d = Path(tmp) / cell_id(cell, hw)
                d.mkdir()
                f = d / "scenario.toml"
                f.write_text(tomli_w.dumps(doc), encoding="utf-8")
                try:
                    api.load(str(f), mode=arena.mode, fmu_dir=str(arena.fmu_dir) if arena.fmu_dir else None)
                except api.InputError as e:
                    raise api.InputError(arena.path, f"{key}.scenario", f"{cell.name} ({hw}): {e.key}: {e.problem}") from None
                camp = C.campaign_doc(arena, cell, hw, "scenario.toml", doc)
                (d / "campaign.toml").write_text(tomli_w.dumps(camp), encoding="utf-8")
                try:  # the campaign as `ftcsim campaign` will run it (stop, seed, draws): before anything is written
                    api.plan_campaign(d / "campaign.toml")
                except api.InputError as e:
                    where = CAMPAIGN_KEYS.get(e.key, f"{key}.campaign")
                    raise api.InputError(arena.path, where, f"{cell.name} ({hw}): {e.key}: {e.problem}") from None
                out.append((cell, hw, doc, camp))
    return out


# the campaign keys the arena file decides (a problem there is named in the arena file)
CAMPAIGN_KEYS = {"campaign.stop": "arena.stop", "campaign.seed": "arena.seed", "campaign.runs": "arena.draws",
                 "campaign.trajectory_step": "arena.trajectory_step", "campaign.mode": "arena.mode"}


def open_folder(arena: Arena, out: Path, cells: list, overwrite: bool = False) -> bool:
    """Publish a new arena folder (True) or accept a folder of the same arena (False: resume); with
    ``overwrite`` an arena folder (of this arena or another) is replaced by a new one, nothing else."""
    marker = out / MARKER
    api.check_target(out)  # a name with room for the staging folder, writable, not /proc: before anything
    replace = False
    if out.is_symlink():
        raise api.InputError("command line", "--out", f"{out} is a symbolic link; give the real folder")
    if out.exists():
        if marker.is_file() and not marker.is_symlink():
            try:
                prev = json.loads(marker.read_text(encoding="utf-8"))
            except (OSError, ValueError):
                prev = {}
            prev = prev if isinstance(prev, dict) else {}
            if overwrite:
                replace = True
            elif prev.get("arena_sha256") != arena.digest:
                raise api.InputError("command line", "--out", f"{out} holds another arena ({prev.get('arena', '?')}): "
                                                              "pass --overwrite to replace it, or choose another folder")
            else:
                return False
        elif not out.is_dir() or any(out.iterdir()):
            raise api.InputError("command line", "--out", f"{out} exists and is not an arena folder: choose another "
                                                          "folder (nothing there is replaced)")
    staging = out.parent / f".{out.name}.tmp-{os.getpid()}"
    try:
        (staging / "cells").mkdir(parents=True)
        (staging / "arena.toml").write_text(arena.text, encoding="utf-8")
        for cell, hw, doc, camp in cells:
            d = staging / "cells" / cell_id(cell, hw)
            d.mkdir()
            (d / "scenario.toml").write_text(tomli_w.dumps(doc), encoding="utf-8")
            (d / "campaign.toml").write_text(tomli_w.dumps(camp), encoding="utf-8")
        (staging / MARKER).write_text(json.dumps({"arena": arena.name, "arena_sha256": arena.digest,
                                                  "file": str(arena.path), "runs": arena.n_runs}, indent=1),
                                      encoding="utf-8")
        if replace:  # the previous arena moved aside, removed once the new folder is in place
            old = out.parent / f".{out.name}.old-{os.getpid()}"
            os.rename(out, old)
            try:
                os.replace(staging, out)
            except BaseException:
                os.rename(old, out)
                raise
            shutil.rmtree(old, ignore_errors=True)
        else:
            if out.exists():
                out.rmdir()  # empty (checked above)
            os.replace(staging, out)
    except OSError as e:  # a full disk while the folder is written: one line, nothing published
        shutil.rmtree(staging, ignore_errors=True)
        raise api.InputError("command line", "--out", f"cannot write {out}: {e.strerror or e}; nothing published"
                             + (", the previous arena there is unchanged" if out.exists() else "")) from None
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        raise
    return True


def run_arena(file, out, *, workers: int | None = None, scheduler: str | None = None, progress: bool = False,
              overwrite: bool = False, **engine) -> Outcome:
    """Run (or resume) an arena into ``out`` and write its leaderboard; ``workers=0``: in this
    process; ``scheduler``: an existing Dask scheduler's address; other keywords (``client``,
    ``scheduler_file``, ...) go to ``orchestrator.api.campaign`` as they are."""
    started = time.perf_counter()
    arena = load(file)
    cells = plan(arena)  # every check before anything is written
    out = Path(out)
    cluster = None
    if scheduler is not None:  # reached before anything is written: an unreachable scheduler leaves nothing
        scheduler = api.reach_scheduler(scheduler)
    elif workers != 0 and not engine:
        cluster = api.start_local_cluster(workers)  # scratch space removed on close; SIGINT honoured
        scheduler = cluster.cluster.scheduler_address
    try:
        open_folder(arena, out, cells, overwrite)
    except BaseException:
        if cluster is not None:
            cluster.close()
        raise
    try:
        rows = []
        for cell, hw, doc, _ in cells:
            d = out / "cells" / cell_id(cell, hw)
            kw = {"workers": 0} if workers == 0 and scheduler is None and not engine else {"scheduler": scheduler}
            if engine:
                kw = dict(engine)
            t0 = time.perf_counter()
            summary = _campaign(d, kw)
            if progress:
                print(f"arena {arena.name}: {cell_id(cell, hw)}: {len(summary)} runs ({time.perf_counter() - t0:.1f} s)",
                      file=sys.stderr, flush=True)
            rows += measure_cell(arena, cell, hw, doc, d / "run", summary)
            if len(summary) < arena.draws * len(arena.faults):
                # interrupted (SIGINT / SIGTERM reach the campaign) or runs lost: stop here; what is
                # stored is measured and ranked below, and the same command resumes
                break
    finally:
        if cluster is not None:
            cluster.close()
    import pandas as pd

    runs = pd.DataFrame(rows)
    if runs.empty:  # nothing stored yet (interrupted at once): no page to write
        return Outcome(out, arena.n_runs, 0, 0, time.perf_counter() - started, None)
    from . import leaderboard

    page = leaderboard.write(arena, runs, out, api.write_table, units=UNITS)
    failed = int((runs["outcome"] == "failed").sum()) if len(runs) else 0
    return Outcome(out, arena.n_runs, len(runs), failed, time.perf_counter() - started, page)


def _campaign(folder: Path, kw: dict):
    import pandas as pd

    try:
        return api.campaign(str(folder / "campaign.toml"), str(folder / "run"), **kw)
    except FileNotFoundError:  # nothing stored (every run lost): no summary
        return pd.DataFrame()


def measure_cell(arena: Arena, cell, hw: str, doc: dict, run_folder: Path, summary) -> list:
    """One row per stored run of a cell: identity, draw, status, outcome and metrics."""

    sig = C.metric_signals(doc, cell)
    target = C.target(doc)
    plant = arena.plants[cell.plant]
    method = arena.methods[cell.method]
    rows = []
    for rec in summary.to_dict("records"):
        status = rec.get("status", "failed")
        traj = api.trajectory_file(run_folder, rec)
        df = api.read_table(traj) if traj.is_file() and status != "failed" else None
        fault = rec["variant"]
        onset = 0.0 if fault == "markov" else rec.get("requested:faults.onset")
        m = measure(df, sig, band=plant.band, settle_from=plant.settle_from, status=status, fault_class=fault,
                    onset=onset, target=target, threshold=cell.threshold, nominal=cell.nominal,
                    estimate_from=cell.estimate_from)
        rows.append({"method": cell.method, "method_label": method.label, "method_paper": method.paper,
                     "plant": cell.plant, "gains": cell.gains, "hardware": hw, "fault": fault,
                     "draw": int(rec["draw"]), "run_id": int(rec["run_id"]), "status": status,
                     "error": rec.get("error"), "onset": rec.get("requested:faults.onset"),
                     "loss": rec.get("requested:faults.loss"), "channel": rec.get("requested:faults.channel"),
                     "wall_time_s": rec.get("wall_time_s"), **{k: m[k] for k in METRICS}, "outcome": m["outcome"]})
    return rows


command = run_arena  # the registry's entry (papers/registry.py: APPLICATIONS)
