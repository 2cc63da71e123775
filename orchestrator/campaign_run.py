"""``ftcsim campaign CAMPAIGN.toml --out DIR``: run a campaign on dask.distributed, resumably.

Execution. The runs of :func:`orchestrator.campaign.expand` are tasks of a Dask cluster: a
``LocalCluster`` of ``--workers`` processes with one thread each (the default; never more
threads than cores asked for) or an existing scheduler (``--scheduler ADDRESS``; its workers
need this installation and the same FMU, scenario and design files at the same paths: each run
checks the FMUs' SHA-256 against the plan). A worker loads each variant's base scenario once
(cached) and runs every task as ``ftcsim run`` with the task's overrides (FMUs through fmpy
by default); after set-up it reads every dispersed value back from the FMUs (fmi2GetReal /
fmi3GetFloat64 of the parameters) for the summary. ``--workers 0`` runs in this process
without Dask (debugging).

Durability. The folder (marker kind ``campaign``, :mod:`orchestrator.common.outputs`) is published at
the start with a copy of the campaign file and ``manifest.json`` (package and FMU versions,
digests); each finished run is written at once as ``runs/<run id>-<key>.parquet`` (one row,
written to a temporary file and renamed), its trajectory first (``trajectories/run_id=<id>/``).
A worker that dies takes no result with it: the scheduler gives its runs to another worker
(``distributed.scheduler.allowed-failures``). SIGINT / SIGTERM stop the campaign at once (runs in
flight are abandoned), the summary of what is finished is written and the exit status is
130 / 143; rerunning the same command on the same ``--out`` computes only the runs whose key
is not stored. A campaign file that differs from the one the folder was started with is
refused unless ``--overwrite``, and so are stored runs whose key no longer matches (FMUs or
scenario changed since).

Outputs: ``summary.parquet`` (one row per stored run, in run-id order: run_id, key, variant,
point, draw, seed, the grid values and the dispersed values as read back (``inst.name``) and as
requested (``requested:inst.name``), every metric of ``ftcsim run``, ``settling_time``, status
(``ok`` | ``incomplete`` | ``failed``), error, and the execution record: ``wall_time_s`` and
``cpu_time_s`` (the task on its worker), ``sim_time_s`` (the master's stepping, without set-up) and ``worker``, the
only columns that differ between two runs of the same campaign). Read it with
``pandas.read_parquet("DIR/summary.parquet")``; trajectories with
``pandas.read_parquet("DIR/trajectories")``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import os
import socket
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from orchestrator.campaign import Campaign, expand, file_digest, load_base
from orchestrator.campaign import load as load_campaign
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.interrupt import handling_signals
from orchestrator.common.jsonio import write_json_atomic
from orchestrator.common.outputs import OutputFolder, is_result_folder
from orchestrator.cosim.runner import run_scenario
from orchestrator.results import compute_metrics, write_results
from orchestrator.scenario.overrides import with_overrides

SUMMARY = "summary.parquet"
MANIFEST = "manifest.json"
CAMPAIGN_COPY = "campaign.toml"
RUNS = "runs"
TRAJECTORIES = "trajectories"
EXECUTION_COLUMNS = ("wall_time_s", "cpu_time_s", "sim_time_s", "worker")
_DROPPED_METRICS = ("wall_time_s", "real_time_factor", "signals", "scenario", "mode", "exchange", "paper",
                    "complete", "error")


# -- on the worker ------------------------------------------------------------------------------
_BASES: dict = {}


def _base(spec):
    k = json.dumps(spec.recipe, sort_keys=True)
    if k not in _BASES:
        _BASES[k] = load_base(spec.recipe)[0]
    return _BASES[k]


def settling_time(result, cfg) -> float | None:
    """Time (s, from ``cfg['from']``) after which the norm of the signal stays within
    ``cfg['level']`` until the end of the run; for a quaternion (4 elements, first index 0) the
    norm of its vector part. None if it is outside the band at the last sample."""
    cols = [result.columns.index(c) for c in cfg["columns"]]
    x = result.data[:, cols]
    if len(cols) == 4 and cfg["columns"][0].endswith("[0]"):
        x = x[:, 1:]
    t = result.time
    w = t >= cfg["from"] - 1e-9
    if not w.any():
        return None
    e = np.linalg.norm(x[w], axis=1)
    tw = t[w]
    outside = np.nonzero(~(e <= cfg["level"]))[0]
    if len(outside) == 0:
        return 0.0
    if outside[-1] == len(e) - 1:
        return None
    return float(tw[outside[-1] + 1] - cfg["from"])


def execute(spec) -> dict:
    """One run (on a worker): {"row": summary row, "trajectory": {column: array} or None}; a run
    that a signal to this process stopped (``--workers 0``) gives ``{"interrupted": signum}``."""
    started, cpu = time.perf_counter(), time.process_time()
    row = {"run_id": spec.run_id, "key": spec.key, "variant": spec.variant_name, "point": spec.point,
           "draw": spec.draw, "seed": spec.seed}
    readback = dict.fromkeys(spec.requested, None)
    trajectory = None
    try:
        for path, digest in spec.fmu_digests.items():
            if file_digest(path) != digest:
                raise SimulationError(f"{path} on this worker ({socket.gethostname()}) is not the FMU the campaign was "
                                      "planned with (SHA-256 differs)")
        sc = with_overrides(_base(spec), parameters=spec.parameters, src="campaign")
        by_instance: dict = {}
        for ref in spec.requested:
            inst, _, name = ref.partition(".")
            by_instance.setdefault(inst, []).append(name)

        def read_back(components):
            for inst, names in by_instance.items():
                for n, x in zip(names, components[inst].read_values(names)):
                    readback[f"{inst}.{n}"] = x

        raw = run_scenario(sc, after_setup=read_back)
        if raw.interrupted:  # stopped by a signal to this process: not a result, never stored
            return {"row": None, "trajectory": None, "interrupted": raw.interrupted}
        row["sim_time_s"] = raw.wall_time
        metrics = compute_metrics(raw, sc)
        if spec.settling and len(raw.time):
            metrics["settling_time"] = settling_time(raw, spec.settling)
        row["status"] = "ok" if raw.complete else ("incomplete" if len(raw.time) else "failed")
        row["error"] = raw.error
        for k, v in metrics.items():
            if k in _DROPPED_METRICS or not (v is None or isinstance(v, (bool, int, float))):
                continue
            row[k] = None if isinstance(v, float) and not math.isfinite(v) else v
        if spec.trajectories and len(raw.time):
            every = 1 if not spec.trajectory_step else max(1, int(round(spec.trajectory_step / sc.step)))
            keep = np.arange(0, len(raw.time), every)
            trajectory = {"time": raw.time[keep]}
            for c in spec.trajectories:
                trajectory[c] = raw.data[keep, raw.columns.index(c)]
    except Exception as e:  # the run failed; the campaign goes on and the row says why
        row["status"] = "failed"
        row["error"] = f"{type(e).__name__}: {' '.join(str(e).split())}" if not isinstance(e, (InputError,
                                                                                             SimulationError)) \
            else " ".join(str(e).split())
    for ref, x in readback.items():
        row[ref] = x
    for ref, x in spec.requested.items():
        row[f"requested:{ref}"] = x
    row["wall_time_s"] = time.perf_counter() - started
    row["cpu_time_s"] = time.process_time() - cpu
    row.setdefault("sim_time_s", None)
    row["worker"] = f"{socket.gethostname()}:{os.getpid()}"
    return {"row": row, "trajectory": trajectory}


# -- storage ------------------------------------------------------------------------------------
def run_file(spec_or_row) -> str:
    run_id = spec_or_row.run_id if hasattr(spec_or_row, "run_id") else spec_or_row["run_id"]
    key = spec_or_row.key if hasattr(spec_or_row, "key") else spec_or_row["key"]
    return f"{run_id:07d}-{key}.parquet"


def _write_table_atomic(table, path: Path) -> None:
    import pyarrow.parquet as pq

    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.parent / f".tmp-{os.getpid()}-{path.name}"
    try:
        pq.write_table(table, tmp)
        with open(tmp, "rb") as f:
            os.fsync(f.fileno())
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def store(folder: Path, result: dict) -> None:
    """Write one finished run durably: its trajectory, then its summary row."""
    import pyarrow as pa

    row = result["row"]
    if result.get("trajectory"):
        tr = result["trajectory"]
        _write_table_atomic(pa.table({k: np.asarray(v, dtype=float) for k, v in tr.items()}),
                            folder / TRAJECTORIES / f"run_id={row['run_id']}" / "part-0.parquet")
    _write_table_atomic(pa.Table.from_pylist([row]), folder / RUNS / run_file(row))


def stored(folder: Path) -> dict:
    """{(run_id, key): file} of the runs stored in a campaign folder."""
    out = {}
    for p in (folder / RUNS).glob("*.parquet"):
        rid, _, key = p.stem.partition("-")
        if rid.isdigit() and key:
            out[(int(rid), key)] = p
    return out


def combine(folder: Path, plan) -> int:
    """Write summary.parquet from the stored runs of ``plan`` (run-id order); returns the row count."""
    import pandas as pd
    import pyarrow as pa

    have = stored(folder)
    files = [have[(s.run_id, s.key)] for s in plan if (s.run_id, s.key) in have]
    frames = [pd.read_parquet(f) for f in files]
    df = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame({"run_id": []})
    if len(df):
        df = df.sort_values("run_id", kind="stable").reset_index(drop=True)
        first = ["run_id", "key", "variant", "point", "draw", "seed"]
        tail = ["status", "error", *EXECUTION_COLUMNS]
        middle = [c for c in df.columns if c not in first and c not in tail]
        df = df[[c for c in first + middle + tail if c in df.columns]]
    _write_table_atomic(pa.Table.from_pandas(df, preserve_index=False), folder / SUMMARY)
    return len(df)


# -- manifest -----------------------------------------------------------------------------------
def _versions() -> dict:
    from importlib import metadata

    out = {"python": sys.version.split()[0]}
    for pkg in ("ftcsim", "numpy", "scipy", "fmpy", "pythonfmu", "pythonfmu3", "dask", "distributed", "pyarrow",
                "pandas"):
        try:
            out[pkg] = metadata.version(pkg)
        except metadata.PackageNotFoundError:
            out[pkg] = None
    return out


def _fmus(c) -> list:
    from fmpy import read_model_description

    seen = {}
    for sc in c.bases:
        for inst in sc.instances.values():
            if inst.fmu is None or str(inst.fmu) in seen:
                continue
            md = read_model_description(str(inst.fmu), validate=False)
            seen[str(inst.fmu)] = {"path": str(inst.fmu), "sha256": file_digest(inst.fmu), "model": md.modelName,
                                   "fmi_version": md.fmiVersion, "guid": md.guid, "generation_tool": md.generationTool,
                                   "generated": md.generationDateAndTime}
    return list(seen.values())


def manifest(c, plan) -> dict:
    return {
        "campaign": c.name, "description": c.description, "campaign_file": str(c.path.resolve()),
        "campaign_sha256": c.digest, "runs": len(plan), "draws": c.runs, "seed": c.seed, "mode": c.mode,
        "variants": [{"name": v.name, "scenario": v.scenario, "fmus": v.fmus, "gains": v.gains,
                      "parameters": v.parameters, "dropped_parameters": v.dropped} for v in c.variants],
        "grid": [{"parameter": r, "values": vals} for r, vals in c.grid],
        "dispersions": [{"parameter": d.ref, "distribution": d.distribution, "apply": d.apply, "shared": d.shared,
                         "elements": [f"{d.inst}.{n}" for n in d.names]} for d in c.dispersions],
        "settling": c.settling, "requirements": c.requirements,
        "trajectories": c.trajectories, "trajectory_step": c.trajectory_step,
        "versions": _versions(), "fmus": _fmus(c), "sessions": [], "status": "running",
    }


def _read_manifest(folder: Path) -> dict:
    try:
        data = json.loads((folder / MANIFEST).read_text(encoding="utf-8"))
        return data if isinstance(data, dict) else {}
    except (OSError, ValueError):
        return {}


# -- executors ----------------------------------------------------------------------------------
@dataclass
class Outcome:
    folder: Path
    total: int  # runs in the plan
    stored: int  # runs stored when the command ended
    computed: int  # runs computed by this command
    skipped: int  # runs found stored at the start
    failed: int  # stored runs whose status is not "ok"
    lost: int  # runs no worker could finish (not stored; a rerun retries them)
    interrupted: int = 0  # signal number (0: none)


def connect(workers: int | None, scheduler: str | None, timeout: float = 5.0):
    """A dask.distributed Client: to ``scheduler`` (refused within ``timeout`` s if unreachable) or
    to a new LocalCluster of ``workers`` processes with one thread each."""
    import logging
    import signal

    import dask
    from distributed import Client, LocalCluster

    dask.config.set({"distributed.scheduler.allowed-failures": 3, "distributed.comm.timeouts.connect": f"{timeout}s"})
    if scheduler:
        try:
            return Client(scheduler, timeout=timeout, set_as_default=False)
        except (OSError, TimeoutError, ValueError, TypeError) as e:
            detail = " ".join(str(e).split())[:200] or type(e).__name__
            raise InputError("command line", "--scheduler",
                             f"no Dask scheduler reachable at {scheduler!r} within {timeout:g} s ({detail})") from None
    n = workers or os.cpu_count() or 1
    # the workers ignore SIGINT (a Ctrl-C reaches the whole process group): this process decides
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN) if _main_thread() else None
    saved_path = sys.path[:]
    # the workers start with this process's sys.path; an FMU run here has put its extracted
    # resources/ on it, whose partial copies of our packages (papers/ without paper.py, ...) would
    # hide the project's in a fresh process
    sys.path[:] = [p for p in sys.path if not _is_fmu_resources(p)]
    try:
        cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                               silence_logs=logging.ERROR)
    finally:
        sys.path[:] = saved_path
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    return Client(cluster, set_as_default=False)


def _is_fmu_resources(folder: str) -> bool:
    """True for an extracted FMU's resources folder (pythonfmu's slavemodule.txt is there)."""
    return bool(folder) and os.path.isfile(os.path.join(folder, "slavemodule.txt"))


def _main_thread() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()


def _close(client) -> None:
    cluster = getattr(client, "cluster", None)
    try:
        client.close()
    except Exception:
        pass
    if cluster is not None:
        try:
            cluster.close()
        except Exception:
            pass


# -- the command --------------------------------------------------------------------------------
def open_folder(c, plan, out, overwrite: bool):
    """The campaign folder, locked: new (published at once), replaced (``overwrite``) or resumed
    (same campaign file, every stored run still in the plan)."""
    out = Path(out)
    if is_result_folder(out, "campaign") and not overwrite:
        prev = _read_manifest(out)
        if prev.get("campaign_sha256") != c.digest:
            raise InputError("command line", "--out", f"{out} holds another campaign ({prev.get('campaign', '?')}, "
                                                      f"from a different campaign file): pass --overwrite to replace it, "
                                                      "or choose another folder")
    folder = OutputFolder(out, "campaign", overwrite=overwrite,
                          resume=lambda p: _read_manifest(p).get("campaign_sha256") == c.digest).check()
    try:
        if folder.resuming:
            keys = {(s.run_id, s.key) for s in plan}
            stale = [k for k in stored(out) if k not in keys]
            if stale:
                raise InputError("command line", "--out", f"{out}: {len(stale)} stored runs were computed from other "
                                 "inputs (the FMUs, the base scenario or a design file changed since): pass --overwrite "
                                 "to start the campaign again")
        else:
            tmp = folder.staging()
            (tmp / CAMPAIGN_COPY).write_text(c.text, encoding="utf-8")
            (tmp / RUNS).mkdir()
            write_json_atomic(tmp / MANIFEST, manifest(c, plan))
            folder.publish(keep_lock=True)
    except BaseException:
        if folder.tmp is not None:
            folder.discard()
        folder.release()
        raise
    return folder


def run_campaign(campaign, out, *, workers: int | None = None, scheduler: str | None = None, overwrite=False,
                 only=None, progress=False, client=None, connect_timeout: float = 5.0, on_result=None) -> Outcome:
    """Run (or resume) a campaign into ``out``; see the module docstring. ``campaign``: a path or
    a loaded :class:`orchestrator.campaign.Campaign`; ``only``: run ids to compute (the others
    are left as they are); ``client``: an existing dask.distributed Client (kept open);
    ``on_result(outcome_so_far)``: called after each stored run (tests, progress hooks)."""
    c = campaign if isinstance(campaign, Campaign) else load_campaign(campaign)
    plan = expand(c)
    todo_ids = None if only is None else set(only)
    if todo_ids is not None:
        expand(c, only=todo_ids)  # refuses ids outside the plan
    serial = workers == 0 and client is None and scheduler is None
    own_client = None
    if not serial and client is None:  # before anything is written: a bad --scheduler leaves nothing behind
        client = own_client = connect(workers, scheduler, connect_timeout)
    try:
        folder = open_folder(c, plan, out, overwrite)
    except BaseException:
        if own_client is not None:
            _close(own_client)
        raise
    path = folder.path
    started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    outcome = Outcome(path, len(plan), 0, 0, 0, 0, 0)
    try:
        done = set(stored(path))
        missing = [s for s in plan if (s.run_id, s.key) not in done and (todo_ids is None or s.run_id in todo_ids)]
        outcome.skipped = sum((s.run_id, s.key) in done for s in plan)
        bar = _bar(len(missing), c.name, progress)
        failures = 0

        def finished(result):
            nonlocal failures
            if result.get("interrupted"):
                return
            store(path, result)
            outcome.computed += 1
            failures += result["row"]["status"] != "ok"
            bar.update(1)
            if failures:
                bar.set_postfix(failed=failures, refresh=False)
            if on_result is not None:
                on_result(outcome)

        with handling_signals() as request:
            if serial:
                for spec in missing:
                    if request:
                        break
                    finished(execute(spec))
            elif missing:
                outcome.lost = _run_dask(client, missing, finished, request)
            outcome.interrupted = request.signum
        bar.close()
    finally:
        try:
            if own_client is not None:
                _close(own_client)
            n = combine(path, plan)
            outcome.stored = n
            info = _read_manifest(path) or manifest(c, plan)
            import pandas as pd

            df = pd.read_parquet(path / SUMMARY, columns=["status"]) if n else None
            outcome.failed = int((df["status"] != "ok").sum()) if n else 0
            info["status"] = "complete" if n == len(plan) else "incomplete"
            info["stored_runs"] = n
            info.setdefault("sessions", []).append({
                "started": started, "ended": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "computed": outcome.computed,
                "skipped": outcome.skipped, "lost": outcome.lost, "interrupted": outcome.interrupted,
                "workers": workers, "scheduler": scheduler, "host": socket.gethostname()})
            write_json_atomic(path / MANIFEST, info)
        finally:
            folder.release()
    return outcome


def _run_dask(client, specs, finished, request) -> int:
    """Submit ``specs``, store each result as it arrives, stop when ``request`` is set. Returns
    the number of runs lost (their task failed outside the run itself, e.g. every worker that
    tried it died)."""
    # no other reference to the futures: a stored result is released from the worker's memory
    pending = client.map(execute, specs, key=[f"ftcsim-run-{s.run_id}-{s.key}" for s in specs], pure=False)
    lost = 0
    try:
        while pending and not request:
            batch = [f for f in pending if f.done()]
            if not batch:
                time.sleep(0.05)
                continue
            ready = set(batch)
            pending = [f for f in pending if f not in ready]
            for f in batch:
                status = f.status
                if status in ("lost", "pending"):
                    # done a moment ago, then its worker died before we read it: the scheduler
                    # recomputes it elsewhere, so it is still pending (not lost to the campaign)
                    pending.append(f)
                elif status == "finished":
                    try:  # waits if the data is lost meanwhile and recomputed
                        row = f.result()
                    except Exception as e:  # noqa: BLE001 - its recomputation failed or was cancelled
                        lost += 1
                        _report_lost(f.key, type(e).__name__, e)
                        continue
                    finished(row)
                else:
                    lost += 1
                    _report_lost(f.key, f.status, f.exception())
    finally:
        if pending:
            client.cancel(list(pending), force=True)
    return lost


def _report_lost(key, status, exception) -> None:
    print(f"ftcsim: run {key} could not be computed ({status}: {' '.join(str(exception).split())[:200]}); "
          "a rerun retries it", file=sys.stderr)


def _bar(total, name, progress):
    from tqdm import tqdm

    return tqdm(total=total, desc=name, unit="run", disable=not progress or total == 0, file=sys.stderr,
                dynamic_ncols=True, smoothing=0.1)


def replay(campaign, run_id: int, out, overwrite=False, progress=True):
    """Run ``run_id`` of a campaign alone as an ordinary ``ftcsim run`` folder (results.csv,
    metrics.json, plots) at ``out``: the full trajectories of, say, a worst run."""
    c = campaign if isinstance(campaign, Campaign) else load_campaign(campaign)
    (spec,) = expand(c, only=[run_id])
    sc = with_overrides(load_base(spec.recipe)[0], parameters=spec.parameters, src="campaign")
    sc = dataclasses.replace(sc, name=f"{c.name}-run{run_id}")
    folder = OutputFolder(out, "run", overwrite=overwrite).check()
    try:
        raw = run_scenario(sc, progress=progress)
    except BaseException:
        folder.discard()
        raise
    metrics, errors = write_results(folder, raw, sc)
    return raw, metrics, errors
