"""Campaign runs on dask.distributed: a LocalCluster of single-threaded worker processes, or any
cluster a lab already has (a scheduler address, a scheduler file, a ``distributed.Client``, a
``LocalCluster`` / dask-jobqueue / dask-kubernetes cluster object: anything with a
``scheduler_address``). The runs are submitted in batches, their results stored as they arrive,
a run that kills its worker recorded as failed after a bounded number of tries.

No global Dask configuration is changed: :func:`dask_settings` is a context (``dask.config.set``)
that a campaign holds while it talks to Dask."""
from __future__ import annotations

import contextlib
import logging
import os
import shutil
import signal
import socket
import struct
import sys
import tempfile
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from orchestrator.campaign.worker import execute_batch, failed_result
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.common.reading import read_json

log = logging.getLogger("ftcsim.campaign")

ALLOWED_FAILURES = 3  # a task whose worker died this many times more is given up (KilledWorker)
# tasks the scheduler of our LocalCluster hands each worker thread ahead (Dask's default 1.1 sends the next
# task only when one ends: the worker waits a round trip to a scheduler that shares its process with the
# client storing results); an existing cluster keeps its own setting
LOCAL_WORKER_SATURATION = 2.0
SCHEMES = ("tcp", "tls", "ws", "wss")
MAX_WORKERS = 4096  # local worker processes (with --force-workers); more is a typo, not a machine


def cores() -> int:
    """The cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return os.cpu_count() or 1


@contextlib.contextmanager
def dask_settings(connect_timeout: float = 5.0, allowed_failures: int = ALLOWED_FAILURES):
    """The Dask configuration a campaign runs under, as a context: the caller's configuration is
    the same afterwards. (A LocalCluster started inside passes it to its worker processes; an
    existing scheduler keeps its own ``allowed-failures``.)"""
    import dask  # distributed: 1 s to import, only when a campaign runs on Dask
    import distributed  # noqa: F401 - its configuration defaults first: set() inserting the missing
    # "distributed" tree would delete it whole on exit, defaults loaded meanwhile included

    # lost-worker-timeout: a LocalCluster closes the nanny of a worker that has not re-registered
    # 15 s (the default) after a death; a run that kills its worker again and again (the nanny
    # restarting it each time) could so leave the cluster without workers. Our nannies restart
    # their workers; a cluster left without any is bounded by run_dask's wait_workers
    with dask.config.set({"distributed.scheduler.allowed-failures": allowed_failures,
                          "distributed.comm.timeouts.connect": f"{connect_timeout}s",
                          "distributed.deploy.lost-worker-timeout": "1h"}):
        yield


@dataclass
class Connection:
    """A Dask client for one campaign and what was started for it (closed and removed by :meth:`close`)."""

    client: object
    where: str  # what it is connected to, for messages and the manifest
    local: bool = False  # our own LocalCluster: the workers see this machine's files
    own_client: bool = False
    cluster: object = None  # our LocalCluster
    scratch: Path | None = None  # its local_directory (dask-scratch-space inside), removed afterwards

    def close(self) -> None:
        if self.own_client:
            with contextlib.suppress(Exception):
                self.client.close()
        if self.cluster is not None:
            with contextlib.suppress(Exception):
                self.cluster.close()
        if self.scratch is not None:
            shutil.rmtree(self.scratch, ignore_errors=True)


def check_address(address, key="--scheduler") -> str:
    """A scheduler address as ``scheme://host:port`` (``host:port`` means tcp); one clear
    ``InputError`` for anything else."""
    if not isinstance(address, str) or not address.strip() or any(ch.isspace() for ch in address) \
            or not address.isprintable():
        raise InputError("command line", key, f"expected a scheduler address like tcp://host:8786, got {address!r}")
    scheme, sep, rest = address.partition("://")
    if not sep:
        scheme, rest = "tcp", address
    if scheme not in SCHEMES:
        raise InputError("command line", key, f"{address!r}: unknown protocol {scheme!r} (expected one of "
                                              f"{', '.join(s + '://' for s in SCHEMES)})")
    host, colon, port = rest.rpartition(":")
    if rest.startswith("[") and "]" in rest:  # [IPv6]:port
        host, _, tail = rest[1:].partition("]")
        colon, port = (":", tail[1:]) if tail.startswith(":") else ("", "")
    if not colon or not host or "/" in host or "/" in port:
        raise InputError("command line", key, f"{address!r}: expected {scheme}://host:port")
    if not port.isdigit() or not 1 <= int(port) <= 65535:
        raise InputError("command line", key, f"{address!r}: port must be a number 1..65535, got {port!r}")
    return f"{scheme}://{rest}"


def read_scheduler_file(path, key="--scheduler-file") -> str:
    """The scheduler address in a Dask scheduler file (``dask scheduler --scheduler-file``)."""
    p = Path(path)
    if not os.path.lexists(p):
        raise InputError(p, key, "scheduler file not found (is the scheduler started, on a disk this machine "
                                 "shares?)")
    try:  # the one reader: a FIFO, a device, a huge or deeply nested file is refused, never waited on
        data = read_json(p, "regular file", key=key, strict=False)
    except InputError as e:
        raise InputError(p, key, f"not a Dask scheduler file ({e.problem})") from None
    address = data.get("address")
    if not isinstance(address, str):
        raise InputError(p, key, "not a Dask scheduler file (no \"address\")")
    return check_address(address, key)


MAX_GREETING = 1 << 20  # bytes: a Dask scheduler's greeting is a few hundred


def _recv_exactly(sock, n: int, deadline: float) -> bytes:
    """``n`` bytes from ``sock`` before ``deadline`` (time.monotonic()); fewer if the peer closed.
    Raises TimeoutError when the deadline passes first (a silent or dripping peer)."""
    data = b""
    while len(data) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise TimeoutError
        sock.settimeout(left)
        chunk = sock.recv(min(n - len(data), 65536))
        if not chunk:
            break
        data += chunk
    return data


def probe(address: str, timeout: float, key="--scheduler") -> None:
    """Refuse within ``timeout`` s (one deadline for everything) an address where nothing listens, or
    where a peer accepts the connection and does not send, whole, the greeting a Dask scheduler sends
    at once: silence, one byte then silence, a drip, a length no greeting has, garbage, a TLS server
    (Dask's own connect waits for it without a bound, or allocates what a garbage length says)."""
    scheme, _, rest = address.partition("://")
    host, _, port = rest.rpartition(":")
    host = host.strip("[]")
    deadline = time.monotonic() + timeout
    try:
        sock = socket.create_connection((host, int(port)), timeout=timeout)
    except OSError as e:
        detail = " ".join(str(e).split())[:200] or type(e).__name__
        raise InputError("command line", key, f"no Dask scheduler reachable at {address!r} within {timeout:g} s "
                                              f"({detail})") from None
    with sock:
        if scheme != "tcp":  # tls / ws: the greeting comes after their own handshake (bounded by connect_client)
            return
        try:
            head = _recv_exactly(sock, 8, deadline)  # Dask's frame: a uint64 length, then the message
            if not head:
                raise InputError("command line", key, f"{address!r} closed the connection at once (not a Dask "
                                                      "scheduler?)")
            if len(head) < 8:
                raise InputError("command line", key, f"{address!r} closed the connection in its greeting (not a Dask "
                                                      "scheduler?)")
            (n,) = struct.unpack("<Q", head)
            if not 0 < n <= MAX_GREETING:
                raise InputError("command line", key, f"{address!r} answered with something that is not a Dask "
                                                      f"greeting (a message of {n} bytes announced)")
            body = _recv_exactly(sock, n, deadline)
        except TimeoutError:
            raise InputError("command line", key, f"{address!r} accepted the connection but did not answer within "
                                                  f"{timeout:g} s with a Dask scheduler's greeting (not a Dask "
                                                  "scheduler?)") from None
        except OSError as e:
            raise InputError("command line", key, f"{address!r} broke the connection ({e})") from None
        if len(body) < n or b"pickle-protocol" not in body:
            raise InputError("command line", key, f"{address!r} answered with something that is not a Dask "
                                                  "scheduler's greeting")


def connect_client(address: str, timeout: float, key="--scheduler"):
    """A ``distributed.Client`` of the scheduler at ``address`` made within ``timeout`` s plus a grace
    second, whatever the peer does after its greeting (a peer that greets and then stays silent, a TLS
    handshake that never ends): the client is made in a thread with that deadline; past it the
    attempt is abandoned (that thread left to end with the process) and the address refused."""
    from distributed import Client

    result: dict = {}

    def make():
        try:
            result["client"] = Client(address, timeout=timeout, set_as_default=False)
        except BaseException as e:  # noqa: BLE001 - handed to the caller's thread
            result["error"] = e

    t = threading.Thread(target=make, name="ftcsim-dask-connect", daemon=True)
    t.start()
    t.join(timeout + 1.0)
    if t.is_alive():
        raise InputError("command line", key, f"{address!r} did not complete a Dask connection within {timeout:g} s "
                                              "(not a Dask scheduler, or not answering)")
    e = result.get("error")
    if e is not None:
        if isinstance(e, (OSError, TimeoutError, ValueError, TypeError, MemoryError, EOFError)) or \
                type(e).__name__ in ("CommClosedError", "CancelledError"):
            detail = " ".join(str(e).split())[:200] or type(e).__name__
            raise InputError("command line", key, f"no Dask scheduler reachable at {address!r} within {timeout:g} s "
                                                  f"({detail})") from None
        raise e
    return result["client"]


def connect(workers: int | None = None, scheduler: str | None = None, timeout: float = 5.0, **kw):
    """A ``distributed.Client`` as :func:`open_connection` makes it (tests, benchmarks); give it to
    :func:`close` to close it with what was started for it."""
    conn = open_connection(workers, scheduler, timeout, **kw)
    conn.client._ftcsim_connection = conn
    return conn.client


def open_connection(workers: int | None = None, scheduler: str | None = None, timeout: float = 5.0, *,
            scheduler_file=None, client=None, cluster=None, force_workers: bool = False,
            wait_workers: float = 120.0, dashboard: bool = True) -> Connection:
    """A :class:`Connection` for a campaign (call inside :func:`dask_settings`): the given ``client``
    (kept open), a client of ``cluster`` (any object with ``scheduler_address``), of the scheduler
    at ``scheduler`` or named in ``scheduler_file`` (each refused within ``timeout`` s if
    unreachable), else a new LocalCluster of ``workers`` processes with one thread each (at most
    the cores unless ``force_workers``). An external cluster without workers is waited for
    ``wait_workers`` s, then refused."""
    given = [k for k, v in (("client", client), ("cluster", cluster), ("scheduler", scheduler),
                            ("scheduler_file", scheduler_file)) if v is not None]
    if len(given) > 1:
        raise InputError("api", given[1], f"give one of client, cluster, scheduler, scheduler_file (got {', '.join(given)})")
    if given and workers is not None:
        raise InputError("command line", "--workers", f"give --workers or --{given[0].replace('_', '-')}, not both")
    from distributed import Client  # 1 s to import: only when a campaign runs on Dask

    if client is not None:
        if not isinstance(client, Client):
            raise InputError("api", "client", f"expected a distributed.Client, got {type(client).__name__}")
        conn = Connection(client, f"client of {client.scheduler.address if client.scheduler else '?'}",
                          local=_in_process_local(getattr(client, "cluster", None)))
    else:
        if cluster is not None:
            address = getattr(cluster, "scheduler_address", None)
            if not isinstance(address, str):
                raise InputError("api", "cluster", f"{type(cluster).__name__} has no scheduler_address (expected a "
                                                   "LocalCluster, a dask-jobqueue or dask-kubernetes cluster)")
            key, address = "cluster", check_address(address, "cluster")
        elif scheduler_file is not None:
            key, address = "--scheduler-file", read_scheduler_file(scheduler_file)
        elif scheduler is not None:
            key, address = "--scheduler", check_address(scheduler)
        else:
            return local_cluster(workers, force_workers, dashboard)
        probe(address, timeout, key)
        c = connect_client(address, timeout, key)
        conn = Connection(c, address, local=_in_process_local(cluster), own_client=True)
    try:
        wait_for_workers(conn, wait_workers)
    except BaseException:
        conn.close()
        raise
    return conn


def wait_for_workers(conn: Connection, wait: float) -> None:
    """Return when the cluster has a worker; warn and wait up to ``wait`` s if it has none."""
    if conn.client.nthreads():
        return
    log.warning("the Dask scheduler at %s has no workers; waiting up to %g s for one", conn.where, wait)
    try:
        conn.client.wait_for_workers(1, timeout=wait)
    except (TimeoutError, OSError):
        raise InputError("command line", "--scheduler", f"no worker joined the scheduler at {conn.where} within "
                                                        f"{wait:g} s (start workers: `dask worker ADDRESS --nthreads 1`; "
                                                        "or wait longer: --wait-workers)") from None


def local_cluster(workers: int | None, force: bool = False, dashboard: bool = True) -> Connection:
    """A LocalCluster of ``workers`` processes (default: the cores), one thread each, its scratch
    space in a temporary folder of ours."""
    import dask
    from distributed import Client, LocalCluster

    n = workers or cores()
    if n > cores() and not force:
        raise InputError("command line", "--workers", f"{n} worker processes on {cores()} cores would share them "
                                                      f"(slower, not faster): give at most {cores()}, or --force-workers")
    dashboard_address = "127.0.0.1:0" if dashboard and _has_bokeh() else None
    scratch = Path(tempfile.mkdtemp(prefix="ftcsim-dask-"))
    # A Ctrl-C while the cluster starts (2-3 s) is this process's to honour: it is recorded here and the
    # cluster closed once started (exit 130, nothing written). The workers ignore SIGINT (a Ctrl-C reaches
    # the whole process group; this process decides): their preload says so, the nannies do it themselves
    interrupted = []
    previous = signal.signal(signal.SIGINT, lambda signum, frame: interrupted.append(signum)) if _main_thread() \
        else None
    saved_path = sys.path[:]
    # the workers start with this process's sys.path; an FMU run here has put its extracted
    # resources/ on it, whose partial copies of our packages (papers/ without paper.py, ...) would
    # hide the project's in a fresh process. A worker the nanny restarts (its task killed it) starts
    # with the sys.path of that later moment: the preload drops them there too
    sys.path[:] = [p for p in sys.path if not _is_fmu_resources(p)]
    cluster = None
    try:
        # temporary-directory: the scheduler's and nannies' own dask-scratch-space go into our scratch folder
        # too (removed on close), not into TMPDIR where every LocalCluster would leave one
        with dask.config.set({"distributed.scheduler.worker-saturation": LOCAL_WORKER_SATURATION,
                              "temporary-directory": str(scratch)}):
            cluster = LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                   dashboard_address=dashboard_address, silence_logs=logging.ERROR,
                                   local_directory=str(scratch), host="127.0.0.1", preload=[DROP_FMU_RESOURCES])
        conn = Connection(Client(cluster, set_as_default=False), f"a local cluster of {n} workers", local=True,
                          own_client=True, cluster=cluster, scratch=scratch)
    except BaseException:
        if cluster is not None:
            with contextlib.suppress(Exception):
                cluster.close()
        shutil.rmtree(scratch, ignore_errors=True)
        raise
    finally:
        sys.path[:] = saved_path
        if previous is not None:
            signal.signal(signal.SIGINT, previous)
    if interrupted:  # Ctrl-C during the start: nothing was computed, nothing is written
        conn.close()
        raise KeyboardInterrupt
    return conn


def _in_process_local(cluster) -> bool:
    """True for a LocalCluster started by this process: its workers share this machine's files."""
    from distributed import LocalCluster

    return isinstance(cluster, LocalCluster)


def _has_bokeh() -> bool:
    try:
        import bokeh  # noqa: F401 - the dashboard's only extra dependency
    except ImportError:
        return False
    return True


# Dask worker preload (source text: run in each worker process as it starts, restarts included, before
# any task): the same test as _is_fmu_resources
DROP_FMU_RESOURCES = """
import os, signal, sys
sys.path[:] = [p for p in sys.path if not (p and os.path.isfile(os.path.join(p, "slavemodule.txt")))]
signal.signal(signal.SIGINT, signal.SIG_IGN)  # a Ctrl-C reaches the whole process group: the campaign decides
"""


def _is_fmu_resources(folder: str) -> bool:
    """True for an extracted FMU's resources folder (pythonfmu's slavemodule.txt is there)."""
    return bool(folder) and os.path.isfile(os.path.join(folder, "slavemodule.txt"))


def _main_thread() -> bool:
    return threading.current_thread() is threading.main_thread()


def close(client) -> None:
    """Close a client and the LocalCluster it runs on (tests and benchmarks that called :func:`connect`)."""
    conn = client if isinstance(client, Connection) else getattr(client, "_ftcsim_connection", None)
    if conn is not None:
        conn.own_client = True
        conn.close()
        return
    cluster = getattr(client, "cluster", None)
    with contextlib.suppress(Exception):
        client.close()
    if cluster is not None:
        with contextlib.suppress(Exception):
            cluster.close()


def batches(specs, size: int) -> list:
    """``specs`` in consecutive groups of at most ``size`` (run-id order kept)."""
    size = max(1, int(size))
    return [specs[i:i + size] for i in range(0, len(specs), size)]


def run_dask(client, specs, finished, request, *, batch: int = 1, task=execute_batch, wait_workers: float = 120.0,
             groups=None) -> int:
    """Submit ``specs`` in tasks of ``batch`` runs (or the tasks ``groups``, lists of specs, in the
    order given: Dask starts earlier submissions first), store each result as it arrives
    (``finished``), stop when ``request`` is set. A task whose workers died ``ALLOWED_FAILURES`` + 1 times
    (KilledWorker) is split into single runs and retried; a single run that still kills its worker
    is stored as failed. Returns the number of runs lost (their task failed outside the runs
    themselves, e.g. the scheduler went away; a rerun retries them)."""
    from distributed import KilledWorker

    def submit(group):
        ids = "-".join(str(s.run_id) for s in (group[0], group[-1]))
        return client.submit(task, group, key=f"ftcsim-runs-{ids}-{group[0].key}-{len(group)}", pure=False,
                             retries=0)

    # no other reference to the futures: a stored result is released from the worker's memory
    pending = {submit(g): g for g in (batches(specs, batch) if groups is None else groups)}
    lost = 0
    idle_since = None
    last_check = time.monotonic()
    try:
        while pending and not request:
            done = [f for f in pending if f.done()]
            if not done:
                time.sleep(0.05)
                if time.monotonic() - last_check > 5.0:  # a cluster that lost every worker: bounded wait
                    last_check = time.monotonic()
                    idle_since = None if client.nthreads() else (idle_since or last_check)
                    if idle_since is not None and last_check - idle_since > wait_workers:
                        raise SimulationError(f"the Dask cluster has had no worker for {wait_workers:g} s")
                continue
            for f in done:
                group = pending.pop(f)
                if f.status in ("lost", "pending"):
                    # done a moment ago, then its worker died before we read it: the scheduler
                    # recomputes it elsewhere, so it is still pending (not lost to the campaign)
                    pending[f] = group
                    continue
                try:  # waits if the data is lost meanwhile and recomputed
                    results = f.result()
                except KilledWorker as e:
                    if len(group) > 1:  # one of them kills its worker: find which, alone
                        pending.update((submit([s]), [s]) for s in group)
                        continue
                    tries = _tries(client)
                    log.warning("run %d killed every worker that ran it (%s tries): stored as failed",
                                group[0].run_id, tries)
                    results = [failed_result(group[0], f"the run killed its worker {tries} times "
                                                       f"(KilledWorker: {' '.join(str(e).split())[:160]})")]
                except Exception as e:  # noqa: BLE001 - cancelled, or the scheduler went away
                    lost += len(group)
                    _report_lost(f.key, type(e).__name__, e)
                    continue
                for result in results:
                    finished(result)
    finally:
        if pending:
            client.cancel(list(pending), force=True)
    return lost


def _tries(client) -> str:
    """How often the scheduler lets a task's workers die before it gives the task up."""
    try:
        n = client.run_on_scheduler(lambda dask_scheduler: dask_scheduler.allowed_failures)
        return str(int(n) + 1)
    except Exception:  # noqa: BLE001 - an old or restricted scheduler: say what is known
        return "several"


def _report_lost(key, status, exception) -> None:
    log.warning("runs %s could not be computed (%s: %s); a rerun retries them", key, status,
                " ".join(str(exception).split())[:200])
