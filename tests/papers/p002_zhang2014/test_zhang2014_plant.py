"""The pitch-axis plant block (plant/pitch_axis.py: PitchAxisSpacecraft) against physics and an
independent integrator, with the 002 and 003 parameter sets.

* u = 0, zero damping: the energy of 002 (1) is conserved to 1e-9 relative over 100 s;
* open loop with a piecewise-constant command, the 003 effectiveness switch and an external torque:
  every output agrees with scipy's solve_ivp (DOP853, rtol 1e-12) to 1e-8 relative;
* rigid-body reduction: with no coupling (F = 0) the plant is the double integrator of 002 (8) with
  w = 0 (closed form), and with coupling its outputs obey 002 (2) / (8):
  (J - F F^T) theta'' = omega u + w, w = d_vib (theta'' by central differences of theta');
* bad input: effectiveness outside [0, 1], non-positive inertia, a mode count inconsistent with the
  coupling vector: one ValueError each, naming the parameter.
"""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from papers.p002_zhang2014 import blocks as b2
from papers.p002_zhang2014.parameters import ZHANG2014
from papers.p003_hang2023 import blocks as b3
from plant.pitch_axis import PitchAxisSpacecraft, flexible_model, rigid_model


def _outputs(p, t, u=0.0):
    return p.outputs_at(t, np.array([u]))


def test_energy_conserved_without_damping_and_input():
    p = b2.plant()
    p.set_parameters({"zeta[1]": 0.0, "zeta[2]": 0.0, "eta_init[1]": 0.01, "eta_dot_init[2]": -0.03})
    p.initialize(0.0)
    E0 = p.energy()
    h = 0.01
    E, rate = [], []
    for k in range(10000):  # 100 s
        p.advance(k * h, h, np.zeros(1))
        E.append(p.energy())
        rate.append(p.z[1])
    drift = np.abs(np.array(E) / E0 - 1.0).max()
    assert drift < 1e-9, drift
    # the test has teeth: hub and modes exchange energy (theta_dot varies by more than 1 %)
    assert np.ptp(rate) > 0.01 * 0.04


def test_open_loop_matches_solve_ivp():
    p = b3.plant()  # 003: J = 6.14, effectiveness 1 -> 0.4 at the onset, external torque
    p.set_parameters({"effectiveness_onset": 2.0, "dist_amplitude": 0.05, "eta_init[1]": 0.002})
    p.initialize(0.0)
    J, F, w, xi = 6.14, np.array([1.27806, 0.91758]), np.array([3.17, 7.38]), np.array([0.001, 0.0016])
    A, B, _ = flexible_model(J, F, w, xi)
    dist = lambda t: 0.05 * (3.0 * np.cos(0.0011 * t) + 1.5 * np.sin(0.0011 * t))  # noqa: E731
    h, n = 0.01, 500
    z = p.z.copy()
    rows_block, rows_ref = [], []
    for k in range(n):
        t = k * h
        u = 0.3 * np.sin(0.7 * t) + 0.1
        rho = 1.0 if t < 2.0 - 1e-12 else 0.4
        sol = solve_ivp(lambda s, y, rho=rho, u=u: A @ y + B[:, 0] * (rho * u + dist(s)), (t, t + h), z, method="DOP853",
                        rtol=1e-12, atol=1e-14)
        z = sol.y[:, -1]
        p.advance(t, h, np.array([u]))
        rows_block.append(p.z.copy())
        rows_ref.append(z.copy())
    a, b = np.array(rows_block), np.array(rows_ref)
    rel = np.abs(a - b).max(axis=0) / np.abs(b).max(axis=0)
    assert rel.max() < 1e-8, rel
    # outputs at a point: the applied torque is the switched effectiveness times u, d_vib = Cw z
    y = _outputs(p, n * h, 0.5)
    assert y[p.output_index["tau_applied"]] == pytest.approx(0.2)
    assert y[p.output_index["effectiveness_now"]] == 0.4
    assert y[p.output_index["u_d"]] == pytest.approx(dist(n * h), rel=1e-14)


def test_effectiveness_switch_acts_exactly_at_the_onset():
    p = b3.plant()  # 003: rho = 1 before 20 s, 0.4 from 20 s
    p.initialize(0.0)
    assert _outputs(p, 20.0 - 1e-6, 1.0)[p.output_index["tau_applied"]] == 1.0
    assert _outputs(p, 20.0, 1.0)[p.output_index["tau_applied"]] == pytest.approx(0.4)
    assert _outputs(p, 20.0 + 3e-15, 1.0)[p.output_index["tau_applied"]] == pytest.approx(0.4)  # host rounding


def test_rigid_reduction_is_002_eq8():
    Je = ZHANG2014["J"] - ZHANG2014["F"] @ ZHANG2014["F"]
    A, B, C = rigid_model(ZHANG2014["J"], ZHANG2014["F"])
    assert B[1, 0] == pytest.approx(1.0 / Je) and np.array_equal(A, [[0, 1], [0, 0]]) and np.array_equal(C, np.eye(2))
    # no coupling: the plant is 002 (8) with w = 0, theta = theta0 + theta'0 t + omega u t^2 / (2 J_e)
    p = b2.plant()
    p.set_parameters({"J": Je, "F[1]": 0.0, "F[2]": 0.0, "effectiveness": 0.5})
    p.initialize(0.0)
    h, u = 0.01, -1.3
    for k in range(1000):
        p.advance(k * h, h, np.array([u]))
    t = 10.0
    assert p.z[0] == pytest.approx(0.08 + 0.04 * t + 0.5 * 0.5 * u / Je * t * t, rel=1e-12)
    assert p.z[1] == pytest.approx(0.04 + 0.5 * u / Je * t, rel=1e-12)
    assert _outputs(p, t)[p.output_index["d_vib"]] == 0.0
    # with coupling: (J - F F^T) theta'' = omega u + w along the run (002 (2)), w = d_vib
    p = b2.plant()
    p.set_parameters({"effectiveness": 0.5, "eta_init[2]": 0.01})
    p.initialize(0.0)
    h = 1e-3
    th_dot, w = [], []
    for k in range(3001):
        y = _outputs(p, k * h, u)
        th_dot.append(y[1])
        w.append(y[p.output_index["d_vib"]])
        p.advance(k * h, h, np.array([u]))
    th_dot, w = np.array(th_dot), np.array(w)
    acc = (th_dot[2:] - th_dot[:-2]) / (2 * h)
    lhs, rhs = Je * acc, 0.5 * u + w[1:-1]
    assert np.abs(lhs - rhs).max() < 1e-5 * np.abs(rhs).max()
    assert np.abs(w).max() > 0.05 * abs(0.5 * u)  # the vibration torque is not negligible here


def test_no_modes_is_a_rigid_body():
    p = PitchAxisSpacecraft(n_modes=0)
    p.set_defaults({"J": 2.0, "theta_dot_init": 0.1})
    p.initialize(0.0)
    p.advance(0.0, 1.0, np.array([0.4]))
    assert p.z[0] == pytest.approx(0.1 + 0.5 * 0.2) and p.z[1] == pytest.approx(0.3)


@pytest.mark.parametrize("name, value, match", [
    ("effectiveness", 1.2, r"effectiveness must be in \[0, 1\], got 1.2"),
    ("effectiveness", -0.1, r"effectiveness must be in \[0, 1\], got -0.1"),
    ("effectiveness_before", 2.0, r"effectiveness_before must be in \[0, 1\]"),
    ("J", 0.0, r"J \(pitch inertia\) must be > 0 kg.m2, got 0"),
    ("J", -35.72, r"J \(pitch inertia\) must be > 0 kg.m2, got -35.72"),
    ("J", 2.0, r"J - F F\^T = -0\.4755\d* kg.m2 must be > 0"),
    ("omega_n[2]", 0.0, r"omega_n must be > 0 rad/s"),
    ("h_max", 0.0, r"h_max must be > 0 s"),
])
def test_bad_plant_parameters(name, value, match):
    p = b2.plant()
    p.set_parameter(name, value)
    with pytest.raises(ValueError, match=match):
        p.initialize(0.0)


def test_mode_count_inconsistent_with_coupling():
    p = PitchAxisSpacecraft(n_modes=2)
    with pytest.raises(ValueError, match=r"'F' has 3 entries but the plant has n_modes = 2"):
        p.set_defaults({"F": [1.0, 2.0, 3.0]})
    with pytest.raises(ValueError, match=r"'omega_n' has 1 entries but the plant has n_modes = 2"):
        p.set_defaults({"omega_n": [3.0]})
