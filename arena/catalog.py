"""The arena's FMUs and parameter sets, as the registry (``papers/registry.py``) lists them.

``FMUS``: (model name, factory in ``arena/blocks.py``, description), the form of a paper's
``declare(fmus=...)``; ``fmu_specs()`` gives them as :class:`papers.paper.FMUSpec`.
``parameter_sets()``: set name -> ``"arena.parameters:ATTRIBUTE"`` (resolved lazily, like the
papers' sets).
"""
from __future__ import annotations

FMUS = (
    ("Euler231ToQuaternion", "euler_to_quaternion", "attitude adapter: 001's 2-3-1 Euler angles -> quaternion"),
    ("QuaternionToEuler231", "quaternion_to_euler", "attitude adapter: quaternion -> 001's 2-3-1 Euler angles"),
    ("AttitudeError", "attitude_error", "attitude adapter: error quaternion and rate error of 000 (4)-(5)"),
    ("TorqueAllocation", "torque_allocation", "torque allocation 3 axes -> 4 wheels, weighted pseudo-inverse, failed wheel dropped"),
    ("WheelsToBody", "wheels_to_body", "4 wheel torques -> body torque, per-wheel faults -> body fault torque"),
    ("FaultCatalog3", "fault_catalog_3", "actuator fault catalog on 3 body axes"),
    ("FaultCatalog4", "fault_catalog_4", "actuator fault catalog on 4 wheels"),
    ("FaultCatalog1", "fault_catalog_1", "actuator fault catalog on the pitch axis"),
    ("ReactionWheels4", "reaction_wheels_4", "4 reaction wheels: torque/momentum limits, friction, drive bandwidth"),
    ("ReactionWheel1", "reaction_wheel_1", "pitch-axis reaction wheel: torque/momentum limits, friction, drive bandwidth"),
    ("RateGyro3", "rate_gyro_3", "3-axis rate gyro: ARW, rate random walk, bias instability, seeded"),
    ("RateGyro1", "rate_gyro_1", "single-axis rate gyro: ARW, rate random walk, bias instability, seeded"),
    ("StarTracker", "star_tracker", "star tracker: quaternion with cross-/about-boresight noise, seeded"),
    ("AngleSensor1", "angle_sensor_1", "pitch-axis attitude sensor: angle noise and bias, seeded"),
    ("ZeroOrderHold3", "zero_order_hold_3", "zero-order hold of a 3-axis command at a controller sample rate"),
    ("ZeroOrderHold4", "zero_order_hold_4", "zero-order hold of 4 wheel commands at a controller sample rate"),
    ("ZeroOrderHold1", "zero_order_hold_1", "zero-order hold of a pitch-axis command at a controller sample rate"),
)


def fmu_specs() -> tuple:
    from papers.paper import FMUSpec

    return tuple(FMUSpec(model, f"arena.blocks:{factory}", description) for model, factory, description in FMUS)


def parameter_sets() -> dict:
    from .parameters import SETS

    return {name: f"arena.parameters:{name.upper()}" for name in SETS}
