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

_BASES: dict = {}


def _base(spec):
    k = json.dumps(spec.recipe, sort_keys=True)
    if k not in _BASES:
        _BASES[k] = load_base(spec.recipe)[0]
    return _BASES[k]


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
