"""Factories of 004's blocks: generic blocks configured with 004's numbers (numpy only).

Each returns a fresh block whose defaults (what its FMU declares) are 004's set-up; the FMU
model names are set here (``papers/registry.py``). Readings and departures: README.md.

Loop (scenarios/xu2024_*.toml): plant -> controller (omega, q) ; mode source -> controller and
actuator (mode) ; controller -> actuator (u) ; disturbance -> actuator (d) ; actuator -> plant (tau).
"""
import numpy as np

from controller.sampled_fuzzy import NETWORK_BYPASS, SAMPLE_UNIFORM, SampledFuzzyFTC
from plant.flexible import FlexibleSpacecraft
from plant.markov import ALPHA_COS2, MarkovModeSource
from plant.mode_faults import ModeFaultActuator
from plant.multisine import MultisineSource
from plant.ts_attitude import TSAttitudePlant

from . import parameters as P
from .gains import DESIGNED

MODELS = {
    "flexible_plant": "Xu2024FlexiblePlant",
    "ts_plant": "Xu2024TSPlant",
    "mode_source": "Xu2024MarkovFaults",
    "fault_actuator": "Xu2024FaultActuator",
    "disturbance": "Xu2024Disturbance",
    "controller": "Xu2024SampledFTC",
}
U_MAX = 1e6  # N.m: 004 has no saturation (ours: a bound that never acts)


def _named(block, key):
    block.model_name = MODELS[key]
    return block


def membership_defaults(order: str = "matched") -> dict:
    return {"z_half_width": P.MEMBERSHIP["z_half_width"], "z_slope": P.MEMBERSHIP["z_slope"],
            "rule_peak": P.RULE_PEAKS[order]}


def flexible_plant():
    """000's flexible spacecraft (rigid hub + 4 modes) with 004's parameter set; no
    saturation (u_max = 1e6 N.m); d(t) arrives through the torque input (fault actuator);
    initial state: omega(0) printed, q(0) from the Gibbs-vector reading, modes at rest."""
    b = FlexibleSpacecraft()
    q0 = P.x0_gibbs_quaternion()
    b.set_defaults({**P.XU2024, "u_max": U_MAX, "omega_init": P.X0_PRINTED[:3], "h_max": 0.001,
                    "disturbance_scale": 0.0, "fault_scale": 0.0,
                    **{f"q_init[{i}]": float(q0[i]) for i in range(4)}})  # q_init is 0-based
    return _named(b, "flexible_plant")


def ts_plant():
    """004's 3-rule T-S model (6) as the plant ("the closed-loop fuzzy system", Figs. 5-6),
    from the printed x(0)."""
    b = TSAttitudePlant(n_rules=3, n_modes=4)
    b.set_defaults({"J": P.XU2024["J"], "delta": P.XU2024["delta"], "points": P.OPERATING_POINTS,
                    **membership_defaults(), "x_init": P.X0_PRINTED, "h_max": 0.001})
    return _named(b, "ts_plant")


def mode_source():
    """Fault modes r(t): rates (52)-(53), r(0) = 1 (ours), seed 0."""
    b = MarkovModeSource(n_modes=3, n_vertices=2)
    b.set_defaults({"Pi": P.RATE_VERTICES, "alpha_profile": ALPHA_COS2, "r0": P.R0, "seed": 0})
    return _named(b, "mode_source")


def fault_actuator():
    """004 (9): F_r, G_r of Cases I-III and the bias v = 0.1 N.m per axis (ours)."""
    b = ModeFaultActuator(n_modes=3)
    b.set_defaults(dict(P.FAULT_MODES))
    return _named(b, "fault_actuator")


def disturbance():
    """d(t) of 004 section 4 (printed)."""
    b = MultisineSource(n_outputs=3, n_terms=2)
    b.set_defaults(dict(P.DISTURBANCE))
    return _named(b, "disturbance")


def controller():
    """004 (14): our designed gains (Theorem 2, nonhomogeneous case, gains.DESIGNED), the
    printed network with network_mode = 1 (bypass, M_s = I: the printed one gives M_s = 0),
    sampling intervals uniform on [0.05, 0.1] s on a 1 ms grid (ours)."""
    b = SampledFuzzyFTC(n_modes=3, n_rules=3, n_nodes=3)
    b.set_defaults({"K": np.asarray(DESIGNED["K"]), **P.NETWORK, "network_mode": NETWORK_BYPASS,
                    "sample_mode": SAMPLE_UNIFORM, **P.SAMPLING, "sample_seed": 0, **membership_defaults()})
    return _named(b, "controller")
