"""TSFDO (estimator/tsfdo.py) with 003's published gain: error dynamics, sampling limit, state, bad input.

* Exosystem test: with x from the double integrator driven by d = V w, w' = W w (memberships frozen
  at 1/2 by very wide Gaussians, u = 0), the observer error e_w = w - w_hat at the communication points follows e_k = D(h)^k e_0 with
  the sampled error map D of the module (to 1e-6), and decays (published L1: by > 1e5 in 0.5 s).
* Step-size limit: rho(D(h)) = 1 at 1.51 ms for the premise theta = 0 (1.19 ms for rule 1 alone,
  1.59 ms for rule 2); in closed loop with plant and ASMFTC the loop stays bounded at 1.40 ms and
  diverges at 1.55 ms (with the check off); the block refuses 2 ms and 1.45 ms (above 0.95 x limit)
  with a message naming the limit and warns at 1.3 ms (above rule 1's limit). Designed L1: 204-206 ms.
* Priming (w_hat(t0) = w_hat_init), exact rollback, bad input (one ValueError each).
"""
import warnings

import numpy as np
import pytest
import scipy.linalg as sla

from estimator.tsfdo import sampled_error_map
from papers.p003_hang2023 import blocks
from papers.p003_hang2023.gains import L1_DESIGNED
from papers.p003_hang2023.parameters import MF_CENTER, MF_SIGMA2, V, W
from plant.fuzzy import Gaussian

MF = Gaussian(MF_CENTER, MF_SIGMA2)
H0 = MF.weights([0.0])  # memberships at theta = 0: 0.148 / 0.852


def _observer(**p):
    o = blocks.observer()
    o.set_parameters(p)
    o.initialize(0.0)
    return o


def _designed():
    return {f"L1[{i + 1},{j + 1}]": L1_DESIGNED[i, j] for i in range(2) for j in range(2)}


def test_error_follows_the_sampled_error_map():
    # very wide memberships: h_j = 1/2 whatever the premise (frozen blend)
    o = _observer(**{"mf_sigma2[1]": 1e12, "mf_sigma2[2]": 1e12})
    h, n = 5e-4, 1000
    Wb, Vb = 0.5 * (W[0] + W[1]), 0.5 * (V[0] + V[1])
    G = np.zeros((4, 4))
    G[:2, :2], G[2, 3], G[3, :2] = Wb, 1.0, o.b0 * Vb[0]
    E = sla.expm(G * h)
    w, x = np.array([0.05, -0.02]), np.zeros(2)
    D = sampled_error_map(Wb, Vb, o.L1, o.b0, h, 1, mode=1)
    e0 = w.copy()  # w_hat(0) = 0
    errs = []
    for k in range(n):
        y = o.outputs_at(k * h, np.array([x[0], x[1], 0.0]))
        errs.append(w - y[1:3])
        o.advance(k * h, h, np.array([x[0], x[1], 0.0]))
        z = E @ np.concatenate([w, x])
        w, x = z[:2], z[2:]
    errs = np.array(errs)
    pred = np.array([np.linalg.matrix_power(D, k) @ e0 for k in range(n)])
    assert np.abs(errs - pred).max() < 1e-6 * np.abs(e0).max()
    assert np.linalg.norm(errs[-1]) < 1e-5 * np.linalg.norm(e0)


def test_stability_limit_of_the_published_gain():
    o = _observer()
    lim = o.stability_limit(H0, 0.01)
    assert 1.505e-3 < lim < 1.515e-3
    assert 1.185e-3 < o.stability_limit([1.0, 0.0], 0.01) < 1.195e-3
    assert 1.58e-3 < o.stability_limit([0.0, 1.0], 0.01) < 1.59e-3
    od = _observer(h_max=1e-3, **_designed())
    assert 0.204 < od.stability_limit(H0, 1.0) < 0.206


def test_refuses_and_warns():
    o = _observer()
    x = np.array([0.08, 0.04, 0.0])
    with pytest.raises(ValueError, match=r"communication step 2 ms is above the accepted step 0.95 x limit = "
                                         r"1.4\d+ ms \(stability limit 1.50\d+ ms .*rule 1: 1.19 ms, rule 2: 1.586 ms"):
        o.advance(0.0, 2e-3, x)
    o = _observer()
    with pytest.raises(ValueError, match=r"1.45 ms is above the accepted step .* too close to it"):
        o.advance(0.0, 1.45e-3, x)
    o = _observer()
    with pytest.warns(RuntimeWarning, match=r"1.3 ms is accepted .* exceeds the limit of rule\(s\) 1 alone"):
        o.advance(0.0, 1.3e-3, x)
    o = _observer()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        o.advance(0.0, 5e-4, x)  # the scenario step: silent
    o = _observer(step_check=1)
    with pytest.warns(RuntimeWarning, match="the sampled loop diverges"):
        o.advance(0.0, 2e-3, x)


def _loop(h, T, step_check=0):
    p, o, c = blocks.plant(), blocks.observer(), blocks.controller()
    o.set_parameter("step_check", step_check)
    for b in (p, o, c):
        b.initialize(0.0)
    u = np.zeros(1)
    oin, cin = np.zeros(3), np.zeros(5)
    worst = 0.0
    for k in range(int(round(T / h))):
        t = k * h
        y = p.outputs_at(t, u)
        oin[:2] = cin[:2] = y[:2]
        cin[4] = o.outputs_at(t, oin)[0]
        u = c.outputs_at(t, cin)[:1]
        oin[2] = u[0]
        p.advance(t, h, u)
        o.advance(t, h, oin)
        c.advance(t, h, cin)
        worst = max(worst, abs(cin[4]))
    return worst


@pytest.mark.slow
def test_closed_loop_limit_brackets_the_map():
    assert _loop(1.40e-3, 1.0) < 2.0  # |d0_hat| stays of the order of d0 (< 0.3 N.m)
    with pytest.raises(FloatingPointError, match="the closed loop diverged"):
        _loop(1.55e-3, 1.0)


def test_priming_and_rollback():
    o = _observer(**{"w_hat_init[1]": 0.3})
    x = np.array([0.08, 0.04, 0.1])
    y0 = o.outputs_at(0.0, x)
    assert y0[1] == 0.3 and y0[0] == pytest.approx(0.3 * (H0[0] * 4 + H0[1] * 3), rel=0.05)
    o.advance(0.0, 5e-4, x)
    state = o.get_state()
    rows = []
    for k in range(20):
        o.advance((k + 1) * 5e-4, 5e-4, x + 1e-3 * k)
        rows.append(o.outputs_at((k + 2) * 5e-4, x).tolist())
    o.set_state(state)
    again = []
    for k in range(20):
        o.advance((k + 1) * 5e-4, 5e-4, x + 1e-3 * k)
        again.append(o.outputs_at((k + 2) * 5e-4, x).tolist())
    assert rows == again and rows[0] != rows[-1]


@pytest.mark.parametrize("name, value, match", [
    ("mf_sigma2[2]", 0.0, r"every variance sigma2 must be > 0"),
    ("premise", 3, r"premise must be 0 \(theta\), 1 \(theta_dot\) or 2"),
    ("sampling_mode", 2, r"sampling_mode must be 0 or 1"),
    ("J", -6.14, r"J \(pitch inertia\) must be > 0"),
    ("step_fraction", 1.5, r"step_fraction must be in \(0, 1\]"),
])
def test_bad_observer_parameters(name, value, match):
    o = blocks.observer()
    o.set_parameter(name, value)
    with pytest.raises(ValueError, match=match):
        o.initialize(0.0)


def test_mode0_refuses_an_unstable_rk4_step():
    o = blocks.observer()
    o.set_parameters({"sampling_mode": 0, "h_max": 2e-3})
    with pytest.raises(ValueError, match=r"h_max = 0.002 s is outside RK4's stability region .* use h_max <= 0.00169 s"):
        o.initialize(0.0)
