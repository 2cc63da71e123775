"""Campaign runs on dask.distributed: a LocalCluster of single-threaded worker processes or an existing
scheduler, the runs submitted and their results stored as they arrive, lost runs reported."""
from __future__ import annotations

import logging
import os
import signal
import sys
import threading
import time

from orchestrator.campaign.worker import execute
from orchestrator.common.errors import InputError


def connect(workers: int | None, scheduler: str | None, timeout: float = 5.0):
    """A dask.distributed Client: to ``scheduler`` (refused within ``timeout`` s if unreachable) or
    to a new LocalCluster of ``workers`` processes with one thread each."""
    import dask  # distributed: 1 s to import, only when a campaign runs on Dask
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
    return threading.current_thread() is threading.main_thread()


def close(client) -> None:
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


def run_dask(client, specs, finished, request) -> int:
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
