"""Factories of the arena's FMUs (numpy only: the FMUs embed this module), as ``papers/*/blocks.py``
are for a paper: a paper-agnostic block under its FMU model name, with defaults.

Defaults chosen here (each a parameter, overridden per scenario or by a parameter set of
``arena/parameters.py``):

* wheel layouts: 001's M (three orthogonal wheels and one along (1, 1, 1)/sqrt 3) for 4 wheels;
* fault catalog: class 0 (no fault); for class 8 004's Markov set-up: the rate vertices (53) with
  alpha = (cos^2 t, sin^2 t) (52), r(0) = 1, and 004's cases I-III (F_2 = diag(0.7, 0.8, 0.6),
  G_3 = I, v = 0.1 N.m, v ours as in paper 004's scenarios). On 4 wheels the fourth wheel takes
  F_2 = 0.7 (ours); on the pitch axis the first entry of each (ours);
* hardware: a Honeywell HR12 (12 N.m.s) wheel, a STIM300 gyro at 100 Hz, a small star tracker at
  5 Hz, a 10 Hz controller sample rate (``plant/hardware/datasheets.py``).
"""
from __future__ import annotations

import numpy as np

from controller.allocation import TorqueAllocation, WheelsToBody
from papers.p001_zhang2019.parameters import ZHANG2019
from papers.p004_xu2024.parameters import FAULT_MODES, RATE_VERTICES
from plant.attitude_adapters import AttitudeError, Euler231ToQuaternion, QuaternionToEuler231
from plant.fault_catalog import FaultCatalog
from plant.hardware.datasheets import ANGLE_SENSORS, GYROS, HOLDS, STAR_TRACKERS, WHEELS
from plant.hardware.sample_hold import ZeroOrderHold
from plant.hardware.sensors import AngleSensor, RateGyro, StarTracker
from plant.hardware.wheels import ReactionWheels
from plant.markov import ALPHA_COS2

M_001 = ZHANG2019["M"]


def _named(block, model: str, description: str | None = None, defaults: dict | None = None):
    block.model_name = model
    if description:
        block.description = description
    if defaults:
        block.set_defaults(defaults)
    return block


# -- adapters --------------------------------------------------------------------------------------
def euler_to_quaternion() -> Euler231ToQuaternion:
    return Euler231ToQuaternion()


def quaternion_to_euler() -> QuaternionToEuler231:
    return QuaternionToEuler231()


def attitude_error() -> AttitudeError:
    return AttitudeError()


def torque_allocation() -> TorqueAllocation:
    """3 axes -> 001's 4 wheels, M^+ by default."""
    return _named(TorqueAllocation(4), "TorqueAllocation", defaults={"M": M_001})


def wheels_to_body() -> WheelsToBody:
    """001's 4 wheels -> body torque M u and body fault torque."""
    return _named(WheelsToBody(4), "WheelsToBody", defaults={"M": M_001})


# -- fault catalog ----------------------------------------------------------------------------------
def _markov_defaults(n: int) -> dict:
    F, G, v = FAULT_MODES["F"], FAULT_MODES["G"], FAULT_MODES["v"]
    if n == 4:
        F, G, v = np.hstack([F, [[1.0], [0.7], [1.0]]]), np.hstack([G, G[:, :1]]), np.append(v, v[0])
    elif n == 1:
        F, G, v = F[:, :1], G[:, :1], v[:1]
    return {"F": F, "G": G, "v": v, "Pi": RATE_VERTICES, "alpha_profile": float(ALPHA_COS2), "r0": 1.0}


def _catalog(n: int, what: str) -> FaultCatalog:
    return _named(FaultCatalog(n), f"FaultCatalog{n}",
                  f"Actuator fault catalog on {what}: LOE step/ramp, bias, intermittent, time-varying, stuck, lost, Markov",
                  _markov_defaults(n))


def fault_catalog_3() -> FaultCatalog:
    return _catalog(3, "3 body axes")


def fault_catalog_4() -> FaultCatalog:
    return _catalog(4, "4 wheels")


def fault_catalog_1() -> FaultCatalog:
    return _catalog(1, "the pitch axis")


# -- hardware ----------------------------------------------------------------------------------------
def reaction_wheels_4() -> ReactionWheels:
    return _named(ReactionWheels(4, 3), "ReactionWheels4",
                  "4 reaction wheels (001's layout): torque/momentum limits, friction, drive bandwidth",
                  {"M": M_001, **WHEELS["wheels_hr12_12"]})


def reaction_wheel_1() -> ReactionWheels:
    return _named(ReactionWheels(1, 1), "ReactionWheel1",
                  "one pitch-axis reaction wheel: torque/momentum limits, friction, drive bandwidth",
                  WHEELS["wheels_hr12_12"])


def rate_gyro_3() -> RateGyro:
    return _named(RateGyro(3), "RateGyro3", defaults=GYROS["gyro_stim300"])


def rate_gyro_1() -> RateGyro:
    return _named(RateGyro(1), "RateGyro1", "single-axis rate gyro: angle random walk, rate random walk, bias instability",
                  GYROS["gyro_stim300"])


def star_tracker() -> StarTracker:
    return _named(StarTracker(), "StarTracker", defaults=STAR_TRACKERS["st_small"])


def angle_sensor_1() -> AngleSensor:
    return _named(AngleSensor(1), "AngleSensor1", defaults=ANGLE_SENSORS["angle_small"])


def zero_order_hold_3() -> ZeroOrderHold:
    return _named(ZeroOrderHold(3), "ZeroOrderHold3", defaults=HOLDS["zoh_10hz"])


def zero_order_hold_4() -> ZeroOrderHold:
    return _named(ZeroOrderHold(4), "ZeroOrderHold4", defaults=HOLDS["zoh_10hz"])


def zero_order_hold_1() -> ZeroOrderHold:
    return _named(ZeroOrderHold(1), "ZeroOrderHold1", defaults=HOLDS["zoh_10hz"])
