"""001's controller (controller/fontsm.py, 001 (23)-(36)) in closed loop: the printed pairing
diverges and the aligned reading converges (both shown), the GL start-up, convergence under the
fault profile (onset moved to 3 s to keep the runs short), the torque-level fault estimate with
the printed and with our observer gains, exact rollback including the fractional history, bad
input."""
import math

import numpy as np
import pytest
from zhang2019_runs import run

from papers.p001_zhang2019 import blocks
from papers.p001_zhang2019.metrics import metrics
from papers.p001_zhang2019.parameters import OMEGA0, SIGMA0
from plant import euler231


def _max_deg(result, t0, t1, sig="plant.sigma"):
    m = (result.time >= t0 - 1e-9) & (result.time <= t1 + 1e-9)
    return float(np.degrees(np.abs(result.vector(sig)[m])).max())


def test_kinematics_at_zero_attitude_is_a_permutation():
    """Why the printed pairing fails: near sigma = 0, nu' = omega_3 and gamma' = omega_1, while
    001 (30) adds the fractional terms of nu to omega_1 (and of gamma to omega_3)."""
    assert np.array_equal(euler231.G(np.zeros(3)), euler231.PAIRING)
    assert np.allclose(np.linalg.eigvals(euler231.PAIRING).real.round(12).tolist().count(-1.0), 1)


@pytest.mark.slow
def test_literal_pairing_diverges_aligned_pairing_converges():
    """Printed gains, h = 1 ms, observer on. Aligned reading (pairing = 1): every |sigma_i| < 0.01 deg
    by 3 s. Literal 001 (30) (pairing = 0): the nu - gamma mode runs away, the rates reach the
    plant's validity guard before 3 s (the run stops with that error), after |sigma| passed 90 deg."""
    _, ok = run("zhang2019_fontsm", stop=3.0)
    assert ok.complete
    assert _max_deg(ok, 2.9, 3.0) < 0.01
    _, bad = run("zhang2019_fontsm_literal", stop=3.0)
    assert not bad.complete and "omega_max" in bad.error, bad.error
    assert bad.time[-1] < 3.0
    assert _max_deg(bad, 0.0, bad.time[-1]) > 90.0
    s = bad.vector("plant.sigma")
    diff = np.abs(s[:, 0] - s[:, 2])
    k = np.searchsorted(bad.time, 0.5)
    assert diff[k] > 3 * diff[0]  # nu - gamma grew from 1.1 to > 3.3 rad in 0.5 s
    s_ok = ok.vector("plant.sigma")
    k1 = np.searchsorted(ok.time, 1.0)
    assert abs(s_ok[k1, 0] - s_ok[k1, 2]) < 0.25 * abs(s_ok[0, 0] - s_ok[0, 2])  # decays instead


@pytest.mark.parametrize("h", [0.001, 0.002])
def test_fo_start_removes_the_first_sample_kick(h):
    """Strict GL (fo_start = 0) differentiates the jump from the implicit zero past at t0: the
    first command is ~1e4 N.m at 1 ms and grows like 1/h; fo_start = 1 (default) gives < 200 N.m."""
    u = {}
    for start in (0, 1):
        c = blocks.controller()
        c.set_parameters({"fo_start": start, "fo_step": h})
        c.initialize(0.0)
        x = np.concatenate([SIGMA0, OMEGA0, np.ones(4), np.zeros(4), np.zeros(3)])
        u[start] = np.abs(c.outputs_at(0.0, x)[0:4]).max()
    assert u[1] < 200.0
    assert u[0] > 1e4 * (0.001 / h) ** 0.99


@pytest.mark.slow
def test_fault_tolerance_with_the_printed_gains():
    """Printed gains, sign(s), full memory, onset moved to 3 s: the attitude stays within 0.01 deg
    across the fault; the printed observer does not estimate the fault torque (RMS error = RMS of
    the fault torque within 1 %): with sign(s) the lost 40 % of wheel 2 is mostly chatter."""
    s, r = run("zhang2019_fontsm", stop=5.0, onset=3.0)
    assert r.complete
    m = metrics(r, dict(s.metrics, accuracy_window=[3.0, 5.0], estimate_window=[3.5, 5.0]))
    assert max(m["attitude_accuracy_deg"]) < 0.01
    assert max(m["rate_accuracy_deg_s"]) < 0.1  # chatter ~ eps_1 h / 2 = 0.043 deg/s
    assert m["stabilization_time_s"]["0.01"] < 3.0
    assert m["fault_torque_estimate_rms_error_ratio"] > 0.99
    assert m["bias_torque_estimate_rms_error_ratio"] > 0.95
    assert m["max_rate_norm_rad_s"] < 2.09  # Theorem 3.1 (Lipschitz reading) holds on the run


@pytest.mark.slow
def test_fault_estimation_with_our_gains_and_table_1_order_accuracy():
    """Boundary layer 0.01, 2 s memory, lambda_1 = lambda_2 = 2000, onset at 2.5 s: 3-4.5 s after
    the fault the torque-level estimate M((E_hat - I) u_c + uf_hat) has an RMS error below 25 % of
    the fault torque's RMS and the attitude is within 3e-5 deg, the rates within 1e-5 deg/s."""
    s, r = run("zhang2019_fontsm_fast_observer", stop=7.0, onset=2.5)
    assert r.complete
    m = metrics(r, dict(s.metrics, accuracy_window=[5.5, 7.0], estimate_window=[5.5, 7.0]))
    assert m["fault_torque_estimate_rms_error_ratio"] < 0.25, m["fault_torque_estimate_rms_error_ratio"]
    assert m["bias_torque_estimate_rms_error_ratio"] < 0.3
    assert max(m["attitude_accuracy_deg"]) < 3e-5
    assert max(m["rate_accuracy_deg_s"]) < 1e-5
    assert m["max_abs_u_c_window"] < 0.1  # no chatter in the command


def _loop(blocks3, t0, n, h, record=True):
    """plant -> observer (no feedthrough) -> controller -> plant, in-process, at step h."""
    p, o, c = blocks3
    out = []
    uc = np.zeros(4)
    for k in range(n):
        t = t0 + k * h
        yp = p.outputs_at(t, uc)
        yo = o.outputs_at(t, np.concatenate([yp[3:6], uc]))
        cin = np.concatenate([yp[0:6], yo[3:11], np.zeros(3)])
        uc = c.outputs_at(t, cin)[0:4].copy()
        oin = np.concatenate([yp[3:6], uc])
        if record:
            out.append(np.concatenate([yp[0:6], yo, c.outputs_at(t, cin)]))
        p.advance(t, h, uc)
        o.advance(t, h, oin)
        c.advance(t, h, cin)
    return out


@pytest.mark.parametrize("memory", [1000.0, 0.15])
def test_rollback_is_exact_including_the_fractional_history(memory):
    """Save every block's state at 0.4 s, run 0.3 s, restore, run again: identical bit for bit,
    with the full memory (history grows) and a 0.15 s memory (history compacted on the way)."""
    h = 0.001
    b = [blocks.plant(), blocks.observer(), blocks.controller()]
    b[2].set_parameters({"fo_memory": memory})
    for x in b:
        x.initialize(0.0)
    _loop(b, 0.0, 400, h, record=False)
    saved = [list(x.get_state()) for x in b]
    n_hist = int(saved[2][10])
    assert n_hist == (400 if memory > 1 else 150)
    assert len(saved[2]) == 11 + 6 * n_hist + 14  # + the sample interval in progress (none here)
    first = _loop(b, 0.4, 300, h)
    for x, s in zip(b, saved):
        x.set_state(s)
    second = _loop(b, 0.4, 300, h)
    assert all(np.array_equal(a, c) for a, c in zip(first, second))
    assert not np.array_equal(first[0], first[-1])
    # a different history really changes the output: the memory is part of the state
    tampered = list(saved[2])
    tampered[11] += 1e-3
    for x, s in zip(b, saved[:2] + [tampered]):
        x.set_state(s)
    third = _loop(b, 0.4, 5, h)
    assert not np.array_equal(third[0], first[0])


@pytest.mark.parametrize(
    "params, name",
    [
        ({"fo_memory": 0.0}, "fo_memory"),
        ({"fo_memory": -2.0}, "fo_memory"),
        ({"fo_memory": 0.0004}, "fo_memory"),
        ({"alpha_2[1]": 1.2}, "alpha_2"),
        ({"r": 1.0}, "r"),
        ({"J[1,1]": 0.0}, "J"),
        ({"M[2,2]": 0.0, "M[2,4]": 0.0, "M[1,1]": 0.0, "M[1,4]": 0.0}, "M"),
        ({"pairing": 0.5}, "pairing"),
        ({"boundary_layer": -0.1}, "boundary_layer"),
    ],
)
def test_bad_input_gives_one_clear_message(params, name):
    c = blocks.controller()
    c.set_parameters(params)
    with pytest.raises(ValueError, match=rf"^{name}: "):
        c.initialize(0.0)


def test_step_other_than_fo_step_is_refused_with_the_parameter_named():
    c = blocks.controller()
    c.initialize(0.0)
    x = np.concatenate([SIGMA0, OMEGA0, np.ones(4), np.zeros(4), np.zeros(3)])
    with pytest.raises(ValueError, match=r"fo_step = 0\.001 s but the communication step is 0\.002 s"):
        c.advance(0.0, 0.002, x)


def test_allocation_refuses_more_than_n_minus_3_dead_wheels():
    c = blocks.controller()
    c.initialize(0.0)
    x = np.concatenate([SIGMA0, OMEGA0, [0.0, 0.0, 1.0, 1.0], np.zeros(4), np.zeros(3)])
    with pytest.raises(FloatingPointError, match=r"allocation 001 \(33\) singular"):
        c.outputs_at(0.0, x)
    x[6:10] = [1.0, 0.0, 1.0, 1.0]  # one dead wheel: still fully actuated (Assumption 2.3)
    assert np.all(np.isfinite(c.outputs_at(0.0, x)))
    assert math.isclose(c.outputs_at(0.0, x)[1], 0.0, abs_tol=1e-12)  # the dead wheel gets nothing


@pytest.mark.parametrize("virtual_control", [1, 0])
def test_omega_d_dot_is_the_time_derivative_of_omega_d(virtual_control):
    """For c > 0, u_cm carries the omega_d' of 001 (29): analytic vs a central difference along
    sigma' = G(sigma) omega (sigma_d constant), for both readings of omega_d (28)-form and (27)."""
    c = blocks.controller()
    c.set_parameters({"c": 2.0, "virtual_control": virtual_control})
    c.initialize(0.0)
    sigma, omega = np.array([0.3, -0.4, 0.7]), np.array([0.2, -0.1, 0.3])
    wd, wd_dot = c._virtual(sigma, omega, euler231.PAIRING @ sigma)
    sd = np.array(euler231.rates(sigma, omega))
    eps = 1e-6
    plus = np.array(c._virtual(sigma + eps * sd, omega, euler231.PAIRING @ (sigma + eps * sd))[0])
    minus = np.array(c._virtual(sigma - eps * sd, omega, euler231.PAIRING @ (sigma - eps * sd))[0])
    assert np.allclose(wd_dot, (plus - minus) / (2 * eps), atol=1e-8)
    if virtual_control == 1:  # (28): G_c omega_d = -c z1, so z1' = -c z1 + G_c z2
        Gc = euler231.PAIRING @ euler231.G(sigma)
        assert np.allclose(Gc @ np.array(wd), -2.0 * (euler231.PAIRING @ sigma), atol=1e-12)
