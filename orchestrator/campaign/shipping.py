"""Campaign inputs that travel with the work to Dask workers (issue 25 items 2 and 3): a worker
plugin carrying the variants' base scenarios (loaded and checked here, so workers read no scenario,
design or SSP file), the FMU files (written into the worker's own folder when it lacks them at the
planned path, checked against the SHA-256 the campaign was planned with) and this machine's numba
kernel cache (unpacked where the worker has none, so a fresh worker loads compiled kernels instead of
compiling them); then each worker runs every base scenario for a few steps before its first task.

The plugin lives on the scheduler while the campaign runs (workers that join later get it too) and is
removed at the end; its teardown deletes what it wrote into the worker's folder."""
from __future__ import annotations

import asyncio
import dataclasses
import hashlib
import importlib.util
import io
import logging
import math
import os
import shutil
import tarfile
import tempfile
import time
import uuid
from pathlib import Path

from distributed.diagnostics.plugin import WorkerPlugin

from orchestrator.campaign.expand import file_digest
from orchestrator.campaign.worker import register_inputs, unregister_inputs
from orchestrator.cosim.runner import run_scenario
from orchestrator.scenario.overrides import with_overrides
from plant import jit

log = logging.getLogger("ftcsim.campaign")

WARM_STEPS = 3  # communication steps of each base scenario a worker runs before its first task


def current_cache_folders(root: str | None = None) -> list[Path]:
    """The folders of the kernel cache (default ``plant.jit.cache_root()``) that hold kernels of this
    installation's sources: ``<module>-<source hash>`` (``plant.jit.KernelCacheLocator``)."""
    root = Path(root or jit.cache_root())
    out = []
    try:
        names = sorted(p.name for p in root.iterdir() if p.is_dir())
    except OSError:
        return out
    for name in names:
        module, _, stamp = name.rpartition("-")
        try:
            spec = importlib.util.find_spec(module) if module else None
        except (ImportError, ValueError):
            spec = None
        if spec is not None and spec.origin and os.path.isfile(spec.origin) \
                and jit._source_hash(os.path.abspath(spec.origin))[:16] == stamp:
            out.append(root / name)
    return out


def kernel_cache_archive(limit_mb: float = 64.0) -> bytes | None:
    """This installation's compiled kernels as a tar archive (None: no kernels, or more than
    ``limit_mb``)."""
    if not jit.enabled():
        return None
    folders = current_cache_folders()
    if not folders or sum(f.stat().st_size for d in folders for f in d.iterdir()) > limit_mb * 2**20:
        return None
    buf = io.BytesIO()
    with tarfile.open(fileobj=buf, mode="w:gz", compresslevel=1) as tar:
        for d in folders:
            tar.add(d, arcname=d.name)
    return buf.getvalue()


def unpack_kernel_cache(data: bytes, root: str | None = None) -> int:
    """Add the folders of a :func:`kernel_cache_archive` that the cache at ``root`` (default
    ``plant.jit.cache_root()``) lacks; a folder it has is left as it is. Returns the folders added."""
    root = Path(root or jit.cache_root())
    root.mkdir(parents=True, exist_ok=True)
    added = 0
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar, \
            tempfile.TemporaryDirectory(dir=root, prefix=".unpack-") as tmp:
        tar.extractall(tmp, filter="data")  # no absolute paths, no .., no links out
        for d in Path(tmp).iterdir():
            if d.is_dir() and not (root / d.name).exists():
                try:
                    os.rename(d, root / d.name)  # whole folders: never a half-written one
                    added += 1
                except OSError:  # another worker on this machine was first
                    pass
    return added


def warm_span(sc) -> float:
    """The time (s) a worker runs a base scenario to warm it: :data:`WARM_STEPS` communication steps,
    rounded up to a whole step of its slowest instance (a multirate run must end on every instance's grid)."""
    slowest = max([i.step for i in sc.instances.values() if getattr(i, "step", None)] + [sc.step])
    return math.ceil(WARM_STEPS * sc.step / slowest) * slowest


def _fmus_of(bases: dict) -> dict:
    """{planned FMU path: SHA-256} of the base scenarios."""
    return {str(i.fmu): file_digest(i.fmu) for sc in bases.values() for i in sc.instances.values() if i.fmu}


class CampaignInputs(WorkerPlugin):
    """The inputs of one campaign for its workers (see the module docstring). ``bases``: {recipe key:
    scenario}; ``fmus``: ship the FMU files; ``kernels``: ship the kernel cache; ``warm``: run each base
    scenario for :data:`WARM_STEPS` steps at set-up."""

    def __init__(self, bases: dict, *, fmus: bool = True, kernels: bool = True, warm: bool = True):
        self.bases = bases
        planned = _fmus_of(bases)
        self.fmus = {}
        for path, digest in planned.items():
            data = Path(path).read_bytes()
            if hashlib.sha256(data).hexdigest() != digest:
                raise OSError(f"{path} changed while the campaign was being planned")
            self.fmus[path] = (digest, data if fmus else None)
        self.kernels = kernel_cache_archive() if kernels else None
        self.warm = warm
        h = hashlib.sha256(repr(sorted(bases)).encode())
        for path, (digest, _) in sorted(self.fmus.items()):
            h.update(f"{path}={digest}".encode())
        # one name per campaign session: two campaigns on one cluster never remove each other's inputs
        self.name = f"ftcsim-inputs-{h.hexdigest()[:12]}-{uuid.uuid4().hex[:8]}"
        self.folder = None  # on the worker: what setup wrote

    async def setup(self, worker):
        # in a thread: a cold kernel compilation must not block the worker's event loop (heartbeats)
        await asyncio.get_running_loop().run_in_executor(None, self._setup, worker.local_directory)

    def _setup(self, local_directory) -> None:
        started = time.perf_counter()
        self.folder = Path(local_directory) / self.name
        local = {}
        for planned, (digest, data) in self.fmus.items():
            if os.path.isfile(planned) and file_digest(planned) == digest:
                continue  # a shared disk or the same machine: the planned file itself
            if data is None:
                continue  # not shipped: the run says which FMU is missing
            if hashlib.sha256(data).hexdigest() != digest:
                raise OSError(f"the copy of {planned} shipped to this worker is damaged (SHA-256 differs)")
            target = self.folder / digest[:16] / Path(planned).name
            if not target.is_file() or file_digest(target) != digest:
                target.parent.mkdir(parents=True, exist_ok=True)
                tmp = target.with_name(f".tmp-{os.getpid()}-{target.name}")
                tmp.write_bytes(data)
                os.replace(tmp, target)
            local[planned] = str(target)
        bases = {}
        for key, sc in self.bases.items():
            instances = {n: dataclasses.replace(i, fmu=Path(local[str(i.fmu)])) if i.fmu and str(i.fmu) in local else i
                         for n, i in sc.instances.items()}
            bases[key] = dataclasses.replace(sc, instances=instances)
        register_inputs(self.name, bases, local)
        added = unpack_kernel_cache(self.kernels) if self.kernels and jit.enabled() else 0
        if self.warm:
            for sc in bases.values():
                try:
                    run_scenario(with_overrides(sc, stop=min(sc.stop, sc.start + warm_span(sc))))
                except Exception as e:  # noqa: BLE001 - the runs themselves will say what is wrong
                    log.warning("warming %s on this worker failed: %s", sc.name, " ".join(str(e).split())[:200])
        log.info("campaign inputs on this worker: %d FMUs copied, %d kernel cache folders added, warm in %.1f s",
                 len(local), added, time.perf_counter() - started)

    def teardown(self, worker):
        unregister_inputs(self.name, str(self.folder) if self.folder is not None else None)
        if self.folder is not None:
            shutil.rmtree(self.folder, ignore_errors=True)
