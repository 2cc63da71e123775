"""Paper 003's blocks with its numbers as defaults (numpy only: embedded in the FMUs).

* :func:`plant`: ``Hang2023Plant``, the pitch axis of 003 section 4 (J = 6.14 kg m^2, H = [1.27806,
  0.91758], modes 3.17 / 7.38 rad/s, damping 0.001 / 0.0016), external torque T_2y of 003 (4.2),
  effectiveness 1 until 20 s and 0.4 from 20 s (set ``effectiveness`` to 0.8 / 1.0 for the other
  cases of Figs. 9-10); theta(0) = 0.08 rad, theta'(0) = 0.04 rad/s (ours, 003 gives none).
* :func:`observer`: ``Hang2023TSFDO``, 003 (3.1) with the published L1, the rule matrices W_j, V_j and
  the Gaussian memberships of section 4.
* :func:`controller`: ``Hang2023ASMFTC``, 003 (3.9)-(3.21) with the gains of section 4; default laws
  (3.21) + (3.19) + (3.20).
"""
from controller.asmftc import ASMFTC
from estimator.tsfdo import TSFDO
from papers.shared_blocks import configured, pitch_axis_plant
from plant.pitch_axis import PitchAxisSpacecraft

from .gains import L1_PUBLISHED
from .parameters import ASMFTC_GAINS, DISTURBANCE, FAULT_FACTORS, FAULT_ONSET, HANG2023, MF_CENTER, MF_SIGMA2, X0, V, W

PLANT_MODEL = "Hang2023Plant"
OBSERVER_MODEL = "Hang2023TSFDO"
CONTROLLER_MODEL = "Hang2023ASMFTC"


def plant() -> PitchAxisSpacecraft:
    return pitch_axis_plant(PLANT_MODEL, "Pitch-axis flexible satellite of 003 section 4 (003 (2.1)-(2.5), (4.2))",
                            HANG2023, X0, **DISTURBANCE, effectiveness=FAULT_FACTORS[0], effectiveness_before=1.0,
                            effectiveness_onset=FAULT_ONSET)


def observer() -> TSFDO:
    return configured(TSFDO(n_rules=len(W), n_w=W[0].shape[0], n_modes=len(HANG2023["F"])), OBSERVER_MODEL,
                      "T-S fuzzy disturbance observer of 003 (3.1), published L1 and section 4 memberships",
                      {"J": HANG2023["J"], "F": HANG2023["F"], "L1": L1_PUBLISHED, "W": list(W), "V": list(V),
                       "mf_center": MF_CENTER, "mf_sigma2": MF_SIGMA2})


def controller() -> ASMFTC:
    return configured(ASMFTC(n_modes=len(HANG2023["F"])), CONTROLLER_MODEL,
                      "Adaptive terminal sliding-mode FTC of 003 (3.9)-(3.21), gains of 003 section 4",
                      {"J": HANG2023["J"], "F": HANG2023["F"], **ASMFTC_GAINS})
