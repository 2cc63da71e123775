"""Metrics of a 004 run (JSON-safe: None where a quantity is not recorded or a window is empty).

Signals (defaults = the instance names of ``scenarios/xu2024_*.toml``; a scenario's
[metrics] table may rename them): ``omega`` plant.omega, ``q`` plant.q, ``mode`` faults.mode,
``u`` ctrl.u, ``t_k`` ctrl.t_k, ``h_ctrl`` ctrl.h (held memberships), ``h_plant`` plant.h.

* x = [omega, q_v]: |x| at start and end, max x^T x (H = I, Theorem 2's weight), the time after
  which |x| stays below ``settle_level`` (0.1);
* control: max |u_i| (N.m), E = int ||u||^2 dt (N^2 m^2 s);
* faults: number of mode jumps, modes visited, fraction of time in each mode;
* sampling: number of samples and min / mean / max interval (s), from the t_k record;
* premise mismatch: max_j |h_j(x(t_k)) - h_j(x(t))| (the design assumes <= rho_mm).
"""
from __future__ import annotations

import math

import numpy as np

DEFAULTS = {"omega": "plant.omega", "q": "plant.q", "mode": "faults.mode", "u": "ctrl.u", "t_k": "ctrl.t_k",
            "h_ctrl": "ctrl.h", "h_plant": "plant.h"}


def _has(result, base) -> bool:
    return any(c == base or c.startswith(base + "[") for c in result.columns)


def _vec(result, base):
    return result.vector(base) if any(c.startswith(base + "[") for c in result.columns) else result.column(base)[:, None]


def _f(x):
    x = float(x)
    return x if math.isfinite(x) else None


def metrics(result, cfg) -> dict:
    table = getattr(cfg, "metrics", cfg) or {}
    sig = {k: table.get(k, v) if isinstance(table.get(k, v), str) else v for k, v in DEFAULTS.items()}
    settle = float(table.get("settle_level", 0.1))
    t = np.asarray(result.time)
    m = {"t_end": _f(t[-1]) if len(t) else None}
    if len(t) < 2:
        return m
    dt = np.diff(t)
    if _has(result, sig["omega"]) and _has(result, sig["q"]):
        x = np.hstack([_vec(result, sig["omega"]), _vec(result, sig["q"])[:, 1:4]])
        n = np.linalg.norm(x, axis=1)
        m.update(x_norm_initial=_f(n[0]), x_norm_final=_f(n[-1]), xHx_max=_f(np.max(n**2)))
        above = np.nonzero(n >= settle)[0]
        m[f"settling_time_x_{settle:g}"] = (_f(t[0]) if above.size == 0 else
                                            _f(t[above[-1] + 1]) if above[-1] + 1 < len(t) else None)
    if _has(result, sig["u"]):
        u = _vec(result, sig["u"])
        m.update(max_abs_u=_f(np.abs(u).max()), control_energy=_f(np.sum(np.sum(u[:-1] ** 2, axis=1) * dt)))
    if _has(result, sig["mode"]):
        r = np.rint(result.column(sig["mode"])).astype(int)
        m["n_jumps"] = int(np.count_nonzero(np.diff(r)))
        m["modes_visited"] = sorted(int(v) for v in np.unique(r))
        m["mode_time_fraction"] = {str(k): _f(np.sum(dt[r[:-1] == k]) / (t[-1] - t[0])) for k in m["modes_visited"]}
    if _has(result, sig["t_k"]):
        tk = np.unique(result.column(sig["t_k"]))
        d = np.diff(tk)
        m["n_samples"] = int(tk.size)
        m.update(sample_interval_min=_f(d.min()) if d.size else None, sample_interval_mean=_f(d.mean()) if d.size else None,
                 sample_interval_max=_f(d.max()) if d.size else None)
    if _has(result, sig["h_ctrl"]) and _has(result, sig["h_plant"]):
        m["max_premise_mismatch"] = _f(np.abs(_vec(result, sig["h_ctrl"]) - _vec(result, sig["h_plant"])).max())
    return m
