"""Metrics of a run, from its recorded signals: what every run reports (completeness, timing, step
statistics), the attitude, rate and control metrics of the scenario's [metrics] table, the paper's
own metrics (``Paper.metrics`` in ``papers/registry.py``) and the settling time of campaigns."""
from __future__ import annotations

import numpy as np

from papers.paper import resolve
from plant.units import power, product
from papers.registry import paper


def quaternion_vector_norm(q_e: np.ndarray) -> np.ndarray:
    """||q_ev|| for rows of [q_e0, q_ev]."""
    return np.linalg.norm(q_e[:, 1:4], axis=1)


def attitude_error_rad(q_ev) -> np.ndarray:
    """``attitude_error`` (rad): the principal angle 2 asin(||q_ev||) of error quaternions, from their
    vector parts ``q_ev`` (rows (n, 3), or one (3,)); in [0, pi], the same for q_e and -q_e (000 (4):
    q_e = q_d^* (x) q). ||q_ev|| is clipped to 1 against rounding of a unit quaternion. The one attitude
    error of runs, campaigns and the arena (``final_attitude_error``, ``attitude_error``)."""
    v = np.atleast_2d(np.asarray(q_ev, dtype=float))
    return 2.0 * np.arcsin(np.minimum(1.0, np.linalg.norm(v, axis=1)))


def base_metrics(result, scenario) -> dict:
    """What every run reports: scenario, completeness, timing, and the step policy's
    ``step_statistics`` (accepted / rejected steps, smallest / largest step, rollbacks, doSteps
    per instance, wall time; ``orchestrator/cosim/policies.py``)."""
    t_end = float(result.time[-1]) if len(result.time) else None
    simulated = t_end - float(result.time[0]) if len(result.time) else 0.0
    m = {
        "scenario": scenario.name,
        "complete": result.complete,
        "error": result.error,
        "mode": result.mode,
        "exchange": result.exchange,
        "t_end": t_end,
        "steps": result.steps,
        "step": scenario.step,
        "step_policy": result.info.get("policy") or getattr(scenario, "step_policy", "fixed"),
        "wall_time_s": round(result.wall_time, 4),
        # simulated time over wall time (steps * step is wrong for variable steps)
        "real_time_factor": (simulated / result.wall_time) if result.wall_time > 0 and simulated > 0 else None,
        "paper": scenario.paper or None,
        "signals": {k: v for k, v in scenario.metrics.items() if isinstance(v, str)},
        "metrics_config": dict(scenario.metrics),  # the whole [metrics] table, for the reports
    }
    if "step_statistics" in result.info:
        m["step_statistics"] = result.info["step_statistics"]
    return m


# What base_metrics and the papers' metrics report about a run rather than measure in it: the
# settings and the run's state, kept in ``Result.info`` / metrics.json's "info", never in "metrics".
INFO_KEYS = frozenset({
    "scenario", "complete", "error", "mode", "exchange", "t_end", "steps", "step", "step_policy", "wall_time_s",
    "real_time_factor", "paper", "signals", "metrics_config", "step_statistics", "u_max", "plots",
    "post_processing_errors", "record_step", "format", "fmus",
})


def split_metrics(flat: dict) -> tuple[dict, dict]:
    """(values, info) of a flat metrics dict (what :func:`compute_metrics` returns): the keys of
    :data:`INFO_KEYS` and every text value (a paper's descriptions) go to info."""
    values, info = {}, {}
    for k, v in flat.items():
        (info if k in INFO_KEYS or isinstance(v, str) else values)[k] = v
    return values, info


def signal_units(scenario, columns) -> dict:
    """column ("inst.var[i]") -> the unit its FMU or block declares ("1" if none); "time": "s"."""
    units = {"time": "s"}
    for col in columns:
        inst, _, var = col.partition(".")
        declared = scenario.instances[inst].interface.units if inst in scenario.instances else {}
        units[col] = declared.get(var) or declared.get(var.split("[")[0]) or "1"
    return units


def metric_units(values: dict, scenario, units: dict) -> dict:
    """metric -> unit (UCUM spelling, :func:`plant.units.ucum`) for the metrics whose unit is known:
    the [metrics] signals' declared units (``units``: :func:`signal_units`), rad for attitude errors,
    "1" for quaternion norms, "s" for times."""
    cfg = scenario.metrics

    def of(key):
        base = cfg.get(key)
        found = [u for c, u in units.items() if isinstance(base, str) and (c == base or c.startswith(base + "["))]
        return found[0] if found else None

    def quaternion(key):
        base = cfg.get(key)
        return isinstance(base, str) and f"{base}[0]" in units and f"{base}[3]" in units and f"{base}[4]" not in units

    u = of("control")
    attitude = ATTITUDE_UNITS if quaternion("attitude_error") else {k: of("attitude_error") for k in ATTITUDE_UNITS}
    known = {**attitude, "final_rate_error": of("rate_error"), "max_abs_u": u, "u_max": u,
             "control_energy": product(power(u or "1", 2), "s"), "settling_time": "s"}
    out = {}
    for k, v in values.items():
        unit = known.get(k)
        if unit is None and isinstance(v, (int, float)) and not isinstance(v, bool):
            if k.endswith("_s") or "settling_time" in k or k.startswith("t_"):
                unit = "s"
            elif k.endswith("_deg"):
                unit = "deg"
        if unit is not None:
            out[k] = unit
    return out


# the attitude metrics (rad: the rotation angle of the error; "1": the error quaternion's vector norm)
ATTITUDE_UNITS = {"final_attitude_error": "rad", "max_attitude_error_last_10s": "rad",
                  "final_q_ev_norm": "1", "max_q_ev_norm_last_10s": "1"}


def attitude_metrics(time: np.ndarray, signal: np.ndarray) -> dict:
    """The attitude error at the end and its largest value over the last 10 s of a run, in rad
    (``final_attitude_error``, ``max_attitude_error_last_10s``). ``signal``: rows of an error
    quaternion [q_e0, q_ev] (the angle :func:`attitude_error_rad`; its vector norm ||q_ev|| is kept
    as ``final_q_ev_norm`` and ``max_q_ev_norm_last_10s``, unit 1), or of angles (a pitch axis'
    theta: the norm of the row, in the signal's unit, rad in every shipped scenario)."""
    signal = np.asarray(signal, dtype=float)
    last = time >= time[-1] - 10.0  # never empty
    if signal.shape[1] == 4:
        nq = quaternion_vector_norm(signal)
        err = attitude_error_rad(signal[:, 1:4])
        out = {"final_q_ev_norm": float(nq[-1]), "max_q_ev_norm_last_10s": float(nq[last].max())}
    else:
        err, out = np.linalg.norm(signal, axis=1), {}
    return {"final_attitude_error": float(err[-1]), "max_attitude_error_last_10s": float(err[last].max()), **out}


def held_integral(time: np.ndarray, values: np.ndarray) -> float:
    """int v(t) dt for a signal held from each row to the next (zero-order hold), over rows
    at any times: sum_k v_k (t_{k+1} - t_k). Exact when the signal changes only at rows (fixed
    and multirate runs, announced instants recorded); for an adaptive run whose command changes
    at every accepted step but is recorded on the output grid, the left Riemann sum on the grid."""
    if len(time) < 2:
        return 0.0
    return float(np.sum(values[:-1] * np.diff(time)))


def compute_metrics(result, scenario) -> dict:
    """Run metrics from the recorded signals named in the scenario's [metrics] table.

    E = int ||u||^2 dt is summed exactly for a command held over each row interval (000 section
    5), with the intervals between the recorded times (:func:`held_integral`)."""
    m = base_metrics(result, scenario)
    cfg = scenario.metrics
    if len(result.time) == 0:
        return m
    if "attitude_error" in cfg:
        m.update(attitude_metrics(result.time, result.vector(cfg["attitude_error"])))
    if "rate_error" in cfg:
        we = np.linalg.norm(result.vector(cfg["rate_error"]), axis=1)
        m["final_rate_error"] = float(we[-1])
    if "control" in cfg:
        u = result.vector(cfg["control"])
        m["control_energy"] = held_integral(result.time, np.sum(u**2, axis=1))
        m["max_abs_u"] = float(np.abs(u).max())
        if "u_max" in cfg:
            m["u_max"] = float(cfg["u_max"])
            m["saturation_respected"] = bool(m["max_abs_u"] <= float(cfg["u_max"]) + 1e-12)
    m.update(paper_metrics(result, scenario))
    return m


def paper_metrics(result, scenario) -> dict:
    """The metrics the scenario's paper defines (``Paper.metrics``), if it names a known paper."""
    try:
        p = paper(scenario.paper)
    except KeyError:
        return {}
    return resolve(p.metrics)(result, scenario.metrics) if p.metrics else {}


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
