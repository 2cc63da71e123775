"""001's observer (estimator/asmfeo.py, 001 (12), (14), (15)): the fast RK4 path against the
plain one, the linearised error system's time constants against simulation (why the printed
lambda_1, lambda_2 cannot estimate the faults within the run, and that our gain choice can),
the unobservable null space of M, Theorem 3.1's condition, bad input."""
import math

import numpy as np
import pytest
from scipy.linalg import expm

from papers.p001_zhang2019 import analysis, blocks
from papers.p001_zhang2019 import gains as G
from papers.p001_zhang2019.parameters import OMEGA0, ZHANG2019

J, M = ZHANG2019["J"], ZHANG2019["M"]
UF = np.array([0.04, 0.0, 0.0, 0.0])


def test_held_innovation_fast_path_equals_plain_rk4_of_the_equations():
    """sampling_mode 1 is written out for speed; it must be RK4 of 001 (12), (14), (15) (``_deriv``)
    with the innovation held, to rounding, including the K branch switching at mu."""
    o = blocks.observer()
    o.set_parameters({"h_max": 0.0005, "K_init": 1.2e-4, "lambda_1": 40.0, "lambda_2": 70.0, "lambda_3": 1000.0})
    o.initialize(0.0)
    rng = np.random.default_rng(2)
    ref = o.x.copy()
    K_seen = []
    for k in range(200):
        u = np.concatenate([ref[0:3] + 1e-5 * rng.normal(size=3), 0.3 * rng.normal(size=4)])  # small innovations
        wt = u[0:3] - ref[0:3]
        x = ref
        for _ in range(2):  # h = 1 ms in two internal steps
            dt = 0.0005
            k1 = o._deriv(x, wt, None, u[3:])
            k2 = o._deriv(x + 0.5 * dt * k1, wt, None, u[3:])
            k3 = o._deriv(x + 0.5 * dt * k2, wt, None, u[3:])
            k4 = o._deriv(x + dt * k3, wt, None, u[3:])
            x = x + dt / 6 * (k1 + 2 * (k2 + k3) + k4)
        ref = x
        o.advance(0.001 * k, 0.001, u)
        assert np.allclose(o.x, ref, rtol=1e-12, atol=1e-15), k
        K_seen.append(o.x[-1])
    assert min(K_seen) < G.MU < max(K_seen)  # both branches of (15) were used


def _bias_only_run(lambda_12, T, h):
    """Plant at rest with u_c = 0, no Delta J / T_d, bias 0.04 N.m on wheel 1 from t = 0; the
    observer sees the true omega. Returns times and M uf_hat (the torque-level estimate; with
    u_c = 0 the effectiveness part is zero), and uf_hat itself."""
    p, o = blocks.plant(), blocks.observer()
    zero = {f"{k}[{i}]": 0.0 for k in ("dJ_amp", "Td_amp", "omega_init", "sigma_init") for i in (1, 2, 3)}
    p.set_parameters(zero | {f"bias_onset[{j}]": 0.0 for j in range(1, 5)} | {"h_max": h})
    o.set_parameters({"lambda_1": lambda_12, "lambda_2": lambda_12, "h_max": h} | {f"omega_hat_init[{i}]": 0.0 for i in (1, 2, 3)})
    p.initialize(0.0)
    o.initialize(0.0)
    uc = np.zeros(4)
    ts, fh, ufh = [], [], []
    for k in range(int(round(T / h)) + 1):
        t = k * h
        yo = o.outputs_at(t, np.concatenate([p.x[3:6], uc]))
        ts.append(t)
        fh.append(yo[12:15])
        ufh.append(yo[7:11])
        if k * h < T:
            oin = np.concatenate([p.x[3:6], uc])
            p.advance(t, h, uc)
            o.advance(t, h, oin)
    return np.array(ts), np.array(fh), np.array(ufh)


def _linear_prediction(lambda_2, ts):
    A = analysis.error_system(G.LAMBDA, J, M, 0.0, lambda_2)
    keep = list(range(3)) + list(range(7, 11))
    A = A[np.ix_(keep, keep)]
    x0 = np.concatenate([np.zeros(3), UF])
    lam, V = np.linalg.eig(A)  # diagonalisable (the zero mode is the null space of M)
    c = np.linalg.solve(V, x0)
    return np.array([M @ (UF - (V @ (np.exp(lam * t) * c)).real[3:]) for t in ts])


def test_printed_gains_cannot_estimate_the_bias_in_the_run_time_as_the_linear_model_says():
    """Slow modes of the bias-error system with lambda_2 = 0.6: time constants 1.2e3, 4.8e3, 6.8e3 s
    (singular values of J^-1 M squared times lambda_2 / Lambda). The simulated torque-level
    estimate follows that linear model (within 10 %) and reaches < 2 % of the 0.04 N.m bias
    after 40 s: Fig. 5's 'accurate estimation' is out of reach within 001's run."""
    modes = analysis.bias_modes(G.LAMBDA, J, M, G.LAMBDA_2)
    tc = np.sort(modes["slowest_time_constants_s"])
    assert np.allclose(tc, [1159.3, 4775.8, 6824.3], rtol=1e-3)
    assert modes["zero_modes"] == 1  # null(M): the bias direction [1, 1, 1, -sqrt 3] is never seen
    ts, fh, _ = _bias_only_run(G.LAMBDA_2, 40.0, 0.02)
    pred = _linear_prediction(G.LAMBDA_2, ts)
    A = analysis.error_system(G.LAMBDA, J, M, 0.0, G.LAMBDA_2)[np.ix_([0, 1, 2, 7, 8, 9, 10], [0, 1, 2, 7, 8, 9, 10])]
    assert np.allclose(pred[-1], M @ (UF - (expm(A * 40.0) @ np.concatenate([np.zeros(3), UF]))[3:]), atol=1e-12)
    k = np.searchsorted(ts, [10.0, 20.0, 40.0])
    assert np.all(np.abs(fh[k, 0] - pred[k, 0]) <= 0.1 * np.abs(pred[k, 0]))
    assert 0.0 < fh[-1, 0] < 0.02 * UF[0]


def test_our_gain_choice_estimates_the_bias_within_seconds_as_the_linear_model_says():
    """lambda_1 = lambda_2 = 2000: slowest time constant 1.8 s. The simulated estimate follows the
    linear model (within 0.002 N.m, 5 % of the bias) and is within 2 % of M u_f after 10 s."""
    lam = G.FAST_OBSERVER["lambda_2"]
    modes = analysis.bias_modes(G.LAMBDA, J, M, lam)
    assert modes["slowest_time_constants_s"].max() < 2.0
    ts, fh, ufh = _bias_only_run(lam, 10.0, 0.01)
    pred = _linear_prediction(lam, ts)
    assert np.abs(fh - pred).max() < 0.002
    assert np.linalg.norm(fh[-1] - M @ UF) < 0.02 * UF[0]
    # uf_hat moves only in range(M^T): its null(M) component stays at its start value 0, so the
    # per-wheel estimate tends to the minimum-norm equivalent, not to [0.04, 0, 0, 0]
    nul = analysis.null_space(M)[:, 0]
    assert np.abs(ufh @ nul).max() < 1e-15
    min_norm = M.T @ np.linalg.solve(M @ M.T, M @ UF)
    assert np.allclose(min_norm, [0.03333, -0.00667, -0.00667, 0.01155], atol=1e-5)
    assert np.linalg.norm(ufh[-1] - min_norm) < 0.1 * np.linalg.norm(min_norm)


def test_theorem_3_1_condition_with_both_readings_of_epsilon():
    """lambda_min(Lambda) - eps ||J^-1|| >= 0. Lipschitz reading: eps = 28.28 ||omega||max, so the
    condition holds for ||omega|| <= 2.10 rad/s (||omega(0)|| = 1.153: margin 2.25 1/s). Literal
    reading (epsilon of (15) = 1e-4 rad/s): margin 5.0 1/s, holds for epsilon <= 59.4."""
    r = analysis.theorem31(G.LAMBDA, J, float(np.linalg.norm(OMEGA0)), G.EPSILON)
    assert math.isclose(r["norm_J_inv"], 0.084221, rel_tol=1e-4)
    assert math.isclose(r["gyro_jacobian_gain"], 28.2834, rel_tol=1e-4)
    assert math.isclose(r["margin_lipschitz"], 2.2528, rel_tol=1e-3)
    assert math.isclose(r["omega_radius_max"], 2.0990, rel_tol=1e-3)
    assert r["margin_literal"] > 4.99 and math.isclose(r["epsilon_boundary_max"], 59.3676, rel_tol=1e-4)
    # the Jacobian gain is a true maximum: no direction on the sphere exceeds it
    rng = np.random.default_rng(4)
    for v in rng.normal(size=(500, 3)):
        v /= np.linalg.norm(v)
        S = lambda x: np.array([[0, -x[2], x[1]], [x[2], 0, -x[0]], [-x[1], x[0], 0]])  # noqa: E731
        assert np.linalg.norm(S(v) @ J - S(J @ v), 2) <= r["gyro_jacobian_gain"] * (1 + 1e-9)


@pytest.mark.parametrize(
    "params, name",
    [
        ({"Lambda[2]": 0.0}, "Lambda"),
        ({"lambda_2": -1.0}, "lambda_2"),
        ({"mu": 0.0}, "mu"),
        ({"J[3,3]": -1.0}, "J"),
        ({"M[1,1]": 0.0, "M[1,4]": 0.0}, "M"),
        ({"sampling_mode": 2.0}, "sampling_mode"),
    ],
)
def test_bad_input_gives_one_clear_message(params, name):
    o = blocks.observer()
    o.set_parameters(params)
    with pytest.raises(ValueError, match=rf"^{name}: "):
        o.initialize(0.0)
