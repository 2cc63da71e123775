"""ftcsim's data-sheet hardware against Basilisk's (issue 32 item 4): the reaction-wheel model
(plant/hardware/wheels.py) against ``reactionWheelStateEffector`` (coast-down, torque steps, torque and
speed limits), the rate gyro and the star tracker (plant/hardware/sensors.py) against ``imuSensor`` and
``starTracker`` (noise statistics).

Wheels: Basilisk's wheels sit on a hub of 1e8 kg.m2 (at rest), integrated by RK4 at 1 ms; ftcsim's
ReactionWheels steps the wheel momentum by explicit Euler at ``h_int``, with a drive lag
``time_constant`` (not in Basilisk, set to 1e-12 s: the motor torque then follows the command after one
internal step). The tolerances follow from those two differences, stated at each test: the Euler error
of the friction decay (exact for a constant Coulomb torque), one internal step of delay per command
change, one Basilisk step of overshoot at the speed limit (Basilisk cuts the motor torque once
|Omega| >= Omega_max at a step; ftcsim clamps h at h_max). Momenta compare as ftcsim's inertial h =
I_w (g^T omega + Omega) (conventions.inertial_momentum).

Sensors: both configured to the same white noise (Basilisk's Gauss-Markov error model with A = 0 is
white noise of standard deviation P per sample; ftcsim's gyro has per-sample standard deviation
arw / sqrt(T), its star tracker sigma_cross, sigma_roll per sample): means, standard deviations and
lag-1 autocorrelations agree with the nominal values and with each other within 5 standard errors of
the estimates (N samples: the mean's 1/sqrt(N), the standard deviation's 1/sqrt(2N) relative, the
autocorrelation's 1/sqrt(N))."""
from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("Basilisk", reason="bsk (the optional extra ftcsim[basilisk]) is not installed")

from Basilisk.architecture import messaging  # noqa: E402
from Basilisk.simulation import imuSensor, reactionWheelStateEffector, spacecraft, starTracker  # noqa: E402
from Basilisk.utilities import SimulationBaseClass, macros, simIncludeRW  # noqa: E402

from orchestrator.interop.basilisk import conventions as cv  # noqa: E402
from plant.hardware.sensors import RateGyro, StarTracker  # noqa: E402
from plant.hardware.wheels import ReactionWheels  # noqa: E402
from plant.so3 import rotation_matrix  # noqa: E402

IW = 0.0796  # kg.m2 (HR16, 50 N.m.s at 6000 rpm)
DT = 0.001  # s, Basilisk's dynamics step
STEP = 0.01  # s, the command's step
EPS = np.finfo(float).eps


class BasiliskWheels:
    """Three wheels on the body axes of a resting 1e8 kg.m2 hub, commanded step by step."""

    def __init__(self, speed0, u_max=-1.0, speed_max=-1.0, coulomb=0.0, viscous=0.0, limit_cycle=1e-4):
        self.sim = SimulationBaseClass.SimBaseClass()
        proc = self.sim.CreateNewProcess("p")
        proc.addTask(self.sim.CreateNewTask("dyn", macros.sec2nano(DT)))
        self.sc = spacecraft.Spacecraft()
        self.sc.hub.IHubPntBc_B = (np.eye(3) * 1e8).tolist()
        fac = simIncludeRW.rwFactory()
        for j in range(3):
            w = fac.create("custom", np.eye(3)[j].tolist(), Js=IW, useRWfriction=True, useMaxTorque=u_max > 0,
                           u_max=u_max, fCoulomb=coulomb, cViscous=viscous, RWModel=messaging.BalancedWheels)
            w.Omega = float(speed0[j])
            w.Omega_max = speed_max
            w.omegaLimitCycle = limit_cycle
        self.rw = reactionWheelStateEffector.ReactionWheelStateEffector()
        fac.addToSpacecraft("rw", self.rw, self.sc)
        self.fac = fac
        self.payload = messaging.ArrayMotorTorqueMsgPayload()
        self.msg = messaging.ArrayMotorTorqueMsg().write(self.payload)
        self.rw.rwMotorCmdInMsg.subscribeTo(self.msg)
        self.sim.AddModelToTask("dyn", self.rw, 20)
        self.sim.AddModelToTask("dyn", self.sc, 10)
        self.sim.InitializeSimulation()
        self.t = 0.0

    def step(self, u_c, step=STEP):
        """Hold the body torques u_c (ftcsim's sign) over ``step``; the inertial momenta after it."""
        self.payload.motorTorque = cv.motor_torque(u_c).tolist()
        self.msg.write(self.payload)
        self.t += step
        self.sim.ConfigureStopTime(macros.sec2nano(self.t))
        self.sim.ExecuteSimulation()
        dm = self.sc.dynManager
        w = np.ravel(dm.getStateObject(self.sc.hub.nameOfHubOmega).getState())
        speed = np.ravel(dm.getStateObject(self.rw.nameOfReactionWheelOmegasState).getState())
        return cv.inertial_momentum(speed, w, np.eye(3), IW)


def ftcsim_wheels(h0, h_int, **params):
    b = ReactionWheels(3, 3)
    b.set_defaults({"M": np.eye(3), "I_w": IW, "h_init": h0, "time_constant": 1e-12, "h_int": h_int,
                    "gyroscopic": 0.0, "h_max": 1e6, "tau_max": 1e6, **params})
    b.initialize(0.0)
    return b


def run_both(bsk, ours, commands, step=STEP):
    hb, ho, uw = [], [], []
    for k, u in enumerate(commands):
        x = np.concatenate((u, np.zeros(3)))
        uw.append(ours.outputs_at(k * step, x)[3:6])
        ours.advance(k * step, step, x)
        ho.append(ours.hw.copy())
        hb.append(bsk.step(u, step))
    return np.array(ho), np.array(hb), np.array(uw)


def test_coast_down_with_coulomb_and_viscous_friction():
    """No command: Coulomb c_c and viscous c_v drag the wheels (h' = -c_c sign(h) - (c_v / I_w) h). Euler's
    error for it is exact to compute: |(h0 + c_c / a)| |(1 - a dt)^n - exp(-a n dt)|, a = c_v / I_w;
    Basilisk's RK4 is exact to 1e-15 here. Compared while the wheels still turn (above the limit-cycle
    speed, where both linearise the Coulomb law alike), then both at rest."""
    cc, cvisc, lc = 0.01, 2e-4, 0.01
    speed0 = np.array([3.0, -2.0, 1.0])  # rad/s
    h0 = IW * speed0
    bsk = BasiliskWheels(speed0, coulomb=cc, viscous=cvisc, limit_cycle=lc)
    ours = ftcsim_wheels(h0, DT, coulomb=cc, viscous=cvisc, omega_eps=lc)
    n = 300  # 30 s: wheel 3 stops at ~7.7 s, wheel 1 at ~22 s
    ho, hb, _ = run_both(bsk, ours, [np.zeros(3)] * n, step=0.1)
    a = cvisc / IW
    t = 0.1 * np.arange(1, n + 1)
    for j in range(3):
        s = math.copysign(1.0, h0[j])
        exact = s * ((abs(h0[j]) + cc / a) * np.exp(-a * t) - cc / a)  # before the stop
        euler = s * ((abs(h0[j]) + cc / a) * (1 - a * DT) ** np.round(t / DT) - cc / a)
        turning = s * exact > 2 * IW * lc  # before the analytic solution reaches zero
        roundoff = (t / DT * 16 * EPS * abs(h0[j]))[turning]  # 16 operations per step, as the dynamics checks
        bound = np.abs(euler - exact)[turning] + 2 * roundoff
        assert np.all(np.abs(hb[turning, j] - exact[turning]) <= roundoff)  # Basilisk's RK4 = exact here
        assert np.all(np.abs(ho[turning, j] - hb[turning, j]) <= bound), j
        assert turning.sum() < n - 10  # the wheel did stop within the run
    assert np.all(np.abs(ho[-1]) < IW * lc) and np.all(np.abs(hb[-1]) < IW * lc)  # both at rest


def test_torque_steps_and_the_torque_limit():
    """Steps of the command, some beyond tau_max = 0.2 N.m (both clip them). ftcsim's motor torque follows
    a change one internal step h_int late: |h_ftcsim - h_Basilisk| <= h_int sum |change of the clipped
    command| (no friction: both integrate a constant torque exactly)."""
    rng = np.random.default_rng(5)
    commands = [rng.uniform(-0.5, 0.5, 3) for _ in range(20) for _ in range(10)]  # 2 s, a new level each 0.1 s
    h_int = 1e-4
    bsk = BasiliskWheels(np.array([10.0, -20.0, 0.0]), u_max=0.2)
    ours = ftcsim_wheels(IW * np.array([10.0, -20.0, 0.0]), h_int, tau_max=0.2)
    ho, hb, uw = run_both(bsk, ours, commands)
    clipped = np.clip(np.array(commands), -0.2, 0.2)
    changes = np.cumsum(np.abs(np.diff(np.vstack([np.zeros(3), clipped]), axis=0)), axis=0)
    assert np.all(np.abs(ho - hb) <= h_int * changes + 1e3 * EPS)
    assert np.abs(ho - hb).max() > 0.0  # the check compares something
    assert np.abs(uw).max() <= 0.2 + 1e-12  # the wheels never exceed tau_max
    assert np.abs(hb - IW * np.array([10.0, -20.0, 0.0])).max() > 0.02  # the wheels moved


def test_speed_limit():
    """Commands pushing the wheels beyond Omega_max: ftcsim holds h at I_w Omega_max, Basilisk cuts the
    motor torque at the first 1 ms step at or beyond it (overshoot <= tau_max DT); no friction. Then the
    command turns back and both leave the limit alike."""
    speed_max = 600.0  # rad/s (~5700 rpm)
    speed0 = np.array([599.0, -599.5, 100.0])
    bsk = BasiliskWheels(speed0, u_max=0.2, speed_max=speed_max)
    ours = ftcsim_wheels(IW * speed0, DT, tau_max=0.2, h_max=IW * speed_max)
    push = np.array([-0.2, 0.2, -0.2])  # body torque: the wheels speed up in the opposite sense
    ho, hb, _ = run_both(bsk, ours, [push] * 200)
    assert np.all(np.abs(ho[:, :2]) <= IW * speed_max + 1e-12)
    assert np.all(np.abs(hb[:, :2]) <= IW * speed_max + 0.2 * DT + 1e-12)
    assert np.abs(ho[-1, :2] - hb[-1, :2]).max() <= 0.2 * DT + 0.2 * DT  # overshoot + ftcsim's delayed start
    assert abs(ho[-1, 2] - hb[-1, 2]) <= 0.2 * DT + 1e-12  # wheel 3 far from the limit: torque * time
    back = run_both(bsk, ours, [-push] * 50)
    assert np.all(np.abs(back[0][-1, :2]) < IW * speed_max - 0.05)  # off the limit again
    assert np.abs(back[0][-1] - back[1][-1]).max() <= 3 * 0.2 * DT


# -- sensors ------------------------------------------------------------------------------------------
N = 4000  # samples
T_S = 0.1  # s, sample period


def static_craft(q, omega):
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("p")
    proc.addTask(sim.CreateNewTask("t", macros.sec2nano(T_S)))
    sc = spacecraft.Spacecraft()
    sc.hub.IHubPntBc_B = (np.eye(3) * 1e12).tolist()  # the rate stays put
    sc.hub.sigma_BNInit = cv.mrp_from_quaternion(q).reshape(3, 1).tolist()
    sc.hub.omega_BN_BInit = np.asarray(omega).reshape(3, 1).tolist()
    sim.AddModelToTask("t", sc, 10)
    return sim, sc


def stats_close(a, b, mean, std, n):
    """Per axis: each sample set's mean within 5 standard errors of ``mean``, standard deviation within
    5 relative standard errors of ``std``, lag-1 autocorrelation within 5 / sqrt(n) of 0; and the two sets
    alike within sqrt(2) times those bands."""
    for x in (a, b):
        assert np.all(np.abs(x.mean(axis=0) - mean) <= 5 * std / math.sqrt(n))
        assert np.all(np.abs(x.std(axis=0, ddof=1) / std - 1) <= 5 / math.sqrt(2 * n))
        d = x - x.mean(axis=0)
        assert np.all(np.abs((d[1:] * d[:-1]).sum(axis=0) / (d * d).sum(axis=0)) <= 5 / math.sqrt(n))
    assert np.all(np.abs(a.std(axis=0, ddof=1) / b.std(axis=0, ddof=1) - 1) <= 5 * math.sqrt(2) / math.sqrt(2 * n))
    assert np.all(np.abs(a.mean(axis=0) - b.mean(axis=0)) <= 5 * math.sqrt(2) * std / math.sqrt(n))


def test_gyro_noise_and_bias_statistics():
    sigma = 1e-4  # rad/s per sample
    bias = np.array([2e-4, -1e-4, 5e-5])
    omega = np.array([0.01, -0.02, 0.03])
    sim, sc = static_craft(np.array([1.0, 0, 0, 0]), omega)
    imu = imuSensor.ImuSensor()
    imu.ModelTag = "imu"
    imu.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    imu.PMatrixGyro = (np.eye(3) * sigma).tolist()
    imu.setAMatrixGyro(np.zeros((3, 3)).tolist())  # white noise
    imu.setWalkBoundsGyro([0.0, 0.0, 0.0])
    imu.senRotBias = bias.tolist()
    imu.senRotMax = 1e3
    imu.RNGSeed = 17
    sim.AddModelToTask("t", imu, 5)
    rec = imu.sensorOutMsg.recorder()
    sim.AddModelToTask("t", rec, 1)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(T_S * N))
    sim.ExecuteSimulation()
    w_true = np.ravel(sc.dynManager.getStateObject(sc.hub.nameOfHubOmega).getState())
    bsk = np.asarray(rec.AngVelPlatform)[1:N + 1] - w_true
    g = RateGyro(3)
    g.set_defaults({"arw": sigma * math.sqrt(T_S), "rrw": 0.0, "bi_sigma": 0.0, "bias_init": bias, "sample_period": T_S,
                    "seed": 17})
    g.initialize(0.0)
    ours = []
    for k in range(N):
        ours.append(g.outputs_at(k * T_S, omega)[:3] - omega)
        g.advance(k * T_S, T_S, omega)
    stats_close(np.array(ours), bsk, bias, sigma, N)


def error_angles(q_m, q) -> np.ndarray:
    """Small body-frame angles d with C(q_m) = (I - [d x]) C(q)."""
    E = rotation_matrix(q_m) @ rotation_matrix(q).T
    return 0.5 * np.array([E[1, 2] - E[2, 1], E[2, 0] - E[0, 2], E[0, 1] - E[1, 0]])


def test_star_tracker_noise_statistics():
    cross, roll = 6.0 * math.pi / 648000, 40.0 * math.pi / 648000  # 6 and 40 arcsec
    q = np.array([0.8, 0.2, -0.5, 0.26])
    q = q / np.linalg.norm(q)
    sim, sc = static_craft(q, np.zeros(3))
    st = starTracker.StarTracker()
    st.ModelTag = "st"
    st.scStateInMsg.subscribeTo(sc.scStateOutMsg)
    st.PMatrix = np.diag([cross, cross, roll]).tolist()
    st.setAMatrix(np.zeros((3, 3)).tolist())
    st.setWalkBounds([0.0, 0.0, 0.0])
    st.dcm_CB = np.eye(3).tolist()
    st.RNGSeed = 23
    sim.AddModelToTask("t", st, 5)
    rec = st.sensorOutMsg.recorder()
    sim.AddModelToTask("t", rec, 1)
    sim.InitializeSimulation()
    sim.ConfigureStopTime(macros.sec2nano(T_S * N))
    sim.ExecuteSimulation()
    bsk = np.array([error_angles(qm, q) for qm in np.asarray(rec.qInrtl2Case)[1:N + 1]])
    s = StarTracker()
    s.set_defaults({"sigma_cross": cross, "sigma_roll": roll, "boresight": 3, "sample_period": T_S, "seed": 23})
    s.initialize(0.0)
    ours = []
    for k in range(N):
        ours.append(error_angles(s.outputs_at(k * T_S, q)[:4], q))
        s.advance(k * T_S, T_S, q)
    sig = np.array([cross, cross, roll])
    stats_close(np.array(ours) / sig, bsk / sig, np.zeros(3), 1.0, N)
