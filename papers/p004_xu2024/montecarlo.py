"""Monte Carlo of 004's sampled-data T-S loop over Markov paths and sampling sequences.

Theorem 2 bounds E[x^T H x](t) < c2 on [0, T] (expectation over the fault modes) for initial
states with x^T H x <= c1. This module estimates E[x^T H x](t) from N seeded runs with a
confidence band, in-process:

* ``engine = "vectorised"`` (default): all runs at once in numpy, the same semantics as the
  blocks under the master's ordered exchange at a fixed step h (see below);
* ``engine = "blocks"``: each run through the in-process master with the blocks of
  ``papers/p004_xu2024/blocks.py`` (the reference path; slow). Tests check they agree.

Run i (0-based) uses Markov seed ``seed + i``, sampling seed ``seed + i`` and, unless ``x0`` is
given, x0_i = sqrt(c1) g / ||H^(1/2) g|| with g ~ N(0, I) from ``default_rng([seed, i])``
(x0^T H x0 = c1). A campaign engine can call :func:`run_batch` on any subset of indices.

Semantics (those of the block loop, ``scenarios/xu2024_ts.toml``): on the grid t_n = n h,
the mode is r(t_n) (jumps taken when ``happened_at``), the controller latches y(t_n) and
h(y(t_n)) when t_n is a sample instant, u = sum_j h_j K_{r j} m_s y(t_k), the actuator gives
tau = F_r u + G_r v + d(t_n), and the T-S plant moves over [t_n, t_n + h] by one RK4 step with
tau held (h = h_max = 1 ms by default, as the blocks).
"""
from __future__ import annotations

import math
import time

import numpy as np

from controller.sampled_fuzzy import SampleSchedule
from plant.fuzzy import TriangularProduct
from plant.markov import ALPHA_COS2, AlphaProfile, MarkovChain
from plant.multisine import multisine
from plant.timing import POINT_TOL
from plant.ts_attitude import local_model

from . import parameters as P


def _ns(x: float) -> int:
    n = round(x * 1e9)
    if abs(x * 1e9 - n) > 1e-6:
        raise ValueError(f"{x!r} s is not a whole number of nanoseconds")
    return n


def initial_states(n_runs: int, seed: int, c1: float = 1.0, H=None, first: int = 0) -> np.ndarray:
    """x0_i on the ellipsoid x^T H x = c1 (Gaussian directions, one generator per run)."""
    H = np.eye(6) if H is None else np.asarray(H, float)
    L = np.linalg.cholesky(H)  # x^T H x = ||L^T x||^2
    out = np.empty((n_runs, 6))
    for k in range(n_runs):
        g = np.random.default_rng([seed, first + k]).standard_normal(6)
        out[k] = math.sqrt(c1) * g / np.linalg.norm(L.T @ g)
    return out


def run_batch(K, indices, T: float, seed: int = 0, x0=None, c1: float = 1.0, H=None, h: float = 0.001,
              rates=P.RATE_VERTICES, alpha_profile: int = ALPHA_COS2, r0: int = P.R0, m_s: float = 1.0,
              tau_min: float = P.SAMPLING["tau_min"], tau_max: float = P.SAMPLING["tau_max"],
              quantum: float = P.SAMPLING["sample_quantum"], disturbance_scale: float = 1.0,
              membership_order: str = "matched", record_every: int = 1) -> dict:
    """Simulate the runs ``indices`` (vectorised). Returns time (s), xHx (runs x samples),
    the states at the recorded times, the mode paths' jump counts, sampling intervals
    (min/max) and the largest premise mismatch max_j |h_j(x(t_k)) - h_j(x(t))|."""
    K = np.asarray(K, float)
    Nm, p = K.shape[0], K.shape[1]
    idx = list(indices)
    n = len(idx)
    H = np.eye(6) if H is None else np.asarray(H, float)
    A, B = local_model(P.XU2024["J"], P.XU2024["delta"], P.OPERATING_POINTS)
    if p != A.shape[0]:
        raise ValueError(f"K has {p} rules, the T-S model {A.shape[0]}")
    memb = TriangularProduct(P.MEMBERSHIP["z_half_width"], P.RULE_PEAKS[membership_order], P.MEMBERSHIP["z_slope"])
    F, G, v = P.FAULT_MODES["F"][:Nm], P.FAULT_MODES["G"][:Nm], P.FAULT_MODES["v"]
    Gv = G * v
    d = P.DISTURBANCE
    h_ns, q_ns = _ns(h), _ns(quantum)
    if q_ns % h_ns:
        raise ValueError(f"the step h = {h:g} s must divide sample_quantum = {quantum:g} s")
    steps = int(round(T / h))
    # per run: Markov chain (jumps taken on the grid) and sampling schedule
    prof = AlphaProfile(alpha_profile, rates.shape[0])
    chain = MarkovChain(rates, prof, r0, seed + idx[0])
    chains, scheds = [], []
    for i in idx:
        c = MarkovChain.__new__(MarkovChain)
        c.__dict__.update(chain.__dict__)
        c.restart(seed + i, r0, 0.0)
        chains.append(c)
        scheds.append(SampleSchedule(0.0, quantum, tau_min, tau_max, seed + i, 1))
    next_tick = np.zeros(n, dtype=np.int64)  # in quanta
    k_sample = np.zeros(n, dtype=np.int64)
    last_tick = np.zeros(n, dtype=np.int64)
    ratio = q_ns // h_ns  # grid steps per quantum
    if x0 is None:
        X = np.vstack([initial_states(1, seed, c1, H, i) for i in idx])
    else:
        X = np.tile(np.asarray(x0, float), (n, 1))
    modes = np.array([c.r for c in chains])
    t_jump = np.array([c.t_next for c in chains])
    Zh = np.zeros((n, 6))
    Hh = np.zeros((n, p))
    rec_t, rec_x, rec_xhx = [], [], []
    mismatch = 0.0
    tau_lo, tau_hi = math.inf, 0.0
    Kf = K.reshape(Nm, p, 18)
    AT = np.transpose(A, (0, 2, 1))  # for X @ A_i^T

    def deriv(Xs, BU):
        W = memb.weights_batch(Xs)  # (n, p)
        AX = np.matmul(Xs, AT)  # (p, n, 6): A_i x for every run
        out = BU.copy()
        for i in range(p):
            out += W[:, i : i + 1] * AX[i]
        return out

    for step in range(steps + 1):
        t = (step * h_ns) / 1e9
        # mode source: jumps that have happened at t
        for c_i in np.nonzero(t_jump <= t + POINT_TOL * max(1.0, t))[0]:  # happened_at
            c = chains[c_i]
            c.advance_to(t)
            modes[c_i], t_jump[c_i] = c.r, c.t_next
        # controller: sample instants at t
        if step % ratio == 0:
            tick = step // ratio
            due = np.nonzero(next_tick == tick)[0]
            if due.size:
                Zh[due] = m_s * X[due]
                Hh[due] = memb.weights_batch(X[due])
                for c_i in due:
                    nt = scheds[c_i].ticks(int(k_sample[c_i]))
                    if k_sample[c_i] > 0:
                        dt = (tick - last_tick[c_i]) * quantum
                        tau_lo, tau_hi = min(tau_lo, dt), max(tau_hi, dt)
                    last_tick[c_i] = tick
                    next_tick[c_i] = tick + nt
                    k_sample[c_i] += 1
        if step % record_every == 0:
            rec_t.append(t)
            rec_x.append(X.copy())
            rec_xhx.append(np.einsum("ni,ij,nj->n", X, H, X))
        if step == steps:
            break
        W_now = memb.weights_batch(X)
        mismatch = max(mismatch, float(np.abs(W_now - Hh).max()))
        # u = sum_j h_j K_{r j} z ; tau = F_r u + G_r v + d(t)
        Kr = Kf[modes]  # (n, p, 18)
        Ku = np.einsum("np,npk->nk", Hh, Kr).reshape(n, 3, 6)
        u = np.einsum("nij,nj->ni", Ku, Zh)
        tau = F[modes] * u + Gv[modes] + disturbance_scale * multisine(t, d["bias"], d["a_cos"], d["a_sin"], d["freq"])
        BU = tau @ B.T
        k1 = deriv(X, BU)
        k2 = deriv(X + (0.5 * h) * k1, BU)
        k3 = deriv(X + (0.5 * h) * k2, BU)
        k4 = deriv(X + h * k3, BU)
        X = X + (h / 6.0) * (k1 + 2.0 * (k2 + k3) + k4)
    return {"time": np.array(rec_t), "xHx": np.array(rec_xhx).T, "x": np.transpose(np.array(rec_x), (1, 0, 2)),
            "n_jumps": np.array([c.n_jumps for c in chains]), "samples": k_sample.copy(),
            "tau_range": (tau_lo, tau_hi), "max_premise_mismatch": mismatch, "indices": idx}


def band(values: np.ndarray, z: float = 4.0) -> dict:
    """Mean over runs (axis 0) with a z-sigma band of the mean: mean +- z s / sqrt(N)."""
    n = values.shape[0]
    mean = values.mean(axis=0)
    sd = values.std(axis=0, ddof=1) if n > 1 else np.zeros_like(mean)
    half = z * sd / math.sqrt(n)
    return {"mean": mean, "std": sd, "lower": mean - half, "upper": mean + half, "z": z, "n": n}


def monte_carlo(K, n_runs: int, T: float, seed: int = 0, c2: float | None = None, z: float = 4.0,
                engine: str = "vectorised", batch: int = 500, **kw) -> dict:
    """E[x^T H x](t) over ``n_runs`` seeded runs on [0, T], with a z-sigma band; if ``c2`` is
    given, whether the band stays below it. Runs per second in ``runs_per_s``."""
    if n_runs < 2:
        raise ValueError("n_runs must be >= 2 for a confidence band")
    t0 = time.perf_counter()
    if engine == "vectorised":
        parts = [run_batch(K, range(a, min(a + batch, n_runs)), T, seed, **kw) for a in range(0, n_runs, batch)]
    elif engine == "blocks":
        parts = [run_blocks(K, range(n_runs), T, seed, **kw)]
    else:
        raise ValueError(f"engine = {engine!r}: 'vectorised' or 'blocks'")
    wall = time.perf_counter() - t0
    t = parts[0]["time"]
    xhx = np.vstack([q["xHx"] for q in parts])
    b = band(xhx, z)
    out = {"time": t, "xHx": xhx, **b, "n_runs": n_runs, "T": T, "seed": seed, "engine": engine,
           "wall_s": wall, "runs_per_s": n_runs / wall if wall > 0 else None,
           "max_premise_mismatch": max(q["max_premise_mismatch"] for q in parts),
           "tau_range": (min(q["tau_range"][0] for q in parts), max(q["tau_range"][1] for q in parts)),
           "mean_jumps": float(np.mean(np.concatenate([q["n_jumps"] for q in parts])))}
    out["max_mean"] = float(b["mean"].max())
    out["max_upper"] = float(b["upper"].max())
    if c2 is not None:
        out["c2"] = float(c2)
        out["bound_holds"] = bool(out["max_upper"] < c2)
    return out


def run_blocks(K, indices, T: float, seed: int = 0, x0=None, c1: float = 1.0, H=None, h: float = 0.001, **kw) -> dict:
    """The reference path: each run through the in-process master with 004's blocks
    (scenario ``xu2024_ts``), Markov and sampling seeds ``seed + i``, x0 as in :func:`run_batch`."""
    from pathlib import Path

    from orchestrator import api

    if kw:
        raise ValueError(f"engine 'blocks' takes no options {sorted(kw)}")
    path = Path(__file__).parent / "scenarios" / "xu2024_ts.toml"
    xs, xhx, times = [], [], None
    H = np.eye(6) if H is None else np.asarray(H, float)
    for i in indices:
        sc = api.load(path, mode="inprocess", step=h)
        x_init = initial_states(1, seed, c1, H, i)[0] if x0 is None else np.asarray(x0, float)
        r = api.run(sc, stop=sc.start + T, parameters={"plant.x_init": x_init, "faults.seed": float(seed + i),
                                                       "ctrl.sample_seed": float(seed + i), "ctrl.K": K}).raw
        if not r.complete:
            raise RuntimeError(f"run {i}: {r.error}")
        x = np.hstack([r.vector("plant.omega"), r.vector("plant.q")[:, 1:]])
        xs.append(x)
        xhx.append(np.einsum("ni,ij,nj->n", x, H, x))
        times = r.time
    return {"time": times, "xHx": np.array(xhx), "x": np.array(xs), "n_jumps": np.zeros(len(xs)),
            "samples": None, "tau_range": (math.nan, math.nan), "max_premise_mismatch": math.nan,
            "indices": list(indices)}
