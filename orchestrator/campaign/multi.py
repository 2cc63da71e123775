"""Several campaigns as one plan (the arena's cells): every campaign keeps its own folder, resume and
summary exactly as :func:`orchestrator.campaign.run.run_campaign` writes them, but their missing
runs go to one cluster in one pass instead of one campaign after another, so the last runs of one
campaign never leave workers idle while the next one waits.

Order: the runs are submitted longest first (estimated from each campaign's steps times
instances, :func:`run_cost`), so that the longest tasks do not come last and leave one worker
computing alone (longest-processing-time first). Each task is one run unless the runs are short
(:func:`orchestrator.campaign.run._batch_size`, per campaign). A signal (SIGINT / SIGTERM) stops
every campaign at once; each folder then holds what was finished, and the same call resumes.
"""
from __future__ import annotations

import contextlib
import dataclasses
import logging
import time
from pathlib import Path

from orchestrator.campaign.cluster import batches, dask_settings, open_connection, run_dask
from orchestrator.campaign.expand import expand
from orchestrator.campaign.run import Outcome, _batch_size, _unregister, finish, open_folder
from orchestrator.campaign.schema import run_columns, trajectory_columns
from orchestrator.campaign.spec import Campaign, recipe
from orchestrator.campaign.spec import load as load_campaign
from orchestrator.campaign.store import store, verified
from orchestrator.campaign.worker import execute, recipe_key
from orchestrator.common.errors import InputError
from orchestrator.common.interrupt import handling_signals
from orchestrator.common.progress import Progress

log = logging.getLogger("ftcsim.campaign")


def run_cost(c: Campaign) -> float:
    """Relative cost of one run of ``c``: communication steps x instances of its longest base scenario."""
    return max((sc.stop - sc.start) / sc.step * max(1, len(sc.instances)) for sc in c.bases)


def run_campaigns(items, *, workers: int | None = None, scheduler: str | None = None, overwrite=False,
                  progress=False, client=None, connect_timeout: float = 5.0, cluster=None, scheduler_file=None,
                  force_workers: bool = False, wait_workers: float = 120.0, ship: bool | None = None,
                  dashboard: bool = True, progress_every: float = 30.0, time_limit: float | None = None,
                  name: str = "campaigns", on_result=None) -> list[Outcome]:
    """Run (or resume) the campaigns ``items`` ([(campaign file or loaded Campaign, out folder, only
    run ids or None)]) as one plan; returns their :class:`Outcome` in the order given. The engine
    keywords are those of :func:`orchestrator.campaign.run.run_campaign`; ``workers=0`` runs every
    run in this process. Every campaign is loaded and expanded, and every folder checked, before
    any run starts; ``on_result(index, outcome)`` after each stored run."""
    loaded = []
    for item in items:
        campaign, out, only = item if len(item) == 3 else (*item, None)
        c = campaign if isinstance(campaign, Campaign) else load_campaign(campaign)
        if time_limit is not None:
            c = dataclasses.replace(c, time_limit=float(time_limit) or None)
        plan = expand(c)
        if only is not None:
            expand(c, only=set(only))  # refuses ids outside the plan
        loaded.append((c, plan, Path(out), None if only is None else set(only)))
    if len({p.resolve() for _, _, p, _ in loaded}) != len(loaded):
        raise InputError("api", "items", "two campaigns write the same folder")
    serial = workers == 0 and client is None and scheduler is None and cluster is None and scheduler_file is None
    folders = []
    with contextlib.ExitStack() as stack:
        conn = None
        if not serial:
            stack.enter_context(dask_settings(connect_timeout))
            conn = open_connection(workers, scheduler, connect_timeout, scheduler_file=scheduler_file, client=client,
                                   cluster=cluster, force_workers=force_workers, wait_workers=wait_workers,
                                   dashboard=dashboard)
            stack.callback(conn.close)
        try:
            for c, plan, out, _ in loaded:
                folders.append(open_folder(c, plan, out, overwrite))
        except BaseException:
            for f in folders:
                f.release()
            raise
        return _run_all(loaded, folders, conn, stack, progress, progress_every, workers, ship, wait_workers, name,
                        on_result)


def _run_all(loaded, folders, conn, stack, progress, progress_every, workers, ship, wait_workers, name,
             on_result) -> list[Outcome]:
    started = time.strftime("%Y-%m-%dT%H:%M:%S%z")
    outcomes, columns, traj_columns, owner, groups = [], [], [], {}, []
    try:
        for j, ((c, plan, _, only), folder) in enumerate(zip(loaded, folders)):
            outcomes.append(Outcome(folder.path, len(plan), 0, 0, 0, 0, 0))
            columns.append(run_columns(c, list(plan[0].requested)))
            traj_columns.append(trajectory_columns(c))
            good, damaged = verified(folder.path, plan, columns[j])
            for file, problem in damaged.items():
                log.warning("%s: %s: damaged run file (%s): recomputing", folder.path, file, problem)
            missing = [s for s in plan if (s.run_id, s.key) not in good and (only is None or s.run_id in only)]
            outcomes[j].skipped = sum((s.run_id, s.key) in good for s in plan)
            del good
            unique = []
            for s in missing:  # a run planned identically by two campaigns (same key) is computed once
                if s.key not in owner:
                    unique.append(s)
                owner.setdefault(s.key, []).append(j)
            groups.append((run_cost(c), unique))
        n_missing = sum(len(m) for _, m in groups)
        bar = Progress(n_missing, name, unit="run", delay=0.0, leave=True, every=progress_every, logger="ftcsim.campaign",
                       enabled=progress, smoothing=0.1, final_line=True)
        failures = 0

        def finished(result):
            nonlocal failures
            if result.get("interrupted"):
                return
            for j in owner[result["row"]["key"]]:
                store(folders[j].path, result, columns[j], traj_columns[j])
                outcomes[j].computed += 1
                if on_result is not None:
                    on_result(j, outcomes[j])
            failures += result["row"]["status"] != "ok"
            bar.update(1, **({"not ok": failures} if failures else {}))

        order = sorted(range(len(groups)), key=lambda j: -groups[j][0])  # longest runs first
        with handling_signals() as request:
            if conn is None:
                for j in order:
                    for spec in groups[j][1]:
                        if request:
                            break
                        finished(execute(spec))
            elif n_missing:
                from orchestrator.campaign.shipping import CampaignInputs  # imports distributed (1 s)

                client = conn.client
                n_workers = max(1, len(client.nthreads()))
                tasks = []
                for j in order:
                    c, missing = loaded[j][0], groups[j][1]
                    if missing:
                        tasks += batches(missing, _batch_size(c, n_missing, n_workers))
                bases = {}
                for c, _, _, _ in loaded:
                    bases.update({recipe_key(recipe(c, v)): sc for v, sc in zip(c.variants, c.bases)})
                ship = not conn.local if ship is None else ship
                plugin = CampaignInputs(bases, fmus=ship, kernels=ship, warm=ship)
                client.register_plugin(plugin, name=plugin.name)
                stack.callback(_unregister, client, plugin.name)
                run_dask(client, [], finished, request, groups=tasks, wait_workers=wait_workers)
            planned = {}
            for keys in owner.values():
                for j in keys:
                    planned[j] = planned.get(j, 0) + 1
            for j, o in enumerate(outcomes):
                o.interrupted = request.signum
                # a run neither stored nor interrupted: its task failed outside the run (a rerun retries it)
                o.lost = 0 if request.signum else planned.get(j, 0) - o.computed
        bar.close()
    finally:
        try:
            stack.close()  # the cluster first: its workers stop computing
        finally:
            first = None
            for j, ((c, plan, _, _), folder) in enumerate(zip(loaded, folders)):
                try:
                    if j < len(columns):
                        finish(c, plan, folder.path, columns[j], outcomes[j], started, workers, conn)
                except Exception as e:  # noqa: BLE001 - every folder is finished and released; the first error is raised
                    first = first or e
                finally:
                    folder.release()
            if first is not None:
                raise first
    return outcomes
