"""``ftcsim campaign CAMPAIGN.toml --out DIR``: run a campaign on dask.distributed, resumably.

Execution. The runs of :func:`orchestrator.campaign.expand` are tasks of a Dask cluster (batches
of runs, :mod:`orchestrator.campaign.cluster`): a ``LocalCluster`` of ``--workers`` processes with
one thread each (the default; at most the cores unless forced) or an existing cluster
(``--scheduler ADDRESS``, ``--scheduler-file FILE``, in Python ``client=`` / ``cluster=``). The
variants' base scenarios, their FMU files (checked by SHA-256) and the kernel cache travel to the
workers of an existing cluster (:mod:`orchestrator.campaign.shipping`): they need this installation
and nothing at the same paths. A worker runs every task as ``ftcsim run`` with the task's overrides
(FMUs through fmpy by default); after set-up it reads every dispersed value back from the FMUs
(fmi2GetReal / fmi3GetFloat64 of the parameters) for the summary. ``--workers 0`` runs in this
process without Dask (debugging). No global Dask configuration is changed.

Durability. The folder (marker kind ``campaign``, :mod:`orchestrator.common.outputs`) is published at
the start with a copy of the campaign file and ``manifest.json`` (package and FMU versions,
digests); each finished run is written at once as ``runs/<run id>-<key>.parquet`` (one row,
written to a temporary file and renamed), its trajectory first (``trajectories/<run id>-<key>.parquet``),
both in the campaign's declared schema (:mod:`orchestrator.campaign.schema`). Stored run files are
verified when read (run id, key, schema); a damaged one is named and computed again. Each run has
a wall-time limit (``time_limit``, :mod:`orchestrator.common.watchdog`).
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
(``ok`` | ``failed`` | ``timeout``; a run that is not ok has no metrics), error, and the execution record: ``wall_time_s`` and
``cpu_time_s`` (the task on its worker), ``sim_time_s`` (the master's stepping, without set-up) and ``worker``, the
only columns that differ between two runs of the same campaign). Read it with
``pandas.read_parquet("DIR/summary.parquet")``; trajectories with
``pandas.read_parquet("DIR/trajectories")``.
"""
from __future__ import annotations

import contextlib
import dataclasses
import logging
import os
import socket
import time
from dataclasses import dataclass
from pathlib import Path

from orchestrator.campaign.cluster import MAX_WORKERS, dask_settings, open_connection, run_dask
from orchestrator.campaign.expand import expand
from orchestrator.campaign.schema import run_columns, trajectory_columns
from orchestrator.campaign.spec import Campaign, load_base, recipe
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.campaign.store import (
    CAMPAIGN_COPY,
    MANIFEST,
    RUNS,
    SUMMARY,
    TRAJECTORIES,
    combine,
    manifest,
    manifest_damaged,
    read_manifest,
    started_with,
    store,
    stored,
    verified,
)
from orchestrator.campaign.worker import execute, recipe_key
from orchestrator.common.errors import InputError
from orchestrator.common.interrupt import handling_signals
from orchestrator.common.jsonio import write_json_atomic
from orchestrator.common.outputs import OutputFolder, is_result_folder, store_folder
from orchestrator.common.parquet import read_table
from orchestrator.common.progress import Progress
from orchestrator.cosim.runner import run_scenario
from orchestrator.results.files import write_results
from orchestrator.scenario.overrides import with_overrides
from orchestrator.scenario.shipped import campaign_file
from orchestrator.scenario.values import seconds, whole

log = logging.getLogger("ftcsim.campaign")


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
    damaged: list = dataclasses.field(default_factory=list)  # run files left out of the summary (damaged)


def open_folder(c, plan, out, overwrite: bool):
    """The campaign folder, locked: new (published at once), replaced (``overwrite``) or resumed
    (same campaign file, every stored run still in the plan)."""
    out = Path(out)
    if is_result_folder(out, "campaign") and not overwrite and started_with(out) != c.digest:
        if manifest_damaged(out):
            raise InputError(out / MANIFEST, "-", "damaged (no campaign digest) and the folder's campaign.toml is not "
                                                  "this campaign file: pass --overwrite to start again, or choose "
                                                  "another folder")
        raise InputError("command line", "--out", f"{out} holds another campaign ({read_manifest(out).get('campaign', '?')}, "
                                                  f"from a different campaign file): pass --overwrite to replace it, "
                                                  "or choose another folder")
    folder = OutputFolder(out, "campaign", overwrite=overwrite, resume=lambda p: started_with(p) == c.digest).check()
    try:
        if folder.resuming and manifest_damaged(out):  # rebuilt from the campaign file (the same: digest checked)
            info = manifest(c, plan)
            info["rebuilt"] = time.strftime("%Y-%m-%dT%H:%M:%S%z")
            write_json_atomic(out / MANIFEST, info)
            log.warning("%s: damaged; rebuilt from %s (earlier session records are lost)", out / MANIFEST,
                        out / CAMPAIGN_COPY)
        if folder.resuming:
            for sub in (RUNS, TRAJECTORIES):  # a link or a file where ftcsim keeps its runs: refused, not followed
                store_folder(out, sub, create=False)
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
    except OSError as e:  # a full disk while the folder is started: one line, nothing published
        if folder.tmp is not None:
            folder.discard()
        folder.release()
        raise InputError(folder.source, folder.key, f"cannot write {out}: {e.strerror or e}; nothing published, "
                                                    + ("the previous campaign there is unchanged" if out.exists()
                                                       else "nothing was written there")) from None
    except BaseException:
        if folder.tmp is not None:
            folder.discard()
        folder.release()
        raise
    return folder


def run_campaign(campaign, out, *, workers: int | None = None, scheduler: str | None = None, overwrite=False,
                 only=None, progress=False, client=None, connect_timeout: float = 5.0, on_result=None,
                 cluster=None, scheduler_file=None, force_workers: bool = False, wait_workers: float = 120.0,
                 batch: int | None = None, ship: bool | None = None, dashboard: bool = True,
                 progress_every: float = 30.0, time_limit: float | None = None) -> Outcome:
    """Run (or resume) a campaign into ``out``; see the module docstring. ``campaign``: a path or
    a loaded :class:`orchestrator.campaign.Campaign`; ``only``: run ids to compute (the others
    are left as they are); ``client`` (a ``distributed.Client``, kept open), ``cluster`` (any object
    with ``scheduler_address``: LocalCluster, dask-jobqueue, dask-kubernetes), ``scheduler``
    (address) or ``scheduler_file``: an existing cluster instead of a LocalCluster of ``workers``;
    ``batch``: runs per Dask task (default: from the runs' length); ``ship``: send the FMUs and the
    kernel cache to the workers and warm them (:mod:`.shipping`; default: unless the cluster is a
    LocalCluster of this process, whose workers share this machine's files and cache);
    ``on_result(outcome_so_far)``: called after each stored run (tests, progress hooks);
    ``time_limit``: s of wall time per run, replacing the campaign file's (0: none)."""
    # the one numeric gate for what the command line, the API and the arena hand in (numpy numbers taken)
    if workers is not None:
        workers = whole("api", "workers", workers, lower=0, upper=MAX_WORKERS)
    connect_timeout = seconds("api", "connect_timeout", connect_timeout)
    wait_workers = seconds("api", "wait_workers", wait_workers)
    progress_every = seconds("api", "progress_every", progress_every)
    if batch is not None:
        batch = whole("api", "batch", batch, lower=1, upper=10_000)
    if not isinstance(campaign, Campaign) and not isinstance(campaign, (str, os.PathLike)):
        raise InputError("api", "campaign", f"expected a campaign file or name, got {type(campaign).__name__}")
    if not isinstance(campaign, Campaign) and not Path(campaign).is_file():
        campaign = campaign_file(str(campaign))  # a shipped campaign's name
    c = campaign if isinstance(campaign, Campaign) else load_campaign(campaign)
    if time_limit is not None:
        c = dataclasses.replace(c, time_limit=float(time_limit) or None)
    plan = expand(c)
    todo_ids = None if only is None else set(only)
    if todo_ids is not None:
        expand(c, only=todo_ids)  # refuses ids outside the plan
    serial = workers == 0 and client is None and scheduler is None and cluster is None and scheduler_file is None
    with contextlib.ExitStack() as dask_stack:
        conn = None
        if not serial:  # before anything is written: a bad --scheduler leaves nothing behind
            dask_stack.enter_context(dask_settings(connect_timeout))
            conn = open_connection(workers, scheduler, connect_timeout, scheduler_file=scheduler_file, client=client,
                                   cluster=cluster, force_workers=force_workers, wait_workers=wait_workers,
                                   dashboard=dashboard)
            dask_stack.callback(conn.close)
            log.info("%s: running on %s%s", c.name, conn.where, _dashboard(conn.client))
        folder = open_folder(c, plan, out, overwrite)
        return _run(c, plan, folder, conn, todo_ids, progress, on_result, workers, batch, ship, progress_every,
                    dask_stack, wait_workers)


def _dashboard(client) -> str:
    try:
        link = client.dashboard_link
    except Exception:  # noqa: BLE001 - no dashboard (bokeh missing, or turned off)
        return ""
    return f"; Dask dashboard: {link}" if link else ""


def _batch_size(c, n_runs: int, n_workers: int) -> int:
    """Runs per task: at least 8 tasks per worker (the last wave leaves a worker idle for at most
    one task), tasks of about 1 s at most (estimated from the steps of the longest base scenario:
    40 us per step and instance plus 50 ms per run, measured for li2023_pd with FMUs: a 20 s run,
    2000 steps of 3 instances, is a 0.29 s task), at most 32 runs."""
    steps = max((sc.stop - sc.start) / sc.step * max(1, len(sc.instances)) for sc in c.bases)
    per_run = 0.05 + steps * 40e-6
    return max(1, min(n_runs // (8 * max(1, n_workers)), int(1.0 / per_run), 32))


def _run(c, plan, folder, conn, todo_ids, progress, on_result, workers, batch, ship, progress_every, dask_stack,
         wait_workers) -> Outcome:
    path = folder.path
    started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    outcome = Outcome(path, len(plan), 0, 0, 0, 0, 0)
    columns = run_columns(c, list(plan[0].requested))
    traj_columns = trajectory_columns(c)
    try:
        good, damaged = verified(path, plan, columns)
        for name, problem in damaged.items():
            log.warning("%s: %s: damaged run file (%s): %s", path, name, problem, "recomputing" if todo_ids is None
                        else "left out of the summary unless its run is recomputed")
        done = set(good)
        del good
        missing = [s for s in plan if (s.run_id, s.key) not in done and (todo_ids is None or s.run_id in todo_ids)]
        outcome.skipped = sum((s.run_id, s.key) in done for s in plan)
        # a bar on a terminal, else a plain line every progress_every s and at the end (logger ftcsim.campaign)
        bar = Progress(len(missing), c.name, unit="run", delay=0.0, leave=True, every=progress_every,
                       logger="ftcsim.campaign", enabled=progress, smoothing=0.1, final_line=True)
        failures = 0

        def finished(result):
            nonlocal failures
            if result.get("interrupted"):
                return
            store(path, result, columns, traj_columns)
            outcome.computed += 1
            failures += result["row"]["status"] != "ok"
            bar.update(1, **({"not ok": failures} if failures else {}))
            if on_result is not None:
                on_result(outcome)

        with handling_signals() as request:
            if conn is None:
                for spec in missing:
                    if request:
                        break
                    finished(execute(spec))
            elif missing:
                from orchestrator.campaign.shipping import CampaignInputs  # imports distributed (1 s)

                client = conn.client
                n_workers = max(1, len(client.nthreads()))
                size = batch or _batch_size(c, len(missing), n_workers)
                bases = {recipe_key(recipe(c, v)): sc for v, sc in zip(c.variants, c.bases)}
                ship = not conn.local if ship is None else ship
                plugin = CampaignInputs(bases, fmus=ship, kernels=ship, warm=ship)
                client.register_plugin(plugin, name=plugin.name)
                dask_stack.callback(_unregister, client, plugin.name)
                outcome.lost = run_dask(client, missing, finished, request, batch=size, wait_workers=wait_workers)
            outcome.interrupted = request.signum
        bar.close()
    finally:
        try:
            dask_stack.close()  # the cluster first: its workers stop computing
            finish(c, plan, path, columns, outcome, started, workers, conn)
        finally:
            folder.release()
    return outcome


def finish(c, plan, path: Path, columns, outcome: Outcome, started: str, workers, conn) -> None:
    """The end of a campaign session: ``summary.parquet`` from the sound stored runs, the counts of
    ``outcome`` (stored, damaged, failed) and the session appended to ``manifest.json``."""
    n, damaged = combine(path, plan, columns)
    outcome.stored = n
    outcome.damaged = sorted(damaged)
    info = read_manifest(path) or manifest(c, plan)
    df = read_table(path / SUMMARY, columns=["status"]) if n else None  # any folder name: the one reader
    outcome.failed = int((df["status"] != "ok").sum()) if n else 0
    info["status"] = "complete" if n == len(plan) else "incomplete"
    info["stored_runs"] = n
    info.setdefault("sessions", []).append({
        "started": started, "ended": time.strftime("%Y-%m-%dT%H:%M:%S%z"), "computed": outcome.computed,
        "skipped": outcome.skipped, "lost": outcome.lost, "interrupted": outcome.interrupted,
        "workers": workers, "scheduler": None if conn is None or conn.local else conn.where,
        "host": socket.gethostname()})
    write_json_atomic(path / MANIFEST, info)


def _unregister(client, name) -> None:
    with contextlib.suppress(Exception):
        client.unregister_worker_plugin(name)


def replay(campaign, run_id: int, out, overwrite=False, progress=True):
    """Run ``run_id`` of a campaign alone as an ordinary ``ftcsim run`` folder (results.parquet,
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
