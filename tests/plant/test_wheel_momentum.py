"""The plants' wheel-momentum option (issue 32 item 3), without Basilisk: with ``wheel_momentum`` = 1 the
wheels only exchange momentum with the body, so the total angular momentum in inertial components,
C^T (J omega + M h_w) (+ delta^T eta' for the flexible craft), is conserved whatever the wheel torques;
with the papers' equations (the default) it is not, and the default is unchanged; 001's inertia gets
one warning line (Basilisk's own checks are in tests/orchestrator/test_basilisk_dynamics.py).

Tolerance: RK4's global error over the run, by Richardson from a run at half the internal step, plus
round-off 16 eps |H| per step."""
import logging

import numpy as np
import pytest

from plant.flexible import FlexibleSpacecraft
from plant.rigid_wheels import RigidSpacecraftWheels
from plant.so3 import rotation_matrix

EPS = np.finfo(float).eps
J = np.array([[30.0, 1.3, 1.4], [1.3, 27.0, 2.0], [1.4, 2.0, 19.0]])


def rigid(h_max, momentum, steps=300):
    b = RigidSpacecraftWheels(4)
    b.set_defaults({"J": J, "sigma_init": [0.2, -0.3, 0.1], "omega_init": [0.3, -0.2, 0.25], "h_max": h_max,
                    "wheel_momentum": float(momentum), "h_w_init": [6.0, -4.0, 3.0, 5.0], "omega_max": 50.0})
    b.initialize(0.0)
    H0 = b.angular_momentum_inertial()
    rng = np.random.default_rng(1)
    for k in range(steps):
        b.advance(k * 0.01, 0.01, rng.normal(size=4) * 0.2)
    return H0, b.angular_momentum_inertial(), b


def flexible(h_max, momentum, steps=300):
    from papers.p000_li2023.blocks import flexible_spacecraft

    b = flexible_spacecraft()
    b.set_defaults({"omega_init": [0.05, -0.03, 0.04], "h_max": h_max, "wheel_momentum": float(momentum),
                    "h_w_init": [2.0, -1.0, 3.0], "u_max": 1e6, "eta_init": [0.02, -0.01, 0.015, 0.005]})
    b.initialize(0.0)
    H0 = b.angular_momentum_inertial()
    rng = np.random.default_rng(2)
    for k in range(steps):
        b.advance(k * 0.01, 0.01, rng.normal(size=3) * 0.5)
    return H0, b.angular_momentum_inertial(), b


@pytest.mark.parametrize("plant", [rigid, flexible], ids=["001", "000"])
def test_total_momentum_is_conserved_with_wheel_momentum(plant):
    H0, H, _ = plant(0.001, True)
    _, H2, _ = plant(0.0005, True)
    drift = float(np.abs(H - H0).max())
    tol = 2 * float(np.abs(H - H2).max()) * 16 / 15 + 3000 * 2 * 16 * EPS * float(np.abs(H0).max())
    assert drift <= tol, f"|H(3 s) - H(0)| = {drift:.3g} > {tol:.3g}"
    assert tol < 1e-9
    # the papers' equation: the wheel torques are external to the body, the momentum changes
    H0p, Hp, _ = plant(0.001, False)
    assert float(np.abs(Hp - H0p).max()) > 1e-2


def test_the_default_is_the_papers_equation():
    """wheel_momentum = 0 integrates 001 (3) as before: the state is [sigma, omega] only and h_w stays put."""
    _, _, b = rigid(0.001, False, steps=10)
    assert len(b.get_state()) == 6 and b.p("wheel_momentum") == 0.0
    y = b.outputs_at(0.1, np.zeros(4))
    assert np.array_equal(y[-4:], [6.0, -4.0, 3.0, 5.0])
    _, _, f = flexible(0.001, False, steps=10)
    assert len(f.get_state()) == 4 + 3 + 8 and f.p("wheel_momentum") == 0.0
    for block in (RigidSpacecraftWheels(4), FlexibleSpacecraft(4)):
        block.set_parameter("wheel_momentum", 0.5)
        with pytest.raises(ValueError, match="wheel_momentum: must be 0"):
            block.initialize(0.0)


def test_wheel_momentum_reaches_the_body_rate():
    """A wheel spun up against the body turns the body the other way: the body's momentum J omega
    changes by -M delta h_w (the omega x M h_w torque aside), checked on one axis from rest."""
    b = RigidSpacecraftWheels(4)
    b.set_defaults({"J": J, "wheel_momentum": 1.0, "h_max": 0.001})
    b.initialize(0.0)
    u = np.array([0.0, 0.0, 0.2, 0.0])  # wheel 3 (body z) pushes the body: h_w3' = -0.2
    for k in range(100):
        b.advance(k * 0.01, 0.01, u)
    w = np.array(b.get_state()[3:6])
    H = rotation_matrix(np.array([1.0, 0, 0, 0])) @ (J @ w + b.M @ np.array(b.get_state()[6:]))
    assert np.abs(H).max() < 1e-12 * 0.2  # from rest: the total stays zero
    assert abs(b.get_state()[8] + 0.2) < 1e-12  # h_w3 = -0.2 N.m.s after 1 s


def test_001_inertia_warning_is_one_line_and_the_run_goes_on(caplog):
    """The values a run uses (after every override) are judged when it starts (cosim/runner.py)."""
    from orchestrator.api import load, run
    from orchestrator.scenario import physical

    physical._WARNED.clear()
    sc = load("zhang2019_fontsm", mode="inprocess")
    with caplog.at_level(logging.WARNING, logger="ftcsim.scenario"):
        r = run(sc, stop=0.002)
        run(sc, stop=0.002)  # once per process
        run(load("zhang2019_passive", mode="inprocess"), stop=0.002)  # another file, the same J: not again
    lines = [r.getMessage() for r in caplog.records if "triangle inequality" in r.getMessage()]
    assert len(lines) == 1 and "instances.plant.parameters.J" in lines[0] and "(the same value in est.J, ctrl.J)" in lines[0]
    assert "the run goes on" in lines[0] and r.complete
    physical._WARNED.clear()
    caplog.clear()
    rigid_body = np.diag([30.0, 27.0, 19.0]).tolist()
    with caplog.at_level(logging.WARNING, logger="ftcsim.scenario"):
        run(sc, stop=0.002, parameters={"plant.J": rigid_body, "est.J": rigid_body, "ctrl.J": rigid_body})
    assert not [r for r in caplog.records if "triangle inequality" in r.getMessage()]  # a rigid body's J: no warning
