"""001's plant (plant/rigid_wheels.py with papers/p001_zhang2019 defaults): kinematics against an
independent quaternion integration, momentum conservation, open loop against solve_ivp of
001 (3), the actuator path 001 (5) per wheel, saturation, the singularity guard, bad input."""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from papers.p001_zhang2019 import blocks
from papers.p001_zhang2019.parameters import ZHANG2019
from plant import euler231

J, M = ZHANG2019["J"], ZHANG2019["M"]
# Delta J = 0, T_d = 0 and no wheel bias (with u = 0 the loss of effectiveness acts on nothing)
NO_DIST = {f"{k}[{i}]": 0.0 for k in ("dJ_amp", "Td_amp") for i in (1, 2, 3)}
QUIET = NO_DIST | {"bias[1]": 0.0}


def _plant(**params):
    p = blocks.plant()
    p.set_parameters(params)
    p.initialize(0.0)
    return p


def _quat_rhs(Jm):
    """Euler's equation for a rigid body and q' = 1/2 Omega(omega) q, written independently."""
    Ji = np.linalg.inv(Jm)

    def rhs(t, x):
        w, q = x[:3], x[3:]
        wd = Ji @ (-np.cross(w, Jm @ w))
        w1, w2, w3 = w
        Om = 0.5 * np.array([[0, -w1, -w2, -w3], [w1, 0, w3, -w2], [w2, -w3, 0, w1], [w3, w2, -w1, 0]])
        return np.concatenate([wd, Om @ q])

    return rhs


def _quat_dcm(q):
    q0, q1, q2, q3 = q / np.linalg.norm(q)
    return np.array(
        [
            [q0**2 + q1**2 - q2**2 - q3**2, 2 * (q1 * q2 + q0 * q3), 2 * (q1 * q3 - q0 * q2)],
            [2 * (q1 * q2 - q0 * q3), q0**2 - q1**2 + q2**2 - q3**2, 2 * (q2 * q3 + q0 * q1)],
            [2 * (q1 * q3 + q0 * q2), 2 * (q2 * q3 - q0 * q1), q0**2 - q1**2 - q2**2 + q3**2],
        ]
    )


def _quat_from_dcm(C):
    """Shepperd's method: the largest of the four squared components first."""
    t = np.trace(C)
    d = [t, C[0, 0], C[1, 1], C[2, 2]]
    i = int(np.argmax(d))
    if i == 0:
        q0 = 0.5 * math.sqrt(1 + t)
        q = [q0, (C[1, 2] - C[2, 1]) / (4 * q0), (C[2, 0] - C[0, 2]) / (4 * q0), (C[0, 1] - C[1, 0]) / (4 * q0)]
    elif i == 1:
        q1 = 0.5 * math.sqrt(1 + 2 * C[0, 0] - t)
        q = [(C[1, 2] - C[2, 1]) / (4 * q1), q1, (C[0, 1] + C[1, 0]) / (4 * q1), (C[0, 2] + C[2, 0]) / (4 * q1)]
    elif i == 2:
        q2 = 0.5 * math.sqrt(1 + 2 * C[1, 1] - t)
        q = [(C[2, 0] - C[0, 2]) / (4 * q2), (C[0, 1] + C[1, 0]) / (4 * q2), q2, (C[1, 2] + C[2, 1]) / (4 * q2)]
    else:
        q3 = 0.5 * math.sqrt(1 + 2 * C[2, 2] - t)
        q = [(C[0, 1] - C[1, 0]) / (4 * q3), (C[0, 2] + C[2, 0]) / (4 * q3), (C[1, 2] + C[2, 1]) / (4 * q3), q3]
    return np.array(q)


def test_torque_free_motion_matches_quaternion_integration_over_60_s():
    """The plant's Euler angles vs a DOP853 integration of Euler's equation and the quaternion,
    converted to the same 2-3-1 angles: 1e-9 rad over 60 s (plant RK4 at 4 ms). A nutating spin about the major axis v
    of J with v along inertial y (so nu stays near asin(v_1) = -38.6 deg, away from the singularity,
    while psi turns through 3.5 revolutions)."""
    lam, V = np.linalg.eigh(J)
    v = V[:, 2]
    a = np.cross(v, [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    C = np.column_stack([np.cross(v, a), v, a])  # body components of the inertial axes
    assert math.isclose(np.linalg.det(C), 1.0)
    sigma0 = euler231.from_dcm(C).tolist()
    omega0 = (0.4 * v + np.array([0.03, -0.02, 0.04])).tolist()
    p = _plant(**QUIET, h_max=0.004, **{f"omega_init[{i + 1}]": w for i, w in enumerate(omega0)},
               **{f"sigma_init[{i + 1}]": s for i, s in enumerate(sigma0)})
    q0 = _quat_from_dcm(euler231.dcm(sigma0))
    assert np.allclose(_quat_dcm(q0), euler231.dcm(sigma0), atol=1e-14)
    ts = np.arange(0.0, 60.0 + 1e-9, 0.5)
    ref = solve_ivp(_quat_rhs(J), (0, 60), np.concatenate([omega0, q0]), method="DOP853", rtol=1e-13, atol=1e-14, t_eval=ts)
    u = np.zeros(4)
    worst, nu_max = 0.0, 0.0
    for k in range(1, len(ts)):
        p.advance(ts[k - 1], 0.5, u)
        s_ref = euler231.from_dcm(_quat_dcm(ref.y[3:, k]))
        d = np.array(p.x[0:3]) - s_ref
        d[1:] = (d[1:] + math.pi) % (2 * math.pi) - math.pi
        worst = max(worst, float(np.abs(d).max()))
        nu_max = max(nu_max, abs(p.x[0]))
    assert nu_max < math.radians(50)
    assert np.ptp(ref.y[3:], axis=1).min() > 0.5  # a real motion
    assert worst < 1e-9, worst


def test_angular_momentum_conserved_without_torque():
    """Delta J = 0, T_d = 0, u = 0: C(sigma)^T J omega constant to 1e-9 relative (001's tumble)."""
    p = _plant(**QUIET, h_max=0.001)
    h0 = p.angular_momentum_inertial()
    worst = 0.0
    nus = []
    for k in range(200):  # 20 s, through large angles; 0.1 s communication steps
        try:
            p.advance(0.1 * k, 0.1, np.zeros(4))
        except FloatingPointError:
            pytest.fail("torque-free tumble from sigma(0), omega(0) of 001 reached the singularity guard")
        nus.append(p.x[0])
        worst = max(worst, np.linalg.norm(p.angular_momentum_inertial() - h0) / np.linalg.norm(h0))
    assert worst < 1e-9, worst
    assert np.ptp(nus) > 0.5  # the attitude really moved


def _reference_rhs(torque):
    """001 (3) solved for omega' with numpy (independently of the block), kinematics (1)."""

    def rhs(t, x):
        s, w = x[:3], x[3:]
        dJ = np.diag([math.sin(0.1 * t), 2 * math.sin(0.2 * t), math.sin(0.3 * t)])
        Td = 0.001 * np.array([1.0, 3.0, 5.0]) * math.sin(t)
        Jt = J + dJ
        wd = np.linalg.solve(Jt, -np.cross(w, Jt @ w) + torque(t) + Td)
        nu, gamma = s[0], s[2]
        sd = [w[1] * math.sin(gamma) + w[2] * math.cos(gamma),
              (w[1] * math.cos(gamma) - w[2] * math.sin(gamma)) / math.cos(nu),
              w[0] - math.tan(nu) * (w[1] * math.cos(gamma) - w[2] * math.sin(gamma))]
        return np.concatenate([sd, wd])

    return rhs


def test_open_loop_with_uncertainty_disturbance_and_faults_matches_solve_ivp():
    """Held wheel commands, Delta J(t), T_d(t) and the 001 faults (onsets moved to 1.0 s, on the
    grid): block RK4 at 1 ms vs DOP853 of 001 (3), piecewise over the steps, 1e-6 over 2 s."""
    onset = {f"{k}_onset[{j}]": 1.0 for k in ("effectiveness", "bias") for j in range(1, 5)}
    p = _plant(**onset, **{"omega_init[1]": 0.05, "omega_init[2]": -0.03, "omega_init[3]": 0.02,
                           "sigma_init[1]": 0.2, "sigma_init[2]": -0.1, "sigma_init[3]": 0.3})
    h = 0.01
    x = np.array(p.x)
    e = np.array([1.0, 0.6, 1.0, 1.0])
    uf = np.array([0.04, 0.0, 0.0, 0.0])
    worst = 0.0
    for k in range(200):
        t = k * h
        uc = np.array([0.3 * math.sin(t), -0.2, 0.1 * math.cos(2 * t), 0.15])
        wheel = (e * uc + uf) if t >= 1.0 - 1e-12 else uc
        sol = solve_ivp(_reference_rhs(lambda _t, tau=M @ wheel: tau), (t, t + h), x, method="DOP853", rtol=1e-12, atol=1e-13)
        x = sol.y[:, -1]
        p.advance(t, h, uc)
        worst = max(worst, float(np.abs(np.array(p.x) - x).max()))
    assert worst < 1e-6, worst
    assert np.abs(x[3:]).max() > 0.03  # the torques did something


def test_actuator_path_per_wheel_with_onsets_on_the_grid():
    """001 (5) per wheel: E u_c + u_f from the onset (inclusive at the communication point),
    equivalent fault torque M((E - I) u_c + u_f), tau = M u_wheel; onsets as time functions."""
    p = _plant()
    uc = np.array([0.1, -0.2, 0.3, 0.05])
    out = lambda t: dict(zip([v.name for v in p.outputs], p.outputs_at(t, uc)))  # noqa: E731
    before, at = out(19.999), out(20.0 - 1e-12)
    for d in (before,):
        assert [d[f"e[{j}]"] for j in range(1, 5)] == [1.0] * 4 and d["u_f[1]"] == 0.0
        assert np.allclose([d[f"fault_torque[{i}]"] for i in (1, 2, 3)], 0.0)
    e = np.array([1, 0.6, 1, 1])
    uf = np.array([0.04, 0, 0, 0])
    assert [at[f"e[{j}]"] for j in range(1, 5)] == e.tolist()  # 20 s - 1e-12 counts as 20 s (timing.py)
    wheel = np.array([at[f"u_wheel[{j}]"] for j in range(1, 5)])
    assert np.allclose(wheel, e * uc + uf, atol=1e-15)
    assert np.allclose([at[f"tau_applied[{i}]"] for i in (1, 2, 3)], M @ wheel, atol=1e-15)
    assert np.allclose([at[f"fault_torque[{i}]"] for i in (1, 2, 3)], M @ ((e - 1) * uc + uf), atol=1e-15)


def test_onset_inside_a_step_acts_at_the_stage():
    """An onset strictly inside a communication step switches at the RK4 stage times: the result
    lies between 'fault from the start' and 'no fault in this step'."""
    on = {f"bias_onset[{j}]": 0.05 for j in range(1, 5)}
    mid = _plant(**NO_DIST, **on)
    mid.advance(0.0, 0.1, np.zeros(4))
    early = _plant(**NO_DIST, **{f"bias_onset[{j}]": 0.0 for j in range(1, 5)})
    early.advance(0.0, 0.1, np.zeros(4))
    late = _plant(**NO_DIST, **{f"bias_onset[{j}]": 1.0 for j in range(1, 5)})
    late.advance(0.0, 0.1, np.zeros(4))
    dw = lambda p: p.x[3] - late.x[3]  # noqa: E731
    assert 0.3 < dw(mid) / dw(early) < 0.7


def test_saturation_per_wheel_is_off_by_default_and_clips_when_set():
    uc = np.array([5.0, -0.1, -7.0, 0.2])
    p = _plant()
    assert p.outputs_at(0.0, uc)[6:10].tolist() == uc.tolist()
    q = _plant(u_max=1.0)
    assert q.outputs_at(0.0, uc)[6:10].tolist() == [1.0, -0.1, -1.0, 0.2]


def test_singularity_guard_stops_with_a_clear_error_not_nan():
    """A steady spin about body z (principal with a diagonal J) from nu = 1.5 rad, gamma = 0:
    nu' = omega_3, so nu reaches the guard (89 deg) at t = 0.107 s."""
    diag = {"J[1,2]": 0.0, "J[2,1]": 0.0, "J[1,3]": 0.0, "J[3,1]": 0.0, "J[2,3]": 0.0, "J[3,2]": 0.0}
    p = _plant(**QUIET, **diag, **{"sigma_init[1]": 1.5, "sigma_init[3]": 0.0, "omega_init[1]": 0.0,
                                    "omega_init[2]": 0.0, "omega_init[3]": 0.5})
    with pytest.raises(FloatingPointError, match=r"singularity: \|nu\| = 89\.\d+ deg exceeds nu_max = 89\.000 deg"):
        for k in range(100):
            p.advance(0.01 * k, 0.01, np.zeros(4))
    assert 0.10 <= (k + 1) * 0.01 <= 0.12  # the step in which nu crossed 89 deg
    assert all(math.isfinite(v) for v in p.x)


@pytest.mark.parametrize(
    "params, name, problem",
    [
        ({"M[1,4]": 0.0, "M[2,4]": 0.0, "M[3,4]": 0.0}, "M", "column 4 is zero"),
        ({"M[1,3]": 1.0, "M[3,3]": 0.0, "M[3,4]": 0.0}, "M", "rank 2 < 3"),
        ({"J[1,1]": -30.0}, "J", "positive definite"),
        ({"J[1,2]": 1.0}, "J", "symmetric"),
        ({"dJ_amp[2]": 30.0}, "dJ_amp", "positive definiteness"),
        ({"effectiveness[2]": 1.4}, "effectiveness", "[0, 1]"),
        ({"sigma_init[1]": 1.56}, "sigma_init", "nu_max"),
        ({"h_max": 0.0}, "h_max", "> 0"),
    ],
)
def test_bad_input_gives_one_clear_message(params, name, problem):
    p = blocks.plant()
    p.set_parameters(params)
    with pytest.raises(ValueError) as e:
        p.initialize(0.0)
    msg = str(e.value)
    assert msg.startswith(f"{name}:") and problem in msg, msg


def test_defaults_with_a_different_wheel_count_are_refused():
    from plant.rigid_wheels import RigidSpacecraftWheels

    b = RigidSpacecraftWheels(4)
    with pytest.raises(ValueError, match=r"M: .*shape \(3, 5\).*\(3, 4\)"):
        b.set_defaults({"M": np.ones((3, 5))})
    with pytest.raises(ValueError, match=r"M: .*shape \(3, 3\).*\(3, 4\)"):
        b.set_defaults({"M": np.eye(3)})


def test_scenario_with_an_m_for_another_wheel_count_is_refused_by_name(tmp_path, capsys):
    """A 3x3 M given to the 4-wheel plant in a scenario: one message naming file and key, exit 2."""
    from orchestrator.cli.main import main

    src = (Path(__file__).resolve().parents[3] / "papers" / "p001_zhang2019" / "scenarios" / "zhang2019_passive.toml").read_text()
    text = src.replace('[instances.plant]\nfmu = "RigidSpacecraftWheels"\n',
                       '[instances.plant]\nfmu = "RigidSpacecraftWheels"\n\n[instances.plant.parameters]\nM = [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n')
    assert text != src
    path = tmp_path / "bad.toml"
    path.write_text(text)
    rc = main(["run", str(path), "--mode", "inprocess", "--out", str(tmp_path / "out"), "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1
    assert "instances.plant.parameters.M: expected shape (3, 4)" in err[0], err[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("n", [3, 4, 6])
def test_plant_observer_and_controller_share_one_default_wheel_layout(n):
    """The unconfigured blocks agree on M (one wheel per axis, the rest along (1,1,1)/sqrt(3)),
    so a user who changes only n_wheels gets an observer and a controller of the same plant."""
    from controller.fontsm import FONTSM
    from estimator.asmfeo import ASMFEO
    from plant.rigid_wheels import RigidSpacecraftWheels

    def default_m(block):
        return np.array([[p.start for p in block.parameters if p.name == f"M[{i},{j}]"][0]
                         for i in range(1, 4) for j in range(1, n + 1)]).reshape(3, n)

    ms = [default_m(cls(n)) for cls in (RigidSpacecraftWheels, ASMFEO, FONTSM)]
    assert np.array_equal(ms[0], ms[1]) and np.array_equal(ms[0], ms[2])
    np.testing.assert_allclose(np.linalg.norm(ms[0], axis=0), 1.0, rtol=1e-15)  # unit spin axes
    assert np.linalg.matrix_rank(ms[0]) == 3
    for cls in (RigidSpacecraftWheels, ASMFEO, FONTSM):
        with pytest.raises(ValueError, match="n_wheels must be an integer >= 3"):
            cls(2.5)
