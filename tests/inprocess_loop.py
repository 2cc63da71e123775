"""A small fixed-step in-process loop: plant -> FAFEO -> controller -> plant, for the tests.

At each communication point t_k: plant outputs -> estimator inputs (omega) -> estimator outputs
(f_hat, d2_hat do not depend on u) -> controller inputs -> controller output u -> plant and
estimator inputs (u), then every block advances over [t_k, t_k + h] with its inputs held.
Signals are recorded at every communication point (every ``record_every``-th one).

Set-up: 000 section 5 (Table 1): q(0) = (sqrt(1 - 0.29), 0.3, 0.2, -0.4), omega(0) = (0.02, -0.03,
0.01) rad/s, modes at rest, faults 000 (66) from 40 s, misalignment (0.2, 0.1, 0.1) / (0.15, 0.1,
0.1) deg, disturbance u_d, target q_d = (sqrt(1-0.29), 0.3, 0.2, -0.4) until 80 s then
(sqrt(1-0.06), 0.2, -0.1, -0.1), omega_d = 0.
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from papers.p000_li2023 import blocks as li2023_blocks

Q_D1 = np.array([math.sqrt(1 - 0.29), 0.3, 0.2, -0.4])
Q_D2 = np.array([math.sqrt(1 - 0.06), 0.2, -0.1, -0.1])
T_SWITCH = 80.0
OMEGA_INIT = (0.02, -0.03, 0.01)

CONTROLLERS = {"fasmc": li2023_blocks.fasmc, "aismc": li2023_blocks.aismc, "pd": li2023_blocks.pd_controller}


def li2023_plant_parameters(fault_scale: float = 1.0) -> dict:
    p = {f"q_init[{i}]": x for i, x in enumerate(Q_D1)}
    p.update({f"omega_init[{i + 1}]": x for i, x in enumerate(OMEGA_INIT)})
    p.update({f"misalign_a[{i + 1}]": x for i, x in enumerate((0.2, 0.1, 0.1))})
    p.update({f"misalign_b[{i + 1}]": x for i, x in enumerate((0.15, 0.1, 0.1))})
    p.update({"fault_scale": fault_scale, "fault_onset": 40.0, "disturbance_scale": 1.0})
    return p


@dataclass
class Run:
    h: float
    t: np.ndarray
    sig: dict = field(default_factory=dict)
    energy: float = 0.0  # int ||u||^2 dt, u held over each step (exact for the ZOH command)
    u_abs_max: float = 0.0
    wall: float = 0.0
    advance_us: dict = field(default_factory=dict)

    def window(self, t0: float, t1: float = math.inf) -> np.ndarray:
        return (self.t >= t0) & (self.t <= t1)

    def obs_error(self) -> np.ndarray:
        return np.linalg.norm(self.sig["omega"] - self.sig["omega_hat"], axis=1)

    def fault_rms_ratio(self, t0: float = 50.0, t1: float = 200.0) -> np.ndarray:
        """RMS(f_hat_i - f_i) / RMS(f_i) over [t0, t1] for the faulty channels 1, 2."""
        m = self.window(t0, t1)
        err = self.sig["f_hat"][m, :2] - self.sig["f"][m, :2]
        ref = self.sig["f"][m, :2]
        return np.sqrt((err**2).mean(axis=0)) / np.sqrt((ref**2).mean(axis=0))


def run_loop(
    controller: str = "fasmc",
    h: float = 0.01,
    t_end: float = 200.0,
    fault_scale: float = 1.0,
    estimator: bool = True,
    plant_params: dict | None = None,
    estimator_params: dict | None = None,
    controller_params: dict | None = None,
    record_every: int = 1,
    blocks: tuple | None = None,
) -> Run:
    plant = li2023_blocks.flexible_spacecraft()
    est = li2023_blocks.fafeo()
    ctrl = CONTROLLERS[controller]()
    plant.set_parameters(li2023_plant_parameters(fault_scale) | (plant_params or {}))
    est.set_parameters(estimator_params or {})
    ctrl.set_parameters(controller_params or {})
    for b in (plant, est, ctrl):
        b.initialize(0.0)
    if blocks is not None:
        blocks[:] = [plant, est, ctrl]

    n_steps = int(round(t_end / h))
    n_rec = n_steps // record_every + 1
    names = {"omega": 3, "omega_hat": 3, "f_hat": 3, "f": 3, "d2_hat": 8, "d2": 8, "u": 3, "q_e": 4, "omega_e": 3}
    sig = {k: np.zeros((n_rec, m)) for k, m in names.items()}
    t_rec = np.zeros(n_rec)

    pi = plant.output_index
    p_omega = slice(pi["omega[1]"], pi["omega[1]"] + 3)
    p_q = slice(pi["q[0]"], pi["q[0]"] + 4)
    p_d2 = slice(pi["eta[1]"], pi["eta[1]"] + 8)
    p_f = slice(pi["f[1]"], pi["f[1]"] + 3)
    ci = ctrl.input_index
    c_q = slice(ci["q[0]"], ci["q[0]"] + 4)
    c_omega = slice(ci["omega[1]"], ci["omega[1]"] + 3)
    c_qd = slice(ci["q_d[0]"], ci["q_d[0]"] + 4)
    c_fd = slice(ci["f_hat[1]"], ci["f_hat[1]"] + 11)  # f_hat (3) and d2_hat (8)

    u = np.zeros(3)
    est_in = np.zeros(6)
    ctrl_in = ctrl.default_inputs()
    energy = 0.0
    u_abs_max = 0.0
    tp = te = tc = 0.0
    clock = time.perf_counter
    start = clock()
    r = 0
    for k in range(n_steps + 1):
        t = k * h
        yp = plant.outputs_at(t, u)
        est_in[0:3] = yp[p_omega]
        ye = est.outputs_at(t, est_in) if estimator else np.zeros(14)
        ctrl_in[c_q] = yp[p_q]
        ctrl_in[c_omega] = yp[p_omega]
        ctrl_in[c_qd] = Q_D1 if t < T_SWITCH else Q_D2
        ctrl_in[c_fd] = ye[3:14]
        yc = ctrl.outputs_at(t, ctrl_in)
        u = yc[0:3].copy()
        est_in[3:6] = u
        if k % record_every == 0:
            t_rec[r] = t
            sig["omega"][r] = yp[p_omega]
            sig["omega_hat"][r] = ye[0:3]
            sig["f_hat"][r] = ye[3:6]
            sig["d2_hat"][r] = ye[6:14]
            sig["f"][r] = yp[p_f]
            sig["d2"][r] = yp[p_d2]
            sig["u"][r] = u
            sig["q_e"][r] = yc[3:7]
            sig["omega_e"][r] = yc[7:10]
            r += 1
        if k == n_steps:
            break
        energy += float(u @ u) * h
        u_abs_max = max(u_abs_max, float(np.abs(u).max()))
        c0 = clock()
        plant.advance(t, h, u)
        c1 = clock()
        if estimator:
            est.advance(t, h, est_in)
        c2 = clock()
        ctrl.advance(t, h, ctrl_in)
        c3 = clock()
        tp += c1 - c0
        te += c2 - c1
        tc += c3 - c2
    wall = clock() - start
    us = {"plant": 1e6 * tp / n_steps, "estimator": 1e6 * te / n_steps, "controller": 1e6 * tc / n_steps}
    return Run(h, t_rec[:r], {k: v[:r] for k, v in sig.items()}, energy, u_abs_max, wall, us)


_CACHE: dict = {}


def cached_run(controller: str = "fasmc", h: float = 0.01, t_end: float = 200.0, fault_scale: float = 1.0) -> Run:
    """``run_loop`` with default parameters, computed once per pytest session."""
    key = (controller, h, t_end, fault_scale)
    if key not in _CACHE:
        _CACHE[key] = run_loop(controller, h=h, t_end=t_end, fault_scale=fault_scale)
    return _CACHE[key]


FAULT_STEPS = (40.0, 70.0, 100.0)  # 000 (66): f2 jumps 0 -> 1, 1 -> 0, 0 -> 1.5 N.m


def away_from_fault_steps(t: np.ndarray, width: float = 2.0) -> np.ndarray:
    """t > 40 s, excluding ``width`` seconds after each step of f2."""
    m = t > FAULT_STEPS[0]
    for s in FAULT_STEPS:
        m &= ~((t > s) & (t < s + width))
    return m
