"""The Basilisk bridge both ways (issue 32 items 1 and 2): ftcsim's FTC loops as Basilisk modules
(orchestrator/interop/basilisk/module.py) against the same loops in ftcsim's master; the Basilisk
spacecraft as an ftcsim plant (orchestrator/interop/basilisk/spacecraft.py, FMU BasiliskSpacecraft4)
against ftcsim's plant with wheel momentum; what the bridge refuses, in one message naming it.

Tolerance of the loop checks: the loops share the FMUs and the 10 ms zero-order hold; the plants differ
in their integration only (RK4 at ``dyn_step`` in MRPs, Euler angles or quaternions), so, as in
test_basilisk_dynamics.py, |Basilisk - ftcsim| <= 2 (e_Basilisk + e_ftcsim) + round-off, each e the
Richardson estimate from a second run at dyn_step / 2, round-off N 16 eps max|x| after N dynamics steps."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

pytest.importorskip("Basilisk", reason="bsk (the optional extra ftcsim[basilisk]) is not installed")

from orchestrator.interop.basilisk import conventions as cv  # noqa: E402
from orchestrator.interop.basilisk import module as bridge  # noqa: E402
from orchestrator.interop.basilisk.module import BridgeError, FMUModule  # noqa: E402
from orchestrator.tools import basilisk_example as ex  # noqa: E402

pytestmark = pytest.mark.fmu
EPS = np.finfo(float).eps
STOP = 0.5  # s of each loop (the faults are moved inside it)


def short(m, stop=STOP):
    """The mission over ``stop`` with its faults at half of it (the loops then see them)."""
    fmus = []
    for name, model, params, *rest in m.fmus:
        if "onset" in params:
            params = {**params, "onset": stop / 2}
        fmus.append((name, model, params, *rest))
    return dataclasses.replace(m, fmus=fmus, stop=stop)


def loop_states(m, tmp_path, dyn_step):
    m = dataclasses.replace(m, dyn_step=dyn_step)
    flight, craft = ex.fly_basilisk(m, m.stop)
    df = ex.run_ftcsim(m, True, m.stop, tmp_path)
    n = min(len(df), len(flight.t))
    ours = {"omega": df[[f"plant.omega[{i}]" for i in (1, 2, 3)]].to_numpy()[:n],
            "C": ex.attitude(m, df)[:n].reshape(n, 9),
            "h_w": df[[c for c in df.columns if c.startswith("plant.h_w[")]].to_numpy()[:n]}
    bsk = {"omega": flight.omega[:n], "C": np.array([cv.mrp_to_dcm(s) for s in flight.sigma_BN[:n]]).reshape(n, 9),
           "h_w": np.array([cv.inertial_momentum(s, o, m.G, craft.I_w) for s, o in zip(flight.speed[:n], flight.omega[:n])])}
    return ours, bsk, flight


def diff(a, b):
    return max(float(np.abs(a[k] - b[k]).max()) for k in a)


@pytest.mark.slow
@pytest.mark.parametrize("mission", ["001", "000"])
def test_ftc_loop_inside_basilisk_matches_the_loop_in_ftcsim(mission, tmp_path, fmu_dir):
    m = short(ex.MISSIONS[mission]())
    o1, b1, flight = loop_states(m, tmp_path, 0.001)
    o2, b2, _ = loop_states(m, tmp_path, 0.0005)
    scale = max(float(np.abs(v).max()) for v in o1.values())
    tol = 2 * (diff(o1, o2) + diff(b1, b2)) * 16 / 15 + (STOP / 0.0005) * 16 * EPS * scale
    err = diff(o1, b1)
    assert err <= tol, f"{mission}: |Basilisk - ftcsim| = {err:.3g} > {tol:.3g}"
    assert tol < 1e-9
    assert np.abs(flight.outputs["u_applied"]).max() > 1e-3  # the loop acted through the wheels
    # 000 / 001 as printed (no wheel momentum in the plant) is another loop
    df_paper = ex.run_ftcsim(m, False, m.stop, tmp_path)
    w = df_paper[[f"plant.omega[{i}]" for i in (1, 2, 3)]].to_numpy()[: len(b1["omega"])]
    assert np.abs(w - b1["omega"]).max() > 100 * tol


def test_a_flipped_wheel_sign_in_the_bridge_fails_the_check(tmp_path, fmu_dir, monkeypatch):
    m = short(ex.MISSIONS["001"](), 0.5)
    o, b, _ = loop_states(m, tmp_path, 0.001)
    ok = diff(o, b)
    port = bridge.PORTS["rw.torque"]
    monkeypatch.setitem(bridge.PORTS, "rw.torque", port[:4] + (np.asarray,))  # motorTorque = +u_c
    o, b, _ = loop_states(m, tmp_path, 0.001)
    assert diff(o, b) > 1e6 * max(ok, 1e-15)


def craft_and(modules, step=0.01):
    m = short(ex.MISSIONS["001"](), 0.1)
    from orchestrator.interop.basilisk.mission import build_craft

    craft = build_craft(m.J, step, dyn_step=0.001, sigma_BN=cv.mrp_from_quaternion(m.q0), omega=m.omega0, G=m.G)
    return m, craft


def test_the_fmu_step_must_be_the_task_period(fmu_dir):
    m, craft = craft_and(None)
    ctrl = FMUModule("FONTSM", 0.02, {"fo_step": 0.02}, inputs={"sigma": "sc.sigma231", "omega": "sc.omega"}, outputs={})
    ctrl.scStateInMsg.subscribeTo(craft.sc.scStateOutMsg)
    craft.sim.AddModelToTask(craft.task, ctrl, 50)  # a 10 ms task
    craft.sim.InitializeSimulation()
    craft.sim.ConfigureStopTime(int(0.05e9))
    with pytest.raises(BridgeError, match=r"FONTSM: called at t = 0.01 s, 0.01 s after its previous call, but its FMU "
                                          r"steps by step = 0.02 s: add it to a task of period 0.02 s"):
        bridge.execute(craft.sim)


def test_a_module_order_against_the_exchange_is_named(fmu_dir):
    m, craft = craft_and(None)
    ctrl = FMUModule("FONTSM", 0.01, {"fo_step": 0.01}, inputs={"sigma": "sc.sigma231", "omega": "sc.omega"}, outputs={},
                     name="ctrl")
    est = FMUModule("ASMFEO", 0.01, {}, inputs={"omega": "sc.omega"}, outputs={}, name="est")
    ctrl.link("e_hat", est)
    est.link("u_c", ctrl)
    for mod in (ctrl, est):
        mod.scStateInMsg.subscribeTo(craft.sc.scStateOutMsg)
    craft.sim.AddModelToTask(craft.task, ctrl, 50)
    craft.sim.AddModelToTask(craft.task, est, 60)  # before the law whose command it reads
    craft.sim.InitializeSimulation()
    craft.sim.ConfigureStopTime(int(0.05e9))
    with pytest.raises(BridgeError, match=r"est: input u_c reads ctrl.u_c, whose value is for t = \(none yet\), not for "
                                          r"this call's t = 0 s: u_c depends on ctrl's inputs, so ctrl must run first"):
        bridge.execute(craft.sim)


def test_what_the_bridge_refuses_at_configuration(fmu_dir):
    with pytest.raises(BridgeError, match=r"inputs.q: unknown port 'sc.quaternion'"):
        FMUModule("FASMC", 0.01, inputs={"q": "sc.quaternion"})
    with pytest.raises(BridgeError, match=r"inputs.sigma: FASMC has no input sigma"):
        FMUModule("FASMC", 0.01, inputs={"sigma": "sc.sigma231"})
    with pytest.raises(BridgeError, match=r"inputs.q: 4 elements, port sc.omega carries 3"):
        FMUModule("FASMC", 0.01, inputs={"q": "sc.omega"})
    with pytest.raises(BridgeError, match=r"parameters.K_x: no such parameter"):
        FMUModule("FASMC", 0.01, {"K_x": 1.0})
    with pytest.raises(BridgeError, match=r"step = 0: the task period in s, > 0"):
        FMUModule("FASMC", 0)
    with pytest.raises(BridgeError, match=r"Nope: FMU file not found"):
        FMUModule("Nope", 0.01)
    m, craft = craft_and(None)
    ctrl = FMUModule("FASMC", 0.01)  # q and omega bound to sc.* by default, but no message subscribed
    craft.sim.AddModelToTask(craft.task, ctrl, 50)
    with pytest.raises(BridgeError, match=r"input q is bound to sc.q, but scStateInMsg is subscribed to no message"):
        bridge.initialize(craft.sim)


def test_an_fmi3_fmu_runs_as_a_module_like_its_fmi2_twin(fmu_dir, fmi3_dir):
    """Any FMI 2.0 / 3.0 co-simulation FMU: the FMI 3.0 FASMC in Basilisk gives the FMI 2.0 one's command."""
    runs = []
    for folder in (fmu_dir, fmi3_dir):
        m, craft = craft_and(None)
        ctrl = FMUModule(folder / "FASMC.fmu", 0.01, {"u_max": 0.2}, inputs={"q": "sc.q", "omega": "sc.omega"},
                         outputs={"u": "cmd.torque"}, name="ctrl")
        ctrl.scStateInMsg.subscribeTo(craft.sc.scStateOutMsg)
        rec = ctrl.cmdTorqueOutMsg.recorder()
        craft.sim.AddModelToTask(craft.task, ctrl, 50)
        craft.sim.AddModelToTask(craft.task, rec, 1)
        craft.sim.InitializeSimulation()
        craft.sim.ConfigureStopTime(int(0.2e9))
        bridge.execute(craft.sim)
        runs.append(np.asarray(rec.torqueRequestBody))
    assert np.abs(runs[0]).max() > 1e-3
    assert np.array_equal(runs[0], runs[1])


# -- Basilisk as ftcsim's plant -------------------------------------------------------------------------
def plant_run(fmu_dir, tmp_path, plant, h_max, stop=1.0):
    """docs/examples/basilisk_plant.toml over ``stop`` with the plant ``plant`` (FMU) at ``h_max``."""
    from orchestrator.api import run
    from tests.docs.test_docs_run import ROOT

    text = (ROOT / "docs" / "examples" / "basilisk_plant.toml").read_text()
    text = text.replace("h_max = 0.001", f"h_max = {h_max!r}").replace("onset = 20.0", "onset = 0.5")
    if plant == "RigidSpacecraftWheels":
        text = text.replace('fmu = "BasiliskSpacecraft4"', 'fmu = "RigidSpacecraftWheels"').replace(
            "h_max = ", 'wheel_momentum = 1.0\nu_max = 0.2\ndJ_amp = [0.0, 0.0, 0.0]\nTd_amp = [0.0, 0.0, 0.0]\n'
                        'effectiveness = [1.0, 1.0, 1.0, 1.0]\nbias = [0.0, 0.0, 0.0, 0.0]\nh_max = ', 1)
        text = text.replace('"plant.speed", "plant.u_wheel", ', "")
    path = tmp_path / f"{plant}_{h_max}.toml"
    path.write_text(text)
    df = run(str(path), stop=stop).df
    from plant.euler231 import dcm

    return {"omega": df[[f"plant.omega[{i}]" for i in (1, 2, 3)]].to_numpy(),
            "C": np.array([dcm(s) for s in df[[f"plant.sigma[{i}]" for i in (1, 2, 3)]].to_numpy()]).reshape(len(df), 9),
            "h_w": df[[f"plant.h_w[{i}]" for i in (1, 2, 3, 4)]].to_numpy()}


@pytest.mark.slow
def test_the_basilisk_plant_in_ftcsim_matches_ftcsim_plant_with_wheel_momentum(fmu_dir, tmp_path):
    """The FMU BasiliskSpacecraft4 in ftcsim's master, 001's observer and law, faults: against
    RigidSpacecraftWheels with wheel_momentum = 1 and the same 0.2 N.m limit (its speed limit is not
    reached), tolerance as the loops'."""
    b1, b2 = (plant_run(fmu_dir, tmp_path, "BasiliskSpacecraft4", h) for h in (0.001, 0.0005))
    o1, o2 = (plant_run(fmu_dir, tmp_path, "RigidSpacecraftWheels", h) for h in (0.001, 0.0005))
    scale = max(float(np.abs(v).max()) for v in o1.values())
    tol = 2 * (diff(o1, o2) + diff(b1, b2)) * 16 / 15 + (1.0 / 0.0005) * 16 * EPS * scale
    err = diff(o1, b1)
    assert err <= tol, f"|Basilisk plant - ftcsim plant| = {err:.3g} > {tol:.3g}"
    assert tol < 1e-9


def test_the_basilisk_plant_rolls_back_exactly_or_refuses():
    from orchestrator.interop.basilisk.spacecraft import BasiliskSpacecraft

    b = BasiliskSpacecraft(4, 2)
    b.set_defaults({"J": np.diag([30.0, 27.0, 19.0]), "omega_init": [0.1, -0.2, 0.05], "h_w_init": [1.0, -2.0, 0.5, 3.0],
                    "panel_mass": [5.0, 5.0], "panel_d": [1.0, 1.0], "panel_r": [[0.5, 0, 0], [-0.5, 0, 0]],
                    "panel_axis": [[0, 1.0, 0], [0, 1.0, 0]], "panel_k": [20.0, 20.0], "panel_c": [0.5, 0.5],
                    "panel_theta_init": [0.05, -0.02], "coulomb": 0.001, "viscous": 1e-5, "gravity_gradient": 1.0})
    b.initialize(0.0)
    u = np.array([0.1, -0.05, 0.02, 0.1, 0.01, 0.0, 0.0])
    for k in range(20):
        b.advance(k * 0.01, 0.01, u)
    saved = json.loads(json.dumps(b.get_state()))  # as an FMU serialises it
    y0 = b.outputs_at(0.2, u)
    for k in range(20, 40):
        b.advance(k * 0.01, 0.01, -u)
    after = b.get_state()
    b.set_state(saved)
    assert np.array_equal(b.outputs_at(0.2, u), y0)
    for k in range(20, 40):
        b.advance(k * 0.01, 0.01, -u)
    assert b.get_state() == after  # bit for bit

    class WithThrusters(BasiliskSpacecraft):
        def configure(self, sim, task, sc):
            pass  # a subclass adding Basilisk modules whose states the block does not know

    w = WithThrusters(4)
    w.initialize(0.0)
    with pytest.raises(ValueError, match=r"rollback refused: the Basilisk spacecraft carries what WithThrusters.configure "
                                         r"adds, whose states the block does not know"):
        w.get_state()
    WithThrusters.extra_states = ()  # the subclass vouches that they hold none
    w.initialize(0.0)
    assert w.get_state()[0] == 0.0  # the time, then the states: rollback allowed


def test_gravity_gradient_on_the_stated_orbit():
    """omega'(0) = J^-1 3 mu / r^3 r_B x (I_hub r_B) (the wheels at rest, omega = 0), r_B the orbit's
    radial direction in the body: from omega(h) / h at h and h / 2 (first-order extrapolation to 0, its
    error estimated by the difference)."""
    from orchestrator.interop.basilisk.spacecraft import EARTH_MU, BasiliskSpacecraft

    J = np.array([[30.0, 1.3, 1.4], [1.3, 27.0, 2.0], [1.4, 2.0, 19.0]])
    q = np.array([0.9, 0.2, -0.3, 0.25])
    q = q / np.linalg.norm(q)
    rates = []
    for h in (0.02, 0.01):
        b = BasiliskSpacecraft(4)
        b.set_defaults({"J": J, "gravity_gradient": 1.0, "orbit_radius": 7.0e6, "tau_max": 0.0})
        for i in range(4):
            b.set_parameter(f"q_init[{i}]", q[i])
        b.initialize(0.0)
        b.advance(0.0, h, np.zeros(7))
        rates.append(b.outputs_at(h, np.zeros(7))[7:10] / h)
    extrapolated = 2 * rates[1] - rates[0]
    C = cv.quaternion_dcm(q)
    r_B = C @ np.array([1.0, 0.0, 0.0])
    I_hub = cv.hub_inertia(J, b.M, b.Iw)
    expected = np.linalg.solve(J, 3 * EARTH_MU / 7.0e6**3 * np.cross(r_B, I_hub @ r_B))
    assert np.abs(expected).max() > 1e-7
    assert np.abs(extrapolated - expected).max() <= np.abs(rates[1] - rates[0]).max() + 1e-12 * np.abs(expected).max()
