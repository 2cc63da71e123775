"""Paper 002's metrics of one run (Figs. 1-2 and Table 2 quantities), JSON-safe (None, never NaN).

``metrics(result, cfg)``: ``result`` a RunResult, ``cfg`` the scenario's [metrics] table, which names
the signals (``theta``, ``theta_dot``, ``torque`` = applied omega u, ``command`` = u, ``vibration``
= w of 002 (8), optional ``modes`` / ``mode_rates`` for eta, eta') and gives ``omega_hat``.

* peak theta and its time; 2 % and 5 % settling times of theta (first time after which
  |theta| <= 2 % / 5 % of |theta(0)| for the rest of the run; None if it never settles);
* J_c of 002 (11) over the run: int x^T Z x + R (omega u)^2 dt, the x part by the trapezoidal rule,
  the torque part exactly (omega u is held over each step); against J* of Table 2 (its omega_hat);
* u(0), omega u(0), max |u|, max |omega u|, max |w|;
* closed-loop poles fitted from the run: the least-squares transition matrix Phi of the recorded
  plant state z_k -> z_k+1 (theta, theta' and, when named, eta, eta'), poles = log(eig Phi) / h.
  They are the poles of the sampled-data loop (ZOH command); papers/p002_zhang2014/report.py and
  the tests compare them with the model's.
"""
from __future__ import annotations

import numpy as np

from .gains import PUBLISHED
from .parameters import R, Z

# [metrics] keys of 002's scenarios (checked by the scenario loader)
KEYS = {"theta": "signal", "theta_dot": "signal", "torque": "signal", "command": "signal", "vibration": "signal",
        "modes": "signal", "mode_rates": "signal", "omega_hat": "number", "fit_until": "time"}


def _col(result, ref):
    return result.column(ref) if ref in result.columns else result.vector(ref)


def settling_time(t, y, band):
    """First time after which |y| <= band until the end (None if the last sample is outside)."""
    out = np.nonzero(np.abs(y) > band)[0]
    if len(out) == 0:
        return float(t[0])
    if out[-1] == len(y) - 1:
        return None
    return float(t[out[-1] + 1])


def fit_poles(t, states, t_max=None):
    """Continuous-time poles of the LTI map fitted to z_k -> z_k+1 (rows of ``states``, up to ``t_max``;
    columns that stay 0 are dropped), sorted by imaginary part then real part; [(re, im), ...]."""
    h = float(t[1] - t[0])
    Zs = np.asarray(states, float)
    if t_max is not None:
        Zs = Zs[t <= t_max]
    Zs = Zs[:, np.abs(Zs).max(axis=0) > 0]  # a state that stays 0 (no coupling) carries no pole
    X, Y = Zs[:-1], Zs[1:]
    scale = np.maximum(np.abs(X).max(axis=0), 1e-300)  # columns of very different size
    Phi_s, *_ = np.linalg.lstsq(X / scale, Y / scale, rcond=None)
    lam = np.log(np.linalg.eigvals(Phi_s.T).astype(complex)) / h
    lam = sorted(lam, key=lambda z: (round(z.imag, 9), z.real))
    return [(float(z.real), float(z.imag)) for z in lam]


def cost(t, x, tau):
    """J_c of 002 (11) along a run: trapezoid for x^T Z x, exact for the held torque tau."""
    h = np.diff(t)
    q = np.einsum("ki,ij,kj->k", x, Z, x)
    return float(np.sum(0.5 * (q[:-1] + q[1:]) * h) + float(R[0, 0]) * np.sum(tau[:-1] ** 2 * h))


def metrics(result, cfg) -> dict:
    t = result.time
    if len(t) < 3:
        return {"paper": "002", "complete": False}
    th, thd = _col(result, cfg["theta"]), _col(result, cfg["theta_dot"])
    tau, u = _col(result, cfg["torque"]), _col(result, cfg["command"])
    m = {"paper": "002", "complete": bool(result.complete), "omega_hat": float(cfg.get("omega_hat", 1.0))}
    k = int(np.argmax(th))
    m["peak_theta"], m["t_peak"] = float(th[k]), float(t[k])
    th0 = abs(float(th[0]))
    m["settling_time_2pct"] = settling_time(t, th, 0.02 * th0) if th0 > 0 else None
    m["settling_time_5pct"] = settling_time(t, th, 0.05 * th0) if th0 > 0 else None
    m["theta_final"], m["theta_dot_final"] = float(th[-1]), float(thd[-1])
    for T in (10.0, 20.0, 30.0, 50.0):
        m[f"theta_at_{T:g}s"] = float(np.interp(T, t, th)) if t[-1] >= T else None
    m["J_c"] = cost(t, np.column_stack([th, thd]), tau)
    pub = PUBLISHED.get(m["omega_hat"])
    m["J_star_printed"] = None if pub is None else float(pub["J_star"])
    m["J_c_le_J_star"] = None if pub is None else bool(m["J_c"] <= pub["J_star"])
    m["u0"], m["tau0"] = float(u[0]), float(tau[0])
    m["max_abs_u"], m["max_abs_tau"] = float(np.abs(u).max()), float(np.abs(tau).max())
    if "vibration" in cfg:
        m["max_abs_vibration_torque"] = float(np.abs(_col(result, cfg["vibration"])).max())
    states = [th, thd]
    if "modes" in cfg and "mode_rates" in cfg:
        eta, etad = _col(result, cfg["modes"]), _col(result, cfg["mode_rates"])
        states += [eta[:, i] for i in range(eta.shape[1])] + [etad[:, i] for i in range(etad.shape[1])]
        m["max_abs_eta"] = [float(x) for x in np.abs(eta).max(axis=0)]
    m["poles_fit"] = fit_poles(t, np.column_stack(states), t_max=float(cfg.get("fit_until", 40.0)))
    return m
