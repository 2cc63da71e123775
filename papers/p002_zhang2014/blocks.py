"""Paper 002's blocks with its numbers as defaults (numpy only: embedded in the FMUs).

* :func:`plant`: ``Zhang2014Plant``, the pitch-axis spacecraft of 002 section 4 (J = 35.72 kg m^2,
  F = [1.27814, 0.91756], modes 3.17 / 7.38 rad/s, damping 0.001 / 0.015), theta(0) = 0.08 rad,
  theta'(0) = 0.04 rad/s, modes at rest (002 gives no eta(0)), effectiveness 1 from t = 0.
* :func:`controller`: ``Zhang2014Hinf``, u = K x (002 (9)) with the three gains of Table 2
  (omega_hat = 1, 0.5, 0.2); parameter ``omega_hat`` selects the case (default 1).
"""
from controller.state_feedback import ScheduledStateFeedback
from papers.shared_blocks import configured, pitch_axis_plant
from plant.pitch_axis import PitchAxisSpacecraft

from .gains import CASES, PUBLISHED
from .parameters import X0, ZHANG2014

PLANT_MODEL = "Zhang2014Plant"
CONTROLLER_MODEL = "Zhang2014Hinf"


def plant() -> PitchAxisSpacecraft:
    return pitch_axis_plant(PLANT_MODEL, "Pitch-axis flexible spacecraft of 002 section 4 (002 (1)-(3))", ZHANG2014, X0)


def controller() -> ScheduledStateFeedback:
    return configured(ScheduledStateFeedback(n_cases=len(CASES)), CONTROLLER_MODEL,
                      "Robust H-infinity passive FTC u = K x, 002 (9), gains of 002 Table 2",
                      {"K": [PUBLISHED[w]["K"][0] for w in CASES], "case_omega_hat": list(CASES), "omega_hat": 1.0})
