"""One campaign run on a worker: the variant's base scenario (loaded once per worker process), the run's
overrides, the run, the values read back from the FMUs, the metrics and the stored trajectory."""
from __future__ import annotations

import json
import math
import os
import socket
import time

import numpy as np

from orchestrator.campaign.expand import file_digest
from orchestrator.campaign.schema import DROPPED_METRICS
from orchestrator.campaign.spec import load_base
from orchestrator.common.errors import InputError, SimulationError
from orchestrator.cosim.runner import run_scenario
from orchestrator.results.metrics import compute_metrics, settling_time
from orchestrator.scenario.overrides import with_overrides

KEPT_WHEN_FAILED = ("t_end", "steps", "step")

_BASES: dict = {}  # recipe key -> base scenario loaded on this worker
_SHIPPED: dict = {}  # plugin name -> {recipe key: base scenario} shipped to it (orchestrator/campaign/shipping.py)
_LOCAL_FMUS: dict = {}  # FMU path as planned -> the copy shipped to this worker


def recipe_key(recipe: dict) -> str:
    return json.dumps(recipe, sort_keys=True)


def register_inputs(name: str, bases: dict, fmus: dict) -> None:
    """Inputs shipped to this worker under plugin ``name``: base scenarios by :func:`recipe_key`
    (their FMUs already pointing at local copies) and {planned FMU path: local copy}."""
    _SHIPPED[name] = bases
    _LOCAL_FMUS.update(fmus)


def unregister_inputs(name: str, folder: str | None = None) -> None:
    """Forget what :func:`register_inputs` was given under ``name`` (its campaign ended): the base
    scenarios, and the FMU copies that lie in ``folder`` (another campaign's stay)."""
    _SHIPPED.pop(name, None)
    for planned, local in list(_LOCAL_FMUS.items()):
        if folder is not None and local.startswith(folder + os.sep):
            del _LOCAL_FMUS[planned]


def _base(spec):
    k = recipe_key(spec.recipe)
    for shipped in reversed(list(_SHIPPED.values())):  # the latest first
        if k in shipped:
            return shipped[k]
    if k not in _BASES:
        _BASES[k] = load_base(spec.recipe)[0]
    return _BASES[k]


def execute_batch(specs) -> list:
    """Several runs in one task (on a worker): their results in order."""
    return [execute(s) for s in specs]


def failed_result(spec, error: str) -> dict:
    """The stored result of a run that produced none (it killed every worker that tried it)."""
    row = {"run_id": spec.run_id, "key": spec.key, "variant": spec.variant_name, "point": spec.point,
           "draw": spec.draw, "seed": spec.seed, "status": "failed", "error": error}
    for ref, x in spec.requested.items():
        row[ref] = None
        row[f"requested:{ref}"] = x
    row.update({"wall_time_s": None, "cpu_time_s": None, "sim_time_s": None, "worker": None})
    return {"row": row, "trajectory": None}


def execute(spec) -> dict:
    """One run (on a worker): {"row": summary row, "trajectory": {column: array} or None}; a run
    that a signal to this process stopped (``--workers 0``) gives ``{"interrupted": signum}``."""
    started, cpu = time.perf_counter(), time.process_time()
    row = {"run_id": spec.run_id, "key": spec.key, "variant": spec.variant_name, "point": spec.point,
           "draw": spec.draw, "seed": spec.seed}
    readback = dict.fromkeys(spec.requested, None)
    trajectory = None
    try:
        for planned, digest in spec.fmu_digests.items():
            path = _LOCAL_FMUS.get(planned, planned)
            if not os.path.isfile(path):
                raise SimulationError(f"FMU {planned} is not on this worker ({socket.gethostname()}) and was not "
                                      "shipped to it")
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

        raw = run_scenario(sc, after_setup=read_back, time_limit=spec.time_limit)
        if raw.interrupted:  # stopped by a signal to this process: not a result, never stored
            return {"row": None, "trajectory": None, "interrupted": raw.interrupted}
        row["sim_time_s"] = raw.wall_time
        metrics = compute_metrics(raw, sc)
        if spec.settling and len(raw.time):
            metrics["settling_time"] = settling_time(raw, spec.settling)
        # a run that did not reach its stop time has no metrics (those of the part that ran would rank it):
        # its status says why, its error what happened, t_end and steps how far it got
        row["status"] = "ok" if raw.complete else ("timeout" if raw.info.get("timed_out") else "failed")
        row["error"] = raw.error
        for k, v in metrics.items():
            if k in DROPPED_METRICS or not (v is None or isinstance(v, (bool, int, float))):
                continue
            if not raw.complete and k not in KEPT_WHEN_FAILED:
                continue
            row[k] = None if isinstance(v, float) and not math.isfinite(v) else v
        if spec.trajectories and len(raw.time):  # kept for a failed run too: what it did until it stopped
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
