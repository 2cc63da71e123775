"""A plant block (plant/block.py) backed by a Basilisk spacecraft: :class:`BasiliskSpacecraft`, for
scenarios (FMU ``BasiliskSpacecraft4``, or in-process) and built as an FMU like any block.

The Basilisk simulation it holds: a hub of inertia J + sum_j I_w g_j g_j^T (``spacecraft``), N balanced
reaction wheels about the columns g_j of ``M`` (``reactionWheelStateEffector``: the wheels' momentum
coupled into the body, their motor-torque limit ``tau_max``, speed limit ``speed_max`` (Basilisk cuts a
command that would speed the wheel up beyond it), Coulomb and viscous friction with Basilisk's
linearisation below ``omega_limit_cycle``), optional hinged panels (``hingedRigidBodyStateEffector``:
mass, hinge offset, inertia, spring, damper, hinge position and axis per panel), an external torque on
the hub (``extForceTorque``), and with ``gravity_gradient`` = 1 the Earth's point-mass gravity and its
gravity-gradient torque (``GravityGradientEffector``) on a stated orbit: circular, of radius
``orbit_radius``, in the inertial x-y plane, from r = [a, 0, 0], v = [0, sqrt(mu / a), 0] (the hub's
mass ``mass`` then matters only for the orbit, not for the attitude).

Conventions (``conventions.py``): ``u_c[j]`` is the torque wheel j exerts on the body (ftcsim's 001 (3)),
Basilisk's motorTorque = -u_c; ``J`` is the craft's inertia without the wheels' spin inertia about their
axes and without the panels; ``h_w`` is each wheel's inertial momentum I_w (g_j^T omega + Omega_j),
``speed`` Basilisk's Omega_j (relative to the body); ``sigma`` is 001's 2-3-1 set [nu, psi, gamma] and
``q`` the quaternion (scalar first) of Basilisk's MRP sigma_BN.

Time: over a communication step [t, t + h] with u held, the block calls the wheels (they read the
command and apply their limits at the wheel speed of the sub-step's start) and then the spacecraft
(one Basilisk RK4 step), for each of the fewest equal sub-steps <= ``h_max``: a Basilisk simulation
whose dynamics task runs at that period with the command held, Basilisk's own numbers.

Rollback: the state is every state object of the spacecraft's ``dynManager`` (hub position, velocity,
MRP, rate, the two gravity-velocity states, wheel speeds, panel angles and rates), the wheels' memory of
Stribeck friction (``omegaBefore``, ``frictionStribeck``) and the time: restoring it restores the block
bit for bit. A subclass that adds Basilisk effectors or modules in :meth:`BasiliskSpacecraft.configure`
must name their dynManager states in ``extra_states`` (``()`` for stateless ones, vouching that they hold
no other state); otherwise :meth:`get_state` refuses (rollback could not be exact): the FMU reports an
error at ``fmi2GetFMUstate``, and a step policy that needs rollback stops with that message. Inputs,
outputs and parameters: the declaration in ``__init__``.
"""
from __future__ import annotations

import math

import numpy as np

from plant.block import Block, matrix, scalar, vector
from plant.integrate import h_max_parameter, substeps

from . import conventions as cv

__all__ = ["BasiliskSpacecraft", "basilisk_spacecraft_4", "EARTH_MU"]

# imported when the block initializes, not at import (the probe of the FMU build imports this module):
# fmus/runtime.py lists it in the FMU's requirements.txt (bsk)
OPTIONAL_IMPORTS = ("Basilisk",)

EARTH_MU = 3.986004418e14  # m3/s2, Basilisk's simIncludeGravBody createEarth()


class BasiliskSpacecraft(Block):
    model_name = "BasiliskSpacecraft"
    description = "Basilisk spacecraft: hub, reaction wheels (momentum, limits, friction), hinged panels, gravity gradient"
    extra_states: tuple | None = None  # dynManager state names of what configure() adds (a subclass names them)

    def __init__(self, n_wheels: int = 4, n_panels: int = 0):
        n, p = self.n, self.n_panels = int(n_wheels), int(n_panels)
        if n < 0 or p < 0:
            raise ValueError(f"n_wheels = {n_wheels}, n_panels = {n_panels}: must be >= 0")
        M0 = np.zeros((3, n))
        M0[:, : min(n, 3)] = np.eye(3)[:, : min(n, 3)]
        if n > 3:
            M0[:, 3:] = 1.0 / math.sqrt(3.0)
        inputs = vector("u_c", n, "N.m", "torque of each wheel on the body (Basilisk motorTorque = -u_c)") \
            + vector("T_ext", 3, "N.m", "external torque on the hub, body components")
        outputs = (vector("sigma", 3, "rad", "Euler angles [nu, psi, gamma] of the 2-3-1 sequence (001)")
                   + vector("q", 4, "1", "attitude quaternion, scalar first", first=0)
                   + vector("omega", 3, "rad/s", "body angular rate")
                   + vector("mrp", 3, "1", "Basilisk's MRP sigma_BN")
                   + vector("h_w", n, "N.m.s", "wheel momentum about each spin axis, inertial")
                   + vector("speed", n, "rad/s", "wheel speed relative to the body (Basilisk's Omega)")
                   + vector("u_wheel", n, "N.m", "torque each wheel exerts on the body at this instant (limits, friction)")
                   + vector("tau_applied", 3, "N.m", "body torque of the wheels M u_wheel")
                   + vector("theta", p, "rad", "panel hinge angle")
                   + vector("theta_dot", p, "rad/s", "panel hinge rate"))
        params = (matrix("J", np.eye(3) * 10.0, "kg.m2", "craft inertia without the wheels' spin inertia and the panels")
                  + matrix("M", M0, "1", "wheel spin axes, unit columns")
                  + scalar("I_w", 0.0796, "kg.m2", "wheel spin inertia (HR16, 50 N.m.s at 6000 rpm)")
                  + scalar("tau_max", 0.2, "N.m", "largest motor torque (0: none)")
                  + scalar("speed_max", 6000.0 * math.pi / 30.0, "rad/s", "wheel speed limit (0: none)")
                  + scalar("coulomb", 0.0, "N.m", "Coulomb friction")
                  + scalar("viscous", 0.0, "N.m.s", "viscous friction")
                  + scalar("omega_limit_cycle", 1e-4, "rad/s", "friction linear below this speed (Basilisk)")
                  + vector("q_init", 4, "1", "initial quaternion (or sigma_init)", [1.0, 0.0, 0.0, 0.0], first=0)
                  + vector("sigma_init", 3, "rad", "initial [nu, psi, gamma] (or q_init)")
                  + vector("omega_init", 3, "rad/s", "initial body rate")
                  + vector("h_w_init", n, "N.m.s", "initial wheel momentum, inertial")
                  + scalar("gravity_gradient", 0.0, "1", "1: Earth's gravity and gravity-gradient torque on the orbit")
                  + scalar("orbit_radius", 7.0e6, "m", "radius of the circular orbit (gravity_gradient = 1)")
                  + scalar("mass", 100.0, "kg", "hub mass")
                  + h_max_parameter(0.001))
        if p:
            params += (vector("panel_mass", p, "kg", "panel mass")
                       + vector("panel_d", p, "m", "hinge to panel centre of mass")
                       + matrix("panel_I", np.ones((p, 3)), "kg.m2",
                                "panel principal inertia about its centre of mass (s1, s2 = hinge, s3)")
                       + vector("panel_k", p, "N.m/rad", "hinge spring", [1.0] * p)
                       + vector("panel_c", p, "N.m.s/rad", "hinge damper")
                       + matrix("panel_r", np.zeros((p, 3)), "m", "hinge position, body")
                       + matrix("panel_axis", np.tile([0.0, 1.0, 0.0], (p, 1)), "1", "hinge axis, body (unit)")
                       + vector("panel_theta_init", p, "rad", "initial hinge angle")
                       + vector("panel_theta_dot_init", p, "rad/s", "initial hinge rate"))
        feed = {f"u_wheel[{j + 1}]": [f"u_c[{j + 1}]"] for j in range(n)}
        feed.update({f"tau_applied[{i}]": [f"u_c[{j + 1}]" for j in range(n)] for i in (1, 2, 3)})
        super().__init__(inputs, outputs, params, feed)
        self._state = None

    # -- set-up -------------------------------------------------------------------------------------
    def configure(self, sim, task: str, sc) -> None:
        """Hook for a subclass: add Basilisk effectors or modules (name their states in ``extra_states``)."""

    def initialize(self, t0: float) -> None:
        from Basilisk.architecture import messaging
        from Basilisk.simulation import extForceTorque, hingedRigidBodyStateEffector, reactionWheelStateEffector, spacecraft
        from Basilisk.utilities import SimulationBaseClass, macros, simIncludeRW

        n, p = self.n, self.n_panels
        J = self.p_matrix("J")
        M = self.p_matrix("M").reshape(3, n) if n else np.zeros((3, 0))
        for name in ("I_w", "h_max", "orbit_radius", "mass"):
            if not self.p(name) > 0:
                raise ValueError(f"{name}: must be > 0, got {self.p(name):g}")
        for name in ("tau_max", "speed_max", "coulomb", "viscous", "omega_limit_cycle"):
            if self.p(name) < 0:
                raise ValueError(f"{name}: must be >= 0, got {self.p(name):g}")
        if self.p("gravity_gradient") not in (0.0, 1.0):
            raise ValueError(f"gravity_gradient: must be 0 or 1, got {self.p('gravity_gradient'):g}")
        if n:
            norms = np.linalg.norm(M, axis=0)
            if np.any(np.abs(norms - 1.0) > 1e-9):
                raise ValueError(f"M: the spin axes (columns) must be unit vectors, norms {np.array2string(norms, precision=6)}")
        q0, s0 = self.p_vector("q_init"), self.p_vector("sigma_init")
        if np.any(s0 != 0.0) and not np.array_equal(q0, [1.0, 0.0, 0.0, 0.0]):
            raise ValueError("sigma_init: give the initial attitude as q_init or as sigma_init, not both")
        if not np.linalg.norm(q0) > 0:
            raise ValueError("q_init must not be zero")
        mrp0 = cv.mrp_from_euler231(s0) if np.any(s0 != 0.0) else cv.mrp_from_quaternion(q0)
        w0 = self.p_vector("omega_init")
        self.M, self.Iw, self.h_max = M, self.p("I_w"), self.p("h_max")
        hub = cv.hub_inertia(J, M, self.Iw) if n else J.copy()
        lam = np.linalg.eigvalsh(0.5 * (hub + hub.T))
        if not (np.allclose(hub, hub.T) and lam[0] > 0):
            raise ValueError(f"J: the hub inertia J + sum I_w g g^T must be symmetric positive definite (eigenvalues {lam})")

        sim = SimulationBaseClass.SimBaseClass()
        proc = sim.CreateNewProcess("plant")
        proc.addTask(sim.CreateNewTask("dynamics", macros.sec2nano(self.h_max)))
        sc = spacecraft.Spacecraft()
        sc.ModelTag = "ftcsim_spacecraft"
        sc.hub.IHubPntBc_B = hub.tolist()
        sc.hub.mHub = self.p("mass")
        sc.hub.sigma_BNInit = mrp0.reshape(3, 1).tolist()
        sc.hub.omega_BN_BInit = w0.reshape(3, 1).tolist()
        self.rw = None
        if n:
            fac = simIncludeRW.rwFactory()
            tau_max, speed_max = self.p("tau_max"), self.p("speed_max")
            speeds = cv.relative_speed(self.p_vector("h_w_init"), w0, M, self.Iw)
            for j in range(n):
                w = fac.create("custom", M[:, j].tolist(), Js=self.Iw, useRWfriction=True, useMaxTorque=tau_max > 0,
                               u_max=tau_max if tau_max > 0 else -1.0, RWModel=messaging.BalancedWheels,
                               fCoulomb=self.p("coulomb"), cViscous=self.p("viscous"))
                w.Omega = float(speeds[j])
                w.Omega_max = speed_max if speed_max > 0 else -1.0
                w.omegaLimitCycle = self.p("omega_limit_cycle")
                w.u_min = 0.0
            self.rw = reactionWheelStateEffector.ReactionWheelStateEffector()
            fac.addToSpacecraft("ftcsim_wheels", self.rw, sc)
            self._fac = fac
            self.rw.setMaxWheelAcceleration(1e300)  # no silent clamp of the wheel acceleration
            self._wheel_data = (tau_max, speed_max, self.p("coulomb"), self.p("viscous"), self.p("omega_limit_cycle"))
            self._cmd_payload = messaging.ArrayMotorTorqueMsgPayload()
            self._cmd_msg = messaging.ArrayMotorTorqueMsg().write(self._cmd_payload)
            self.rw.rwMotorCmdInMsg.subscribeTo(self._cmd_msg)
        self.panels = []
        for i in range(p):
            pan = hingedRigidBodyStateEffector.HingedRigidBodyStateEffector()
            pan.ModelTag = f"ftcsim_panel{i + 1}"
            pan.mass = self.p(f"panel_mass[{i + 1}]")
            pan.d = self.p(f"panel_d[{i + 1}]")
            pan.IPntS_S = np.diag([self.p(f"panel_I[{i + 1},{k}]") for k in (1, 2, 3)]).tolist()
            pan.k, pan.c = self.p(f"panel_k[{i + 1}]"), self.p(f"panel_c[{i + 1}]")
            pan.r_HB_B = [[self.p(f"panel_r[{i + 1},{k}]")] for k in (1, 2, 3)]
            axis = np.array([self.p(f"panel_axis[{i + 1},{k}]") for k in (1, 2, 3)])
            if abs(np.linalg.norm(axis) - 1.0) > 1e-9:
                raise ValueError(f"panel_axis: row {i + 1} must be a unit vector, norm {np.linalg.norm(axis):.6g}")
            pan.dcm_HB = cv.hinge_dcm(axis).tolist()
            pan.thetaInit = self.p(f"panel_theta_init[{i + 1}]")
            pan.thetaDotInit = self.p(f"panel_theta_dot_init[{i + 1}]")
            sc.addStateEffector(pan)
            self.panels.append(pan)
        self._torque_payload = messaging.CmdTorqueBodyMsgPayload()
        self._torque_msg = messaging.CmdTorqueBodyMsg().write(self._torque_payload)
        ext = extForceTorque.ExtForceTorque()
        ext.ModelTag = "ftcsim_torque"
        ext.cmdTorqueInMsg.subscribeTo(self._torque_msg)
        sc.addDynamicEffector(ext)
        keep = [ext]  # Basilisk holds raw pointers: every object it uses lives as long as the block
        if self.p("gravity_gradient") == 1.0:
            from Basilisk.simulation import GravityGradientEffector
            from Basilisk.utilities import simIncludeGravBody

            grav = simIncludeGravBody.gravBodyFactory()
            earth = grav.createEarth()
            earth.isCentralBody = True
            earth.mu = EARTH_MU
            grav.addBodiesTo(sc)
            a = self.p("orbit_radius")
            sc.hub.r_CN_NInit = [[a], [0.0], [0.0]]
            sc.hub.v_CN_NInit = [[0.0], [math.sqrt(EARTH_MU / a)], [0.0]]
            gg = GravityGradientEffector.GravityGradientEffector()
            gg.ModelTag = "ftcsim_gravity_gradient"
            gg.addPlanetName(earth.planetName)
            sc.addDynamicEffector(gg)
            sim.AddModelToTask("dynamics", gg)
            keep += [gg, grav, earth]
        sim.AddModelToTask("dynamics", sc)
        self.configure(sim, "dynamics", sc)
        hooked = type(self).configure is not BasiliskSpacecraft.configure
        self._unknown = [f"what {type(self).__name__}.configure adds"] if hooked and self.extra_states is None else []
        sim.InitializeSimulation()
        self.sim, self.sc, self._keep = sim, sc, keep
        hub_names = (sc.hub.nameOfHubPosition, sc.hub.nameOfHubVelocity, sc.hub.nameOfHubSigma, sc.hub.nameOfHubOmega,
                     sc.hub.nameOfHubGravVelocity, sc.hub.nameOfBcGravVelocity)
        names = list(hub_names)
        if self.rw is not None:
            names.append(self.rw.nameOfReactionWheelOmegasState)
        for pan in self.panels:
            names += [pan.nameOfThetaState, pan.nameOfThetaDotState]
        names += list(self.extra_states or ())
        self._objects = [sc.dynManager.getStateObject(nm) for nm in names]
        self._sizes = [len(np.ravel(o.getState())) for o in self._objects]
        self._sigma_obj, self._omega_obj = self._objects[2], self._objects[3]
        self._speed_obj = self._objects[6] if self.rw is not None else None
        first = 7 if self.rw is not None else 6
        self._panel_objs = [(self._objects[first + 2 * i], self._objects[first + 2 * i + 1]) for i in range(p)]
        self._t_ns = int(round(t0 * 1e9))
        self.sc.timeBeforeNanos = self._t_ns
        self.sc.timeBefore = self._t_ns * 1e-9
        self._u = np.zeros(n + 3)

    # -- dynamics -----------------------------------------------------------------------------------
    def advance(self, t: float, h: float, u: np.ndarray) -> None:
        n = self.n
        steps, _ = substeps(h, self.h_max)
        t0 = int(round(t * 1e9))
        t1 = int(round((t + h) * 1e9))
        if n:
            self._cmd_payload.motorTorque = cv.motor_torque(u[:n]).tolist()
            self._cmd_msg.write(self._cmd_payload, t0)
        self._torque_payload.torqueRequestBody = [float(x) for x in u[n:n + 3]]
        self._torque_msg.write(self._torque_payload, t0)
        self.sc.timeBeforeNanos = t0
        self.sc.timeBefore = t0 * 1e-9
        prev = t0
        try:
            for k in range(1, steps + 1):
                tk = t0 + (t1 - t0) * k // steps
                if self.rw is not None:
                    self.rw.UpdateState(prev)  # the command and the wheel limits at the sub-step's start
                self.sc.UpdateState(tk)
                prev = tk
        except Exception as e:  # a Basilisk error (its logger raises): an error of this instance
            raise FloatingPointError(f"Basilisk: {' '.join(str(e).split())}") from None
        w = np.ravel(self._omega_obj.getState())
        if not np.all(np.isfinite(w)):
            raise FloatingPointError(f"non-finite body rate at t = {(t + h):.6g} s: {w.tolist()}")
        self._t_ns = t1

    def _wheel_torques(self, u: np.ndarray, speed: np.ndarray) -> np.ndarray:
        """What the wheels exert on the body for the command u at the speeds ``speed``: Basilisk's
        ``ConfigureRWRequests`` (motor-torque clip, speed cut) and friction (``updateContributions``,
        without Stribeck), with the sign of u_c."""
        out = np.zeros(self.n)
        u_max, speed_max, cc, cv_, lim = self._wheel_data
        for j in range(self.n):
            um = -float(u[j])
            if u_max > 0:
                um = min(max(um, -u_max), u_max)
            s = float(speed[j])
            if speed_max > 0 and abs(s) >= speed_max and s * um >= 0.0:
                um = 0.0
            if abs(s) < lim:
                friction = (cc + cv_ * lim) / lim * s
            else:
                friction = math.copysign(cc, s) * (s != 0.0) + cv_ * s
            out[j] = -(um - friction)
        return out

    def outputs_at(self, t: float, u: np.ndarray) -> np.ndarray:
        mrp = np.ravel(self._sigma_obj.getState())
        w = np.ravel(self._omega_obj.getState())
        n = self.n
        if n:
            speed = np.ravel(self._speed_obj.getState())
            hw = cv.inertial_momentum(speed, w, self.M, self.Iw)
            uw = self._wheel_torques(u, speed)
        else:
            speed = hw = uw = np.zeros(0)
        theta = np.array([np.ravel(a.getState())[0] for a, _ in self._panel_objs])
        theta_dot = np.array([np.ravel(b.getState())[0] for _, b in self._panel_objs])
        return np.concatenate((cv.euler231_from_mrp(mrp), cv.quaternion_from_mrp(mrp), w, mrp, hw, speed, uw,
                               self.M @ uw if n else np.zeros(3), theta, theta_dot))

    # -- rollback -----------------------------------------------------------------------------------
    def get_state(self) -> list:
        if self._unknown:
            raise ValueError(f"{self.model_name}: rollback refused: the Basilisk spacecraft carries {', '.join(self._unknown)}, "
                             "whose states the block does not know, so a restored state could not be exact (name their "
                             "dynManager states in the class attribute extra_states; () if they have none)")
        out = [float(self._t_ns)]
        for o in self._objects:
            out += np.ravel(o.getState()).tolist()
        for j in range(self.n):  # (indexing: iterating the SWIG vector drops the GIL)
            w = self.rw.ReactionWheelData[j]
            out += [float(w.omegaBefore), float(bool(w.frictionStribeck))]
        return out

    def set_state(self, state) -> None:
        s = [float(x) for x in state]
        self._t_ns = int(s[0])
        k = 1
        for o, m in zip(self._objects, self._sizes):
            o.setState([[x] for x in s[k:k + m]])
            k += m
        for j in range(self.n):
            w = self.rw.ReactionWheelData[j]
            w.omegaBefore, w.frictionStribeck = s[k], bool(s[k + 1])
            k += 2
        self.sc.timeBeforeNanos = self._t_ns
        self.sc.timeBefore = self._t_ns * 1e-9


def basilisk_spacecraft_4() -> BasiliskSpacecraft:
    """Four Honeywell HR16 wheels (50 N.m.s at 6000 rpm, 0.2 N.m, no friction: simIncludeRW's defaults)
    in 001's layout (three on the body axes, one along (1, 1, 1)/sqrt(3)), no panels, J = 10 I kg.m2."""
    b = BasiliskSpacecraft(4, 0)
    b.model_name = "BasiliskSpacecraft4"
    return b
