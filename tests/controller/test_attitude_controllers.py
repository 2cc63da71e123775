"""FASMC 000 (39)-(40), (64) and the AISMC baseline 000 (70)-(71): gains, laws, closed loop."""
import math

import numpy as np
import pytest
from inprocess_loop import cached_run, run_loop

from controller.attitude import skew
from papers.p000_li2023 import blocks as li2023
from papers.p000_li2023 import gains as G
from papers.p000_li2023.parameters import LI2023, OMEGA_BOX
from plant.flexible import modal_matrices
from plant.ts_fuzzy import fuzzy_model, memberships

FM = fuzzy_model(LI2023["J"], LI2023["delta"], LI2023["omega_n"], LI2023["zeta"], OMEGA_BOX)
JM = LI2023["J"] - LI2023["delta"].T @ LI2023["delta"]


def test_gain_transcription():
    assert G.K_C.shape == (8, 3, 3)
    assert G.K_C[0, 0, 0] == -34.7440 and G.K_C[4, 1, 0] == -0.0102 and G.K_C[7, 2, 0] == 2.2599
    assert G.K_C[5, 2, 1] == -2.0212 and G.K_C[2, 2, 2] == -19.9350
    assert (G.GAMMA_2, G.MU, G.PHI_2, G.EPS_2, G.BETA) == (1.7919, 0.1, 20.0, 20.0, 2.0)
    assert G.VARSIGMA == 5 * math.sqrt(3) and (G.SIGMA_1, G.SIGMA_2, G.SIGMA_2_PRIME) == (0.2, 0.15, 1e-4)
    assert (G.AISMC_BETA, G.AISMC_SIGMA, G.AISMC_SIGMA_PRIME) == (2.0, 0.002, 0.01)


def test_virtual_control_gains_meet_theorem_2_region():
    """A_i + B Gamma K_c^i Hurwitz with eigenvalues in the disc O(-20, 20) (printed (20, 20))."""
    for i in range(8):
        ev = np.linalg.eigvals(FM.A[i] + FM.B @ G.K_C[i])
        assert np.all(ev.real < -0.1) and np.all(np.abs(ev + 20.0) < 20.0), (i, ev)


def _inputs(ctrl, q, omega, q_d, f_hat=np.zeros(3), d2_hat=np.zeros(8)):
    u = ctrl.default_inputs()
    ix = ctrl.input_index
    u[ix["q[0]"] : ix["q[0]"] + 4] = q
    u[ix["omega[1]"] : ix["omega[1]"] + 3] = omega
    u[ix["q_d[0]"] : ix["q_d[0]"] + 4] = q_d
    u[ix["f_hat[1]"] : ix["f_hat[1]"] + 3] = f_hat
    u[ix["d2_hat[1]"] : ix["d2_hat[1]"] + 8] = d2_hat
    return u


def _hand_terms(q, omega, q_d, beta):
    """q_ev, omega_e, s, g(s) from 000 (4), (5), (36) written out again (omega_d = 0)."""
    q0, qv, qd0, qdv = q[0], q[1:], q_d[0], q_d[1:]
    qe0 = qdv @ qv + qd0 * q0
    qev = qd0 * qv - np.cross(qdv, qv) - qdv * q0
    omega_e = omega.copy()
    s = omega_e + beta * qev
    B = np.linalg.inv(JM)
    g = 0.5 * beta * (qe0 * np.eye(3) + skew(qev)) @ omega_e + B @ skew(omega) @ LI2023["J"] @ (beta * qev)
    return qe0, qev, omega_e, s, g


def test_fasmc_law_against_hand_computation():
    rng = np.random.default_rng(5)
    c = li2023.fasmc()
    c.set_parameter("u_max", 1e6)  # look at the law itself
    c.initialize(0.0)
    C, K = modal_matrices(LI2023["omega_n"], LI2023["zeta"])
    for small in (True, False):
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        q_d = q + (0.002 if small else 0.3) * rng.normal(size=4)
        q_d /= np.linalg.norm(q_d)
        omega = rng.normal(0, 0.001 if small else 0.2, 3)
        f_hat, d2_hat = rng.normal(0, 0.5, 3), rng.normal(0, 0.01, 8)
        out = c.outputs_at(0.0, _inputs(c, q, omega, q_d, f_hat, d2_hat))
        qe0, qev, omega_e, s, g = _hand_terms(q, omega, q_d, G.BETA)
        b = memberships(omega, OMEGA_BOX)
        v = sum(b[j] * G.K_C[j] @ s for j in range(8))
        if not small:
            assert np.linalg.norm(v) > G.VARSIGMA  # the saturation is exercised
            v = v * G.VARSIGMA / np.linalg.norm(v)
        else:
            assert np.linalg.norm(v) < G.VARSIGMA
        D2 = sum(b[i] * FM.D2[i] for i in range(8))
        u = v - f_hat - JM @ D2 @ d2_hat - JM @ g - G.SIGMA_1 * s - G.SIGMA_2 * s / (np.linalg.norm(s) + G.SIGMA_2_PRIME)
        np.testing.assert_allclose(out[0:3], u, rtol=1e-9, atol=1e-12)
        np.testing.assert_allclose(out[3:7], np.r_[qe0, qev], atol=1e-15)


def test_command_saturation_and_feedthrough():
    c = li2023.fasmc()
    c.initialize(0.0)
    q = np.array([1.0, 0, 0, 0])
    out = c.outputs_at(0.0, _inputs(c, q, np.array([0.5, -0.5, 0.3]), np.array([0.0, 1.0, 0, 0])))
    assert np.all(np.abs(out[0:3]) <= 5.0) and np.abs(out[0:3]).max() == 5.0
    assert "f_hat[1]" in c.feedthrough["u[1]"] and "d2_hat[8]" in c.feedthrough["u[3]"]
    a = li2023.aismc()
    assert "f_hat[1]" not in a.feedthrough["u[1]"] and "omega_d_dot[1]" in a.feedthrough["u[1]"]
    assert [v.name for v in a.outputs] == [v.name for v in li2023.pd_controller().outputs] == [v.name for v in c.outputs]


def test_aismc_law_and_integral():
    rng = np.random.default_rng(6)
    a = li2023.aismc()
    a.initialize(0.0)
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    q_d = q + 0.01 * rng.normal(size=4)
    q_d /= np.linalg.norm(q_d)
    omega = rng.normal(0, 0.01, 3)
    inp = _inputs(a, q, omega, q_d)
    qe0, qev, omega_e, s, g = _hand_terms(q, omega, q_d, G.AISMC_BETA)
    b = memberships(omega, OMEGA_BOX)
    integral = np.zeros(3)
    for k in range(3):
        out = a.outputs_at(0.1 * k, inp)
        S = s - integral  # 000 (71)
        gain = sum(b[i] * np.linalg.norm(G.K_C[i] @ s) for i in range(8)) + G.AISMC_SIGMA + np.linalg.norm(S)
        u = -gain * s / (np.linalg.norm(s) + G.AISMC_SIGMA_PRIME) - JM @ g  # 000 (70)
        np.testing.assert_allclose(out[0:3], np.clip(u, -5, 5), rtol=1e-9, atol=1e-12)
        a.advance(0.1 * k, 0.1, inp)
        integral = integral + 0.1 * sum(b[i] * (FM.A[i] + FM.B @ G.K_C[i]) for i in range(8)) @ s
        np.testing.assert_allclose(a.get_state(), integral, rtol=1e-10, atol=1e-15)


def test_controller_rollback_is_bit_exact():
    blocks = []
    run_loop("aismc", h=0.01, t_end=5.0, blocks=blocks)
    a = blocks[2]
    s0 = a.get_state()
    rng = np.random.default_rng(1)
    inp = [_inputs(a, np.r_[1.0, 0, 0, 0], rng.normal(0, 0.01, 3), np.r_[0.9, 0.1, 0.2, math.sqrt(1 - 0.86)]) for _ in range(10)]

    def run10():
        out = []
        for k, x in enumerate(inp):
            a.advance(5.0 + 0.01 * k, 0.01, x)
            out.append(a.outputs_at(5.0 + 0.01 * (k + 1), x))
        return np.array(out)

    r1 = run10()
    a.set_state(s0)
    assert np.array_equal(run10(), r1)


# -- closed loop, 000 section 5 ------------------------------------------------------------------------------
def test_fasmc_tracking_at_200_s():
    run = cached_run("fasmc", h=0.01)
    assert np.linalg.norm(run.sig["q_e"][-1, 1:]) < 1e-3
    assert np.linalg.norm(run.sig["omega_e"][-1]) < 1e-4
    assert run.u_abs_max <= 5.0
    assert run.u_abs_max == 5.0  # the 80 s manoeuvre does saturate the actuators


@pytest.mark.parametrize("h", [0.01])
def test_fasmc_uses_less_energy_than_aismc(h):
    fasmc, aismc = cached_run("fasmc", h=h), cached_run("aismc", h=h)
    assert fasmc.energy < aismc.energy
    assert aismc.u_abs_max <= 5.0
    # FASMC also tracks better than the baseline at the end (000 Figures 10-11)
    assert np.linalg.norm(fasmc.sig["q_e"][-1, 1:]) < np.linalg.norm(aismc.sig["q_e"][-1, 1:])


def test_weak_faults_tracking():
    run = cached_run("fasmc", h=0.01, fault_scale=0.2)
    assert np.linalg.norm(run.sig["q_e"][-1, 1:]) < 1e-3
    assert np.linalg.norm(run.sig["omega_e"][-1]) < 1e-4


def test_fast_sliding_terms_equal_the_reference_functions():
    from controller.attitude import g_term, quaternion_error, rate_error, sliding_terms

    rng = np.random.default_rng(9)
    B = np.linalg.inv(JM)
    for _ in range(50):
        q, q_d = rng.normal(size=4), rng.normal(size=4)
        q, q_d = q / np.linalg.norm(q), q_d / np.linalg.norm(q_d)
        w, wd, wdd = rng.normal(0, 0.1, 3), rng.normal(0, 0.1, 3), rng.normal(0, 0.01, 3)
        qe0, qev = quaternion_error(q, q_d)
        we, th = rate_error(qe0, qev, w, wd)
        g = g_term(2.0, qe0, qev, w, we, wd, wdd, th, B, LI2023["J"])
        r = sliding_terms(q, w, q_d, wd, wdd, 2.0, B, LI2023["J"])
        np.testing.assert_allclose(r[0], qe0, atol=1e-15)
        np.testing.assert_allclose(r[1], qev, atol=1e-15)
        np.testing.assert_allclose(r[2], we, atol=1e-15)
        np.testing.assert_allclose(r[3], we + 2.0 * qev, atol=1e-15)
        np.testing.assert_allclose(r[4], g, rtol=1e-12, atol=1e-15)
