"""A campaign expanded into its runs: the draws of every dispersion (one seeded generator per draw and
dispersion), the grid points and variants, and each run's key, a hash of everything that decides the
run (:func:`fingerprint` of its base scenario: timing and step policy, wiring, sources, recording,
metrics, every parameter value, the FMUs by their SHA-256 and an in-process block by the digest of its
sources; then its overrides and draws), under which its result is stored. A run whose inputs changed
has another key: a resumed campaign computes it again or refuses the stale stored one, never mixes it
in (``orchestrator/common/digest.py`` computes the digests, for the arena's cells too)."""
from __future__ import annotations

import dataclasses
import math
import zlib

import numpy as np

from orchestrator.campaign.spec import Campaign, RunSpec, recipe
from orchestrator.common.digest import digest, file_digest, source_digest
from orchestrator.common.errors import InputError
from orchestrator.scenario.overrides import expand_parameters, nominal_values, with_overrides


def run_seed(seed: int, draw: int) -> np.random.SeedSequence:
    """``SeedSequence(seed).spawn(runs)[draw]`` (for any runs > draw), built directly: the k-th
    child of a spawn is ``SeedSequence(seed, spawn_key=(k,))`` (tested)."""
    return np.random.SeedSequence(seed, spawn_key=(draw,))


def run_generator(seed: int, draw: int, ref: str) -> np.random.Generator:
    """The generator of dispersion ``ref`` in draw ``draw``: the child of :func:`run_seed` keyed
    by the CRC-32 of ``ref``."""
    child = run_seed(seed, draw)
    return np.random.default_rng(np.random.SeedSequence(child.entropy, spawn_key=child.spawn_key
                                                        + (zlib.crc32(ref.encode("utf-8")),)))


def draws(c: Campaign, draw: int, base, cache=None) -> dict:
    """{'inst.name': value} of draw ``draw`` for the dispersions, applied to the nominal values of
    ``base`` (a scenario with the grid point applied). ``cache``: a dict keeping the raw draws
    (the same for every variant and grid point)."""
    out = {}
    for d in c.dispersions:
        if cache is None or (draw, d.ref) not in cache:
            x = d.draw(run_generator(c.seed, draw, d.ref))
            if cache is not None:
                cache[(draw, d.ref)] = x
        x = cache[(draw, d.ref)] if cache is not None else x
        if d.apply != "value":
            nominal = nominal_values(base.instances[d.inst])
            missing = [n for n in d.names if n not in nominal]
            if missing:
                raise InputError(c.path, f"dispersions.{d.ref}", f"{d.inst}.{missing[0]} has no nominal value to "
                                                                 f"{d.apply} (give apply = 'value')")
            nom = np.array([nominal[n] for n in d.names])
            x = nom * x if d.apply == "scale" else nom + x
        for n, v in zip(d.names, x):
            if not math.isfinite(v):
                raise InputError(c.path, f"dispersions.{d.ref}", f"draw {draw} gives a non-finite {d.inst}.{n}")
            out[f"{d.inst}.{n}"] = float(v)
    return out


def _block_code(inst) -> str | None:
    """Digest of the sources an in-process instance's block runs (None for an FMU: its bytes count)."""
    if inst.fmu is not None or inst.factory is None:
        return None
    module = getattr(inst.factory, "__module__", None)
    return source_digest(module) if module else None


# 2: final_attitude_error and max_attitude_error_last_10s in rad (2 asin ||q_ev||), the quaternion norm
# as final_q_ev_norm / max_q_ev_norm_last_10s (issue 36); 1 before
METRIC_DEFINITIONS = 2


def fingerprint(sc) -> dict:
    """Everything of a scenario that decides a run, as plain JSON data: timing and the resolved step
    policy, each instance's model, FMU (SHA-256) or block code (digest of its sources), step,
    announced instants and parameter values, the wiring, sources, recorded signals and metrics."""
    timing = dataclasses.asdict(sc.timing)
    timing.pop("given", None)  # which keys the file spelled out: the resolved values are what counts
    return {
        "start": sc.start, "stop": sc.stop, "step": sc.step, "exchange": sc.exchange, "timing": timing,
        "paper": sc.paper,
        "instances": {n: {"model": i.model_name, "fmu": file_digest(i.fmu) if i.fmu else None,
                          "code": _block_code(i), "step": i.step, "announces": list(i.announces or ()),
                          "parameters": sorted(i.parameters.items())} for n, i in sc.instances.items()},
        "connections": [list(x) for x in sc.connections],
        "sources": [[s.name, list(s.times), np.asarray(s.values).tolist(), [list(t) for t in s.targets]]
                    for s in sc.sources],
        "record": [list(x) for x in sc.record],
        "metrics": {k: v for k, v in sorted(sc.metrics.items())},
        # what the metrics mean: stored runs computed under another definition are not reused
        "metric_definitions": METRIC_DEFINITIONS,
    }


def expand(c: Campaign, only=None) -> list[RunSpec]:
    """Every run of the campaign (or the run ids in ``only``), in run-id order."""
    points = c.points
    n_pts = len(points)
    wanted = None if only is None else set(only)
    if wanted is not None:
        bad = sorted(k for k in wanted if not 0 <= k < c.n_runs)
        if bad:
            raise InputError("command line", "--run", f"run {bad[0]} does not exist (runs 0..{c.n_runs - 1})")
    specs = []
    raw_draws: dict = {}
    for j, (v, base) in enumerate(zip(c.variants, c.bases)):
        r = recipe(c, v)
        base_print = digest(fingerprint(base))
        digests = {str(i.fmu): file_digest(i.fmu) for i in base.instances.values() if i.fmu}
        for pt_index, point in enumerate(points):
            grid_params: dict = {}
            for ref, value in point.items():
                inst, _, name = ref.partition(".")
                grid_params.setdefault(inst, {}).update(
                    expand_parameters(c.path, f"grid.{ref}", base.instances[inst].interface, {name: value}))
            try:
                at_point = with_overrides(base, parameters=grid_params, src=c.path)
            except InputError as e:  # a point no run can use (a meaningless physical value): named in the file
                raise InputError(c.path, f"grid (point {pt_index}: {', '.join(f'{r} = {x}' for r, x in point.items())})",
                                 f"{e.key}: {e.problem}") from None
            for k in range(c.runs):
                run_id = (j * n_pts + pt_index) * c.runs + k
                if wanted is not None and run_id not in wanted:
                    continue
                requested = {f"{i}.{n}": x for i, p in grid_params.items() for n, x in p.items()}
                requested.update(draws(c, k, at_point, raw_draws))
                params = {i: dict(p) for i, p in grid_params.items()}
                for ref, x in requested.items():
                    inst, _, name = ref.partition(".")
                    params.setdefault(inst, {})[name] = x
                resolved = {"run_id": run_id, "variant": v.name, "point": pt_index, "draw": k, "mode": c.mode,
                            "base": base_print, "overrides": {i: sorted(p.items()) for i, p in sorted(params.items())},
                            "trajectories": c.trajectories, "trajectory_step": c.trajectory_step,
                            "settling": c.settling}
                key = digest(resolved, 20)
                specs.append(RunSpec(run_id=run_id, key=key, variant=j, variant_name=v.name, point=pt_index, draw=k,
                                     seed=c.seed, recipe=r, parameters=params, requested=requested,
                                     fmu_digests=digests, trajectories=list(c.trajectories),
                                     trajectory_step=c.trajectory_step, settling=c.settling,
                                     time_limit=c.time_limit))
    return specs
