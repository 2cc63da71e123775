"""A Basilisk spacecraft with Honeywell reaction wheels (``simIncludeRW``), optional hinged panels
(000's flexible modes, ``conventions.panels_from_modes``), flown by ftcsim FMUs (:class:`FMUModule`):
the parts of the shipped examples (``python -m orchestrator.tools.basilisk_example``) and of the
cross-checks (tests/interop/test_basilisk_*.py).

The dynamics task (period ``dyn_step``) holds, by priority (higher first, Basilisk's order): the reaction
wheels (read the last command written, clip it at their torque and speed limits), the spacecraft
(integrates [t - dyn_step, t] with Basilisk's RK4, one step per call, and writes its state at t) and the
panels; the flight-software task (period ``step``, run after the dynamics task at a common time) holds
the FMU modules in the order of ftcsim's ordered exchange (``FMUModule``). The command computed at t
acts over [t, t + step]: ftcsim's zero-order hold, with ftcsim's internal step h_max = ``dyn_step``.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from Basilisk.architecture import messaging
from Basilisk.simulation import hingedRigidBodyStateEffector, reactionWheelStateEffector, spacecraft
from Basilisk.utilities import SimulationBaseClass, macros, simIncludeRW

from . import conventions as cv
from .module import FMUModule, execute, initialize

__all__ = ["Craft", "Flight", "build_craft", "fly", "HONEYWELL"]

RPM = 2.0 * np.pi / 60.0
HONEYWELL = {"Honeywell_HR16": (50.0, 75.0, 100.0), "Honeywell_HR14": (25.0, 50.0, 75.0),
             "Honeywell_HR12": (12.0, 25.0, 50.0)}  # simIncludeRW's momentum options, N.m.s


@dataclass
class Craft:
    """A Basilisk simulation with one spacecraft: the objects, ftcsim's view of them (J without the
    wheels' spin inertia, spin axes G, wheel spin inertia I_w) and the FMU modules added to it."""

    sim: object
    task: str
    step: float
    sc: object
    rw: object | None
    rw_factory: object | None
    panels: list
    J: np.ndarray
    G: np.ndarray | None
    I_w: float
    modules: dict = field(default_factory=dict)
    recorders: dict = field(default_factory=dict)


def build_craft(J, step: float, *, dyn_step: float | None = None, sigma_BN=(0.0, 0.0, 0.0), omega=(0.0, 0.0, 0.0), G=None,
                wheel="Honeywell_HR16",
                max_momentum: float = 50.0, h_w=None, wheel_options: dict | None = None, modes: dict | None = None,
                eta=None, eta_dot=None, torque_in=None) -> Craft:
    """A Basilisk simulation with a flight-software task of period ``step`` (s; the FMU modules' step) and
    a dynamics task of period ``dyn_step`` (s, a divisor of ``step``; default ``step``: Basilisk integrates
    one RK4 step per call, so ``dyn_step`` is ftcsim's ``h_max``), run first at a common time, holding a spacecraft of ftcsim inertia
    ``J`` (kg.m2; with ``modes``, 000's J including the appendages), attitude ``sigma_BN`` (MRP) and rate
    ``omega`` (rad/s), reaction wheels about the unit columns of ``G`` (3 x N) from ``simIncludeRW``
    (``wheel``, ``max_momentum`` N.m.s; ``wheel_options``: more ``rwFactory.create`` keywords, e.g.
    ``useMaxTorque=False``) with inertial momenta ``h_w`` (N.m.s, ftcsim's convention; 0 by default),
    and with ``modes`` (000's ``delta``, ``omega_n``, ``zeta``) one massless hinged panel per mode at
    ``eta``, ``eta_dot``. ``torque_in``: a CmdTorqueBodyMsg for an extForceTorque on the hub."""
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("spacecraft")
    dyn_step = step if dyn_step is None else dyn_step
    ratio = step / dyn_step
    if abs(ratio - round(ratio)) > 1e-9 * ratio:
        raise ValueError(f"dyn_step = {dyn_step:g} s must divide step = {step:g} s")
    proc.addTask(sim.CreateNewTask("dynamics", macros.sec2nano(dyn_step)), 100)
    proc.addTask(sim.CreateNewTask("fsw", macros.sec2nano(step)), 50)
    sc = spacecraft.Spacecraft()
    sc.ModelTag = "spacecraft"
    J = np.asarray(J, dtype=float)
    hub = J.copy()
    panels = []
    if modes is not None:
        delta = np.asarray(modes["delta"], dtype=float)
        hub = hub - delta.T @ delta  # 000 (1): the panels carry delta^T delta
        n = delta.shape[0]
        eta = np.zeros(n) if eta is None else np.asarray(eta, dtype=float)
        eta_dot = np.zeros(n) if eta_dot is None else np.asarray(eta_dot, dtype=float)
        for i, p in enumerate(cv.panels_from_modes(delta, modes["omega_n"], modes["zeta"])):
            panel = hingedRigidBodyStateEffector.HingedRigidBodyStateEffector()
            panel.ModelTag = f"panel{i + 1}"
            panel.mass = 0.0
            panel.d = 0.0
            panel.IPntS_S = [[0.0, 0.0, 0.0], [0.0, p["inertia"], 0.0], [0.0, 0.0, 0.0]]
            panel.k, panel.c = p["k"], p["c"]
            panel.r_HB_B = [[0.0], [0.0], [0.0]]
            panel.dcm_HB = cv.hinge_dcm(p["axis"]).tolist()
            panel.thetaInit = float(eta[i] / p["scale"])
            panel.thetaDotInit = float(eta_dot[i] / p["scale"])
            sc.addStateEffector(panel)
            panels.append((panel, p))
    rw = fac = None
    I_w = 0.0
    if G is not None:
        G = np.asarray(G, dtype=float)
        fac = simIncludeRW.rwFactory()
        options = {"maxMomentum": float(max_momentum), "RWModel": messaging.BalancedWheels, **(wheel_options or {})}
        made = [fac.create(wheel, G[:, j].tolist(), **options) for j in range(G.shape[1])]
        I_w = float(made[0].Js)
        h_w = np.zeros(G.shape[1]) if h_w is None else np.asarray(h_w, dtype=float)
        speeds = cv.relative_speed(h_w, omega, G, I_w)
        for r, s in zip(made, speeds):
            r.Omega = float(s)  # rad/s (create() takes rpm; set after)
        rw = reactionWheelStateEffector.ReactionWheelStateEffector()
        fac.addToSpacecraft("wheels", rw, sc)
        hub = cv.hub_inertia(hub, G, I_w)
    sc.hub.IHubPntBc_B = hub.tolist()
    sc.hub.mHub = 100.0  # kg (the attitude does not depend on it: no translation is coupled)
    sc.hub.sigma_BNInit = np.asarray(sigma_BN, dtype=float).reshape(3, 1).tolist()
    sc.hub.omega_BN_BInit = np.asarray(omega, dtype=float).reshape(3, 1).tolist()
    if rw is not None:
        sim.AddModelToTask("dynamics", rw, 300)
    if torque_in is not None:
        from Basilisk.simulation import extForceTorque

        ext = extForceTorque.ExtForceTorque()
        ext.ModelTag = "torque"
        ext.cmdTorqueInMsg.subscribeTo(torque_in)
        sc.addDynamicEffector(ext)
        sim.AddModelToTask("dynamics", ext, 250)
    sim.AddModelToTask("dynamics", sc, 200)
    for panel, _ in panels:
        sim.AddModelToTask("dynamics", panel, 150)
    return Craft(sim, "fsw", float(step), sc, rw, fac, [p for p, _ in panels], J, G, I_w)


def add_module(craft: Craft, name: str, module: FMUModule, priority: int) -> FMUModule:
    """Add an FMU module to the craft's task (priority: higher runs first, below 100 for FSW)."""
    craft.sim.AddModelToTask(craft.task, module, priority)
    craft.modules[name] = module
    return module


@dataclass
class Flight:
    """What a flight recorded at every call: t (s), sigma_BN (MRP), omega (rad/s), wheel speeds Omega
    (rad/s, relative), panel angles theta (rad), and the FMU outputs (name.base -> array)."""

    t: np.ndarray
    sigma_BN: np.ndarray
    omega: np.ndarray
    speed: np.ndarray | None
    theta: np.ndarray | None
    outputs: dict

    def quaternion(self) -> np.ndarray:
        return np.array([cv.quaternion_from_mrp(s) for s in self.sigma_BN])

    def euler231(self) -> np.ndarray:
        return np.array([cv.euler231_from_mrp(s) for s in self.sigma_BN])


class _Recorder:
    """Records chosen outputs of the FMU modules at every call (after them in the task)."""

    def __init__(self, craft: Craft, record: dict):
        from Basilisk.architecture import sysModel

        class Rec(sysModel.SysModel):
            def __init__(self):
                super().__init__()
                self.rows = {k: [] for k in record}

            def UpdateState(self, CurrentSimNanos):
                for key, (module, base) in record.items():
                    self.rows[key].append(module.current[base].copy())

        self.model = Rec()
        self.model.ModelTag = "ftcsim_recorder"
        craft.sim.AddModelToTask(craft.task, self.model, 1)

    def arrays(self) -> dict:
        return {k: np.array(v) for k, v in self.model.rows.items()}


def fly(craft: Craft, stop: float, record: dict | None = None) -> Flight:
    """Run the craft's simulation from 0 to ``stop`` (s), recording the spacecraft and wheel states and
    ``record`` (key -> (FMUModule, output base)) at every call."""
    sc_rec = craft.sc.scStateOutMsg.recorder()
    craft.sim.AddModelToTask(craft.task, sc_rec, 0)
    rw_rec = None
    if craft.rw is not None:
        rw_rec = craft.rw.rwSpeedOutMsg.recorder()
        craft.sim.AddModelToTask(craft.task, rw_rec, 0)
    p_recs = []
    for p in craft.panels:
        r = p.hingedRigidBodyOutMsg.recorder()
        craft.sim.AddModelToTask(craft.task, r, 0)
        p_recs.append(r)
    rec = _Recorder(craft, record or {})
    initialize(craft.sim)
    craft.sim.ConfigureStopTime(macros.sec2nano(stop))
    execute(craft.sim)
    n_w = 0 if craft.G is None else craft.G.shape[1]
    return Flight(t=np.asarray(sc_rec.times()) * 1e-9, sigma_BN=np.asarray(sc_rec.sigma_BN),
                  omega=np.asarray(sc_rec.omega_BN_B),
                  speed=np.asarray(rw_rec.wheelSpeeds)[:, :n_w] if rw_rec is not None else None,
                  theta=np.column_stack([np.asarray(r.theta) for r in p_recs]) if p_recs else None,
                  outputs=rec.arrays())
